//! The continuum wall (`bladder_model` 3): the limit of the layered wall of eq. 2.19-2.20 as the
//! number of layers grows without bound, integrated through the wall by Gauss-Legendre quadrature.
//!
//! In the limit the layer recursion (eq. 2.12 per layer, `p_out = p_in (1 + k) - h k` with
//! `k = lambda_3 Delta D / (lambda_2 D_0)` and `h = sigma_22 - sigma_33` the Mooney-Rivlin hoop
//! difference of eq. 2.9b) becomes the linear ODE `dp/ds = kappa(s) (p - h(s))` through the
//! unstretched diameter `s` from `D_RI` to `D_RO`, with `kappa = 1 / (lambda_1 lambda_2^2 s)`.
//! Incompressibility (eq. 2.20) makes the deformed diameter `d(s) = lambda_2 s` satisfy
//! `d d' = s / lambda_1`, so `kappa = d'/d` and the ODE integrates in closed form:
//!
//! `p(s) = d(s) (P / d_in - G(s))`, with `G(s) = int_{D_RI}^s g`, `g = h d' / d^2`,
//!
//! hence `P_eff = (x / d_in) P - x G(D_RO)` (`x` the outer diameter). The rubber's axial force
//! (eq. 2.17 summed over the layers) `int (sigma_axial - p) w ds` with `w = pi s L_R0 / (2 L)`
//! reduces, by exchanging the order of integration and `int_t^{D_RO} d w ds = pi/6 (x^3 - d(t)^3)`,
//! to single integrals of node-local terms. So the whole wall is three smooth integrals over the
//! unstretched wall, and an `n`-point Gauss-Legendre rule converges like `rho^-2n` where the
//! layered sum (a left Riemann sum) converges like `1/n`.

use super::hyper_dual::KernelScalar;
use super::{Bladder, InnerLayer, Kernel, SleeveGeometry};
use std::f64::consts::PI;

/// Nodes whose positions are computed ahead of their algebra, at a time (stack buffer).
const NODE_CHUNK: usize = 16;

/// One Gauss-Legendre node on `[0, 1]`: where it sits between the inner and the outer wall in
/// the logarithm of the deformed diameter, and its weight (the weights sum to 1).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct WallNode {
    pub(super) at: f64,
    pub(super) weight: f64,
}

/// Gauss-Legendre nodes and weights on `[-1, 1]` (Newton on the Legendre polynomial from the
/// Tricomi initial guess; at initialization only, `O(n^2)`).
pub(super) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // Three-term recurrence for P_n(x) and its derivative.
            let (mut p0, mut p1) = (1.0, x);
            if n == 1 {
                p1 = x;
                p0 = 1.0;
            } else {
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / dp;
            x -= step;
            if step.abs() <= 1e-16 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// `nodes` Gauss-Legendre nodes on `[0, 1]`.
pub(super) fn wall_nodes(nodes: usize) -> Vec<WallNode> {
    gauss_legendre(nodes)
        .into_iter()
        .map(|(u, w)| WallNode {
            at: 0.5 * (1.0 + u),
            weight: 0.5 * w,
        })
        .collect()
}

impl<S: SleeveGeometry> Bladder<S> {
    /// The continuum wall at muscle length `l` and outer diameter `x`: the same [`Kernel`] as the
    /// layer recursion, from the closed form above. `None` where a squared hoop stretch is not
    /// positive or not finite.
    pub(super) fn continuum_kernel<T: KernelScalar>(
        &self,
        pressure: f64,
        l: T,
        x: T,
    ) -> Option<Kernel<T>> {
        let c1x2 = 2.0 * self.tube.mooney_c1;
        let c2x2 = 2.0 * self.tube.mooney_c2;
        let lambda1 = l * (1.0 / self.tube.unstretched_length);
        let inv_lambda1 = lambda1.recip();
        let lambda1_sq = lambda1 * lambda1;
        let inv_lambda1_sq = inv_lambda1 * inv_lambda1;
        let x_sq = x * x;
        let x_cu = x_sq * x;
        // The hoop and axial Mooney-Rivlin differences at a squared hoop stretch (eq. 2.9b, 2.9a
        // without the radial stress).
        let mooney = |l2_sq: T, inv_l2_sq: T| {
            let (v, inv) = (l2_sq.value(), inv_l2_sq.value());
            if !(v > 0.0 && v.is_finite() && inv.is_finite()) {
                return None;
            }
            let l3_sq = inv_lambda1_sq * inv_l2_sq;
            let inv_l3_sq = lambda1_sq * l2_sq;
            let hoop = (l2_sq - l3_sq) * c1x2 - (inv_l2_sq - inv_l3_sq) * c2x2;
            let axial = (lambda1_sq - l3_sq) * c1x2 - (inv_lambda1_sq - inv_l3_sq) * c2x2;
            Some((hoop, axial))
        };
        let d_ri = self.tube.inner_diameter;
        let d_ro = self.outer_diameter;
        // The inner wall, exactly (eq. 2.20 at s = D_RI).
        let d_in_sq = x_sq - inv_lambda1 * (d_ro * d_ro - d_ri * d_ri);
        let l2_in = d_in_sq * (1.0 / (d_ri * d_ri));
        let (hoop_in, axial_in) = mooney(l2_in, l2_in.recip())?;
        let d_in = d_in_sq.sqrt();
        let inv_d_in = d_in.recip();
        let zero = T::constant(0.0);
        // Through the wall in the squared deformed diameter u = d^2 (du = 2 s ds / lambda_1):
        // int g ds = int h / (2 d^3) du, int g Phi ds = pi/6 int h (x^3 - d^3) / (2 d^3) du and
        // int sigma_axial w ds = pi/4 int sigma_axial du. The integrands are singular where d = 0
        // and where s = 0 (u_s = x^2 - D_RO^2 / lambda_1), both below the wall; the nearer one
        // approaches the inner wall as it collapses (d_in -> 0, near the fill limit) or as the
        // wall's own bore dominates. So the nodes are placed evenly in ln(u - u_0) with u_0 the
        // nearer singular point: each integrand is then smooth on the scale of the interval.
        let u_s = x_sq - lambda1.recip() * (d_ro * d_ro);
        let u_0 = if u_s.value() > 0.0 { u_s } else { zero };
        let (inner_gap, outer_gap) = (d_in_sq - u_0, x_sq - u_0);
        let ln_in = inner_gap.ln();
        let span = outer_gap.ln() - ln_in;
        // With l3^2 = 1/(lambda_1^2 l2^2), eq. 2.9b's hoop difference is l2^2 A - B / l2^2 and the
        // node-dependent part of the axial one l2^2 A' - B' / l2^2, with A, B, A', B' fixed per
        // call: so the nodes only add up l2^2 and 1/l2^2 with two weights each.
        let c2_lambda = lambda1_sq * c2x2;
        let c1_over_lambda = inv_lambda1_sq * c1x2;
        let (mut jac_sum, mut l2_sum, mut inv_l2_sum) = (zero, zero, zero);
        let (mut l2_h_sum, mut inv_l2_h_sum) = (zero, zero);
        // The node positions first, then the nodes' algebra: with the libm `exp` calls out of
        // the second loop, the nodes' square roots and divisions (independent from node to node)
        // overlap in the pipeline instead of waiting on each other behind every call; the
        // kernel was latency-bound.
        let mut positions = [zero; NODE_CHUNK];
        let n = self.nodes.len();
        for chunk in self.nodes.chunks(NODE_CHUNK) {
            if n == chunk.len() {
                // The nodes are symmetric (`at` and `1 - at`), so a node's `u - u_0` times its
                // mirror's is `(d_in^2 - u_0)(x^2 - u_0)`: half the `exp` calls.
                let product = inner_gap * outer_gap;
                for i in 0..n.div_ceil(2) {
                    let e = (ln_in + span * chunk[i].at).exp();
                    positions[i] = e;
                    positions[n - 1 - i] = product * e.recip();
                }
            } else {
                for (slot, node) in positions.iter_mut().zip(chunk) {
                    *slot = (ln_in + span * node.at).exp();
                }
            }
            for (&e, node) in positions.iter().zip(chunk) {
                let u = u_0 + e;
                // Two divisions per node: 1/sqrt(u) gives 1/d^3 and 1/u, and 1/s^2.
                let inv_d = u.rsqrt();
                let inv_u = inv_d * inv_d;
                // s^2 = D_RO^2 - lambda_1 (x^2 - u) (eq. 2.20 solved for the unstretched diameter).
                let s_sq = (u - x_sq) * lambda1 + d_ro * d_ro;
                let l2_sq = u * s_sq.recip();
                let inv_l2_sq = s_sq * inv_u;
                if !(l2_sq.value() > 0.0
                    && l2_sq.value().is_finite()
                    && inv_l2_sq.value().is_finite())
                {
                    return None;
                }
                let jacobian = e * (node.weight * 0.5);
                let (l2_term, inv_l2_term) = (l2_sq * jacobian, inv_l2_sq * jacobian);
                let per_d3 = inv_u * inv_d;
                jac_sum = jac_sum + jacobian;
                l2_sum = l2_sum + l2_term;
                inv_l2_sum = inv_l2_sum + inv_l2_term;
                l2_h_sum = l2_h_sum + l2_term * per_d3;
                inv_l2_h_sum = inv_l2_h_sum + inv_l2_term * per_d3;
            }
        }
        let (hoop_a, hoop_b) = (c2_lambda + c1x2, c1_over_lambda + c2x2);
        // int h / (2 d^3) du, int h du / 2 and int sigma_axial du / 2 over the nodes.
        let h_sum = l2_h_sum * hoop_a - inv_l2_h_sum * hoop_b;
        // h (x^3 - d^3) / (2 d^3) = x^3 h / (2 d^3) - h / 2: the first part is x^3 h_sum.
        let hoop_sum = l2_sum * hoop_a - inv_l2_sum * hoop_b;
        let axial_sum = jac_sum * (lambda1_sq * c1x2 - inv_lambda1_sq * c2x2) + l2_sum * c2_lambda
            - inv_l2_sum * c1_over_lambda;
        let h_phi_sum = x_cu * h_sum - hoop_sum;
        let a = x * inv_d_in;
        let c = x * h_sum * span;
        let p_eff = a * pressure - c;
        // int sigma_axial w ds - int p w ds, with int p w ds = P Phi(D_RI) / d_in - int g Phi ds.
        let phi_in = (x_cu - d_in_sq * d_in) * (PI / 6.0);
        let elastic =
            (axial_sum * (PI / 2.0) + h_phi_sum * (PI / 6.0)) * span - phi_in * inv_d_in * pressure;
        Some(Kernel {
            a,
            c,
            p_eff,
            threshold: c.value() / a.value(),
            elastic,
            // Only the last term of `elastic` depends on P (at fixed L and x).
            elastic_dp: [phi_in, inv_d_in],
            inner: InnerLayer {
                l2_sq: l2_in,
                axial: axial_in,
                hoop: hoop_in,
            },
        })
    }
}
