//! A locked rotor's Gilbert onion on a schedule faster than its ringing, once the step's budget
//! is spent (see [`Motor::locked_budget_drop`]).

use super::{reduced_direction, Drive, Motor, MotorInputs, StepRun, GILBERT_SUBSTEP_WEIGHT};
use std::f64::consts::PI;

/// The segments over which a locked step's refusal for its ringing is put off where the onion's
/// periods may still repeat (see [`Motor::locked_budget_drop`]): the onion-periods skip needs two
/// or three period ends alike.
const REFUSAL_PUT_OFF: u32 = 3;

#[cfg(test)]
thread_local! {
    /// Passes of [`Motor::step`]'s loop on this thread (tests count them).
    pub(super) static PASSES: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

impl Motor {
    /// Whether a locked rotor's Gilbert onion is put into the minimum of eq. 3.4 it rings about
    /// once the step's budget is spent (or a substep was forced beyond the tolerance), the
    /// segment ending at `segment_end`.
    ///
    /// - Its ringing ends within the tolerance by the segment's end
    ///   ([`Self::locked_ringing_ends`]): it is dropped, the onion's angle there within the
    ///   tolerance of the resolved one. So it is, whatever its ringing, without a switch in the
    ///   step (the frozen landscape's ringing).
    /// - On a schedule switching within the step, an onion that creeps (the onion block's tilt
    ///   relaxes faster than the onion turns, `alpha^2 T > 4 |U''|` at the minimum, `U''` eq.
    ///   3.4's curvature there) is kept: the forced substeps follow its slow path.
    /// - A ringing one is kept in the step's last segment, where its ringing is the output; before
    ///   it, it is dropped where every switch's ringing ends within the tolerance within its
    ///   period and the present ringing by the step's end ([`Self::switch_ringing_ends`]), and
    ///   otherwise the step is refused (`run.unresolvable`; put off over [`REFUSAL_PUT_OFF`]
    ///   segments while the budget lasts where the onion's periods may still repeat). A drop
    ///   into the minimum at every switch turns the onion with the strain where the resolved
    ///   onion, its period of precession or of decay longer than the schedule's, barely follows
    ///   it (1 us steps ended up to 900 rad off an RK4), and forced substeps spanning several
    ///   precession periods do not follow it either.
    pub(super) fn locked_budget_drop(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
    ) -> bool {
        // In the step's last segment, with a switch in the step, the check ends here unless the
        // ringing ends: its bound refuses before the settle's march.
        let last = segment_end >= run.t_end
            && run
                .schedule
                .is_some_and(|s| s.step_index(run.t_end) > s.step_index(run.start));
        let settled = if last {
            let state = (&run.y, d);
            let Some(minimum) =
                self.settled_unless_ringing_on(&run.settle_memo, state, segment_end - run.t)
            else {
                return false;
            };
            minimum.onion
        } else {
            self.settled_minimum(&run.settle_memo, &run.y, d).onion
        };
        if self.locked_ringing_ends(&run.y, d, settled, segment_end - run.t) {
            return true;
        }
        let Some(s) = run
            .schedule
            .filter(|s| s.step_index(run.t_end) > s.step_index(run.start))
        else {
            return true;
        };
        let k = self
            .landscape(run.y[0], d.direction, d.stress)
            .curvature(settled);
        let alpha = self.params.gilbert_damping;
        if alpha * alpha * self.tilt_stiffness > 4.0 * k.abs() || segment_end >= run.t_end {
            // A creeping onion's slow path, or the last segment's ringing (the step's output).
            return false;
        }
        let ends = self.switch_ringing_ends(run, d, &s, settled, k, segment_end);
        // Where the onion's periods may still repeat (a ring decoupled from the onion, see
        // `Self::skip_onion_periods`, which compares their ends), the refusal is put off over
        // [`REFUSAL_PUT_OFF`] segments while the budget lasts: the substeps go on (flagged where
        // one was forced) and may reach that repeat at the next switches (a kept tilt, no
        // longer dropped with the ringing, can leave the first periods' ends apart).
        let spent = run.attempts.saturating_add(run.extra_cost);
        let broke = spent.saturating_add(GILBERT_SUBSTEP_WEIGHT) > self.params.max_substeps;
        if !ends && !broke && run.onion_decoupled == Some(true) {
            let (at, count) = &mut run.refusal_put_off;
            if *at != segment_end {
                (*at, *count) = (segment_end, *count + 1);
            }
            if *count <= REFUSAL_PUT_OFF {
                return false;
            }
        }
        run.unresolvable = !ends;
        ends
    }

    /// Whether a locked rotor's ringing Gilbert onion at `run.y`, about the minimum `settled`
    /// (curvature `k > 0`), ends the step within the tolerance of the minimum where it is put at
    /// every switch from now on: the distance between the minima before and after a switch (the
    /// next one's, or the strain's turn folded into the half turn of eq. 3.4, whichever is
    /// larger) decays within the tolerance within a period of the schedule, and the present
    /// ringing's distance in the energy's norm by the step's end, each at the slowest rate of
    /// the onion's linearization ([`Self::onion_decay_rate`]) where eq. 3.4's curvature is within
    /// `2 M distance` of `k` (`M` its third derivative's bound). Each later segment then starts at
    /// most its switch's kick from the minimum and ends within the tolerance of it, so the
    /// ringing dropped at every switch moves the onion's angle at the step's end by the tolerance
    /// at most.
    fn switch_ringing_ends(
        &self,
        run: &StepRun,
        d: &Drive,
        s: &super::SteppingSchedule,
        settled: f64,
        k: f64,
        segment_end: f64,
    ) -> bool {
        if k.is_nan() || k <= 0.0 {
            return false;
        }
        let tol = self.params.tolerance;
        let folded = (s.step_angle - PI * (s.step_angle / PI).round()).abs();
        let next = reduced_direction(s.direction(segment_end));
        let kick = (self.landscape(run.y[0], next, d.stress).settle(settled) - settled).abs();
        let gap =
            ((settled - run.y[2]).powi(2) + self.tilt_stiffness * run.y[3].powi(2) / k).sqrt();
        // The slowest decay rate where the curvature is within `M reach` of `k` (`M` the bound
        // on eq. 3.4's third derivative), the ringing's reach taken as twice its distance: a
        // margin for the curvature's change over it.
        let m = self
            .landscape(run.y[0], d.direction, d.stress)
            .third_derivative_bound();
        let decays = |distance: f64, time: f64| {
            let spread = 2.0 * distance * m;
            let rate = self
                .onion_decay_rate(k - spread)
                .min(self.onion_decay_rate(k + spread));
            spread < k && distance * (-rate * time).exp() <= tol
        };
        decays(kick.max(folded), s.step_period) && decays(gap, run.t_end - run.t)
    }

    /// Whether a locked rotor's Gilbert step on a schedule has more switches than the step's
    /// `passes` (the loop of [`Self::step`]) where no skip over whole periods but the onion's
    /// linear spans can apply: those of repeated periods compare the rotor's offset from the
    /// strain, which turns by the step angle folded into the half turn of eq. 3.4 (here beyond
    /// their threshold of `tolerance / 1000`) from period to period while the rotor stays; those
    /// of the onion's periods and cycles need a ring decoupled from the onion
    /// ([`Self::ring_decoupled`]); the unstrained advance needs no strain, and the strain-held
    /// one a quasi-static onion. Such a step is refused once its linear spans are over
    /// ([`Self::passes_run_out`]): every pass then ends within its segment of constant drive.
    pub(super) fn switches_outnumber_passes(
        &self,
        run: &StepRun,
        inputs: &MotorInputs,
        passes: u64,
    ) -> bool {
        let Some(s) = inputs.schedule.get() else {
            return false;
        };
        if self.quasi_static()
            || !inputs.rotor_locked
            || self.magnetoelastic_per_stress * s.stress_amplitude == 0.0
        {
            return false;
        }
        // Each pass ends by the next switch, so after `n` passes the schedule's index is at
        // most `n` past the start's; one more is allowed for rounding (the index is never NaN).
        let switches = s.step_index(run.t_end) - s.step_index(run.start);
        if switches <= passes as f64 + 1.0 {
            return false;
        }
        let folded = (s.step_angle - PI * (s.step_angle / PI).round()).abs();
        let largest = s
            .direction(run.start)
            .abs()
            .max(s.direction(run.t_end).abs());
        let rounding = 16.0 * f64::EPSILON * (largest + run.y[0].abs() + PI);
        folded > 1e-3 * self.params.tolerance + rounding
            && !self.ring_decoupled(s, true, run.t_end - run.start)
    }

    /// Why a locked rotor's step was refused by [`Self::locked_budget_drop`].
    pub(super) fn unresolvable_message(&self, time: f64, h: f64) -> String {
        format!(
            "the step from t = {time} s by {h} s needs more than max_substeps = {} to resolve \
             the Gilbert onion's ringing on the locked rotor through the schedule's switches \
             (it outlasts a period of the schedule); raise max_substeps or shorten the step",
            self.params.max_substeps
        )
    }
}
