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
            assert_eq!(report.substeps <= 2, held, "{report:?}");
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
