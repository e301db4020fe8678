//! A rotor under a load far beyond the ring's torque: the speed past which its bar would burst,
//! and its drift between the switches of a fast schedule, where the ring cannot move it.

use super::spin::SETTLES_PER_SUBSTEP;
use super::{Drive, Motor, StepRun};
use std::f64::consts::PI;

/// The tip speed (m/s) above which no material holds a bar spinning about its centre: the
/// centrifugal stress peaks there at `rho v^2 / 2` for a tip speed `v`, so `v <= sqrt(2 sigma /
/// rho)`, and the highest specific strength `sigma / rho` of any material (carbon-nanotube
/// fibres, about 5e7 N m/kg) gives 1e4 m/s (nickel: about 300 m/s).
pub const BURST_TIP_SPEED: f64 = 1e4;

impl Motor {
    /// The rotor speed (rad/s) at which the bar's tips reach [`BURST_TIP_SPEED`].
    pub fn burst_speed(&self) -> f64 {
        2.0 * BURST_TIP_SPEED / self.params.bar_length
    }

    /// `Err` when the load drives the rotor past [`Self::burst_speed`] within a step of `h`
    /// seconds from `speed`, whatever the ring does: with drag `c`, `I w' = load + tau - c w` and
    /// `|tau| <= tau_max` keep the speed along the load at least
    /// `w0 e^(-h c/I) + (|load| - tau_max) / c (1 - e^(-h c/I))` (`w0 + (|load| - tau_max) h / I`
    /// without drag). Such loads (up to 1e-6 N m is accepted, 1e11 times Table 3.1's torque)
    /// spin a nano-bar at up to 1e17 rad/s, where the rotor leaves its bounds within a step and
    /// no substep means anything.
    pub(super) fn check_burst_speed(&self, speed: f64, load: f64, h: f64) -> Result<(), String> {
        let (i, c) = (self.inertia, self.drag);
        let force = load.abs() - self.torque_bound();
        let along = speed * load.signum();
        let bound = if c > 0.0 {
            let approach = -(-h * c / i).exp_m1();
            along * (1.0 - approach) + force / c * approach
        } else {
            along + force * h / i
        };
        let limit = self.burst_speed();
        if bound <= limit {
            return Ok(());
        }
        Err(format!(
            "load_torque = {load:e} N m spins the rotor (now at {speed:e} rad/s) beyond {bound:.3e} \
             rad/s within this step, past its burst speed {limit:.3e} rad/s (the bar's tips at \
             {BURST_TIP_SPEED:e} m/s, beyond any material's strength; bar_length = {:e} m, \
             fluid_viscosity = {:e} Pa s); lower the load or shorten the step",
            self.params.bar_length, self.params.fluid_viscosity
        ))
    }

    /// A segment over which the ring's torque cannot move the rotor by a tenth of the
    /// tolerance: the rotor follows load and drag alone, `I phi'' = load - c phi'`, exactly, and
    /// the quasi-static onion is settled along its path (strides of at most
    /// [`MAX_DRIFT_STRIDE`], so that its snaps keep their memory rule). The ring's torque,
    /// `|tau| <= tau_max`, moves the rotor from that motion by at most `tau_max g(h)` in angle
    /// and `tau_max s(h)` in speed, with `g(h) = (h - I/c (1 - e^(-h c/I))) / c` and
    /// `s(h) = (1 - e^(-h c/I)) / c` the response to a unit torque (`h^2 / 2I`, `h / I` without
    /// drag). The angle's is held below `tolerance / 10`; the speed's, which does not add up
    /// over segments (the angle's bound includes its effect), below the tolerance on the error
    /// norm's scale, as an accepted substep's local error.
    ///
    /// This is the rotor of a fast schedule under a load far beyond the ring's torque: it turns
    /// by a fraction of a turn between switches (the onion's cycle, two turns of strides, was
    /// marched again after every switch, 20-30 us each), or barely turns where the ring's torque
    /// is too weak to move it within the segment. Applies (else `false`) with a quasi-static
    /// onion and a free rotor turning one way (`omega load >= 0`) by at most
    /// [`MAX_DRIFT_TURN`].
    pub(super) fn advance_drifting(&self, run: &mut StepRun, d: &Drive, segment_end: f64) -> bool {
        let c = self.drag;
        if d.locked || !self.quasi_static() || run.y[1] * d.load < 0.0 {
            return false;
        }
        let h = segment_end - run.t;
        let (coast, torque_speed, torque_angle) = self.drift_response(h);
        if !self.ring_is_negligible(torque_speed, torque_angle) {
            return false;
        }
        let turn = run.y[1] * coast + d.load * torque_angle;
        if turn.is_nan() || turn.abs() > MAX_DRIFT_TURN {
            return false;
        }
        let speed = run.y[1] * (1.0 - c * torque_speed) + d.load * torque_speed;
        let strides = (turn.abs() / MAX_DRIFT_STRIDE).ceil().max(1.0);
        let mut psi = run.y[2];
        for k in 1..=strides as usize {
            let phi = run.y[0] + turn * (k as f64 / strides);
            psi = self.landscape(phi, d.direction, d.stress).settle(psi);
        }
        run.y = [run.y[0] + turn, speed, psi, 0.0];
        run.t = segment_end;
        run.settled = false;
        run.attempts = run.attempts.saturating_add(1);
        run.extra_cost = run
            .extra_cost
            .saturating_add((strides as u32).div_ceil(SETTLES_PER_SUBSTEP));
        true
    }

    /// Without eq. 3.4's term (no stress, or no wall volume: `E = 0` for every segment of the
    /// step, since the schedule holds its stress), the onion's landscape is eq. 3.3 alone, whose
    /// one minimum per turn is at the bar (`beta = 0`): the settled onion turns rigidly with the
    /// rotor, its torque on the bar stays what it is now (zero but for the settle's rounding), and
    /// the rotor follows `I phi'' = load + tau - c phi'` exactly over the rest of the step,
    /// through every switch of the schedule (the strain direction it changes does not enter).
    /// A locked rotor stays as it is. Applies (else `false`) with a quasi-static onion settled
    /// on that minimum (not a Gilbert onion following its branch, which does so one segment at a
    /// time).
    ///
    /// Without it, the step was cut at every switch of a nanosecond schedule (a drift or a settle
    /// each, hundreds per 1 us step) or the onion's cycle (zero torque) was marched every step.
    pub(super) fn advance_unstrained(&self, run: &mut StepRun, d: &Drive) -> bool {
        if !self.quasi_static()
            || !run.following.is_nan()
            || self.magnetoelastic_per_stress * d.stress != 0.0
        {
            return false;
        }
        let (phi, psi) = (run.y[0], run.y[2]);
        let offset = psi - phi;
        let at_minimum = super::angles::turned_back(offset).cos() > 0.0;
        if !at_minimum {
            return false;
        }
        let y = if d.locked {
            [phi, 0.0, psi, 0.0]
        } else {
            let c = self.drag;
            let force = d.load + self.ring_bar.torque(offset);
            let (coast, torque_speed, torque_angle) = self.drift_response(run.t_end - run.t);
            let turn = run.y[1] * coast + force * torque_angle;
            let speed = run.y[1] * (1.0 - c * torque_speed) + force * torque_speed;
            [phi + turn, speed, psi + turn, 0.0]
        };
        if !(y.iter().all(|v| v.is_finite()) && y[0].abs().max(y[2].abs()) <= super::MAX_ANGLE) {
            return false;
        }
        run.y = y;
        run.t = run.t_end;
        run.settled = false;
        run.angles = None;
        run.attempts = run.attempts.saturating_add(1);
        true
    }

    /// The rotor's response over `h` to its initial speed and to a unit torque, under drag `c`
    /// and inertia `I`: `(I/c (1 - e^(-h c/I)), s(h), g(h))` with `s` and `g` as above (the angle
    /// a unit speed coasts, the speed and the angle a unit torque gives).
    pub(super) fn drift_response(&self, h: f64) -> (f64, f64, f64) {
        let (i, c) = (self.inertia, self.drag);
        if c > 0.0 {
            let approach = -(-h * c / i).exp_m1();
            (i / c * approach, approach / c, (h - i / c * approach) / c)
        } else {
            (h, h / i, 0.5 * h * h / i)
        }
    }

    /// Whether the ring's largest torque moves the rotor by at most a tenth of the tolerance in
    /// angle and the tolerance in speed, given the unit-torque responses of [`Self::drift_response`].
    pub(super) fn ring_is_negligible(&self, torque_speed: f64, torque_angle: f64) -> bool {
        let tau = self.torque_bound();
        let tol = self.params.tolerance;
        tau * torque_angle <= 0.1 * tol && tau * torque_speed <= tol * self.speed_scale
    }
}

/// Largest turn of a drifting rotor within a segment (rad; see [`Motor::advance_drifting`]): a
/// quarter turn of onion settles, beyond which the averaged spin's cycle is the cheaper.
const MAX_DRIFT_TURN: f64 = 0.5 * PI;
/// Largest rotor stride between the drifting onion's settles (rad), as the rotor march's.
const MAX_DRIFT_STRIDE: f64 = 0.05;
