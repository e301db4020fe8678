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
//! ringing is small). While the rotor turns, the minimum moves at `m' = omega k_bar / k` and the
//! onion rings about the tilt `-m' / (g T)`.
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
use super::step::StepRun;
use super::{Angles, Drive, Motor, Vector};
use crate::physics::numerics::dormand_prince;

/// Midpoint nodes on a half orbit.
const NODES: usize = 32;
/// Gauss-Legendre nodes on part of a half orbit.
const GAUSS: usize = 16;
/// The orbit's energy at most this fraction of the lowest rim's height above the minimum: the
/// quadrature stays converged and the averaged orbit's energy off by its oscillating part
/// cannot leave the well.
const RIM_MARGIN: f64 = 0.9;
/// At most this fraction of the energy lost per orbit (the averaging's small parameter).
const MAX_LOSS_PER_ORBIT: f64 = 0.05;
/// The averaged advance is tried when the segment has at least this many orbits left (fewer
/// are resolved at about the cost of the averaged advance's entry and exit).
const MIN_ORBITS: f64 = 8.0;
/// An evaluation of the averaged equations' right-hand side (an orbit's quadrature and the
/// well's minimum, about 2 us) in the budget's units, substeps of the quasi-static onion
/// (0.32 us, see [`super::GILBERT_SUBSTEP_WEIGHT`]).
const ORBIT_EVALUATION_WEIGHT: u32 = 6;
/// A Dormand-Prince step of the averaged equations (six evaluations) in the budget's units.
const AVERAGED_STEP_WEIGHT: u32 = 6 * ORBIT_EVALUATION_WEIGHT;
/// A free rotor whose speed relaxes within this fraction of an orbit (`I / c`) is taken as
/// overdamped over the averaged advance: it turns at `(<tau> + load) / c`.
const OVERDAMPED: f64 = 0.01;
/// The most RK4 steps of the march to the first turning point (two orbits), one unit each.
const MARCH_STEPS: u32 = 256;

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
/// leave it), from `guess` when it lies inside. `None` if `outside` is not above the level.
fn turning_point(
    land: &Landscape,
    floor: f64,
    e: f64,
    mut inside: f64,
    mut outside: f64,
    guess: f64,
) -> Option<f64> {
    if point(land, outside).0 - floor - e <= 0.0 {
        return None;
    }
    let between = |x: f64, a: f64, b: f64| (x - a) * (x - b) < 0.0;
    let mut x = if between(guess, inside, outside) {
        guess
    } else {
        0.5 * (inside + outside)
    };
    for _ in 0..100 {
        let (u, grad, _) = point(land, x);
        let f = u - floor - e;
        let newton = x - f / grad;
        // (The energy's rounding moves the root by about 1e-15 rad.)
        if (newton - x).abs() <= 1e-13 * (1.0 + x.abs()) || f == 0.0 {
            return Some(newton);
        }
        if f < 0.0 {
            inside = x;
        } else {
            outside = x;
        }
        x = if between(newton, inside, outside) {
            newton
        } else {
            0.5 * (inside + outside)
        };
    }
    Some(x)
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
    /// The well of eq. 3.4 at rotor angle `phi` whose minimum the onion at `near` settles into,
    /// with its rims; `None` where it has none (a flat or degenerate landscape).
    pub(super) fn onion_well(&self, land: &Landscape, near: f64) -> Option<Well> {
        let minimum = land.settle(near);
        let k = land.curvature(minimum);
        let m = land.third_derivative_bound();
        if !(k > 0.0 && k.is_finite() && m > 0.0 && m.is_finite()) {
            return None;
        }
        let (below, above) = land.well_rims(minimum, 0.25 * k / m);
        let floor = point(land, minimum).0;
        let barrier = point(land, below).0.min(point(land, above).0) - floor;
        (below < minimum && minimum < above && barrier > 0.0).then_some(Well {
            minimum,
            below,
            above,
            barrier,
            floor,
            curvature: k,
        })
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
        let a = turning_point(land, well.floor, e, well.minimum, well.below, guess.0)?;
        let b = turning_point(land, well.floor, e, well.minimum, well.above, guess.1)?;
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
    fn phase_on_orbit(
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

/// The averaged ringing's state: rotor angle and speed (rad, rad/s), the orbit's energy above
/// the minimum (J) and its phase (cycles).
type Slow = [f64; 4];

/// The averaged equations' right-hand side at one rotor angle after another, each well and orbit
/// found from the last (the landscape moves little between calls).
struct Averager<'a> {
    m: &'a Motor,
    d: &'a Drive,
    well: Well,
    orbit: Orbit,
    /// Evaluations of the right-hand side.
    evaluations: u32,
    /// The rotor is overdamped (see [`OVERDAMPED`]).
    overdamped: bool,
}

impl Averager<'_> {
    /// The well at rotor angle `phi`: the last one's rims moved with its minimum (they bracket
    /// the turning points; [`turning_point`] checks that they still do).
    fn well_at(&self, land: &Landscape) -> Option<Well> {
        let minimum = land.settle(self.well.minimum);
        let shift = minimum - self.well.minimum;
        let k = land.curvature(minimum);
        let floor = point(land, minimum).0;
        let (below, above) = (self.well.below + shift, self.well.above + shift);
        let barrier = point(land, below).0.min(point(land, above).0) - floor;
        (k > 0.0 && barrier > 0.0).then_some(Well {
            minimum,
            below,
            above,
            barrier,
            floor,
            curvature: k,
        })
    }

    /// The well and orbit at the slow state `s`, the turning points' iterations started from the
    /// last orbit's moved with its minimum.
    fn orbit_at(&self, s: &Slow) -> Option<(Well, Orbit)> {
        let land = self.m.landscape(s[0], self.d.direction, self.d.stress);
        let well = self.well_at(&land)?;
        let shift = well.minimum - self.well.minimum;
        let guess = (self.orbit.below + shift, self.orbit.above + shift);
        let o = self.m.orbit(&land, &well, s[2], guess)?;
        Some((well, o))
    }

    /// The averaged equations: the rotor driven by the orbit's mean torque, the energy lowered by
    /// the damping and by the landscape turning under the orbit (the orbit's mean of
    /// `dU/dphi omega` less the minimum's), the phase at the damped orbit's frequency.
    fn rate(&mut self, s: &Slow) -> Option<Slow> {
        self.evaluations += 1;
        let m = self.m;
        let (well, o) = self.orbit_at(s)?;
        let (alpha, t) = (m.params.gilbert_damping, m.tilt_stiffness);
        let k = well.curvature;
        let shift = 1.0 - alpha * alpha * (t - k) * (t - k) / (4.0 * k * t);
        if shift.is_nan() || shift <= 0.0 {
            return None;
        }
        self.well = well;
        self.orbit = o;
        let rotor = if self.d.locked {
            [0.0, 0.0]
        } else if self.overdamped {
            [(o.torque + self.d.load) / m.drag, 0.0]
        } else {
            [s[1], (o.torque + self.d.load - m.drag * s[1]) / m.inertia]
        };
        Some([
            rotor[0],
            rotor[1],
            o.damping_rate(alpha) - rotor[0] * (o.torque - o.torque_at_minimum),
            shift.sqrt() / o.period,
        ])
    }
}

/// What [`Motor::advance_orbits`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct OrbitAdvance {
    /// Accepted and rejected steps of the averaged equations.
    pub(super) steps: u32,
    /// Their right-hand sides' evaluations.
    pub(super) evaluations: u32,
    /// RK4 steps of the full system to the first turning point.
    pub(super) resolved: u32,
}

impl OrbitAdvance {
    /// The budget units beyond `steps`: each evaluation by its measured cost, each RK4 step one.
    pub(super) fn extra_cost(&self) -> u32 {
        self.evaluations
            .saturating_mul(ORBIT_EVALUATION_WEIGHT)
            .saturating_add(self.resolved)
    }
}

impl Motor {
    /// The tilt about which the onion rings while the rotor turns at `omega`: the minimum moves
    /// at `m' = omega k_bar / k` (the ring-bar stiffness over the well's curvature), and
    /// `psi' = -g T theta` follows it about `theta = -m' / (g T)`.
    fn tilt_centre(&self, land: &Landscape, well: &Well, omega: f64) -> f64 {
        let k_bar = land.ring_bar.stiffness(well.minimum - land.bar_angle);
        -omega * k_bar / (well.curvature * self.llg_rate * self.tilt_stiffness)
    }

    /// Advances the Gilbert onion's ringing and the rotor by the orbit-averaged equations (see
    /// the module documentation) from `run`'s state towards `segment_end`, when the onion is
    /// trapped in its well (at most [`RIM_MARGIN`] of the lowest rim's height above the
    /// minimum), loses at most [`MAX_LOSS_PER_ORBIT`] of its energy per orbit, the segment has
    /// at least [`MIN_ORBITS`] orbits left and the rotor angle's oscillating part `Q~ / I`
    /// (left out) is within a tenth of the tolerance.
    ///
    /// The averaged advance starts and ends at the orbit's lower turning point: there the
    /// oscillating parts of the rotor's impulse and of the damping's energy loss vanish, and the
    /// phase's (the damping's first-order pull along the orbit) is the same at both ends. The
    /// onion is first resolved to that point (classical RK4 at 1/128 of a period); the averaged
    /// equations are integrated by Dormand-Prince 5(4), each step's error within a tenth of the
    /// tolerance on the rotor and on the onion's place (through the energy and the phase, at
    /// the orbit's width); the advance ends at the last whole orbit before `segment_end`, or
    /// earlier once the ringing is within the relaxed onion's slack (the branch then takes over,
    /// see [`Self::relaxed_onion`]). The onion is put back at its turning point, and the rest of
    /// the segment (less than an orbit) is left to the resolved substeps. `None` (and `run`
    /// untouched) where it does not apply.
    pub(super) fn advance_orbits(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
    ) -> Option<OrbitAdvance> {
        // At most half the budget left: the resolved substeps still end the step.
        let spent = run.attempts.saturating_add(run.extra_cost);
        let allowance = self.params.max_substeps.saturating_sub(spent) / 2;
        if allowance < MARCH_STEPS + 4 + 4 * AVERAGED_STEP_WEIGHT {
            return None;
        }
        let max_steps = (allowance - MARCH_STEPS - 4) / AVERAGED_STEP_WEIGHT;
        let (well, o) = self.averageable(&run.y, d, segment_end - run.t)?;
        let (y, marched, resolved) = self.march_to_turning_point(&run.y, d, &well, o.period)?;
        let start = run.t + marched;
        let (well, o) = self.averageable(&y, d, segment_end - start)?;
        let land = self.landscape(y[0], d.direction, d.stress);
        let overdamped = !d.locked && self.overdamped(o.period);
        let omega = self.rotor_speed(&y, d, overdamped);
        let tilt = y[3] - self.tilt_centre(&land, &well, omega);
        let (phase, impulse, damped) = self.phase_on_orbit(&land, &well, &o, y[2], tilt);
        // Within a rounding of the turning point: the phase within [-1/2, 1/2).
        let phase = phase - phase.round();
        // (An overdamped rotor's speed is not a variable; its angle's oscillating part
        // `P~ / c` vanishes with `P~` at the turning point.)
        let speed = if overdamped {
            0.0
        } else {
            omega - impulse / self.inertia
        };
        let mut s: Slow = [y[0], speed, o.energy - damped, phase];
        let mut avg = Averager {
            m: self,
            d,
            well,
            orbit: o,
            evaluations: 0,
            overdamped,
        };
        let mut k1 = avg.rate(&s)?;
        let tol = self.params.tolerance;
        let speed_scale = tol * self.speed_scale;
        let slack = self.relaxed_slack();
        // A first step of a tenth of the energy's decay time.
        let mut h = (0.1 * s[2] / k1[2].abs()).min(segment_end - start);
        let mut time = start;
        let mut steps = 0u32;
        // The accepted steps' starts: the last whole orbit is found from one of them.
        let mut history: Vec<(f64, Slow, Slow)> = Vec::new();
        while time < segment_end && steps < max_steps {
            let h_try = h.min(segment_end - time);
            steps += 1;
            let Some((next, k7, err)) = dormand_prince(&mut avg, &s, &k1, h_try, |next, width| {
                [
                    0.1 * tol,
                    0.1 * speed_scale,
                    0.1 * tol * 2.0 * next[2].abs() / width,
                    0.1 * tol / (2.0 * PI * width),
                ]
            }) else {
                h = 0.25 * h_try;
                if h < 4.0 * o.period {
                    break;
                }
                continue;
            };
            if err <= 1.0 {
                history.push((time, s, k1));
                time = if segment_end - (time + h_try) < 1e-15 * segment_end {
                    segment_end
                } else {
                    time + h_try
                };
                s = next;
                k1 = k7;
                if self.onion_relaxes_fast() && avg.orbit.half_width() <= slack {
                    break;
                }
            }
            h = h_try * (0.9 * err.powf(-0.2)).clamp(0.2, 5.0);
            // Where the first steps cannot reach beyond a few orbits the averaging gains nothing
            // over resolving them.
            if steps < 8 && h < 2.0 * avg.orbit.period && time < segment_end {
                break;
            }
        }
        // Back to the last lower turning point: the step from the last accepted start before it
        // that ends there, by the secant method on its length.
        let whole = s[3].floor();
        let (t0, s0, k0) = *history.iter().rev().find(|(_, z, _)| z[3] <= whole)?;
        let mut length = (whole - s0[3]) / k0[3];
        for _ in 0..4 {
            let (z, _, _) = dormand_prince(&mut avg, &s0, &k0, length, |_, _| [1.0; 4])?;
            let miss = whole - z[3];
            s = z;
            if miss.abs() <= 1e-12 {
                break;
            }
            length += miss / k0[3];
        }
        let time = t0 + length;
        if !(time > run.t && time <= segment_end) {
            return None;
        }
        // The onion back at its lower turning point.
        let land = self.landscape(s[0], d.direction, d.stress);
        let (well, o) = avg.orbit_at(&s)?;
        let omega = if overdamped {
            self.rotor_speed(&[s[0], 0.0, o.below, 0.0], d, true)
        } else if d.locked {
            0.0
        } else {
            s[1]
        };
        run.y = [s[0], omega, o.below, self.tilt_centre(&land, &well, omega)];
        run.t = time;
        run.angles = None;
        run.settled = false;
        Some(OrbitAdvance {
            steps,
            evaluations: avg.evaluations,
            resolved,
        })
    }

    /// Whether a free rotor is taken as overdamped over orbits of `period` (see [`OVERDAMPED`]).
    fn overdamped(&self, period: f64) -> bool {
        self.inertia <= OVERDAMPED * self.drag * period
    }

    /// The rotor's speed at `y`: its own, or an overdamped rotor's `(tau + load) / c`, or 0
    /// locked.
    fn rotor_speed(&self, y: &Vector, d: &Drive, overdamped: bool) -> f64 {
        if d.locked {
            0.0
        } else if overdamped {
            let land = self.landscape(y[0], d.direction, d.stress);
            (point(&land, y[2]).2 + d.load) / self.drag
        } else {
            y[1]
        }
    }

    /// Ringing narrower than this (rad) is within the relaxed onion's slack (see
    /// [`Self::relaxed_onion`]): the averaged advance stops there and the branch takes over.
    fn relaxed_slack(&self) -> f64 {
        let tol = self.params.tolerance;
        0.5 * (0.1 * tol * self.rotor_relaxation_time() / self.onion_relaxation_time()).min(1e-3)
    }

    /// The well and orbit of the onion at `y` when the averaged advance applies to it with
    /// `remaining` time (s) left in its segment (see [`Self::advance_orbits`]).
    fn averageable(&self, y: &Vector, d: &Drive, remaining: f64) -> Option<(Well, Orbit)> {
        let land = self.landscape(y[0], d.direction, d.stress);
        let t = self.tilt_stiffness;
        // First from the linearization at the minimum (no search for the rims): its period
        // `2 pi / (g sqrt(k T))` and energy loss per orbit `g alpha (k + T) P` (the orbit's are
        // within a factor of two of them in the wells met), against the checks below.
        let k = land.curvature(land.settle(y[2]));
        let period = 2.0 * PI / (self.llg_rate * (k * t).sqrt());
        let loss = self.llg_rate * self.params.gilbert_damping * (k + t) * period;
        let stiff = !d.locked
            && self.inertia < self.drag * period
            && self.inertia > 2.0 * OVERDAMPED * self.drag * period;
        if !(loss <= 2.0 * MAX_LOSS_PER_ORBIT && remaining >= 0.5 * MIN_ORBITS * period) || stiff {
            return None;
        }
        let well = self.onion_well(&land, y[2])?;
        let omega = self.rotor_speed(y, d, self.overdamped(period));
        // The tilt about the orbit's centre.
        let tilt = y[3] - self.tilt_centre(&land, &well, omega);
        let e = point(&land, y[2]).0 - well.floor + 0.5 * t * tilt * tilt;
        if !(well.below < y[2] && y[2] < well.above && e <= RIM_MARGIN * well.barrier) {
            return None;
        }
        let guess = (well.minimum - 1e-3, well.minimum + 1e-3);
        let o = self.orbit(&land, &well, e, guess)?;
        let alpha = self.params.gilbert_damping;
        let loss = -o.damping_rate(alpha) * o.period / e;
        if !(loss <= MAX_LOSS_PER_ORBIT && remaining >= MIN_ORBITS * o.period) {
            return None;
        }
        let tol = self.params.tolerance;
        // The rotor angle's oscillating part, left out: its fundamental's amplitude
        // `max |tau - <tau>| P^2 / (4 pi^2 I)` (the torque's harmonics add less).
        let wobble = o.swing * o.period * o.period / (4.0 * PI * PI * self.inertia);
        // A free rotor whose speed relaxes within a few orbits holds the explicit steps to a few
        // orbits (Dormand-Prince's stability reaches 3.3 relaxation times), unless it is
        // overdamped: then its angle oscillates by `max |tau - <tau>| P / (2 pi c)` with the
        // precession, and lags its drag-limited turn by `I / c` times its speed's change,
        // `2 max |tau - <tau>| / c` at most, both held within a tenth of the tolerance.
        let c = self.drag;
        let overdamped = self.overdamped(o.period)
            && o.swing * o.period / (2.0 * PI * c) <= 0.1 * tol
            && self.inertia / c * 2.0 * o.swing / c <= 0.1 * tol;
        let stiff = self.inertia < 2.0 * self.drag * o.period;
        if !(d.locked || overdamped || (wobble <= 0.1 * tol && !stiff)) {
            return None;
        }
        // The phase's drift: the damped orbit's frequency is that of the averaged equations
        // within the linearization's shift `alpha^2 (T - k)^2 / (8 k T)` (measured: 0.6 of it at
        // 0.3 of the rim, exact near the minimum). Over `N` orbits it misplaces the onion at the
        // advance's end by `2 pi N` times that shift times the tilt's amplitude
        // `A sqrt(k / T)` there, `A` the ringing's width then (decaying by `e^(-loss N / 2)`, to
        // the relaxed onion's slack at most).
        let k = well.curvature;
        let shift = alpha * alpha * (t - k) * (t - k) / (8.0 * k * t);
        let width = o.half_width();
        let mut orbits = remaining / o.period;
        let slack = self.relaxed_slack();
        if self.onion_relaxes_fast() && slack < width {
            orbits = orbits.min(2.0 * (width / slack).ln() / loss);
        }
        let end_width = width * (-0.5 * loss * orbits).exp();
        let drift = 2.0 * PI * shift * orbits * end_width * (k / t).sqrt();
        (drift <= tol).then_some((well, o))
    }

    /// The full macrospin and rotor from `y` to the onion's next lower turning point (its tilt
    /// through zero from above, below the minimum), by classical RK4 at 1/128 of the orbit's
    /// `period`, the crossing refined by Newton steps in time: the state there, the time taken
    /// and the RK4 steps. `None` if it is not met within two periods.
    fn march_to_turning_point(
        &self,
        y: &Vector,
        d: &Drive,
        well: &Well,
        period: f64,
    ) -> Option<(Vector, f64, u32)> {
        let h = period / 128.0;
        let overdamped = !d.locked && self.overdamped(period);
        let rate = |z: &Vector| {
            let mut f = self.rhs_jacobian(z, d, h).0;
            if d.locked {
                f[0] = 0.0;
                f[1] = 0.0;
            } else if overdamped {
                // (tau + load) / c, the speed left out.
                f[0] = z[1] + f[1] * self.inertia / self.drag;
                f[1] = 0.0;
            }
            f
        };
        let step = |z: &Vector, h: f64| {
            let k1 = rate(z);
            let k2 = rate(&std::array::from_fn(|i| z[i] + 0.5 * h * k1[i]));
            let k3 = rate(&std::array::from_fn(|i| z[i] + 0.5 * h * k2[i]));
            let k4 = rate(&std::array::from_fn(|i| z[i] + h * k3[i]));
            let out: Vector = std::array::from_fn(|i| {
                z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
            out
        };
        let below = |z: &Vector| z[2] < well.minimum;
        let (mut z, mut time) = (*y, 0.0);
        for n in 0..MARCH_STEPS {
            let next = step(&z, h);
            if z[3] > 0.0 && next[3] <= 0.0 && below(&next) {
                // The tilt's zero: Newton in time from the nearer end.
                let (mut w, mut t) = (next, time + h);
                for _ in 0..3 {
                    let dt = -w[3] / rate(&w)[3];
                    w = step(&w, dt);
                    t += dt;
                }
                return Some((w, t, n + 4));
            }
            z = next;
            time += h;
        }
        None
    }
}

/// One Dormand-Prince 5(4) step of the averaged equations from `s` (rates `k1` there) over `h`:
/// the result, the rates at it and the error against the scales `scales(result, orbit width)`.
fn dormand_prince(
    avg: &mut Averager,
    s: &Slow,
    k1: &Slow,
    h: f64,
    scales: impl Fn(&Slow, f64) -> [f64; 4],
) -> Option<(Slow, Slow, f64)> {
    let (next, k) = dormand_prince::step(s, k1, h, |z| avg.rate(z))?;
    let scale = scales(&next, avg.orbit.half_width().max(f64::MIN_POSITIVE));
    let err = (0..4)
        .map(|i| dormand_prince::error(h, &k, i).abs() / scale[i])
        .fold(0.0, f64::max);
    err.is_finite().then_some((next, k[6], err))
}
