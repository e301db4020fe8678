//! Whether a Gilbert onion that a step cannot afford to resolve may be put on its quasi-static
//! branch: only if it heads for the branch's minimum within the step anyway.

use super::{Motor, Vector};
use crate::physics::numerics::expm2::expm2;

impl Motor {
    /// Whether the Gilbert onion at `y` heads for the `minimum` of eq. 3.4 it sits in (the one
    /// it settles into, curvature `k` there) within `horizon` seconds (the step, or what is
    /// left of it): its ringing decays by a factor `e` at least over that time
    /// (`lambda horizon >= 1`, `lambda` [`Self::onion_decay_rate`] at `k`), or ends within the
    /// tolerance of the minimum (its distance in the energy's norm, `sqrt(dpsi^2 + t theta^2 / k)`,
    /// times `exp(-lambda horizon)`).
    ///
    /// An onion that does not cannot follow the strain within the step at all; putting it on the
    /// quasi-static branch would turn it with the strain at every switch where the resolved onion
    /// barely moves: 38.5 rad off after a 1 us step on a 1.26 ns schedule (`lambda T` 4e-6).
    pub(super) fn heads_for_minimum(&self, y: &Vector, minimum: f64, k: f64, horizon: f64) -> bool {
        if k.is_nan() || k <= 0.0 {
            return false;
        }
        let decay = self.onion_decay_rate(k) * horizon;
        decay >= 1.0 || self.decayed_gap(y, minimum, k, horizon) <= self.params.tolerance
    }

    /// Whether the Gilbert onion at `y` ends `horizon` seconds (what is left of the step) within
    /// the tolerance of the `minimum` of eq. 3.4 it settles into (curvature `k` there): its
    /// decayed distance ([`Self::decayed_gap`]), and its angle and tilt carried to the step's end
    /// by the linearization there ([`Self::propagated_gap`]). A step that drops the onion's
    /// ringing unflagged reports the minimum at its end, so the ringing must have decayed to the
    /// tolerance by then, not merely by a factor `e` ([`Self::heads_for_minimum`], which serves
    /// the flagged budget drop): an onion started 0.039 rad from a minimum that it approaches at
    /// `lambda = 1e6 /s` ended a 1 us step 0.014 rad (4,300 tolerances) off a plain RK4.
    ///
    /// The tolerance bounds the angle and the tilt alike, while the energy's norm weighs the tilt
    /// by `sqrt(t / k)`: an onion settled in angle, its tilt 3.35 rad in a well `2.7e9` times
    /// stiffer than the tilt, decays at `lambda = 2.9e6 /s` to 0.18 rad by the end of a 1 us
    /// step, which its norm's distance put within the tolerance.
    pub(super) fn ends_at_minimum(&self, y: &Vector, minimum: f64, k: f64, horizon: f64) -> bool {
        let tol = self.params.tolerance;
        k > 0.0
            && self.decayed_gap(y, minimum, k, horizon) <= tol
            && self.propagated_gap(y, minimum, k, horizon) <= tol
    }

    /// The larger of the Gilbert onion's angle from the `minimum` (curvature `k > 0`) and its
    /// tilt after `horizon` seconds of the macrospin's equations linearized there (eq. 3.4's
    /// torque `k (psi - minimum)`; the rates are linear in the tilt), exactly:
    /// `exp(A horizon) (psi - minimum, theta)` with `A = g [[-alpha k, -t], [k, -alpha t]]`
    /// (the rows of [`Self::rhs_jacobian`]); infinite where that exponential is out of range.
    pub(super) fn propagated_gap(&self, y: &Vector, minimum: f64, k: f64, horizon: f64) -> f64 {
        let (g, alpha, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let h = horizon;
        let ah = [
            [-g * alpha * k * h, -g * t * h],
            [g * k * h, -g * alpha * t * h],
        ];
        let Some(e) = expm2(&ah) else {
            return f64::INFINITY;
        };
        let x = [y[2] - minimum, y[3]];
        let end = e.map(|row| row[0] * x[0] + row[1] * x[1]);
        let gap = end[0].abs().max(end[1].abs());
        if gap.is_nan() {
            f64::INFINITY
        } else {
            gap
        }
    }

    /// The Gilbert onion's distance at `y` from the `minimum` of eq. 3.4 (curvature `k > 0`) in
    /// the energy's norm, `sqrt(dpsi^2 + t theta^2 / k)`, after `horizon` seconds of decay at
    /// the slowest rate of its linearization there ([`Self::onion_decay_rate`]).
    pub(super) fn decayed_gap(&self, y: &Vector, minimum: f64, k: f64, horizon: f64) -> f64 {
        let t = self.tilt_stiffness;
        let gap = ((minimum - y[2]).powi(2) + t * y[3] * y[3] / k).sqrt();
        gap * (-self.onion_decay_rate(k) * horizon).exp()
    }
}
