use super::super::tests::{motor_with, rk4_step};
use super::super::{Drive, OnionModel, Vector};

/// `y' = f + J (y - y0)` over `dt` by RK4 in `n` steps: the substep's linear system,
/// integrated without any exponential.
fn linear_rk4(f: &Vector, j: &[[f64; 4]; 4], dt: f64, n: usize) -> Vector {
    let rate = |z: &Vector| -> Vector {
        std::array::from_fn(|i| f[i] + (0..4).map(|k| j[i][k] * z[k]).sum::<f64>())
    };
    let h = dt / n as f64;
    let mut z = [0.0; 4];
    for _ in 0..n {
        z = rk4_step(&rate, &z, h);
    }
    z
}

/// The Gilbert substep's increments over `dt` and `dt / 2` (one balanced exponential and a
/// squaring) against a fine RK4 of the same linear system, from a ringing onion on a turning
/// rotor, for substeps from a fraction of the precession period to many relaxation times.
#[test]
fn gilbert_increments_match_a_fine_integration_of_the_linearization() {
    let m = motor_with(|p| p.onion_model = OnionModel::Gilbert);
    let d = Drive {
        direction: -0.7,
        applied_direction: -0.7,
        stress: 2e8,
        load: 3e-19,
        locked: false,
    };
    let y = [0.2, 3e4, 0.7, 0.01];
    for dt in [1e-12, 1e-11, 1e-10, 1e-9, 1e-8] {
        let (half, full) = m.exponential_increments(&y, dt, &d, true).unwrap();
        for (span, got) in [(dt, full), (0.5 * dt, half.unwrap())] {
            let (f, j) = m.rhs_jacobian(&y, &d, span);
            // RK4 steps well inside the fastest rate (|lambda| h <= 0.01).
            let n = (span * 1e13).ceil().max(100.0) as usize;
            let truth = linear_rk4(&f, &j, span, n);
            for i in 0..4 {
                let scale = truth[i].abs().max(1e-12 * truth[1].abs() * span);
                assert!(
                    (got[i] - truth[i]).abs() <= 1e-8 * scale,
                    "dt {span}: state {i}: {} against {}",
                    got[i],
                    truth[i]
                );
            }
        }
    }
}

#[test]
fn cube_root_and_step_factor() {
    for x in [0.005, 0.01, 0.3, 1.0, 2.0, 27.0, 92.0] {
        let y = super::cube_root(x);
        assert!((y - f64::cbrt(x)).abs() <= 1e-7 * f64::cbrt(x), "{x}: {y}");
    }
    assert_eq!(super::step_factor(0.0), 5.0);
    assert_eq!(super::step_factor(f64::NAN), 0.2);
    assert_eq!(super::step_factor(1e6), 0.2);
    assert!((super::step_factor(1.0) - 0.9).abs() < 1e-7);
}
