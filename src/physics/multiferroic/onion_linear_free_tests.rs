//! A free rotor's Gilbert onion that the ring turns but whose rotor the ring barely turns,
//! advanced over many switches by the linear macro spans ([`Motor::free_ring_term`]), against
//! a converged RK4 of the full equations.

use super::locked_accuracy_tests::converged_rk4;
use super::onion_linear::SPANS;
use super::onion_periods_tests::{case, values};
use super::ringing_drop_tests::C370371;

/// A benchmark case (full precision): a free rotor spinning at 3,540 rad/s under its load on a
/// 1.03 ns schedule, a Gilbert onion damped at 1.2e-4 that the ring's torque offsets by 1.7e-4
/// rad (6,000 tolerances).
const C993794: &str = "strain_direction=-3.7235154732822815e10 stress=-2.6344017747301916e-2 \
    load_torque=-5.018731672649758e-7 ring_outer_diameter=7.355942219543544e-2 \
    ring_inner_diameter=1.6647111408949155e-3 bar_length=4.017482898366122e-5 \
    bar_width=6.87766858837534e-7 thickness=1.7566159577744545e-7 \
    saturation_magnetization=5.244321998429113e6 magnetostriction=-7.977167030642485e-3 \
    wall_volume=6.021240112569207e-11 density=8.954167078804581e4 \
    fluid_viscosity=8.304661382894546e3 gilbert_damping=1.1578067790703509e-4 \
    tolerance=2.7933318955594736e-8 step_angle=4.598700042196322e0 \
    step_period=1.0312071396712218e-9 stress_amplitude=-3.935286840287876e0 \
    schedule_initial_direction=-7.179310171477787e2 onion_model=1e0 max_substeps=9.249e3 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=2.5361047823027893e-5 \
    strain=4.9709541722195216e-2 youngs_modulus=1.244836482447901e10 strain_drive=1e0";

/// A benchmark case (full precision): a free rotor in a 0.70 m ring on a 1.12 ns schedule, a
/// Gilbert onion damped at 0.037 at a tolerance of 0.17 rad and a budget of 1,972 substeps.
const C943623: &str = "strain_direction=9.293128595768033e6 stress=1.3358571039689146e4 \
    load_torque=-3.619377309010687e-8 ring_outer_diameter=6.994020640659625e-1 \
    ring_inner_diameter=4.289385074105419e-2 bar_length=1.4485937814359398e-3 \
    bar_width=4.3511616612279064e-4 thickness=5.275909592993535e-5 \
    saturation_magnetization=1.7975444909092315e4 magnetostriction=8.549807029133888e-3 \
    wall_volume=7.680704808540798e-11 density=1.2856617152333592e3 \
    fluid_viscosity=1.997890428144144e-5 gilbert_damping=3.7320167074652175e-2 \
    tolerance=1.7462770666924735e-1 step_angle=-3.0600772731864385e0 \
    step_period=1.1231512719289451e-9 stress_amplitude=1.0839590285512827e-2 \
    schedule_initial_direction=8.382962296192973e3 onion_model=1e0 max_substeps=1.972e3 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=5.2027271397217515e-11 \
    strain=-4.5106828132214984e-2 youngs_modulus=1.4669750900788707e8 strain_drive=0e0";

/// A case's first 1 us step with its tolerance scaled by `scale` against [`converged_rk4`] at
/// `per_ns`: the errors of the rotor's and the onion's angles and the onion's tilt in
/// tolerances, the step's substeps and the spans taken.
fn first_step(text: &str, scale: f64, per_ns: f64) -> ([f64; 3], u32, u32) {
    let mut kv = values(text);
    let tol = kv["tolerance"] * scale;
    kv.insert("tolerance".into(), tol);
    let (m, start, inputs) = case(&kv).unwrap();
    let mut end = start;
    let spans = SPANS.with(|c| c.get());
    let report = m.step(&mut end, &inputs, 1e-6).unwrap();
    let spans = SPANS.with(|c| c.get()) - spans;
    assert!(!report.accuracy_limited);
    let truth = converged_rk4(&m, &start, &inputs, end.time, per_ns);
    let errors = [
        (end.rotor_angle - truth[0]).abs() / tol,
        (end.onion_angle - truth[2]).abs() / tol,
        (end.onion_tilt - truth[3]).abs() / tol,
    ];
    println!(
        "{errors:?} in tolerances, {} substeps, {spans} spans",
        report.substeps
    );
    (errors, report.substeps, spans)
}

/// A 0.93 m ring on a 1.26 ns schedule: the ring's torque offsets the slow onion (precessing
/// at 2.6e6 rad/s) by 9e-6 rad, 36,000 tolerances, but turns the massive rotor by 2e-21 rad
/// over the step. The spans chain its 794 switches in 9 spans (one substep a switch without
/// them), within the tolerance of the RK4.
#[test]
fn a_free_rotor_barely_turned_by_its_ring_chains_its_switches() {
    let (errors, substeps, spans) = first_step(C370371, 1.0, 50.0);
    assert!(errors.iter().all(|&e| e <= 1.0), "{errors:?}");
    assert!(
        spans >= 1 && substeps <= 100,
        "{substeps} substeps, {spans} spans"
    );
}

/// A rotor spinning at 3,540 rad/s turns the offset by 3.6e-6 rad a switch, which moves the
/// ring's torque on the onion by about as much as eq. 3.4's own nonlinearity: at a thousand
/// times its tolerance the spans are taken while the bar turns, within the tolerance of the
/// RK4.
#[test]
fn a_spinning_free_rotor_turns_the_ring_torque_within_the_bound() {
    let (errors, _, spans) = first_step(C993794, 1e3, 2e3);
    assert!(errors.iter().all(|&e| e <= 1.0), "{errors:?}");
    assert!(spans >= 1, "{spans} spans");
}

/// One substep a switch spent this draw's budget within the step (893 substeps, the step
/// flagged, 4.2e-3 tolerances off the RK4); the spans chain its 889 switches in about 50
/// substeps, unflagged.
#[test]
fn a_free_rotor_whose_switches_outran_its_budget_chains_them() {
    let (errors, substeps, spans) = first_step(C943623, 1.0, 20.0);
    assert!(errors.iter().all(|&e| e <= 1.0), "{errors:?}");
    assert!(
        spans >= 1 && substeps <= 200,
        "{substeps} substeps, {spans} spans"
    );
}
