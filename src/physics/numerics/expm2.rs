//! The exponential of a real 2x2 matrix in closed form, well conditioned over its whole range:
//! real eigenvalues far apart (an overdamped mode over a long interval), repeated or nearly
//! repeated ones (critical damping), a complex pair (ringing), and arguments from tiny to huge.
//!
//! With `Z = m I + N`, `m` half the trace and `N` trace-free, `N^2 = q I` (Cayley-Hamilton), so
//! `exp(Z) = e^m (C(q) I + S(q) N)` with `C = cosh w`, `S = sinh(w) / w` for `q = w^2 > 0` and
//! `C = cos w`, `S = sin(w) / w` for `q = -w^2 < 0`; both are smooth in `q` through 0, where
//! `C = S = 1`. Forming `e^m` and `cosh w` apart overflows to `0 x inf` where `m -+ w` are both
//! moderate but `w` alone is huge (an overdamped mode: `m = -1000`, `w = 999`), and `sinh w - ...`
//! cancels at small `w`. Here the exponents are combined before exponentiating, `e^m cosh w =
//! e^{m+w} (1 + e^{-2w}) / 2` and `e^m sinh(w) / w = e^{m+w} (1 - e^{-2w}) / (2w)`, the latter
//! from `expm1(-2w)`, which keeps its digits as `w -> 0`; `sin(w) / w` keeps its digits for any
//! `w > 0` as it is. The larger real eigenvalue `m + w` is taken from the determinant where
//! `m - w` is the one of larger magnitude (`det / (m - w)`, no cancellation: a stiff mode beside
//! a slow one), as [`crate::physics::multiferroic::phi::Phi2x2`] does.
//!
//! Cost: one `exp` near repeated eigenvalues (`|q| <= 1e-2`, series of `C` and `S`), else one
//! `exp` and one `exp` or `expm1` (real eigenvalues) or one `exp` and one `sin_cos` (complex).

/// `|q|` (the squared half gap of the eigenvalues) below which `C` and `S` are summed as series:
/// one `exp` instead of two transcendental calls where a substep resolves the ringing.
const SERIES_BELOW: f64 = 1e-2;

/// A real 2x2 matrix, rows first.
pub type M2 = [[f64; 2]; 2];

/// `exp(z)` of a real 2x2 matrix (see the module documentation).
///
/// `None` where `z` is not finite or its exponential does not fit a finite `f64` (the larger
/// eigenvalue's real part beyond about 709, or entries beyond about 1e154, whose square
/// overflows); otherwise every entry is finite (an entry below the smallest normal underflows
/// towards 0, as its true value).
#[inline(always)]
pub fn expm2(z: &M2) -> Option<M2> {
    let m = 0.5 * (z[0][0] + z[1][1]);
    let n0 = 0.5 * (z[0][0] - z[1][1]);
    let q = n0 * n0 + z[0][1] * z[1][0];
    let (c, s) = if q.abs() <= SERIES_BELOW {
        // `C = sum q^k / (2k)!`, `S = sum q^k / (2k + 1)!` to `q^5`: the remainders are below
        // `q^6 / 12!` ~ 2e-21 relative.
        let em = m.exp();
        let c = 1.0
            + q / 2.0 * (1.0 + q / 12.0 * (1.0 + q / 30.0 * (1.0 + q / 56.0 * (1.0 + q / 90.0))));
        let s = 1.0
            + q / 6.0 * (1.0 + q / 20.0 * (1.0 + q / 42.0 * (1.0 + q / 72.0 * (1.0 + q / 110.0))));
        (em * c, em * s)
    } else if q > 0.0 {
        let w = q.sqrt();
        // The larger eigenvalue, from the determinant where `m + w` would cancel.
        let det = z[0][0] * z[1][1] - z[0][1] * z[1][0];
        let hi = if m > 0.0 || !det.is_finite() {
            m + w
        } else {
            det / (m - w)
        };
        let up = hi.exp();
        // e^{-2w} - 1, in [-1, 0]: from `expm1` where it would cancel (`exp` costs less).
        let gap = if w < 0.35 {
            (-2.0 * w).exp_m1()
        } else {
            (-2.0 * w).exp() - 1.0
        };
        (up * (1.0 + 0.5 * gap), up * (-gap / (2.0 * w)))
    } else if q < 0.0 {
        let w = (-q).sqrt();
        let em = m.exp();
        let (sin, cos) = w.sin_cos();
        (em * cos, em * (sin / w))
    } else {
        // (A NaN `q`: refused below.)
        (f64::NAN, f64::NAN)
    };
    let e = [[c + s * n0, s * z[0][1]], [s * z[1][0], c - s * n0]];
    e.iter().flatten().all(|x| x.is_finite()).then_some(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mul(a: &M2, b: &M2) -> M2 {
        std::array::from_fn(|i| std::array::from_fn(|k| a[i][0] * b[0][k] + a[i][1] * b[1][k]))
    }

    fn scaled(a: &M2, f: f64) -> M2 {
        a.map(|r| r.map(|x| f * x))
    }

    fn norm(a: &M2) -> f64 {
        (a[0][0].abs() + a[0][1].abs()).max(a[1][0].abs() + a[1][1].abs())
    }

    /// An independent exponential: the Taylor series to 30 terms of `z / 2^s` (`||z / 2^s|| <=
    /// 1/8`, remainder below 1e-50), squared `s` times; the eigenvalues' real parts are shifted
    /// out first (`exp(z) = e^t exp(z - t I)`, `t` half the trace) so that the squarings do not
    /// meet the cancellation of a large decaying matrix's powers.
    fn reference(z: &M2) -> M2 {
        let t = 0.5 * (z[0][0] + z[1][1]);
        let x = [[z[0][0] - t, z[0][1]], [z[1][0], z[1][1] - t]];
        let mut s = 0;
        while norm(&x) / f64::from(1u32 << s.min(31)) > 0.125 && s < 200 {
            s += 1;
        }
        let x = scaled(&x, 0.5f64.powi(s));
        let mut sum = [[1.0, 0.0], [0.0, 1.0]];
        let mut term = sum;
        for n in 1..30 {
            term = scaled(&mul(&term, &x), 1.0 / f64::from(n));
            sum = std::array::from_fn(|i| std::array::from_fn(|k| sum[i][k] + term[i][k]));
        }
        for _ in 0..s {
            sum = mul(&sum, &sum);
        }
        let et = (t * 0.5).exp();
        sum.map(|r| r.map(|v| v * et * et))
    }

    /// Normwise relative distance of `a` from `b`.
    fn distance(a: &M2, b: &M2) -> f64 {
        let d: M2 = std::array::from_fn(|i| std::array::from_fn(|k| a[i][k] - b[i][k]));
        norm(&d) / norm(b).max(f64::MIN_POSITIVE)
    }

    /// A spread of matrices over the regimes: overdamped with huge arguments, critically damped
    /// (and within rounding of it from either side), ringing, nilpotent, tiny, and generic ones.
    fn samples() -> Vec<M2> {
        let mut out: Vec<M2> = vec![
            [[-1000.0 + 999.0, 0.0], [0.0, -1000.0 - 999.0]],
            [[-1000.0, 999.0], [999.0, -1000.0]],
            [[0.0, 1.0], [-1.0, 0.0]],
            [[0.0, 0.0], [0.0, 0.0]],
            [[0.0, 5.0], [0.0, 0.0]],
            [[-3.0, 1.0], [-1.0, -1.0]],
            [[-1.0, 1e-8], [0.0, -1.0]],
            [[1e-300, -1e-300], [1e-300, 1e-300]],
            [[-40.0, -1.0], [30.0, -2.0]],
            [[0.5, -1.0], [-2.0, 0.1]],
            [[-0.02, -25.0], [0.01, -0.03]],
            [[200.0, 3.0], [-7.0, 100.0]],
            [[-600.0, 1e3], [-1e3, -600.0]],
        ];
        // The linearized onion `[[-a d, -T], [d, -a T]] h` of eq. 3.4 over its regimes.
        for alpha in [1e-4, 0.01, 0.3, 1.0, 3.0] {
            for d in [-30.0, -1e-3, 0.0, 1e-6, 1e-2, 1.0, 50.0] {
                for h in [1e-6, 1e-2, 1.0, 30.0, 1e3] {
                    let t = 40.0;
                    out.push([[-alpha * d * h, -t * h], [d * h, -alpha * t * h]]);
                }
            }
        }
        // Around critical damping: `q = n^2 - b c` crossing 0 by a few ulps and by more.
        // (`q = -9 eps`: both sides of the series' reach, 1e-2, and of `w = 0.35`.)
        for eps in [
            -0.0137, -0.0135, -2e-3, -1e-3, -1e-6, -1e-12, -1e-15, 0.0, 1e-15, 1e-12, 1e-6, 1e-3,
            2e-3,
        ] {
            for m in [-50.0, -1.0, 0.0, 2.0] {
                out.push([[m + 3.0, 9.0 * (1.0 + eps)], [-1.0, m - 3.0]]);
            }
        }
        out
    }

    /// Against the scaled-and-squared series: 1e-13 of the norm where the exponential is
    /// moderate, and finite everywhere; an exponential that overflows is refused.
    #[test]
    fn matches_the_scaled_and_squared_series() {
        for z in samples() {
            let r = reference(&z);
            let e = expm2(&z);
            if norm(&r) > 1e300 || !norm(&r).is_finite() {
                continue;
            }
            let e = e.unwrap_or_else(|| panic!("{z:?} refused, reference {r:?}"));
            assert!(e.iter().flatten().all(|x| x.is_finite()), "{z:?}: {e:?}");
            // The reference's `s` squarings carry its own rounding up by `2^s ~ 8 ||z||`.
            let cond = 1.0 + 8.0 * norm(&z);
            assert!(
                distance(&e, &r) <= 2e-14 * cond || norm(&r) < 1e-290,
                "{z:?}: {e:?} vs {r:?} ({:e})",
                distance(&e, &r)
            );
        }
        assert!(expm2(&[[800.0, 0.0], [0.0, 0.0]]).is_none());
        assert!(expm2(&[[f64::NAN, 0.0], [0.0, 0.0]]).is_none());
        assert!(expm2(&[[0.0, f64::INFINITY], [0.0, 0.0]]).is_none());
    }

    /// The overdamped mode over a long interval, `m = -1000`, `w = 999` (eigenvalues -1 and
    /// -1999): `e^{-1}` and `e^{-1999} = 0` on the eigenvectors, exactly, where `e^m cosh w` is
    /// `0 x inf`.
    #[test]
    fn an_overdamped_mode_over_a_long_interval_is_finite() {
        let e = expm2(&[[-1000.0, 999.0], [999.0, -1000.0]]).unwrap();
        let half = 0.5 * (-1.0f64).exp();
        for (x, r) in e.iter().flatten().zip([half, half, half, half]) {
            assert!((x - r).abs() <= 1e-15 * half, "{e:?}");
        }
        // Both factors alone leave the range: 0 x inf.
        assert!(((-1000.0f64).exp() * 999.0f64.cosh()).is_nan());
    }

    /// `det exp(z) = e^{tr z}` and `exp(z (s + t)) = exp(z s) exp(z t)`, over the samples and
    /// a log-uniform sweep of random ones (entries from 1e-8 to 1e3 of either sign).
    #[test]
    fn keeps_the_determinant_and_the_semigroup() {
        let mut zs = samples();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..4000 {
            let mut entry = || {
                let sign = if uniform() < 0.5 { -1.0 } else { 1.0 };
                sign * 10f64.powf(-8.0 + 11.0 * uniform())
            };
            zs.push([[entry(), entry()], [entry(), entry()]]);
        }
        let (mut dets, mut products_checked) = (0, 0);
        for z in zs {
            let tr = z[0][0] + z[1][1];
            let Some(e) = expm2(&z) else {
                // Refused only where the larger eigenvalue's real part is beyond the range.
                let m = 0.5 * tr;
                let n0 = 0.5 * (z[0][0] - z[1][1]);
                let q = n0 * n0 + z[0][1] * z[1][0];
                assert!(m + q.max(0.0).sqrt() > 700.0, "{z:?}");
                continue;
            };
            assert!(e.iter().flatten().all(|x| x.is_finite()), "{z:?}");
            // The determinant, where it does not cancel by more than a thousandfold: entries
            // correct to rounding of the largest, times the condition `16 + ||z||`.
            let cond = 16.0 + norm(&z);
            let det = e[0][0] * e[1][1] - e[0][1] * e[1][0];
            let largest = e.iter().flatten().fold(0.0f64, |s, x| s.max(x.abs()));
            let products = largest * e.iter().flatten().map(|x| x.abs()).sum::<f64>();
            let exact = tr.exp();
            if exact.is_normal() && products.is_finite() && products <= 1e3 * exact {
                assert!(
                    (det - exact).abs() <= 1e-15 * cond * products,
                    "{z:?}: det {det:e} vs {exact:e}"
                );
                dets += 1;
            }
            // The semigroup, with s = 0.3, t = 0.7.
            let (Some(a), Some(b)) = (expm2(&scaled(&z, 0.3)), expm2(&scaled(&z, 0.7))) else {
                continue;
            };
            let ab = mul(&a, &b);
            // The product's own rounding relative to `|a| |b|`, and the exponential's condition
            // `||z||` (a rounded ringing frequency `w` shifts the phase by `w` ulps).
            let scale = norm(&a) * norm(&b);
            let d: M2 = std::array::from_fn(|i| std::array::from_fn(|k| ab[i][k] - e[i][k]));
            assert!(
                norm(&d) <= 1e-15 * cond * scale.max(norm(&e)) || scale < 1e-290,
                "{z:?}: {ab:?} vs {e:?}"
            );
            products_checked += 1;
        }
        assert!(
            dets > 1000 && products_checked > 3000,
            "{dets} {products_checked}"
        );
    }
}
