//! The Gilbert onion's ringing averaged over its orbits: while the onion rings trapped in one
//! well and loses a small fraction of its energy per orbit, the rotor and the ringing advance by
//! the orbit-averaged equations instead of resolving every precession (see
//! [`Motor::advance_orbits`]).
//!
//! With the landscape `U(psi)` of eq. 3.4 frozen, the undamped macrospin is Hamiltonian in
//! `(psi, -theta/g)` with energy `E = U - U(psi*) + T theta^2 / 2` above the minimum `psi*`:
//! `psi' = -g T theta`, `theta' = g U'`. An orbit trapped in its well has the action
//! `J = closed int |theta| dpsi` (times `1/g`) and the period `P = (dJ/dE) / g`. Gilbert damping
//! lowers the energy at `dE/dt = -g alpha (U'^2 + T^2 theta^2)`, over an orbit by
//! `<E'> = -(alpha / P) (T J + closed int U'^2 / (T |theta|) dpsi)`; the rotor turning at `omega`
//! moves the landscape under the orbit (eq. 3.3 depends on `psi - phi`), which changes `E` by
//! `-omega (tau(psi) - tau(psi*))`, over an orbit by `-omega (<tau> - tau(psi*))` (the rotor
//! gains what the onion loses). The rotor feels the orbit's mean ring torque `<tau>`, and the
//! phase advances at `1/P` cycles per second less the damped precession's frequency shift (for
//! the linearization `sqrt(1 - alpha^2 (T - k)^2 / (4 k T))`, `k = U''(psi*)`, exact once the
//! ringing is small; its error along a nonlinear orbit is bounded in `orbit_phase.rs`). While
//! the rotor turns, the minimum moves at `m' = omega k_bar / k` and the onion rings about the
//! tilt `-m' / (g T)`.
//!
//! The phase is counted from the turning point below the minimum. The time-reversal symmetry of
//! the undamped orbit about its turning points makes the oscillating parts of the rotor's
//! impulse `P~ = int (tau - <tau>) dt` and of the damping's energy loss vanish there: the
//! averaged advance starts and ends at that turning point, where the averaged rotor speed and
//! energy are the resolved ones, and the damping's first-order pull on the phase is the same at
//! both ends. (Off it, the averaged speed is `omega - P~ / I` and the energy `E - E~`, integrated
//! from the turning point; they absorb the rounding of the start.) The rotor angle's oscillating
//! part `Q~ / I` (the integral of `P~ / I`) is about `max |tau - <tau>| P^2 / (4 pi^2 I)` and is
//! bounded at the start.
//!
//! Quadrature: `psi = c + h sin u` between the turning points `c -+ h` makes `dpsi / |theta|`
//! smooth in `u` over the whole orbit: the midpoint rule on a half orbit converges spectrally
//! (32 nodes within 1e-10 up to 0.99 of the rim), Gauss-Legendre on part of it. The turning
//! points are found by Newton's method kept inside the bracket of the minimum and a rim: an
//! orbit's quadrature takes about 1.4 us (release).

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

use super::onion::Landscape;
use super::{Angles, Drive, Motor, Vector};

/// The orbit-averaged advance takes an orbit whose energy is at most this fraction of the lowest
/// rim's height above the minimum: the quadrature stays converged and the averaged orbit's energy
/// off by its oscillating part cannot leave the well.
pub(super) const RIM_MARGIN: f64 = 0.9;
/// A free rotor whose speed relaxes within this fraction of an orbit (`I / c`) is taken as
/// overdamped over the averaged advance: it turns at `(<tau> + load) / c`.
pub(super) const OVERDAMPED: f64 = 0.01;

/// Midpoint nodes on a half orbit.
const NODES: usize = 32;
/// Gauss-Legendre nodes on part of a half orbit.
const GAUSS: usize = 16;

/// A well of eq. 3.4 at one rotor angle: its minimum, rims and curvature.
#[derive(Clone, Copy, Debug)]
pub(super) struct Well {
    pub(super) minimum: f64,
    /// The maxima either side (rad).
    pub(super) below: f64,
    pub(super) above: f64,
    /// The lowest rim's height above the minimum (J).
    pub(super) barrier: f64,
    /// The energy at the minimum (J), as [`point`] gives it.
    pub(super) floor: f64,
    /// `U''` at the minimum (J/rad^2).
    pub(super) curvature: f64,
}

impl Well {
    /// The well with minimum `minimum` (curvature `curvature`) between the rims `(below, above)`
    /// of the landscape `land`, its floor and barrier evaluated there (not checked).
    pub(super) fn between(
        land: &Landscape,
        minimum: f64,
        (below, above): (f64, f64),
        curvature: f64,
    ) -> Well {
        let floor = point(land, minimum).0;
        let barrier = point(land, below).0.min(point(land, above).0) - floor;
        Well {
            minimum,
            below,
            above,
            barrier,
            floor,
            curvature,
        }
    }
}

/// An orbit of the frozen, undamped macrospin in a well.
#[derive(Clone, Copy, Debug)]
pub(super) struct Orbit {
    /// Energy above the minimum (J).
    pub(super) energy: f64,
    /// Turning points below and above the minimum (rad).
    pub(super) below: f64,
    pub(super) above: f64,
    /// s.
    pub(super) period: f64,
    /// `closed int |theta| dpsi` (rad).
    pub(super) action: f64,
    /// The orbit's mean ring torque on the rotor (N m).
    pub(super) torque: f64,
    /// `closed int U'^2 / (T |theta|) dpsi` (J rad).
    pub(super) dissipation: f64,
    /// The largest `|tau - <tau>|` at the nodes (N m).
    pub(super) swing: f64,
    /// The ring torque with the onion at the minimum (N m).
    pub(super) torque_at_minimum: f64,
    /// `T` (J/rad^2).
    tilt_stiffness: f64,
}

impl Orbit {
    /// The orbit's mean energy loss by Gilbert damping `alpha`,
    /// `<E'> = -(alpha / P) (T J + closed int U'^2 / (T |theta|) dpsi)` (W).
    pub(super) fn damping_rate(&self, alpha: f64) -> f64 {
        -alpha * (self.tilt_stiffness * self.action + self.dissipation) / self.period
    }

    /// Half the orbit's width (rad).
    pub(super) fn half_width(&self) -> f64 {
        0.5 * (self.above - self.below)
    }
}

/// Energy (J, up to a constant), gradient (J/rad) and ring torque on the rotor (N m) of the
/// landscape at `x`, from one pair of `sin_cos`.
#[inline]
pub(super) fn point(land: &Landscape, x: f64) -> (f64, f64, f64) {
    let a = Angles::exact(x, land.bar_angle, land.strain_direction);
    let (torque, ring) = land.ring_bar.torque_energy_of(a.sin_offset, a.cos_offset);
    let energy = ring + 0.5 * land.magnetoelastic * (1.0 - a.cos_double);
    (energy, torque + land.magnetoelastic * a.sin_double, torque)
}

/// `(sin u, cos u)` at the midpoint nodes of `[-pi/2, pi/2]`.
fn midpoint_nodes() -> &'static [(f64, f64); NODES] {
    static N: OnceLock<[(f64, f64); NODES]> = OnceLock::new();
    N.get_or_init(|| {
        std::array::from_fn(|j| {
            let u = -FRAC_PI_2 + (j as f64 + 0.5) * PI / NODES as f64;
            u.sin_cos()
        })
    })
}

/// Gauss-Legendre nodes and weights on `[-1, 1]` (Newton on the Legendre polynomial).
fn gauss_nodes() -> &'static [(f64, f64); GAUSS] {
    static N: OnceLock<[(f64, f64); GAUSS]> = OnceLock::new();
    N.get_or_init(|| {
        std::array::from_fn(|i| {
            let n = GAUSS as f64;
            let mut x = -(PI * (i as f64 + 0.75) / (n + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=GAUSS {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                }
                dp = n * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
    })
}

/// The point between `inside` (below the level) and `outside` (above it) where the landscape
/// stands `e` above `floor`: Newton's method kept inside the bracket (bisection when it would
/// leave it), from `guess` when it lies inside, and the landscape's evaluations it took. `None`
/// if `outside` is not above the level. Near the minimum of a small orbit the energy's rounding
/// (its terms are far larger than their difference) over the small gradient there can move
/// Newton's step beyond its stopping size at every point: the bracket then shrinks to two
/// neighbouring floats, and the point where it can shrink no more is the root.
pub(super) fn turning_point(
    land: &Landscape,
    floor: f64,
    e: f64,
    mut inside: f64,
    mut outside: f64,
    guess: f64,
) -> Option<(f64, u32)> {
    if point(land, outside).0 - floor - e <= 0.0 {
        return None;
    }
    let between = |x: f64, a: f64, b: f64| (x - a) * (x - b) < 0.0;
    let mut x = if between(guess, inside, outside) {
        guess
    } else {
        0.5 * (inside + outside)
    };
    for n in 1..=100 {
        let (u, grad, _) = point(land, x);
        let f = u - floor - e;
        let newton = x - f / grad;
        // (The energy's rounding moves the root by about 1e-15 rad, more where `grad` is small.)
        if (newton - x).abs() <= 1e-13 * (1.0 + x.abs()) || f == 0.0 {
            return Some((newton, n));
        }
        if f < 0.0 {
            inside = x;
        } else {
            outside = x;
        }
        let next = if between(newton, inside, outside) {
            newton
        } else {
            0.5 * (inside + outside)
        };
        // The bracket cannot shrink further: every later pass repeats this one.
        if next == x {
            return Some((x, n));
        }
        x = next;
    }
    Some((x, 100))
}

/// Partial integrals along the half orbit rising from the turning point below (see
/// [`Motor::partial_orbit`]).
struct Partial {
    /// s.
    time: f64,
    /// `int (tau - <tau>) dt` (N m s).
    impulse: f64,
    /// `int (E'(t) - <E'>) dt` of the damping's `E' = -g alpha (U'^2 + T^2 theta^2)` (J).
    energy: f64,
}

impl Motor {
    /// The tilt about which the onion rings in the well of `minimum` (its `curvature` `k` there)
    /// while the rotor turns at `omega`: the minimum moves at `m' = omega k_bar / k` (`k_bar`
    /// the ring-bar stiffness), and `psi' = -g T theta` follows it about `theta = -m' / (g T)`.
    pub(super) fn tilt_centre(
        &self,
        land: &Landscape,
        minimum: f64,
        curvature: f64,
        omega: f64,
    ) -> f64 {
        let k_bar = land.ring_bar.stiffness(minimum - land.bar_angle);
        -omega * k_bar / (curvature * self.llg_rate * self.tilt_stiffness)
    }

    /// Whether a free rotor is taken as overdamped over orbits of `period` (see [`OVERDAMPED`]).
    pub(super) fn overdamped(&self, period: f64) -> bool {
        self.inertia <= OVERDAMPED * self.drag * period
    }

    /// The rotor's speed at `y`: its own, or an overdamped rotor's `(tau + load) / c`, or 0
    /// locked.
    pub(super) fn rotor_speed(&self, y: &Vector, d: &Drive, overdamped: bool) -> f64 {
        if d.locked {
            0.0
        } else if overdamped {
            let land = self.landscape(y[0], d.direction, d.stress);
            (point(&land, y[2]).2 + d.load) / self.drag
        } else {
            y[1]
        }
    }

    /// The well of eq. 3.4 at rotor angle `phi` whose minimum the onion at `near` settles into,
    /// with its rims; `None` where it has none (a flat or degenerate landscape).
    pub(super) fn onion_well(&self, land: &Landscape, near: f64) -> Option<Well> {
        self.well_of_minimum(land, land.settle(near))
    }

    /// [`Self::onion_well`] of the minimum `minimum` (`land.settle` of the onion).
    pub(super) fn well_of_minimum(&self, land: &Landscape, minimum: f64) -> Option<Well> {
        let k = land.curvature(minimum);
        let m = land.third_derivative_bound();
        if !(k > 0.0 && k.is_finite() && m > 0.0 && m.is_finite()) {
            return None;
        }
        let (below, above) = land.well_rims(minimum, 0.25 * k / m);
        Some(Well::between(land, minimum, (below, above), k))
            .filter(|w| below < minimum && minimum < above && w.barrier > 0.0)
    }

    /// The orbit `e` (J) above the minimum of `well` (the rims bracket its turning points),
    /// starting the turning points' Newton iterations from `guess`.
    pub(super) fn orbit(
        &self,
        land: &Landscape,
        well: &Well,
        e: f64,
        guess: (f64, f64),
    ) -> Option<Orbit> {
        if !(e > 0.0 && e < well.barrier) {
            return None;
        }
        let a = turning_point(land, well.floor, e, well.minimum, well.below, guess.0)?.0;
        let b = turning_point(land, well.floor, e, well.minimum, well.above, guess.1)?.0;
        let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
        let (g, t) = (self.llg_rate, self.tilt_stiffness);
        let du = PI / NODES as f64;
        let (mut time, mut action, mut torque, mut dissipation) = (0.0, 0.0, 0.0, 0.0);
        let (mut least, mut most) = (f64::INFINITY, f64::NEG_INFINITY);
        for &(sin, cos) in midpoint_nodes() {
            let x = c + h * sin;
            let dpsi = h * cos * du;
            let (u, grad, tau) = point(land, x);
            // T |theta| at x.
            let t_theta = (2.0 * t * (e - (u - well.floor)).max(0.0)).sqrt();
            let dt = dpsi / (g * t_theta);
            time += dt;
            action += dpsi * t_theta;
            torque += dt * tau;
            (least, most) = (least.min(tau), most.max(tau));
            dissipation += grad * grad * dpsi / t_theta;
        }
        let o = Orbit {
            energy: e,
            below: a,
            above: b,
            period: 2.0 * time,
            action: 2.0 * action / t,
            torque: torque / time,
            dissipation: 2.0 * dissipation,
            swing: (most - torque / time).max(torque / time - least),
            torque_at_minimum: point(land, well.minimum).2,
            tilt_stiffness: t,
        };
        [o.period, o.action, o.torque, o.dissipation]
            .iter()
            .all(|x| x.is_finite())
            .then_some(o)
    }

    /// Time, rotor impulse and the damping's energy loss's oscillating part accumulated on the half orbit `o` rising
    /// from its lower turning point to `psi = c + h sin u1` (Gauss-Legendre in `u`).
    fn partial_orbit(&self, land: &Landscape, well: &Well, o: &Orbit, u1: f64) -> Partial {
        let (g, t, alpha) = (
            self.llg_rate,
            self.tilt_stiffness,
            self.params.gilbert_damping,
        );
        let (c, h) = (0.5 * (o.below + o.above), 0.5 * (o.above - o.below));
        let mean_rate = o.damping_rate(alpha);
        let half = 0.5 * (u1 + FRAC_PI_2);
        let (mut time, mut impulse, mut energy_dev) = (0.0, 0.0, 0.0);
        for &(v, w) in gauss_nodes() {
            let u = -FRAC_PI_2 + half * (v + 1.0);
            let (sin, cos) = u.sin_cos();
            let x = c + h * sin;
            let (energy, grad, tau) = point(land, x);
            let gap = (o.energy - (energy - well.floor)).max(0.0);
            let t_theta = (2.0 * t * gap).sqrt();
            let dt = w * half * h * cos / (g * t_theta);
            if !dt.is_finite() {
                continue;
            }
            time += dt;
            impulse += dt * (tau - o.torque);
            let rate = -g * alpha * (grad * grad + 2.0 * t * gap);
            energy_dev += dt * (rate - mean_rate);
        }
        Partial {
            time,
            impulse,
            energy: energy_dev,
        }
    }

    /// The phase (cycles from the lower turning point, in `[0, 1)`) of the onion at `(psi,
    /// theta)` on the orbit `o`, with the oscillating parts `(P~, J~)` there.
    pub(super) fn phase_on_orbit(
        &self,
        land: &Landscape,
        well: &Well,
        o: &Orbit,
        psi: f64,
        theta: f64,
    ) -> (f64, f64, f64) {
        let h = o.half_width();
        let c = o.below + h;
        let u1 = ((psi - c) / h).clamp(-1.0, 1.0).asin();
        let p = self.partial_orbit(land, well, o, u1);
        let fraction = p.time / o.period;
        // Rising (psi' = -g T theta > 0) on the first half orbit, falling back on the second.
        if theta <= 0.0 {
            (fraction, p.impulse, p.energy)
        } else {
            (1.0 - fraction, -p.impulse, -p.energy)
        }
    }
}
