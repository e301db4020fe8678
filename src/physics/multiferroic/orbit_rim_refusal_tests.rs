//! The orbit-averaged advance's refusals of a locked rotor's onion too near its rim, decided
//! again from the well kept ([`Motor::rim_refusal_holds`]).

use super::locked_accuracy_tests::step_against_rk4;
use super::onion_periods_tests::{case, values};
use super::orbit_rim_refusal::{FULL, OFF, SKIPPED};
use super::*;

/// A benchmark draw: the rotor locked, no switch within the step (a 6.7e4 s period),
/// gilbert_damping 7.5e-4, tolerance 7.9e-5: the onion rings near its well's rim, where the
/// averaged advance refuses it at every check, until it is put on its branch.
const NEAR_RIM: &str = "strain_direction=2.3194432418338086e-3 stress=8.495611757183485e1 \
     load_torque=-2.034365242732889e-7 ring_outer_diameter=1.4094676972265283e-1 \
     ring_inner_diameter=1.0772350881802226e-1 bar_length=5.8607348238318695e-2 \
     bar_width=3.707479659960714e-3 thickness=2.1473891274865035e-3 \
     saturation_magnetization=1.3674998272837853e5 magnetostriction=1.3649389524808923e-3 \
     wall_volume=3.094033896902824e-11 density=3.4507373053097926e3 \
     fluid_viscosity=2.156464599868278e2 gilbert_damping=7.511367605645657e-4 \
     tolerance=7.856630192656752e-5 step_angle=-4.755648860973678e0 \
     step_period=6.715550922418927e4 stress_amplitude=-2.321094662390607e9 \
     schedule_initial_direction=-2.677481330657743e-9 onion_model=1e0 max_substeps=4.036e3 \
     schedule=1e0 rotor_locked=1e0 initial_onion_offset=2.6728755154663565e-5 \
     strain=-5.083023805541514e-2 youngs_modulus=1.2305609904440123e11 strain_drive=1e0";

/// The first 1 us step of [`NEAR_RIM`] with every check of the averaged advance made in full
/// (`full`) or not: the state, the report and the checks made in full and skipped.
fn first_step(full: bool) -> (MotorState, StepReport, u32, u32) {
    let (m, mut st, inputs) = case(&values(NEAR_RIM)).unwrap();
    OFF.with(|c| c.set(full));
    FULL.with(|c| c.set(0));
    SKIPPED.with(|c| c.set(0));
    let report = m.step(&mut st, &inputs, 1e-6);
    OFF.with(|c| c.set(false));
    (
        st,
        report.unwrap(),
        FULL.with(|c| c.get()),
        SKIPPED.with(|c| c.get()),
    )
}

/// The refusals decided from the kept well leave the step bit for bit as the full checks do,
/// which search the well's rims afresh each time: 13 of them, now 1 (the first).
#[test]
fn near_rim_refusals_decided_from_the_kept_well() {
    let (a, report_a, full_a, skipped_a) = first_step(true);
    let (b, report_b, full_b, skipped_b) = first_step(false);
    let bits = |s: &MotorState| {
        [s.rotor_angle, s.rotor_speed, s.onion_angle, s.onion_tilt].map(f64::to_bits)
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(report_a, report_b);
    assert_eq!((full_a + skipped_a, skipped_a), (full_b + skipped_b, 0));
    assert!(full_a >= 10, "{full_a} full checks");
    assert!(full_b <= 2, "{full_b} full checks, {skipped_b} skipped");
}

/// The same step against a plain RK4 of the macrospin: within the tolerance (1e-11 and 3e-10
/// tolerances in angle and tilt).
#[test]
fn near_rim_onion_against_rk4() {
    step_against_rk4(NEAR_RIM, 0, 2e3, 1.0);
}
