//! A free rotor that the ring's torque cannot move: the Gilbert onion's ringing is dropped where
//! its orbit-averaged decay ends it within the segment ([`Motor::decoupled_ringing_decays`]), or
//! where the budget can no longer resolve it, into the minimum of the well it is trapped in
//! ([`Motor::decoupled_budget_drop`]).

use super::decoupled::torque_bound;
use super::orbit::point;
use super::ringing::{Rims, MAX_FOLLOWED_LAG};
use super::settle_memo::SettleMemo;
use super::{Drive, Motor, Vector};

impl Motor {
    /// Whether the Gilbert onion at `y`, under a free rotor that the ring's torque cannot move
    /// (the first condition of [`Self::decoupled_ringing`], checked there), ends the `remaining`
    /// time of its segment (s) within the tolerance of the minimum `settled` it rings about, at its
    /// orbit-averaged energy loss in the landscape frozen at the rotor's present angle
    /// ([`Self::locked_ringing_decays`]: from at most 0.999 of its well's lowest rim, losing at
    /// most a tenth of its energy per orbit, within 3/4 of the time left). The ring-bar term
    /// moves the well with the rotor, its minimum at `omega k_bar / k`: held within
    /// [`MAX_FOLLOWED_LAG`] over the segment, as the decoupled ringing's lag (the well moves
    /// adiabatically, as [`Self::trapped_ringing`] takes it). The instantaneous bounds of
    /// [`Self::decoupled_ringing`] see ringing near the rims decay 100 times slower than its
    /// linearization at the minimum, or at the sublevel bound's rate, which vanishes at a rim: an
    /// onion released at 0.99 of its rim was resolved until the budget ran out.
    /// `rims.decay_retry_level` spaces the retries as for a locked rotor. Tried only in the
    /// step's last segment (`rims.ends_step`, no switch before the step's end): a switch rings
    /// the onion again, so a drop before one saves at most the rest of its segment, while a fast
    /// schedule would try it in every segment. Declining leaves the ringing resolved.
    pub(super) fn decoupled_ringing_decays(
        &self,
        y: &Vector,
        d: &Drive,
        settled: f64,
        rims: &mut Rims,
        remaining: f64,
    ) -> bool {
        if !rims.ends_step {
            return false;
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let drift =
            (self.ring_bar.stiffness(settled - y[0]) / land.curvature(settled) * y[1]).abs();
        // (A NaN fails.)
        let follows = drift * remaining <= MAX_FOLLOWED_LAG;
        if !follows {
            return false;
        }
        let frozen = Drive { locked: true, ..*d };
        let (retry, orbits) = (&mut rims.decay_retry_level, &mut rims.decay_orbits);
        self.locked_ringing_decays(y, &frozen, settled, remaining, retry, orbits)
    }

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
    ///
    /// The minimum that the onion settles into is `memo`'s ([`Self::settled_minimum`]).
    pub(super) fn decoupled_budget_drop(
        &self,
        y: &Vector,
        d: &Drive,
        (remaining, to_switch): (f64, f64),
        memo: &SettleMemo,
    ) -> bool {
        if d.locked || to_switch < remaining {
            return false;
        }
        let tau_max = torque_bound(&self.ring_bar);
        // (A NaN fails.)
        let negligible = 2.0 * tau_max * remaining <= 0.01 * self.params.tolerance * self.drag;
        if !negligible {
            return false;
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let minimum = self.settled_minimum(memo, y, d).onion;
        let Some(well) = self.well_of_minimum(&land, minimum) else {
            return false;
        };
        let excess = point(&land, y[2]).0 - well.floor + 0.5 * self.tilt_stiffness * y[3] * y[3];
        let turn = y[1].abs().max((d.load / self.drag).abs()) * remaining;
        well.below < y[2] && y[2] < well.above && excess + 3.0 * tau_max * turn < well.barrier
    }
}
