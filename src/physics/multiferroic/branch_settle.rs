//! The quasi-static settle behind the Gilbert onion's checks for its branch
//! ([`Motor::relaxed_onion`], [`Motor::heads_for_minimum`]): skipped where a bound on eq. 3.4's
//! landscape shows that the minimum lies beyond the checks' slack (the onion right after a
//! switch of a fast schedule, once a switch), and handed on where the onion joins its branch so
//! that the next constrain does not march to the same minimum again.

use super::angles::Angles;
use super::settle_memo::SettleMemo;
use super::{Drive, Motor, Vector};

/// Where a settle starts: the angles at the onion and the gradient and curvature of eq. 3.4
/// there, which the settle's first iteration uses ([`super::onion::Landscape::settle_from_slope`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct SettleStart {
    pub(super) angles: Angles,
    pub(super) gradient: f64,
    pub(super) curvature: f64,
}

/// A Gilbert onion relaxed onto its quasi-static branch ([`Motor::relaxed_onion`]): the rotor's
/// speed kick (rad/s), the angles at the minimum it settles into (where the branch starts, the
/// same march from the same angles as the next constrain's) and the curvature of eq. 3.4 there
/// (which the check evaluated).
#[derive(Clone, Copy, Debug)]
pub(super) struct Relaxed {
    pub(super) kick: f64,
    pub(super) settled: Angles,
    pub(super) curvature: f64,
}

impl Motor {
    /// The angles at the onion at `y` for the drive `d`, where the settle starts
    /// ([`Self::settle`]), with the gradient and curvature there (the settle's first iteration
    /// uses them), or `None` where the minimum it settles into lies provably more than `gap`
    /// (rad) from it, from the gradient `U'` and curvature `U''` at the onion alone (one
    /// evaluation where the settle marches and refines).
    ///
    /// Along `s` rad from the onion, `|U''| <= |U''(psi)| + M s` with `M` the landscape's
    /// third-derivative bound, so `|U'|` stays above `|U'(psi)| - |U''(psi)| s - M s^2 / 2`: no
    /// root of the gradient lies within `r` where that is positive at `s = r`. The settle's
    /// downhill march never steps over a root (see [`super::onion`]) and ends on one, to its root
    /// tolerance; `r` is taken as four times `gap` plus four root tolerances, so the first
    /// stride, each Newton step that converges and each bracket the refinement returns from all
    /// lie beyond `gap`. Where the settle would stay at the start (a gradient within its
    /// rounding, or no finite third-derivative bound) the angles are returned, as for NaN.
    pub(super) fn settle_start_within(
        &self,
        y: &Vector,
        d: &Drive,
        gap: f64,
        memo: &SettleMemo,
    ) -> Option<SettleStart> {
        let land = self.landscape(y[0], d.direction, d.stress);
        let angles = memo.fresh_angles(y, d);
        let (g, c) = land.gradient_curvature_of(&angles);
        let start = SettleStart {
            angles,
            gradient: g,
            curvature: c,
        };
        let m = land.third_derivative_bound();
        if !(g.abs() > land.gradient_tolerance() && m.is_finite() && m > 0.0) {
            return Some(start);
        }
        let r = 4.0 * (gap + land.root_tolerance(y[2]));
        let beyond = g.abs() > c.abs() * r + 0.5 * m * r * r;
        (!beyond).then_some(start)
    }

    /// The angles at the minimum of eq. 3.4 that the onion at `y` settles into for the drive
    /// `d`, `None` where it does not head for it within `horizon` ([`Self::heads_for_minimum`]):
    /// the minimum is [`Self::constrain`]'s for a quasi-static onion at `y` (the same march from
    /// the same angles), so the branch that the onion joins starts there without a second march.
    ///
    /// The minimum and its curvature are kept in `memo` for the other checks of the pass.
    pub(super) fn heads_for_settled(
        &self,
        y: &Vector,
        d: &Drive,
        horizon: f64,
        memo: &SettleMemo,
    ) -> Option<Angles> {
        let (minimum, k) = self.settled_curvature(memo, y, d);
        self.heads_for_minimum(y, minimum.onion, k, horizon)
            .then_some(minimum)
    }
}
