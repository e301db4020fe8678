//! The budget's forecast drop ([`Motor::budget_forecast_drops`]) on a benchmark case whose
//! ringing onion outlasts every budget: a free rotor on a 78.5 ns schedule, damping 5.6e-4.

use super::budget_forecast::FORECAST_OFF;
use super::onion_periods_tests::{case, values};
use super::*;

/// The case: the load drives the rotor at `tau / c` (1.4e6 rad/s) through a ring whose torque
/// cannot move it; a switch every 78.5 ns turns a weak strain by 1.4 rad, and the onion then
/// rings near its rims, its tilt above 2 rad (its linearization at the minimum decays by `e` in
/// about 0.2 us). The exponential RK4 resolves it at about 56 ps a substep: 18,000 substeps a
/// 1 us step against a budget of 3,282 Gilbert substeps. Classical RK4s at 4,000, 8,000 and
/// 16,000 substeps a nanosecond end the first step with the onion 1,475, 361 and 769 rad from
/// its start: its path over a step is not resolvable at any affordable cost, and the step is
/// flagged.
const OUTLASTING: &str = super::stiff_rotor_tests::BUDGET_BOUND_FREE_ROTOR;

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
