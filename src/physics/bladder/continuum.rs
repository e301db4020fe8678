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

use super::{Bladder, InnerLayer, Kernel, SleeveGeometry};
use crate::physics::numerics::dual::Dual;
use std::f64::consts::{LOG2_E, PI};
use std::ops::{Add, Mul, Sub};

/// The number the layer recursion and the continuum quadrature are written over: [`Dual`] for
/// every step and first-order partial, [`HyperDual`](crate::physics::numerics::hyper_dual::HyperDual)
/// only when the partials of `stiffness` (itself `dF/dL`) are asked for (the impls are in
/// `kernel_scalar.rs`). It needs arithmetic and the few elementary functions the kernel calls.
pub(super) trait KernelScalar:
    Copy
    + Add<Output = Self>
    + Add<f64, Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Mul<f64, Output = Self>
{
    fn constant(v: f64) -> Self;
    fn value(self) -> f64;
    fn recip(self) -> Self;
    fn ln(self) -> Self;
    fn exp(self) -> Self;
    fn rsqrt(self) -> Self;
    fn sqrt(self) -> Self;
    /// The continuum wall's sums over its quadrature nodes.
    fn wall_sums(nodes: &[WallNode], call: &WallCall<Self>) -> Option<WallSums<Self>> {
        node_sums(nodes, call)
    }
}

/// Nodes whose positions are computed ahead of their algebra, at a time (stack buffer).
const NODE_CHUNK: usize = 16;
/// Mirror pairs of nodes per block of the [`Dual`] path: its 8 nodes are 8 independent lanes.
const PAIRS: usize = 4;
const LANES: usize = 2 * PAIRS;
/// Largest `ln(outer gap / inner gap)` of the [`Dual`] path: keeps `|span t| <= 700`, so that
/// [`exp_pairs`]'s powers of two stay normal. (A ratio of e^1400 is not met in practice; beyond
/// it the generic path takes over.)
const MAX_SPAN: f64 = 1400.0;

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

/// What the node sums depend on at one call (functions of the muscle length and outer diameter).
#[derive(Clone, Copy)]
pub(super) struct WallCall<T> {
    lambda1: T,
    x_sq: T,
    d_ro_sq: f64,
    /// The singular point the nodes are placed from (see [`Bladder::continuum_kernel`]).
    u_0: T,
    /// `d_in^2 - u_0` and `x^2 - u_0`.
    inner_gap: T,
    outer_gap: T,
    /// The power of `u` the weighted sums divide by: 3/2 for this wall's `1/d^3`, 1 for the
    /// exact wall's `dr/r = du / (2u)` (see `exact.rs`).
    pub(super) weight: WallWeight,
}

/// What the weighted node sums divide by.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum WallWeight {
    /// `1/d^3 = u^(-3/2)`: this wall's closed form.
    PerCube,
    /// `1/u`: the exact wall's `dr/r`.
    PerSquare,
}

impl WallWeight {
    fn power(self) -> f64 {
        match self {
            Self::PerCube => 1.5,
            Self::PerSquare => 1.0,
        }
    }
}

impl<T: KernelScalar> WallCall<T> {
    /// The call at axial stretch `lambda1`, squared outer and inner diameters `x_sq`, `d_in_sq`,
    /// for a tube of squared relaxed outer diameter `d_ro_sq`. The integrands are singular where
    /// `d = 0` and where `s = 0` (`u_s = x^2 - D_RO^2 / lambda_1`), both below the wall; the nearer
    /// one approaches the inner wall as it collapses (`d_in -> 0`, near the fill limit) or as the
    /// wall's own bore dominates. So the nodes are placed evenly in `ln(u - u_0)` with `u_0` the
    /// nearer singular point: each integrand is then smooth on the scale of the interval.
    pub(super) fn new(lambda1: T, x_sq: T, d_in_sq: T, d_ro_sq: f64, weight: WallWeight) -> Self {
        let u_s = x_sq - lambda1.recip() * d_ro_sq;
        let u_0 = if u_s.value() > 0.0 {
            u_s
        } else {
            T::constant(0.0)
        };
        Self {
            lambda1,
            x_sq,
            d_ro_sq,
            u_0,
            inner_gap: d_in_sq - u_0,
            outer_gap: x_sq - u_0,
            weight,
        }
    }
}

/// `span = ln(outer_gap / inner_gap)` and the node sums (each still to be multiplied by `span`):
/// the jacobian `e w / 2` (`e = u - u_0`, `w` the weight) alone and times `l2^2`, `1/l2^2`,
/// `l2^2 q` and `q / l2^2` with `q` the [`WallWeight`].
pub(super) struct WallSums<T> {
    pub(super) span: T,
    pub(super) jac: T,
    pub(super) l2: T,
    pub(super) inv_l2: T,
    pub(super) l2_h: T,
    pub(super) inv_l2_h: T,
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
        self.continuum_parts::<T, false>(pressure, l, x)
            .map(|(k, _)| k)
    }

    /// The continuum wall's elastic force at a free root, `P_eff = 0` (eq. 2.17 through the
    /// wall): with `P / d_in = G(D_RO)` there, the pressure through the wall is taken from the
    /// outside in, `p(s) = d(s) (G(D_RO) - G(s))`, and `int p w ds = G(D_RO) Phi(D_RI) - int g Phi ds`
    /// loses the `x^3 G(D_RO)` both of its terms carry. Written with `P / d_in`, as the kernel
    /// does for any `x`, those terms cancel to the root's residual: where a vacuum has pulled
    /// the bore nearly closed, `G(D_RO)` is huge and a root known to rounding leaves the force
    /// wrong by newtons. A function of `(L, x)` only. `None` outside the geometry.
    pub(super) fn continuum_free_elastic(&self, l: Dual, x: Dual) -> Option<Dual> {
        self.continuum_parts::<Dual, true>(0.0, l, x)?.1
    }

    /// [`Self::continuum_kernel`], with [`Self::continuum_free_elastic`] at `(L, x)` if `AT_ROOT`
    /// (decided at compile time: the kernel's own calls compute nothing more).
    #[inline(always)]
    fn continuum_parts<T: KernelScalar, const AT_ROOT: bool>(
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
        // One division for 1/d_in and 1/l2_in.
        let d_in = d_in_sq.sqrt();
        let inv_d_in = d_in.recip();
        let (hoop_in, axial_in) = mooney(l2_in, inv_d_in * inv_d_in * (d_ri * d_ri))?;
        // Through the wall in the squared deformed diameter u = d^2 (du = 2 s ds / lambda_1):
        // int g ds = int h / (2 d^3) du, int g Phi ds = pi/6 int h (x^3 - d^3) / (2 d^3) du and
        // int sigma_axial w ds = pi/4 int sigma_axial du.
        let call = WallCall::new(lambda1, x_sq, d_in_sq, d_ro * d_ro, WallWeight::PerCube);
        let sums = T::wall_sums(&self.nodes, &call)?;
        let span = sums.span;
        // With l3^2 = 1/(lambda_1^2 l2^2), eq. 2.9b's hoop difference is l2^2 A - B / l2^2 and the
        // node-dependent part of the axial one l2^2 A' - B' / l2^2, with A, B, A', B' fixed per
        // call: so the nodes only add up l2^2 and 1/l2^2 with two weights each.
        let c2_lambda = lambda1_sq * c2x2;
        let c1_over_lambda = inv_lambda1_sq * c1x2;
        let (hoop_a, hoop_b) = (c2_lambda + c1x2, c1_over_lambda + c2x2);
        // int h / (2 d^3) du, int h du / 2 and int sigma_axial du / 2 over the nodes.
        let h_sum = sums.l2_h * hoop_a - sums.inv_l2_h * hoop_b;
        // h (x^3 - d^3) / (2 d^3) = x^3 h / (2 d^3) - h / 2: the first part is x^3 h_sum.
        let hoop_sum = sums.l2 * hoop_a - sums.inv_l2 * hoop_b;
        let axial_sum = sums.jac * (lambda1_sq * c1x2 - inv_lambda1_sq * c2x2)
            + sums.l2 * c2_lambda
            - sums.inv_l2 * c1_over_lambda;
        let h_phi_sum = x_cu * h_sum - hoop_sum;
        let a = x * inv_d_in;
        let c = x * h_sum * span;
        let p_eff = a * pressure - c;
        // int sigma_axial w ds - int p w ds, with int p w ds = P Phi(D_RI) / d_in - int g Phi ds.
        let phi_in = (x_cu - d_in_sq * d_in) * (PI / 6.0);
        let elastic =
            (axial_sum * (PI / 2.0) + h_phi_sum * (PI / 6.0)) * span - phi_in * inv_d_in * pressure;
        let at_root = AT_ROOT.then(|| {
            (axial_sum * (PI / 2.0) + (d_in_sq * d_in * h_sum - hoop_sum) * (PI / 6.0)) * span
        });
        let kernel = Kernel {
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
        };
        Some((kernel, at_root))
    }
}

/// The node sums for any [`KernelScalar`] (the second order, and the [`Dual`] path's fallback):
/// node by node, with libm's `exp`.
pub(super) fn node_sums<T: KernelScalar>(
    nodes: &[WallNode],
    call: &WallCall<T>,
) -> Option<WallSums<T>> {
    let WallCall {
        lambda1,
        x_sq,
        d_ro_sq,
        u_0,
        inner_gap,
        outer_gap,
        weight,
    } = *call;
    let zero = T::constant(0.0);
    let ln_in = inner_gap.ln();
    let span = outer_gap.ln() - ln_in;
    let (mut jac_sum, mut l2_sum, mut inv_l2_sum) = (zero, zero, zero);
    let (mut l2_h_sum, mut inv_l2_h_sum) = (zero, zero);
    // The node positions first, then the nodes' algebra: with the libm `exp` calls out of
    // the second loop, the nodes' square roots and divisions (independent from node to node)
    // overlap in the pipeline instead of waiting on each other behind every call.
    let mut positions = [zero; NODE_CHUNK];
    let n = nodes.len();
    for chunk in nodes.chunks(NODE_CHUNK) {
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
            let s_sq = (u - x_sq) * lambda1 + d_ro_sq;
            let l2_sq = u * s_sq.recip();
            let inv_l2_sq = s_sq * inv_u;
            if !(l2_sq.value() > 0.0 && l2_sq.value().is_finite() && inv_l2_sq.value().is_finite())
            {
                return None;
            }
            let jacobian = e * (node.weight * 0.5);
            let (l2_term, inv_l2_term) = (l2_sq * jacobian, inv_l2_sq * jacobian);
            let per = match weight {
                WallWeight::PerCube => inv_u * inv_d,
                WallWeight::PerSquare => inv_u,
            };
            jac_sum = jac_sum + jacobian;
            l2_sum = l2_sum + l2_term;
            inv_l2_sum = inv_l2_sum + inv_l2_term;
            l2_h_sum = l2_h_sum + l2_term * per;
            inv_l2_h_sum = inv_l2_h_sum + inv_l2_term * per;
        }
    }
    Some(WallSums {
        span,
        jac: jac_sum,
        l2: l2_sum,
        inv_l2: inv_l2_sum,
        l2_h: l2_h_sum,
        inv_l2_h: inv_l2_h_sum,
    })
}

/// `(exp(y), exp(-y))` lane by lane for `|y| <= 700`, within 1e-15 relative (tested; 2 ulp seen).
///
/// Hand-written instead of libm's `exp` because the four lanes then run in lock-step in vector
/// registers (libm calls do not vectorize) and one polynomial gives both signs: `y = k ln 2 + r`
/// with `|r| <= ln 2 / 2`, `exp(+-y) = 2^(+-k) (C(r) +- S(r))` with `C` and `S` the even and odd
/// parts of the Taylor series, cut where the next term is below 3e-16 of `exp(r)`.
#[inline(always)]
pub(super) fn exp_pairs(y: [f64; PAIRS]) -> ([f64; PAIRS], [f64; PAIRS]) {
    // 1.5 * 2^52: adding it rounds to an integer held in the low bits of the sum.
    const SHIFT: f64 = 6755399441055744.0;
    // ln 2 in two parts, the first with enough trailing zeros that k ln2_hi is exact.
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let (mut plus, mut minus) = ([0.0; PAIRS], [0.0; PAIRS]);
    for j in 0..PAIRS {
        let shifted = y[j] * LOG2_E + SHIFT;
        let k = shifted - SHIFT;
        let r = (y[j] - k * LN2_HI) - k * LN2_LO;
        let z = r * r;
        // Estrin's scheme (in z, z^2, z^4): a shorter dependency chain than Horner's.
        let (z2, z4) = (z * z, z * z * (z * z));
        let even = (1.0 + z * (1.0 / 2.0) + z2 * (1.0 / 24.0 + z * (1.0 / 720.0)))
            + z4 * ((1.0 / 40320.0 + z * (1.0 / 3628800.0)) + z2 * (1.0 / 479001600.0));
        let odd = r
            * ((1.0 + z * (1.0 / 6.0) + z2 * (1.0 / 120.0 + z * (1.0 / 5040.0)))
                + z4 * (1.0 / 362880.0 + z * (1.0 / 39916800.0)));
        // k itself is the low bits of `shifted`'s representation, less SHIFT's.
        let k_bits = shifted.to_bits().wrapping_sub(SHIFT.to_bits());
        let up = f64::from_bits(k_bits.wrapping_add(1023) << 52);
        let down = f64::from_bits(1023u64.wrapping_sub(k_bits) << 52);
        plus[j] = (even + odd) * up;
        minus[j] = (even - odd) * down;
    }
    (plus, minus)
}

/// The node sums on [`Dual`] numbers (every step and first-order partial): the same sums as
/// [`node_sums`], but 8 nodes at a time as 8 independent lanes (value and both derivatives as
/// separate arrays), so that the compiler keeps them in vector registers, and with
/// [`exp_pairs`] for the positions.
pub(super) fn dual_node_sums(nodes: &[WallNode], call: &WallCall<Dual>) -> Option<WallSums<Dual>> {
    let WallCall {
        lambda1: lam,
        x_sq,
        d_ro_sq,
        u_0,
        inner_gap: inner,
        outer_gap: outer,
        weight: wall_weight,
    } = *call;
    let power = wall_weight.power();
    // The nodes sit at e = u - u_0 = g exp(+-span t), g = sqrt(inner outer), t = at - 1/2, so
    // d ln e = d ln g +- t d span.
    let (inv_in, inv_out) = (1.0 / inner.v, 1.0 / outer.v);
    let span = (outer.v * inv_in).ln();
    let g = (inner.v * outer.v).sqrt();
    if !(span.abs() <= MAX_SPAN && g > 0.0 && g.is_finite()) {
        return node_sums(nodes, call);
    }
    let (ln_in_dl, ln_in_dx) = (inner.dl * inv_in, inner.dx * inv_in);
    let (ln_out_dl, ln_out_dx) = (outer.dl * inv_out, outer.dx * inv_out);
    let span = Dual {
        v: span,
        dl: ln_out_dl - ln_in_dl,
        dx: ln_out_dx - ln_in_dx,
    };
    let (mid_dl, mid_dx) = (0.5 * (ln_in_dl + ln_out_dl), 0.5 * (ln_in_dx + ln_out_dx));
    // u - x^2 = e + (u_0 - x^2).
    let base = u_0 - x_sq;
    let n = nodes.len();
    let pairs = n.div_ceil(2);
    // Lane sums: [jac, l2, inv_l2, l2_h, inv_l2_h] x [value, d/dl, d/dx].
    let mut acc = [[[0.0; LANES]; 3]; 5];
    let mut least = [f64::INFINITY; LANES];
    for first in (0..pairs).step_by(PAIRS) {
        // Lanes j and j + PAIRS are node i and its mirror n - 1 - i; unused lanes weigh 0 (and
        // the middle node of an odd count has no mirror).
        let (mut t, mut weight) = ([0.0; LANES], [0.0; LANES]);
        if first + PAIRS <= n / 2 {
            // A full block of pairs (the usual case): fixed indices, no branches.
            let low = &nodes[first..first + PAIRS];
            let high = &nodes[n - first - PAIRS..n - first];
            for j in 0..PAIRS {
                t[j] = low[j].at - 0.5;
                t[j + PAIRS] = 0.5 - low[j].at;
                weight[j] = 0.5 * low[j].weight;
                weight[j + PAIRS] = 0.5 * high[PAIRS - 1 - j].weight;
            }
        } else {
            for j in 0..PAIRS.min(pairs - first) {
                let i = first + j;
                t[j] = nodes[i].at - 0.5;
                t[j + PAIRS] = -t[j];
                weight[j] = 0.5 * nodes[i].weight;
                if n - 1 - i != i {
                    weight[j + PAIRS] = 0.5 * nodes[n - 1 - i].weight;
                }
            }
        }
        let mut y = [0.0; PAIRS];
        for j in 0..PAIRS {
            y[j] = span.v * t[j];
        }
        let (plus, minus) = exp_pairs(y);
        let mut e = [0.0; LANES];
        for j in 0..PAIRS {
            e[j] = g * plus[j];
            e[j + PAIRS] = g * minus[j];
        }
        for j in 0..LANES {
            let e = e[j];
            // d ln e, which is also d ln(jacobian).
            let (le_dl, le_dx) = (mid_dl + t[j] * span.dl, mid_dx + t[j] * span.dx);
            let u = u_0.v + e;
            let (u_dl, u_dx) = (u_0.dl + e * le_dl, u_0.dx + e * le_dx);
            // s^2 = D_RO^2 - lambda_1 (x^2 - u) (eq. 2.20 solved for the unstretched diameter).
            let diff = base.v + e;
            let (diff_dl, diff_dx) = (base.dl + e * le_dl, base.dx + e * le_dx);
            let s = diff * lam.v + d_ro_sq;
            let (s_dl, s_dx) = (
                diff_dl * lam.v + diff * lam.dl,
                diff_dx * lam.v + diff * lam.dx,
            );
            // One division for 1/sqrt(u) and 1/s^2.
            let root = u.sqrt();
            let w = 1.0 / (s * root);
            let (inv_d, inv_s) = (s * w, root * w);
            let inv_u = inv_d * inv_d;
            let l2 = u * inv_s;
            let inv_l2 = s * inv_u;
            // (Compared as floats, not bits, to stay in vector registers; a non-finite l2 or
            // 1/l2 makes a sum non-finite, which is checked at the end.)
            least[j] = if l2 < least[j] { l2 } else { least[j] };
            // The terms are powers of u and s times the jacobian, so their logarithmic
            // derivatives are sums of d ln e, d ln u and d ln s.
            let jac = e * weight[j];
            let l2_term = jac * l2;
            let inv_l2_term = jac * inv_l2;
            let per = match wall_weight {
                WallWeight::PerCube => inv_u * inv_d,
                WallWeight::PerSquare => inv_u,
            };
            let terms = [jac, l2_term, inv_l2_term, l2_term * per, inv_l2_term * per];
            for (dir, (le, du, ds)) in [(le_dl, u_dl, s_dl), (le_dx, u_dx, s_dx)]
                .into_iter()
                .enumerate()
            {
                let (lu, ls) = (du * inv_u, ds * inv_s);
                let l2_log = le + lu - ls;
                let inv_l2_log = le + ls - lu;
                let logs = [
                    le,
                    l2_log,
                    inv_l2_log,
                    l2_log - power * lu,
                    inv_l2_log - power * lu,
                ];
                for k in 0..5 {
                    acc[k][dir + 1][j] += terms[k] * logs[k];
                }
            }
            for k in 0..5 {
                acc[k][0][j] += terms[k];
            }
        }
    }
    let sum = |k: usize| {
        let lanes = |c: usize| {
            let a = &acc[k][c];
            ((a[0] + a[4]) + (a[1] + a[5])) + ((a[2] + a[6]) + (a[3] + a[7]))
        };
        Dual {
            v: lanes(0),
            dl: lanes(1),
            dx: lanes(2),
        }
    };
    let sums = WallSums {
        span,
        jac: sum(0),
        l2: sum(1),
        inv_l2: sum(2),
        l2_h: sum(3),
        inv_l2_h: sum(4),
    };
    // Every node's l2^2 positive, and (so) finite: [`node_sums`]' test.
    let finite = [sums.jac, sums.l2, sums.inv_l2, sums.l2_h, sums.inv_l2_h]
        .iter()
        .all(|s| s.v.is_finite());
    (finite && least.iter().all(|&l| l > 0.0)).then_some(sums)
}
