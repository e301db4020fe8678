//! Cheap refusals of the checks that place a locked rotor's ringing onion on its minimum
//! ([`Motor::relaxed_onion`], [`Motor::locked_budget_drop`]), made before the settle's march to
//! the minimum it rings about: on the tilt alone ([`Motor::ringing_outlasts_switches`]), and on
//! the slope of eq. 3.4 at the onion, the march's first evaluation
//! ([`Motor::settle_outlasts_switches`], [`Motor::settled_unless_ringing_on`]).
//!
//! Every curvature of eq. 3.4 is at most `K = max |U_m''| + 2 |E|` (eq. 3.3's stiffness bound
//! plus eq. 3.4's wall term), and the slowest decay rate of the onion's linearization
//! ([`Motor::onion_decay_rate`]) does not decrease with the curvature: at
//! `lambda* = g T (1 + alpha^2) / alpha` its characteristic polynomial is `lambda* g T / alpha
//! > 0`, so its smaller root stays below `lambda*`, where the root's slope in the curvature,
//! `g (g T (1 + alpha^2) - alpha lambda) / (trace - 2 lambda)`, is not negative (and it is at
//! most 0 for a curvature of at most 0). The rate at `K` bounds every rate at the minimum.

use super::angles::Angles;
use super::onion::{downhill_stride, Landscape};
use super::settle_memo::SettleMemo;
use super::{Drive, Motor, Vector};

impl Motor {
    /// Whether the switch test that a locked rotor's onion at `y` must pass before it is placed
    /// on its minimum (`Motor::ringing_ends_in`, its gap to the minimum decayed to the next
    /// switch times the switches it remembers, within `slack`) fails whatever minimum of eq. 3.4
    /// in `land` it settles into: the energy-norm gap is at least the tilt's `|theta| sqrt(T /
    /// K)`, and it decays no faster, and the memory `1 + 1 / (lambda period)` is no shorter,
    /// than at the rate for `K` (see the module documentation), at most half the
    /// linearization's trace there, `g alpha (K + T) / 2`. The bound must exceed twice
    /// `slack`, a margin far beyond rounding on either side. `(to_switch, period)` as for
    /// `ringing_ends_in` (both infinite without a schedule: never refused here).
    pub(super) fn ringing_outlasts_switches(
        &self,
        land: &Landscape,
        y: &Vector,
        switches: (f64, f64),
        slack: f64,
    ) -> bool {
        self.switch_gap_exceeds(land, 0.0, y[3], switches, slack)
    }

    /// [`Self::ringing_outlasts_switches`] with the onion's angle from the minimum bounded too
    /// ([`settle_distance`], from the slope at `start`, the angles at the onion `y[2]`).
    pub(super) fn settle_outlasts_switches(
        &self,
        land: &Landscape,
        y: &Vector,
        slope: (&Angles, f64, f64),
        switches: (f64, f64),
        slack: f64,
    ) -> bool {
        let angle = settle_distance(land, slope);
        angle > 0.0 && self.switch_gap_exceeds(land, angle, y[3], switches, slack)
    }

    /// Whether the switch test's left-hand side exceeds twice `slack` for every minimum of
    /// curvature at most `K` at least `angle` rad from the onion, its tilt `tilt`.
    fn switch_gap_exceeds(
        &self,
        land: &Landscape,
        angle: f64,
        tilt: f64,
        (to_switch, period): (f64, f64),
        slack: f64,
    ) -> bool {
        let t = self.tilt_stiffness;
        let k = curvature_bound(land);
        // On the tilt alone, half the linearization's trace at `K`, which bounds the rate at `K`
        // too, spares its square root.
        let rate = if angle > 0.0 {
            self.onion_decay_rate(k)
        } else {
            0.5 * self.llg_rate * self.params.gilbert_damping * (k + t)
        };
        if !(k > 0.0 && t > 0.0 && rate > 0.0 && k.is_finite() && rate.is_finite()) {
            return false;
        }
        let memory = 1.0 + 1.0 / (rate * period);
        let gap = (angle * angle + t * tilt * tilt / k).sqrt() * (-rate * to_switch).exp();
        gap * memory > 2.0 * slack
    }

    /// [`Self::settled_minimum`] of the onion at `y` under `d` (eq. 3.4's landscape `land`),
    /// or `None` where the check that places it on that minimum fails whatever minimum the
    /// march returns: then without the march. The check fails where the switch test does
    /// ([`Self::settle_outlasts_switches`]) and, given `remaining` (a locked rotor's onion that
    /// the averaged ringing does not place), where its ringing does not end the segment's
    /// `remaining` time within the tolerance ([`Self::ringing_ends_far`]). The march, where
    /// made, starts from the gradient and curvature that the bounds evaluated.
    pub(super) fn settled_unless_outlasting(
        &self,
        land: &Landscape,
        memo: &SettleMemo,
        (y, d): (&Vector, &Drive),
        (switches, slack): ((f64, f64), f64),
        remaining: Option<f64>,
    ) -> Option<Angles> {
        if let Some(kept) = memo.kept(y, d) {
            return Some(kept);
        }
        let start = land.angles(y[2]);
        let (g0, c0) = land.gradient_curvature_of(&start);
        let angle = settle_distance(land, (&start, g0, c0));
        if angle > 0.0
            && (self.switch_gap_exceeds(land, angle, y[3], switches, slack)
                || remaining.is_some_and(|r| self.ringing_ends_far(land, angle, r)))
        {
            return None;
        }
        Some(memo.get_or(y, d, || land.settle_from_slope(start, g0, c0)))
    }

    /// [`Self::settled_minimum`] of a locked rotor's onion at `y` under `d`, or `None` where
    /// [`Self::ringing_ends_far`] finds that [`Self::locked_ringing_ends`] fails over the
    /// segment's `remaining` time for whatever minimum the march returns: then without the
    /// march, which, where made, starts from the gradient and curvature that the bound evaluated.
    pub(super) fn settled_unless_ringing_on(
        &self,
        memo: &SettleMemo,
        (y, d): (&Vector, &Drive),
        remaining: f64,
    ) -> Option<Angles> {
        if let Some(kept) = memo.kept(y, d) {
            return Some(kept);
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let start = land.angles(y[2]);
        let (g0, c0) = land.gradient_curvature_of(&start);
        let angle = settle_distance(&land, (&start, g0, c0));
        if angle > 0.0 && self.ringing_ends_far(&land, angle, remaining) {
            return None;
        }
        Some(memo.get_or(y, d, || land.settle_from_slope(start, g0, c0)))
    }

    /// Whether [`Self::locked_ringing_ends`] fails on its first test for every minimum of eq.
    /// 3.4 in `land` at least `angle` rad from the onion: that angle decayed over the segment's
    /// `remaining` time (s) at a rate of at most the rate for `K / 2` (the test's rate is the
    /// lesser of those for half and one and a half times the curvature; see the module
    /// documentation) is more than twice the tolerance.
    fn ringing_ends_far(&self, land: &Landscape, angle: f64, remaining: f64) -> bool {
        let rate = self.onion_decay_rate(0.5 * curvature_bound(land));
        rate.is_finite() && angle * (-rate * remaining).exp() > 2.0 * self.params.tolerance
    }
}

/// `K`, the bound on every curvature of eq. 3.4 in `land` (J/rad^2; see the module
/// documentation).
fn curvature_bound(land: &Landscape) -> f64 {
    land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs()
}

/// A lower bound (rad) on the distance from the onion at `start` to whatever point the settle's
/// march (`Landscape::settle_from_slope` from `start`, where eq. 3.4's gradient is `g0` and
/// curvature `c0`) returns, or 0. The march goes one way, downhill, so that distance is at
/// least the lesser of:
/// - its first stride, taken as the march takes it: every later point, and every point of a
///   bracket found later, lies beyond it;
/// - where the first stride brackets the minimum, the distance to the nearest point where the
///   slope can vanish, `|U'(psi)| / K` (mean value theorem, `|U''| <= K`), less the slope's
///   rounding and the refinement's tolerance: the refinement returns a point within that
///   tolerance of a sign change of the slope. (Out of iterations it would return its last
///   iterate, the one end not covered; its safeguarded Newton steps, none of which widens the
///   bracket, converge long before.)
///
/// Without a slope beyond rounding the march stays at the start (and a stride of zero, or one
/// lost to rounding, keeps it there): 0 then.
fn settle_distance(land: &Landscape, (start, g0, c0): (&Angles, f64, f64)) -> f64 {
    let k = curvature_bound(land);
    let tiny = land.gradient_tolerance();
    let m = land.third_derivative_bound();
    if !(g0.abs() > tiny && m.is_finite() && m > 0.0 && k > 0.0 && k.is_finite()) {
        return 0.0;
    }
    // The march's first stride (`Landscape::settle_from_slope`), and where it ends.
    let dir = if g0 > tiny { -1.0 } else { 1.0 };
    let a = (-dir * g0).max(0.0);
    let newton = a / c0;
    let stride = if c0 > 0.0 && newton < 0.99 * c0 / m {
        newton
    } else {
        downhill_stride(a, c0, m).0
    };
    if !(stride.is_finite() && stride > 0.0) {
        return 0.0;
    }
    let first = ((start.onion + dir * stride) - start.onion).abs();
    // The slope's rounding (its torques' relative rounding on a scale of `K` rad) and the
    // refinement's tolerance, with margins.
    let rounding = 4.0 * (tiny + 1e-12 * k);
    let root = 8.0 * land.root_tolerance(start.onion.abs() + stride);
    let distance = first.min((a - rounding) / k - root);
    if distance > 0.0 {
        distance
    } else {
        0.0
    }
}
