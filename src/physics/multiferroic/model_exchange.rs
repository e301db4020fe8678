//! The motor as an ODE for Model Exchange: the importer's integrator advances the states, the
//! motor gives their derivatives, its outputs, an event indicator and the event update, and exact
//! partial derivatives of all of them.
//!
//! Continuous states: rotor angle `phi` and speed `omega` (section 3.2.2's rotor,
//! `I phi'' = tau_bar(psi - phi) + tau_load - c phi'`), and in the Gilbert option the onion's `psi`
//! and `theta` (see [`Motor::onion_relaxation_time`]).
//!
//! With the quasi-static onion, `psi` is not integrated: it sits at its branch's minimum of eq. 3.3
//! plus eq. 3.4, found from the stored onion angle by [`Landscape::follow`](super::onion::Landscape::follow), which never jumps to
//! another branch. The stored angle (an anchor on the branch) is a discrete state: refreshed along
//! the branch at completed integrator steps ([`Motor::me_follow_branch`]) and moved at events
//! ([`Motor::me_event_update`]). Where the branch's minimum vanishes (a fold: the curvature there
//! reaches zero) the event indicator [`MeEvaluation::fold_indicator`] changes sign; in event mode
//! the onion then settles downhill to the next minimum by the rule Co-Simulation uses
//! ([`Landscape::settle`](super::onion::Landscape::settle)). The schedule's direction is a discrete state too: it is read at the
//! time of the last event, so it changes only at its switches, which are time events.

use super::angles::turned_back;
use super::branch::Branch;
use super::{
    within_limits, Drive, Motor, MotorInputs, MotorOutputs, MotorState, OnionModel, MAX_ANGLE,
};

/// The Gilbert onion's integration windows after a jump of its drive ([`Motor::me_ringing`]):
/// precession periods per window (a few hundred CVode steps at its default tolerance, where 500
/// are allowed), envelope decay times covered (e^-25 ~ 1e-11, below any tolerance), and at most
/// this many windows per jump (a weakly damped onion gets longer windows).
pub const RINGING_WINDOW_PERIODS: f64 = 4.0;
pub const RINGING_RELAXATIONS: f64 = 25.0;
pub const MAX_RINGING_WINDOWS: f64 = 1000.0;

/// The rotor's inertial time in Model Exchange is at least this fraction of its overdamped
/// relaxation time `c / k` ([`Motor::me_inertia`]) ...
pub const INERTIAL_TIME_FRACTION: f64 = 1e-4;
/// ... and at least this long (s) where that fraction is longer: the time below which
/// `step_period` is not followed either.
pub const INERTIAL_TIME_FLOOR: f64 = 1e-9;

/// The Gilbert onion's fastest rate in Model Exchange is at most the inverse of this time (s)
/// ([`Motor::me_llg_rate`]), or of [`INERTIAL_TIME_FRACTION`] of the rotor's relaxation time, or
/// of [`ONION_ROTOR_FRACTION`] of the rotor's (Model Exchange) inertial time, where shorter.
pub const ONION_TIME_FLOOR: f64 = 1e-10;
/// The floored onion stays this much faster than the rotor's speed: a slowed precession near the
/// rotor's inertial time couples to it (a light bar, 0.31 ns, then exceeds FMPy's step budget).
pub const ONION_ROTOR_FRACTION: f64 = 0.1;

/// [`Motor::me_inertia`] from the bar's inertia, the drag and the alignment stiffness, computed
/// once when the motor is built.
pub(super) fn floored_inertia(inertia: f64, drag: f64, alignment_stiffness: f64) -> f64 {
    let relaxation = drag / alignment_stiffness.abs();
    let floor = INERTIAL_TIME_FLOOR.min(INERTIAL_TIME_FRACTION * relaxation);
    let floored = drag * floor;
    if floored.is_finite() {
        inertia.max(floored)
    } else {
        inertia
    }
}

/// The shortest `step_period` Model Exchange runs (s) ([`Motor::me_check_schedule`]).
pub const MIN_SCHEDULE_PERIOD: f64 = 1e-7;

/// Indices of the independent variables of an [`MeGradient`]: the four states (the last two only
/// in the Gilbert option) and the three real inputs of [`MotorInputs`].
pub mod by {
    pub const ROTOR_ANGLE: usize = 0;
    pub const ROTOR_SPEED: usize = 1;
    pub const ONION_ANGLE: usize = 2;
    pub const ONION_TILT: usize = 3;
    pub const STRAIN_DIRECTION: usize = 4;
    pub const STRESS: usize = 5;
    pub const LOAD_TORQUE: usize = 6;
    pub const COUNT: usize = 7;
}

/// Partial derivatives of one quantity with respect to the variables of [`by`].
pub type MeGradient = [f64; by::COUNT];

/// Everything Model Exchange reads at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeEvaluation {
    /// Time derivatives of (phi, omega, psi, theta); the onion's are 0 in the quasi-static option.
    pub derivatives: [f64; 4],
    pub outputs: MotorOutputs,
    /// The quasi-static onion's branch (`None` in the Gilbert option).
    pub branch: Option<Branch>,
    /// Event indicator: the branch's [`Branch::fold_distance`] over the alignment stiffness
    /// (dimensionless, 1 at alignment without stress); negative once the minimum has vanished.
    /// 1 in the Gilbert option, which has no folds.
    pub fold_indicator: f64,
}

/// Exact partials at one state, on the branch the evaluation takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MePartials {
    /// Of the time derivatives of (phi, omega, psi, theta).
    pub derivatives: [MeGradient; 4],
    pub torque: MeGradient,
    pub rotor_angle: MeGradient,
    pub rotor_speed: MeGradient,
    pub onion_angle: MeGradient,
    pub offset_angle: MeGradient,
    pub magnetostatic_energy: MeGradient,
    pub magnetoelastic_energy: MeGradient,
    pub applied_strain_direction: MeGradient,
}

/// `a * x + b * y` elementwise.
fn combine(a: f64, x: &MeGradient, b: f64, y: &MeGradient) -> MeGradient {
    std::array::from_fn(|i| a * x[i] + b * y[i])
}

fn unit(i: usize) -> MeGradient {
    let mut g = [0.0; by::COUNT];
    g[i] = 1.0;
    g
}

/// The state at which everything is evaluated: rotor, onion (solved or integrated) and drive.
struct Point {
    y: [f64; 4],
    drive: Drive,
    branch: Option<Branch>,
}

impl Motor {
    /// Number of continuous states: 2 (rotor), 4 with the Gilbert onion.
    pub fn me_state_count(&self) -> usize {
        if self.quasi_static() {
            2
        } else {
            4
        }
    }

    /// A Model Exchange state: checked as by [`Motor::validate_state`], except that the Gilbert
    /// onion's tilt may be any angle up to [`MAX_ANGLE`]. An importer's trial states may tilt far
    /// (CVode's first trial under OMSimulator's settings: -800 rad), and a refusal there stops
    /// the run (fmi2Error); the LLG rates are linear in the tilt (the film's shape anisotropy is
    /// quadratic in it, see [`Motor::onion_relaxation_time`]), so any finite tilt has finite
    /// derivatives, and the solution the integrator accepts stays small.
    pub fn me_validate_state(state: &MotorState) -> Result<(), String> {
        Self::validate_state(&MotorState {
            onion_tilt: 0.0,
            ..*state
        })?;
        within_limits(&[("onion_tilt", state.onion_tilt, MAX_ANGLE, "rad")])
    }

    /// The rotor's speed scale (rad/s): the terminal speed at the ring's peak torque against the
    /// rod drag, `max |tau_bar| / c` (Fig. 3.3a, section 3.2.2); infinite without drag. The rotor
    /// reaches it within a few inertial times `I / c` of a step of the schedule, so it is the
    /// scale of `rotor_speed` as a continuous state.
    pub fn terminal_speed(&self) -> f64 {
        self.ring_bar.max_torque().1.abs() / self.drag
    }

    /// The inertia Model Exchange integrates the rotor with (kg m^2): the bar's `I` where its
    /// inertial time `I / c` is at least `T = min(INERTIAL_TIME_FLOOR, INERTIAL_TIME_FRACTION c / k)`,
    /// else `c T`, which gives it that time.
    ///
    /// In `I w' = tau - c w` (section 3.2.2) the speed follows the overdamped speed `tau / c`
    /// with the lag `I / c`; the torque changes on the rotor's relaxation time `c / k` or slower
    /// (`k` the alignment stiffness, the steepest the rotor sees on a branch), or when the drive
    /// jumps. Where `I / c` is far below `c / k` (a viscous fluid, a light bar) the rotor is
    /// overdamped to within that lag, and the lag is far below any time the importer resolves,
    /// but its integrator must still resolve it at every jump of the drive: CVode under
    /// OMSimulator's settings (minimum step 1e-12 s) stops for Table 3.1's motor once it is
    /// below 24 to 48 ps. The floor keeps the overdamped limit and lets the speed relax on `T`
    /// instead. What it changes: the floored rotor's angle lags the overdamped one by `T w` at
    /// most, so by `T (tau_max + |load|) / c <= 1e-4 (tau_max + |load|) / k` (2.1e-5 rad for
    /// Table 3.1's ring and bar without load, whatever the fluid or density), and the lag
    /// relaxes on `c / k`; the bar's own rotor lags by `I / c < T` in the same way. Table 3.1's
    /// motor in water (`I / c` 2.2 ns, `c / k` 3.1 us) is not floored.
    pub fn me_inertia(&self) -> f64 {
        self.me_inertia
    }

    /// The rate per unit torque Model Exchange integrates the Gilbert onion with (1/(J s)), and its
    /// partial by the stress: the macrospin's `g` of [`Motor::onion_relaxation_time`] where the
    /// onion's fastest rate is at most `1 / T`, else the rate that makes it `1 / T`, with
    /// `T = min(ONION_TIME_FLOOR, INERTIAL_TIME_FRACTION c / k, ONION_ROTOR_FRACTION I_me / c)`.
    ///
    /// Linearized at a point of in-plane stiffness `K` (tilt stiffness `t`), the macrospin's
    /// rates are the eigenvalues of `g [[-alpha K, -t], [K, -alpha t]]`, at most
    /// `g L` with `L = alpha (K + t) + sqrt(K t (1 + alpha^2))`, `K` at most the alignment
    /// stiffness plus the magnetoelastic one at its steepest (`2 |E|`). After a jump of the drive
    /// the onion starts `D` (up to pi/2) from its new minimum with a second derivative of about
    /// `(g L)^2 D`; an integrator's first step (order 1) must then stay below
    /// `sqrt(2 tol / psi'')`: 0.8 ps for Table 3.1 at the schedule's first jump (`psi''` 3.4e20
    /// rad/s^2, tolerance 1e-4 rad), less at a larger stress or magnetostriction, a smaller `Ms`
    /// or a thicker film, where under OMSimulator's settings (minimum step 1e-12 s) CVode stops. Scaling `g` alone rescales the onion's time: its path
    /// (the precession, which minimum it reaches) is the same whatever `g`, since the rotor
    /// barely turns within it. What it changes: the ringing lasts `g / g_me` times longer, so the
    /// torque on the rotor differs within it by at most `k D` over an envelope decay time
    /// `tau_me` of the floored onion (and `tau` of the real one), and the rotor angle by at most
    /// `D (tau_me + tau) / (c / k)` after each jump (the impulse over the drag), relaxing on
    /// `c / k`. For Table 3.1 at 2e8 Pa the
    /// onion is slowed 5.2 times (`tau_me` = 2.1 ns): after Fig. 3.3b's jump to -45 degrees at
    /// most 3.3e-4 rad (measured against the macrospin at its own rate: 2.2e-5 rad).
    pub fn me_llg_rate(&self, stress: f64) -> (f64, f64) {
        let alpha = self.params.gilbert_damping;
        let t = self.tilt_stiffness;
        let e = self.magnetoelastic_per_stress * stress;
        let k = self.largest_in_plane_stiffness(stress);
        let root = (k * t * (1.0 + alpha * alpha)).sqrt();
        let largest = alpha * (k + t) + root;
        let floor = ONION_TIME_FLOOR
            .min(INERTIAL_TIME_FRACTION * self.drag / self.alignment_stiffness.abs())
            .min(ONION_ROTOR_FRACTION * self.me_inertia / self.drag);
        let floored = 1.0 / (floor * largest);
        if !(floored.is_finite() && floored < self.llg_rate) {
            return (self.llg_rate, 0.0);
        }
        // d largest / d stress, through K = |k0| + 2 |m sigma| (one-sided at zero stress).
        let dk = if e == 0.0 {
            0.0
        } else {
            2.0 * e.signum() * self.magnetoelastic_per_stress
        };
        // d root / dK = root / (2 K); root is 0 where K is (no in-plane stiffness at all).
        let droot = if k > 0.0 { 0.5 * root / k } else { 0.0 };
        let dlargest = (alpha + droot) * dk;
        (floored, -floored * dlargest / largest)
    }

    /// The strain direction and stress in effect at `time` (the inputs', or the schedule's there).
    pub fn me_drive(&self, inputs: &MotorInputs, time: f64) -> [f64; 2] {
        let d = self.drive_at(inputs, time);
        [d.direction, d.stress]
    }

    /// The Gilbert onion's ringing after a jump of its drive at stress `stress`: the length of
    /// one integration window and of the whole ringing (s), or `None` when it does not ring (the
    /// quasi-static option, no damping, or an overdamped onion).
    ///
    /// Linearized about its minimum (in-plane stiffness `k`, tilt stiffness `t = mu0 Ms^2 V`), the
    /// macrospin of [`Motor::onion_relaxation_time`] is a damped oscillator with eigenvalues
    /// `g (-alpha (k + t) / 2 +- i sqrt(k t (1 + alpha^2)))` to first order: for Table 3.1 a
    /// 0.14 ns precession whose envelope decays in 0.41 ns, 86 degrees from the negative real
    /// axis. A variable-order BDF (CVode) must resolve that ringing to its tolerance, some
    /// hundreds of steps within a few nanoseconds of every jump, more than FMPy's CVode allows
    /// between two output points (500). Model Exchange therefore announces time events every
    /// [`RINGING_WINDOW_PERIODS`] precession periods until the envelope has decayed by
    /// `exp(-RINGING_RELAXATIONS)`: each ends the importer's integrator call, which then starts
    /// the next window afresh. Nothing changes at these events.
    pub fn me_ringing(&self, stress: f64) -> Option<(f64, f64)> {
        let alpha = self.params.gilbert_damping;
        if self.quasi_static() || alpha <= 0.0 {
            return None;
        }
        let k = self.largest_in_plane_stiffness(stress);
        let rate = self.me_llg_rate(stress).0;
        let precession = rate * (k * self.tilt_stiffness * (1.0 + alpha * alpha)).sqrt();
        let window = RINGING_WINDOW_PERIODS * 2.0 * std::f64::consts::PI / precession;
        let ringing = RINGING_RELAXATIONS * self.onion_relaxation_time() * self.llg_rate / rate;
        let window = window.max(ringing / MAX_RINGING_WINDOWS);
        (window.is_finite() && window > 0.0 && ringing.is_finite() && window < ringing)
            .then_some((window, ringing))
    }

    /// The onion's largest in-plane stiffness (N m/rad) at `stress`: the ring-bar spring at
    /// alignment plus the magnetoelastic one at its steepest (`2 |E|`).
    fn largest_in_plane_stiffness(&self, stress: f64) -> f64 {
        self.alignment_stiffness.abs() + 2.0 * (self.magnetoelastic_per_stress * stress).abs()
    }

    /// Refuses a schedule faster than [`MIN_SCHEDULE_PERIOD`] in Model Exchange, where every
    /// switch is a time event that ends the importer's integrator call and restarts it (measured
    /// through FMPy under OMSimulator's settings: 0.9 ms of wall time per switch with the
    /// quasi-static onion, 4 to 7 ms with the Gilbert onion's windows, so 15 minutes to 2 hours
    /// per simulated millisecond at the declared minimum, 1 ns). Below it the schedule switches
    /// within a hundred of the rotor's inertial-time floor ([`INERTIAL_TIME_FLOOR`]) and within
    /// the Gilbert onion's floored ringing ([`Motor::me_llg_rate`], 53 ns for Table 3.1), which
    /// Model Exchange does not resolve, and the rotor (relaxation time 3.1 us for Table 3.1)
    /// barely turns: 2.6 mrad in 100 us at 10 ns. Co-Simulation runs these periods.
    pub fn me_check_schedule(&self, inputs: &MotorInputs) -> Result<(), String> {
        match inputs.schedule.get() {
            Some(s) if s.step_period < MIN_SCHEDULE_PERIOD => Err(format!(
                "step_period = {:e} s is below {MIN_SCHEDULE_PERIOD:e} s, the shortest Model \
                 Exchange runs: every switch of the schedule is a time event, and faster than \
                 that the rotor cannot follow it; run Co-Simulation for faster schedules",
                s.step_period
            )),
            _ => Ok(()),
        }
    }

    /// The next switch of the schedule after the one in effect at `schedule_time` (the time of the
    /// last event), if a schedule runs: the next time event.
    pub fn me_next_time_event(&self, inputs: &MotorInputs, schedule_time: f64) -> Option<f64> {
        inputs
            .schedule
            .get()
            .map(|s| s.next_switch_after(schedule_time))
    }

    fn me_point(
        &self,
        state: &MotorState,
        inputs: &MotorInputs,
        schedule_time: f64,
    ) -> Result<Point, String> {
        self.validate_inputs(inputs)?;
        Self::me_validate_state(state)?;
        let drive = self.drive_at(inputs, schedule_time);
        let speed = if drive.locked { 0.0 } else { state.rotor_speed };
        let mut y = [
            state.rotor_angle,
            speed,
            state.onion_angle,
            state.onion_tilt,
        ];
        let branch = self.quasi_static().then(|| {
            self.landscape(y[0], drive.direction, drive.stress)
                .follow(state.onion_angle)
        });
        if let Some(b) = branch {
            y[2] = b.angle();
            y[3] = 0.0;
        }
        Ok(Point { y, drive, branch })
    }

    /// Derivatives, outputs and the fold indicator at `state` (its time is not used; the schedule
    /// is read at `schedule_time`, the time of the last event). Nothing is stored.
    pub fn me_evaluate(
        &self,
        state: &MotorState,
        inputs: &MotorInputs,
        schedule_time: f64,
    ) -> Result<MeEvaluation, String> {
        let Point {
            y,
            drive: d,
            branch,
        } = self.me_point(state, inputs, schedule_time)?;
        let mut derivatives = [0.0; 4];
        let beta = y[2] - y[0];
        if !d.locked {
            derivatives[0] = y[1];
            derivatives[1] =
                (self.ring_bar.torque(beta) + d.load - self.drag * y[1]) / self.me_inertia();
        }
        if self.params.onion_model == OnionModel::Gilbert {
            let (g, a, t) = (
                self.me_llg_rate(d.stress).0,
                self.params.gilbert_damping,
                self.tilt_stiffness,
            );
            let e = self.magnetoelastic_per_stress * d.stress;
            let grad =
                self.ring_bar.torque(beta) + e * turned_back(2.0 * (y[2] - d.direction)).sin();
            derivatives[2] = g * (-t * y[3] - a * grad);
            derivatives[3] = g * (grad - a * t * y[3]);
        }
        let fold_indicator = match branch {
            Some(b) => {
                let m = self
                    .landscape(y[0], d.direction, d.stress)
                    .third_derivative_bound();
                b.fold_distance(m) / self.alignment_stiffness.abs()
            }
            None => 1.0,
        };
        Ok(MeEvaluation {
            derivatives,
            outputs: self.outputs_at(&y, &d),
            branch,
            fold_indicator,
        })
    }

    /// Completed integrator step: moves the stored onion angle along its branch to the present
    /// minimum, so that the next evaluations start next to it. Past a fold (the event is due) the
    /// anchor stays. Nothing else changes.
    pub fn me_follow_branch(
        &self,
        state: &mut MotorState,
        inputs: &MotorInputs,
        schedule_time: f64,
    ) -> Result<(), String> {
        if let Some(Branch::Minimum { angle, .. }) =
            self.me_point(state, inputs, schedule_time)?.branch
        {
            state.onion_angle = angle;
        }
        Ok(())
    }

    /// Event mode at `state.time`: the schedule's direction becomes the one in effect then, the
    /// quasi-static onion settles downhill from where it was (the Co-Simulation rule: at a fold it
    /// moves to the next minimum, else it stays on its branch), a locked rotor stands still.
    /// Returns whether a continuous state changed (only a locked rotor's speed can).
    pub fn me_event_update(
        &self,
        state: &mut MotorState,
        inputs: &MotorInputs,
    ) -> Result<bool, String> {
        self.validate_inputs(inputs)?;
        Self::me_validate_state(state)?;
        let d = self.drive_at(inputs, state.time);
        let mut y = [
            state.rotor_angle,
            state.rotor_speed,
            state.onion_angle,
            state.onion_tilt,
        ];
        self.constrain(&mut y, &d, None);
        let changed = y[1] != state.rotor_speed;
        state.rotor_speed = y[1];
        state.onion_angle = y[2];
        Ok(changed)
    }

    /// Exact partials of the derivatives and outputs with respect to the states and inputs at
    /// `state`, on the branch [`Self::me_evaluate`] takes: the quasi-static onion's by the
    /// implicit function theorem on `dU/dpsi = 0` at its minimum (on `d2U/dpsi2 = 0` at the ghost
    /// past a fold, the extension evaluated until the event fires). At the fold itself the
    /// one-sided partials are infinite; the curvature is then floored at 1e-9 of the alignment
    /// stiffness so they stay finite.
    pub fn me_partials(
        &self,
        state: &MotorState,
        inputs: &MotorInputs,
        schedule_time: f64,
    ) -> Result<MePartials, String> {
        let Point {
            y,
            drive: d,
            branch,
        } = self.me_point(state, inputs, schedule_time)?;
        let scheduled = inputs.schedule.get().is_some();
        // The drive's direction, stress (and the energy scale E = m sigma) by the variables.
        let direction = if scheduled {
            [0.0; by::COUNT]
        } else {
            unit(by::STRAIN_DIRECTION)
        };
        let stress = if scheduled {
            [0.0; by::COUNT]
        } else {
            unit(by::STRESS)
        };
        let m = self.magnetoelastic_per_stress;
        let e = m * d.stress;
        let phi = unit(by::ROTOR_ANGLE);
        let psi_now = y[2];
        let beta = psi_now - y[0];
        let k_bar = self.ring_bar.stiffness(beta);
        let (s2, c2) = turned_back(2.0 * (psi_now - d.direction)).sin_cos();
        let k_me = 2.0 * e * c2;
        let floor = 1e-9 * self.alignment_stiffness.abs();
        let psi = match branch {
            // F(psi, phi, E, gamma) = 0 with F = dU/dpsi at the minimum, d2U/dpsi2 at the ghost:
            // dpsi = -(F_phi dphi + F_E dE + F_gamma dgamma) / F_psi.
            Some(b) => {
                let (f_psi, f_phi, f_e, f_gamma) = match b {
                    Branch::Minimum { .. } => (k_bar + k_me, -k_bar, s2, -k_me),
                    Branch::Vanished { .. } => {
                        let slope = self.ring_bar.stiffness_slope(beta);
                        (slope - 4.0 * e * s2, -slope, 2.0 * c2, 4.0 * e * s2)
                    }
                };
                let f_psi = if f_psi.abs() < floor {
                    floor.copysign(f_psi)
                } else {
                    f_psi
                };
                let de = stress.map(|x| m * x);
                std::array::from_fn(|i| {
                    -(f_phi * phi[i] + f_e * de[i] + f_gamma * direction[i]) / f_psi
                })
            }
            None => unit(by::ONION_ANGLE),
        };
        let offset = combine(1.0, &psi, -1.0, &phi);
        let torque = offset.map(|x| k_bar * x);
        let speed = if d.locked {
            [0.0; by::COUNT]
        } else {
            unit(by::ROTOR_SPEED)
        };
        let mut derivatives = [[0.0; by::COUNT]; 4];
        if !d.locked {
            derivatives[0] = speed;
            let (i, c) = (self.me_inertia(), self.drag);
            let load = unit(by::LOAD_TORQUE);
            derivatives[1] = std::array::from_fn(|j| (torque[j] + load[j] - c * speed[j]) / i);
        }
        if self.params.onion_model == OnionModel::Gilbert {
            let ((g, dg), a, t) = (
                self.me_llg_rate(d.stress),
                self.params.gilbert_damping,
                self.tilt_stiffness,
            );
            // grad = tau(beta) + E sin(2 (psi - gamma)); the rate g depends on the stress.
            let grad: MeGradient = std::array::from_fn(|j| {
                torque[j] + m * stress[j] * s2 + k_me * (psi[j] - direction[j])
            });
            let grad_now = self.ring_bar.torque(beta) + e * s2;
            let (psi_rate, tilt_rate) = (-t * y[3] - a * grad_now, grad_now - a * t * y[3]);
            let tilt = unit(by::ONION_TILT);
            derivatives[2] = std::array::from_fn(|j| {
                g * (-t * tilt[j] - a * grad[j]) + dg * stress[j] * psi_rate
            });
            derivatives[3] = std::array::from_fn(|j| {
                g * (grad[j] - a * t * tilt[j]) + dg * stress[j] * tilt_rate
            });
        }
        let tau = self.ring_bar.torque(beta);
        let sin2 = turned_back(psi_now - d.direction).sin().powi(2);
        Ok(MePartials {
            derivatives,
            torque,
            rotor_angle: phi,
            rotor_speed: speed,
            onion_angle: psi,
            offset_angle: offset,
            magnetostatic_energy: offset.map(|x| tau * x),
            magnetoelastic_energy: std::array::from_fn(|j| {
                m * sin2 * stress[j] + e * s2 * (psi[j] - direction[j])
            }),
            applied_strain_direction: direction,
        })
    }
}
