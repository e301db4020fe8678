//! The orbit-averaged advance of the Gilbert onion's weakly damped ringing
//! ([`Motor::advance_orbits`]): the orbit's energy and phase and the rotor, integrated between
//! lower turning points of the orbits that `orbit.rs` evaluates (the method is described there).

use super::onion::Landscape;
use super::orbit::{point, Orbit, Well, OVERDAMPED, RIM_MARGIN};
use super::orbit_averager::{Averager, Slow};
use super::orbit_finish::MAX_FINISH_STEPS;
use super::orbit_kept_well::KeptWell;
use super::orbit_rim_refusal::RimRefusal;
use super::step::StepRun;
use super::{Drive, Motor, Vector};
use crate::physics::numerics::dormand_prince;
use crate::physics::numerics::rk4::rk4_step;
use std::f64::consts::PI;

/// At most this fraction of the energy lost per orbit (the averaging's small parameter).
pub(super) const MAX_LOSS_PER_ORBIT: f64 = 0.05;
/// The averaged advance is tried when the segment has at least this many orbits left (fewer
/// are resolved at about the cost of the averaged advance's entry and exit).
pub(super) const MIN_ORBITS: f64 = 8.0;
/// An evaluation of the averaged equations' right-hand side (an orbit's quadrature and the
/// well's minimum, about 2 us) in the budget's units, substeps of the quasi-static onion
/// (0.32 us, see [`super::GILBERT_SUBSTEP_WEIGHT`]).
const ORBIT_EVALUATION_WEIGHT: u32 = 6;
/// A Dormand-Prince step of the averaged equations (six evaluations) in the budget's units.
const AVERAGED_STEP_WEIGHT: u32 = 6 * ORBIT_EVALUATION_WEIGHT;
/// The relative error allowed to an orbit's quadrature against [`Motor::period_floor`] (the
/// midpoint rule converges spectrally, within 1e-10 up to 0.99 of the rim; see `orbit.rs`).
const PERIOD_FLOOR_MARGIN: f64 = 1e-3;
/// The most RK4 steps of the march to the first turning point (two orbits), one unit each.
const MARCH_STEPS: u32 = 256;
/// Under a locked rotor the rest of the segment after the advance, up to this many orbits, is
/// resolved at once ([`Motor::finish_locked_orbits`]).
const FINISH_ORBITS: f64 = 1.5;

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
    /// the orbit's width, under a locked rotor at the width it keeps until `segment_end`, see
    /// [`Self::locked_fade`]); the advance ends at the last whole orbit before `segment_end`, or
    /// earlier once the ringing is within the relaxed onion's slack, or under a locked rotor
    /// where [`Self::locked_handover`] finds it ends the segment within the tolerance (the
    /// branch then takes over, see [`Self::relaxed_onion`]). The onion is put back at its
    /// turning point (a locked rotor's step flagged where the phase still misses it by enough to
    /// misplace the onion along its orbit by half the tolerance, see [`turning_slack`]), and the
    /// rest of the segment (less than an orbit) is left to the resolved substeps, or under a
    /// locked rotor resolved at once within the tolerance ([`Self::finish_locked_orbits`]).
    /// `None` (and `run` untouched) where it does not apply.
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
        let mut near_rim = None;
        let kept = &mut run.kept_well;
        let first = self.averageable(&run.y, d, segment_end - run.t, &mut near_rim, kept);
        if let Some(well) = near_rim {
            run.rim_refusal = RimRefusal::new(segment_end, run.y[0], &well, RIM_MARGIN);
        }
        let (well, o, _, _) = first?;
        let (y, marched, resolved) = self.march_to_turning_point(&run.y, d, &well, o.period)?;
        let start = run.t + marched;
        let (well, o, dropped, placed) =
            self.averageable(&y, d, segment_end - start, &mut None, &mut run.kept_well)?;
        let land = self.landscape(y[0], d.direction, d.stress);
        let overdamped = !d.locked && self.overdamped(o.period);
        let omega = self.rotor_speed(&y, d, overdamped);
        let tilt = y[3] - self.tilt_centre(&land, well.minimum, well.curvature, omega);
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
        let energy = o.energy - damped;
        // The energy's logarithm under a locked rotor, and for a free rotor's ringing dropped at
        // the advance's end (its phase untracked). A free rotor's tracked ringing keeps the
        // energy's own steps: at loose tolerances, ringing near its rims decides between wells
        // on energy differences the tolerance does not resolve, and the logarithm's steps, as
        // good by their estimate, sent a draw at `tolerance` 0.36 rad into another well, 196
        // tolerances off a plain RK4 after 1 us (7 with the energy's).
        let log_energy = d.locked || dropped;
        let energy = if log_energy { energy.ln() } else { energy };
        let mut s: Slow = [y[0], speed, energy, phase];
        let mut avg = Averager {
            m: self,
            d,
            well,
            orbit: o,
            evaluations: 0,
            overdamped,
            log_energy,
        };
        let mut k1 = avg.rate(&s)?;
        let tol = self.params.tolerance;
        let speed_scale = tol * self.speed_scale;
        let slack = self.relaxed_slack(d.locked);
        // Ringing that the branch drops once it is within the slack (see [`Self::averageable`]):
        // its phase only places the advance's end on a turning point, and its width only
        // matters against the slack.
        let (width_error, phase_error) = if dropped {
            (0.1 * tol.max(slack), 0.01)
        } else {
            (0.1 * tol, 0.1 * tol)
        };
        // A first step of a tenth of the energy's decay time.
        let first = if log_energy {
            0.1 / k1[2].abs()
        } else {
            0.1 * s[2] / k1[2].abs()
        };
        let mut h = first.min(segment_end - start);
        let mut time = start;
        let mut steps = 0u32;
        // A locked onion's averaged steps are held below half the last one whose stages left the
        // well: the landscape is frozen, so that size changes little along the advance.
        let mut ceiling = f64::INFINITY;
        // The accepted steps' starts: the last whole orbit is found from one of them.
        let mut history: Vec<(f64, Slow, Slow)> = Vec::new();
        while time < segment_end && steps < max_steps {
            let h_try = h.min(segment_end - time);
            steps += 1;
            let fade = if d.locked {
                self.locked_fade(&avg, &s, &k1, segment_end - time - h_try)
            } else {
                1.0
            };
            let Some((next, k7, err)) = dormand_prince(&mut avg, &s, &k1, h_try, |next, width| {
                let width = width * fade;
                // (The energy's relative error moves the onion by half that times the width.)
                let energy = if log_energy { 1.0 } else { next[2].abs() };
                [
                    0.1 * tol,
                    0.1 * speed_scale,
                    width_error * 2.0 * energy / width,
                    if dropped {
                        phase_error
                    } else {
                        phase_error / (2.0 * PI * width)
                    },
                ]
            }) else {
                h = 0.25 * h_try;
                if d.locked {
                    ceiling = 0.5 * h_try;
                }
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
                let handover = if d.locked {
                    self.locked_handover(&avg, &s, &k1, d, segment_end - time)
                } else {
                    self.onion_relaxes_fast() && avg.orbit.half_width() <= slack
                };
                if handover {
                    break;
                }
            }
            h = (h_try * (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)).min(ceiling);
            // Where the first steps cannot reach beyond a few orbits the averaging gains nothing
            // over resolving them.
            if steps < 8 && h < 2.0 * avg.orbit.period && time < segment_end {
                break;
            }
        }
        // Back to the last lower turning point: the step from the last accepted start before it
        // that ends there, by the secant method on its length; under a locked rotor only until
        // the phase misses it by less than the averaged steps' own errors allow
        // ([`turning_slack`]): each iteration is a step of the averaged equations (six orbit
        // quadratures), and the quadratures leave the phase's last digits noisy.
        let whole = s[3].floor();
        let (t0, s0, k0) = *history.iter().rev().find(|(_, z, _)| z[3] <= whole)?;
        let mut length = (whole - s0[3]) / k0[3];
        let mut miss = f64::INFINITY;
        for _ in 0..4 {
            let (z, _, _) = dormand_prince(&mut avg, &s0, &k0, length, |_, _| [1.0; 4])?;
            miss = whole - z[3];
            s = z;
            #[cfg(test)]
            RETURN_STEPS.with(|c| c.set(c.get() + 1));
            if miss.abs() <= 1e-12 {
                break;
            }
            length += miss / k0[3];
            if d.locked && miss.abs() <= turning_slack(&avg, dropped, phase_error) {
                break;
            }
        }
        // Where that noise keeps a locked rotor's miss beyond the slack after all four (up to
        // 6.3e-3 cycles against 1.9e-5 met), the onion put at the turning point lies up to
        // `2 pi miss` times the orbit's reach along it: beyond half the tolerance (the rest left
        // to the averaged steps and the last orbit) the step is flagged. (Ringing that is dropped
        // leaves its phase out of every output.)
        let missed = d.locked && !dropped && 2.0 * PI * miss.abs() * orbit_reach(&avg) > 0.5 * tol;
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
        run.limited |= missed;
        run.y = [
            s[0],
            omega,
            o.below,
            self.tilt_centre(&land, well.minimum, well.curvature, omega),
        ];
        run.t = time;
        run.angles = None;
        run.settled = false;
        // A locked rotor's last orbit to the segment's end, resolved within the tolerance where
        // the advance placed the onion within it.
        let mut resolved = resolved;
        if d.locked && placed && segment_end - time <= FINISH_ORBITS * o.period {
            let cap = allowance.min(MAX_FINISH_STEPS);
            let (y, steps) =
                self.finish_locked_orbits(&run.y, d, segment_end - time, o.period, cap);
            resolved = resolved.saturating_add(steps);
            if let Some(y) = y {
                run.y = y;
                run.t = segment_end;
            }
        }
        Some(OrbitAdvance {
            steps,
            evaluations: avg.evaluations,
            resolved,
        })
    }

    /// Whether a locked rotor's onion on the averaged orbit `s` (rates `rate` there), with
    /// `remaining` time (s) left in its segment, is handed over to the branch: whether
    /// [`Self::locked_ringing_ends`], the check that [`Self::relaxed_onion`] makes on it next,
    /// accepts an onion of the energy it has at the lower turning point where the advance ends.
    /// That point lies up to an orbit back (`1 / phase'`), where the energy is bounded by the
    /// present one raised by twice the present loss over an orbit, and has more time left to
    /// decay: the ringing dropped there ends the segment within the tolerance of the minimum.
    fn locked_handover(
        &self,
        avg: &Averager,
        s: &Slow,
        rate: &Slow,
        d: &Drive,
        remaining: f64,
    ) -> bool {
        let orbit = 1.0 / rate[3];
        let loss = (-avg.relative_rate(s, rate)).max(0.0) * orbit;
        let energy = avg.energy(s) * (2.0 * loss).exp();
        if !(energy.is_finite() && energy >= 0.0) {
            return false;
        }
        // The same energy, all in the tilt, at the minimum: the check sees only the energy.
        let minimum = avg.well.minimum;
        let y = [
            s[0],
            0.0,
            minimum,
            (2.0 * energy / self.tilt_stiffness).sqrt(),
        ];
        self.locked_ringing_ends(&y, d, minimum, remaining)
    }

    /// The fraction of its present width (at least) that a locked rotor's ringing on the
    /// averaged orbit `s` (rates `rate` there) keeps over the `left` time (s) to its segment's
    /// end. Its energy and phase only place the onion at that end (the landscape is frozen, the
    /// rotor takes no impulse), to within the width there times the relative error of the
    /// energy over two and the phase's error in radians, both carried along unchanged by the
    /// decay: each step's error is held to a tenth of the tolerance at that width, not at the
    /// present one. The width decays at half the energy's rate or faster (a softening well's
    /// width grows faster than `sqrt(E)`), and that rate tends to the linearization's
    /// ([`Self::onion_decay_rate`]) as the ringing decays: half the slower of the two is taken.
    fn locked_fade(&self, avg: &Averager, s: &Slow, rate: &Slow, left: f64) -> f64 {
        let own = 0.5 * (-avg.relative_rate(s, rate));
        let linear = self.onion_decay_rate(avg.well.curvature);
        let r = 0.5 * own.min(linear);
        if r.is_nan() || r <= 0.0 || left <= 0.0 {
            return 1.0;
        }
        (-r * left).exp()
    }

    /// Ringing narrower than this (rad) is within the relaxed onion's slack (see
    /// [`Self::relaxed_onion`]): the averaged advance stops there and the branch takes over.
    /// Half the tolerance under a `locked` rotor, whose onion's angle the ringing moves (there
    /// it only bounds where the advance ends, [`Self::locked_handover`] ends it).
    pub(super) fn relaxed_slack(&self, locked: bool) -> f64 {
        let tol = self.params.tolerance;
        if locked {
            return 0.5 * tol;
        }
        0.5 * (0.1 * tol * self.rotor_relaxation_time() / self.onion_relaxation_time()).min(1e-3)
    }

    /// The well and orbit of the onion at `y` when the averaged advance applies to it with
    /// `remaining` time (s) left in its segment (see [`Self::advance_orbits`]), whether its
    /// ringing is dropped at the advance's end, and whether the advance places the onion within
    /// the tolerance in angle as well as tilt (then a locked rotor's last orbit is resolved at
    /// once, [`Self::finish_locked_orbits`]). Refused for a locked rotor's onion within its
    /// well's rims above [`RIM_MARGIN`] of its barrier, `near_rim` is that well (see
    /// [`Self::rim_refusal_holds`]).
    fn averageable(
        &self,
        y: &Vector,
        d: &Drive,
        remaining: f64,
        near_rim: &mut Option<Well>,
        kept: &mut KeptWell,
    ) -> Option<(Well, Orbit, bool, bool)> {
        let land = self.landscape(y[0], d.direction, d.stress);
        let t = self.tilt_stiffness;
        // Fewer than `MIN_ORBITS` of the shortest period any orbit can have: refused below
        // without a search or a quadrature.
        if remaining < MIN_ORBITS * (1.0 - PERIOD_FLOOR_MARGIN) * self.period_floor(&land) {
            return None;
        }
        // First from the linearization at the minimum (no search for the rims): its period
        // `2 pi / (g sqrt(k T))` and energy loss per orbit `g alpha (k + T) P` (the orbit's are
        // within a factor of two of them in the wells met), against the checks below.
        let minimum = land.settle(y[2]);
        let k = land.curvature(minimum);
        let period = 2.0 * PI / (self.llg_rate * (k * t).sqrt());
        let loss = self.llg_rate * self.params.gilbert_damping * (k + t) * period;
        let stiff = !d.locked
            && self.inertia < self.drag * period
            && self.inertia > 2.0 * OVERDAMPED * self.drag * period;
        if !(loss <= 2.0 * MAX_LOSS_PER_ORBIT && remaining >= 0.5 * MIN_ORBITS * period) || stiff {
            return None;
        }
        // The energy above the minimum, the tilt taken about the orbit's centre (both set by
        // the well's minimum and its curvature there alone).
        let omega = self.rotor_speed(y, d, self.overdamped(period));
        let tilt = y[3] - self.tilt_centre(&land, minimum, k, omega);
        let e = point(&land, y[2]).0 - point(&land, minimum).0 + 0.5 * t * tilt * tilt;
        if self.above_every_barrier(&land, d, (y[2], minimum), e) {
            return None;
        }
        let well = self.kept_onion_well(kept, &land, minimum)?;
        let inside = well.below < y[2] && y[2] < well.above;
        if !(inside && e <= RIM_MARGIN * well.barrier) {
            if d.locked && inside {
                *near_rim = Some(well);
            }
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
        // The phase's drift: the averaged phase errs by at most `C` cycles over `N` orbits, `N`
        // times the linearization's shift `alpha^2 (T - k)^2 / (8 k T)` or, in eq. 3.4's
        // pendulum well, as [`Self::averaged_phase_error`] bounds it, the smaller (the shift,
        // measured within the error near the minimum for `k / T` beyond 10 only, keeps the
        // averaging where refusing it leaves the ringing to substeps whose errors add up over
        // the orbits: 55 to 1,600 tolerances over three 1 us steps). It misplaces the onion at
        // the advance's end by `2 pi C` times the tilt's amplitude `A sqrt(k / T)` there, `A`
        // the ringing's width then (decaying by `e^(-loss N / 2)`, to the relaxed onion's slack
        // at most).
        let k = well.curvature;
        let shift = alpha * alpha * (t - k) * (t - k) / (8.0 * k * t);
        let width = o.half_width();
        let mut orbits = remaining / o.period;
        let slack = self.relaxed_slack(d.locked);
        if self.onion_relaxes_fast() && slack < width {
            orbits = orbits.min(2.0 * (width / slack).ln() / loss);
        }
        let end_width = width * (-0.5 * loss * orbits).exp();
        // Ringing that decays to the relaxed onion's slack within the segment, at half its
        // slowest loss per orbit (its own or its linearization's at the minimum), ends the
        // advance there and is dropped at whatever phase it has (see [`Self::relaxed_onion`]):
        // its phase never reaches an output. (Not under an overdamped rotor: its angle, held to
        // a tenth of the tolerance, takes the averaged steps there, dozens per segment on
        // schedules of tens of nanoseconds, where resolving the ringing costs less.)
        let least_loss = loss.min(2.0 * PI * alpha * (k + t) / (k * t).sqrt());
        let dropped = self.onion_relaxes_fast()
            && (d.locked || !self.overdamped(o.period))
            && 4.0 * (width / slack).max(1.0).ln() / least_loss <= remaining / o.period;
        if dropped {
            return Some((well, o, true, false));
        }
        let linear = 2.0 * PI * shift * orbits * end_width * (k / t).sqrt();
        let drift = match self.averaged_phase_error(&land, &well, &o, orbits, least_loss) {
            Some(cycles) => (2.0 * PI * cycles * end_width * (k / t).sqrt()).min(linear),
            None => linear,
        };
        // The same misplacement along the orbit reaches the angle's amplitude `A` a quarter
        // orbit on: the onion is placed within the tolerance in both where
        // `drift max(1, sqrt(T / k))` is.
        let placed = drift * (t / k).sqrt().max(1.0) <= tol;
        (drift <= tol).then_some((well, o, false, placed))
    }

    /// A lower bound of every orbit's period in the landscape `land` (s): the frozen orbit obeys
    /// `x'' = -g^2 T q x` about the minimum (`x = psi - psi*`, `q = U'(psi) / x` the mean of `U''`
    /// over `[psi*, psi]`), and with `U'' <= K` everywhere (`K` the ring-bar stiffness's bound
    /// plus eq. 3.4's `2 |E|`) Sturm's comparison with `x'' = -g^2 T K x` puts the orbit's
    /// passes through the minimum at least `pi / (g sqrt(K T))` apart: its period is at least
    /// `2 pi / (g sqrt(K T))`.
    pub(super) fn period_floor(&self, land: &Landscape) -> f64 {
        let bound = land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs();
        2.0 * PI / (self.llg_rate * (bound * self.tilt_stiffness).sqrt())
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
        let step = |z: &Vector, h: f64| rk4_step(&rate, z, h);
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

/// The phase's miss (cycles) within which the averaged advance's end is taken as its lower
/// turning point: the onion put there is then misplaced along its orbit by at most a tenth of
/// what each averaged step may err by (`phase_error` cycles where the ringing is dropped, else a
/// displacement of `phase_error` rad at the orbit's reach, [`orbit_reach`]).
fn turning_slack(avg: &Averager, dropped: bool, phase_error: f64) -> f64 {
    if dropped {
        return 0.1 * phase_error;
    }
    0.1 * phase_error / (2.0 * PI * orbit_reach(avg))
}

/// The averaged orbit's reach (rad): the larger of its half width and its largest tilt
/// `sqrt(2 E / T)`.
fn orbit_reach(avg: &Averager) -> f64 {
    let o = &avg.orbit;
    o.half_width()
        .max((2.0 * o.energy / avg.m.tilt_stiffness).sqrt())
}

#[cfg(test)]
thread_local! {
    /// Steps of the averaged equations taken back to the advance's last turning point on this
    /// thread (for tests).
    pub(super) static RETURN_STEPS: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
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
