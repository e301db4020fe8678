//! A free rotor that the ring's torque cannot move, whose Gilbert onion the budget can no longer
//! resolve: its ringing is dropped into the minimum of the well it is trapped in (see
//! [`Motor::decoupled_budget_drop`]).

use super::decoupled::torque_bound;
use super::orbit::point;
use super::{Drive, Motor, Vector};

impl Motor {
    /// Whether the Gilbert onion at `y`, which the budget can no longer resolve (a forced substep
    /// went beyond the tolerance), may be dropped into the minimum of its well for the `remaining` time of
    /// the step (s) under a free rotor, though it does not head for that minimum within the step
    /// ([`Self::heads_for_minimum`]). The step stays flagged. Three conditions:
    ///
    /// - The ring cannot move the rotor: its torque on the bar is at most `tau_max` in magnitude
    ///   ([`torque_bound`]), so the branch's torque and the ringing onion's differ by at most
    ///   `2 tau_max`, which turns the rotor by at most `2 tau_max remaining / c`; held below a
    ///   hundredth of the tolerance, as in [`Self::decoupled_ringing`]. Only the onion's own
    ///   outputs are at stake.
    /// - No switch of the schedule comes before the step's end (`to_switch`, s, is the time to
    ///   the next one): the drive, and with it the well, stays; across a switch the resolved onion
    ///   may barely move where the branch would turn with the strain.
    /// - The ringing is trapped in its well for the rest of the step: with the landscape frozen
    ///   the macrospin's energy `U(psi) - U(psi*) + T theta^2 / 2` only falls (eq. 3.4 with the
    ///   LLG damping), and the rotor's turn changes eq. 3.3's ring-bar term by at most `tau_max`
    ///   per radian at any onion angle, so over a turn of at most
    ///   `max(|omega|, |tau_load| / c) remaining` (the rotor's speed relaxes monotonically from
    ///   `omega` towards the load's drift) the onion gains, and the rims and the minimum each
    ///   move in energy, by at most `tau_max` times that turn. The energy plus three times that
    ///   is held below the well's lowest rim.
    ///
    /// The onion then ends the step within its well's reach of the minimum, where the resolved
    /// one rings. Forced substeps instead, each beyond the tolerance and spanning a good part of
    /// a precession period, can carry ringing near the rims over one into the next well, and
    /// they spend the rest of the budget.
    pub(super) fn decoupled_budget_drop(
        &self,
        y: &Vector,
        d: &Drive,
        remaining: f64,
        to_switch: f64,
    ) -> bool {
        if d.locked || to_switch < remaining {
            return false;
        }
        let tau_max = torque_bound(&self.ring_bar);
        // (A NaN fails.)
        if !(2.0 * tau_max * remaining <= 0.01 * self.params.tolerance * self.drag) {
            return false;
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let Some(well) = self.onion_well(&land, y[2]) else {
            return false;
        };
        let excess = point(&land, y[2]).0 - well.floor + 0.5 * self.tilt_stiffness * y[3] * y[3];
        let turn = y[1].abs().max((d.load / self.drag).abs()) * remaining;
        well.below < y[2] && y[2] < well.above && excess + 3.0 * tau_max * turn < well.barrier
    }
}
