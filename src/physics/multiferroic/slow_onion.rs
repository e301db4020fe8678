//! Whether a Gilbert onion that a step cannot afford to resolve may be put on its quasi-static
//! branch: only if it heads for the branch's minimum within the step anyway.

use super::{Drive, Motor, Vector};

impl Motor {
    /// The slower decay rate (1/s) of the Gilbert onion's linearized motion about a minimum of
    /// eq. 3.4 whose curvature is `k` (J/rad^2 per unit volume of the landscape): the onion block
    /// of the Jacobian has trace `-g a (k + t)` and determinant `g^2 (1 + a^2) k t`, with `g` the
    /// gyromagnetic rate, `a` the Gilbert damping and `t` the tilt stiffness.
    pub(super) fn slowest_onion_decay(&self, k: f64) -> f64 {
        let (g, a, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let half_trace = 0.5 * g * a * (k + t);
        let det = g * g * (1.0 + a * a) * k * t;
        let disc = half_trace * half_trace - det;
        if disc > 0.0 {
            det / (half_trace + disc.sqrt())
        } else {
            half_trace
        }
    }

    /// Whether the Gilbert onion at `y` heads for the minimum of eq. 3.4 it sits in for the drive
    /// `d` within `horizon` seconds (the step, or what is left of it): its ringing decays by a
    /// factor `e` at least over that time (`lambda horizon >= 1`, `lambda`
    /// [`Self::slowest_onion_decay`] at the minimum's curvature `k`), or ends within the
    /// tolerance of the minimum (its distance in the energy's norm, `sqrt(dpsi^2 + t theta^2 / k)`,
    /// times `exp(-lambda horizon)`).
    ///
    /// An onion that does not cannot follow the strain within the step at all; putting it on the
    /// quasi-static branch turned it with the strain at every switch where the resolved onion
    /// barely moves: 38.5 rad off after a 1 us step on a 1.26 ns schedule (`lambda T` 4e-6).
    pub(super) fn heads_for_minimum(&self, y: &Vector, d: &Drive, horizon: f64) -> bool {
        let land = self.landscape(y[0], d.direction, d.stress);
        let minimum = land.settle(y[2]);
        let k = land.curvature(minimum);
        if k.is_nan() || k <= 0.0 {
            return false;
        }
        let decay = self.slowest_onion_decay(k) * horizon;
        if decay >= 1.0 {
            return true;
        }
        let t = self.tilt_stiffness;
        let gap = ((minimum - y[2]).powi(2) + t * y[3] * y[3] / k).sqrt();
        gap * (-decay).exp() <= self.params.tolerance
    }
}
