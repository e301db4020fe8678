//! A Gilbert onion on a fast schedule whose ring barely couples it to the rotor and whose periods
//! repeat in the strain's frame only every few switches (see [`Motor::skip_onion_cycles`]).

use super::{Motor, MotorInputs, StepRun, SteppingSchedule};
use std::f64::consts::PI;

/// Units in the last place of the onion's angle allowed beside the tolerance when two relaxed
/// switches are compared, as for single periods ([`Motor::skip_onion_periods`]).
const ROUNDING_ULPS: f64 = 64.0;

/// The most switches after a relaxed one whose onion is kept, to end a step inside a cycle.
const KEPT_SWITCHES: usize = 64;

/// A switch at which the Gilbert onion had relaxed onto its quasi-static branch: the index of
/// the period it starts, the onion's offset from the strain of the period that ended there and
/// its angle (rad), and the onion's angle and tilt at the switches since (up to
/// [`KEPT_SWITCHES`]; `None` beyond).
#[derive(Clone, Debug)]
pub(super) struct RelaxedSwitch {
    index: f64,
    offset: f64,
    onion: f64,
    since: Option<Vec<[f64; 2]>>,
}

impl Motor {
    /// Takes whole cycles of `L` periods of the schedule at once when the Gilbert onion has
    /// relaxed onto its quasi-static branch at two switches `L` periods apart with the same
    /// offset from the strain (within `tolerance / 1000`, modulo the half turn of eq. 3.4), the
    /// first placement forgotten within the cycle ([`Self::snaps_forgotten`]), in
    /// the regime where eq. 3.3's ring-bar torque is negligible
    /// ([`Self::ring_decoupled`]); `relaxed` says whether it has at this switch, `offset` is its
    /// offset there. The step's last switch inside a cycle is reached too, the onion's angle and
    /// tilt those of the same switch of the cycle resolved, turned.
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
        let index = s.step_index(run.t);
        if !relaxed {
            if let Some(r) = run.relaxed_switch.as_mut() {
                // Kept only while every switch since the relaxed one is, in order.
                let next = r.since.as_ref().map_or(0.0, |v| v.len() as f64) + 1.0;
                match r.since.as_mut() {
                    Some(v) if index == r.index + next && v.len() < KEPT_SWITCHES => {
                        v.push([run.y[2], run.y[3]]);
                    }
                    _ => r.since = None,
                }
            }
            return false;
        }
        let here = RelaxedSwitch {
            index,
            offset,
            onion: run.y[2],
            since: Some(Vec::new()),
        };
        let Some(last) = run.relaxed_switch.replace(here) else {
            return false;
        };
        let cycle = index - last.index;
        let periods_left = s.step_index(run.t_end) - index;
        if !(cycle >= 1.0 && periods_left >= 1.0 && self.snaps_forgotten(s, cycle)) {
            return false;
        }
        let shift = offset - last.offset;
        let mismatch = (shift - PI * (shift / PI).round()).abs();
        let rounding = ROUNDING_ULPS * f64::EPSILON * run.y[2].abs().max(last.onion.abs());
        if mismatch > 1e-3 * self.params.tolerance + rounding {
            return false;
        }
        // The onion's turn over a cycle: `L step_angle` but for the half turns eq. 3.4 allows.
        let nominal = cycle * s.step_angle;
        let turn = nominal + PI * ((run.y[2] - last.onion - nominal) / PI).round();
        let blocks = (periods_left / cycle).floor();
        // The switch `inside` periods into the cycle after the last whole one, as resolved in
        // the cycle between the two relaxed switches (`None` at a relaxed switch).
        let inside = periods_left - blocks * cycle;
        let within = match last.since.as_deref() {
            _ if inside == 0.0 => None,
            Some(since) if inside as usize <= since.len() => Some(since[inside as usize - 1]),
            _ if blocks >= 1.0 => {
                // Not kept: stop at the last relaxed switch.
                return self.advance_cycles(run, s, inputs, index, cycle, blocks, turn, offset);
            }
            _ => return false,
        };
        let Some([onion, tilt]) = within else {
            return self.advance_cycles(run, s, inputs, index, cycle, blocks, turn, offset);
        };
        let end = (s.step_index(run.t_end) * s.step_period).min(run.t_end);
        let target = onion + (blocks + 1.0) * turn;
        if !(end > run.t && self.advance_onion_periods_to(run, inputs, end, target - run.y[2])) {
            return false;
        }
        run.y[3] = tilt;
        true
    }

    /// The skip of `blocks` cycles of `cycle` periods from the relaxed switch starting period
    /// `index`, each turning the onion by `turn`, to the relaxed switch with the same `offset`.
    #[allow(clippy::too_many_arguments)]
    fn advance_cycles(
        &self,
        run: &mut StepRun,
        s: &SteppingSchedule,
        inputs: &MotorInputs,
        index: f64,
        cycle: f64,
        blocks: f64,
        turn: f64,
        offset: f64,
    ) -> bool {
        let end = ((index + blocks * cycle) * s.step_period).min(run.t_end);
        if !(end > run.t && self.advance_onion_periods_to(run, inputs, end, blocks * turn)) {
            return false;
        }
        // The state reached is the relaxed one turned: a cycle on from it repeats alike.
        run.relaxed_switch = Some(RelaxedSwitch {
            index: s.step_index(end),
            offset,
            onion: run.y[2],
            since: Some(Vec::new()),
        });
        true
    }
}
