//! The orbit-averaged advance's checks taking the well kept from the last check
//! ([`Motor::kept_onion_well`]).

use super::locked_budget_forecast::LOCKED_FORECAST_OFF;
use super::onion_periods_tests::{case, values};
use super::orbit_kept_well::{OFF, REUSED, SEARCHED};
use super::*;

/// A benchmark draw: the rotor locked under a held stress (no schedule), gilbert_damping
/// 6.3e-4, tolerance 6.4e-10: the onion rings trapped in its well, where the averaged advance
/// refuses it for the averaged phase's drift at check after check.
const PHASE_REFUSED: &str = "strain_direction=6.89819503016559e5 stress=3.9995927439655665e4 \
     load_torque=1.689753871409024e-8 ring_outer_diameter=1.0625656096102617e-3 \
     ring_inner_diameter=2.643194611257996e-4 bar_length=1.7617788080714576e-5 \
     bar_width=3.1438829073220446e-9 thickness=2.6763768307710804e-9 \
     saturation_magnetization=9.798616394924227e3 magnetostriction=-3.399986457118611e-3 \
     wall_volume=3.066996654411993e-11 density=8.881999942997303e3 \
     fluid_viscosity=8.427338853515728e-4 gilbert_damping=6.303103895847836e-4 \
     tolerance=6.381913818766089e-10 step_angle=3.7985950160616593e0 \
     step_period=2.3914211234350652e-1 stress_amplitude=-4.722907603765584e0 \
     schedule_initial_direction=-3.742167062103022e5 onion_model=1e0 max_substeps=1.4536e4 \
     schedule=0e0 rotor_locked=1e0 initial_onion_offset=-4.914632218808278e-11 \
     strain=4.846643816149579e-2 youngs_modulus=1.9849244256873298e12 strain_drive=0e0";

/// The first 1 us step of [`PHASE_REFUSED`] with every well searched for (`searched`) or not:
/// the state, the report and the wells searched for and taken from the one kept. (The locked
/// forecast, which drops this ringing early in the step, is off: the checks run to the
/// budget's drop.)
fn first_step(searched: bool) -> (MotorState, StepReport, u32, u32) {
    let (m, mut st, inputs) = case(&values(PHASE_REFUSED)).unwrap();
    LOCKED_FORECAST_OFF.with(|c| c.set(true));
    OFF.with(|c| c.set(searched));
    SEARCHED.with(|c| c.set(0));
    REUSED.with(|c| c.set(0));
    let report = m.step(&mut st, &inputs, 1e-6);
    OFF.with(|c| c.set(false));
    LOCKED_FORECAST_OFF.with(|c| c.set(false));
    (
        st,
        report.unwrap(),
        SEARCHED.with(|c| c.get()),
        REUSED.with(|c| c.get()),
    )
}

/// The wells taken from the one kept leave the step bit for bit as the searches do, which find
/// each check's well afresh: 48 searches, now 5 (the settled minimum takes five values a unit of
/// roundoff apart).
#[test]
fn phase_refusals_take_the_kept_well() {
    let (a, report_a, searched_a, reused_a) = first_step(true);
    let (b, report_b, searched_b, reused_b) = first_step(false);
    let bits = |s: &MotorState| {
        [s.rotor_angle, s.rotor_speed, s.onion_angle, s.onion_tilt].map(f64::to_bits)
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(report_a, report_b);
    assert_eq!(
        (searched_a + reused_a, reused_a),
        (searched_b + reused_b, 0)
    );
    assert!(searched_a >= 40, "{searched_a} searches");
    assert!(
        searched_b <= 8,
        "{searched_b} searches, {reused_b} wells kept"
    );
}
