//! The `phi` functions of exponential integrators, `phi_k(z) = sum_n z^n / (n + k)!`
//! (`phi_0 = exp`, `phi_{k+1}(z) = (phi_k(z) - 1/k!) / z`), of a 2x2 matrix in closed form.
//!
//! For a 2x2 matrix with distinct eigenvalues `mu_1`, `mu_2`, any analytic function is
//! `f(A) = c_0 I + c_1 A` with `c_1 = (f(mu_1) - f(mu_2)) / (mu_1 - mu_2)` and
//! `c_0 = (mu_1 f(mu_2) - mu_2 f(mu_1)) / (mu_1 - mu_2)` (Sylvester's formula). The quasi-static
//! rotor is strongly overdamped (eigenvalues about 300x apart), so this replaces a scaling-and-
//! squaring exponential (about 22 3x3 products) by two scalar `expm1` calls. Hand-written: on
//! plain arrays it needs no allocation and no generic matrix machinery (nalgebra's fixed-size
//! matrices would add nothing to two scalars and a 2-vector).

/// `[phi_1(z), phi_2(z), phi_3(z)]` together: one `expm1` and the downward recurrence away from 0;
/// near 0 the series of `phi_3` (reciprocal constants, no division) and the upward recurrence
/// `phi_k = 1/k! + z phi_{k+1}`, which is stable there.
#[inline]
pub fn phis(z: f64) -> [f64; 3] {
    if z.abs() < 0.5 {
        // phi_3(z) = sum_n z^n / (n + 3)!, 16 terms: the remainder is below 0.5^16 / 19! ~ 1e-22.
        let mut sum = 0.0;
        for n in (0..16).rev() {
            sum = sum * z + INV_FACTORIAL[n + 3];
        }
        let phi2 = 0.5 + z * sum;
        return [1.0 + z * phi2, phi2, sum];
    }
    // Below -40, exp(z) < 5e-18 is under half an ulp of 1 and expm1 is -1 exactly: skip the call
    // (the stiff rotor's inertial eigenvalue, -h c/I, is about -500 at 1 us substeps).
    let phi1 = if z < -40.0 { -1.0 } else { z.exp_m1() } / z;
    let phi2 = (phi1 - 1.0) / z;
    [phi1, phi2, (phi2 - 0.5) / z]
}

/// `1 / n!` for n = 0..=18.
const INV_FACTORIAL: [f64; 19] = {
    let mut t = [1.0; 19];
    let mut n = 1;
    while n < 19 {
        t[n] = t[n - 1] / n as f64;
        n += 1;
    }
    t
};

/// `phi_k(z)` for `k` in 1..=3, by its series near 0 and the recurrence from `expm1` elsewhere.
pub fn phi(k: u32, z: f64) -> f64 {
    if z.abs() < 0.5 {
        // 16 terms: the remainder is below 0.5^16 / 16! ~ 1e-18.
        let mut factorial = (1..=k).map(f64::from).product::<f64>();
        let (mut term, mut sum) = (1.0 / factorial, 0.0);
        for n in 0..16u32 {
            sum += term;
            factorial = f64::from(n + k + 1);
            term *= z / factorial;
        }
        return sum;
    }
    let mut value = z.exp_m1() / z;
    let mut inv_factorial = 1.0;
    for j in 2..=k {
        inv_factorial /= f64::from(j - 1);
        value = (value - inv_factorial) / z;
    }
    value
}

/// `phi_k(A)` for a real 2x2 matrix `A` with real, well-separated eigenvalues, as `(c_0, c_1)`
/// with `phi_k(A) = c_0 I + c_1 A`; `None` for complex or nearly repeated eigenvalues (the
/// caller then uses the general matrix exponential).
pub struct Phi2x2 {
    mu: (f64, f64),
    /// `1 / (mu_1 - mu_2)`, shared by every [`Self::apply`].
    inv_gap: f64,
    /// `phi_1..3` at each eigenvalue.
    at_mu: ([f64; 3], [f64; 3]),
}

impl Phi2x2 {
    /// Inlined, as [`Self::apply`]: a returned struct goes through memory.
    #[inline(always)]
    pub fn new(a: &[[f64; 2]; 2]) -> Option<Self> {
        let half_trace = 0.5 * (a[0][0] + a[1][1]);
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let disc = half_trace * half_trace - det;
        if !(disc.is_finite() && disc > 0.0) {
            return None;
        }
        // The larger eigenvalue without cancellation, the smaller from the determinant.
        let root = disc.sqrt();
        let mu1 = if half_trace <= 0.0 {
            half_trace - root
        } else {
            half_trace + root
        };
        if mu1 == 0.0 {
            return None;
        }
        let mu2 = det / mu1;
        ((mu1 - mu2).abs() > 1e-6 * (mu1.abs() + mu2.abs())).then(|| Self {
            mu: (mu1, mu2),
            inv_gap: 1.0 / (mu1 - mu2),
            at_mu: (phis(mu1), phis(mu2)),
        })
    }

    /// `phi_k(A) v` (`k` in 1..=3) for the matrix `a` given to [`Self::new`].
    #[inline(always)]
    pub fn apply(&self, k: u32, a: &[[f64; 2]; 2], v: [f64; 2]) -> [f64; 2] {
        let (mu1, mu2) = self.mu;
        let i = (k.clamp(1, 3) - 1) as usize;
        let (f1, f2) = (self.at_mu.0[i], self.at_mu.1[i]);
        let c1 = (f1 - f2) * self.inv_gap;
        let c0 = (mu1 * f2 - mu2 * f1) * self.inv_gap;
        [
            c0 * v[0] + c1 * (a[0][0] * v[0] + a[0][1] * v[1]),
            c0 * v[1] + c1 * (a[1][0] * v[0] + a[1][1] * v[1]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the Taylor series of the matrix function, summed directly for a small matrix,
    /// and against the scalar definition on a diagonal matrix with stiff eigenvalues.
    #[test]
    fn matches_the_series_and_the_scalar_definition() {
        for k in 1..=3 {
            for z in [-30.0f64, -1.0, -0.49, -1e-9, 0.0, 0.3, 0.51, 2.0] {
                let series: f64 = (0..60u32)
                    .map(|n| z.powi(n as i32) / (1..=n + k).map(f64::from).product::<f64>())
                    .sum();
                if z.abs() <= 2.0 {
                    assert!(
                        (phi(k, z) - series).abs() <= 1e-14 * series.abs(),
                        "{k} {z}"
                    );
                }
            }
            let big = -500.0f64;
            let direct = match k {
                1 => big.exp_m1() / big,
                2 => (big.exp_m1() / big - 1.0) / big,
                _ => ((big.exp_m1() / big - 1.0) / big - 0.5) / big,
            };
            assert!((phi(k, big) - direct).abs() <= 1e-15 * direct.abs());
        }
        // An overdamped rotor block [[0, h], [-h k/I, -h c/I]] against the scaling-and-squaring
        // exponential of the augmented matrix [[A, v], [0, 0]], whose last column is phi_1(A) v.
        let a = [[0.0, 1.0], [-0.3, -500.0]];
        let v = [0.7, -1.3];
        let p1 = Phi2x2::new(&a).unwrap().apply(1, &a, v);
        let mut m = [[0.0; 3]; 3];
        for i in 0..2 {
            m[i][0] = a[i][0];
            m[i][1] = a[i][1];
            m[i][2] = v[i];
        }
        let e = crate::physics::numerics::expm::expm(&m).unwrap();
        for i in 0..2 {
            assert!(
                (p1[i] - e[i][2]).abs() <= 1e-12 * e[i][2].abs(),
                "{p1:?} {e:?}"
            );
        }
        // The joint evaluation agrees with the single one.
        for z in [
            -700.0f64, -30.0, -0.6, -0.49, -1e-3, 0.0, 0.2, 0.49, 0.51, 3.0,
        ] {
            let p = phis(z);
            for k in 1..=3u32 {
                let single = phi(k, z);
                assert!(
                    (p[k as usize - 1] - single).abs() <= 4e-16 * single.abs(),
                    "{k} {z}"
                );
            }
        }
        // A complex pair is refused.
        assert!(Phi2x2::new(&[[0.0, 1.0], [-1.0, 0.0]]).is_none());
    }
}
