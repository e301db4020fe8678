//! Whether a Gilbert onion that a step cannot afford to resolve may be put on its quasi-static
//! branch: only if it heads for the branch's minimum within the step anyway.

use super::{Motor, Vector};

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
    /// decayed distance ([`Self::decayed_gap`]). A step that drops the onion's ringing unflagged
    /// reports the minimum at its end, so the ringing must have decayed to the tolerance by
    /// then, not merely by a factor `e` ([`Self::heads_for_minimum`], which serves the flagged
    /// budget drop): an onion started 0.039 rad from a minimum that it approaches at
    /// `lambda = 1e6 /s` ended a 1 us step 0.014 rad (4,300 tolerances) off a plain RK4.
    pub(super) fn ends_at_minimum(&self, y: &Vector, minimum: f64, k: f64, horizon: f64) -> bool {
        k > 0.0 && self.decayed_gap(y, minimum, k, horizon) <= self.params.tolerance
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
