//! The exact wall (`bladder_model` 3): the incompressible Mooney-Rivlin tube of eq. 2.8 solved
//! exactly through its thickness (Rivlin's integral), under the assumptions of section 2.2.2: a
//! long cylinder with uniform axial stretch `lambda_1 = L / L_R0` (eq. 2.8a), the outer wall at the
//! sleeve's diameter in contact, no end effects.
//!
//! Incompressibility fixes every material circle: a circle of relaxed diameter `s` has the
//! deformed diameter `d` with `d^2 = x^2 - (D_RO^2 - s^2) / lambda_1` (eq. 2.20), `x` the outer
//! diameter, so its stretches are `lambda_2 = d / s` and `lambda_3 = 1 / (lambda_1 lambda_2)`.
//! Radial equilibrium of the thick tube, `d sigma_rr / dr = (sigma_tt - sigma_rr) / r`, with the
//! Mooney-Rivlin difference `h = sigma_tt - sigma_rr` of eq. 2.9b, gives the pressure through the
//! wall `p(r) = P - int_{r_in}^r h dr'/r'`, so the contact pressure on the sleeve is
//!
//! `P_eff = P - int h dr / r` (over the deformed wall),
//!
//! where eq. 2.12 and 2.19 keep a term `p_out (d_out - d_in)` that is first order in the wall's
//! thickness (their recursion's limit is `dp/dr = (p - h)/r`; see `continuum.rs`). The rubber's
//! axial force is `N = int (g - p) 2 pi r dr` with `g = sigma_zz - sigma_rr` of eq. 2.9a; by
//! exchanging the order of integration
//!
//! `N = int g 2 pi r dr + int h pi (r_o^2 - r^2) / r dr - P V_R / L`.
//!
//! With no stiffness (`C1 = C2 = 0`) `P_eff = P` and `N = -P V_R / L`, and the muscle's force
//! (eq. 2.16 + 2.17) is eq. 2.3 exactly: the rubber only takes up volume.
//!
//! In the squared deformed diameter `u = d^2`, `dr / r = du / (2u)` and `2 pi r dr = pi/4 du`, so
//! the wall is three smooth integrals in `u`, evaluated by the same Gauss-Legendre nodes (placed
//! evenly in the logarithm of the distance to the nearer singular point) as the continuum wall.

use super::continuum::KernelScalar;
use super::continuum::{WallCall, WallWeight};
use super::{Bladder, InnerLayer, Kernel, SleeveGeometry};
use crate::physics::numerics::dual::Dual;
use std::f64::consts::PI;

impl<S: SleeveGeometry> Bladder<S> {
    /// The exact wall at muscle length `l` and outer diameter `x`: `a = 1`, `c = int h dr / r`,
    /// the rubber's axial force `N`. `None` where a squared hoop stretch is not positive or not
    /// finite (outside the geometry).
    pub(super) fn exact_kernel<T: KernelScalar>(
        &self,
        pressure: f64,
        l: T,
        x: T,
    ) -> Option<Kernel<T>> {
        self.exact_parts::<T, false>(pressure, l, x).map(|(k, _)| k)
    }

    /// The exact wall's axial force at a free root, `P_eff = 0`: with `P = int h dr / r` there,
    /// `N = int g 2 pi r dr - int h pi r dr + P pi r_in^2` (the pressure through the wall taken
    /// from the outside in), without the `x^2 P` that both of the kernel's terms carry and that
    /// cancel to the root's residual. A function of `(L, x)` only. `None` outside the geometry.
    pub(super) fn exact_free_elastic(&self, l: Dual, x: Dual) -> Option<Dual> {
        self.exact_parts::<Dual, true>(0.0, l, x)?.1
    }

    /// [`Self::exact_kernel`], with [`Self::exact_free_elastic`] at `(L, x)` if `AT_ROOT`
    /// (decided at compile time: the kernel's own calls compute nothing more).
    #[inline(always)]
    fn exact_parts<T: KernelScalar, const AT_ROOT: bool>(
        &self,
        pressure: f64,
        l: T,
        x: T,
    ) -> Option<(Kernel<T>, Option<T>)> {
        let c1x2 = 2.0 * self.tube.mooney_c1;
        let c2x2 = 2.0 * self.tube.mooney_c2;
        let lambda1 = l * (1.0 / self.tube.unstretched_length);
        let inv_lambda1 = lambda1.recip();
        let lambda1_sq = lambda1 * lambda1;
        let inv_lambda1_sq = inv_lambda1 * inv_lambda1;
        let x_sq = x * x;
        let d_ri_sq = self.tube.inner_diameter * self.tube.inner_diameter;
        let d_ro_sq = self.outer_diameter * self.outer_diameter;
        // The inner wall, exactly (eq. 2.20 at s = D_RI).
        let d_in_sq = x_sq - inv_lambda1 * (d_ro_sq - d_ri_sq);
        let l2_in = d_in_sq * (1.0 / d_ri_sq);
        let inv_l2_in = d_in_sq.recip() * d_ri_sq;
        if !(l2_in.value() > 0.0 && l2_in.value().is_finite() && inv_l2_in.value().is_finite()) {
            return None;
        }
        // Eq. 2.9b and 2.9a: with l3^2 = 1/(lambda_1^2 l2^2) the hoop difference is
        // l2^2 A - B / l2^2 and the axial one G + l2^2 A' - B' / l2^2, with A, B, A', B', G fixed
        // per call: so the nodes only add up l2^2 and 1/l2^2 with two weights each.
        let c2_lambda = lambda1_sq * c2x2;
        let c1_over_lambda = inv_lambda1_sq * c1x2;
        let (hoop_a, hoop_b) = (c2_lambda + c1x2, c1_over_lambda + c2x2);
        let axial_const = lambda1_sq * c1x2 - inv_lambda1_sq * c2x2;
        let hoop_in = l2_in * hoop_a - inv_l2_in * hoop_b;
        let axial_in = axial_const + l2_in * c2_lambda - inv_l2_in * c1_over_lambda;
        let call = WallCall::new(lambda1, x_sq, d_in_sq, d_ro_sq, WallWeight::PerSquare);
        let sums = T::wall_sums(&self.nodes, &call)?;
        let span = sums.span;
        // int h du / (2u) = int h dr / r, int h du / 2 and int g du / 2 (each / span).
        let h_per_u = sums.l2_h * hoop_a - sums.inv_l2_h * hoop_b;
        let hoop_sum = sums.l2 * hoop_a - sums.inv_l2 * hoop_b;
        let axial_sum = sums.jac * axial_const + sums.l2 * c2_lambda - sums.inv_l2 * c1_over_lambda;
        let c = h_per_u * span;
        let p_eff = c * -1.0 + pressure;
        // The deformed rubber's cross-section, V_R / L (incompressibility).
        let rubber_area = (x_sq - d_in_sq) * (PI / 4.0);
        // pi/4 int g du + pi/8 (x^2 int h du / u - int h du) - P V_R / L.
        let elastic = (axial_sum * (PI / 2.0) + (x_sq * h_per_u - hoop_sum) * (PI / 4.0)) * span
            - rubber_area * pressure;
        let at_root = AT_ROOT
            .then(|| (axial_sum * (PI / 2.0) + (d_in_sq * h_per_u - hoop_sum) * (PI / 4.0)) * span);
        let kernel = Kernel {
            a: T::constant(1.0),
            c,
            p_eff,
            threshold: c.value(),
            elastic,
            // Only the last term of `elastic` depends on P (at fixed L and x).
            elastic_dp: [rubber_area, T::constant(1.0)],
            inner: InnerLayer {
                l2_sq: l2_in,
                axial: axial_in,
                hoop: hoop_in,
            },
        };
        Some((kernel, at_root))
    }
}
