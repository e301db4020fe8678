//! A locked rotor's Gilbert onion over whole 1 us steps against a plain RK4 of the macrospin:
//! its angle is the output, so its ringing is dropped only within the tolerance on that angle
//! ([`Motor::relaxed_onion`]).

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4;
use super::*;

/// The classical RK4 of the motor's equations ([`rk4`], the locked rotor's rows zero) from
/// `start` to `t_end` at `per_ns` substeps per nanosecond and at twice that: the finer result,
/// once the two agree within a hundredth of the tolerance in the onion's angle and tilt.
pub(super) fn converged_rk4(
    m: &Motor,
    start: &MotorState,
    inputs: &MotorInputs,
    t_end: f64,
    per_ns: f64,
) -> Vector {
    let run = |per_ns: f64| rk4(m, start, inputs, t_end, per_ns);
    let (coarse, fine) = (run(per_ns), run(2.0 * per_ns));
    let tol = m.params.tolerance;
    assert!(
        (coarse[2] - fine[2]).abs() <= 0.01 * tol && (coarse[3] - fine[3]).abs() <= 0.01 * tol,
        "RK4 not converged: {coarse:?} {fine:?}"
    );
    fine
}

/// The onion's angle and tilt at `end` against [`converged_rk4`] from `start` to `end.time` at
/// `per_ns`, in tolerances.
pub(super) fn onion_errors(
    m: &Motor,
    start: &MotorState,
    end: &MotorState,
    inputs: &MotorInputs,
    per_ns: f64,
) -> [f64; 2] {
    let truth = converged_rk4(m, start, inputs, end.time, per_ns);
    let tol = m.params.tolerance;
    [
        (end.onion_angle - truth[2]).abs() / tol,
        (end.onion_tilt - truth[3]).abs() / tol,
    ]
}

/// A benchmark case's 1 us step after `warm` others (which bring the onion onto its cycle of
/// switches) against [`converged_rk4`] from the same start: not accuracy-limited, the onion's
/// angle and tilt within `bound` tolerances of it. Returns the errors in tolerances and the
/// step's substeps.
pub(super) fn step_against_rk4(
    text: &str,
    warm: usize,
    per_ns: f64,
    bound: f64,
) -> ([f64; 2], u32) {
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    assert!(inputs.rotor_locked);
    for _ in 0..warm {
        m.step(&mut st, &inputs, 1e-6).unwrap();
    }
    let start = st;
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let truth = converged_rk4(&m, &start, &inputs, st.time, per_ns);
    let tol = m.params.tolerance;
    let errors = [
        (st.onion_angle - truth[2]).abs() / tol,
        (st.onion_tilt - truth[3]).abs() / tol,
    ];
    println!(
        "{} substeps, errors / tolerance against RK4 {errors:?}",
        report.substeps
    );
    assert!(!report.accuracy_limited, "{report:?}");
    assert_eq!(st.rotor_angle, start.rotor_angle);
    assert!(
        errors.iter().all(|e| *e <= bound),
        "{st:?} against {truth:?}"
    );
    (errors, report.substeps)
}

/// Strain turned by -0.014 rad every 22 ns, gilbert_damping 1.4e-4, tolerance 1e-8: the onion
/// rings through every switch, losing 0.1% a period. The third 1 us step, resolved (a budget of
/// 30,000: the drawn 6,861 cannot pay for the ringing, and such a step is refused,
/// [`Motor::locked_budget_drop`]), within 300 tolerances of the RK4, the substeps' local errors
/// carried by the weakly damped ringing over 45 switches; the free rotor's allowance for ringing
/// (up to 1e-3 rad) ended it 8.5e5 tolerances off.
#[test]
fn locked_onion_on_a_22_ns_schedule_against_rk4() {
    step_against_rk4(
        "strain_direction=-2.670e5 stress=-3.356e0 load_torque=-2.325e-7 \
         ring_outer_diameter=5.987e-2 ring_inner_diameter=3.915e-2 bar_length=1.390e-5 \
         bar_width=7.725e-7 thickness=1.577e-9 saturation_magnetization=2.609e3 \
         magnetostriction=6.341e-3 wall_volume=1.532e-12 density=5.774e3 fluid_viscosity=4.801e-2 \
         gilbert_damping=1.448e-4 tolerance=1.012e-8 step_angle=-1.358e-2 step_period=2.224e-8 \
         stress_amplitude=-4.277e1 schedule_initial_direction=4.313e-7 onion_model=1 \
         max_substeps=3e4 schedule=1 rotor_locked=1 initial_onion_offset=-4.883e-2 \
         strain=-4.801e-2 youngs_modulus=6.645e6",
        2,
        400.0,
        300.0,
    );
}

/// Strain turned by 0.083 rad every 1.1 ns, gilbert_damping 4.9e-4, tolerance 1.6e-2: each
/// switch kicks the onion again, its ringing (tilt 5e-3 rad, several tolerances in angle) never
/// decays within the tolerance. Within the tolerance of the RK4; dropped where it came within
/// the free rotor's allowance, it ended 4 tolerances off.
#[test]
fn locked_onion_on_a_1_ns_schedule_against_rk4() {
    step_against_rk4(
        "strain_direction=1.339e8 stress=-1.679e6 load_torque=4.062e-7 \
         ring_outer_diameter=6.792e-1 ring_inner_diameter=3.939e-1 bar_length=9.345e-7 \
         bar_width=8.587e-7 thickness=6.104e-9 saturation_magnetization=6.218e4 \
         magnetostriction=9.855e-3 wall_volume=7.798e-11 density=1.016e4 fluid_viscosity=1.506e8 \
         gilbert_damping=4.936e-4 tolerance=1.576e-2 step_angle=3.225e0 step_period=1.124e-9 \
         stress_amplitude=2.000e2 schedule_initial_direction=-2.932e-4 onion_model=1 \
         max_substeps=1.223e4 schedule=1 rotor_locked=1 initial_onion_offset=-7.576e-11 \
         strain=5.453e-3 youngs_modulus=4.263e6 strain_drive=1",
        1,
        100.0,
        1.0,
    );
}

/// Gilbert damping 0.78, tolerance 5.8e-10, a 15.6 us period: the onion creeps towards its
/// minimum through the third 1 us step. Within the tolerance of the RK4; put on its branch
/// where it came within the free rotor's allowance, it ended 1.7e-4 rad (3e5 tolerances) off.
#[test]
fn locked_onion_creeping_to_its_minimum_against_rk4() {
    step_against_rk4(
        "strain_direction=5.519e3 stress=-1.144e6 load_torque=-5.975e-7 \
         ring_outer_diameter=2.221e-1 ring_inner_diameter=5.259e-3 bar_length=5.108e-4 \
         bar_width=9.605e-7 thickness=1.137e-8 saturation_magnetization=1.503e5 \
         magnetostriction=-8.649e-3 wall_volume=7.000e-11 density=2.131e4 fluid_viscosity=1.527e8 \
         gilbert_damping=7.778e-1 tolerance=5.791e-10 step_angle=-5.341e-1 step_period=1.558e-5 \
         stress_amplitude=9.325e1 schedule_initial_direction=-3.007e-6 onion_model=1 \
         max_substeps=1.111e4 schedule=1 rotor_locked=1 initial_onion_offset=1.035e-1 \
         strain=4.858e-2 youngs_modulus=7.320e6",
        2,
        1000.0,
        1.0,
    );
}

/// Strain turned by 8.8 rad every 1.3 us, gilbert_damping 2.8e-4, tolerance 3.5e-6: the third
/// 1 us step's switch sets the onion ringing 0.6 rad wide, which decays to 1.3 tolerances by the
/// step's end and so is averaged over the orbits ([`Motor::advance_orbits`]) to the step's end.
/// Within the tolerance of the RK4, in at most 16 substeps: its averaged steps held to the
/// tolerance at the ringing's width at the step's end, not at its present one, and carrying the
/// energy's logarithm, whose rate changes only with the orbit's shape, instead of 44 (78 before
/// that): the energy itself decays exponentially, and its explicit steps' stages overshoot the
/// minimum once a step spans about a decay time.
#[test]
fn locked_onion_ringing_averaged_to_the_step_end_against_rk4() {
    let (_, substeps) = step_against_rk4(
        "strain_direction=-6.203e-3 stress=3.318e4 load_torque=-8.577e-7 \
         ring_outer_diameter=1.856e-3 ring_inner_diameter=1.170e-3 bar_length=1.624e-4 \
         bar_width=9.096e-7 thickness=1.177e-8 saturation_magnetization=9.982e5 \
         magnetostriction=7.253e-4 wall_volume=6.737e-11 density=6.815e3 fluid_viscosity=6.948e1 \
         gilbert_damping=2.762e-4 tolerance=3.548e-6 step_angle=8.813e0 step_period=1.312e-6 \
         stress_amplitude=1.606e7 schedule_initial_direction=2.620e-5 onion_model=1 \
         max_substeps=5.213e3 schedule=1 rotor_locked=1 initial_onion_offset=1.252e-9 \
         strain=5.524e-2 youngs_modulus=2.084e11 strain_drive=1",
        2,
        1000.0,
        1.0,
    );
    assert!(substeps <= 16, "{substeps} substeps");
}

/// No switch within the steps (an 8206 s period), gilbert_damping 3.0e-4, tolerance 1.6e-4:
/// the onion rings 5 rad off its minimum and is averaged over its orbits
/// ([`Motor::advance_orbits`]) to the last whole orbit before each 1 us step's end. Within the
/// tolerance of the RK4 in angle and tilt: the rest of the step, under an orbit, is resolved
/// with its error measured by step doubling ([`Motor::finish_locked_orbits`]). Left to
/// substeps each held to the tolerance on its own, it ended the first step 4.1 tolerances off
/// in the tilt.
#[test]
fn locked_onion_last_orbit_after_averaging_against_rk4() {
    let text = "strain_direction=7.197e4 stress=4.029e6 load_torque=5.310e-7 \
         ring_outer_diameter=2.709e-1 ring_inner_diameter=6.823e-3 bar_length=2.666e-6 \
         bar_width=1.574e-6 thickness=3.463e-7 saturation_magnetization=1.221e2 \
         magnetostriction=-4.125e-3 wall_volume=4.704e-11 density=1.659e3 fluid_viscosity=1.064e1 \
         gilbert_damping=2.992e-4 tolerance=1.580e-4 step_angle=9.498e0 step_period=8.206e3 \
         stress_amplitude=1.330e1 schedule_initial_direction=-2.924e-9 onion_model=1 \
         max_substeps=1.148e4 schedule=1 rotor_locked=1 initial_onion_offset=5.017e0 \
         strain=6.898e-2 youngs_modulus=7.588e9 strain_drive=1";
    for warm in 0..3 {
        step_against_rk4(text, warm, 100.0, 1.0);
    }
}

/// Strain turned by -0.022 rad every 1.77 us, gilbert_damping 1.8e-3, tolerance 3.9e-9: in the
/// third 1 us step the onion's ringing is dropped once it ends the segment within the
/// tolerance of its minimum ([`Motor::locked_ringing_ends`]). The tilt is an output as well as
/// the angle, and its reach `sqrt(2 E / T)` is the larger here: within the tolerance of the RK4
/// in both. Bounded by the angle's reach alone, the drop left the tilt 8.3 tolerances off.
#[test]
fn locked_onion_dropped_with_its_tilt_within_the_tolerance_against_rk4() {
    step_against_rk4(
        "strain_direction=5.898e8 stress=1.418e4 load_torque=2.236e-8 \
         ring_outer_diameter=4.510e-5 ring_inner_diameter=5.327e-6 bar_length=2.800e-7 \
         bar_width=3.233e-8 thickness=1.184e-9 saturation_magnetization=3.252e1 \
         magnetostriction=-7.344e-3 wall_volume=4.627e-11 density=1.242e4 fluid_viscosity=3.435e-4 \
         gilbert_damping=1.844e-3 tolerance=3.894e-9 step_angle=-2.201e-2 step_period=1.767e-6 \
         stress_amplitude=1.255e2 schedule_initial_direction=-6.861e2 onion_model=1 \
         max_substeps=1.289e4 schedule=1 rotor_locked=1 initial_onion_offset=-3.842e1 \
         strain=-6.999e-2 youngs_modulus=6.145e9 strain_drive=1",
        2,
        100.0,
        1.0,
    );
}
