//! A free rotor's first step, whose Gilbert onion rings from its initial offset: against the
//! rotor's exact motion under load and drag and a converged RK4 of the onion it drives.

use super::budget_forecast::FIRED;
use super::decoupled::torque_bound;
use super::decoupled_tests::driven_rk4;
use super::onion_periods_tests::{case, values};

/// A weak ring under a load (the ring's torque moves the rotor by 1.3e-7 of the tolerance over
/// the step) whose onion, 7e-4 rad from its minimum, rings at a 232 ns period and decays by `e`
/// in 58 us; tolerance 2.8e-10 rad, `max_substeps` 2,458.
const SMALL_RINGING: &str = "strain_direction=1.2119858661556038e-1 stress=5.0943387184080813e5 load_torque=-6.341699249689225e-7 ring_outer_diameter=9.402048205857613e-2 ring_inner_diameter=1.308406586620207e-2 bar_length=1.0540969369762336e-3 bar_width=3.1855539109173497e-6 thickness=4.5317722146221875e-8 saturation_magnetization=3.9717823570573825e2 magnetostriction=-3.0165630556039207e-4 wall_volume=9.069484547407164e-11 density=1.3545878627339896e4 fluid_viscosity=8.139161135153311e-3 gilbert_damping=3.5687671591814974e-4 tolerance=2.788466197646577e-10 step_angle=4.149305673040097e0 step_period=2.438010048679238e4 stress_amplitude=-2.084262063358658e1 schedule_initial_direction=-6.961574600457749e-4 onion_model=1e0 max_substeps=2.458e3 schedule=1e0 rotor_locked=0e0 initial_onion_offset=5.91413940482487e-9 strain=7.174037441545364e-2 youngs_modulus=1.0433507982399842e7 strain_drive=0e0";

/// The same regime with the onion 1.43 rad from its minimum (a 481 ns period, decaying by `e`
/// in 10 us); tolerance 1.7e-10 rad, `max_substeps` 2,267.
const WIDE_RINGING: &str = "strain_direction=-3.274928548447067e-1 stress=-2.5849424274683585e6 load_torque=-2.9068603925173025e-7 ring_outer_diameter=8.82473431417558e-3 ring_inner_diameter=8.786025548293314e-5 bar_length=3.3508278120547707e-6 bar_width=2.3988172737406676e-7 thickness=1.6661322900472797e-7 saturation_magnetization=5.795350410941152e2 magnetostriction=6.247415305323401e-4 wall_volume=2.973261745400433e-11 density=1.90193374718089e3 fluid_viscosity=1.0545977264942358e5 gilbert_damping=1.5159961253899488e-3 tolerance=1.657030811763765e-10 step_angle=-6.6076083928538605e0 step_period=3.9432171324621444e5 stress_amplitude=2.337665191434012e0 schedule_initial_direction=2.6782981353439095e-8 onion_model=1e0 max_substeps=2.267e3 schedule=1e0 rotor_locked=0e0 initial_onion_offset=-6.740606188980908e1 strain=6.477498332685822e-4 youngs_modulus=5.054063438722256e12 strain_drive=1e0";

/// A load that spins a weak-ringed rotor (drag time `I / c` 11 us) towards 8.6e7 rad/s, past
/// its burst speed (1.6e7 rad/s for its 1.2 mm bar) 2.4 us after it starts from rest.
const SPUN_UP: &str = "strain_direction=7.07320388957077e2 stress=-4.7988341312383485e0 load_torque=7.159820392361648e-7 ring_outer_diameter=2.731073927720788e-1 ring_inner_diameter=6.73947647310986e-2 bar_length=1.216281794563719e-3 bar_width=5.195481338209981e-7 thickness=5.238270146880956e-8 saturation_magnetization=6.448137080659887e1 magnetostriction=4.059109150514299e-3 wall_volume=5.709960942475446e-11 density=2.283291527207852e4 fluid_viscosity=3.590861705493732e-5 gilbert_damping=4.823621134924321e-3 tolerance=1.1359280475017689e-10 step_angle=-5.034572787666443e0 step_period=1.2681067186131895e-5 stress_amplitude=-1.0600599227628892e6 schedule_initial_direction=-1.9653467329983783e5 onion_model=1e0 max_substeps=4.735e3 schedule=0e0 rotor_locked=0e0 initial_onion_offset=3.435356101493943e-6 strain=-9.14933319504455e-2 youngs_modulus=1.334665508920819e11 strain_drive=0e0";

/// The budget's forecast holds during these first steps (their early spending, kept up, would
/// spend the budget's fine half within the segment), yet the ringing's substeps grow as it
/// settles and each step resolves it within the budget: a forecast that holds must not drop
/// the onion by itself (where it does not head for its minimum within the step). Each step
/// ends unflagged within the tolerance of the rotor's exact motion under load and drag (the
/// ring cannot move it) and a converged RK4 of the onion it drives. A drop on the forecast
/// alone flagged both and left their onions 9.7e5 and 3.7e9 tolerances off that RK4.
#[test]
fn forecast_alone_does_not_drop_ringing_resolved_within_budget() {
    let h = 1e-6;
    for (name, text) in [("small", SMALL_RINGING), ("wide", WIDE_RINGING)] {
        let (m, mut state, inputs) = case(&values(text)).unwrap();
        let tol = m.params.tolerance;
        // The truth leaves out the ring's torque and the schedule's switches.
        let ring = 2.0 * torque_bound(&m.ring_bar) * h / m.drag;
        assert!(
            ring <= 1e-3 * tol,
            "{name}: the ring turns the rotor {ring:e}"
        );
        let next = inputs
            .schedule
            .get()
            .map_or(f64::INFINITY, |s| s.next_switch_after(0.0));
        assert!(next > h, "{name}: a switch at {next:e}");
        let d = m.drive_at(&inputs, 0.0);
        let y0 = [
            state.rotor_angle,
            state.rotor_speed,
            state.onion_angle,
            state.onion_tilt,
        ];
        FIRED.with(|c| c.set(0));
        let report = m.step(&mut state, &inputs, h).unwrap();
        let fired = FIRED.with(|c| c.get());
        let (coarse, truth) = (driven_rk4(&m, &d, y0, h, 1), driven_rk4(&m, &d, y0, h, 2));
        for i in [0, 2, 3] {
            assert!(
                (coarse[i] - truth[i]).abs() <= 0.01 * tol,
                "{name}: RK4 {i} unconverged"
            );
        }
        let end = [
            state.rotor_angle,
            state.rotor_speed,
            state.onion_angle,
            state.onion_tilt,
        ];
        let off = [0, 2, 3].map(|i| (end[i] - truth[i]).abs() / tol);
        println!(
            "{name}: {} substeps, forecast held {fired} times, off (tolerances) {off:?}",
            report.substeps
        );
        assert!(fired > 0, "{name}: the forecast never held");
        assert!(!report.accuracy_limited, "{name}: flagged");
        assert!(
            off.iter().all(|e| *e <= 1.0),
            "{name}: {end:?} against {truth:?}"
        );
    }
}

/// The load's refusal at the burst speed comes at the step within which the rotor's exact
/// speed under load and drag, `tau / c (1 - e^(-t c / I))`, passes it (the third 1 us step; the
/// ring's torque changes that speed by 1e-8 of itself), not before; the first two steps end at
/// that speed.
#[test]
fn load_refused_at_the_step_that_passes_the_burst_speed() {
    let (m, mut state, inputs) = case(&values(SPUN_UP)).unwrap();
    let (c, tau) = (m.drag, m.inertia / m.drag);
    let exact = |t: f64| -inputs.load_torque / c * (-t / tau).exp_m1();
    let burst = m.burst_speed();
    assert!(torque_bound(&m.ring_bar) <= 1e-8 * inputs.load_torque);
    assert!(exact(2e-6) < burst && burst < exact(3e-6));
    for k in 1..=2 {
        m.step(&mut state, &inputs, 1e-6).unwrap();
        let w = exact(k as f64 * 1e-6);
        assert!(
            (state.rotor_speed - w).abs() <= 1e-9 * w,
            "step {k}: {} against {w}",
            state.rotor_speed
        );
    }
    let refusal = m.step(&mut state, &inputs, 1e-6).unwrap_err();
    assert!(refusal.contains("burst speed"), "{refusal}");
}
