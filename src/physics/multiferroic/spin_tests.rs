//! The averaged spin ([`Motor::advance_spinning`]) against the same rotor integrated finely here.

use super::tests::motor_with;
use super::*;

/// Section 3.2.2's rotor `I phi'' = tau(psi - phi) + load - c phi'` with the quasi-static onion
/// settled downhill from its last value at every evaluation, by classical RK4 at a fixed step:
/// an implementation independent of the motor's integrators, sharing only eq. 3.3-3.4.
fn fine_rotor(m: &Motor, d: (f64, f64, f64), state: &mut MotorState, h: f64, dt: f64) {
    let (direction, stress, load) = d;
    let (i, c) = (m.inertia, m.drag);
    let mut psi = state.onion_angle;
    let accel = |phi: f64, omega: f64, psi: &mut f64| {
        *psi = m.landscape(phi, direction, stress).settle(*psi);
        (m.ring_bar.torque_stiffness(*psi - phi).0 + load - c * omega) / i
    };
    let n = (h / dt).ceil() as usize;
    let dt = h / n as f64;
    let (mut phi, mut omega) = (state.rotor_angle, state.rotor_speed);
    for _ in 0..n {
        let mut p = psi;
        let a1 = accel(phi, omega, &mut p);
        let a2 = accel(phi + 0.5 * dt * omega, omega + 0.5 * dt * a1, &mut p);
        let a3 = accel(
            phi + 0.5 * dt * (omega + 0.5 * dt * a1),
            omega + 0.5 * dt * a2,
            &mut p,
        );
        let a4 = accel(phi + dt * (omega + 0.5 * dt * a2), omega + dt * a3, &mut p);
        phi += dt * (omega + dt * (a1 + a2 + a3) / 6.0);
        omega += dt * (a1 + 2.0 * a2 + 2.0 * a3 + a4) / 6.0;
        psi = m.landscape(phi, direction, stress).settle(psi);
    }
    *state = MotorState {
        time: state.time + h,
        rotor_angle: phi,
        rotor_speed: omega,
        onion_angle: psi,
        ..*state
    };
}

/// A Table 3.1 rotor spinning at its terminal speed under loads from 1e-14 to 1e-12 N m (4,600 to
/// 5e5 times eq. 3.3's peak torque; 1e-12 N m spins it at 3.3e10 rad/s, near its burst speed):
/// two steps of about 100 turns each. The motor takes each in
/// one averaged segment; angle and speed agree with the fine RK4 (0.1 ns or 1e-3 rad per step)
/// within the tolerance, at whatever phase the steps end.
#[test]
fn spinning_rotor_agrees_with_fine_integration() {
    let m = motor_with(|p| p.max_substeps = 20_000);
    let d = (0.3, CALIBRATION_STRESS);
    for load in [-1e-14, 3e-14, 1e-13, -1e-12] {
        let terminal = load / m.drag;
        let h = 600.0 / terminal.abs();
        let start = MotorState {
            rotor_speed: terminal,
            ..MotorState::aligned(0.0)
        };
        let inputs = MotorInputs {
            load_torque: load,
            ..MotorInputs::fixed(d.0, d.1)
        };
        let (mut s, mut r) = (start, start);
        s.onion_angle = m.outputs(&s, &inputs).unwrap().onion_angle;
        r.onion_angle = s.onion_angle;
        let dt = (1e-3 / terminal.abs()).min(0.05 * m.inertial_time());
        for k in 0..2 {
            let report = m.step(&mut s, &inputs, h).unwrap();
            fine_rotor(&m, (d.0, d.1, load), &mut r, h, dt);
            eprintln!(
                "{load:e} step {k}: {} substeps, rotor {} against {} ({:e}), speed {} against {} ({:e})",
                report.substeps,
                s.rotor_angle,
                r.rotor_angle,
                s.rotor_angle - r.rotor_angle,
                s.rotor_speed,
                r.rotor_speed,
                (s.rotor_speed - r.rotor_speed) / r.rotor_speed
            );
            assert!(
                !report.accuracy_limited && report.substeps <= 2,
                "{report:?}"
            );
            assert!((s.rotor_angle - r.rotor_angle).abs() < 1e-6, "{load:e}");
            assert!((s.rotor_speed - r.rotor_speed).abs() < 1e-6 * r.rotor_speed.abs());
        }
    }
}

/// A Gilbert substep costs up to about four of the quasi-static onion's, and counts so in the budget:
/// a step that needs more than the budget (tolerance 1e-12 through the precession of an undamped
/// onion, which never relaxes onto its branch) attempts at most `max_substeps / GILBERT_SUBSTEP_WEIGHT` Gilbert substeps (plus the few
/// that finish it), so `max_substeps` bounds a step's cost alike in both onion models.
#[test]
fn a_gilbert_substep_counts_as_its_cost_in_the_budget() {
    for budget in [800, 20_000] {
        let m = motor_with(|p| {
            p.onion_model = OnionModel::Gilbert;
            p.gilbert_damping = 0.0;
            p.tolerance = 1e-12;
            p.max_substeps = budget;
        });
        let mut s = MotorState::aligned(0.0);
        let report = m
            .step(&mut s, &super::tests::schedule(20e-6), 1e-6)
            .unwrap();
        assert!(report.accuracy_limited, "{report:?}");
        assert!(
            report.substeps <= budget / GILBERT_SUBSTEP_WEIGHT + 16,
            "{budget}: {report:?}"
        );
        assert!(s.rotor_angle.is_finite() && (s.time - 1e-6).abs() < 1e-18);
    }
}

/// From rest, where `tau_max / |load|` is at most half the tolerance (here 1e-3, from about
/// 2e-14 N m), the averaged spin takes the whole speed-up in one segment: within the tolerance
/// of the fine RK4 at the end of a step of a quarter inertial time (600 and 720 rad, still
/// speeding up). In air (fluid_viscosity 1.8e-5 Pa s) the inertial time (0.1 us) lets the rotor
/// turn hundreds of radians before it nears its burst speed.
#[test]
fn spinning_rotor_from_rest_agrees_with_fine_integration() {
    let m = motor_with(|p| {
        p.max_substeps = 20_000;
        p.tolerance = 1e-3;
        p.fluid_viscosity = 1.8e-5;
    });
    let d = (0.3, CALIBRATION_STRESS);
    for load in [1e-13f64, -1.2e-13] {
        let h = 0.25 * m.inertial_time();
        let inputs = MotorInputs {
            load_torque: load,
            ..MotorInputs::fixed(d.0, d.1)
        };
        let mut s = MotorState::aligned(0.0);
        s.onion_angle = m.outputs(&s, &inputs).unwrap().onion_angle;
        let mut r = s;
        let dt = (1e-3 * m.drag / load.abs()).min(0.05 * m.inertial_time());
        let report = m.step(&mut s, &inputs, h).unwrap();
        fine_rotor(&m, (d.0, d.1, load), &mut r, h, dt);
        eprintln!(
            "{load:e}: {} substeps, rotor {} against {}, speed {} against {}",
            report.substeps, s.rotor_angle, r.rotor_angle, s.rotor_speed, r.rotor_speed
        );
        assert!(
            !report.accuracy_limited && report.substeps <= 2,
            "{report:?}"
        );
        let tol = m.params.tolerance;
        assert!((s.rotor_angle - r.rotor_angle).abs() < tol, "{load:e}");
        assert!((s.rotor_speed - r.rotor_speed).abs() < tol * r.rotor_speed.abs());
    }
}

/// A Table 3.1 rotor from rest under loads of 1e-15 to 1e-12 N m (200 to 2e5 times eq. 3.3's
/// peak torque), one step of up to 600 rad: the error-controlled integrator resolves the speed's
/// rise through the onion's snaps (two a turn), and the angle at the step's end agrees with the
/// fine RK4 within a few tolerances. A substep cut at a snap had ended at the snap's far side
/// with the rotor's state from its near side, a lag of the speed times the bracket: 2.1e-5,
/// 2.4e-3 and 0.15 rad here, growing with the speed.
#[test]
fn rotor_through_snaps_from_rest_agrees_with_fine_integration() {
    let m = motor_with(|p| p.max_substeps = 20_000);
    let d = (0.3, CALIBRATION_STRESS);
    for load in [1e-15f64, -1e-13, 1e-12] {
        let terminal = load / m.drag;
        let h = (600.0 / terminal.abs()).min(1e-6);
        let inputs = MotorInputs {
            load_torque: load,
            ..MotorInputs::fixed(d.0, d.1)
        };
        let mut s = MotorState::aligned(0.0);
        s.onion_angle = m.outputs(&s, &inputs).unwrap().onion_angle;
        let mut r = s;
        let dt = (1e-3 / terminal.abs()).min(0.05 * m.inertial_time());
        let report = m.step(&mut s, &inputs, h).unwrap();
        fine_rotor(&m, (d.0, d.1, load), &mut r, h, dt);
        eprintln!(
            "{load:e}: {} substeps, rotor {} against {} ({:e}), speed {} against {}",
            report.substeps,
            s.rotor_angle,
            r.rotor_angle,
            s.rotor_angle - r.rotor_angle,
            s.rotor_speed,
            r.rotor_speed
        );
        assert!(r.rotor_angle.abs() > 30.0 && !report.accuracy_limited);
        assert!((s.rotor_angle - r.rotor_angle).abs() < 5e-6, "{load:e}");
        assert!((s.rotor_speed - r.rotor_speed).abs() < 1e-6 * r.rotor_speed.abs());
    }
}

/// A rotor spinning at 1e-13 N m through a fast schedule (a 20 ns period: about 10 turns a
/// period, the strain turned by 60 degrees at each switch): one step over ten periods, each
/// period taken by the averaged spin on the onion's cycle marched for the first and turned with
/// the strain for the others (eq. 3.3-3.4 depend on `psi - phi` and `psi - gamma` only). Angle
/// and speed agree with the fine RK4 through the same switches.
#[test]
fn spinning_rotor_through_a_fast_schedule_agrees_with_fine_integration() {
    let m = motor_with(|p| p.max_substeps = 20_000);
    let load = 1e-13;
    let period = 20e-9;
    let inputs = MotorInputs {
        load_torque: load,
        ..super::tests::schedule(period)
    };
    let schedule = *inputs.schedule.get().unwrap();
    let terminal = load / m.drag;
    let mut s = MotorState {
        rotor_speed: terminal,
        ..MotorState::aligned(0.0)
    };
    s.onion_angle = m.outputs(&s, &inputs).unwrap().onion_angle;
    let mut r = s;
    let report = m.step(&mut s, &inputs, 10.0 * period).unwrap();
    let dt = 1e-3 / terminal;
    for k in 0..10 {
        let direction = schedule.direction((k as f64 + 0.5) * period);
        fine_rotor(
            &m,
            (direction, schedule.stress_amplitude, load),
            &mut r,
            period,
            dt,
        );
    }
    eprintln!(
        "{} substeps, rotor {} against {} ({:e}), speed {} against {}",
        report.substeps,
        s.rotor_angle,
        r.rotor_angle,
        s.rotor_angle - r.rotor_angle,
        s.rotor_speed,
        r.rotor_speed
    );
    assert!(
        !report.accuracy_limited && report.substeps <= 10,
        "{report:?}"
    );
    assert!(r.rotor_angle > 600.0);
    assert!((s.rotor_angle - r.rotor_angle).abs() < 1e-6);
    assert!((s.rotor_speed - r.rotor_speed).abs() < 1e-6 * r.rotor_speed);
}

/// `n` RK4 steps of `dt` of the overdamped rotor `c phi' = tau + load` under a fixed strain,
/// the quasi-static onion settled at every evaluation: the fine reference of the drifting-rotor
/// tests. Returns the rotor and onion angles.
fn overdamped_rk4(
    m: &Motor,
    direction: f64,
    stress: f64,
    load: f64,
    (mut phi, mut psi): (f64, f64),
    dt: f64,
    n: usize,
) -> (f64, f64) {
    let rate = |phi: f64, psi: &mut f64| {
        *psi = m.landscape(phi, direction, stress).settle(*psi);
        (m.ring_bar.torque_stiffness(*psi - phi).0 + load) / m.drag
    };
    for _ in 0..n {
        let mut p = psi;
        let k1 = rate(phi, &mut p);
        let k2 = rate(phi + 0.5 * dt * k1, &mut p);
        let k3 = rate(phi + 0.5 * dt * k2, &mut p);
        let k4 = rate(phi + dt * k3, &mut p);
        phi += dt * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0;
        psi = m.landscape(phi, direction, stress).settle(psi);
    }
    (phi, psi)
}

/// A rotor in a viscous fluid (1e3 Pa s: relaxation time 3 s) driven by 1e-9 N m through a
/// 2 ns schedule: between switches the ring's torque moves it by at most 3e-10 rad, so each
/// segment is the load's motion with the onion settled along the path
/// ([`Motor::advance_drifting`]). Against an overdamped RK4 here (`c phi' = tau + load`, the
/// inertial time 2e-15 s being negligible) with the onion settled at every evaluation, through
/// 100 switches and the onion's snaps as the rotor turns 6 rad.
#[test]
fn a_drifting_rotor_through_a_fast_schedule_agrees_with_fine_integration() {
    let m = motor_with(|p| p.fluid_viscosity = 1e3);
    let load = 1e-9;
    let period = 2e-9;
    let inputs = MotorInputs {
        load_torque: load,
        ..super::tests::schedule(period)
    };
    let schedule = *inputs.schedule.get().unwrap();
    let mut s = MotorState::aligned(0.0);
    s.onion_angle = m.outputs(&s, &inputs).unwrap().onion_angle;
    let (mut phi, mut psi) = (s.rotor_angle, s.onion_angle);
    let report = m.step(&mut s, &inputs, 100.0 * period).unwrap();
    let n = 2000;
    let dt = period / n as f64;
    for k in 0..100 {
        let direction = schedule.direction((k as f64 + 0.5) * period);
        let stress = schedule.stress_amplitude;
        psi = m.landscape(phi, direction, stress).settle(psi);
        (phi, psi) = overdamped_rk4(&m, direction, stress, load, (phi, psi), dt, n);
    }
    // The step ends at a switch: the onion there is settled for the next direction.
    let next = schedule.direction(100.5 * period);
    psi = m
        .landscape(phi, next, schedule.stress_amplitude)
        .settle(psi);
    eprintln!(
        "{} substeps, rotor {} against {phi} ({:e}), onion {} against {psi}",
        report.substeps,
        s.rotor_angle,
        s.rotor_angle - phi,
        s.onion_angle
    );
    assert!(phi > 5.0 && !report.accuracy_limited, "{report:?}");
    let tol = m.params.tolerance;
    assert!((s.rotor_angle - phi).abs() < tol);
    assert!((s.onion_angle - psi).abs() < tol);
    assert!((s.rotor_speed - load / m.drag).abs() < 1e-3 * s.rotor_speed);
    assert!(report.substeps <= 500, "{report:?}");
}

/// The overdamped marches are charged by their settles (one budget substep per
/// `SETTLES_PER_SUBSTEP`), also when they do not apply: a Table 3.1 rotor settling from 1 rad
/// off its equilibrium (a march of a few dozen strides), and one under twice the peak torque,
/// which slips (two turns of about 126 strides each).
#[test]
fn overdamped_marches_are_charged_by_their_settles() {
    let m = motor_with(|p| p.tolerance = 1e-6);
    let d = |load| super::Drive {
        direction: 0.3,
        applied_direction: 0.3,
        stress: CALIBRATION_STRESS,
        load,
        locked: false,
    };
    for (load, slips) in [(0.0, false), (4.4e-18, true)] {
        let d = d(load);
        let mut state = MotorState::aligned(1.0);
        state.onion_angle = m
            .outputs(&state, &MotorInputs::fixed(0.3, CALIBRATION_STRESS))
            .unwrap()
            .onion_angle;
        let mut run = super::StepRun::new(&state, 1.0);
        run.y[2] = state.onion_angle;
        assert!(m.advance_overdamped(&mut run, &d, 1.0));
        assert_eq!(run.attempts, 1);
        assert_eq!(run.limited, slips);
        let least = if slips {
            2 * 126 / super::spin::SETTLES_PER_SUBSTEP
        } else {
            2
        };
        assert!(run.extra_cost >= least, "{load:e}: {}", run.extra_cost);
    }
}

/// A rotor spun by loads of 1e-13 and 2e-13 N m, 1e10 and 2e10 times eq. 3.3's torque bound
/// (Table 3.1 with the ring and bar magnetized at `Ms / 1000`: 1e-23 N m, under 20 Pa to 20 kPa
/// of stress), through schedules of 5 and 100 turns a period, the strain turned by 1.1 or 2.5 rad
/// at each switch. Where the onion follows the bar (20 and 60 Pa) its cycle is its own turn by
/// half a turn; where the strain holds it at an end of its axis (20 kPa: `E` 30 times the
/// torque bound) it turns by the step modulo pi, within a quarter turn (1.1 and -0.64 rad). There
/// the averaged spin takes the periods at once ([`Motor::periods_ahead`]: one or two substeps).
/// In between (200 Pa) the drive has two cycles, the onion near either end of the strain axis,
/// and which one it lands on after a switch depends on the rotor's phase: the periods are taken
/// one by one (turning the cycle through all of them by the step put the onion two turns off).
/// Rotor angle, speed and onion agree with the fine RK4 through every switch within the
/// tolerance.
#[test]
fn spinning_rotor_over_many_periods_agrees_with_fine_integration() {
    let m = motor_with(|p| {
        p.saturation_magnetization *= 1e-3;
        p.max_substeps = 20_000;
    });
    let tol = m.params.tolerance;
    for (load, period, periods) in [(1e-13, 10e-9, 40.0), (2e-13, 1e-7, 3.0)] {
        for (stress, step_angle, at_once) in [
            (20.0, 1.1, true),
            (60.0, 1.1, true),
            (200.0, 1.1, false),
            (2e4, 1.1, true),
            (2e4, 2.5, true),
        ] {
            let schedule =
                SteppingSchedule::new((-30f64).to_radians(), step_angle, period, stress).unwrap();
            let inputs = MotorInputs {
                load_torque: load,
                schedule: ScheduleSwitch::on(schedule),
                ..MotorInputs::fixed(0.0, 0.0)
            };
            let terminal = load / m.drag;
            let mut s = MotorState {
                rotor_speed: terminal,
                ..MotorState::aligned(0.0)
            };
            s.onion_angle = m.outputs(&s, &inputs).unwrap().onion_angle;
            let mut r = s;
            let report = m.step(&mut s, &inputs, periods * period).unwrap();
            for k in 0..periods as usize {
                let direction = schedule.direction((k as f64 + 0.5) * period);
                fine_rotor(
                    &m,
                    (direction, stress, load),
                    &mut r,
                    period,
                    1e-3 / terminal,
                );
            }
            // The step ends at a switch: the onion there is settled for the next direction.
            let next = schedule.direction((periods + 0.5) * period);
            let psi = m
                .landscape(r.rotor_angle, next, stress)
                .settle(r.onion_angle);
            eprintln!(
                "{load:e} N m, {period:e} s, {stress} Pa, {step_angle} rad: {} substeps, rotor {} against {} \
                 ({:e}), speed {:e} relative, onion {} against {psi}",
                report.substeps,
                s.rotor_angle,
                r.rotor_angle,
                s.rotor_angle - r.rotor_angle,
                (s.rotor_speed - r.rotor_speed) / r.rotor_speed,
                s.onion_angle
            );
            assert!(!report.accuracy_limited, "{report:?}");
            assert_eq!(f64::from(report.substeps) <= 2.0, at_once, "{report:?}");
            assert!((s.rotor_angle - r.rotor_angle).abs() < tol);
            assert!((s.rotor_speed - r.rotor_speed).abs() < 1e-6 * r.rotor_speed);
            assert!((s.onion_angle - psi).abs() < tol);
        }
    }
}

/// Table 3.1 with the ring and bar magnetized at `Ms / 1000` (eq. 3.3's torque bound 1e-23 N m)
/// under a 1 ns schedule of 20 kPa (`E` 30 times that bound: the strain holds the onion at an end
/// of its axis) and of 200 Pa (it does not): a locked rotor, and a free one in a viscous fluid
/// (1e3 Pa s) drifting under 1e-9 N m, where the ring cannot move it by a tenth of the tolerance
/// over the whole step. Held, the step takes its switches at once
/// ([`Motor::skip_strain_held_periods`]); not held, one by one. Against the onion settled at
/// every switch from the last (the locked rotor) and the overdamped RK4 with the onion settled
/// at every evaluation (the drifting one): rotor and onion within the tolerance.
#[test]
fn a_strain_held_onion_takes_a_fast_schedule_at_once() {
    let tol = 1e-6;
    let period = 1e-9;
    let switches = 200;
    for locked in [true, false] {
        let m = motor_with(|p| {
            p.saturation_magnetization *= 1e-3;
            p.fluid_viscosity = 1e3;
        });
        let load = if locked { 0.0 } else { 1e-9 };
        for (stress, step_angle, held) in [(2e4, 2.5, true), (2e4, 1.1, true), (200.0, 1.1, false)]
        {
            let schedule =
                SteppingSchedule::new((-30f64).to_radians(), step_angle, period, stress).unwrap();
            let inputs = MotorInputs {
                load_torque: load,
                rotor_locked: locked,
                schedule: ScheduleSwitch::on(schedule),
                ..MotorInputs::fixed(0.0, 0.0)
            };
            let mut s = MotorState::aligned(0.0);
            s.onion_angle = m.outputs(&s, &inputs).unwrap().onion_angle;
            let (mut phi, mut psi) = (s.rotor_angle, s.onion_angle);
            let report = m.step(&mut s, &inputs, switches as f64 * period).unwrap();
            let n = 200;
            let dt = period / n as f64;
            for k in 0..switches {
                let direction = schedule.direction((k as f64 + 0.5) * period);
                psi = m.landscape(phi, direction, stress).settle(psi);
                if locked {
                    continue;
                }
                (phi, psi) = overdamped_rk4(&m, direction, stress, load, (phi, psi), dt, n);
            }
            // The step ends at a switch: the onion there is settled for the next direction.
            let next = schedule.direction((switches as f64 + 0.5) * period);
            psi = m.landscape(phi, next, stress).settle(psi);
            eprintln!(
                "locked {locked}, {stress} Pa, {step_angle} rad: {} substeps, rotor {} against \
                 {phi} ({:e}), onion {} against {psi} ({:e})",
                report.substeps,
                s.rotor_angle,
                s.rotor_angle - phi,
                s.onion_angle,
                s.onion_angle - psi
            );
            assert!(!report.accuracy_limited, "{report:?}");
            // A locked rotor's onion is settled switch by switch in one pass where not held.
            assert_eq!(report.substeps <= 2, held || locked, "{report:?}");
            assert!(locked || phi > 5.0);
            assert!((s.rotor_angle - phi).abs() < tol);
            assert!((s.onion_angle - psi).abs() < tol);
        }
    }
}

/// Without eq. 3.4's term (no wall volume, so the schedule's stress does nothing) the onion sits
/// at the bar and the rotor follows load and drag alone ([`Motor::advance_unstrained`]): a Table
/// 3.1 rotor from rest with the onion started 3.2 rad off (it settles a turn ahead of the bar)
/// through 50 switches of a 2 ns schedule, at rest, drifting (1e-16 N m) and spinning (1e-13 N m,
/// 3.3e9 rad/s), and locked. One step over all 50 switches and steps switch by switch (their
/// ends, the state at every switch) against the fine RK4 here, run period by period with each
/// period's strain direction; the long step takes one substep where the integrator took at least
/// one per switch.
#[test]
fn an_unstrained_rotor_takes_a_fast_schedule_at_once() {
    let m = motor_with(|p| p.wall_volume = 0.0);
    let period = 2e-9;
    let periods = 50;
    for (load, locked) in [(0.0, false), (1e-16, false), (-1e-13, false), (1e-13, true)] {
        let inputs = MotorInputs {
            load_torque: load,
            rotor_locked: locked,
            ..super::tests::schedule(period)
        };
        let schedule = *inputs.schedule.get().unwrap();
        let mut start = MotorState {
            onion_angle: 3.2,
            ..MotorState::aligned(0.0)
        };
        start.onion_angle = m.outputs(&start, &inputs).unwrap().onion_angle;
        assert!((start.onion_angle - 2.0 * PI).abs() < 1e-9);
        let terminal = load / m.drag;
        let dt = (1e-3 / terminal.abs()).min(0.005 * m.inertial_time());
        let (mut long, mut short, mut r) = (start, start, start);
        let report = m.step(&mut long, &inputs, periods as f64 * period).unwrap();
        assert_eq!(report.substeps, 1, "{report:?}");
        for k in 0..periods {
            let t = k as f64 * period;
            let report = m.step(&mut short, &inputs, period).unwrap();
            assert_eq!(report.substeps, 1, "{report:?}");
            if locked {
                r.time += period;
            } else {
                let direction = schedule.direction(t + 0.5 * period);
                fine_rotor(
                    &m,
                    (direction, schedule.stress_amplitude, load),
                    &mut r,
                    period,
                    dt,
                );
            }
            let tol = m.params.tolerance;
            let ends = if k + 1 == periods { 2 } else { 1 };
            for s in [&short, &long].into_iter().take(ends) {
                assert!(
                    (s.rotor_angle - r.rotor_angle).abs() < tol,
                    "{load:e} {k}: {s:?} {r:?}"
                );
                assert!(
                    (s.onion_angle - r.onion_angle).abs() < tol,
                    "{load:e} {k}: {s:?} {r:?}"
                );
                assert!(
                    (s.rotor_speed - r.rotor_speed).abs() <= 1e-9 * terminal.abs() + 1e-3,
                    "{load:e} {k}: {s:?} {r:?}"
                );
            }
        }
        eprintln!(
            "{load:e}: rotor {} against {}",
            long.rotor_angle, r.rotor_angle
        );
        if load.abs() > 1e-14 && !locked {
            assert!(r.rotor_angle.abs() > 100.0, "{r:?}");
        }
    }
}

/// The quasi-static onion by its own gradient flow `psi' = -U'(psi) / K` (eq. 3.3 plus eq. 3.4)
/// to rest, by RK4 with a step a tenth of the flow's fastest time: the memory rule (downhill
/// from where it was) without the settle's march.
fn onion_by_gradient_flow(m: &Motor, phi: f64, direction: f64, stress: f64, psi: f64) -> f64 {
    let l = m.landscape(phi, direction, stress);
    let scale = m.torque_bound() + 2.0 * l.magnetoelastic.abs();
    let dt = 0.05;
    let rate = |x: f64| -l.gradient(x) / scale;
    let mut x = psi;
    for _ in 0..1_000_000 {
        let k1 = rate(x);
        let k2 = rate(x + 0.5 * dt * k1);
        let k3 = rate(x + 0.5 * dt * k2);
        let k4 = rate(x + dt * k3);
        let dx = dt * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0;
        x += dx;
        if dx.abs() < 1e-14 {
            break;
        }
    }
    x
}

/// A locked Table 3.1 rotor under a 2 ns schedule whose strain (200 MPa, turning 1.1 rad a
/// switch) does not hold the onion: its onion is settled switch by switch in one pass
/// ([`Motor::settle_locked_periods`], a step's report shows two substeps where it showed one a
/// switch). At every fifth switch (the ends of 5-period steps) and after one 100-period step,
/// the onion is the one its gradient flow reaches from the last one at every switch.
#[test]
fn a_locked_rotor_onion_follows_its_gradient_flow_through_a_fast_schedule() {
    let m = motor_with(|p| p.tolerance = 1e-9);
    let period = 2e-9;
    let stress = CALIBRATION_STRESS;
    let schedule = SteppingSchedule::new(0.3, 1.1, period, stress).unwrap();
    let inputs = MotorInputs {
        rotor_locked: true,
        schedule: ScheduleSwitch::on(schedule),
        ..MotorInputs::fixed(0.0, 0.0)
    };
    let held = m.drive_at(&inputs, 0.0);
    assert!(m.strain_held_turn(&held, 1.1).is_none());
    let mut start = MotorState::aligned(0.5);
    start.onion_angle = m.outputs(&start, &inputs).unwrap().onion_angle;
    let (mut long, mut short) = (start, start);
    let report = m.step(&mut long, &inputs, 100.0 * period).unwrap();
    assert!(report.substeps <= 2, "{report:?}");
    let mut psi = start.onion_angle;
    let mut distinct = 0;
    for k in 1..=100 {
        let before = psi;
        let direction = schedule.direction((k as f64 + 0.5) * period);
        psi = onion_by_gradient_flow(&m, 0.5, direction, stress, psi);
        distinct += ((psi - before).abs() > 0.5) as usize;
        if k % 5 == 0 {
            let report = m.step(&mut short, &inputs, 5.0 * period).unwrap();
            assert!(report.substeps <= 2, "{report:?}");
            assert!(
                (short.onion_angle - psi).abs() < 1e-8,
                "{k}: {short:?} {psi}"
            );
            assert_eq!(short.rotor_angle, 0.5);
        }
    }
    assert!((long.onion_angle - psi).abs() < 1e-8, "{long:?} {psi}");
    // The onion snapped between the strain's axes at switches, not only followed them.
    assert!(distinct > 10, "{distinct}");
}

/// The slowest quasi-static step of the worst-case benchmark before the spin went on through
/// strain-held switches: a rotor at 1.6e7 rad/s, 0.46 rad per 29 ns period, its onion held
/// across the strain axis (`E < 0`) by a strain turning 0.7 rad a switch. One call of
/// [`Motor::advance_spinning`] takes the first segment and every later one of a step
/// (`spin_held_periods`), and the state at the ends of steps of 1 to 34 periods agrees with the
/// fine RK4 here run period by period; a step restored from a saved state repeats bit for bit
/// on a fresh copy of the motor (no memoized cycle) and on the one that memoized it.
#[test]
fn a_strain_held_spin_goes_on_through_the_switches() {
    let m = Motor::new(MotorParams {
        ring_outer_diameter: 3.641e-3,
        ring_inner_diameter: 3.230e-5,
        bar_length: 2.241e-5,
        bar_width: 1.942e-5,
        thickness: 2.415e-7,
        saturation_magnetization: 1.742e6,
        magnetostriction: 2.379e-3,
        wall_volume: 9.741e-11,
        density: 1.421e4,
        fluid_viscosity: 2.172,
        gilbert_damping: 1.203e-3,
        onion_model: OnionModel::QuasiStatic,
        tolerance: 4.756e-6,
        max_substeps: 136,
    })
    .unwrap();
    let period = 2.928e-8;
    let schedule = SteppingSchedule::new(-5.632e-8, 6.999e-1, period, 2.354e9).unwrap();
    let inputs = MotorInputs {
        load_torque: 2.455e-7,
        schedule: ScheduleSwitch::on(schedule),
        ..MotorInputs::fixed(0.0, 0.0)
    };
    let d = m.drive_at(&inputs, 0.0);
    assert!(m.strain_held_turn(&d, schedule.step_angle).is_some());
    let terminal = inputs.load_torque / m.drag;
    let mut start = MotorState {
        rotor_speed: terminal,
        ..MotorState::aligned(0.0)
    };
    start.onion_angle = m.outputs(&start, &inputs).unwrap().onion_angle;
    let periods = 34;
    let mut reference = vec![start];
    let mut r = start;
    let dt = (1e-3 / terminal).min(0.005 * m.inertial_time());
    for k in 0..periods {
        let direction = schedule.direction((k as f64 + 0.5) * period);
        fine_rotor(
            &m,
            (direction, schedule.stress_amplitude, inputs.load_torque),
            &mut r,
            period,
            dt,
        );
        reference.push(r);
    }
    for k in [1, 2, 5, 17, periods] {
        let h = k as f64 * period;
        let mut run = StepRun::new(&start, h);
        run.schedule = Some(schedule);
        assert!(m.advance_spinning(&mut run, &d, period.min(h)));
        assert_eq!(run.t, run.t_end, "{k} periods");
        let mut s = start;
        m.step(&mut s, &inputs, h).unwrap();
        let r = reference[k];
        eprintln!(
            "{k} periods: rotor {} against {} ({:e})",
            s.rotor_angle,
            r.rotor_angle,
            s.rotor_angle - r.rotor_angle
        );
        let tol = m.params.tolerance;
        assert!(
            (s.rotor_angle - r.rotor_angle).abs() < tol,
            "{k}: {s:?} {r:?}"
        );
        assert!(
            (s.rotor_speed - r.rotor_speed).abs() < 1e-6 * terminal,
            "{k}: {s:?} {r:?}"
        );
        // The step ends at a switch: the onion there is settled for the next direction.
        let next = schedule.direction((k as f64 + 0.5) * period);
        let psi = m
            .landscape(r.rotor_angle, next, schedule.stress_amplitude)
            .settle(r.onion_angle);
        assert!((s.onion_angle - psi).abs() < tol, "{k}: {s:?} {psi}");
    }
    // Steps from a saved state: the same bits on a fresh copy and on the motor that memoized.
    let mut saved = start;
    m.step(&mut saved, &inputs, 1e-6).unwrap();
    let (mut again, mut fresh) = (saved, saved);
    m.step(&mut again, &inputs, 1e-6).unwrap();
    m.clone().step(&mut fresh, &inputs, 1e-6).unwrap();
    assert_eq!(again, fresh);
    let mut y = [again.rotor_angle, again.rotor_speed, again.onion_angle, 0.0];
    y[2] = m.settle(&y, &m.drive_at(&inputs, again.time));
    assert!(m
        .canonical_cycle(&y, &m.drive_at(&inputs, again.time), 1.0, &mut 0)
        .is_some());
}

/// The onion's cycle ([`Motor::onion_cycle`]: a landing march up to its first snap, the snaps of
/// the measured turn placed by secant steps on the squared curvature) against the onion settled
/// here along three turns of the rotor in 1e-4 rad strides: on the third turn the energy its
/// jumps release (the cycle's work, eq. 3.3 plus 3.4 before less after each jump, located by
/// bisection) and the onion at the cycle's samples (modulo turns) agree.
#[test]
fn the_onion_cycle_agrees_with_a_fine_march() {
    let m = motor_with(|p| p.tolerance = 1e-9);
    for (direction, stress, dir) in [(0.3, CALIBRATION_STRESS, 1.0), (-0.7, 2.5e8, -1.0)] {
        let d = super::Drive {
            direction,
            applied_direction: direction,
            stress,
            load: dir * 1e-12,
            locked: false,
        };
        let cycle = m.onion_cycle(&[0.0; 4], &d, dir, &mut 0).unwrap();
        let l = |phi: f64| m.landscape(phi, direction, stress);
        let stride = 1e-4;
        let n = (2.0 * PI / stride).round() as usize;
        let mut psi = l(0.0).settle(0.0);
        let (mut work, mut jumps) = (0.0, 0);
        let mut path = Vec::with_capacity(n);
        for k in 1..=3 * n {
            let phi = dir * k as f64 * stride;
            let next = l(phi).settle(psi);
            if k > 2 * n {
                if (next - psi).abs() > 0.05 {
                    // The fold by bisection, each side settled from the onion before the jump.
                    let (mut lo, mut psi_lo, mut hi, mut psi_hi) =
                        (phi - dir * stride, psi, phi, next);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        let at = l(mid).settle(psi_lo);
                        if (at - psi_lo).abs() > 0.05 {
                            (hi, psi_hi) = (mid, at);
                        } else {
                            (lo, psi_lo) = (mid, at);
                        }
                    }
                    work += l(hi).energy(psi_hi) - l(lo).energy(psi_lo);
                    jumps += 1;
                }
                path.push((phi, next));
            }
            psi = next;
        }
        eprintln!("work {} against {work}, {jumps} jumps", cycle.work);
        assert!(jumps >= 1);
        assert!(
            (cycle.work - work).abs() <= 1e-6 * work.abs(),
            "{} {work}",
            cycle.work
        );
        let mut agreeing = 0;
        for j in (0..cycle.torque.len()).step_by(7) {
            let phi = cycle.rotor + dir * cycle.torque[j].0;
            let at = ((dir * (phi - path[0].0)).rem_euclid(2.0 * PI) / stride).round() as usize;
            let (phi_ref, psi_ref) = path[at.min(n - 1)];
            let psi = l(phi_ref).settle(cycle.onion_samples[j]);
            // Away from the snaps the two follow the same branch.
            if (psi - psi_ref - 2.0 * PI * ((psi - psi_ref) / (2.0 * PI)).round()).abs() > 1e-6 {
                let near_snap = cycle
                    .torque
                    .windows(2)
                    .filter(|w| w[1].0 - w[0].0 < 1e-9)
                    .any(|w| {
                        let gap = (w[0].0 - cycle.torque[j].0).rem_euclid(2.0 * PI);
                        gap.min(2.0 * PI - gap) < 2e-4
                    });
                assert!(near_snap, "{j}: {psi} {psi_ref}");
            } else {
                agreeing += 1;
            }
        }
        assert!(agreeing >= 15, "{agreeing}");
    }
}
