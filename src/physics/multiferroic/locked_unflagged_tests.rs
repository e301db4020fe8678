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
        println!(
            "step {k}: {} substeps, flagged {}, {} passes, rk4 {per_ns:.0}/ns",
            report.substeps,
            report.accuracy_limited,
            trace.len()
        );
        let mut truth = start;
        let plain = std::env::var("TRACE_NO_RK4").is_ok();
        for (i, (label, t0, y0, t1, y1, limited)) in trace.iter().enumerate() {
            if plain {
                let d = m.drive_at(&inputs, *t0);
                println!(
                    "  {i} [{label}] {t0:.6e}..{t1:.6e} psi {:.6} theta {:.4e} -> psi {:.6} theta {:.4e} rate {:.2e}/ns flag {limited}",
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
