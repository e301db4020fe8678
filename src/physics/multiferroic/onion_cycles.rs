//! A Gilbert onion on a fast schedule whose ring barely couples it to the rotor and whose periods
//! repeat in the strain's frame only every few switches (see [`Motor::skip_onion_cycles`]).

use super::{Motor, MotorInputs, StepRun, SteppingSchedule};
use std::f64::consts::PI;

/// Units in the last place of the onion's angle allowed beside the tolerance when two relaxed
/// switches are compared, as for single periods ([`Motor::skip_onion_periods`]).
const ROUNDING_ULPS: f64 = 64.0;

/// A switch at which the Gilbert onion had relaxed onto its quasi-static branch: the index of
/// the period it starts, the onion's offset from the strain of the period that ended there and
/// its angle (rad).
#[derive(Clone, Copy, Debug)]
pub(super) struct RelaxedSwitch {
    index: f64,
    offset: f64,
    onion: f64,
}

impl Motor {
    /// Takes whole cycles of `L` periods of the schedule at once when the Gilbert onion has
    /// relaxed onto its quasi-static branch at two switches `L` periods apart with the same
    /// offset from the strain (within `tolerance / 1000`, modulo the half turn of eq. 3.4), in
    /// the regime where eq. 3.3's ring-bar torque is negligible
    /// ([`Self::ring_decoupled`]); `relaxed` says whether it has at this switch, `offset` is its
    /// offset there.
    ///
    /// A relaxed onion sits settled (no tilt) in a minimum of eq. 3.4, so the periods that follow
    /// depend on its offset from the strain alone (without the ring-bar torque the onion's
    /// equations depend on `psi - gamma` and the tilt only, and a locked rotor stays, a free one
    /// follows load and drag, exactly solved). Two relaxed switches with the same offset thus
    /// start the same `L` periods turned by `L step_angle` (and whole half turns): every later
    /// block of `L` periods repeats them. This generalizes [`Self::skip_onion_periods`]' two
    /// relaxed periods in a row to an onion that rings through a few switches and relaxes
    /// only at every `L`-th, in step with the schedule (`step_angle` small against the strain's
    /// half turn, or slow precession against the period): every switch was resolved, 1-15
    /// Gilbert substeps each, up to 900 per 1 us step of a 1 ns schedule.
    pub(super) fn skip_onion_cycles(
        &self,
        run: &mut StepRun,
        s: &SteppingSchedule,
        inputs: &MotorInputs,
        relaxed: bool,
        offset: f64,
    ) -> bool {
        if !relaxed {
            return false;
        }
        let here = RelaxedSwitch {
            index: s.step_index(run.t),
            offset,
            onion: run.y[2],
        };
        let Some(last) = run.relaxed_switch.replace(here) else {
            return false;
        };
        let cycle = here.index - last.index;
        let periods_left = s.step_index(run.t_end) - here.index;
        if !(cycle >= 1.0 && periods_left >= cycle) {
            return false;
        }
        let shift = here.offset - last.offset;
        let mismatch = (shift - PI * (shift / PI).round()).abs();
        let rounding = ROUNDING_ULPS * f64::EPSILON * here.onion.abs().max(last.onion.abs());
        if mismatch > 1e-3 * self.params.tolerance + rounding {
            return false;
        }
        // The onion's turn over a cycle: `L step_angle` but for the half turns eq. 3.4 allows.
        let nominal = cycle * s.step_angle;
        let turn = nominal + PI * ((here.onion - last.onion - nominal) / PI).round();
        let blocks = (periods_left / cycle).floor();
        let end = (here.index + blocks * cycle) * s.step_period;
        if !(end > run.t && end <= run.t_end) {
            return false;
        }
        if !self.advance_onion_periods_to(run, inputs, end, blocks * turn) {
            return false;
        }
        // The state reached is the relaxed one turned: a cycle on from it repeats alike.
        run.relaxed_switch = Some(RelaxedSwitch {
            index: s.step_index(end),
            offset,
            onion: run.y[2],
        });
        true
    }
}
