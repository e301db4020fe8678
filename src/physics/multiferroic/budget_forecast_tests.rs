//! The budget's forecast drop ([`Motor::budget_forecast_drops`]) on a benchmark case whose
//! ringing onion outlasts every budget: a free rotor on a 78.5 ns schedule, damping 5.6e-4.

use super::budget_forecast::FORECAST_OFF;
use super::onion_periods_tests::{case, values};
use super::*;

/// The case: the load drives the rotor at `tau / c` (1.4e6 rad/s) through a ring whose torque
/// cannot move it; a switch every 78.5 ns turns a weak strain by 1.4 rad, and the onion then
/// rings near its rims, its tilt above 2 rad, decaying by `e` in about 0.3 us. The exponential
/// RK4 resolves it at about 56 ps a substep: 18,000 substeps a 1 us step against a budget of
/// 3,282 Gilbert substeps. Classical RK4s at 4,000, 8,000 and 16,000 substeps a nanosecond end
/// the first step with the onion 1,475, 361 and 769 rad from its start: its path over a step is
/// not resolvable at any affordable cost, and the step is flagged.
const OUTLASTING: &str = "strain_direction=-1.554122678401819e2 stress=-3.479031041687615e9 \
    load_torque=3.022337314507582e-7 ring_outer_diameter=5.9280961443378716e-5 \
    ring_inner_diameter=3.8194746212636794e-5 bar_length=1.983684983299965e-5 \
    bar_width=1.0339555921940574e-5 thickness=1.8907428537130158e-9 \
    saturation_magnetization=1.3725082270133316e4 magnetostriction=6.175377615668639e-3 \
    wall_volume=8.990225427710952e-11 density=5.6033971852967725e3 \
    fluid_viscosity=1.0923420605366032e2 gilbert_damping=5.586777528696512e-4 \
    tolerance=3.074548873010051e-5 step_angle=1.401337090158865e0 \
    step_period=7.854046876472495e-8 stress_amplitude=-6.51759975053556e4 \
    schedule_initial_direction=7.320039591034606e3 onion_model=1e0 max_substeps=1.3127e4 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=-7.309428939339728e-12";

/// Three 1 us steps with the forecast on or off: each step's report and end state.
fn three_steps(forecast: bool) -> Vec<(StepReport, MotorState)> {
    let (m, mut state, inputs) = case(&values(OUTLASTING)).unwrap();
    FORECAST_OFF.with(|c| c.set(!forecast));
    let steps = (0..3)
        .map(|_| {
            let r = m.step(&mut state, &inputs, 1e-6).unwrap();
            (r, state)
        })
        .collect();
    FORECAST_OFF.with(|c| c.set(false));
    steps
}

/// The forecast drops the ringing within the first segment of each step, at under half the
/// substeps that the budget's drop spends there (1,327 a step), flagged as that drop is, and
/// with the rotor on its exact path under load and drag (the ring's torque cannot move it).
#[test]
fn forecast_drops_the_outlasting_ringing_early() {
    let (m, start, inputs) = case(&values(OUTLASTING)).unwrap();
    let (c, tau) = (m.drag, m.inertia / m.drag);
    let tol = m.params.tolerance;
    for (i, (report, end)) in three_steps(true).iter().enumerate() {
        assert!(report.accuracy_limited, "step {i}");
        assert!(
            report.substeps <= 600,
            "step {i}: {} substeps",
            report.substeps
        );
        let t = end.time - start.time;
        let exact = inputs.load_torque / c * (t + tau * (-t / tau).exp_m1());
        assert!(
            (end.rotor_angle - exact).abs() <= 0.01 * tol,
            "step {i}: rotor {} against {exact}",
            end.rotor_angle
        );
    }
}

/// The early drop ends each step where the budget's drop later in the same segment does: the
/// onion in the same minimum and on the same branch (bit for bit), the rotor within rounding.
#[test]
fn forecast_drop_ends_where_the_budget_drop_does() {
    let (on, off) = (three_steps(true), three_steps(false));
    let tol = case(&values(OUTLASTING)).unwrap().0.params.tolerance;
    for (i, ((r_on, s_on), (r_off, s_off))) in on.iter().zip(&off).enumerate() {
        assert!(r_off.accuracy_limited && r_on.accuracy_limited, "step {i}");
        assert!(
            r_off.substeps > 2 * r_on.substeps,
            "step {i}: {} against {}",
            r_on.substeps,
            r_off.substeps
        );
        assert_eq!(s_on.onion_angle, s_off.onion_angle, "step {i}");
        assert_eq!(s_on.onion_tilt, s_off.onion_tilt, "step {i}");
        assert_eq!(s_on.rotor_speed, s_off.rotor_speed, "step {i}");
        assert!(
            (s_on.rotor_angle - s_off.rotor_angle).abs() <= 1e-6 * tol,
            "step {i}: {} against {}",
            s_on.rotor_angle,
            s_off.rotor_angle
        );
    }
}
