//! The Gilbert onion's ringing after a jump of its drive: when it has relaxed onto its
//! quasi-static branch, when it is trapped in its well and can be averaged out, and how fast it
//! decays (see [`Motor::relaxed_onion`], [`Motor::averaged_ringing`]).

use super::branch_settle::Relaxed;
use super::settle_memo::SettleMemo;
use super::{Drive, Motor, Vector};

impl Motor {
    /// Whether the Gilbert onion at `y` has relaxed onto its quasi-static branch, with the speed
    /// kick (rad/s) that its averaged ringing gives the rotor and the minimum it settles into
    /// ([`Relaxed`]): either its tilt and its distance to the minimum of eq. 3.4 it would settle
    /// into are within `tolerance` plus the larger of its lag behind a turning rotor and the
    /// ringing that no longer matters, and below [`MAX_FOLLOWED_LAG`] (no kick), or its ringing is
    /// trapped about that minimum and averages out ([`Self::averaged_ringing`]). A locked rotor's
    /// onion is held to the tolerance instead ([`Self::locked_ringing_ends`]): its angle is the
    /// output that the ringing moves.
    ///
    /// Ringing of amplitude `A` left undecayed turns the rotor by at most `A tau_o / tau_rotor`
    /// (its torque acts over about `tau_o`, the rotor answers over `tau_rotor`; the precession's
    /// alternating sign makes it less still), so ringing below `tolerance tau_rotor / (10 tau_o)`
    /// (7.6e-4 rad for Table 3.1) is dropped: the rotor moves by a tenth of the tolerance at most.
    ///
    /// The onion relaxes in `tau_o` ([`Self::onion_relaxation_time`], ~0.4 ns), ~1e4 times faster
    /// than the rotor (~3 us), so once the ringing after a jump of its drive has decayed it lies
    /// on the slow manifold: in the minimum, behind it by its lag `tau_o |psi'|` (the tilt is
    /// smaller, `alpha tau_o |psi'| / 2`), with `|psi'|` a few times the rotor's speed along its
    /// branch. Following the branch drops that lag: the rotor's path is then the quasi-static one,
    /// ahead of the Gilbert one by about `tau_o` in time, i.e. by up to `tau_o |omega|` in angle
    /// while it turns (2e-5 rad at the default schedule's peak 5e4 rad/s) and by nothing once it
    /// has settled. A rotor that turns so fast that the lag exceeds [`MAX_FOLLOWED_LAG`], or an
    /// onion that relaxes slower than a tenth of the rotor, is integrated in full. A fold met on
    /// the branch is taken by the quasi-static memory rule (downhill to the nearest minimum).
    /// The averaged ringing is tried when `rim_barrier` is given, the lowest rim found in this
    /// segment (see [`Self::trapped_ringing`]); `remaining` is the time left in the segment (s).
    ///
    /// The onion must also have relaxed in fact, whichever way it is placed and whether the rotor
    /// is free or locked: `switches` holds the time to the schedule's next switch and its period
    /// (s; both infinite without one), and the gap that placing the onion drops, decayed to that
    /// switch and summed over the switches the onion remembers, must be within a tenth of the
    /// tolerance beyond the lag ([`Self::ringing_ends_in`]; a locked rotor has none). Being near
    /// a minimum is not enough, nor is ending the segment within the tolerance of it: an onion
    /// that relaxes slowly against the switches passes within the tolerance of some minimum
    /// every few of them, and each placement would move it there, the same way each time (and
    /// repeated periods or cycles repeat that shift).
    pub(super) fn relaxed_onion(
        &self,
        y: &Vector,
        d: &Drive,
        rim_barrier: Option<&mut Rims>,
        remaining: f64,
        switches: (f64, f64),
        memo: &SettleMemo,
    ) -> Option<Relaxed> {
        // Without the averaged ringing only the first test can pass, and its slack is at most
        // the tolerance plus MAX_FOLLOWED_LAG: a larger tilt fails it before the settle (a
        // locked onion's, which may still decay within its segment, waits for the averaged
        // ringing's check).
        let small_tilt = y[3].abs() <= self.params.tolerance + MAX_FOLLOWED_LAG;
        if rim_barrier.is_none() && !small_tilt {
            return None;
        }
        let tol = self.params.tolerance;
        let lag_time = self.onion_relaxation_time();
        let lag = (4.0 * lag_time * y[1].abs()).min(MAX_FOLLOWED_LAG);
        // A free rotor's onion without the averaged ringing passes only the slack test below,
        // which a minimum provably beyond the slack fails without the settle's march.
        let slack = || {
            let ringing = 0.1 * tol * self.rotor_relaxation_time() / lag_time;
            tol + lag.max(ringing).min(MAX_FOLLOWED_LAG)
        };
        let land = self.landscape(y[0], d.direction, d.stress);
        // Every onion placed here passes the switch test below: its tilt alone, or its slope
        // (the settle's first evaluation), may fail it before the settle's march.
        if self.ringing_outlasts_switches(&land, y, switches, 0.1 * tol + lag) {
            return None;
        }
        let minimum = if !d.locked && rim_barrier.is_none() {
            if !self.onion_relaxes_fast() || y[3].abs() > slack() {
                return None;
            }
            // The same march as `self.settle`, from the angles and slope the bound evaluated
            // (or the pass's, kept in `memo`).
            let start = self.settle_start_within(y, d, slack(), memo)?;
            let slope = (&start.angles, start.gradient, start.curvature);
            if self.settle_outlasts_switches(&land, y, slope, switches, 0.1 * tol + lag) {
                return None;
            }
            memo.get_or(y, d, || {
                land.settle_from_slope(start.angles, start.gradient, start.curvature)
            })
        } else {
            let test = (switches, 0.1 * tol + lag);
            let ends = (d.locked && rim_barrier.is_none()).then_some(remaining);
            self.settled_unless_outlasting(&land, memo, (y, d), test, ends)?
        };
        let settled = minimum.onion;
        let relaxed = |kick: f64, curvature: f64| Relaxed {
            kick,
            settled: minimum,
            curvature,
        };
        // Whatever is dropped here, the onion carries over the next switch (a locked rotor's
        // speed, and so its lag, is 0). A free rotor's onion takes the cheap slack test first.
        // Made once at most, it gives the curvature at the minimum where it passes.
        let relaxed_in_fact = || {
            let (_, k) = self.settled_curvature(memo, y, d);
            self.ringing_ends_in(y, settled, k, switches, 0.1 * tol + lag)
                .then_some(k)
        };
        let k = if d.locked {
            let k = relaxed_in_fact()?;
            // The onion's angle is the output and nothing else is moved by its ringing: it is
            // dropped only where it ends the segment within the tolerance of the minimum.
            if self.locked_ringing_ends(y, d, settled, remaining) {
                return Some(relaxed(0.0, k));
            }
            k
        } else {
            if self.onion_relaxes_fast() {
                // Ringing of amplitude A left behind moves the rotor by at most A tau_o / tau_rotor.
                let slack = slack();
                if y[3].abs() <= slack && (settled - y[2]).abs() <= slack {
                    return relaxed_in_fact().map(|k| relaxed(0.0, k));
                }
            }
            rim_barrier.as_ref()?;
            relaxed_in_fact()?
        };
        let rims = rim_barrier?;
        if let Some(kick) = self.averaged_ringing(y, d, settled, rims, remaining) {
            return Some(relaxed(kick, k));
        }
        // A locked rotor's ringing that its orbit-averaged loss ends within the segment.
        let (retry, orbits) = (&mut rims.decay_retry_level, &mut rims.decay_orbits);
        self.locked_ringing_decays(y, d, settled, remaining, retry, orbits)
            .then(|| relaxed(0.0, k))
    }

    /// Whether the gap between the Gilbert onion at `y` and the minimum `settled` of eq. 3.4
    /// (curvature `k` there), which placing it there drops, stays within `slack` over the
    /// schedule's switches: decayed over the time to the next switch ([`Self::decayed_gap`], at the
    /// slowest rate `lambda` of the onion's linearization there), times the switches the onion
    /// remembers, `1 + 1 / (lambda T)` (`T` the period; `(to_switch, period)` both infinite without
    /// a schedule, nothing carried).
    ///
    /// What is left of the gap at a switch, the onion carries into the next period, where the
    /// minimum moves away and the resolved onion would not have dropped it. Placements at later
    /// switches shift the onion the same way, while each shift decays by `exp(-lambda T)` a
    /// period: their sum is at most the shift times the memory. On a 1 ns schedule at
    /// `lambda T = 0.04` (the onion remembers 25 switches) an onion snapped 1e-3 rad onto a
    /// minimum that the next switch moves away would end its 1 us step 1.5e-3 rad off a plain
    /// RK4 (5e4 tolerances); one within the tolerance (0.56 rad) of a minimum every few switches
    /// of a 2.2 ns schedule at `lambda T = 0.26`, 93 tolerances.
    fn ringing_ends_in(
        &self,
        y: &Vector,
        settled: f64,
        k: f64,
        (to_switch, period): (f64, f64),
        slack: f64,
    ) -> bool {
        let memory = 1.0 + 1.0 / (self.onion_decay_rate(k) * period);
        k > 0.0 && self.decayed_gap(y, settled, k, to_switch) * memory <= slack
    }

    /// Whether a locked rotor's Gilbert onion at `y` ends the `remaining` time of its segment (s)
    /// within the tolerance of the minimum `settled` it rings about, so that putting it there
    /// now moves the onion's angle at the segment's end (the step's end or the next switch) by
    /// the tolerance at most: its ringing lies in the window about the minimum where the
    /// curvature of eq. 3.4 stays within half of its value `k` ([`Self::trapped_ringing`]), its
    /// reach there `sqrt(12 E / (5 k))` (`E` its energy above the minimum, tilt included), and
    /// that reach and the tilt's `sqrt(2 E / T)` times `exp(-lambda remaining)`, `lambda` the
    /// slowest decay rate of the onion's linearization anywhere in the window, are at most the
    /// tolerance. (The free rotor's allowance, ringing that moves the rotor by a tenth of the
    /// tolerance, up to [`MAX_FOLLOWED_LAG`], would leave a 22 ns schedule's locked onion
    /// 8.5e-3 rad off an RK4 after 1 us at tolerance 1e-8.)
    pub(super) fn locked_ringing_ends(
        &self,
        y: &Vector,
        d: &Drive,
        settled: f64,
        remaining: f64,
    ) -> bool {
        let tol = self.params.tolerance;
        // The reach is at least the onion's distance from the minimum, decaying at the same
        // rate: most passes of a ringing onion fail on it, before the rest of the trap is built.
        let land = self.landscape(y[0], d.direction, d.stress);
        let k = land.curvature(settled);
        let rate = self
            .onion_decay_rate(0.5 * k)
            .min(self.onion_decay_rate(1.5 * k));
        if (settled - y[2]).abs() * (-rate * remaining).exp() > tol {
            return false;
        }
        let tilt_reach = self.tilt_reach(y, d, settled);
        self.trapped_ringing(y, d, settled, None)
            .is_some_and(|trap| {
                trap.amplitude.max(tilt_reach) * (-trap.rate * remaining).exp() <= tol
            })
    }

    /// The reach `sqrt(2 E / T)` of a locked rotor's Gilbert onion's tilt (rad), `E` its energy
    /// above the minimum `settled` of eq. 3.4, tilt included: the tilt, put to zero with the
    /// ringing, is an output as well, and its reach decays with the energy as the angle's does.
    /// Where the tilt stiffness `T` is far below the curvature (an onion that creeps back after
    /// a switch on its slow, tilt-led mode) it is the tilt itself, far beyond the angle's reach.
    fn tilt_reach(&self, y: &Vector, d: &Drive, settled: f64) -> f64 {
        let land = self.landscape(y[0], d.direction, d.stress);
        let excess =
            land.energy(y[2]) - land.energy(settled) + 0.5 * self.tilt_stiffness * y[3] * y[3];
        (2.0 * excess.max(0.0) / self.tilt_stiffness).sqrt()
    }

    /// The rotor's speed kick (rad/s) that replaces the Gilbert onion's ringing about the minimum
    /// `settled` of eq. 3.4 when that ringing is trapped in the minimum's well and, averaged out,
    /// moves the rotor by less than a tenth of the tolerance beyond that kick; `None` otherwise.
    /// The rotor then sees the ringing through its cycle average: the branch itself, plus the
    /// kick to first order in the amplitude, plus what is bounded below.
    ///
    /// Trapped: with the landscape frozen, Gilbert damping only lowers the macrospin's energy
    /// `U(psi) + T theta^2 / 2` (`dE/dt = -g alpha (U'^2 + T^2 theta^2)`), so an onion whose
    /// energy is below both rims of its well (the maxima of `U` either side) never leaves it.
    /// Near the minimum a cheaper bound does: with `k = U''(psi*)` and `M` a bound on `|U'''|`,
    /// `U(psi* + s) - U(psi*) >= k s^2/2 - M |s|^3/6 >= 5 k s^2/12` for `|s| <= w = k / (2M)`,
    /// where the curvature stays within `[k/2, 3k/2]`; an onion in that window with less energy
    /// than `5 k w^2/12` above the minimum rings within `sqrt(12 dE / (5 k))` of it. (The rotor's
    /// own motion is slow against the onion's, at least ten times, so the well moves
    /// adiabatically.)
    ///
    /// Negligible: ringing of amplitude `A` decays at least at the slowest rate `r` of the onion's
    /// linearization in the window (the damped precession's `g alpha (k + T)/2` or, overdamped,
    /// its slow creep; for ringing out to the rims, the faster of [`RIM_SLOWDOWN`] times slower
    /// and the decay that [`sublevel_gradient_bound`] guarantees). Near the
    /// minimum the ringing is the onion's linear mode `x' = J x` (`x = (psi - psi*, theta)`,
    /// `J = g [[-alpha k, -T], [k, -alpha T]]`), whose offset integrates to
    /// `(-J^-1 x0)_psi = (alpha x0_psi - theta0) / (g k (1 + alpha^2))`: times the ring-bar
    /// stiffness `k_bar` that is the impulse on the rotor, given to it as a kick of its speed
    /// (a locked rotor takes none). What is left is second order: the torque's curvature
    /// (`|tau_bar''| <= M_bar`) and the onion's own (its centre shifts by `M A^2 / k`) add at most
    /// `(M_bar + 2 |k_bar| M / k) A^2 / (4 r)` to the impulse. Out to the rims no first order
    /// is taken: the whole ringing's torque integrates to at most `k_bar A / r` there. Either
    /// bound, divided by the drag `c` (the rotor's eventual turn, with or without inertia), is
    /// held below a tenth of the tolerance, as is the rotor's turn `|omega| / r` over the decay
    /// (the onion's lag behind a turning rotor, dropped with the ringing).
    ///
    /// This replaces resolving the ringing (about `1/alpha` precession periods per decay time)
    /// once it is trapped, at the cost of the onion's outputs: it is reported at the centre of its
    /// ringing, the minimum, not at the ringing's phase.
    ///
    /// Where the ring's whole torque over the rest of the segment cannot move a free rotor, the
    /// trapped ringing is dropped at once ([`Self::decoupled_ringing`]).
    ///
    /// A locked rotor takes no impulse, so those bounds decide nothing for it: trapped ringing is
    /// dropped there only when it decays to within the tolerance of the minimum in the `remaining`
    /// time of its segment (s), at its bound on the decay rate, so that the onion meets the
    /// segment's end (the step's end or the next switch) where the resolved one does.
    pub(super) fn averaged_ringing(
        &self,
        y: &Vector,
        d: &Drive,
        settled: f64,
        rim_barrier: &mut Rims,
        remaining: f64,
    ) -> Option<f64> {
        if self.decoupled_ringing(y, d, settled, rim_barrier, remaining) {
            return Some(0.0);
        }
        let limit = 0.1 * self.params.tolerance * self.drag;
        let k_bar = self.ring_bar.stiffness(settled - y[0]);
        // The rims are looked for only where ringing anywhere in the turn, and the rotor's turn
        // over its decay, would pass.
        let turn = 2.0 * std::f64::consts::PI;
        let widest = turn * (k_bar.abs() + self.ring_bar_slope_bound * turn);
        let speed = if d.locked { 0.0 } else { y[1].abs() };
        let least_rate = if d.locked {
            0.0
        } else {
            (widest / limit).max(speed * self.drag / limit)
        };
        let trap = self.trapped_ringing(y, d, settled, Some((rim_barrier, least_rate)))?;
        if let Some((level, rims)) = trap.sublevel {
            // Out to the rims: the ringing dies out within the segment (a locked rotor: it takes
            // no impulse, so only that counts), or its whole torque moves the rotor too little.
            // (A NaN fails every bound.)
            let tol = self.params.tolerance;
            let tilt_reach = if d.locked {
                self.tilt_reach(y, d, settled)
            } else {
                0.0
            };
            let passes = |amplitude: f64, rate: f64| {
                if d.locked {
                    amplitude.max(tilt_reach) * (-rate * remaining).exp() <= tol
                } else {
                    speed * self.drag <= limit * rate
                        && amplitude * (k_bar.abs() + self.ring_bar_slope_bound * amplitude)
                            <= limit * rate
                }
            };
            if passes(trap.amplitude, trap.rate) {
                return Some(0.0);
            }
            // Else at the decay that the energy's sublevel gradient bound guarantees, sampled
            // only where it can pass: that bound is below the curvature at the minimum.
            let (g, alpha, t) = (
                self.llg_rate,
                self.params.gilbert_damping,
                self.tilt_stiffness,
            );
            let k = trap.curvature;
            let fastest = g * alpha * k.min(t);
            // Sampled again only once the energy has halved since (the bound grows as the set
            // shrinks).
            if !passes(trap.amplitude.min((2.0 * level / k).sqrt()), fastest)
                || level > 0.5 * rim_barrier.sampled_level
            {
                return None;
            }
            rim_barrier.sampled_level = level;
            let land = self.landscape(y[0], d.direction, d.stress);
            let floor = super::orbit::point(&land, settled).0;
            let kappa = sublevel_gradient_bound(&land, settled, floor, level, rims);
            let amplitude = trap.amplitude.min((2.0 * level / kappa).sqrt());
            return (kappa > 0.0 && passes(amplitude, g * alpha * kappa.min(t))).then_some(0.0);
        }
        let (amplitude, rate) = (trap.amplitude, trap.rate);
        // A locked rotor takes no impulse, so the bounds below on it decide nothing: its onion's
        // ringing is dropped only once it has decayed by the segment's end.
        if d.locked {
            let reach = amplitude.max(self.tilt_reach(y, d, settled));
            return (reach * (-rate * remaining).exp() <= self.params.tolerance).then_some(0.0);
        }
        // (A NaN fails every bound below.)
        if speed * self.drag > limit * rate {
            return None;
        }
        if trap.near {
            let (g, alpha, k) = (self.llg_rate, self.params.gilbert_damping, trap.curvature);
            let second = (self.ring_bar_slope_bound + 2.0 * k_bar.abs() * trap.slope_bound / k)
                * amplitude
                * amplitude
                / (4.0 * rate);
            if second <= limit {
                let offset = (alpha * (y[2] - settled) - y[3]) / (g * k * (1.0 + alpha * alpha));
                return Some(k_bar * offset / self.inertia);
            }
        }
        // The ring-bar stiffness anywhere the ringing reaches (its slope is bounded).
        let stiffness = k_bar.abs() + self.ring_bar_slope_bound * amplitude;
        (amplitude * stiffness <= limit * rate).then_some(0.0)
    }

    /// The Gilbert onion's ringing about `settled` when it is trapped in that minimum's well and
    /// relaxes within a tenth of the rotor's relaxation time (see [`Self::averaged_ringing`]);
    /// under a locked rotor also slower, within the window about the minimum.
    ///
    /// Out of the window about the minimum, the rims are looked for when `rims` is given, none
    /// were found yet in this segment (the search, a march over the well both ways, records
    /// them) or, for a locked rotor, they were found for another minimum, and the decay rate
    /// that the ringing out to the rims is held to ([`RIM_SLOWDOWN`] times slower than at the
    /// minimum) is at least its second value (1/s). A locked rotor's rims found for this minimum
    /// are used again (its landscape is frozen); a well that moved by less than half the window
    /// is the one found, its rims moved with it. [`Self::averaged_ringing`] may also take the
    /// rate that [`sublevel_gradient_bound`] guarantees for the ringing's energy,
    /// `g alpha min(kappa, T)` in amplitude, from within `sqrt(2 E / kappa)`.
    pub(super) fn trapped_ringing(
        &self,
        y: &Vector,
        d: &Drive,
        settled: f64,
        rims: Option<(&mut Rims, f64)>,
    ) -> Option<Trap> {
        let land = self.landscape(y[0], d.direction, d.stress);
        let k = land.curvature(settled);
        let m = land.third_derivative_bound();
        if !(k > 0.0 && k.is_finite() && m.is_finite() && m > 0.0) {
            return None;
        }
        let rate = self
            .onion_decay_rate(0.5 * k)
            .min(self.onion_decay_rate(1.5 * k));
        // A locked rotor does not answer the ringing: no separation of time scales is needed
        // about the minimum, but its rims are looked for only with one, as for a free rotor.
        let separated = rate * self.rotor_relaxation_time() >= 10.0;
        if !(rate > 0.0 && (separated || d.locked)) {
            return None;
        }
        let window = 0.5 * k / m;
        let offset = y[2] - settled;
        let excess =
            land.energy(y[2]) - land.energy(settled) + 0.5 * self.tilt_stiffness * y[3] * y[3];
        let near = (2.4 * excess.max(0.0) / k).sqrt().max(offset.abs());
        let trap = |amplitude, rate, near| Trap {
            amplitude,
            rate,
            near,
            curvature: k,
            slope_bound: m,
            sublevel: None,
        };
        if near < window {
            return Some(trap(near, rate, true));
        }
        let found = match rims {
            Some((found, least_rate)) if separated && rate >= least_rate * RIM_SLOWDOWN => found,
            _ => return None,
        };
        // A locked rotor's landscape is frozen: the well found in this segment stays the same
        // as long as the onion settles into the same minimum.
        let same_well = d.locked && (found.minimum - settled).abs() <= 1e-9;
        // A well that moved by less than half the window with a turning rotor (or settling
        // onion) is the same one: its rims are moved with its minimum, and its barrier taken
        // there, where the energy is at most the rims' own (the moved points bracket the orbit
        // all the same).
        let shift = settled - found.minimum;
        if !same_well && found.barrier.is_finite() && shift.abs() <= 0.5 * window {
            let (below, above) = (found.below + shift, found.above + shift);
            let floor = land.energy(settled);
            *found = Rims {
                barrier: land.energy(below).min(land.energy(above)) - floor,
                minimum: settled,
                below,
                above,
                ..*found
            };
        } else if !same_well {
            if found.barrier.is_finite() && !d.locked {
                return None;
            }
            let (below, above) = land.well_rims(settled, 0.5 * window);
            *found = Rims {
                barrier: land.energy(below).min(land.energy(above)) - land.energy(settled),
                minimum: settled,
                below,
                above,
                sampled_level: f64::INFINITY,
                decay_retry_level: f64::INFINITY,
                ..*found
            };
        }
        let Rims {
            barrier,
            below,
            above,
            ..
        } = *found;
        if !(below < y[2] && y[2] < above && excess < 0.99 * barrier) {
            return None;
        }
        let reach = (above - settled).max(settled - below);
        Some(Trap {
            sublevel: Some((excess, (below, above))),
            ..trap(reach, rate / RIM_SLOWDOWN, false)
        })
    }

    /// The slowest decay rate (1/s) of the Gilbert onion's linearization about a minimum of
    /// curvature `k` with the rotor held: the eigenvalues of
    /// `g [[-alpha k, -T], [k, -alpha T]]` (see [`Self::onion_relaxation_time`]), whose trace is
    /// `-g alpha (k + T)` and determinant `g^2 k T (1 + alpha^2)`. 0 without damping.
    pub(super) fn onion_decay_rate(&self, k: f64) -> f64 {
        let (g, alpha, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let trace = g * alpha * (k + t);
        let det = g * g * k * t * (1.0 + alpha * alpha);
        let discriminant = trace * trace - 4.0 * det;
        if discriminant <= 0.0 {
            0.5 * trace
        } else {
            // The smaller root, (trace - sqrt(disc)) / 2, without cancellation.
            2.0 * det / (trace + discriminant.sqrt())
        }
    }

    /// Whether the Gilbert onion relaxes within a tenth of the rotor's relaxation time (the
    /// separation of time scales that following its quasi-static branch rests on).
    pub(super) fn onion_relaxes_fast(&self) -> bool {
        self.onion_relaxation_time() <= 0.1 * self.rotor_relaxation_time()
    }
}

/// A lower bound `kappa` (J/rad^2) on `U'^2 / (2 (U - U(minimum)))` over the sublevel set
/// `U - U(minimum) <= level` of the well between `rims` of the landscape `land` (`floor` its
/// energy at the minimum): with the landscape frozen, Gilbert damping then lowers the macrospin's
/// energy `E = U - U(minimum) + T theta^2 / 2` at least at the rate
/// `dE/dt = -g alpha (U'^2 + T^2 theta^2) <= -2 g alpha min(kappa, T) E` (a Polyak-Lojasiewicz
/// inequality), and the onion stays within `sqrt(2 E / kappa)` of the minimum (the quadratic
/// growth that the inequality implies). Sampled on [`SUBLEVEL_NODES`] points out to the rim on
/// either side, the ratio at the first point beyond the level taken at the level, and halved for
/// the samples' spacing; 0 where the set reaches a rim (the gradient vanishes there).
pub(super) fn sublevel_gradient_bound(
    land: &super::onion::Landscape,
    minimum: f64,
    floor: f64,
    level: f64,
    rims: (f64, f64),
) -> f64 {
    if level.is_nan() || level <= 0.0 {
        return 0.0;
    }
    let mut least = f64::INFINITY;
    for rim in [rims.0, rims.1] {
        let mut beyond = false;
        for i in 1..=SUBLEVEL_NODES {
            let x = minimum + (rim - minimum) * i as f64 / SUBLEVEL_NODES as f64;
            let (energy, gradient, _) = super::orbit::point(land, x);
            let rise = energy - floor;
            // Within rounding of the minimum the ratio is the curvature there, sampled further out.
            if rise <= 1e-9 * level {
                continue;
            }
            least = least.min(gradient * gradient / (2.0 * rise.min(level)));
            if rise > level {
                beyond = true;
                break;
            }
        }
        if !beyond {
            return 0.0;
        }
    }
    if least.is_finite() {
        0.5 * least
    } else {
        0.0
    }
}

/// Samples per side of [`sublevel_gradient_bound`].
const SUBLEVEL_NODES: usize = 48;

/// The rims of the Gilbert onion's well found in a segment (see [`Motor::trapped_ringing`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Rims {
    /// The lowest rim's height above the minimum (J); infinite before the search.
    pub(super) barrier: f64,
    /// The minimum whose well it is, and the well's rims (rad).
    pub(super) minimum: f64,
    pub(super) below: f64,
    pub(super) above: f64,
    /// The energy above the minimum (J) at which [`sublevel_gradient_bound`] was last sampled in
    /// this segment; infinite before.
    pub(super) sampled_level: f64,
    /// The energy above the minimum (J) below which [`Motor::locked_ringing_decays`] is tried
    /// again in this segment; infinite before.
    pub(super) decay_retry_level: f64,
    /// Whether the segment ends at the step's end, no switch before it (see
    /// [`Motor::decoupled_ringing`]).
    pub(super) ends_step: bool,
    /// The orbits' quadratures [`Motor::locked_ringing_decays`] evaluated in this segment (the
    /// step charges them to its budget).
    pub(super) decay_orbits: u32,
}

impl Rims {
    pub(super) const NONE: Rims = Rims {
        barrier: f64::INFINITY,
        minimum: f64::NAN,
        below: f64::NAN,
        above: f64::NAN,
        sampled_level: f64::INFINITY,
        decay_retry_level: f64::INFINITY,
        ends_step: true,
        decay_orbits: 0,
    };
}

/// A Gilbert onion's ringing trapped in the well of a minimum (see [`Motor::averaged_ringing`]).
pub(super) struct Trap {
    /// Bound on its distance from the minimum (rad).
    pub(super) amplitude: f64,
    /// Bound below its decay rate (1/s).
    pub(super) rate: f64,
    /// Within the window about the minimum where the curvature stays within half of its value.
    pub(super) near: bool,
    /// The curvature of eq. 3.4 at the minimum (J/rad^2).
    pub(super) curvature: f64,
    /// The bound on the third derivative of eq. 3.4 (J/rad^3).
    pub(super) slope_bound: f64,
    /// Out to the rims: its energy above the minimum (J) and the rims (rad), the sublevel set
    /// of [`sublevel_gradient_bound`].
    pub(super) sublevel: Option<(f64, (f64, f64))>,
}

/// How much slower than its linearization's at the minimum ringing that reaches out to the rims of
/// its well may decay (see [`Motor::averaged_ringing`]): the curvature falls to zero on the way
/// and the orbit lingers near the rims.
pub(super) const RIM_SLOWDOWN: f64 = 100.0;

/// The largest lag of the Gilbert onion behind its branch (rad) that following the branch may
/// drop (see [`Motor::relaxed_onion`]).
pub(super) const MAX_FOLLOWED_LAG: f64 = 1e-3;

#[cfg(test)]
mod tests {
    use super::super::tests::{motor_with, rk4_step, schedule};
    use super::super::{OnionModel, Vector};
    use super::sublevel_gradient_bound;

    /// The bound on `U'^2 / (2 (U - U*))` over a sublevel set of Table 3.1's well after the
    /// schedule's first switch against the least ratio on 200,000 points of the same set: below
    /// it and within a factor of 4 of it, from a tenth of the lowest rim's height to 0.99 of
    /// it; 0 at the rim (the gradient vanishes there) and above it.
    #[test]
    fn sublevel_gradient_bound_is_below_a_dense_minimum() {
        let m = motor_with(|p| p.onion_model = OnionModel::Gilbert);
        let d = m.drive_at(&schedule(20e-6), 0.0);
        let land = m.landscape(0.0, d.direction, d.stress);
        let well = m.onion_well(&land, 0.0).unwrap();
        let floor = land.energy(well.minimum);
        let rims = (well.below, well.above);
        for fraction in [0.1, 0.5, 0.9, 0.99, 1.0, 1.5] {
            let level = fraction * well.barrier;
            let kappa = sublevel_gradient_bound(&land, well.minimum, floor, level, rims);
            // The dense minimum over the connected set about the minimum, walked out both ways.
            let mut least = f64::INFINITY;
            for rim in [well.below, well.above] {
                let n = 100_000;
                for i in 1..=n {
                    let x = well.minimum + (rim - well.minimum) * i as f64 / n as f64;
                    let rise = land.energy(x) - floor;
                    if rise > level {
                        break;
                    }
                    if rise > 1e-9 * level {
                        let g = land.gradient(x);
                        least = least.min(g * g / (2.0 * rise));
                    }
                }
            }
            println!("{fraction} of the rim: bound {kappa:e}, dense {least:e}");
            if fraction >= 1.0 {
                assert_eq!(kappa, 0.0, "{fraction}");
                continue;
            }
            assert!(
                kappa <= least && kappa >= least / 4.0,
                "{fraction}: {kappa} {least}"
            );
        }
    }

    /// With the rotor locked (the landscape frozen), Table 3.1's onion released from rest at 0.9
    /// and 0.98 of its well's lowest rim above the minimum, at dampings 1e-4 to 0.1: along a
    /// fine RK4 of the full macrospin its energy stays below `E0 exp(-2 r t)` and its distance
    /// to the minimum below `sqrt(2 E0 / kappa) exp(-r t)`, `r = g alpha min(kappa, T)` from
    /// [`sublevel_gradient_bound`]; at 0.1 it has decayed by more than half of that bound's
    /// decay over the span (the bound is not empty).
    #[test]
    fn locked_onion_decays_within_the_sublevel_bound() {
        for alpha in [1e-4, 1e-3, 1e-2, 0.1] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.gilbert_damping = alpha;
            });
            let inputs = super::super::MotorInputs {
                rotor_locked: true,
                ..schedule(20e-6)
            };
            let d = m.drive_at(&inputs, 0.0);
            let land = m.landscape(0.0, d.direction, d.stress);
            let well = m.onion_well(&land, 0.0).unwrap();
            let floor = land.energy(well.minimum);
            for fraction in [0.9, 0.98] {
                // The point below the minimum at that height.
                let (mut lo, mut hi) = (well.below, well.minimum);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if land.energy(mid) - floor > fraction * well.barrier {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let e0 = land.energy(hi) - floor;
                let kappa = sublevel_gradient_bound(
                    &land,
                    well.minimum,
                    floor,
                    e0,
                    (well.below, well.above),
                );
                assert!(kappa > 0.0, "{alpha} {fraction}");
                let rate = m.llg_rate * alpha * kappa.min(m.tilt_stiffness);
                let energy =
                    |y: &Vector| land.energy(y[2]) - floor + 0.5 * m.tilt_stiffness * y[3] * y[3];
                let (_, j) = m.rhs_jacobian(&[0.0, 0.0, hi, 0.0], &d, 1e-12);
                let h = 0.02 / (j[2][2].abs() + j[3][3].abs() + (j[2][3] * j[3][2]).abs().sqrt());
                // A few of the bound's decay times, at most 2e5 steps.
                let steps = ((3.0 / rate / h).ceil() as usize).min(200_000);
                let rate_fn = |z: &Vector| m.rhs_jacobian(z, &d, h).0;
                let mut y: Vector = [0.0, 0.0, hi, 0.0];
                let mut worst = 0.0f64;
                for n in 1..=steps {
                    y = rk4_step(&rate_fn, &y, h);
                    y[0] = 0.0;
                    y[1] = 0.0;
                    let t = n as f64 * h;
                    let bound = e0 * (-2.0 * rate * t).exp();
                    worst = worst.max(energy(&y) / bound);
                    let reach = (2.0 * e0 / kappa).sqrt() * (-rate * t).exp();
                    assert!(
                        (y[2] - well.minimum).abs() <= reach * (1.0 + 1e-9),
                        "{alpha} {fraction} t {t:e}: {} beyond {reach}",
                        y[2] - well.minimum
                    );
                }
                let span = steps as f64 * h;
                println!(
                    "damping {alpha}, {fraction} of the rim: kappa {kappa:e}, rate {rate:e} 1/s over {span:e} s: energy at most {worst} of the bound, ends at {} of E0",
                    energy(&y) / e0
                );
                assert!(worst <= 1.0 + 1e-9, "{alpha} {fraction}: {worst}");
                if alpha == 0.1 {
                    assert!(energy(&y) / e0 < (-rate * span).exp(), "{alpha} {fraction}");
                }
            }
        }
    }
}
