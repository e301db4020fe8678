//! The Gilbert onion's repeated periods on a fast schedule ([`Motor::skip_onion_periods`])
//! against the resolved substeps, and the regime's classification of a benchmark log's cases.

use super::onion_periods::SKIPS;
use super::*;
use std::collections::HashMap;

/// `name=value` pairs as the worst-case benchmark prints a case (the FMU's variable names).
pub(super) fn values(text: &str) -> HashMap<String, f64> {
    text.split_whitespace()
        .filter_map(|p| {
            let (k, v) = p.split_once('=')?;
            Some((k.to_string(), v.parse().ok()?))
        })
        .collect()
}

/// The motor, its start (rotor at rest at 0, the onion `initial_onion_offset` from it) and its
/// inputs for a case's values, the FMU's start values elsewhere; `Err` if the motor refuses
/// them (the printed digits can make two diameters equal).
pub(super) fn case(kv: &HashMap<String, f64>) -> Result<(Motor, MotorState, MotorInputs), String> {
    let mut p = MotorParams::table_3_1();
    let g = |k: &str, d: f64| kv.get(k).copied().unwrap_or(d);
    p.ring_outer_diameter = g("ring_outer_diameter", p.ring_outer_diameter);
    p.ring_inner_diameter = g("ring_inner_diameter", p.ring_inner_diameter);
    p.bar_length = g("bar_length", p.bar_length);
    p.bar_width = g("bar_width", p.bar_width);
    p.thickness = g("thickness", p.thickness);
    p.saturation_magnetization = g("saturation_magnetization", p.saturation_magnetization);
    p.magnetostriction = g("magnetostriction", p.magnetostriction);
    p.wall_volume = g("wall_volume", p.wall_volume);
    p.density = g("density", p.density);
    p.fluid_viscosity = g("fluid_viscosity", p.fluid_viscosity);
    p.gilbert_damping = g("gilbert_damping", p.gilbert_damping);
    p.tolerance = g("tolerance", p.tolerance);
    p.max_substeps = g("max_substeps", f64::from(p.max_substeps)) as u32;
    p.onion_model = if g("onion_model", 0.0) > 0.5 {
        OnionModel::Gilbert
    } else {
        OnionModel::QuasiStatic
    };
    let m = Motor::new(p)?;
    let s = SteppingSchedule::new(
        g("schedule_initial_direction", -PI / 6.0),
        g("step_angle", PI / 3.0),
        g("step_period", 1e-4),
        g("stress_amplitude", 2e8),
    )?;
    let stress = if g("strain_drive", 0.0) > 0.5 {
        drive::uniaxial_stress(g("strain", 0.0), g("youngs_modulus", 1e11))?
    } else {
        g("stress", 0.0)
    };
    let inputs = MotorInputs {
        strain_direction: g("strain_direction", 0.0),
        stress,
        load_torque: g("load_torque", 0.0),
        rotor_locked: g("rotor_locked", 0.0) > 0.5,
        schedule: ScheduleSwitch::new(g("schedule", 0.0) > 0.5, s),
    };
    let state = MotorState {
        onion_angle: g("initial_onion_offset", 0.0),
        ..MotorState::aligned(0.0)
    };
    Ok((m, state, inputs))
}

/// Eq. 3.4's curvature `k = 2 |E|` at a minimum under the stress and the onion block's slowest
/// decay rate there, from the eigenvalues in complex form:
/// `lambda^2 + g a (k + t) lambda + g^2 (1 + a^2) k t = 0`.
fn curvature_and_slowest_decay(m: &Motor, stress: f64) -> (f64, f64) {
    let k = 2.0 * (m.magnetoelastic_per_stress * stress).abs();
    let (g, a, t) = (m.llg_rate, m.params.gilbert_damping, m.tilt_stiffness);
    let (b, c) = (g * a * (k + t), g * g * (1.0 + a * a) * k * t);
    let disc = b * b - 4.0 * c;
    let slowest = if disc >= 0.0 {
        0.5 * (b - disc.sqrt())
    } else {
        0.5 * b
    };
    (k, slowest)
}

fn skips() -> u32 {
    SKIPS.with(|c| c.get())
}

/// The same motor with `tolerance / 100` and a budget of 1e8 substeps, stepped from `state` to
/// `t_end` one period of the schedule at a time (a step that spans no whole period cannot
/// repeat one: every switch is resolved).
fn resolved(m: &Motor, state: &MotorState, inputs: &MotorInputs, t_end: f64) -> MotorState {
    let mut p = m.params.clone();
    p.tolerance *= 0.01;
    p.max_substeps = 100_000_000;
    let fine = Motor::new(p).unwrap();
    let s = inputs.schedule.get().unwrap();
    let mut st = *state;
    let before = skips();
    while st.time < t_end {
        let next = s.next_switch_after(st.time).min(t_end);
        let h = next - st.time;
        fine.step(&mut st, inputs, h).unwrap();
    }
    assert_eq!(skips(), before, "the reference repeated periods");
    st
}

/// Two 1 us steps (the FMU's) of a benchmark case against the resolved reference: rotor angle,
/// speed, onion angle and tilt within ten tolerances (the speed's on the error norm's scale),
/// and the repeated periods taken in each step.
fn agrees_with_resolved(text: &str) {
    let (m, start, inputs) = case(&values(text)).unwrap();
    assert!(m.ring_decoupled(inputs.schedule.get().unwrap(), inputs.rotor_locked, 2e-6));
    let tol = m.params.tolerance;
    let mut st = start;
    for k in 1..=2 {
        let before = skips();
        let rep = m.step(&mut st, &inputs, 1e-6).unwrap();
        assert!(!rep.accuracy_limited, "step {k} is accuracy-limited");
        assert!(skips() > before, "step {k}: no periods repeated");
        let r = resolved(&m, &start, &inputs, st.time);
        let rounding = |x: f64| 1e-12 * x.abs();
        let speed_scale = m.speed_scale.max(1e-12 * r.rotor_speed.abs() / tol);
        let errors = [
            (st.rotor_angle - r.rotor_angle).abs() / (tol + rounding(r.rotor_angle)),
            (st.rotor_speed - r.rotor_speed).abs() / (tol * speed_scale),
            (st.onion_angle - r.onion_angle).abs() / (tol + rounding(r.onion_angle)),
            (st.onion_tilt - r.onion_tilt).abs() / tol,
        ];
        println!("step {k}: errors / tolerance {errors:?}");
        if !inputs.rotor_locked {
            // From rest under load and drag alone, `I phi'' = L - c phi'` (the ring's torque moves
            // it by a tenth of the tolerance at most): `phi = L/c (t - tau (1 - e^(-t/tau)))`.
            let (c, tau) = (m.drag, m.inertia / m.drag);
            let t = st.time;
            let exact = inputs.load_torque / c * (t + tau * (-t / tau).exp_m1());
            let error = (st.rotor_angle - exact).abs();
            println!(
                "step {k}: rotor {} exact {exact} reference {}",
                st.rotor_angle, r.rotor_angle
            );
            assert!(
                error <= 0.1 * k as f64 * tol + rounding(exact),
                "step {k}: rotor {} against {exact}",
                st.rotor_angle
            );
        }
        assert!(
            errors.iter().all(|e| *e <= 10.0),
            "step {k}: {st:?} against {r:?}: errors / tolerance {errors:?}"
        );
    }
}

/// Onion relaxed within each switch (slowest decay ~370 per period), free rotor under a load.
#[test]
fn relaxed_onion_free_rotor_repeats_its_periods() {
    agrees_with_resolved(
        "load_torque=1e-6 ring_outer_diameter=3.253e-1 ring_inner_diameter=1.279e-1 \
         bar_length=4e-5 bar_width=1e-5 thickness=1e-6 saturation_magnetization=7.248e4 \
         magnetostriction=6.666e-3 wall_volume=3.307e-11 density=6.435e3 fluid_viscosity=1e3 \
         gilbert_damping=3.089e-3 tolerance=6.272e-4 step_angle=2.677e0 step_period=2.160e-9 \
         stress_amplitude=-2.300e9 schedule_initial_direction=8.853e2 onion_model=1 \
         max_substeps=1.795e4 initial_onion_offset=-3.639e-3 schedule=1",
    );
}

/// Onion relaxed within each switch (slowest decay ~1,300 per period), locked rotor.
#[test]
fn relaxed_onion_locked_rotor_repeats_its_periods() {
    agrees_with_resolved(
        "load_torque=7.676e-7 ring_outer_diameter=7.975e-2 ring_inner_diameter=2.245e-3 \
         bar_length=9.416e-4 bar_width=1.171e-4 thickness=9.632e-8 saturation_magnetization=1.205e5 \
         magnetostriction=-7.697e-3 wall_volume=7.316e-12 density=4.562e4 fluid_viscosity=2.131e3 \
         gilbert_damping=1.582e-1 tolerance=7.096e-4 step_angle=7.862e0 step_period=7.549e-9 \
         stress_amplitude=-1.416e11 schedule_initial_direction=-2.236e0 onion_model=1 \
         max_substeps=2e4 schedule=1 rotor_locked=1 initial_onion_offset=1.571e-11",
    );
}

/// An onion precessing too slowly to follow the switches (decay ~0.3 per period, rotor
/// decoupled) never repeats a period: every switch is resolved.
#[test]
fn a_precessing_onion_is_resolved() {
    let (m, mut st, inputs) = case(&values(
        "load_torque=-2.671e-7 ring_outer_diameter=2.661e-6 ring_inner_diameter=6.941e-7 \
         bar_length=3.855e-7 bar_width=3.392e-8 thickness=1.165e-8 saturation_magnetization=1.712e4 \
         magnetostriction=-7.157e-3 wall_volume=6.328e-11 density=3.751e4 fluid_viscosity=7.833e4 \
         gilbert_damping=1.257e-2 tolerance=7.966e-6 step_angle=-3.418e0 step_period=1.226e-8 \
         stress_amplitude=2.279e0 schedule_initial_direction=-7.294e-5 onion_model=1 \
         max_substeps=2e4 schedule=1 initial_onion_offset=-5.832e-5",
    ))
    .unwrap();
    assert!(m.ring_decoupled(inputs.schedule.get().unwrap(), false, 1e-6));
    let before = skips();
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    assert!(!report.accuracy_limited);
    assert_eq!(skips(), before);
}

/// Onion ringing through several switches (slowest decay ~0.86 per period, ~19 periods to
/// relax to the tolerance), locked rotor, a tolerance of 7.6e-8 rad.
#[test]
fn ringing_onion_locked_rotor_repeats_its_periods() {
    agrees_with_resolved(
        "load_torque=3.628e-7 ring_outer_diameter=6.585e-1 ring_inner_diameter=6.196e-2 \
         bar_length=1.989e-4 bar_width=1.525e-8 thickness=9.572e-9 saturation_magnetization=2.716e5 \
         magnetostriction=-6.231e-3 wall_volume=8.089e-11 density=2.816e3 fluid_viscosity=3.923e-1 \
         gilbert_damping=1.380e-2 tolerance=7.626e-8 step_angle=-6.134e0 step_period=1.213e-8 \
         stress_amplitude=-7.405e1 schedule_initial_direction=-3.582e5 onion_model=1 \
         max_substeps=2e4 schedule=1 rotor_locked=1 initial_onion_offset=4.130e-8",
    );
}

/// Table 3.1's Gilbert motor on a 1 ns schedule of 60 degree steps: its ring holds the bar
/// (the rotor follows the onion), so no period is repeated in the strain's frame alone.
#[test]
fn a_coupled_rotor_is_resolved() {
    let m = super::tests::motor_with(|p| p.onion_model = OnionModel::Gilbert);
    let inputs = super::tests::schedule(1e-9);
    assert!(!m.ring_decoupled(inputs.schedule.get().unwrap(), false, 1e-8));
    assert!(!m.ring_decoupled(inputs.schedule.get().unwrap(), true, 1e-8));
    let mut st = MotorState::aligned(0.0);
    let before = skips();
    m.step(&mut st, &inputs, 1e-8).unwrap();
    assert_eq!(skips(), before);
}

/// The regime's bound, `tau_max / (2 |E|) (1 + 1 / (lambda T)) <= tolerance / 100`, with the
/// slowest decay rate `lambda` taken here from the onion block's eigenvalues in complex form:
/// the decision flips where the bound crosses, as the stress is lowered.
#[test]
fn the_regime_ends_where_the_ring_can_shift_the_onion() {
    let (m, _, inputs) = case(&values(
        "ring_outer_diameter=5.241e-4 ring_inner_diameter=8.939e-8 bar_length=7.899e-8 \
         bar_width=2.906e-9 thickness=2.212e-9 saturation_magnetization=1.274e3 \
         magnetostriction=1.762e-3 wall_volume=6.022e-11 gilbert_damping=4.591e-2 \
         tolerance=2.097e-3 step_angle=8.082e-1 step_period=6.492e-9 onion_model=1 schedule=1",
    ))
    .unwrap();
    let s = *inputs.schedule.get().unwrap();
    let bound = |stress: f64| {
        let (k, slowest) = curvature_and_slowest_decay(&m, stress);
        m.torque_bound() / k * (1.0 + 1.0 / (slowest * s.step_period)) / m.params.tolerance
    };
    let mut flips = 0;
    let mut stress = 1e12;
    while stress > 1e-6 {
        let schedule = SteppingSchedule {
            stress_amplitude: stress,
            ..s
        };
        let b = bound(stress);
        if (b - 0.01).abs() > 1e-6 {
            assert_eq!(
                m.ring_decoupled(&schedule, true, 1e-6),
                b <= 0.01,
                "stress {stress}: {b}"
            );
        }
        flips += usize::from(b > 0.01 && bound(stress * 1.5) <= 0.01);
        stress /= 1.5;
    }
    assert_eq!(flips, 1);
}

/// Prints the regime of every Gilbert case on a 1 ns - 1 us schedule in a worst-case log
/// (`MOTOR_CASES=path cargo test --release --lib classify_fast_schedules -- --ignored
/// --nocapture`): the onion's slowest decay per period `lambda T`, the periods it needs to
/// relax to the tolerance, the ring's largest effect on the rotor and on the onion over a 1 us
/// step against the tolerance, the step angle modulo pi, and the periods repeated in three steps.
#[test]
#[ignore]
fn classify_fast_schedules() {
    let Ok(path) = std::env::var("MOTOR_CASES") else {
        return;
    };
    for line in std::fs::read_to_string(path).unwrap().lines() {
        let Some(rest) = line.split("slow step: ").nth(1) else {
            continue;
        };
        let label = rest.split(':').next().unwrap_or_default();
        let kv = values(
            line.rsplit('[')
                .next()
                .unwrap_or_default()
                .trim_end_matches(']'),
        );
        let Ok((m, mut st, inputs)) = case(&kv) else {
            continue;
        };
        let Some(s) = inputs.schedule.get().copied() else {
            continue;
        };
        if m.params.onion_model != OnionModel::Gilbert || !(1e-9..1e-6).contains(&s.step_period) {
            continue;
        }
        let (k, slowest) = curvature_and_slowest_decay(&m, s.stress_amplitude);
        let a = m.params.gilbert_damping;
        let tol = m.params.tolerance;
        let tau = m.torque_bound();
        let (_, speed, angle) = m.drift_response(1e-6);
        let rotor = if inputs.rotor_locked {
            0.0
        } else {
            tau * angle.min(speed / m.speed_scale)
        };
        let before = skips();
        let steps: Vec<_> = (0..3)
            .map(|_| m.step(&mut st, &inputs, 1e-6).map(|r| r.substeps))
            .collect();
        println!(
            "{label}: T {:.2e} damping {a:.1e} tol {tol:.1e} locked {} | lambda T {:.2e} periods to relax {:.1e} | ring on rotor / tol {:.1e}, on onion / tol {:.1e} | step angle mod pi {:.3} | repeats {} substeps {steps:?}",
            s.step_period,
            u8::from(inputs.rotor_locked),
            slowest * s.step_period,
            (1.0 / tol).ln() / (slowest * s.step_period),
            rotor / tol,
            tau / k / tol,
            s.step_angle.rem_euclid(PI),
            skips() - before,
        );
    }
}
