//! A locked rotor's Gilbert step whose schedule switches outnumber the passes left in its loop
//! (see [`Motor::passes_run_out`]).

use super::onion_linear_locked::stiffness_slope_bound;
use super::{Motor, MotorInputs, StepRun};

impl Motor {
    /// Whether the loop of [`Motor::step`], with `passes_left` passes left, is sure to end short
    /// of the step's end, for a step found by [`Self::switches_outnumber_passes`] (a locked rotor's
    /// Gilbert onion on a schedule where the skips over repeated periods, over the onion's periods
    /// and cycles, the strain-held and the unstrained advances cannot apply): the switches left
    /// outnumber the passes left (one more allowed for rounding), and the onion's linear spans
    /// ([`Self::advance_onion_linear`]) are over for the step. Those spans, the locked rotor's
    /// ring torque folded into their affine maps, cross many switches in one pass; they are
    /// tried at every switch until they fail or the budget cannot pay for them and then no more
    /// in the step (or never, where the ring's stiffness slope has no finite bound). From then
    /// on every pass ends by the next switch. So the step is refused once its spans are over,
    /// not before its first pass: where the spans carry the onion as far as the budget pays,
    /// the step ends (945 switches of a 1.06 ns schedule with `max_substeps` 600, in a few
    /// dozen passes of 1216).
    pub(super) fn passes_run_out(
        &self,
        run: &StepRun,
        inputs: &MotorInputs,
        passes_left: u64,
    ) -> bool {
        let Some(s) = inputs.schedule.get() else {
            return false;
        };
        let spans_over = run.onion_linear.disabled()
            || run.onion_decoupled == Some(false)
                && inputs.rotor_locked
                && !(0.5 * stiffness_slope_bound(&self.ring_bar)).is_finite();
        spans_over && s.step_index(run.t_end) - s.step_index(run.t) > passes_left as f64 + 1.0
    }
}
