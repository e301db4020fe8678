//! A Gilbert onion on a fast schedule whose ring barely couples it to the rotor: in the strain's
//! frame its periods repeat, while the rotor follows load and drag alone (see
//! [`Motor::skip_onion_periods`]).

use super::{Motor, MotorInputs, StepRun, SteppingSchedule};
use std::f64::consts::PI;

/// Units in the last place of the onion's angle allowed beside the tolerance when periods are
/// compared: an unwrapped angle of many turns carries that much rounding from every substep.
const ROUNDING_ULPS: f64 = 64.0;

/// The decay, `e^{-lambda t}`, an onion placed on its quasi-static branch must have undergone
/// before it is compared at another such placement (see [`Motor::snaps_forgotten`]).
const SNAP_DECAY: f64 = 1e-2;

#[cfg(test)]
thread_local! {
    /// Periods skipped by [`Motor::skip_onion_periods`] on this thread (for tests).
    pub(super) static SKIPS: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

impl Motor {
    /// Takes the rest of the step's whole periods of the schedule at once when the Gilbert
    /// onion repeats in the strain's frame and eq. 3.3's ring-bar torque is negligible.
    ///
    /// Without the ring-bar torque the onion's equations (eq. 3.4's magnetoelastic term and
    /// the shape anisotropy) depend on `psi - gamma` and the tilt alone, and the rotor follows
    /// `I phi'' = load - c phi'`, exactly solved ([`Self::drift_response`]). So once three
    /// consecutive whole periods have ended with the same onion offset from their strain and
    /// the same tilt (within `tolerance / 100`, then `tolerance / 1000`), every later period
    /// repeats the last one turned by `step_angle`; two, within `tolerance / 1000`, where the
    /// onion ended both on its quasi-static branch (relaxed: the period that follows depends
    /// on that offset alone) and had forgotten the first placement ([`Self::snaps_forgotten`]).
    /// This is where a schedule turns the strain
    /// faster than the rotor can follow (by angles that never repeat, so the rotor never
    /// comes back to the same place relative to the strain, as
    /// [`Self::skip_repeated_periods`] needs) while the onion settles or rings down within a
    /// few switches: every switch was resolved, about 1.7 us each, 1,000 per 1 us step of a
    /// 1 ns schedule.
    ///
    /// Applies when the ring-bar torque, at most `tau_max` ([`Self::torque_bound`]), could
    /// move a free rotor by a tenth of the tolerance over the rest of the step at most
    /// ([`Self::ring_is_negligible`]), and could shift the onion from its repeating path by a
    /// hundredth of it: its static shift `tau_max / (2 |E|)` (eq. 3.4's curvature at a minimum
    /// is `2 |E|`) times the periods it remembers, `1 + 1 / (lambda T)` with `lambda` the onion's
    /// slowest decay rate at that curvature and `T` the schedule's period.
    pub(super) fn skip_onion_periods(
        &self,
        run: &mut StepRun,
        s: &SteppingSchedule,
        inputs: &MotorInputs,
    ) -> bool {
        if self.quasi_static() {
            return false;
        }
        let decoupled = *run
            .onion_decoupled
            .get_or_insert_with(|| self.ring_decoupled(s, inputs.rotor_locked, run.t_end - run.t));
        if !decoupled {
            return false;
        }
        let tol = self.params.tolerance;
        // Whether the onion followed its quasi-static branch to the period's end (settled,
        // no tilt): the next period then depends on its offset from the strain alone.
        let relaxed = run.following == run.segment_end;
        let relative = [
            run.y[2] - run.segment_direction,
            run.y[3],
            run.y[2],
            f64::from(u8::from(relaxed)),
        ];
        if run.whole_period {
            // Eq. 3.4 repeats every half turn of the offset: the onion may settle a half turn
            // away from the strain's own turn, and the reduced strain direction (see
            // `REDUCED_DIRECTION_ABOVE`) jumps by half turns.
            let mismatch = run.onion_period_end.map_or(f64::INFINITY, |p| {
                let offset = p[0] - relative[0];
                let offset = offset - PI * (offset / PI).round();
                offset.abs().max((p[1] - relative[1]).abs())
            });
            // The offset's rounding, a few units in the last place of the onion's angle.
            let rounding = ROUNDING_ULPS * f64::EPSILON * run.y[2].abs();
            let periods = s.step_index(run.t_end) - s.step_index(run.t);
            // The onion's turn over a period: `step_angle` but for the half turns eq. 3.4's
            // symmetry allows, as over the last period.
            let turn = run.onion_period_end.map_or(0.0, |p| {
                let half_turns = ((relative[2] - p[2] - s.step_angle) / PI).round();
                s.step_angle + half_turns * PI
            });
            // Two periods from the branch with the same offset repeat for good; otherwise the
            // one before must have converged too.
            let from_branch = relaxed && run.onion_period_end.is_some_and(|p| p[3] == 1.0);
            if (!from_branch || self.snaps_forgotten(s, 1.0))
                && mismatch <= 1e-3 * tol + rounding
                && (from_branch || run.onion_period_mismatch <= 1e-2 * tol + rounding)
                && periods >= 1.0
                && self.advance_onion_periods(run, s, inputs, periods, turn)
            {
                return true;
            }
            run.onion_period_mismatch = mismatch;
            if self.skip_onion_cycles(run, s, inputs, relaxed, relative[0]) {
                return true;
            }
        }
        run.onion_period_end = Some(relative);
        false
    }

    /// The skip of [`Self::skip_onion_periods`] over `periods` whole periods, each turning the
    /// onion by `turn`; `false` (nothing changed) if the rotor would leave its bounds.
    fn advance_onion_periods(
        &self,
        run: &mut StepRun,
        s: &SteppingSchedule,
        inputs: &MotorInputs,
        periods: f64,
        turn: f64,
    ) -> bool {
        let t = (s.step_index(run.t_end) * s.step_period).min(run.t_end);
        self.advance_onion_periods_to(run, inputs, t, periods * turn)
    }

    /// The rotor of `y` over `dt` where the ring's torque is negligible: a locked one stays, at
    /// rest; a free one follows load and drag alone, exactly ([`Self::drift_response`]).
    pub(super) fn drift_rotor(&self, y: &mut super::Vector, inputs: &MotorInputs, dt: f64) {
        if inputs.rotor_locked {
            y[1] = 0.0;
        } else {
            let (coast, torque_speed, torque_angle) = self.drift_response(dt);
            let load = inputs.load_torque;
            y[0] += y[1] * coast + load * torque_angle;
            y[1] = y[1] * (1.0 - self.drag * torque_speed) + load * torque_speed;
        }
    }

    /// A skip of repeated periods to the switch at `t`, turning the onion by `turn` in all;
    /// `false` (nothing changed) if the rotor would leave its bounds.
    pub(super) fn advance_onion_periods_to(
        &self,
        run: &mut StepRun,
        inputs: &MotorInputs,
        t: f64,
        turn: f64,
    ) -> bool {
        let mut y = run.y;
        self.drift_rotor(&mut y, inputs, t - run.t);
        y[2] += turn;
        if !(self.rotor_sane(&y) && Self::onion_sane(&y)) {
            return false;
        }
        run.jump_onion_to(y, t, f64::NAN);
        #[cfg(test)]
        SKIPS.with(|c| c.set(c.get() + 1));
        true
    }

    /// Whether an onion placed on its quasi-static branch at a switch has forgotten that placement
    /// `periods` periods of the schedule `s` later: its slowest decay at eq. 3.4's curvature at a
    /// minimum, `2 |E|` ([`Self::onion_decay_rate`]), shrinks a perturbation to [`SNAP_DECAY`]
    /// of itself over that time.
    ///
    /// A placement on the branch drops what is left of the onion's ringing
    /// ([`Self::relaxed_onion`]), and two placements compare alike by construction (the offset at
    /// the branch's minimum). Repeating the periods between them turns whatever shift a
    /// placement leaves into a drift every cycle, where the true onion keeps forgetting it. Once
    /// the onion's own decay has forgotten a placement within the cycle, the repeated state is
    /// the onion's, not the placement's.
    pub(super) fn snaps_forgotten(&self, s: &SteppingSchedule, periods: f64) -> bool {
        let curvature = 2.0 * (self.magnetoelastic_per_stress * s.stress_amplitude).abs();
        let decay = self.onion_decay_rate(curvature) * periods * s.step_period;
        decay >= -SNAP_DECAY.ln()
    }

    /// Whether the ring-bar torque is negligible over `h` seconds of the schedule `s`, for the
    /// rotor (unless `locked`) and for the onion (see [`Self::skip_onion_periods`]).
    pub(super) fn ring_decoupled(&self, s: &SteppingSchedule, locked: bool, h: f64) -> bool {
        let curvature = 2.0 * (self.magnetoelastic_per_stress * s.stress_amplitude).abs();
        if curvature.is_nan() || curvature <= 0.0 {
            return false;
        }
        if !locked {
            let (_, torque_speed, torque_angle) = self.drift_response(h);
            if !self.ring_is_negligible(torque_speed, torque_angle) {
                return false;
            }
        }
        let slowest = self.onion_decay_rate(curvature);
        let memory = 1.0 + 1.0 / (slowest * s.step_period);
        self.torque_bound() / curvature * memory <= 0.01 * self.params.tolerance
    }
}
