//! Model Exchange form of the motor: the right-hand side integrated by a fine reference Runge-Kutta
//! with its events against [`Motor::step`], the fold's event indicator, and the exact partials
//! against central differences.

use super::branch::Branch;
use super::model_exchange::{by, MeGradient};
use super::tests::{motor_with, schedule};
use super::*;

fn motor() -> Motor {
    Motor::new(MotorParams::table_3_1()).unwrap()
}

fn gilbert() -> Motor {
    motor_with(|p| p.onion_model = OnionModel::Gilbert)
}

fn reference_run(
    m: &Motor,
    inputs: &MotorInputs,
    start: MotorState,
    h: f64,
    until: f64,
) -> (MotorState, usize) {
    let n = m.me_state_count();
    let mut s = start;
    let mut schedule_time = s.time;
    m.me_event_update(&mut s, inputs).unwrap();
    let mut events = 0;
    let rk4 = |s: &MotorState, dt: f64, schedule_time: f64| -> MotorState {
        let eval = |y: &MotorState| m.me_evaluate(y, inputs, schedule_time).unwrap().derivatives;
        let shift = |k: &[f64; 4], f: f64| {
            let mut y = *s;
            y.rotor_angle += f * k[0];
            y.rotor_speed += f * k[1];
            if n == 4 {
                y.onion_angle += f * k[2];
                y.onion_tilt += f * k[3];
            }
            y
        };
        let k1 = eval(s);
        let k2 = eval(&shift(&k1, 0.5 * dt));
        let k3 = eval(&shift(&k2, 0.5 * dt));
        let k4 = eval(&shift(&k3, dt));
        let k: [f64; 4] =
            std::array::from_fn(|i| (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0);
        let mut y = shift(&k, dt);
        y.time = s.time + dt;
        y
    };
    while s.time < until * (1.0 - 1e-14) {
        let next_event = m
            .me_next_time_event(inputs, schedule_time)
            .unwrap_or(f64::INFINITY);
        let target = next_event.min(until);
        let dt = h.min(target - s.time);
        let before = m
            .me_evaluate(&s, inputs, schedule_time)
            .unwrap()
            .fold_indicator;
        let mut next = rk4(&s, dt, schedule_time);
        let after = m
            .me_evaluate(&next, inputs, schedule_time)
            .unwrap()
            .fold_indicator;
        let mut event = false;
        if before > 0.0 && after <= 0.0 {
            let (mut lo, mut hi) = (0.0, dt);
            while hi - lo > 1e-6 * h {
                let mid = 0.5 * (lo + hi);
                let y = rk4(&s, mid, schedule_time);
                if m.me_evaluate(&y, inputs, schedule_time)
                    .unwrap()
                    .fold_indicator
                    > 0.0
                {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            next = rk4(&s, hi, schedule_time);
            event = true;
            events += 1;
        }
        s = next;
        if (target - s.time).abs() <= 1e-12 * target.abs().max(1e-300) {
            s.time = target;
        }
        if event || s.time >= next_event {
            schedule_time = s.time;
            m.me_event_update(&mut s, inputs).unwrap();
        } else {
            m.me_follow_branch(&mut s, inputs, schedule_time).unwrap();
        }
    }
    (s, events)
}

fn co_simulation(
    m: &Motor,
    inputs: &MotorInputs,
    start: MotorState,
    h: f64,
    until: f64,
) -> MotorState {
    let mut s = start;
    while s.time < until * (1.0 - 1e-12) {
        let dt = h.min(until - s.time);
        m.step(&mut s, inputs, dt).unwrap();
    }
    s
}

#[test]
fn stiffness_slope_is_the_stiffness_derivative() {
    let m = motor();
    for i in -40..=40 {
        let beta = i as f64 * 0.077;
        let h = 1e-6;
        let fd = (m.ring_bar.stiffness(beta + h) - m.ring_bar.stiffness(beta - h)) / (2.0 * h);
        let exact = m.ring_bar.stiffness_slope(beta);
        assert!(
            (exact - fd).abs() <= 1e-6 * m.ring_bar.stiffness(0.0).abs(),
            "{beta}: {exact:e} {fd:e}"
        );
    }
}

#[test]
fn following_the_branch_agrees_with_settling_away_from_folds() {
    let m = motor();
    // A locked sweep below the fold of tension at -10 degrees (the fold is near 150 MPa): the
    // minimum found from the previous one is the one the Co-Simulation rule settles to.
    let mut anchor = 0.0;
    for i in 0..=100 {
        let stress = 1e6 * i as f64;
        let l = m.landscape(0.0, (-10f64).to_radians(), stress);
        let settled = l.settle(anchor);
        match l.follow(anchor) {
            Branch::Minimum { angle, curvature } => {
                assert!(
                    (angle - settled).abs() < 1e-12,
                    "{stress}: {angle} {settled}"
                );
                assert!(curvature > 0.0);
            }
            other => panic!("{stress}: {other:?}"),
        }
        anchor = settled;
    }
}

/// Tension at -10 degrees on a locked rotor: the branch near alignment folds at a critical stress
/// (`onion_jumps_when_its_minimum_disappears`). The indicator falls to zero there and turns negative
/// just beyond, continuously; the event update then moves the onion to the far minimum, the one
/// Co-Simulation jumps to.
#[test]
fn fold_indicator_changes_sign_where_the_minimum_vanishes() {
    let m = motor();
    let direction = (-10f64).to_radians();
    let locked = |stress| MotorInputs {
        rotor_locked: true,
        ..MotorInputs::fixed(direction, stress)
    };
    let mut s = MotorState::aligned(0.0);
    let mut previous = f64::INFINITY;
    let mut stress = 100e6;
    let mut crossing = None;
    while stress < 300e6 {
        let e = m.me_evaluate(&s, &locked(stress), 0.0).unwrap();
        assert!(
            e.fold_indicator < previous,
            "{stress}: {}",
            e.fold_indicator
        );
        if e.fold_indicator <= 0.0 {
            crossing = Some((stress, previous, e.fold_indicator));
            break;
        }
        previous = e.fold_indicator;
        m.me_follow_branch(&mut s, &locked(stress), 0.0).unwrap();
        stress += 1e4;
    }
    let (critical, last_positive, first_negative) = crossing.expect("a fold below 300 MPa");
    // Both sides of the crossing are small: the indicator is continuous there.
    assert!(
        last_positive < 0.05 && first_negative > -0.05,
        "{last_positive} {first_negative}"
    );
    // The fold's stress from the equilibrium curve (maximum of the branch's stress).
    let e = m.magnetoelastic_per_stress;
    let equilibrium_stress = |b: f64| m.ring_bar.torque(b) / (-e * (2.0 * (b - direction)).sin());
    let mut fold = 0.0;
    for i in 1..20000 {
        let s = equilibrium_stress(i as f64 * 1e-4);
        if s < fold {
            break;
        }
        fold = s;
    }
    assert!((critical - fold).abs() <= 2e4, "{critical:e} {fold:e}");
    // Event: the Co-Simulation rule from the same stored onion.
    let inputs = locked(critical);
    let mut cs = s;
    m.step(&mut cs, &inputs, 1e-9).unwrap();
    let mut me = s;
    m.me_event_update(&mut me, &inputs).unwrap();
    assert!((me.onion_angle - cs.onion_angle).abs() < 1e-12);
    assert!(me.onion_angle.to_degrees() > 60.0, "{}", me.onion_angle);
    let after = m.me_evaluate(&me, &inputs, 0.0).unwrap();
    assert!(after.fold_indicator > 0.0);
}

#[test]
fn right_hand_side_integrates_to_the_co_simulation_rotor() {
    let m = motor();
    // Tension at -45 degrees from alignment: the rotor follows the onion over ~20 us.
    let inputs = MotorInputs::fixed((-45f64).to_radians(), 200e6);
    let start = MotorState::aligned(0.0);
    let (me, events) = reference_run(&m, &inputs, start, 1e-10, 20e-6);
    let cs = co_simulation(&m, &inputs, start, 1e-6, 20e-6);
    assert_eq!(events, 0);
    assert!(me.rotor_angle.abs() > 0.1, "{}", me.rotor_angle);
    assert!(
        (me.rotor_angle - cs.rotor_angle).abs() < 1e-5,
        "{} {}",
        me.rotor_angle,
        cs.rotor_angle
    );
    assert!((me.onion_angle - cs.onion_angle).abs() < 1e-5);
}

#[test]
fn schedule_switches_are_time_events_matching_co_simulation() {
    let m = motor();
    // 20 us periods (several relaxation times): three switches of 60 degrees.
    let inputs = schedule(20e-6);
    let start = MotorState::aligned(0.0);
    let (me, _) = reference_run(&m, &inputs, start, 1e-10, 70e-6);
    let cs = co_simulation(&m, &inputs, start, 1e-6, 70e-6);
    assert!(
        me.rotor_angle.to_degrees() > 150.0,
        "{}",
        me.rotor_angle.to_degrees()
    );
    assert!(
        (me.rotor_angle - cs.rotor_angle).abs() < 1e-4,
        "{} {}",
        me.rotor_angle,
        cs.rotor_angle
    );
}

#[test]
fn a_slipping_rotor_folds_the_onion_with_state_events_as_in_co_simulation() {
    let m = motor();
    // A load beyond the largest torque drags the rotor backwards under the onion, which the
    // tension holds; when the offset passes the fold the onion snaps over (a state event), as in
    // Co-Simulation. Over 100 us the rotor slips more than a turn.
    let (_, peak) = m.ring_bar.max_torque();
    let inputs = MotorInputs {
        load_torque: -1.5 * peak,
        ..MotorInputs::fixed((-45f64).to_radians(), 200e6)
    };
    let start = MotorState::aligned(0.0);
    let until = 100e-6;
    let (me, events) = reference_run(&m, &inputs, start, 2e-10, until);
    let cs = co_simulation(&m, &inputs, start, 1e-7, until);
    assert!(events >= 1, "{events}");
    assert!(me.rotor_angle < -6.5, "{}", me.rotor_angle);
    assert!(
        (me.rotor_angle - cs.rotor_angle).abs() < 1e-4,
        "{} {}",
        me.rotor_angle,
        cs.rotor_angle
    );
    assert!((me.onion_angle - cs.onion_angle).abs() < 1e-3);
}

#[test]
fn gilbert_right_hand_side_integrates_to_the_co_simulation_rotor() {
    let m = gilbert();
    let inputs = MotorInputs::fixed((-45f64).to_radians(), 200e6);
    let start = MotorState::aligned(0.0);
    let (me, events) = reference_run(&m, &inputs, start, 4e-12, 2e-6);
    let cs = co_simulation(&m, &inputs, start, 1e-8, 2e-6);
    assert_eq!(events, 0);
    assert!(me.rotor_angle.abs() > 0.01);
    // Model Exchange's onion is floored (Motor::me_llg_rate): the rotor and the onion, which
    // follows it, within the floor's lag bound (measured: 2.1e-5 rad of 4.2e-4).
    let jump = m
        .landscape(0.0, inputs.strain_direction, 200e6)
        .settle(0.0)
        .abs();
    let bound = onion_lag_bound(&m, jump, 200e6);
    for (a, b, tol) in [
        (me.rotor_angle, cs.rotor_angle, bound),
        (me.onion_angle, cs.onion_angle, bound),
        (me.onion_tilt, cs.onion_tilt, 1e-5),
    ] {
        assert!((a - b).abs() < tol, "{a} {b} {tol}");
    }
}

/// The largest rotor-angle difference the Gilbert onion's floored rate allows after a jump of
/// the drive that leaves the onion `jump` (rad) from its minimum: `jump (tau_me + tau) / (c / k)`,
/// `tau` the envelope decay time and `tau_me` the floored one (see [`Motor::me_llg_rate`]).
fn onion_lag_bound(m: &Motor, jump: f64, stress: f64) -> f64 {
    let slow = m.llg_rate / m.me_llg_rate(stress).0;
    jump * (1.0 + slow) * m.onion_relaxation_time() / m.rotor_relaxation_time()
}

/// The inertial rotor (the bar's own inertia) with the Gilbert macrospin at its own rate under a
/// fixed drive, written here from section 3.2.2 and the LLG equation independently of the Model
/// Exchange form: `I w' = tau_bar(psi - phi) - c w`, `psi' = -g (t theta + alpha G)`,
/// `theta' = g (G - alpha t theta)` with `G = tau_bar(psi - phi) + E sin(2 (psi - gamma))`,
/// `g = gamma / (Ms V (1 + alpha^2))`, `t = mu0 Ms^2 V`, `E = (3/2) lambda_s V sigma`. RK4 of
/// step `h`; the rotor angle at each multiple of `every`.
fn independent_gilbert_rotor(
    m: &Motor,
    drive: (f64, f64),
    h: f64,
    until: f64,
    every: f64,
) -> Vec<f64> {
    let p = &m.params;
    let (alpha, ms, v) = (p.gilbert_damping, p.saturation_magnetization, p.wall_volume);
    let t = magnetics::MU0 * ms * ms * v;
    let g = magnetics::GYROMAGNETIC_RATIO / (ms * v * (1.0 + alpha * alpha));
    let e = 1.5 * p.magnetostriction * v * drive.1;
    let rate = |y: [f64; 4]| -> [f64; 4] {
        let tau = m.ring_bar.torque(y[2] - y[0]);
        let grad = tau + e * (2.0 * (y[2] - drive.0)).sin();
        [
            y[1],
            (tau - m.drag * y[1]) / m.inertia,
            -g * (t * y[3] + alpha * grad),
            g * (grad - alpha * t * y[3]),
        ]
    };
    let (mut y, mut angles) = ([0.0f64; 4], vec![]);
    let steps_per_sample = (every / h).round() as usize;
    for _ in 0..(until / every).round() as usize {
        for _ in 0..steps_per_sample {
            let shift =
                |k: [f64; 4], f: f64| -> [f64; 4] { std::array::from_fn(|i| y[i] + f * k[i]) };
            let k1 = rate(y);
            let k2 = rate(shift(k1, 0.5 * h));
            let k3 = rate(shift(k2, 0.5 * h));
            let k4 = rate(shift(k3, h));
            y = std::array::from_fn(|i| y[i] + h * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]) / 6.0);
        }
        angles.push(y[0]);
    }
    angles
}

/// The Gilbert onion's floored rate against the macrospin at its own rate written above, at the
/// default stress and at 5e8 Pa (where CVode under OMSimulator's settings stopped at t = 0 before
/// the floor): the Model Exchange rotor within the floor's lag bound after the jump at t = 0.
#[test]
fn the_floored_onion_turns_the_rotor_as_the_macrospin_does() {
    let m = gilbert();
    for stress in [200e6, 500e6] {
        let drive = ((-45f64).to_radians(), stress);
        let (until, every) = (6e-6, 1e-6);
        let me: Vec<f64> = model_exchange_rotor(&m, drive, 1e-11, until, every)
            .iter()
            .map(|r| r.0)
            .collect();
        let reference = independent_gilbert_rotor(&m, drive, 2e-13, until, every);
        let jump = m.landscape(0.0, drive.0, stress).settle(0.0).abs();
        let bound = onion_lag_bound(&m, jump, stress);
        let worst = me
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{stress:e} Pa: slowed {:.1}x, rotor at {:.4} rad, largest difference {worst:e} rad \
             (bound {bound:e} rad)",
            m.llg_rate / m.me_llg_rate(stress).0,
            reference[reference.len() - 1]
        );
        assert!(m.me_llg_rate(stress).0 < 0.5 * m.llg_rate);
        assert!(reference[reference.len() - 1].abs() > 0.05, "{reference:?}");
        assert!(worst <= bound, "{worst} > {bound}");
    }
}

/// Central differences of every derivative and output by every state and input.
fn check_partials(m: &Motor, state: &MotorState, inputs: &MotorInputs, what: &str) {
    let p = m.me_partials(state, inputs, state.time).unwrap();
    let exact: Vec<(&str, MeGradient)> = vec![
        ("d rotor_angle/dt", p.derivatives[0]),
        ("d rotor_speed/dt", p.derivatives[1]),
        ("d onion_angle/dt", p.derivatives[2]),
        ("d onion_tilt/dt", p.derivatives[3]),
        ("torque", p.torque),
        ("rotor_angle", p.rotor_angle),
        ("rotor_speed", p.rotor_speed),
        ("onion_angle", p.onion_angle),
        ("offset_angle", p.offset_angle),
        ("magnetostatic_energy", p.magnetostatic_energy),
        ("magnetoelastic_energy", p.magnetoelastic_energy),
        ("applied_strain_direction", p.applied_strain_direction),
    ];
    let values = |s: &MotorState, i: &MotorInputs| -> Vec<f64> {
        let e = m.me_evaluate(s, i, s.time).unwrap();
        let o = e.outputs;
        let mut v = e.derivatives.to_vec();
        v.extend([
            o.torque,
            o.rotor_angle,
            o.rotor_speed,
            o.onion_angle,
            o.offset_angle,
            o.magnetostatic_energy,
            o.magnetoelastic_energy,
            o.applied_strain_direction,
        ]);
        v
    };
    let scale_of = |j: usize| match j {
        by::ROTOR_SPEED => 1e3,
        by::STRESS => 1e5,
        by::LOAD_TORQUE => 1e-21,
        _ => 1e-5,
    };
    for j in 0..by::COUNT {
        let h = scale_of(j);
        let moved = |f: f64| {
            let (mut s, mut i) = (*state, *inputs);
            match j {
                by::ROTOR_ANGLE => s.rotor_angle += f * h,
                by::ROTOR_SPEED => s.rotor_speed += f * h,
                by::ONION_ANGLE => s.onion_angle += f * h,
                by::ONION_TILT => s.onion_tilt += f * h,
                by::STRAIN_DIRECTION => i.strain_direction += f * h,
                by::STRESS => i.stress += f * h,
                _ => i.load_torque += f * h,
            }
            values(&s, &i)
        };
        let (plus, minus) = (moved(1.0), moved(-1.0));
        for (k, (name, gradient)) in exact.iter().enumerate() {
            let fd = (plus[k] - minus[k]) / (2.0 * h);
            let d = gradient[j];
            // Relative to the larger of the two, with a floor: a millionth of the largest change
            // any variable's perturbation makes in this quantity.
            let size = d.abs().max(fd.abs());
            let floor = (0..by::COUNT)
                .map(|i| (gradient[i] * scale_of(i)).abs())
                .fold(0.0, f64::max)
                * 1e-6
                / h
                + 1e-300;
            assert!(
                (d - fd).abs() <= 2e-5 * size + floor,
                "{what}: d {name} / d var {j}: exact {d:e}, central difference {fd:e}"
            );
        }
    }
}

#[test]
fn partials_match_central_differences() {
    let m = motor();
    let direction = (-45f64).to_radians();
    let free = MotorInputs {
        load_torque: 3e-19,
        ..MotorInputs::fixed(direction, 200e6)
    };
    let at = |phi: f64, omega: f64, psi: f64| MotorState {
        rotor_angle: phi,
        rotor_speed: omega,
        onion_angle: psi,
        ..MotorState::aligned(0.0)
    };
    // Near alignment, at the torque peak's side, and moving.
    check_partials(&m, &at(0.0, 0.0, 0.0), &free, "aligned");
    check_partials(&m, &at(0.3, 2e3, 0.1), &free, "offset, moving");
    check_partials(&m, &at(-0.2, -5e4, -0.5), &free, "far offset, fast");
    // Locked rotor, then the schedule (its direction and stress are not inputs).
    let locked = MotorInputs {
        rotor_locked: true,
        ..free
    };
    check_partials(&m, &at(0.1, 0.0, 0.0), &locked, "locked");
    let sched = MotorInputs {
        load_torque: -2e-19,
        ..schedule(1e-4)
    };
    check_partials(&m, &at(0.2, 1e3, 0.9), &sched, "schedule");
    // Gilbert onion: psi and theta are states.
    let g = gilbert();
    let gs = MotorState {
        onion_tilt: 1e-3,
        ..at(0.2, 1e3, 0.5)
    };
    check_partials(&g, &gs, &free, "gilbert");
    check_partials(&g, &gs, &locked, "gilbert locked");
}

#[test]
fn partials_past_the_fold_follow_the_ghost() {
    // Trial evaluations just beyond a fold see the ghost (the inflection the minimum left); its
    // partials are those of the inflection's position.
    let m = motor();
    let direction = (-10f64).to_radians();
    let mut s = MotorState::aligned(0.0);
    let mut stress = 100e6;
    let inputs = |stress| MotorInputs {
        rotor_locked: true,
        ..MotorInputs::fixed(direction, stress)
    };
    loop {
        let e = m.me_evaluate(&s, &inputs(stress), 0.0).unwrap();
        if let Some(Branch::Vanished { .. }) = e.branch {
            break;
        }
        m.me_follow_branch(&mut s, &inputs(stress), 0.0).unwrap();
        stress += 1e5;
        assert!(stress < 300e6);
    }
    // Well past it, so the central differences stay on the ghost.
    check_partials(&m, &s, &inputs(stress + 2e6), "ghost");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
    /// From a minimum of a nearby landscape, following the branch finds the minimum the
    /// Co-Simulation settle finds unless the branch vanished; then the settle jumps away.
    #[test]
    fn follow_agrees_with_settle_or_reports_the_fold(
        phi in -3.0f64..3.0,
        direction in -3.2f64..3.2,
        stress in 0.0f64..600e6,
        start in -3.2f64..3.2,
        dphi in -0.1f64..0.1,
        dstress in -20e6f64..20e6,
    ) {
        let m = motor();
        let anchor = m.landscape(phi, direction, stress).settle(start);
        let moved = m.landscape(phi + dphi, direction, stress + dstress);
        let settled = moved.settle(anchor);
        match moved.follow(anchor) {
            Branch::Minimum { angle, curvature } => {
                proptest::prop_assert!((angle - settled).abs() < 1e-9, "{} {}", angle, settled);
                proptest::prop_assert!(curvature >= 0.0);
            }
            Branch::Vanished { ghost, gradient } => {
                proptest::prop_assert!(moved.curvature(ghost).abs() < 1e-6 * m.alignment_stiffness);
                proptest::prop_assert!(gradient != 0.0);
                // The settle crossed the ghost to another minimum.
                proptest::prop_assert!((settled - ghost).abs() > 1e-3, "{} {}", settled, ghost);
                let again = moved.follow(settled);
                proptest::prop_assert!((again.angle() - settled).abs() < 1e-9, "{:?}", again);
            }
        }
    }
}

/// The Gilbert onion's ringing windows ([`Motor::me_ringing`]) against the macrospin itself: a
/// fine RK4 of the Model Exchange right-hand side after a jump of the drive (tension at -40
/// degrees, 200 MPa, on a locked rotor) rings with the period of the linearized LLG matrix at the
/// new minimum, and has settled to 1e-7 of its jump by the end of the windows.
#[test]
fn gilbert_ringing_windows_cover_the_onion_ringing() {
    let m = gilbert();
    let inputs = MotorInputs {
        rotor_locked: true,
        ..MotorInputs::fixed(-0.7, 2e8)
    };
    let (window, length) = m.me_ringing(2e8).unwrap();
    // The precession at the new minimum: the eigenvalues of g [[-a k, -t], [k, -a t]] with the
    // landscape's curvature k there and the tilt stiffness t = mu0 Ms^2 V.
    let settled = m.landscape(0.0, -0.7, 2e8).settle(0.0);
    let k = m.landscape(0.0, -0.7, 2e8).curvature(settled);
    let (alpha, ms, v) = (0.045, 4.85e5, m.params.wall_volume);
    let t = magnetics::MU0 * ms * ms * v;
    let g = magnetics::GYROMAGNETIC_RATIO / (ms * v * (1.0 + alpha * alpha));
    // Model Exchange integrates it at its floored rate (Motor::me_llg_rate): the same path,
    // slower by g / g_me.
    let g_me = m.me_llg_rate(2e8).0;
    assert!(g_me < 0.5 * g, "{g_me} {g}");
    let slow = g / g_me;
    let g = g_me;
    let (trace, det) = (-g * alpha * (k + t), g * g * (1.0 + alpha * alpha) * k * t);
    let precession = (det - 0.25 * trace * trace).sqrt();
    let periods = window * precession / (2.0 * PI);
    assert!(
        (1.0..=model_exchange::RINGING_WINDOW_PERIODS).contains(&periods),
        "{periods} periods per window"
    );
    assert!((length - 25.0 * m.onion_relaxation_time() * slow).abs() < 1e-9 * length);
    // RK4 at 1/500 of a precession period, well past the windows.
    let h = 2.0 * PI / precession / 500.0;
    let mut s = MotorState::aligned(0.0);
    let mut samples = vec![];
    while s.time < 3.0 * length {
        let rate = |y: &MotorState| m.me_evaluate(y, &inputs, 0.0).unwrap().derivatives;
        let shift = |y: &MotorState, k: [f64; 4], f: f64| MotorState {
            onion_angle: y.onion_angle + f * k[2],
            onion_tilt: y.onion_tilt + f * k[3],
            ..*y
        };
        let k1 = rate(&s);
        let k2 = rate(&shift(&s, k1, 0.5 * h));
        let k3 = rate(&shift(&s, k2, 0.5 * h));
        let k4 = rate(&shift(&s, k3, h));
        let k: [f64; 4] =
            std::array::from_fn(|i| (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0);
        s = shift(&s, k, h);
        s.time += h;
        samples.push((s.time, s.onion_angle));
    }
    let last = s.onion_angle;
    assert!((last - settled).abs() < 1e-9, "{last} {settled}");
    let jump = settled.abs();
    let deviation_after = |from: f64| {
        samples
            .iter()
            .filter(|(time, _)| *time >= from)
            .map(|(_, psi)| (psi - last).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        deviation_after(length) < 1e-7 * jump,
        "{}",
        deviation_after(length)
    );
    // It does ring: a window after the jump it is still far from settled.
    assert!(deviation_after(window) > 1e-2 * jump);
}

/// Neither the quasi-static onion nor an undamped macrospin (which never settles) has windows.
#[test]
fn only_a_damped_gilbert_onion_rings() {
    assert!(gilbert().me_ringing(2e8).is_some());
    assert!(motor().me_ringing(2e8).is_none());
    let undamped = motor_with(|p| {
        p.onion_model = OnionModel::Gilbert;
        p.gilbert_damping = 0.0
    });
    assert!(undamped.me_ringing(2e8).is_none());
}

/// The rotor with the quasi-static onion under a fixed drive, integrated by RK4 of step `h`
/// over `until`, written here from section 3.2.2 independently of the Model Exchange form:
/// inertial (`I w' = tau_bar(psi - phi) - c w` with the bar's own `I`) or, with `inertia` None,
/// overdamped (`c phi' = tau_bar(psi - phi)`). The onion sits on its branch's minimum next to
/// where it was. Returns the rotor angle at each multiple of `every`.
fn independent_rotor(
    m: &Motor,
    drive: (f64, f64),
    inertia: Option<f64>,
    h: f64,
    until: f64,
    every: f64,
) -> Vec<f64> {
    let (direction, stress) = drive;
    let mut onion = 0.0;
    let torque = |phi: f64, onion: &mut f64| {
        *onion = m.landscape(phi, direction, stress).follow(*onion).angle();
        m.ring_bar.torque(*onion - phi)
    };
    let rate = |y: [f64; 2], onion: &mut f64| -> [f64; 2] {
        let tau = torque(y[0], onion);
        match inertia {
            Some(i) => [y[1], (tau - m.drag * y[1]) / i],
            None => [tau / m.drag, 0.0],
        }
    };
    let (mut y, mut t, mut angles) = ([0.0f64; 2], 0.0, vec![]);
    let steps_per_sample = (every / h).round() as usize;
    while t < until * (1.0 - 1e-12) {
        for _ in 0..steps_per_sample {
            let shift = |k: [f64; 2], f: f64| [y[0] + f * k[0], y[1] + f * k[1]];
            let mut o = onion;
            let k1 = rate(y, &mut o);
            let k2 = rate(shift(k1, 0.5 * h), &mut o);
            let k3 = rate(shift(k2, 0.5 * h), &mut o);
            let k4 = rate(shift(k3, h), &mut o);
            y = std::array::from_fn(|i| y[i] + h * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]) / 6.0);
            rate(y, &mut onion);
        }
        t += every;
        angles.push(y[0]);
    }
    angles
}

/// The Model Exchange rotor angle and speed at each multiple of `every` (fine RK4 of its
/// right-hand side).
fn model_exchange_rotor(
    m: &Motor,
    drive: (f64, f64),
    h: f64,
    until: f64,
    every: f64,
) -> Vec<(f64, f64)> {
    let inputs = MotorInputs::fixed(drive.0, drive.1);
    let mut s = MotorState::aligned(0.0);
    let mut rotor = vec![];
    let samples = (until / every).round() as usize;
    for k in 1..=samples {
        s = reference_run(m, &inputs, s, h, k as f64 * every).0;
        rotor.push((s.rotor_angle, s.rotor_speed));
    }
    rotor
}

/// Largest difference of the rotor angles `a` from `b`, and largest difference from the lag
/// `lag x speed` of a first-order lag of time `lag` (`phi_b - phi_a = lag w` for a rotor whose
/// speed lags by `lag` more than `b`'s, to first order).
fn lag_check(a: &[(f64, f64)], b: &[f64], lag: f64) -> (f64, f64) {
    a.iter()
        .zip(b)
        .fold((0.0, 0.0), |(worst, off), (&(phi, w), &reference)| {
            let d = reference - phi;
            (worst.max(d.abs()), f64::max(off, (d - lag * w).abs()))
        })
}

/// Table 3.1's motor in water is not floored: Model Exchange integrates the bar's inertia. In a
/// viscous fluid the floor is 1 ns; for a light bar in water, 1e-4 of the relaxation time.
#[test]
fn the_inertial_time_floor_applies_only_far_below_the_relaxation_time() {
    let m = motor();
    println!(
        "tau_max / k = {:e} rad",
        m.ring_bar.max_torque().1.abs() / m.alignment_stiffness
    );
    assert_eq!(m.me_inertia(), m.inertia);
    assert!(m.inertial_time() > 1e-4 * m.rotor_relaxation_time());
    let viscous = motor_with(|p| p.fluid_viscosity = 4.0);
    assert!(viscous.inertial_time() < 1e-12);
    let floored = viscous.me_inertia() / viscous.drag;
    assert!((floored - 1e-9).abs() < 1e-12 * 1e-9, "{floored}");
    let light = motor_with(|p| p.density = 1000.0);
    let floored = light.me_inertia() / light.drag;
    let expected = 1e-4 * light.rotor_relaxation_time();
    assert!(light.inertial_time() < expected);
    assert!(
        (floored - expected).abs() < 1e-12 * expected,
        "{floored} {expected}"
    );
}

/// A light bar (1000 kg/m^3: inertial time 0.24 ns, floored to 0.31 ns) under tension at -45
/// degrees, against the inertial rotor with its own inertia written above: the floored rotor
/// lags within the bound `T tau_max / c` the documentation gives (measured: a fifth of it; the
/// lag relaxes on `c / k` ~ 3 us, so it is not `(T - I / c) w`).
#[test]
fn the_floored_rotor_follows_the_inertial_rotor_within_its_lag() {
    let m = motor_with(|p| p.density = 1000.0);
    let drive = ((-45f64).to_radians(), 200e6);
    let (until, every) = (10e-6, 1e-6);
    let me = model_exchange_rotor(&m, drive, 2e-11, until, every);
    let inertial = independent_rotor(&m, drive, Some(m.inertia), 1e-11, until, every);
    let floor = m.me_inertia() / m.drag;
    let bound = floor * m.ring_bar.max_torque().1.abs() / m.drag;
    let (worst, off) = lag_check(&me, &inertial, floor - m.inertial_time());
    println!(
        "floor {floor:e} s vs inertial time {:e} s: largest difference {worst:e} rad \
         (bound {bound:e} rad), {off:e} rad from the lag law",
        m.inertial_time()
    );
    assert!(me[me.len() - 1].0 > 0.1, "{me:?}");
    assert!(worst <= bound && worst > 0.0, "{worst} > {bound}");
}

/// In a viscous fluid (0.05 Pa s: inertial time 40 ps, relaxation time 0.17 ms, floor 1 ns) the
/// floored rotor follows the overdamped rotor `c phi' = tau`, written above, lagging by
/// `T w` (measured to 5% over 100 us, where the lag relaxes on `c / k`), at most `T tau_max / c`
/// (to within 1%, the second order).
#[test]
fn the_floored_rotor_in_a_viscous_fluid_is_the_overdamped_rotor() {
    let m = motor_with(|p| p.fluid_viscosity = 0.05);
    let drive = ((-45f64).to_radians(), 200e6);
    let (until, every) = (100e-6, 10e-6);
    let me = model_exchange_rotor(&m, drive, 2e-10, until, every);
    let overdamped = independent_rotor(&m, drive, None, 1e-8, until, every);
    let floor = m.me_inertia() / m.drag;
    assert!((floor - 1e-9).abs() < 1e-20);
    let bound = floor * m.ring_bar.max_torque().1.abs() / m.drag;
    let (worst, off) = lag_check(&me, &overdamped, floor);
    println!(
        "largest difference {worst:e} rad (bound {bound:e} rad), {off:e} rad from the lag law"
    );
    assert!(me[me.len() - 1].0 > 0.05, "{me:?}");
    assert!(worst <= 1.01 * bound, "{worst} > {bound}");
    assert!(off <= 0.1 * worst, "{off} vs {worst}");
}

/// A schedule faster than Model Exchange's shortest period is refused with the parameter and the
/// limit named; at the limit, or without the schedule, it runs.
#[test]
fn model_exchange_refuses_a_schedule_faster_than_its_shortest_period() {
    let m = gilbert();
    let limit = model_exchange::MIN_SCHEDULE_PERIOD;
    let why = m.me_check_schedule(&schedule(0.5 * limit)).unwrap_err();
    assert!(
        why.contains("step_period = 5e-8 s") && why.contains("1e-7 s"),
        "{why}"
    );
    assert!(m.me_check_schedule(&schedule(limit)).is_ok());
    assert!(m.me_check_schedule(&MotorInputs::fixed(0.3, 2e8)).is_ok());
}

/// Table 3.1's onion is floored: its fastest rate bound `g_me L` (written here from the
/// linearized macrospin) is exactly 1 / 0.1 ns. In the thinnest fluid the rotor's relaxation is
/// 15 ns, so the floor (1e-4 of it, 1.6 ps) lies below the onion's own time and `g` is kept;
/// with a light bar it is a tenth of the rotor's floored inertial time.
#[test]
fn the_onion_floor_applies_only_where_the_onion_is_faster_than_it() {
    let m = gilbert();
    let (alpha, ms, v) = (0.045, 4.85e5, m.params.wall_volume);
    let t = magnetics::MU0 * ms * ms * v;
    let g = magnetics::GYROMAGNETIC_RATIO / (ms * v * (1.0 + alpha * alpha));
    let k = m.alignment_stiffness + 2.0 * (1.5 * m.params.magnetostriction * v * 2e8).abs();
    let largest = alpha * (k + t) + (k * t * (1.0 + alpha * alpha)).sqrt();
    println!("fastest rate {:e} /s", g * largest);
    assert!(g * largest > 4e10);
    let (g_me, _) = m.me_llg_rate(2e8);
    assert!((g_me * largest * 1e-10 - 1.0).abs() < 1e-12, "{g_me}");
    assert_eq!(m.me_llg_rate(-2e8).0, g_me);
    let thin = motor_with(|p| {
        p.onion_model = OnionModel::Gilbert;
        p.fluid_viscosity = 5e-6
    });
    assert!(1e-4 * thin.rotor_relaxation_time() < 2e-12);
    assert_eq!(thin.me_llg_rate(2e8), (thin.llg_rate, 0.0));
    // A light bar's rotor (floored inertial time 0.31 ns) keeps the onion ten times faster.
    let light = motor_with(|p| {
        p.onion_model = OnionModel::Gilbert;
        p.density = 1000.0
    });
    let rotor = light.me_inertia() / light.drag;
    assert!((rotor - 1e-4 * light.rotor_relaxation_time()).abs() < 1e-12 * rotor);
    let (g_light, _) = light.me_llg_rate(2e8);
    assert!(
        (g_light * largest * 0.1 * rotor - 1.0).abs() < 1e-12,
        "{g_light}"
    );
}
