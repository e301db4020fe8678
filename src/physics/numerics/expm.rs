//! Matrix exponential of a small fixed-size matrix by scaling and squaring with a Taylor series
//! (degree 12, evaluated by Paterson and Stockmeyer's scheme).
//!
//! Hand-written on plain arrays for speed on the per-substep hot path (two calls per substep)
//! and so that a hopeless argument returns `None` instead of panicking or producing NaN. Generic
//! over the size: the quasi-static motor needs 3x3 (rotor and forcing), the Gilbert one 5x5.

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
    let norm = m
        .iter()
        .map(|row| row.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if !norm.is_finite() {
        return None;
    }
    // Scale to norm <= 1/4: 12 Taylor terms then leave a remainder below 0.25^13/13! ~ 2e-18.
    let mut squarings = 0u32;
    let mut scale = 1.0;
    while norm * scale > 0.25 {
        scale *= 0.5;
        squarings += 1;
        if squarings > 200 {
            return None;
        }
    }
    let mut a = *m;
    for row in a.iter_mut() {
        for x in row.iter_mut() {
            *x *= scale;
        }
    }
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

/// `exp(m)` of an augmented matrix `[[J, f], [0, 0]]` (last row zero), balanced first: the
/// forcing column is divided by a power of two `s` until it is no larger than the norm of `J`,
/// and the result's column multiplied back (`exp(D^-1 m D) = D^-1 exp(m) D`, exact in binary).
/// Scaling and squaring then needs the squarings of `J` alone: a forcing of 1e23 (a fuzzed load
/// torque over the Gilbert rotor's inertia) had taken 79 squarings where `J` needed 24, and
/// each extra squaring doubles the rounding error of the `J` block.
pub fn expm_augmented<const N: usize>(m: &Mat<N>) -> Option<Mat<N>> {
    let last = N - 1;
    let block = m[..last]
        .iter()
        .map(|row| row[..last].iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let forcing = m[..last]
        .iter()
        .map(|row| row[last].abs())
        .fold(0.0, f64::max);
    let target = block.max(0.25);
    if !(forcing.is_finite() && forcing > target) {
        return expm(m);
    }
    // s = 2^k with forcing / s <= target; at most 2^1000 (the forcing is finite).
    let k = (forcing / target).log2().ceil().clamp(0.0, 1000.0) as i32;
    let (down, up) = (0.5f64.powi(k), 2.0f64.powi(k));
    let mut balanced = *m;
    for row in balanced[..last].iter_mut() {
        row[last] *= down;
    }
    let mut e = expm(&balanced)?;
    for row in e[..last].iter_mut() {
        row[last] *= up;
    }
    e[..last]
        .iter()
        .all(|row| row[last].is_finite())
        .then_some(e)
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

/// `m * m`, the squaring that turns `exp(m / 2)` into `exp(m)`.
pub fn square<const N: usize>(m: &Mat<N>) -> Mat<N> {
    mul(m, m)
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
        assert!(expm_augmented(&m).is_none());
        m[3][3] = f64::NAN;
        assert!(expm(&m).is_none());
    }

    /// The balanced exponential of an augmented matrix matches the closed form where the forcing
    /// dominates. The plain one loses accuracy there to its extra squarings: its `exp(J)` is off
    /// by 9e-12 at a forcing of 1e6, 9e-9 at 1e12 and 0.9 at 1e22.
    #[test]
    fn balanced_augmented_exponential_matches_the_closed_form() {
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
            let m = [
                [j[0][0], j[0][1], f[0]],
                [j[1][0], j[1][1], f[1]],
                [0.0, 0.0, 0.0],
            ];
            let e = expm_augmented(&m).unwrap();
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
        let huge = [[0.0, 1.0, 1e308], [-4.0, -3.0, 1e308], [0.0, 0.0, 0.0]];
        assert!(expm_augmented(&huge).is_none_or(|e| e.iter().flatten().all(|x| x.is_finite())));
    }
}
