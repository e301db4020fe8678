//! A rotor whose inertial time is far beyond the step speeds up under its load: the overdamped
//! slip's whole turns (speed `F / c` at once) do not apply to it.

use super::held_torque_tests::{converged_quasi_static_rk4, errors};
use super::onion_periods_tests::{case, values};

/// A benchmark case (full precision): a 0.14 mm bar in a 0.4 mm ring under a 5.7e-7 N m load
/// (beyond the ring's torque), inertial time `I/c` 0.14 ms and relaxation time `c/k` 85 ns, at
/// constant strain.
const C1098002: &str = "\
    strain_direction=-1.2526918513953904e4 stress=-1.9720526639198181e0 \
    load_torque=-5.686562602122564e-7 ring_outer_diameter=4.1419996056075493e-4 \
    ring_inner_diameter=2.084150796217709e-4 bar_length=1.3871774521805538e-4 \
    bar_width=5.22345694556909e-6 thickness=3.5862837381524977e-6 \
    saturation_magnetization=6.242222514076117e6 magnetostriction=-8.076181994995721e-3 \
    wall_volume=7.264057362325307e-11 density=5.398503465876775e3 \
    fluid_viscosity=1.581702731042879e-4 gilbert_damping=7.62067711247783e-3 \
    tolerance=5.6903298941956944e-8 step_angle=-3.173253691291502e0 \
    step_period=4.1740253737815533e-7 stress_amplitude=5.624217431106863e-2 \
    schedule_initial_direction=5.798273477978823e2 onion_model=0e0 max_substeps=1.58e3 \
    schedule=0e0 rotor_locked=0e0 initial_onion_offset=-1.0210742796031089e2 \
    strain=8.765281547426887e-2 youngs_modulus=2.917182022156538e7 strain_drive=0e0";

/// [`C1098002`]'s first 1 us step from rest against the converged RK4: within the tolerance and
/// not accuracy-limited. The segment is longer than ten relaxation times, and the overdamped
/// slip took the rotor at its terminal speed `F / c` from the start: -3,494 rad and -3.5e9 rad/s
/// against the RK4's -12.59 rad and -2.5e7 rad/s (6e10 tolerances), flagged, and the next step
/// was refused at the bar's burst speed.
#[test]
fn inertial_rotor_is_not_slipped_overdamped() {
    let (m, mut st, inputs) = case(&values(C1098002)).unwrap();
    assert!(m.inertial_time() > 100.0 * 1e-6);
    let start = st;
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let truth = converged_quasi_static_rk4(&m, &start, &inputs, st.time);
    let e = errors(&m, &st, &truth);
    println!(
        "{} substeps: {st:?} against {truth:?}: {e:?}",
        report.substeps
    );
    assert!(!report.accuracy_limited);
    assert!(e[0] <= 1.0 && e[2] <= 1.0, "{e:?}");
}
