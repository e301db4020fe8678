//! A free rotor's Gilbert onion that approaches its minimum slowly, handed over to its
//! quasi-static branch, against a plain RK4 of the macrospin ([`Motor::ends_at_minimum`]).

use super::locked_accuracy_tests::converged_rk4;
use super::onion_periods_tests::{case, values};

/// A benchmark draw: gilbert_damping 0.5, tolerance 3.3e-6, a load that spins the rotor from
/// rest to 1.8e7 rad/s within the 1 us step. The onion starts 0.039 rad from the minimum of
/// eq. 3.4 that the strain holds it in, which it approaches at `lambda = 1e6 /s` (a weak well:
/// `Ms` 1.2e3 A/m): it decays by a factor `e` over the step, yet ends 0.014 rad from it.
const SPUN_UP: &str = "strain_direction=2.831707175446057e0 stress=-4.263456709690666e1 \
    load_torque=8.819564974949527e-7 ring_outer_diameter=7.722696735518704e-1 \
    ring_inner_diameter=9.399703726968881e-3 bar_length=1.0936850592135104e-4 \
    bar_width=6.375113544672636e-5 thickness=4.497893326350123e-6 \
    saturation_magnetization=1.2029470381554663e3 magnetostriction=-9.339694190975514e-3 \
    wall_volume=1.43627298942828e-11 density=1.1639487361050292e3 \
    fluid_viscosity=8.173845444016835e-5 gilbert_damping=5.045949362413119e-1 \
    tolerance=3.278096304330736e-6 step_angle=6.597877186031798e0 \
    step_period=2.6354109986202224e4 stress_amplitude=-1.2474082363880158e-1 \
    schedule_initial_direction=-8.344388154479304e4 onion_model=1e0 max_substeps=1.228e3 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=-2.9365805498205793e-6 \
    strain=3.764097700905106e-2 youngs_modulus=2.523774204639009e6 strain_drive=1e0";

/// The step is resolved, not handed to the branch: the onion's angle and tilt end within a
/// tolerance of the RK4 (0.19 and 0.003 tolerances), the rotor's angle too. Handing the onion
/// over at the start (its ringing "decays" by a factor `e` within the step) took one substep,
/// unflagged, and ended 4,320 tolerances off.
#[test]
fn slowly_relaxing_onion_of_a_free_rotor_against_rk4() {
    let (m, start, inputs) = case(&values(SPUN_UP)).unwrap();
    let mut st = start;
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let truth = converged_rk4(&m, &start, &inputs, st.time, 2.0);
    let tol = m.params.tolerance;
    let errors = [
        (st.rotor_angle - truth[0]).abs() / tol,
        (st.onion_angle - truth[2]).abs() / tol,
        (st.onion_tilt - truth[3]).abs() / tol,
    ];
    println!("{report:?}, errors / tolerance {errors:?}");
    assert!(!report.accuracy_limited, "{report:?}");
    assert!(errors.iter().all(|e| *e <= 1.0), "{st:?} against {truth:?}");
}
