//! A forced Gilbert substep (taken beyond the tolerance at the budget's minimum size) that carries
//! a trapped onion over its well's rim: not taken, the ringing dropped instead.

use super::orbit::point;
use super::{Drive, Motor, Vector};

/// The smallest error estimate (rad) of a forced substep that is checked for a crossing: the
/// substep that carried an onion over its rim estimated its own error at 0.22 rad (its true
/// error 2.5 rad), the forced substeps before it, inside the well, at up to 0.094 rad.
const CROSSING_ERROR: f64 = 1e-2;

impl Motor {
    /// Whether the forced substep from `y` to `y_new` carried the Gilbert onion out of a well it
    /// was trapped in (under a free rotor).
    ///
    /// At `y` the onion's energy, eq. 3.4's `U(psi)` plus the tilt's `T theta^2 / 2` above the
    /// well's floor, is below the well's lowest rim. Over one substep the landscape barely moves
    /// with the rotor, and the damped macrospin (eq. 3.5) only loses energy in a frozen one, so
    /// the resolved onion stays in that well. A forced substep that ends it beyond a rim did so
    /// through its own error: a weakly damped onion, forced across several precession periods
    /// as the budget runs out, crossed a rim after a rim into a minimum `3 pi` from the resolved
    /// onion's. The caller drops the ringing from `y` instead ([`Motor::follows_branch`]): the
    /// onion settles into the minimum it rings about, off by at most the ringing's reach, and the
    /// step stays flagged.
    ///
    /// Only a substep whose error estimate (`err` tolerances) reaches [`CROSSING_ERROR`] is
    /// looked at: finding the well's rims is a march (0.4-0.6 us, as much as the substep), and a
    /// substep estimated a hundredth of a radian off is far from an error of a well's width.
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
