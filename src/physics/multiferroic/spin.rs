//! A rotor that turns many times within a step: the ring's torque averaged over the onion's
//! hysteresis cycle, with the periodic deviation from the mean motion added back (the method of
//! averaging to first order in `tau_max / |load|`, its secular drift to second order).

use super::cycle::{OnionCycle, Wobble};
use super::{Drive, Motor, StepRun};
use std::f64::consts::PI;

/// What [`Motor::spin`] did.
enum Spin {
    /// Not near enough its terminal speed yet: the integrator goes on.
    NotYet,
    /// The averaged spin does not apply in this step.
    Failed,
    Ended(super::Vector),
}

impl Motor {
    /// A rotor driven by a load torque far beyond anything the ring can exert, turning many times
    /// within the segment. The ring's torque, periodic in the rotor angle along the onion's
    /// hysteresis cycle, is then a small perturbation `epsilon = tau_max / |load|` of a uniform
    /// spin (`tau_max` a bound of eq. 3.3's torque). With `phi = theta + delta(theta)` and
    /// `omega = Omega + u(theta)` the mean angle and speed obey
    /// `I Omega' = load + <tau> + <tau' delta> - c Omega` (section 3.2.2's rotor averaged over a
    /// turn), solved exactly over the segment, where `<tau>` is the ring's mean torque over the
    /// cycle (the energy its snaps dissipate per turn over 2 pi, see [`Self::onion_cycle`]) and
    /// `<tau' delta>` the second-order drift; `u` is the periodic solution of
    /// `I Omega du/dtheta + c u = tau - <tau>` and `delta' = u / Omega` ([`Self::wobble`]).
    /// The deviation is taken off at the start and added back at the end, so the rotor angle and
    /// speed stay right at any phase. The onion ends on its cycle at the end angle.
    ///
    /// Applies (else `false`) with a quasi-static onion and a free rotor, in either of:
    /// - `epsilon <= 0.5 tolerance`, also from rest: the speed's rise through the first turns
    ///   leaves a phase error of about `epsilon` (against a fine RK4 from rest, Table 3.1:
    ///   8.5e-8, 1.9e-6 and 1.1e-5 rad at `epsilon` = 1e-7, 1e-6 and 1e-5, i.e. loads of 1e-10,
    ///   1e-11 and 1e-12 N m, where the error-controlled integrator was 0.12, 0.92 and 0.43 rad
    ///   off), and later the periodic part moves it by at most `tau_max / (I omega^2)`;
    /// - with drag, `epsilon <= MAX_SPIN_EPSILON`, the rotor already turning with the load at
    ///   least [`MIN_SPIN_TURNS`] turns within the segment, near enough its terminal speed
    ///   (the deviation's amplitude times the speed's relative distance to it below `tol / 10`),
    ///   and the third-order drift `epsilon^3` times the angle turned below `tol / 10`. Before
    ///   that (a rotor starting from rest), the error-controlled integrator resolves the few
    ///   turns of its speed's rise.
    ///
    /// On a schedule, the spin goes on through the following switches while the cycle each
    /// segment's onion follows is known and the periodic deviation's phase jumps at the switches
    /// stay within a tenth of the tolerance ([`Self::periods_ahead`]).
    ///
    /// Resolving every turn took the whole substep budget here (20,000 substeps, 11-40 ms per
    /// 1 us step for loads of 1e-14 to 1e-10 N m on Table 3.1).
    pub(super) fn advance_spinning(&self, run: &mut StepRun, d: &Drive, segment_end: f64) -> bool {
        if self.advance_unstrained(run, d) {
            return true;
        }
        if self.advance_drifting(run, d, segment_end) {
            return true;
        }
        let (i, c) = (self.inertia, self.drag);
        let load = d.load;
        if run.spin_failed || d.locked || !self.quasi_static() || load == 0.0 {
            return false;
        }
        let dir = load.signum();
        let tol = self.params.tolerance;
        let bound = self.torque_bound();
        let epsilon = bound / load.abs();
        let h = segment_end - run.t;
        let speed = dir * run.y[1];
        // From rest, or once the integrator has had to force a substep beyond the tolerance
        // while the rotor speeds up (the spin from there is far closer to the resolved motion:
        // see the tests), as long as the periodic part stays small against the load.
        let resolved_free = speed >= 0.0
            && (epsilon <= LOAD_DOMINATED * tol || (run.limited && epsilon <= MAX_SPIN_EPSILON));
        // Near enough its terminal speed: the deviation (at most `2 tau_max / (omega
        // sqrt(c^2 + I^2 omega^2))`) times the mean speed's relative distance to the terminal
        // one below tol / 10 (here the speed's own deviation, up to `2 epsilon`, allowed for;
        // checked precisely in `spin`); a rotor still speeding up from rest is resolved until
        // then.
        let corrected = c > 0.0
            && speed > 0.0
            && epsilon <= MAX_SPIN_EPSILON
            && h * speed >= MIN_SPIN_TURNS * 2.0 * PI
            && 2.0 * bound / (speed * c.hypot(i * speed))
                * ((1.0 - load.abs() / (c * speed)).abs() - 2.0 * epsilon).max(0.0)
                <= 0.1 * tol;
        if !(resolved_free || corrected) {
            return false;
        }
        // Within a step only the schedule's strain direction changes (the load and the stress
        // are held): the cycle marched for one segment, turned with the strain, serves the next
        // when the onion is on it (after a switch it may sit on the other branch of the
        // bistable stretch until the next fold; then the cycle is marched again from the state).
        if let Some((direction, cycle)) = &mut run.spin_cycle {
            if *direction != d.direction {
                cycle.rotate(d.direction - *direction);
                *direction = d.direction;
            }
            if !cycle.holds(self, &run.y, dir, d) {
                run.spin_cycle = None;
            }
        }
        if run.spin_cycle.is_none() {
            // The march costs at least SPIN_CYCLE_WEIGHT substeps of the budget, or is not
            // started; it is charged by its settles.
            let spent = run.attempts.saturating_add(run.extra_cost);
            if spent.saturating_add(SPIN_CYCLE_WEIGHT) > self.params.max_substeps {
                run.spin_failed = true;
                return false;
            }
            let mut settles = 0;
            let cycle = match self.canonical_cycle(&run.y, d, dir, &mut settles) {
                Some(cycle) => Some(cycle),
                None => self.onion_cycle(&run.y, d, dir, &mut settles),
            };
            run.extra_cost = run
                .extra_cost
                .saturating_add(settles.div_ceil(SETTLES_PER_SUBSTEP));
            match cycle {
                Some(cycle) => run.spin_cycle = Some((d.direction, cycle)),
                None => {
                    run.spin_failed = true;
                    return false;
                }
            }
        }
        let Some((direction, cycle)) = run.spin_cycle.take() else {
            return false;
        };
        if let Some((end, end_drive, end_cycle)) = self.periods_ahead(run, &cycle, d, segment_end) {
            let y = self.spin(
                &run.y,
                &cycle,
                (&end_cycle, &end_drive),
                d,
                end - run.t,
                !resolved_free,
            );
            if let Spin::Ended(y) = y {
                run.y = y;
                run.t = end;
                run.spin_cycle = Some((end_drive.direction, end_cycle));
                run.settled = false;
                run.attempts = run.attempts.saturating_add(1);
                return true;
            }
        }
        let spun = self.spin(&run.y, &cycle, (&cycle, d), d, h, !resolved_free);
        run.spin_cycle = Some((direction, cycle));
        match spun {
            Spin::NotYet => false,
            Spin::Failed => {
                run.spin_failed = true;
                false
            }
            Spin::Ended(y) => {
                run.y = y;
                run.t = segment_end;
                run.settled = false;
                run.attempts = run.attempts.saturating_add(1);
                self.spin_held_periods(run, d, !resolved_free);
                true
            }
        }
    }

    /// After a segment of the averaged spin, the step's following segments of the schedule, one
    /// by one, where the strain holds the onion at an end of its axis
    /// ([`Self::strain_held_turn`]): the onion then lands at every switch on the cycle turned by
    /// its own turn there, so each segment is the spin on that cycle
    /// ([`Self::spin_rotor`], the periodic deviation taken off and added back at the switches as
    /// the segment-by-segment spin does) without the settles that checked the onion was on it and
    /// placed it at every switch: the onion is placed once, at the end. Stops where a segment's
    /// spin does not apply (the loop of [`Motor::step`] goes on from there) or the budget, a
    /// substep a segment as before, is spent.
    fn spin_held_periods(&self, run: &mut StepRun, d: &Drive, correct_start: bool) {
        let Some(s) = run.schedule else {
            return;
        };
        let Some(turn) = self.strain_held_turn(d, s.step_angle) else {
            return;
        };
        let Some((_, mut cycle)) = run.spin_cycle.take() else {
            return;
        };
        let (t0, attempts0) = (run.t, run.attempts);
        let mut drive = *d;
        let mut rotor = [run.y[0], run.y[1]];
        while run.t < run.t_end
            && run.attempts.saturating_add(run.extra_cost) < self.params.max_substeps
        {
            let applied = s.direction(run.t);
            drive = Drive {
                direction: super::reduced_direction(applied),
                applied_direction: applied,
                ..drive
            };
            cycle.rotate(turn);
            let end = s.next_switch_after(run.t).min(run.t_end);
            let y = [rotor[0], rotor[1], 0.0, 0.0];
            match self.spin_rotor(&y, &cycle, &cycle, &drive, end - run.t, correct_start) {
                Ok(r) => rotor = r,
                Err(_) => break,
            }
            run.t = end;
            run.attempts = run.attempts.saturating_add(1);
        }
        if run.t == t0 {
            run.spin_cycle = Some((drive.direction, cycle));
            return;
        }
        match self.onion_on_cycle(&cycle, &drive, rotor[0], d.load.signum()) {
            Some(psi) => {
                run.y = [rotor[0], rotor[1], psi, 0.0];
                run.spin_cycle = Some((drive.direction, cycle));
                run.angles = None;
            }
            None => (run.t, run.attempts) = (t0, attempts0),
        }
    }

    /// The state `y` advanced by `h` on the averaged spin of `cycle`, with the periodic deviation
    /// taken off at the start (`correct_start`) and added back at the end on `end`'s cycle and
    /// drive (those of the start, or of a later segment of the schedule, see
    /// [`Self::periods_ahead`]).
    fn spin(
        &self,
        y: &super::Vector,
        cycle: &OnionCycle,
        end: (&OnionCycle, &Drive),
        d: &Drive,
        h: f64,
        correct_start: bool,
    ) -> Spin {
        let (end_cycle, end_drive) = end;
        let dir = d.load.signum();
        match self.spin_rotor(y, cycle, end_cycle, d, h, correct_start) {
            Ok([phi, omega]) => match self.onion_on_cycle(end_cycle, end_drive, phi, dir) {
                Some(psi) => Spin::Ended([phi, omega, psi, 0.0]),
                None => Spin::Failed,
            },
            Err(spin) => spin,
        }
    }

    /// The rotor's angle and speed of [`Self::spin`], without the onion.
    fn spin_rotor(
        &self,
        y: &super::Vector,
        cycle: &OnionCycle,
        end_cycle: &OnionCycle,
        d: &Drive,
        h: f64,
        correct_start: bool,
    ) -> Result<[f64; 2], Spin> {
        let (i, c) = (self.inertia, self.drag);
        let dir = d.load.signum();
        let tol = self.params.tolerance;
        let speed = dir * y[1];
        // In the direction of motion, from the cycle's reference angle.
        let s_of = |phi: f64| dir * (phi - cycle.turns - cycle.rotor);
        let force = d.load.abs() + cycle.work / (2.0 * PI);
        // The mean motion at constant force over `h`: advance and end speed.
        let mean_motion = |omega0: f64, force: f64| -> (f64, f64) {
            if c > 0.0 {
                let rate = c / i;
                let terminal = force / c;
                // 1 - exp(-h c / I) without cancellation.
                let approach = -(-h * rate).exp_m1();
                (
                    terminal * h + (omega0 - terminal) * approach / rate,
                    terminal + (omega0 - terminal) * (1.0 - approach),
                )
            } else {
                (omega0 * h + 0.5 * force / i * h * h, omega0 + force / i * h)
            }
        };
        // The deviation at a mean speed this close to the terminal one is the terminal one's
        // within tol / 100 (it and its drift scale with the speed's inverse).
        let near_terminal = |omega: f64| {
            cycle.terminal.as_ref().filter(|w| {
                let relative = (1.0 - omega / w.omega).abs();
                (w.amplitude() + h * w.drift_force.abs() / c) * relative <= 0.01 * tol
            })
        };
        let (mut theta, mut speed0) = (y[0], speed);
        if correct_start {
            // The error against resolved integration (see the tests) at the speed it will spin
            // at: the second-order periodic terms left out, `amplitude (epsilon + 1e-3)`, and the
            // third-order drift, `epsilon^3` per radian turned.
            let computed;
            let terminal = match &cycle.terminal {
                Some(w) => w,
                None => {
                    computed = self.wobble(cycle, force / c);
                    &computed
                }
            };
            let amplitude = terminal.amplitude();
            let epsilon = cycle
                .torque
                .iter()
                .fold(0.0, |a: f64, t| a.max((t.1 - terminal.mean).abs()))
                / force;
            let turned = h * force / c;
            if amplitude * (epsilon + 1e-3) + epsilon.powi(3) * turned > tol {
                return Err(Spin::Failed);
            }
            // The deviation's dependence on the mean speed, neglected while that approaches its
            // terminal value, stays below tol / 10.
            let computed;
            let start = match near_terminal(speed) {
                Some(w) => w,
                None => {
                    computed = self.wobble(cycle, speed);
                    &computed
                }
            };
            let (delta, u) = start.at(cycle, s_of(y[0]), c);
            theta -= dir * delta;
            speed0 -= u;
            if start.amplitude() * (1.0 - force / (c * speed0)).abs() > 0.1 * tol {
                return Err(Spin::NotYet);
            }
        }
        let (mut advance, mut omega) = mean_motion(speed0, force);
        let mut end_wobble = None;
        if c > 0.0 && omega > 0.0 {
            let end = match near_terminal(omega) {
                Some(w) => std::borrow::Cow::Borrowed(w),
                None => std::borrow::Cow::Owned(self.wobble(cycle, omega)),
            };
            (advance, omega) = mean_motion(speed0, force + end.drift_force);
            end_wobble = Some(end);
        }
        theta += dir * advance;
        let (mut phi, mut omega) = (theta, dir * omega);
        let s_of_end = |phi: f64| dir * (phi - end_cycle.turns - end_cycle.rotor);
        if let Some(end) = &end_wobble {
            let (delta, u) = end.at(end_cycle, s_of_end(theta), c);
            phi += dir * delta;
            omega += dir * u;
        }
        if !(phi.is_finite() && phi.abs() <= super::MAX_ANGLE && omega.is_finite()) {
            return Err(Spin::Failed);
        }
        Ok([phi, omega])
    }

    /// The onion on `cycle` (of the drive `d`) at the rotor angle `phi`: whole turns shift it by
    /// the winding, the rest is settled from the cycle's sample below it.
    fn onion_on_cycle(&self, cycle: &OnionCycle, d: &Drive, phi: f64, dir: f64) -> Option<f64> {
        let from_cycle = phi - cycle.turns - cycle.rotor;
        let whole = (dir * from_cycle / (2.0 * PI)).floor();
        let rest = from_cycle - dir * whole * 2.0 * PI;
        let onion = cycle.onion_at(self, dir * rest, dir, d);
        let psi = onion + cycle.turns + cycle.onion_turns + cycle.winding * dir * whole * 2.0 * PI;
        (psi.is_finite() && psi.abs() <= super::MAX_ANGLE).then_some(psi)
    }

    /// The periodic deviation from the mean motion at mean speed `omega` (> 0, in the direction
    /// of motion), for a drag `c > 0`: `I omega du/ds + c u = tau~(s)` with `tau~` the cycle's
    /// torque less its mean, solved exactly for `tau~` linear between samples (an exponential
    /// integrator over the phase, decay `kappa = c / (I omega)` per radian) and made periodic by
    /// `u(0) = u_1(2 pi) / (1 - exp(-2 pi kappa))` (`u_1` started from 0). `delta` integrates
    /// `u / omega` (trapezoid) less its mean.
    pub(super) fn wobble(&self, cycle: &OnionCycle, omega: f64) -> Wobble {
        let (i, c) = (self.inertia, self.drag);
        let tau = &cycle.torque;
        let n = tau.len();
        let mut mean = 0.0;
        for w in tau.windows(2) {
            mean += 0.5 * (w[1].0 - w[0].0) * (w[0].1 + w[1].1);
        }
        mean /= 2.0 * PI;
        let mut wobble = Wobble {
            angle: vec![0.0; n],
            speed: vec![0.0; n],
            drift_force: 0.0,
            omega,
            kappa: c / (i * omega),
            mean,
        };
        let sweep = |w: &mut Wobble, u0: f64| {
            w.speed[0] = u0;
            for j in 1..n {
                let (e, a, b) = w.stride(tau[j].0 - tau[j - 1].0, c);
                w.speed[j] = e * w.speed[j - 1] + a * (tau[j - 1].1 - mean) + b * (tau[j].1 - mean);
            }
        };
        sweep(&mut wobble, 0.0);
        let period_decay = -(-2.0 * PI * wobble.kappa).exp_m1();
        let periodic_start = wobble.speed[n - 1] / period_decay;
        sweep(&mut wobble, periodic_start);
        let (speed, angle) = (&wobble.speed, &mut wobble.angle);
        let (mut angle_mean, mut drift) = (0.0, 0.0);
        for j in 1..n {
            let h = tau[j].0 - tau[j - 1].0;
            angle[j] = angle[j - 1] + 0.5 * h * (speed[j - 1] + speed[j]) / omega;
            angle_mean += 0.5 * h * (angle[j - 1] + angle[j]);
            drift +=
                0.5 * h * ((tau[j - 1].1 - mean) * speed[j - 1] + (tau[j].1 - mean) * speed[j]);
        }
        angle_mean /= 2.0 * PI;
        for a in angle.iter_mut() {
            *a -= angle_mean;
        }
        wobble.drift_force = -drift / (2.0 * PI * omega);
        wobble
    }

    /// An upper bound of eq. 3.3's torque on the bar (N m): `K a r (1/(r - a)^3 + 1/(r + a)^3)`.
    pub(super) fn torque_bound(&self) -> f64 {
        let rb = &self.ring_bar;
        let (a, r) = (rb.bar_charge_radius, rb.wall_radius);
        (rb.coupling * a * r * ((r - a).powi(-3) + (r + a).powi(-3))).abs()
    }
}

/// The regime of [`Motor::advance_spinning`] from rest: `tau_max / |load|` at most this times the
/// tolerance.
const LOAD_DOMINATED: f64 = 0.5;
/// The corrected regime of [`Motor::advance_spinning`]: `tau_max / |load|` at most this, and at
/// least this many turns within the segment (fewer cost less resolved than the cycle's march).
const MAX_SPIN_EPSILON: f64 = 0.05;
const MIN_SPIN_TURNS: f64 = 2.0;
/// The onion's cycle ([`Motor::onion_cycle`], two turns of 126 strides with their settles, about
/// 25 us in release) counts as at least this many quasi-static substeps (about 0.32 us each) in
/// `max_substeps`, so that the budget bounds a step that marches it again at every switch of a
/// fast schedule (at 40, such steps took up to 9.6 ms with the budget at its declared maximum).
pub(super) const SPIN_CYCLE_WEIGHT: u32 = 80;
/// Settles of the quasi-static onion per substep of the budget: the cycle's march of about 320
/// settles costs about 80 substeps (about 0.08 us a settle against 0.32 us a substep). Marches
/// (the cycle's, the drifting onion's, the overdamped rotor's) are charged by their settles.
pub(super) const SETTLES_PER_SUBSTEP: u32 = 4;
