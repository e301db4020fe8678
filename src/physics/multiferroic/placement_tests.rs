//! The Gilbert onion's placement on its quasi-static branch ([`Motor::relaxed_onion`]) on fast
//! schedules against a converged RK4 of the motor's equations.

use super::onion_periods_tests::{case, values};
use super::*;

/// The state at `t_end` by the classical RK4 of the motor's equations
/// ([`super::resolved_tests::rk4`]) from `start`, its substeps per nanosecond doubled from 8
/// until two runs agree within a hundredth of the tolerance in the rotor's and the onion's angles
/// and the tilt.
fn converged(m: &Motor, start: &MotorState, inputs: &MotorInputs, t_end: f64) -> Vector {
    let tol = m.params.tolerance;
    let mut per_ns = 8.0;
    let mut last = super::resolved_tests::rk4(m, start, inputs, t_end, per_ns);
    loop {
        per_ns *= 2.0;
        assert!(per_ns <= 4e4, "RK4 not converged");
        let y = super::resolved_tests::rk4(m, start, inputs, t_end, per_ns);
        if [0, 2, 3]
            .iter()
            .all(|&i| (y[i] - last[i]).abs() <= 0.01 * tol)
        {
            return y;
        }
        last = y;
    }
}

/// Three 1 us steps of benchmark draw 879579 (free rotor, damping 8.2e-2, tolerance 0.56 rad,
/// the strain turned by -9.25 rad every 2.24 ns; the ring's torque cannot move the rotor): the
/// onion's gap from a minimum shrinks to `exp(-lambda T)` = 0.77 of itself a period, so it
/// passes within the tolerance of some minimum every few switches without having relaxed. Each
/// step's rotor and onion angles and tilt are within a tolerance of [`converged`] from the same
/// start. (Placed on its branch there, it ended each step 92-94 tolerances off.)
#[test]
fn an_onion_near_a_minimum_is_placed_only_once_relaxed() {
    let (m, mut st, inputs) = case(&values(DRAW_879579)).unwrap();
    let s = *inputs.schedule.get().unwrap();
    let k = 2.0 * (m.magnetoelastic_per_stress * s.stress_amplitude).abs();
    let decay = (-m.onion_decay_rate(k) * s.step_period).exp();
    println!("decay over a period at the minimum's curvature: {decay}");
    assert!(decay > 0.7, "{decay}");
    let tol = m.params.tolerance;
    for n in 0..3 {
        let start = st;
        let report = m.step(&mut st, &inputs, 1e-6).unwrap();
        let truth = converged(&m, &start, &inputs, st.time);
        let errors = [
            (st.rotor_angle - truth[0]).abs() / tol,
            (st.onion_angle - truth[2]).abs() / tol,
            (st.onion_tilt - truth[3]).abs() / tol,
        ];
        println!(
            "step {n}: {} substeps, errors / tolerance against RK4 {errors:?}",
            report.substeps
        );
        assert!(!report.accuracy_limited, "step {n}");
        assert!(errors.iter().all(|e| *e <= 1.0), "step {n}: {errors:?}");
    }
}

/// Benchmark draw 879579 (free rotor, damping 8.2e-2, the strain turned by -9.25 rad every
/// 2.24 ns).
const DRAW_879579: &str = "strain_direction=4.5059466230394336e5 stress=9.84935167724793e-3 \
    load_torque=9.735252176210894e-8 ring_outer_diameter=9.646425416221389e-1 \
    ring_inner_diameter=3.520139674271862e-1 bar_length=1.5971770250015274e-1 \
    bar_width=2.0874873905760543e-7 thickness=2.162366405402761e-9 \
    saturation_magnetization=9.225907667555375e5 magnetostriction=-9.392607423701453e-4 \
    wall_volume=2.5423423893863373e-11 density=7.404904357184041e3 \
    fluid_viscosity=5.379477647136184e0 gilbert_damping=8.180130053052166e-2 \
    tolerance=5.566669196623509e-1 step_angle=-9.251264299878647e0 \
    step_period=2.2411946956575363e-9 stress_amplitude=-1.7243658723112974e4 \
    schedule_initial_direction=1.6614134442543017e-7 onion_model=1e0 max_substeps=7.916e3 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=-7.885761944492388e0 \
    strain=6.774645300132973e-2 youngs_modulus=5.7842162650969446e7 strain_drive=0e0";
