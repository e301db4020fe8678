//! Matrix exponential of a small fixed-size matrix by scaling and squaring with a Taylor series.
//!
//! Hand-written on plain arrays for speed on the per-substep hot path (three calls per substep)
//! and so that a hopeless argument returns `None` instead of panicking or producing NaN. Generic
//! over the size: the quasi-static motor needs 3x3 (rotor and forcing), the Gilbert one 5x5.

/// The size of the full augmented system: rotor angle and speed, onion angle and tilt, forcing.
pub const N: usize = 5;
pub type Mat<const N: usize> = [[f64; N]; N];

fn mul<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    let mut c = [[0.0; N]; N];
    for i in 0..N {
        for k in 0..N {
            let aik = a[i][k];
            if aik != 0.0 {
                for j in 0..N {
                    c[i][j] += aik * b[k][j];
                }
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
    // Horner: I + a (I + a/2 (I + a/3 (...))).
    let mut e = identity();
    for k in (1..=12).rev() {
        let mut t = mul(&a, &e);
        let inv = 1.0 / k as f64;
        for (i, row) in t.iter_mut().enumerate() {
            for x in row.iter_mut() {
                *x *= inv;
            }
            row[i] += 1.0;
        }
        e = t;
    }
    for _ in 0..squarings {
        e = mul(&e, &e);
    }
    if e.iter().flatten().all(|x| x.is_finite()) {
        Some(e)
    } else {
        None
    }
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
        let mut m = [[0.0; N]; N];
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
        m[3][3] = f64::NAN;
        assert!(expm(&m).is_none());
    }
}
