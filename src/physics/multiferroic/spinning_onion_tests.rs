//! A free rotor's Gilbert onion spinning just above its wells' rims: its dynamics carry the
//! substeps' local errors far beyond the tolerance, and the step is flagged
//! ([`Motor::errors_amplified`]).

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4;
use super::MotorState;

/// A benchmark draw (the FMU's variables, full precision): damping 1.3e-4, tolerance 9.9e-6, a
/// 109 ns schedule; the onion, kicked over its rims by the first switches, spins just above
/// them and passes one every few nanoseconds; the rotor, which the ring cannot move, drifts
/// under its load.
const SPINNING: &str = "strain_direction=1.3024736793068118e-2 stress=-8.196682656120177e4 \
     load_torque=-2.0978096651517462e-7 ring_outer_diameter=3.032449967664053e-1 \
     ring_inner_diameter=1.2093064848961722e-1 bar_length=3.538641960077361e-3 \
     bar_width=1.0033689835586008e-3 thickness=1.0369514286630586e-6 \
     saturation_magnetization=1.0071939752201122e2 magnetostriction=-2.3860143911545728e-4 \
     wall_volume=2.966696133053281e-11 density=7.26396810997685e3 \
     fluid_viscosity=1.0050575826874843e-1 gilbert_damping=1.2527760100882932e-4 \
     tolerance=9.909567620436135e-6 step_angle=8.371627819937316e0 \
     step_period=1.0921300845490324e-7 stress_amplitude=5.77023984067447e2 \
     schedule_initial_direction=-7.691313234556783e-5 onion_model=1e0 max_substeps=4.809e3 \
     schedule=1e0 rotor_locked=0e0 initial_onion_offset=1.975364602390113e-4 \
     strain=-1.4373859032901379e-2 youngs_modulus=4.2870643797974917e12 strain_drive=0e0";

/// The first 1 us step against a plain RK4 of the motor's equations (100 and 200 substeps per
/// nanosecond agree within half the tolerance; their own errors are amplified too): each resolved substep is within about the
/// tolerance of the RK4 from its start, but the onion ends thousands of tolerances off in angle
/// and a radian in tilt. Not an error of any path: the RK4 itself, started 1e-11 rad away in
/// the onion's angle, ends more than 1e-4 rad away (the dynamics amplify by 3.4e8), so no local
/// tolerance the budget can pay for resolves the step. It is flagged; unflagged, it was 2,911
/// tolerances off in angle and 1.3e5 in tilt.
#[test]
fn onion_spinning_above_its_rims_is_flagged() {
    let (m, start, inputs) = case(&values(SPINNING)).unwrap();
    let tol = m.params.tolerance;
    let t_end = 1e-6;
    let (coarse, truth) = (
        rk4(&m, &start, &inputs, t_end, 100.0),
        rk4(&m, &start, &inputs, t_end, 200.0),
    );
    assert!(
        (coarse[2] - truth[2]).abs() <= 0.5 * tol && (coarse[3] - truth[3]).abs() <= 0.5 * tol,
        "{coarse:?} {truth:?}"
    );
    let nudged = MotorState {
        onion_angle: start.onion_angle + 1e-11,
        ..start
    };
    let apart = rk4(&m, &nudged, &inputs, t_end, 100.0);
    assert!(
        (apart[2] - coarse[2])
            .abs()
            .max((apart[3] - coarse[3]).abs())
            > 1e-4,
        "{apart:?} {coarse:?}"
    );
    let mut st = start;
    let report = m.step(&mut st, &inputs, t_end).unwrap();
    let errors = [
        (st.onion_angle - truth[2]).abs() / tol,
        (st.onion_tilt - truth[3]).abs() / tol,
    ];
    println!("{report:?} {st:?} against {truth:?}: errors / tolerance {errors:?}");
    assert!(errors[0] > 100.0, "{errors:?}");
    assert!(report.accuracy_limited);
}

/// The 2x2 exponential of the bound against the Taylor series' scaling and squaring
/// ([`expm`](crate::physics::numerics::expm::expm)) on the onion's blocks: damped precession,
/// overdamped decay over long substeps, a saddle, and the repeated eigenvalues between.
#[test]
fn onion_block_exponential_matches_the_series() {
    use crate::physics::numerics::expm::expm;
    let blocks = [
        [[-1e-4, -3.0], [2.0, -2e-4]],
        [[-40.0, -1.0], [30.0, -2.0]],
        [[0.5, -1.0], [-2.0, 0.1]],
        [[-1.0, 1e-8], [0.0, -1.0]],
        [[-3.0, 1.0], [-1.0, -1.0]],
        [[-0.02, -25.0], [0.01, -0.03]],
    ];
    for a in blocks {
        let e = crate::physics::numerics::expm2::expm2(&a).unwrap();
        let reference = expm(&a).unwrap();
        for (row, expected) in e.iter().zip(&reference) {
            for (x, r) in row.iter().zip(expected) {
                let scale = reference
                    .iter()
                    .flatten()
                    .map(|v| v.abs())
                    .fold(0.0, f64::max);
                assert!((x - r).abs() <= 1e-12 * scale, "{a:?}: {e:?} {reference:?}");
            }
        }
    }
}
