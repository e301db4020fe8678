//! The locked rotor's forecast drop ([`Motor::locked_budget_forecast_drops`]) against the
//! budget's drop it anticipates.

use super::locked_budget_forecast::LOCKED_FORECAST_OFF;
use super::onion_periods_tests::{case, values};
use super::*;

/// A locked rotor without switches (a 537 s period), gilbert_damping 3.9e-3, tolerance 1.1e-10,
/// a budget of 1,843: the onion, released 0.25 rad from its rotor, rings in its well at a loss
/// of 12% of its energy an orbit, 3,900 orbits a microsecond, too lossy for the averaged paths
/// and too wide for the linear ringing; its resolution spends the budget within the first
/// 1 us step, whose onion the budget's drop then puts into the minimum it rings about.
const LOSSY_RINGING: &str = "strain_direction=-7.869e4 stress=-2.137e4 load_torque=6.795e-7 \
     ring_outer_diameter=3.221e-1 ring_inner_diameter=4.627e-3 bar_length=2.405e-3 \
     bar_width=7.257e-4 thickness=5.891e-7 saturation_magnetization=2.326e4 \
     magnetostriction=-6.176e-4 wall_volume=3.264e-11 density=1.747e4 fluid_viscosity=1.094e5 \
     gilbert_damping=3.939e-3 tolerance=1.084e-10 step_angle=1.039e0 step_period=5.373e2 \
     stress_amplitude=-6.920e9 schedule_initial_direction=-3.003e-9 onion_model=1 \
     max_substeps=1.843e3 rotor_locked=1 initial_onion_offset=-2.529e-1 strain=7.058e-2 \
     youngs_modulus=1.181e8 strain_drive=1";

/// A locked rotor without switches whose onion, released at its well's rim, is resolved within
/// the budget: its ringing falls below the rim's margin and is averaged to the step's end
/// (a loss of 1.3% an orbit), unflagged.
pub(super) const RESOLVED_FROM_THE_RIM: &str = "strain_direction=-1.0963221905851172e-3 \
     stress=-7.985238336789477e9 load_torque=-6.730225346953287e-7 \
     ring_outer_diameter=1.4448020898266485e-3 ring_inner_diameter=1.2794678053490536e-4 \
     bar_length=8.677215111553606e-5 bar_width=9.106718477076665e-6 \
     thickness=4.537886385748834e-6 saturation_magnetization=3.9859192549820524e4 \
     magnetostriction=-5.93461997516773e-3 wall_volume=7.4624512815325e-11 \
     density=8.419903747509235e4 fluid_viscosity=3.654549799857549e7 \
     gilbert_damping=1.053601158486246e-3 tolerance=1.0328500410242096e-5 \
     step_angle=-9.057631254767527e0 step_period=5.628239232505195e1 \
     stress_amplitude=1.1572159331422608e9 schedule_initial_direction=-1.8393503674061744e1 \
     onion_model=1 max_substeps=3.444e3 schedule=0 rotor_locked=1 \
     initial_onion_offset=-8.615980940591263e-7 strain=3.779735998451483e-2 \
     youngs_modulus=4.352166751436662e6 strain_drive=1";

/// A locked rotor without a schedule, gilbert_damping 6.3e-4, tolerance 6.4e-10, a budget of
/// 14,536: the onion, released 1.07 rad from its minimum (0.16 of its well's barrier), rings
/// 630 orbits a microsecond at a loss of 0.9% of its energy an orbit. The averaged advance
/// refuses it on its phase's drift (thousands of tolerances over the step's orbits at this
/// tolerance) and the averaged decay time on the time left, throughout the step; its resolution
/// spends the budget's fine half within the first 1 us step.
pub(super) const SLOW_RINGING: &str =
    "strain_direction=6.89819503016559e5 stress=3.9995927439655665e4 \
     load_torque=1.689753871409024e-8 ring_outer_diameter=1.0625656096102617e-3 \
     ring_inner_diameter=2.643194611257996e-4 bar_length=1.7617788080714576e-5 \
     bar_width=3.1438829073220446e-9 thickness=2.6763768307710804e-9 \
     saturation_magnetization=9.798616394924227e3 magnetostriction=-3.399986457118611e-3 \
     wall_volume=3.066996654411993e-11 density=8.881999942997303e3 \
     fluid_viscosity=8.427338853515728e-4 gilbert_damping=6.303103895847836e-4 \
     tolerance=6.381913818766089e-10 step_angle=3.7985950160616593e0 \
     step_period=2.3914211234350652e-1 stress_amplitude=-4.722907603765584e0 \
     schedule_initial_direction=-3.742167062103022e5 onion_model=1 max_substeps=1.4536e4 \
     schedule=0 rotor_locked=1 initial_onion_offset=-4.914632218808278e-11 \
     strain=4.846643816149579e-2 youngs_modulus=1.9849244256873298e12 strain_drive=0";

/// Three 1 us steps of `text` with the forecast on or off: each step's report and end state.
fn three_steps(text: &str, forecast: bool) -> Vec<(StepReport, MotorState)> {
    let (m, mut state, inputs) = case(&values(text)).unwrap();
    LOCKED_FORECAST_OFF.with(|c| c.set(!forecast));
    let steps = (0..3)
        .map(|_| {
            let r = m.step(&mut state, &inputs, 1e-6).unwrap();
            (r, state)
        })
        .collect();
    LOCKED_FORECAST_OFF.with(|c| c.set(false));
    steps
}

/// The forecast drops the lossy ringing early in the first step, at under half the substeps
/// the budget's drop spends (186), flagged as that drop is, and every step ends where the
/// budget's drop leaves it: the onion in the same minimum, within rounding of the settle's
/// march, which is a minimum of eq. 3.4 (no gradient, positive curvature).
#[test]
fn forecast_drops_lossy_ringing_into_the_budget_drops_minimum() {
    let (m, _, inputs) = case(&values(LOSSY_RINGING)).unwrap();
    let (early, late) = (
        three_steps(LOSSY_RINGING, true),
        three_steps(LOSSY_RINGING, false),
    );
    assert!(late[0].0.accuracy_limited && late[0].0.substeps > 150);
    assert!(early[0].0.accuracy_limited);
    assert!(
        early[0].0.substeps <= 80,
        "{} substeps",
        early[0].0.substeps
    );
    for (i, ((re, se), (rl, sl))) in early.iter().zip(&late).enumerate() {
        assert_eq!(re.accuracy_limited, rl.accuracy_limited, "step {i}");
        assert_eq!(
            (se.rotor_angle, se.rotor_speed),
            (sl.rotor_angle, sl.rotor_speed)
        );
        assert!(
            (se.onion_angle - sl.onion_angle).abs() <= 1e-12 && se.onion_tilt == sl.onion_tilt,
            "step {i}: {se:?} against {sl:?}"
        );
        let d = m.drive_at(&inputs, se.time);
        let land = m.landscape(se.rotor_angle, d.direction, d.stress);
        let (gradient, curvature) = land.gradient_curvature(se.onion_angle);
        assert!(
            curvature > 0.0 && gradient.abs() <= 1e-9 * curvature,
            "step {i}"
        );
    }
}

/// A step that the resolved substeps and the averaged ringing end within the budget is left to
/// them: bit for bit the same with the forecast on or off, and unflagged.
#[test]
fn forecast_leaves_a_resolvable_step_alone() {
    let (on, off) = (
        three_steps(RESOLVED_FROM_THE_RIM, true),
        three_steps(RESOLVED_FROM_THE_RIM, false),
    );
    assert!(!off[0].0.accuracy_limited);
    for ((ro, so), (rf, sf)) in on.iter().zip(&off) {
        assert_eq!(
            (ro.substeps, ro.accuracy_limited),
            (rf.substeps, rf.accuracy_limited)
        );
        assert_eq!(
            [so.onion_angle, so.onion_tilt].map(f64::to_bits),
            [sf.onion_angle, sf.onion_tilt].map(f64::to_bits)
        );
    }
}

/// Ringing that loses too little an orbit for the loss alone to rule out the averaged paths,
/// but which both provably refuse until the budget's fine half is spent: dropped early in the
/// first step at under a tenth of the substeps the budget's drop spends, flagged as that drop
/// is, and every step ends where the budget's drop leaves it, in a minimum of eq. 3.4.
#[test]
fn forecast_drops_ringing_the_averaging_refuses_throughout() {
    let (m, _, inputs) = case(&values(SLOW_RINGING)).unwrap();
    let (early, late) = (
        three_steps(SLOW_RINGING, true),
        three_steps(SLOW_RINGING, false),
    );
    assert!(late[0].0.accuracy_limited && late[0].0.substeps > 1000);
    assert!(
        early[0].0.substeps <= 100,
        "{} substeps",
        early[0].0.substeps
    );
    for (i, ((re, se), (rl, sl))) in early.iter().zip(&late).enumerate() {
        assert_eq!(re.accuracy_limited, rl.accuracy_limited, "step {i}");
        assert_eq!(
            (se.rotor_angle, se.rotor_speed),
            (sl.rotor_angle, sl.rotor_speed)
        );
        assert!(
            (se.onion_angle - sl.onion_angle).abs() <= 1e-12 && se.onion_tilt == sl.onion_tilt,
            "step {i}: {se:?} against {sl:?}"
        );
        let d = m.drive_at(&inputs, se.time);
        let land = m.landscape(se.rotor_angle, d.direction, d.stress);
        let (gradient, curvature) = land.gradient_curvature(se.onion_angle);
        assert!(
            curvature > 0.0 && gradient.abs() <= 1e-9 * curvature,
            "step {i}"
        );
    }
}

/// A locked rotor without a schedule, gilbert_damping 8.9e-4, tolerance 2.1e-8, a budget of 988:
/// the onion, released beside a maximum, rings down into the well of its minimum at 1.068 rad
/// (a plain RK4 keeps it there), too slowly for the averaged paths and the budget.
const SMALL_BUDGET: &str = "strain_direction=1.140440041606553e6 stress=6.073526936874994e8 \
     load_torque=7.237854396073946e-7 ring_outer_diameter=1.5126138451699198e-2 \
     ring_inner_diameter=1.5301020530239888e-3 bar_length=1.858786760452875e-5 \
     bar_width=5.516579865728073e-9 thickness=2.701470326372294e-9 \
     saturation_magnetization=4.328268722595498e3 magnetostriction=9.244867960322006e-4 \
     wall_volume=9.790542485544858e-11 density=9.355553270409981e4 \
     fluid_viscosity=6.838301938949665e4 gilbert_damping=8.875604957613958e-4 \
     tolerance=2.0863084990919274e-8 step_angle=-2.432845804242345e0 \
     step_period=4.206054628329679e-8 stress_amplitude=-2.105274321540755e10 \
     schedule_initial_direction=1.9959782654982476e0 onion_model=1e0 max_substeps=9.88e2 \
     schedule=0e0 rotor_locked=1e0 initial_onion_offset=-1.3183692763920512e-7 \
     strain=2.093238324796673e-2 youngs_modulus=2.146425028383979e6 strain_drive=1e0";

/// The forecast drops the ringing into the minimum of the well that a plain RK4's onion rings
/// about at the step's end (its energy only falls below the well's rim); the budget's drop,
/// after the forced substeps, put it into the opposite well, 3.1 rad away.
#[test]
fn forecast_drops_into_the_well_a_plain_rk4_keeps() {
    let (m, start, inputs) = case(&values(SMALL_BUDGET)).unwrap();
    let steps = three_steps(SMALL_BUDGET, true);
    let (report, end) = steps[0];
    assert!(report.accuracy_limited);
    let y = super::resolved_tests::rk4(&m, &start, &inputs, 1e-6, 400.0);
    let d = m.drive_at(&inputs, 1e-6);
    let land = m.landscape(y[0], d.direction, d.stress);
    let minimum = land.settle(y[2]);
    assert!(
        (end.onion_angle - minimum).abs() <= 1e-9,
        "{} against {minimum} (RK4 onion {})",
        end.onion_angle,
        y[2]
    );
}
