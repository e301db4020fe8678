//! A budget-bound free rotor's Gilbert onion against an RK4 of the macrospin: forced substeps
//! must not carry the onion it rings in out of its well.

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4;

/// A benchmark case: a free rotor that the load turns and the ring barely moves, no schedule, its Gilbert onion (damping
/// 1.3e-3) released 0.64 rad from its minimum rings 0.6 rad wide through a 1 us step, far longer
/// than its decay time allows: the budget of 1939 substeps runs out a third of the way.
const BUDGET_RINGING: &str = "strain_direction=1.2973539972703342e-3 \
    stress=-1.0578091047413373e1 load_torque=-3.2889031397661305e-7 \
    ring_outer_diameter=1.1434994042594364e-2 ring_inner_diameter=8.50519202235739e-3 \
    bar_length=1.041983927782893e-3 bar_width=3.731516646021733e-4 \
    thickness=1.2620789069477533e-9 saturation_magnetization=1.527893170576517e3 \
    magnetostriction=-7.7067762737838864e-3 wall_volume=1.4374820604167616e-12 \
    density=6.79156915430682e4 fluid_viscosity=1.0364607658948028e-3 \
    gilbert_damping=1.2878737192662411e-3 tolerance=1.3263276054670223e-9 \
    onion_model=1 max_substeps=1939 schedule=0 rotor_locked=0 \
    initial_onion_offset=-1.9099395344177327e2";

/// The step is flagged (its ringing dropped once the budget cannot resolve it), but its onion
/// must end in the well the resolved onion rings in, off by at most the ringing's reach. Forced
/// substeps spanning a good part of a precession period carried it over three rims: it ended
/// 9.31 rad (`3 pi`) off an RK4 of the macrospin, against 0.117 rad when the substep that
/// leaves the well is not taken and the ringing is dropped there.
#[test]
fn budget_bound_onion_stays_in_its_well() {
    let (m, start, inputs) = case(&values(BUDGET_RINGING)).unwrap();
    let t_end = 1e-6;
    // RK4 at 50 and 100 substeps per ns (the precession period is 64 ns).
    let reference = rk4(&m, &start, &inputs, t_end, 100.0);
    let coarse = rk4(&m, &start, &inputs, t_end, 50.0);
    let tol = m.params.tolerance;
    assert!(
        (reference[2] - coarse[2]).abs() <= 0.01 * tol,
        "{reference:?} {coarse:?}"
    );
    let mut st = start;
    let report = m.step(&mut st, &inputs, t_end).unwrap();
    assert!(report.accuracy_limited);
    let d = m.drive_at(&inputs, t_end);
    let y = [
        st.rotor_angle,
        st.rotor_speed,
        st.onion_angle,
        st.onion_tilt,
    ];
    let minimum = m.settle(&y, &d);
    let resolved_minimum = m.settle(&reference, &d);
    println!("{st:?} against {reference:?}; minima {minimum} {resolved_minimum}");
    assert!(
        (minimum - resolved_minimum).abs() <= 1e-6,
        "{minimum} {resolved_minimum}"
    );
    assert!((st.onion_angle - reference[2]).abs() <= 0.2);
    // The ring barely moves the rotor: it stays within the tolerance.
    assert!((st.rotor_angle - reference[0]).abs() <= tol);
}

/// A benchmark case: a free rotor that the ring barely moves, no schedule, its Gilbert onion
/// (damping 3e-3) ringing through a 1 us step that its budget of 503 substeps cannot resolve at
/// a tolerance of 1.5e-8 rad.
const PUMPED_RINGING: &str = "strain_direction=2.7978746258783985e1 \
    stress=4.775887545759327e0 load_torque=-5.182915971377839e-7 \
    ring_outer_diameter=7.961406580798013e-1 ring_inner_diameter=4.359324131190089e-2 \
    bar_length=4.071635230948753e-3 bar_width=2.9935271310954098e-5 \
    thickness=2.487593208662239e-7 saturation_magnetization=8.296337566605736e1 \
    magnetostriction=-7.7240132015470205e-3 wall_volume=5.090184028298043e-11 \
    density=4.482227132894987e3 fluid_viscosity=1.5130221499148394e1 \
    gilbert_damping=2.9636758559733723e-3 tolerance=1.499773439829388e-8 \
    onion_model=1 max_substeps=503 schedule=0 rotor_locked=0 \
    initial_onion_offset=7.874487900664065e-11";

/// Forced substeps must not pump energy into the onion: the damped macrospin's energy rises
/// only by the work of the rotor's turn. Taken, they left the flagged step's onion 2.75 rad off
/// an RK4 of the macrospin; refused (the ringing dropped where the first one would raise the
/// onion's energy), it ends 0.39 rad off.
#[test]
fn forced_substeps_do_not_pump_the_onion() {
    let (m, start, inputs) = case(&values(PUMPED_RINGING)).unwrap();
    let t_end = 1e-6;
    let reference = rk4(&m, &start, &inputs, t_end, 1000.0);
    let coarse = rk4(&m, &start, &inputs, t_end, 500.0);
    let tol = m.params.tolerance;
    assert!(
        (reference[2] - coarse[2]).abs() <= 0.01 * tol,
        "{reference:?} {coarse:?}"
    );
    let mut st = start;
    let report = m.step(&mut st, &inputs, t_end).unwrap();
    println!("{st:?} against {reference:?}");
    assert!(report.accuracy_limited);
    assert!((st.onion_angle - reference[2]).abs() <= 0.5);
    assert!((st.rotor_angle - reference[0]).abs() <= tol);
}
