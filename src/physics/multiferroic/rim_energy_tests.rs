//! A locked rotor's Gilbert onion near and above the rims of eq. 3.4 against a converged RK4
//! of the macrospin: its energy bounds which wells it reaches ([`Motor::energy_checked_error`]).

use super::locked_accuracy_tests::converged_rk4;
use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4_span;
use super::rim_energy::RimLedger;
use super::*;

/// Benchmark draw 139866 at full precision: a locked rotor, no schedule, the strain nearly along
/// the bar and eq. 3.4 far above eq. 3.3 (wells of `|E|` = 3.4e-10 J, tilt stiffness 2.8e-10 J).
const RELEASED_BELOW_RIM: &str = "strain_direction=-6.2878428187391595e0 stress=2.3663549863067e3 \
    load_torque=6.205378551457873e-7 ring_outer_diameter=5.8731173113397e-7 \
    ring_inner_diameter=5.380247200809597e-8 bar_length=1.676255112651537e-8 \
    bar_width=6.086461704960331e-9 thickness=2.2097593295069306e-9 \
    saturation_magnetization=5.425468988995863e3 magnetostriction=-4.376990672870021e-4 \
    wall_volume=7.697771204144733e-12 density=4.360859102082564e3 \
    fluid_viscosity=5.091001964554426e-1 gilbert_damping=1.1360753155494558e-3 \
    tolerance=1.865882601086424e-1 step_angle=1.6330077254621767e0 \
    step_period=3.719735885250392e5 stress_amplitude=2.81320742521948e-3 \
    schedule_initial_direction=-1.4687316242890378e-1 onion_model=1 max_substeps=1.7264e4 \
    schedule=0 rotor_locked=1 initial_onion_offset=-2.229889081125255e-8 \
    strain=6.574031156574442e-2 youngs_modulus=1.0138261932171631e6 strain_drive=1";

/// A locked rotor's onion released from rest 0.0047 rad inside a rim of eq. 3.4 (2e-5 of its
/// well's depth below the rim's height), damping 1.1e-3, tolerance 0.19 rad, no switch: the
/// exact solution swings between the well's rims for the whole 1 us step. Within two tolerances of a
/// converged RK4 in angle and tilt, unflagged, the RK4 in the starting well. A substep whose
/// angle error estimate passed carried the onion over the rim and later ones pumped it to 30
/// times the depth: it ended 80 turns off (2,676 tolerances), unflagged.
#[test]
fn locked_onion_released_below_its_rim_stays_in_its_well_against_rk4() {
    let (m, mut st, inputs) = case(&values(RELEASED_BELOW_RIM)).unwrap();
    let start = st;
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(start.rotor_angle, d.direction, d.stress);
    let well = m.onion_well(&land, start.onion_angle).unwrap();
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let truth = converged_rk4(&m, &start, &inputs, st.time, 1000.0);
    let tol = m.params.tolerance;
    let errors = [
        (st.onion_angle - truth[2]).abs() / tol,
        (st.onion_tilt - truth[3]).abs() / tol,
    ];
    println!("{report:?}, errors / tolerance against RK4 {errors:?}");
    assert!(
        well.below < truth[2] && truth[2] < well.above,
        "{well:?} {truth:?}"
    );
    assert!(
        !report.accuracy_limited && errors.iter().all(|e| *e <= 2.0),
        "{st:?} {truth:?}"
    );
}

/// The same onion given a tilt of 1 rad: 0.42 of the well's depth above every rim, it spins
/// about 38 turns over the 1 us step. Within 50 tolerances of a converged RK4 (the energy's
/// error, which the substeps' control on the angles does not bound, shifts the spin's phase by
/// about 35). Substeps that lost energy 25 and 127 times faster than the damping can take
/// captured it in a well in its fourth substep: 1,262 tolerances off, unflagged.
#[test]
fn locked_onion_spinning_above_its_rims_is_not_captured_early_against_rk4() {
    let (m, mut st, inputs) = case(&values(RELEASED_BELOW_RIM)).unwrap();
    st.onion_tilt = 1.0;
    let start = st;
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let truth = converged_rk4(&m, &start, &inputs, st.time, 1000.0);
    let tol = m.params.tolerance;
    let error = (st.onion_angle - truth[2]).abs() / tol;
    println!("{report:?}, {error} tolerances off RK4 {truth:?}");
    assert!(truth[2] < -200.0, "{truth:?}");
    assert!(report.accuracy_limited || error <= 50.0, "{st:?} {truth:?}");
}

/// The check itself, from the onion of [`RELEASED_BELOW_RIM`] with and without a tilt, over
/// 1 ns: a fine RK4 substep passes unchanged; a substep ending past the rim that its energy
/// cannot reach, and one whose energy falls from above every rim to the well's bottom (far
/// beyond what the damping takes in 1 ns), are rejected.
#[test]
fn energy_check_passes_exact_substeps_and_rejects_impossible_ones() {
    let (m, st, inputs) = case(&values(RELEASED_BELOW_RIM)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(st.rotor_angle, d.direction, d.stress);
    let well = m.onion_well(&land, st.onion_angle).unwrap();
    let dt = 1e-9;
    for tilt in [0.0, 1.0] {
        let y = [st.rotor_angle, 0.0, st.onion_angle, tilt];
        let exact = rk4_span(&m, &d, y, dt, 10_000);
        // The rims are looked for from the second substep in a landscape on.
        let mut ledger = RimLedger::NONE;
        let mut check = |u: &Vector| m.energy_checked_error(&mut ledger, (&y, u), dt, &d, 0.5);
        for _ in 0..2 {
            assert_eq!(check(&exact), 0.5, "tilt {tilt}: {exact:?}");
        }
        let impossible = if tilt == 0.0 {
            // Past the rim above the well, where the onion is headed.
            [y[0], 0.0, well.above + 0.3, exact[3]]
        } else {
            [y[0], 0.0, well.minimum, 0.0]
        };
        assert!(check(&impossible) > 1.0, "tilt {tilt}: {impossible:?}");
    }
}
