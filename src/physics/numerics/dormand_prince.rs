//! One step of the explicit Dormand-Prince 5(4) pair (Dormand and Prince, J. Comput. Appl. Math.
//! 6, 1980) on a small fixed-size system, with its embedded error. Hand-written on plain arrays:
//! it runs inside the motor's per-substep loops, where a rate may fail (`None`) instead of
//! panicking.

/// The stages' coefficients; the last row is the fifth-order weights, at whose result the
/// seventh stage is evaluated (first same as last: it is the next step's first).
const A: [&[f64]; 6] = [
    &[0.2],
    &[3.0 / 40.0, 9.0 / 40.0],
    &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
    &[
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
    ],
    &[
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
    ],
    &[
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// The fifth-order weights less the embedded fourth-order ones.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// The fifth-order result of a step from `y` (rates `k1` there) over `h`, and the seven stages'
/// rates (the last at the result). `None` where `rate` fails at a stage.
pub fn step<const N: usize>(
    y: &[f64; N],
    k1: &[f64; N],
    h: f64,
    mut rate: impl FnMut(&[f64; N]) -> Option<[f64; N]>,
) -> Option<([f64; N], [[f64; N]; 7])> {
    let mut k = [*k1; 7];
    let mut at = [0.0; N];
    for stage in 0..6 {
        at = std::array::from_fn(|i| {
            y[i] + h * A[stage].iter().zip(&k).map(|(a, k)| a * k[i]).sum::<f64>()
        });
        k[stage + 1] = rate(&at)?;
    }
    Some((at, k))
}

/// Component `i` of the fifth-order result less the embedded fourth-order one, over a step `h`
/// with stages `k`.
pub fn error<const N: usize>(h: f64, k: &[[f64; N]; 7], i: usize) -> f64 {
    h * E.iter().zip(k).map(|(w, k)| w * k[i]).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On `y' = y` the step is the fifth-order Taylor polynomial of `exp(h)` plus the method's
    /// sixth-order term, and the error estimate is of the fifth order: both checked against
    /// `exp` at halving steps (the local error falls 64-fold, the estimate 32-fold).
    #[test]
    fn local_error_and_estimate_have_their_orders() {
        let rate = |z: &[f64; 1]| Some(*z);
        let (mut last_err, mut last_est) = (f64::NAN, f64::NAN);
        for n in 0..4 {
            let h = 0.2 * 0.5f64.powi(n);
            let (y, k) = step(&[1.0], &[1.0], h, rate).unwrap();
            let (err, est) = ((y[0] - h.exp()).abs(), error(h, &k, 0).abs());
            if n > 0 {
                let (p, q) = ((last_err / err).log2(), (last_est / est).log2());
                assert!((p - 6.0).abs() < 0.2, "local order {p}");
                assert!((q - 5.0).abs() < 0.2, "estimate order {q}");
            }
            (last_err, last_est) = (err, est);
        }
    }

    /// A failing rate ends the step.
    #[test]
    fn a_failing_rate_gives_none() {
        let mut calls = 0;
        let out = step(&[1.0], &[1.0], 0.1, |z: &[f64; 1]| {
            calls += 1;
            (calls < 3).then_some(*z)
        });
        assert!(out.is_none());
        assert_eq!(calls, 3);
    }
}
