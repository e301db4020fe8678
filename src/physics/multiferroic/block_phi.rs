//! The `phi` functions of a real 2x2 block with real or complex eigenvalues (a precessing
//! onion), which [`super::phi::Phi2x2`] leaves out, and a locked onion's exponential increments
//! in closed form from them.

use super::phi::phis;
use super::Vector;

/// `phi_1..3(A)` of a real 2x2 matrix `A`, as matrices (`phi_k(A) = c_0 I + c_1 A` by
/// Cayley-Hamilton, see [`super::phi`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct BlockPhi {
    p: [[[f64; 2]; 2]; 3],
}

impl BlockPhi {
    /// `None` for a block whose eigenvalues are nearly repeated (relative gap below 1e-6) and
    /// whose norm is above 1/4, or that is not finite.
    #[inline(always)]
    pub(super) fn new(a: &[[f64; 2]; 2]) -> Option<Self> {
        let norm = (a[0][0].abs() + a[0][1].abs()).max(a[1][0].abs() + a[1][1].abs());
        if !norm.is_finite() {
            return None;
        }
        if norm <= 0.25 {
            return Some(Self::series(a));
        }
        let m = 0.5 * (a[0][0] + a[1][1]);
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let disc = m * m - det;
        let gap = disc.abs().sqrt();
        if gap.is_nan() || gap <= 1e-6 * (m.abs() + gap) {
            return None;
        }
        let coefficients: [(f64, f64); 3] = if disc > 0.0 {
            // Real eigenvalues: the larger without cancellation, the smaller from the
            // determinant (Sylvester's formula, as [`super::phi::Phi2x2`]).
            let mu1 = if m <= 0.0 { m - gap } else { m + gap };
            let mu2 = det / mu1;
            let inv = 1.0 / (mu1 - mu2);
            let (f1, f2) = (phis(mu1), phis(mu2));
            std::array::from_fn(|k| {
                let c1 = (f1[k] - f2[k]) * inv;
                (f2[k] - mu2 * c1, c1)
            })
        } else {
            // Eigenvalues m +- i b: c_1 = Im f(m + i b) / b, c_0 = Re f(m + i b) - m c_1.
            let f = complex_phis(m, gap);
            std::array::from_fn(|k| {
                let c1 = f[k].1 / gap;
                (f[k].0 - m * c1, c1)
            })
        };
        let p = coefficients.map(|(c0, c1)| {
            [
                [c0 + c1 * a[0][0], c1 * a[0][1]],
                [c1 * a[1][0], c0 + c1 * a[1][1]],
            ]
        });
        p.iter()
            .flatten()
            .flatten()
            .all(|x| x.is_finite())
            .then_some(Self { p })
    }

    /// `phi_k(A) = sum_n A^n / (n + k)!` by Horner's rule for `||A|| <= 1/4`: 14 terms leave
    /// less than `0.25^14 / 14!` ~ 1e-19.
    fn series(a: &[[f64; 2]; 2]) -> Self {
        let mul = |x: &[[f64; 2]; 2]| -> [[f64; 2]; 2] {
            std::array::from_fn(|i| std::array::from_fn(|k| a[i][0] * x[0][k] + a[i][1] * x[1][k]))
        };
        let plus_identity =
            |x: [[f64; 2]; 2], c: f64| [[x[0][0] + c, x[0][1]], [x[1][0], x[1][1] + c]];
        let mut inv_factorial = [1.0f64; 18];
        for n in 1..18 {
            inv_factorial[n] = inv_factorial[n - 1] / n as f64;
        }
        let mut p3 = [[inv_factorial[16], 0.0], [0.0, inv_factorial[16]]];
        for n in (0..13).rev() {
            p3 = plus_identity(mul(&p3), inv_factorial[n + 3]);
        }
        let p2 = plus_identity(mul(&p3), 0.5);
        let p1 = plus_identity(mul(&p2), 1.0);
        Self { p: [p1, p2, p3] }
    }

    /// `phi_k(2A)` from `phi_k(A)` (`a` is `A`): `phi_k(2A) = 2^-k (e^A phi_k(A) + sum_{j=1}^k
    /// phi_j(A) / (k - j)!)` with `e^A = I + A phi_1(A)` (all of them functions of `A`, so
    /// they commute).
    #[inline(always)]
    pub(super) fn doubled(&self, a: &[[f64; 2]; 2]) -> Self {
        let mul = |x: &[[f64; 2]; 2], y: &[[f64; 2]; 2]| -> [[f64; 2]; 2] {
            std::array::from_fn(|i| std::array::from_fn(|k| x[i][0] * y[0][k] + x[i][1] * y[1][k]))
        };
        let [p1, p2, p3] = self.p;
        let mut e = mul(a, &p1);
        e[0][0] += 1.0;
        e[1][1] += 1.0;
        let (e1, e2, e3) = (mul(&e, &p1), mul(&e, &p2), mul(&e, &p3));
        let p = [
            std::array::from_fn(|i| std::array::from_fn(|k| 0.5 * (e1[i][k] + p1[i][k]))),
            std::array::from_fn(|i| {
                std::array::from_fn(|k| 0.25 * (e2[i][k] + p1[i][k] + p2[i][k]))
            }),
            std::array::from_fn(|i| {
                std::array::from_fn(|k| 0.125 * (e3[i][k] + 0.5 * p1[i][k] + p2[i][k] + p3[i][k]))
            }),
        ];
        Self { p }
    }

    /// `phi_k(A) v` for `k` in 1..=3.
    #[inline(always)]
    pub(super) fn apply(&self, k: usize, v: [f64; 2]) -> [f64; 2] {
        let p = &self.p[k - 1];
        [
            p[0][0] * v[0] + p[0][1] * v[1],
            p[1][0] * v[0] + p[1][1] * v[1],
        ]
    }
}

/// Least `|f(mu_1) - f(mu_2)|` (real eigenvalues) or `|Im f(m + i b)|` (a complex pair)
/// relative to the values of `f = phi_1` that [`block_phi1`] takes: its `c_1` then keeps all
/// but about two of its digits.
const PHI1_SEPARATED: f64 = 1e-2;

/// Terms of [`block_phi1`]'s series within the unit disc: the `n`-th is at most `n / (n + 1)!`
/// (`|h_m| <= m + 1`), below 1e-18 from the 20th.
const PHI1_SERIES_TERMS: usize = 20;

/// `1 / n!` for the terms of [`block_phi1`]'s series.
const INV_FACTORIAL: [f64; PHI1_SERIES_TERMS + 2] = {
    let mut t = [1.0; PHI1_SERIES_TERMS + 2];
    let mut n = 1;
    while n < t.len() {
        t[n] = t[n - 1] / n as f64;
        n += 1;
    }
    t
};

/// `phi_1(A) = sum_n A^n / (n + 1)!` of a real 2x2 matrix `A` as `c_0 I + c_1 A`. With both
/// eigenvalues within the unit disc (however large `A` itself, as a stiff tilt over a soft angle
/// makes it), by the series of `A^n = -det h_{n-2} I + h_{n-1} A` (Cayley-Hamilton; `h_n` the
/// complete symmetric polynomials of the eigenvalues, `h_n = tr h_{n-1} - det h_{n-2}`), which
/// holds through repeated eigenvalues; else from `phi_1` at the eigenvalues as in
/// [`BlockPhi::new`]. `None` where that divided difference would cancel (nearly repeated
/// eigenvalues, or a zero of `Im phi_1` on a complex pair) or the matrix is not finite: the
/// caller then takes a series of its own.
#[inline]
pub(super) fn block_phi1(a: &[[f64; 2]; 2]) -> Option<[[f64; 2]; 2]> {
    let m = 0.5 * (a[0][0] + a[1][1]);
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let disc = m * m - det;
    let gap = disc.abs().sqrt();
    if !gap.is_finite() {
        return None;
    }
    let (c0, c1) = if m.abs() + gap <= 1.0 {
        let (mut c0, mut c1) = (1.0, 0.0);
        let (mut before, mut h) = (0.0, 1.0);
        for inv_factorial in &INV_FACTORIAL[2..PHI1_SERIES_TERMS + 2] {
            c0 -= det * before * inv_factorial;
            c1 += h * inv_factorial;
            (before, h) = (h, 2.0 * m * h - det * before);
        }
        (c0, c1)
    } else if gap == 0.0 {
        return None;
    } else if disc > 0.0 {
        let mu1 = if m <= 0.0 { m - gap } else { m + gap };
        let mu2 = det / mu1;
        let (f1, f2) = (phis(mu1)[0], phis(mu2)[0]);
        // (Values that are not finite fail the final check.)
        if (f1 - f2).abs() < PHI1_SEPARATED * (f1.abs() + f2.abs()) {
            return None;
        }
        let c1 = (f1 - f2) / (mu1 - mu2);
        (f2 - mu2 * c1, c1)
    } else {
        let (re, im) = complex_phis(m, gap)[0];
        if im.abs() < PHI1_SEPARATED * re.hypot(im) {
            return None;
        }
        let c1 = im / gap;
        (re - m * c1, c1)
    };
    let p = [
        [c0 + c1 * a[0][0], c1 * a[0][1]],
        [c1 * a[1][0], c0 + c1 * a[1][1]],
    ];
    p.iter().flatten().all(|x| x.is_finite()).then_some(p)
}

/// Onion blocks `h J` above this norm take the closed form in [`locked_onion_increments`]: the
/// scaling-and-squaring exponential's rounding of the slow mode's increment grows about as
/// [`EXPONENTIAL_ROUNDING`] `||h J||` (its decay factor 5e-6 to 7e-4 off at norms 5e9 to 4e10),
/// so below 1e-11 of it up to here.
const CLOSED_FORM_ABOVE: f64 = 1e3;

/// The scaling-and-squaring exponential's rounding of a stiff onion block's increments relative
/// to `||h J||` and to the larger of the increment and `h f` (measured: 1.3e-15 where the slow
/// mode decays by 0.57 over the substep, 2e-16 where by 0.012).
const EXPONENTIAL_ROUNDING: f64 = 2e-15;

#[cfg(test)]
thread_local! {
    /// Test-only: the general exponential everywhere, to compare the two.
    pub(super) static CLOSED_FORM_OFF: std::cell::Cell<bool> =
        const { std::cell::Cell::new(false) };
}

/// For a locked rotor (its rows of `J` and `f` vanish, so only the onion's block acts), the
/// exponential pair's increments `h phi_1(h J) f` over `dt / 2` and `dt` from the onion block's
/// eigenvalues ([`BlockPhi::new`]), which keeps the slow mode's decay to rounding however far
/// apart the eigenvalues are: `None` where the block is small enough for the general exponential
/// or its eigenvalues are nearly repeated. With it, the general exponential's rounding relative to
/// the onion's increments and `h f` (0 where it is negligible or the closed form applies).
pub(super) fn locked_onion_increments(
    f: &Vector,
    j: &[[f64; 4]; 4],
    dt: f64,
) -> (Option<(Option<Vector>, Vector)>, f64) {
    #[cfg(test)]
    if CLOSED_FORM_OFF.with(|c| c.get()) {
        return (None, 0.0);
    }
    let block = |h: f64| [[h * j[2][2], h * j[2][3]], [h * j[3][2], h * j[3][3]]];
    let z = block(dt);
    let norm = (z[0][0].abs() + z[0][1].abs()).max(z[1][0].abs() + z[1][1].abs());
    // (Within for a NaN norm too.)
    let beyond = norm > CLOSED_FORM_ABOVE;
    if !beyond {
        return (None, 0.0);
    }
    let increments = |h: f64| {
        let [psi, theta] = BlockPhi::new(&block(h))?.apply(1, [f[2], f[3]]);
        let out = [0.0, 0.0, h * psi, h * theta];
        out.iter().all(|x| x.is_finite()).then_some(out)
    };
    match (increments(0.5 * dt), increments(dt)) {
        (Some(half), Some(full)) => (Some((Some(half), full)), 0.0),
        _ => (None, EXPONENTIAL_ROUNDING * norm),
    }
}

/// `[phi_1, phi_2, phi_3]` at `x + i y` as `(re, im)`: the series of `phi_3` near 0 and the
/// downward recurrence `phi_{k+1} = (phi_k - 1/k!) / z` from `e^z - 1` elsewhere (as
/// [`phis`]).
fn complex_phis(x: f64, y: f64) -> [(f64, f64); 3] {
    let mul = |p: (f64, f64), q: (f64, f64)| (p.0 * q.0 - p.1 * q.1, p.0 * q.1 + p.1 * q.0);
    let z = (x, y);
    if x.hypot(y) < 0.5 {
        let mut sum = (0.0, 0.0);
        let mut inv_factorial = [1.0f64; 19];
        for n in 1..19 {
            inv_factorial[n] = inv_factorial[n - 1] / n as f64;
        }
        for n in (0..16).rev() {
            let s = mul(sum, z);
            sum = (s.0 + inv_factorial[n + 3], s.1);
        }
        let p2 = mul(z, sum);
        let phi2 = (0.5 + p2.0, p2.1);
        let p1 = mul(z, phi2);
        return [(1.0 + p1.0, p1.1), phi2, sum];
    }
    let inv_z = {
        let r = 1.0 / (x * x + y * y);
        (x * r, -y * r)
    };
    // e^z - 1 = expm1(x) cos y - 2 sin^2(y/2) + i e^x sin y.
    let em1 = if x < -40.0 {
        (-1.0, 0.0)
    } else {
        let (s, c) = y.sin_cos();
        let half = (0.5 * y).sin();
        (x.exp_m1() * c - 2.0 * half * half, x.exp() * s)
    };
    let phi1 = mul(em1, inv_z);
    let phi2 = mul((phi1.0 - 1.0, phi1.1), inv_z);
    let phi3 = mul((phi2.0 - 0.5, phi2.1), inv_z);
    [phi1, phi2, phi3]
}
