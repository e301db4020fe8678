//! A locked rotor's creeping onion with the exponential RK4 tried first near the explicit
//! pair's stability limit ([`Motor::locked_stiff_step`]), against a plain RK4.

use super::locked_accuracy_tests::{onion_errors, step_against_rk4};
use super::onion_periods_tests::{case, values};

/// Gilbert damping 0.16, tolerance 1.3e-10, the rotor locked and no switch within the step: the
/// onion, released 0.4 rad off its minimum, creeps there within about 7 ns, its tilt relaxing at
/// 8e10/s, faster than it turns.
const CREEPER: &str = "strain_direction=4.767180892121511e11 stress=9.27047012884767e3 \
    load_torque=-2.452732207603578e-7 ring_outer_diameter=1.0864692610322602e-2 \
    ring_inner_diameter=1.9456020961206927e-4 bar_length=1.8345430719627792e-5 \
    bar_width=4.98656014328723e-7 thickness=4.90123375068334e-7 \
    saturation_magnetization=2.2462883579158476e6 magnetostriction=7.641492003332485e-3 \
    wall_volume=4.089848462414344e-11 density=1.25588739036532e3 \
    fluid_viscosity=1.2105183424720793e4 gilbert_damping=1.587190167848106e-1 \
    tolerance=1.3147242394036854e-10 step_angle=5.811643805565508e0 \
    step_period=4.756717716120883e-3 stress_amplitude=5.389475844491013e6 \
    schedule_initial_direction=-5.12990142882202e4 onion_model=1 max_substeps=1.4921e4 \
    schedule=0 rotor_locked=1 initial_onion_offset=5.268448677524112e-10 \
    strain=-5.5748546746975804e-2 youngs_modulus=9.398411927250062e11 strain_drive=0";

/// Steps of `dt` from the creeper's start: each step's substeps and its onion angle's and tilt's
/// errors in tolerances against the converged RK4 ([`onion_errors`]) from that step's start.
fn creep(dt: f64, steps: usize) -> Vec<(u32, [f64; 2])> {
    let (m, mut st, inputs) = case(&values(CREEPER)).unwrap();
    assert!(inputs.rotor_locked);
    (0..steps)
        .map(|_| {
            let start = st;
            let report = m.step(&mut st, &inputs, dt).unwrap();
            assert!(!report.accuracy_limited, "{report:?}");
            assert_eq!(st.rotor_angle, start.rotor_angle);
            let errors = onion_errors(&m, &start, &st, &inputs, 1000.0);
            println!(
                "{} substeps, errors / tolerance {errors:?}",
                report.substeps
            );
            (report.substeps, errors)
        })
        .collect()
}

/// The creeper's first 1 us step: within the tolerance of the RK4 in at most 60 substeps; with
/// the explicit pair held at its stability reach by the tilt's relaxation (the substep growing by
/// half a percent a substep at an error estimate near 0.73) it took 192.
#[test]
fn locked_creeping_onion_step_in_few_substeps_against_rk4() {
    let steps = creep(1e-6, 1);
    let (substeps, errors) = steps[0];
    assert!(errors.iter().all(|e| *e <= 1.0), "{errors:?}");
    assert!(substeps <= 60, "{substeps} substeps");
}

/// The creeper in 2 ns steps, the first ending mid-creep: each within a tenth of the tolerance
/// of the RK4, the first in at most 30 substeps (91 with the explicit pair, 0.17 tolerances off).
#[test]
fn locked_creeping_onion_mid_creep_against_rk4() {
    let steps = creep(2e-9, 4);
    for (_, errors) in &steps {
        assert!(errors.iter().all(|e| *e <= 0.1), "{steps:?}");
    }
    assert!(steps[0].0 <= 30, "{steps:?}");
}

/// Gilbert damping 0.31, tolerance 1.7e-10, no switch within the steps (a 407 s period): the
/// third 1 us step, the onion still creeping to its minimum, within a hundredth of the tolerance
/// of the RK4 in at most 18 substeps (24 with the explicit pair, 0.47 tolerances off).
#[test]
fn locked_onion_creeping_from_half_a_radian_against_rk4() {
    let (errors, substeps) = step_against_rk4(
        "strain_direction=-1.036e9 stress=2.986e-2 load_torque=6.046e-7 \
         ring_outer_diameter=4.532e-1 ring_inner_diameter=7.484e-5 bar_length=4.954e-7 \
         bar_width=4.271e-7 thickness=1.265e-9 saturation_magnetization=6.137e2 \
         magnetostriction=4.094e-3 wall_volume=4.967e-12 density=4.937e3 fluid_viscosity=5.529e1 \
         gilbert_damping=3.094e-1 tolerance=1.656e-10 step_angle=-4.647e0 step_period=4.066e2 \
         stress_amplitude=1.259e-3 schedule_initial_direction=-1.090e-4 onion_model=1 \
         max_substeps=4.060e2 rotor_locked=1 initial_onion_offset=-5.548e-1 strain=2.288e-2 \
         youngs_modulus=8.883e12",
        2,
        1000.0,
        0.01,
    );
    assert!(substeps <= 18, "{substeps} substeps, errors {errors:?}");
}
