//! The orbit-averaged Gilbert ringing as an independent test-side model (bisected turning points,
//! frozen landscape, entry mid-orbit) against RK4 of the full macrospin and rotor: the theory that
//! `orbit.rs` implements, checked apart from its implementation.
//!
//! With the landscape `U(psi)` of eq. 3.4 frozen, the undamped macrospin is Hamiltonian in
//! `(psi, -theta/g)` with energy `E = U + T theta^2 / 2`: `psi' = -g T theta`, `theta' = g U'`.
//! An orbit trapped in its well (below both rims) has the action `J = closed int |theta| dpsi`
//! (times `1/g`), period `(dJ/dE) / g`, and Gilbert damping lowers its energy at
//! `dE/dt = -g alpha (U'^2 + T^2 theta^2)`, so over an orbit
//! `J' = -g alpha (T J + closed int U'^2 / (T |theta|) dpsi)`.
//! The rotor turning with the landscape leaves `J` an adiabatic invariant, so `J` is the slow
//! variable; the rotor feels the orbit's mean ring torque `<tau>`. Entering mid-orbit the rotor's
//! speed and angle carry the oscillating parts `P~ / I` and `Q~ / I`, with `P~` the zero-mean
//! antiderivative in time of `tau - <tau>` along the orbit and `Q~` that of `P~`: the averaged
//! rotor starts from `omega - P~ / I`, `phi - Q~ / I`.
//!
//! Quadrature: `psi = c + h sin u` between the turning points `c -+ h` makes `dpsi / |theta|`
//! smooth and periodic in `u` over the whole orbit, so the midpoint rule converges spectrally.

use super::orbit_tests::resolved;
use super::tests::{motor_with, rk4_step, schedule};
use super::{Drive, Motor, MotorInputs, OnionModel, Vector};

/// An orbit of the frozen, undamped macrospin in a well.
struct Orbit {
    /// s.
    period: f64,
    /// `closed int |theta| dpsi` (rad).
    action: f64,
    /// The orbit's mean ring torque on the rotor (N m).
    torque: f64,
    /// `closed int U'^2 / (T |theta|) dpsi` (J rad).
    dissipation: f64,
}

/// The well of the minimum nearest `near` of the landscape at rotor angle `phi`: the minimum and
/// its rims.
fn well(m: &Motor, d: &Drive, phi: f64, near: f64) -> (f64, (f64, f64)) {
    let land = m.landscape(phi, d.direction, d.stress);
    let min = land.settle(near);
    let window = 0.5 * land.curvature(min) / land.third_derivative_bound();
    (min, land.well_rims(min, 0.5 * window))
}

/// The orbit `E` (J) above the minimum `min` with rims `rims`, landscape at rotor angle `phi`, by
/// the midpoint rule on `nodes` points of a half orbit (turning points by bisection).
fn orbit(
    m: &Motor,
    d: &Drive,
    phi: f64,
    (min, rims): (f64, (f64, f64)),
    e: f64,
    nodes: usize,
) -> Orbit {
    let land = m.landscape(phi, d.direction, d.stress);
    let u0 = land.energy(min);
    let above = |x: f64| land.energy(x) - u0;
    let turning = |inside: f64, outside: f64| {
        let (mut a, mut b) = (inside, outside);
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid == a || mid == b {
                break;
            }
            if above(mid) < e {
                a = mid;
            } else {
                b = mid;
            }
        }
        0.5 * (a + b)
    };
    let (a, b) = (turning(min, rims.0), turning(min, rims.1));
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let (g, t) = (m.llg_rate, m.tilt_stiffness);
    let du = std::f64::consts::PI / nodes as f64;
    let (mut time, mut action, mut torque, mut dissipation) = (0.0, 0.0, 0.0, 0.0);
    for j in 0..nodes {
        let u = -std::f64::consts::FRAC_PI_2 + (j as f64 + 0.5) * du;
        let x = c + h * u.sin();
        let dpsi = h * u.cos() * du;
        let gap = (e - above(x)).max(0.0);
        // T |theta| at x.
        let t_theta = (2.0 * t * gap).sqrt();
        let dt = dpsi / (g * t_theta);
        time += dt;
        action += dpsi * t_theta / t;
        torque += dt * m.ring_bar.torque(x - phi);
        let grad = land.gradient(x);
        dissipation += grad * grad * dpsi / t_theta;
    }
    Orbit {
        period: 2.0 * time,
        action: 2.0 * action,
        torque: torque / time,
        dissipation: 2.0 * dissipation,
    }
}

/// The averaged rotor `(phi, omega)` and action `J` after `span` from the full state `y0` in the
/// drive `d`, by RK4 at steps `h` or a tenth of the action's decay time (the action dropped below `1e-10` of its start: the onion on
/// its branch). Returns also the entry's boundary terms `(P~, Q~) / I`.
fn averaged(m: &Motor, d: &Drive, y0: Vector, span: f64, h: f64) -> ([f64; 3], (f64, f64)) {
    const NODES: usize = 32;
    let (g, t, alpha) = (m.llg_rate, m.tilt_stiffness, m.params.gilbert_damping);
    let land = m.landscape(y0[0], d.direction, d.stress);
    let w = well(m, d, y0[0], y0[2]);
    let e0 = land.energy(y0[2]) - land.energy(w.0) + 0.5 * t * y0[3] * y0[3];
    let o = orbit(m, d, y0[0], w, e0, NODES);
    // The boundary terms: the frozen undamped orbit from y0 over one period.
    let steps = 20_000;
    let dt = o.period / steps as f64;
    let rate = |z: &Vector| [0.0, 0.0, -g * t * z[3], g * land.gradient(z[2])];
    let excess = |z: &Vector| m.ring_bar.torque(z[2] - z[0]) - o.torque;
    let (mut z, mut last) = (y0, excess(&y0));
    let (mut p, mut q, mut p_sum, mut q_sum) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..steps {
        z = rk4_step(&rate, &z, dt);
        let now = excess(&z);
        let p_next = p + 0.5 * dt * (last + now);
        q += 0.5 * dt * (p + p_next);
        (p, last) = (p_next, now);
        p_sum += p * dt;
        q_sum += q * dt;
    }
    // P(t) = int_0^t (tau - <tau>) and Q(t) = int_0^t (P - <P>): P~(0) = -<P>, Q~(0) = -<Q>.
    let p_mean = p_sum / o.period;
    let q_mean = (q_sum - 0.5 * p_mean * o.period * o.period) / o.period;
    let boundary = (-p_mean / m.inertia, -q_mean / m.inertia);
    let j_start = o.action;
    let mut guess = e0;
    let mut near = w.0;
    let mut rate = |s: &[f64; 3]| -> [f64; 3] {
        let w = well(m, d, s[0], near);
        near = w.0;
        if s[2] <= 1e-10 * j_start {
            let tau = m.ring_bar.torque(w.0 - s[0]);
            return [s[1], (tau + d.load - m.drag * s[1]) / m.inertia, 0.0];
        }
        // The energy of the orbit of action s[2]: Newton's method, dJ/dE = g period.
        let mut o = orbit(m, d, s[0], w, guess, NODES);
        for _ in 0..20 {
            let step = (s[2] - o.action) / (g * o.period);
            guess += step;
            o = orbit(m, d, s[0], w, guess, NODES);
            if step.abs() <= 1e-12 * guess {
                break;
            }
        }
        [
            s[1],
            (o.torque + d.load - m.drag * s[1]) / m.inertia,
            -g * alpha * (t * s[2] + o.dissipation),
        ]
    };
    let mut s = [y0[0] - boundary.1, y0[1] - boundary.0, j_start];
    // RK4 resolves the action's decay, at about g alpha T.
    let n = (span / h.min(0.1 / (g * alpha * t))).ceil() as usize;
    let h = span / n as f64;
    for _ in 0..n {
        let k1 = rate(&s);
        let k2 = rate(&std::array::from_fn(|i| s[i] + 0.5 * h * k1[i]));
        let k3 = rate(&std::array::from_fn(|i| s[i] + 0.5 * h * k2[i]));
        let k4 = rate(&std::array::from_fn(|i| s[i] + h * k3[i]));
        s = std::array::from_fn(|i| s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        s[2] = s[2].max(0.0);
    }
    (s, boundary)
}

/// The quadrature of a trapped orbit of Table 3.1's onion after the first switch of the
/// schedule, from 0.3 to 0.99 of its well's lowest rim: 32 nodes give the period, action and mean
/// torque of 4096 within 1e-10 (16 nodes within 1e-4 near the rim).
#[test]
fn orbit_quadrature_converges_to_the_rims() {
    let m = motor_with(|p| p.onion_model = OnionModel::Gilbert);
    let d = m.drive_at(&schedule(20e-6), 0.0);
    let w = well(&m, &d, 0.0, 0.0);
    let land = m.landscape(0.0, d.direction, d.stress);
    let barrier = land.energy(w.1 .0).min(land.energy(w.1 .1)) - land.energy(w.0);
    for fraction in [0.3, 0.9, 0.99] {
        let reference = orbit(&m, &d, 0.0, w, fraction * barrier, 4096);
        let o = orbit(&m, &d, 0.0, w, fraction * barrier, 32);
        let worst = [
            o.period / reference.period - 1.0,
            o.action / reference.action - 1.0,
            o.torque / reference.torque - 1.0,
            o.dissipation / reference.dissipation - 1.0,
        ]
        .iter()
        .fold(0.0f64, |a, x| a.max(x.abs()));
        println!(
            "{fraction} of the rim: period {:e} s, 32 nodes within {worst:e}",
            o.period
        );
        assert!(worst < 1e-10, "{fraction}: {worst:e}");
    }
}

/// Table 3.1's motor on the schedule (20 us periods), the onion ringing after the first switch
/// (released from its settled state at 0.3 of its well's rim, or on the same orbit mid-way with
/// either tilt): the orbit-averaged rotor after 1 us (300 ns for the mid-orbit entries) is within
/// a tenth of the tolerance of a fine RK4 of the full system at dampings 1e-4 and 1e-3 (the
/// ringing itself moves it by 5.5e-4 and 5.9e-5 rad), and within the tolerance at 1e-2, where
/// the action changes by a third per orbit. Entered mid-orbit, the boundary term `P~ / I`
/// (125 rad/s) is what keeps it there: without it the rotor is off by `P~ / c` (2.7e-7 rad).
#[test]
fn orbit_averaged_ringing_keeps_the_rotor_of_a_full_integration() {
    for (alpha, entry, span, bound) in [
        (1e-4, 0.0, 1e-6, 1e-7),
        (1e-3, 0.0, 1e-6, 1e-7),
        (1e-2, 0.0, 1e-6, 1e-6),
        (1e-4, 1.0, 3e-7, 1e-7),
        (1e-3, -1.0, 3e-7, 1e-7),
    ] {
        let m = motor_with(|p| {
            p.onion_model = OnionModel::Gilbert;
            p.gilbert_damping = alpha;
        });
        let d = m.drive_at(&schedule(20e-6), 0.0);
        let mut y0: Vector = [0.0; 4];
        if entry != 0.0 {
            // The same orbit entered at the minimum.
            let land = m.landscape(0.0, d.direction, d.stress);
            let min = land.settle(0.0);
            let e = land.energy(0.0) - land.energy(min);
            y0 = [0.0, 0.0, min, entry * (2.0 * e / m.tilt_stiffness).sqrt()];
        }
        let truth = resolved(&m, &d, y0, span);
        let (s, boundary) = averaged(&m, &d, y0, span, 1e-9);
        let error = (s[0] - truth[0]).abs();
        let without = (s[0] + boundary.0 * m.inertia / m.drag - truth[0]).abs();
        println!(
            "damping {alpha}, entry {entry}: rotor {} against {}: error {error:e} rad \
             (boundary {boundary:?}, without P~ {without:e})",
            s[0], truth[0]
        );
        assert!(error < bound, "{alpha} {entry}: {error:e}");
        if entry != 0.0 {
            assert!(without > 10.0 * error, "{alpha} {entry}: {without:e}");
        }
    }
}

/// The averaged advance's refusal before any quadrature rests on two bounds: the ring-bar
/// stiffness never exceeds [`super::magnetics::RingBar::stiffness_bound`] (against the stiffness
/// at 0.01 degree steps), and no orbit is shorter than [`Motor::period_floor`] (against the
/// test-side quadrature above, 256 nodes and bisected turning points, and `orbit.rs`'s) at
/// energies up to 0.95 of the lowest rim, in wells from ring-dominated to strain-dominated, with
/// the bar short and long against the ring.
#[test]
fn no_orbit_is_shorter_than_the_period_floor() {
    let mut checked = 0;
    for bar_length in [350e-9, 150e-9, 450e-9] {
        let m = motor_with(|p| {
            p.onion_model = OnionModel::Gilbert;
            p.bar_length = bar_length;
        });
        let bound = m.ring_bar.stiffness_bound();
        for i in 0..36_000 {
            let k = m
                .ring_bar
                .stiffness(i as f64 * std::f64::consts::TAU / 36_000.0);
            assert!(k.abs() <= bound, "stiffness {k} above its bound {bound}");
        }
        for stress in [0.0, 1e5, 1e7, 2e8, 1e9] {
            let d = m.drive_at(&MotorInputs::fixed(0.5, stress), 0.0);
            let land = m.landscape(0.3, d.direction, d.stress);
            let floor = m.period_floor(&land);
            for near in [0.0, 1.0, 2.0, 3.0, 4.0, 5.0] {
                let Some(well) = m.onion_well(&land, near) else {
                    continue;
                };
                let rims = (well.below, well.above);
                for share in [1e-6, 0.01, 0.1, 0.3, 0.6, 0.9, 0.95] {
                    let e = share * well.barrier;
                    let test_side = orbit(&m, &d, 0.3, (well.minimum, rims), e, 256).period;
                    assert!(test_side >= floor, "{test_side} below the floor {floor}");
                    let guess = (well.minimum - 1e-3, well.minimum + 1e-3);
                    let o = m.orbit(&land, &well, e, guess).unwrap();
                    assert!(o.period >= floor, "{} below the floor {floor}", o.period);
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 100, "only {checked} orbits checked");
}
