//! Matrix exponential of a small fixed-size matrix by scaling and squaring with a Taylor series
//! (degree 12, evaluated by Paterson and Stockmeyer's scheme).
//!
//! Hand-written on plain arrays for speed on the per-substep hot path (two calls per substep)
//! and so that a hopeless argument returns `None` instead of panicking or producing NaN. Generic
//! over the size: the quasi-static motor needs 3x3 (rotor and forcing), the Gilbert one 4x4 with
//! its forcing's `phi_1` column ([`expm_affine`]).

pub type Mat<const N: usize> = [[f64; N]; N];

/// Dense and branch-free, so that the rows vectorize (a test for zero entries cost more than
/// it saved, and the products are the squarings' whole cost).
fn mul<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    let mut c = [[0.0; N]; N];
    for (ci, ai) in c.iter_mut().zip(a) {
        for (aik, bk) in ai.iter().zip(b) {
            for (cij, bkj) in ci.iter_mut().zip(bk) {
                *cij += aik * bkj;
            }
        }
    }
    c
}

/// `exp(m)`, or `None` if `m` is not finite, too large to scale (norm above 2^200), or the
/// result overflows.
pub fn expm<const N: usize>(m: &Mat<N>) -> Option<Mat<N>> {
    let (a, squarings, _) = scaled_to_a_quarter(m)?;
    let mut e = taylor_12(&a);
    for _ in 0..squarings {
        e = mul(&e, &e);
    }
    if e.iter().flatten().all(|x| x.is_finite()) {
        Some(e)
    } else {
        None
    }
}

/// `exp(a)` and `phi_1(a) b = sum_k a^k b / (k + 1)!`: the blocks of the exponential of the
/// augmented matrix `[[a, b], [0, 0]]` (its last column is `phi_1(a) b`, its corner 1), without
/// building it. Its powers are `[[a^k, a^(k-1) b], [0, 0]]`, so scaling and squaring needs the
/// products of `a` alone plus one matrix-vector product per squaring
/// (`[[X, x], [0, 1]]^2 = [[X^2, X x + x], [0, 1]]`): a third of the augmented matrix's work at
/// `M` = 4, and a forcing of any size adds no squaring (the series of `phi_1(a) b` converges
/// relative to `b`, at the rate of `a`'s). `None` if an input is not finite, `a` is too large to
/// scale (norm above 2^200) or the result overflows.
pub fn expm_affine<const M: usize>(a: &Mat<M>, b: &[f64; M]) -> Option<(Mat<M>, [f64; M])> {
    if !b.iter().all(|x| x.is_finite()) {
        return None;
    }
    // 12 Taylor terms leave remainders below 0.25^13/13! ~ 2e-18 of exp and 0.25^12/13! ~ 1e-17
    // of phi_1 (relative to b).
    let (s, squarings, scale) = scaled_to_a_quarter(a)?;
    let mut e = taylor_12(&s);
    // phi_1(s) (scale b) by Horner: b + s (b + s (b + ...) / 3) / 2, to s^11 b / 12!.
    let scaled_b: [f64; M] = std::array::from_fn(|i| b[i] * scale);
    let mut x = scaled_b;
    for k in (2..=12).rev() {
        let inv_k = 1.0 / k as f64;
        let sx = mul_vec(&s, &x);
        x = std::array::from_fn(|i| scaled_b[i] + sx[i] * inv_k);
    }
    for _ in 0..squarings {
        let ex = mul_vec(&e, &x);
        x = std::array::from_fn(|i| ex[i] + x[i]);
        e = mul(&e, &e);
    }
    (e.iter().flatten().all(|v| v.is_finite()) && x.iter().all(|v| v.is_finite())).then_some((e, x))
}

/// `m` scaled by a power of two to a norm of at most 1/4, where 12 Taylor terms leave a
/// remainder below 0.25^13/13! ~ 2e-18: the scaled matrix, the squarings that undo it and the
/// scale. `None` if `m` is not finite or its norm exceeds 2^200.
fn scaled_to_a_quarter<const N: usize>(m: &Mat<N>) -> Option<(Mat<N>, u32, f64)> {
    let norm = m
        .iter()
        .map(|row| row.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if !norm.is_finite() {
        return None;
    }
    let squarings = quarter_squarings(norm)?;
    // Exact: 2^-squarings is a normal number (squarings <= 200).
    let scale = 0.5f64.powi(squarings as i32);
    let mut a = *m;
    for row in a.iter_mut() {
        for x in row.iter_mut() {
            *x *= scale;
        }
    }
    Some((a, squarings, scale))
}

/// The fewest halvings `s` that bring the finite `norm >= 0` to at most 1/4, or `None` above
/// 200. With `norm = (1 + f) 2^e`, `norm 2^-s <= 2^-2` holds from `s = e + 2` when `f = 0` and
/// from `e + 3` otherwise: read off the bits instead of halving until it holds (a multiplication
/// and a dependent comparison per squaring, on every substep's exponential).
fn quarter_squarings(norm: f64) -> Option<u32> {
    if norm <= 0.25 {
        return Some(0);
    }
    // Above 1/4 the number is normal: its biased exponent is e + 1023.
    let bits = norm.to_bits();
    let exponent = (bits >> 52) as i64 - 1023;
    let fraction = bits & ((1 << 52) - 1);
    let s = exponent + 2 + i64::from(fraction != 0);
    (s <= 200).then_some(s as u32)
}

/// `a v`.
fn mul_vec<const M: usize>(a: &Mat<M>, v: &[f64; M]) -> [f64; M] {
    std::array::from_fn(|i| a[i].iter().zip(v).map(|(x, y)| x * y).sum())
}

/// `sum_{k=0}^{12} a^k / k!` by Paterson and Stockmeyer: with `a^2`, `a^3` and `a^4` it is
/// `P0 + a^4 (P1 + a^4 P2)`, the `Pi` cubic (or, for `P2`, quartic) in `a` with no products of
/// their own, so 5 matrix products where Horner's rule takes 12 (the products are the whole cost).
fn taylor_12<const N: usize>(a: &Mat<N>) -> Mat<N> {
    let a2 = mul(a, a);
    let a3 = mul(&a2, a);
    let a4 = mul(&a2, &a2);
    let mut c = [1.0f64; 13];
    for k in 1..13 {
        c[k] = c[k - 1] / k as f64;
    }
    // sum_k coefficients[k] a^k over a^0..a^4.
    let combine = |coefficients: [f64; 5]| {
        let mut p = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..N {
                p[i][j] = coefficients[1] * a[i][j]
                    + coefficients[2] * a2[i][j]
                    + coefficients[3] * a3[i][j]
                    + coefficients[4] * a4[i][j];
            }
            p[i][i] += coefficients[0];
        }
        p
    };
    let p0 = combine([c[0], c[1], c[2], c[3], 0.0]);
    let p1 = combine([c[4], c[5], c[6], c[7], 0.0]);
    let p2 = combine([c[8], c[9], c[10], c[11], c[12]]);
    let mut inner = mul(&a4, &p2);
    for (row, p) in inner.iter_mut().zip(&p1) {
        for (x, y) in row.iter_mut().zip(p) {
            *x += y;
        }
    }
    let mut e = mul(&a4, &inner);
    for (row, p) in e.iter_mut().zip(&p0) {
        for (x, y) in row.iter_mut().zip(p) {
            *x += y;
        }
    }
    e
}

pub fn identity<const N: usize>() -> Mat<N> {
    let mut e = [[0.0; N]; N];
    for (i, row) in e.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_of_a_rotation_generator_and_a_decay() {
        let mut m = [[0.0; 5]; 5];
        m[0][1] = 1.0;
        m[1][0] = -1.0;
        m[2][2] = -3.0;
        let e = expm(&m).unwrap();
        assert!((e[0][0] - 1f64.cos()).abs() < 1e-14);
        assert!((e[0][1] - 1f64.sin()).abs() < 1e-14);
        assert!((e[2][2] - (-3f64).exp()).abs() < 1e-14);
        assert_eq!(e[4][4], 1.0);
        // The 3x3 exponential of the rotation block agrees with the 5x5 one.
        let small = expm(&[[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]).unwrap();
        assert!((small[0][1] - e[0][1]).abs() < 1e-15 && small[2][2] == 1.0);
        m[3][3] = 1e300;
        assert!(expm(&m).is_none());
        let block: Mat<4> = std::array::from_fn(|i| std::array::from_fn(|k| m[i][k]));
        assert!(expm_affine(&block, &[1.0; 4]).is_none());
        m[3][3] = f64::NAN;
        assert!(expm(&m).is_none());
    }

    /// The squarings read off the bits are those of halving until the norm is at most 1/4.
    #[test]
    fn squarings_are_the_halvings_to_a_quarter() {
        let halvings = |norm: f64| {
            let (mut s, mut scaled) = (0u32, norm);
            while scaled > 0.25 {
                scaled *= 0.5;
                s += 1;
            }
            (s <= 200).then_some(s)
        };
        let mut norms = vec![
            0.0,
            1e-300,
            0.1,
            0.25,
            2.5e-1 + 1e-17,
            0.3,
            0.5,
            1.0,
            3.0,
            1e11,
        ];
        for e in -3..=205 {
            let p = 2f64.powi(e);
            norms.extend([
                p,
                p * (1.0 + f64::EPSILON),
                p * (1.0 - f64::EPSILON / 2.0),
                1.7 * p,
            ]);
        }
        for norm in norms {
            assert_eq!(quarter_squarings(norm), halvings(norm), "{norm:e}");
        }
        assert_eq!(quarter_squarings(2f64.powi(198)), Some(200));
        assert_eq!(quarter_squarings(1.5 * 2f64.powi(198)), None);
    }

    /// The affine exponential's blocks match the closed form from a small forcing to one that
    /// dominates. (The plain exponential of the augmented matrix loses accuracy there to the
    /// squarings the forcing adds: its `exp(J)` is off by 9e-12 at a forcing of 1e6, 9e-9 at
    /// 1e12 and 0.9 at 1e22.)
    #[test]
    fn affine_exponential_matches_the_closed_form() {
        // A damped rotor block with eigenvalues -1 and -4: exp(J) = a I + b J.
        let j = [[0.0, 1.0], [-4.0, -5.0]];
        let (l1, l2) = (-1.0f64, -4.0f64);
        let b = (l1.exp() - l2.exp()) / (l1 - l2);
        let a = l1.exp() - b * l1;
        let exp_j = [
            [a + b * j[0][0], b * j[0][1]],
            [b * j[1][0], a + b * j[1][1]],
        ];
        // J^-1 = [[-5, -1], [4, 0]] / 4.
        let inv = [[-1.25, -0.25], [1.0, 0.0]];
        for forcing in [1e-3, 1.0, 1e6, 1e12, 1e22] {
            let f = [0.5 * forcing, forcing];
            let (e_j, column) = expm_affine(&j, &f).unwrap();
            let e = [
                [e_j[0][0], e_j[0][1], column[0]],
                [e_j[1][0], e_j[1][1], column[1]],
                [0.0, 0.0, 1.0],
            ];
            // (exp(J) - I) f, then J^-1 of it.
            let g = [
                (exp_j[0][0] - 1.0) * f[0] + exp_j[0][1] * f[1],
                exp_j[1][0] * f[0] + (exp_j[1][1] - 1.0) * f[1],
            ];
            for i in 0..2 {
                let column = inv[i][0] * g[0] + inv[i][1] * g[1];
                assert!(
                    (e[i][2] - column).abs() <= 1e-14 * forcing,
                    "{forcing}: {i}: {} against {column}",
                    e[i][2]
                );
                for k in 0..2 {
                    assert!(
                        (e[i][k] - exp_j[i][k]).abs() <= 1e-14,
                        "{forcing}: [{i}][{k}]"
                    );
                }
            }
            assert_eq!(e[2], [0.0, 0.0, 1.0]);
        }
        // An overflowing forcing column is refused, never returned as infinity.
        let huge = [[0.0, 1.0], [-4.0, -3.0]];
        assert!(expm_affine(&huge, &[1e308, 1e308]).is_none_or(|(e, x)| e
            .iter()
            .flatten()
            .chain(&x)
            .all(|v| v.is_finite())));
    }
}
