//! Locked rotors' Gilbert onions whose steps end far from a converged RK4 of the macrospin
//! without their flag: each pass of the step (its path) against an RK4 from the pass's start and
//! from the step's start.

use super::pass_trace::PASS_TRACE;
use super::resolved_tests::rk4;
use super::*;

/// The RK4's steps a nanosecond for the onion's fastest rate at `y` (a fiftieth of its period).
fn rk4_rate(m: &Motor, y: &Vector, d: &Drive) -> f64 {
    let (_, j) = m.rhs_jacobian(y, d, 1e-12);
    let fastest = j[2][2].abs() + j[3][3].abs() + (j[2][3] * j[3][2]).abs().sqrt();
    1e-9 * fastest / 0.02
}

fn state_at(t: f64, y: &Vector) -> MotorState {
    MotorState {
        time: t,
        rotor_angle: y[0],
        rotor_speed: y[1],
        onion_angle: y[2],
        onion_tilt: y[3],
        substep_hint: 0.0,
    }
}

/// Prints each pass of `steps` 1 us steps of the case `text`: its path, its span, the onion's
/// angle and tilt against an RK4 from the pass's start (the path's own error) and from the step's
/// start (the error carried so far), in tolerances; and the step's end against the RK4 at twice
/// its rate.
pub(super) fn trace_against_rk4(text: &str, steps: usize) {
    let (m, mut st, inputs, _, _) = super::resolved_tests::start_of(text);
    let tol = m.params.tolerance;
    for k in 0..steps {
        let start = st;
        PASS_TRACE.with(|t| *t.borrow_mut() = Some(Vec::new()));
        let report = m.step(&mut st, &inputs, 1e-6);
        let trace = PASS_TRACE.with(|t| t.take()).unwrap_or_default();
        let Ok(report) = report else {
            println!("step {k}: {report:?}");
            return;
        };
        let d = m.drive_at(&inputs, start.time);
        let y0 = [
            start.rotor_angle,
            start.rotor_speed,
            start.onion_angle,
            start.onion_tilt,
        ];
        let per_ns = rk4_rate(&m, &y0, &d);
        let land = m.landscape(y0[0], d.direction, d.stress);
        let stiffest = land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs();
        println!(
            "step {k}: {} substeps, flagged {}, {} passes, rk4 {per_ns:.0}/ns, amplification bound {:.3e}, sqrt(T/K) {:.3e}",
            report.substeps,
            report.accuracy_limited,
            trace.len(),
            super::amplification::AMPLIFICATION.with(|c| c.get()),
            (m.tilt_stiffness / stiffest).sqrt()
        );
        let mut truth = start;
        let plain = std::env::var("TRACE_NO_RK4").is_ok();
        for (i, (label, t0, y0, t1, y1, limited)) in trace.iter().enumerate() {
            if plain {
                let d = m.drive_at(&inputs, *t0);
                println!(
                    "  {i} [{label}] {t0:.6e}..{t1:.6e} psi {:.6} theta {:.4e} -> psi {:?} theta {:?} rate {:.2e}/ns flag {limited}",
                    y0[2], y0[3], y1[2], y1[3], rk4_rate(&m, y0, &d).max(rk4_rate(&m, y1, &d))
                );
                continue;
            }
            // The RK4 at the faster of the pass's ends' rates, and at half of it.
            let d = m.drive_at(&inputs, *t0);
            let rate = per_ns.max(rk4_rate(&m, y0, &d)).max(rk4_rate(&m, y1, &d));
            let own = rk4(&m, &state_at(*t0, y0), &inputs, *t1, rate);
            let own_half = rk4(&m, &state_at(*t0, y0), &inputs, *t1, 0.5 * rate);
            let carried = rk4(&m, &truth, &inputs, *t1, rate);
            let rk4_own = (own[2] - own_half[2])
                .abs()
                .max((own[3] - own_half[3]).abs())
                / tol;
            let (own_a, own_t) = ((y1[2] - own[2]) / tol, (y1[3] - own[3]) / tol);
            let (car_a, car_t) = ((y1[2] - carried[2]) / tol, (y1[3] - carried[3]) / tol);
            if std::env::var("TRACE_ALL").is_ok()
                || own_a.abs().max(own_t.abs()) > 0.1
                || i + 1 == trace.len()
            {
                println!(
                    "  {i} [{label}] {t0:.4e}..{t1:.4e} psi {:.6} theta {:.3e} own {own_a:.3e} {own_t:.3e} carried {car_a:.3e} {car_t:.3e} (rk4 {rk4_own:.1e}) flag {limited}",
                    y1[2], y1[3]
                );
            }
            truth = state_at(*t1, &carried);
        }
        if plain {
            continue;
        }
        let a = rk4(&m, &start, &inputs, st.time, per_ns);
        let b = rk4(&m, &start, &inputs, st.time, 2.0 * per_ns);
        println!(
            "  end: onion {:.3e} tilt {:.3e} tolerances off the RK4 (RK4 halved: {:.1e} {:.1e})",
            (st.onion_angle - b[2]) / tol,
            (st.onion_tilt - b[3]) / tol,
            (a[2] - b[2]) / tol,
            (a[3] - b[3]) / tol
        );
    }
}

/// `LOCKED_CASE` (a bench log's `name=value` list) traced by [`trace_against_rk4`] over
/// `LOCKED_STEPS` (3) steps.
#[test]
#[ignore]
fn trace_locked_case() {
    let Ok(text) = std::env::var("LOCKED_CASE") else {
        return;
    };
    let steps = std::env::var("LOCKED_STEPS").map_or(3, |s| s.parse().unwrap());
    let off = std::env::var("CLOSED_FORM_OFF").is_ok();
    super::block_phi::CLOSED_FORM_OFF.with(|c| c.set(off));
    trace_against_rk4(&text, steps);
}

/// The onion's linear flow about the locked step's end (its settled minimum) from the state
/// `LOCKED_STATE` (`psi,theta,t`) of `LOCKED_CASE` to 1 us: the exact solution of the onion's
/// linearization there, with the rates of its block.
#[test]
#[ignore]
fn linear_flow_at_the_minimum() {
    let Ok(text) = std::env::var("LOCKED_CASE") else {
        return;
    };
    let (m, mut st, inputs, d, y0) = super::resolved_tests::start_of(&text);
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let v: Vec<f64> = std::env::var("LOCKED_STATE")
        .unwrap()
        .split(',')
        .map(|s| s.parse().unwrap())
        .collect();
    let (psi, theta, t) = (v[0], v[1], v[2]);
    let minimum = [y0[0], 0.0, st.onion_angle, 0.0];
    let (f_min, j) = m.rhs_jacobian(&minimum, &d, 1e-12);
    let y = [y0[0], 0.0, psi, theta];
    let (f, j_at) = m.rhs_jacobian(&y, &d, 1e-12);
    let (g, a, tt) = (m.llg_rate, m.params.gilbert_damping, m.tilt_stiffness);
    let k = j[3][2] / g;
    println!(
        "flagged {} end psi {:.12} theta {:e}; g {g:e} a {a} T {tt:e} k(min) {k:e} k(state) {:e}",
        report.accuracy_limited,
        st.onion_angle,
        st.onion_tilt,
        j_at[3][2] / g
    );
    println!("rates at the minimum {f_min:?}, at the state {f:?}");
    let tr = j[2][2] + j[3][3];
    let det = j[2][2] * j[3][3] - j[2][3] * j[3][2];
    let disc = tr * tr - 4.0 * det;
    println!("block eigenvalues: trace {tr:e} det {det:e} disc {disc:e}");
    let h = 1e-6 - t;
    // Pieces short enough for the 2x2 exponential.
    let n = 1000;
    let a2 = [
        [j[2][2] * h / n as f64, j[2][3] * h / n as f64],
        [j[3][2] * h / n as f64, j[3][3] * h / n as f64],
    ];
    let e = crate::physics::numerics::expm2::expm2(&a2).unwrap();
    let mut x = [psi - st.onion_angle, theta];
    for _ in 0..n {
        x = [
            e[0][0] * x[0] + e[0][1] * x[1],
            e[1][0] * x[0] + e[1][1] * x[1],
        ];
    }
    let tol = m.params.tolerance;
    println!(
        "linear flow at 1 us: psi - psi* {:e} theta {:e} ({:.3e} {:.3e} tolerances)",
        x[0],
        x[1],
        x[0] / tol,
        x[1] / tol
    );
}

/// A locked rotor's onion on a landscape 5.8e11 times stiffer than its tilt (`gilbert_damping`
/// 0.12, tolerance 1.04e-9 rad, no schedule): within 1e-15 s the onion settles beside its
/// minimum with a tilt of -1.117 rad, which then decays on the slow mode of the onion's
/// linearization, `theta(t) = theta(t1) exp(-lambda (t - t1))` (`lambda` its slow eigenvalue,
/// 8.0e6 /s; the equations are linear in the tilt and the angle stays within 1e-11 rad of the
/// minimum). The first 1 us step must end on it: a dropped tilt ends 3.55e5 tolerances off, and
/// exponential substeps whose onion block (norm up to 4e10) is taken by scaling and squaring lose
/// 5e-6 to 7e-4 of the slow mode's decay each, beyond their estimates of 0 (266 tolerances off).
#[test]
fn stiff_locked_tilt_decays_on_its_slow_mode() {
    let (m, mut st, inputs, d, y0) = super::resolved_tests::start_of(
        "strain_direction=-3.1002191807592154e8 stress=-3.948789659539256e4 \
         load_torque=-2.915188660354659e-7 ring_outer_diameter=7.837451461560799e-1 \
         ring_inner_diameter=1.035370771336858e-2 bar_length=3.4210622097133195e-4 \
         bar_width=6.39162716150182e-5 thickness=1.0607461343112492e-7 \
         saturation_magnetization=4.355039291841464e0 magnetostriction=-2.8791103888862945e-3 \
         wall_volume=7.77674560293228e-11 density=3.1722774403025265e4 \
         fluid_viscosity=1.6959714680699903e-2 gilbert_damping=1.2029041133580391e-1 \
         tolerance=1.0440132657313633e-9 step_angle=-5.976616289125117e0 \
         step_period=1.782970712804833e3 stress_amplitude=-3.1497651246790237e9 \
         schedule_initial_direction=-7.61318701039412e-1 onion_model=1 max_substeps=11968 \
         schedule=0 rotor_locked=1 initial_onion_offset=-1.132617672120048e-6 \
         strain=8.060435449644146e-2 youngs_modulus=1.9847058949682484e10 strain_drive=1",
    );
    let tol = m.params.tolerance;
    let t1 = 1e-15;
    let mut early = st;
    m.step(&mut early, &inputs, t1).unwrap();
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    // The slow eigenvalue of `g [[-a k, -T], [k, -a T]]` at the step's end (its minimum).
    let (_, j) = m.rhs_jacobian(&[y0[0], 0.0, st.onion_angle, 0.0], &d, 1e-12);
    let trace = -(j[2][2] + j[3][3]);
    let det = j[2][2] * j[3][3] - j[2][3] * j[3][2];
    let slow = 2.0 * det / (trace + (trace * trace - 4.0 * det).sqrt());
    let tilt = early.onion_tilt * (-slow * (1e-6 - t1)).exp();
    println!(
        "tilt at {t1:e} s {:e}; end tilt {:e} against {tilt:e}: {:.3e} tolerances, flagged {}",
        early.onion_tilt,
        st.onion_tilt,
        (st.onion_tilt - tilt) / tol,
        report.accuracy_limited
    );
    assert!(report.accuracy_limited || (st.onion_tilt - tilt).abs() <= tol);
}

/// The cases of a benchmark log (`MOTOR_CASES`, its "slow step" lines) whose labels are listed in
/// `LOCKED_LABELS` (comma-separated, e.g. `random 189369`), each with its motor, start and inputs;
/// `None` without both. `CLOSED_FORM_OFF` takes the general exponential.
fn listed_cases() -> Option<Vec<(String, Motor, MotorState, MotorInputs)>> {
    let path = std::env::var("MOTOR_CASES").ok()?;
    let labels = std::env::var("LOCKED_LABELS").ok()?;
    let off = std::env::var("CLOSED_FORM_OFF").is_ok();
    super::block_phi::CLOSED_FORM_OFF.with(|c| c.set(off));
    let labels: Vec<&str> = labels.split(',').collect();
    let text = std::fs::read_to_string(path).unwrap();
    let listed = text.lines().filter_map(|line| {
        let rest = line.split("slow step: ").nth(1)?;
        let label = rest.split(':').next().unwrap_or_default();
        if !labels.contains(&label) {
            return None;
        }
        let values = line.rsplit('[').next().unwrap_or_default();
        let (m, st, inputs) = super::onion_periods_tests::case(
            &super::onion_periods_tests::values(values.trim_end_matches(']')),
        )
        .unwrap();
        Some((label.to_string(), m, st, inputs))
    });
    Some(listed.collect())
}

/// Each locked Gilbert case of a benchmark log (`MOTOR_CASES`) whose label is listed in
/// `LOCKED_LABELS` (comma-separated, e.g. `random 189369`): each of three 1 us steps' flag, its
/// amplification bound and its end's onion and tilt against an RK4 of the macrospin from the
/// step's start (at 1/50 of the onion's fastest period, skipped beyond `RK4_MOST` steps).
#[test]
#[ignore]
fn locked_step_ends_against_rk4() {
    let Some(cases) = listed_cases() else {
        return;
    };
    let most: f64 = std::env::var("RK4_MOST").map_or(2e7, |s| s.parse().unwrap());
    for (label, m, mut st, inputs) in cases {
        let tol = m.params.tolerance;
        for k in 0..3 {
            let start = st;
            let Ok(report) = m.step(&mut st, &inputs, 1e-6) else {
                println!("{label} step {k}: refused");
                break;
            };
            let bound = super::amplification::AMPLIFICATION.with(|c| c.get());
            let y0 = [
                start.rotor_angle,
                start.rotor_speed,
                start.onion_angle,
                start.onion_tilt,
            ];
            let d = m.drive_at(&inputs, start.time);
            let per_ns = rk4_rate(&m, &y0, &d);
            if per_ns * 1e3 > most {
                println!(
                    "{label} step {k}: flagged {} bound {bound:.2e}: RK4 skipped ({per_ns:.1e}/ns)",
                    report.accuracy_limited
                );
                continue;
            }
            let a = rk4(&m, &start, &inputs, st.time, per_ns);
            let b = rk4(&m, &start, &inputs, st.time, 2.0 * per_ns);
            println!(
                "{label} step {k}: flagged {} bound {bound:.2e}: onion {:.3e} tilt {:.3e} tolerances off (RK4 halved {:.1e})",
                report.accuracy_limited,
                (st.onion_angle - b[2]) / tol,
                (st.onion_tilt - b[3]) / tol,
                (a[2] - b[2]).abs().max((a[3] - b[3]).abs()) / tol
            );
        }
    }
}

/// Each locked Gilbert case of a benchmark log (`MOTOR_CASES`) listed in `LOCKED_LABELS`, for
/// onions too stiff for an RK4: each step's end tilt against its exact decay on the slow mode of
/// the onion's linearization from a point `SETTLED_AFTER` s into the step (default 1e-9 s, its
/// fast mode long over; the slow eigenvalue at that point's angle and at the end's, which differ
/// where a switch changes the landscape). `CLOSED_FORM_OFF` takes the general exponential.
#[test]
#[ignore]
fn locked_tilts_against_their_slow_decay() {
    let Some(cases) = listed_cases() else {
        return;
    };
    let settled: f64 = std::env::var("SETTLED_AFTER").map_or(1e-9, |s| s.parse().unwrap());
    for (label, m, mut st, inputs) in cases {
        let tol = m.params.tolerance;
        let slow = |s: &super::MotorState| {
            let d = m.drive_at(&inputs, s.time);
            let (_, j) = m.rhs_jacobian(&[s.rotor_angle, 0.0, s.onion_angle, 0.0], &d, 1e-12);
            let trace = -(j[2][2] + j[3][3]);
            let det = j[2][2] * j[3][3] - j[2][3] * j[3][2];
            2.0 * det / (trace + (trace * trace - 4.0 * det).sqrt())
        };
        for k in 0..3 {
            let mut early = st;
            let Ok(_) = m.step(&mut early, &inputs, settled) else {
                println!("{label} step {k}: refused");
                break;
            };
            let Ok(report) = m.step(&mut st, &inputs, 1e-6) else {
                println!("{label} step {k}: refused");
                break;
            };
            let left = 1e-6 - settled;
            let (a, b) = (slow(&early), slow(&st));
            let exact = |lambda: f64| early.onion_tilt * (-lambda * left).exp();
            println!(
                "{label} step {k}: flagged {} {} substeps: tilt {:e}, {:.3e} / {:.3e} tolerances off (slow {a:.4e} / {b:.4e} /s, tilt at {settled:e} s {:.3e})",
                report.accuracy_limited,
                report.substeps,
                st.onion_tilt,
                (st.onion_tilt - exact(a)) / tol,
                (st.onion_tilt - exact(b)) / tol,
                early.onion_tilt
            );
        }
    }
}
