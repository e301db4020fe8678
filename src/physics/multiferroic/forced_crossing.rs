//! A forced Gilbert substep (taken beyond the tolerance at the budget's minimum size) that takes
//! the onion where the damped macrospin cannot go: not taken, the ringing dropped instead.

use super::decoupled::torque_bound;
use super::orbit::point;
use super::{Drive, Motor, Vector};

/// The smallest error estimate (rad) of a forced substep that is checked: the
/// substep that carried an onion over its rim estimated its own error at 0.22 rad (its true
/// error 2.5 rad), the forced substeps before it, inside the well, at up to 0.094 rad.
const CROSSING_ERROR: f64 = 1e-2;

impl Motor {
    /// Whether the forced substep from `y` to `y_new` (its error estimate `err` tolerances)
    /// took the Gilbert onion where the damped macrospin cannot go (under a free rotor).
    ///
    /// The onion's energy, eq. 3.4's `U(psi, phi)` plus the tilt's `T theta^2 / 2`, only falls
    /// under Gilbert damping (eq. 3.5) but for the work of the rotor's turn, `dE = -tau dphi`
    /// with the ring's torque `|tau|` at most [`torque_bound`] (the rotor turning one way over a
    /// substep; rounding allowed for). A forced substep that raises it
    /// by more pumps the ringing through its own error: taken, such substeps pumped an onion's
    /// tilt past 9 rad and ended its step 8.6 rad off a plain RK4.
    ///
    /// Where the onion's energy at `y` is below its well's lowest rim, the resolved onion stays
    /// in that well over the substep (the landscape barely moves with the rotor); a forced
    /// substep that ends it beyond a rim crossed it through its own error: a weakly damped onion,
    /// forced across several precession periods as the budget runs out, crossed rim after rim
    /// into a minimum `3 pi` from the resolved onion's.
    ///
    /// The caller drops the ringing from `y` instead ([`Motor::follows_branch`]): the onion
    /// settles into the minimum it rings about, and the step stays flagged. Only a substep whose
    /// error estimate reaches [`CROSSING_ERROR`] is looked at: finding the well's rims is a
    /// march (0.4-0.6 us, as much as the substep), and a substep estimated a hundredth of a
    /// radian off is far from an error of a well's width.
    pub(super) fn forced_out_of_well(
        &self,
        y: &Vector,
        y_new: &Vector,
        err: f64,
        d: &Drive,
    ) -> bool {
        if err * self.params.tolerance < CROSSING_ERROR
            || d.locked
            || self.quasi_static()
            || !self.onion_relaxes_fast()
        {
            return false;
        }
        let energy_at = |y: &Vector| {
            let land = self.landscape(y[0], d.direction, d.stress);
            point(&land, y[2]).0 + 0.5 * self.tilt_stiffness * y[3] * y[3]
        };
        let (before, after) = (energy_at(y), energy_at(y_new));
        let supply = torque_bound(&self.ring_bar) * (y_new[0] - y[0]).abs();
        if after - before > supply + 1e-12 * before.abs().max(after.abs()) {
            return true;
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let Some(well) = self.onion_well(&land, y[2]) else {
            return false;
        };
        let energy = point(&land, y[2]).0 - well.floor + 0.5 * self.tilt_stiffness * y[3] * y[3];
        let trapped = well.below < y[2] && y[2] < well.above && energy < well.barrier;
        // The rims move with the rotor's turn over the substep, the minimum by as much.
        let turn = (y_new[0] - y[0]).abs();
        trapped && !(well.below - turn < y_new[2] && y_new[2] < well.above + turn)
    }
}
