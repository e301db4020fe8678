//! Matrix exponential of a small fixed-size matrix by scaling and squaring with a Taylor series.
//!
//! Hand-written on plain arrays for speed on the per-substep hot path (three calls per substep)
//! and so that a hopeless argument returns `None` instead of panicking or producing NaN.

pub const N: usize = 5;
pub type Mat = [[f64; N]; N];

fn mul(a: &Mat, b: &Mat) -> Mat {
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
pub fn expm(m: &Mat) -> Option<Mat> {
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

pub fn identity() -> Mat {
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
        m[3][3] = 1e300;
        assert!(expm(&m).is_none());
        m[3][3] = f64::NAN;
        assert!(expm(&m).is_none());
    }
}
