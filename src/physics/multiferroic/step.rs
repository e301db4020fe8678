//! One communication step of the motor: the loop that cuts it at the schedule's switches and
//! advances each piece of constant drive (see [`Motor::step`]).

use super::{Angles, Drive, Motor, MotorInputs, MotorState, StepReport, Vector, MAX_STEP};

/// Progress through one call of [`Motor::step`].
pub(super) struct StepRun {
    pub(super) y: Vector,
    pub(super) t: f64,
    pub(super) t_end: f64,
    /// Attempted substeps (accepted and rejected), settles and turn jumps.
    pub(super) attempts: u32,
    /// Budget spent beyond `attempts`: a Gilbert substep costs [`GILBERT_SUBSTEP_WEIGHT`].
    pub(super) extra_cost: u32,
    pub(super) limited: bool,
    /// Next substep size to try (s).
    pub(super) dt: f64,
    /// The segment whose settle was tried.
    pub(super) settle_tried_for: f64,
    /// The averaged spin ([`Motor::advance_spinning`]) was tried in this call
    /// and did not apply: its onion cycle (two turns of strides) is not tried again on every pass.
    pub(super) spin_failed: bool,
    /// The onion's cycle of the averaged spin for the segment ending at the given time.
    pub(super) spin_cycle: Option<(f64, super::spin::OnionCycle)>,
    /// The segment in progress: its end, strain direction, and whether it began at a switch (a
    /// whole period of the schedule).
    pub(super) segment_end: f64,
    pub(super) segment_direction: f64,
    pub(super) whole_period: bool,
    /// The state at the end of the last whole period relative to its strain direction (rotor,
    /// onion, speed) and how far it was from the one before (rad).
    pub(super) period_end: Option<[f64; 3]>,
    pub(super) period_mismatch: f64,
    /// The eq. 3.3-3.4 angles' sines and cosines at the last evaluated state, the starting point
    /// of the next evaluation's (see [`angles`](super::angles)).
    pub(super) angles: Option<Angles>,
    /// Whether `angles` are those of a quasi-static onion settled at `y` for the present drive
    /// (then the next [`Motor::constrain`] has nothing to do).
    pub(super) settled: bool,
    /// The Gilbert onion's segment (its end) over which the relaxed onion follows the
    /// quasi-static branch (see [`Motor::relaxed_onion`]).
    pub(super) following: f64,
    /// The lowest rim of the Gilbert onion's well found in the segment ending at the first value
    /// (J above its minimum, infinite before the search; see [`Motor::trapped_ringing`]).
    pub(super) rim_barrier: (f64, Rims),
    /// The attempt from which the Gilbert onion's averaged ringing is tried next.
    pub(super) average_check_at: u32,
    /// The stepping schedule switching inside this step, if any.
    pub(super) schedule: Option<super::SteppingSchedule>,
}

impl StepRun {
    pub(super) fn new(state: &MotorState, h: f64) -> Self {
        Self {
            y: [
                state.rotor_angle,
                state.rotor_speed,
                state.onion_angle,
                state.onion_tilt,
            ],
            t: state.time,
            t_end: state.time + h,
            attempts: 0,
            extra_cost: 0,
            limited: false,
            dt: if state.substep_hint > 0.0 {
                state.substep_hint
            } else {
                1e-10
            },
            settle_tried_for: f64::NAN,
            spin_failed: false,
            spin_cycle: None,
            segment_end: f64::NAN,
            segment_direction: 0.0,
            whole_period: false,
            period_end: None,
            period_mismatch: f64::INFINITY,
            angles: None,
            settled: false,
            following: f64::NAN,
            rim_barrier: (f64::NAN, Rims::NONE),
            average_check_at: 0,
            schedule: None,
        }
    }

    /// Whether the state is the settled one whose angles are kept, for the drive `d`.
    pub(super) fn is_settled(&self, d: &Drive) -> bool {
        match (&self.angles, self.settled) {
            (Some(a), true) => {
                !d.locked && a.onion == self.y[2] && a.bar == self.y[0] && a.strain == d.direction
            }
            _ => false,
        }
    }

    /// Records the segment of constant drive ending at `segment_end` if it is a new one.
    pub(super) fn enter_segment(&mut self, segment_end: f64, direction: f64) {
        if segment_end != self.segment_end {
            self.whole_period = self.t == self.segment_end;
            self.segment_end = segment_end;
            self.segment_direction = direction;
        }
    }
}

impl Motor {
    /// Advances `state` by `h` seconds with `inputs` held (the schedule, if any, switching inside
    /// the step) and returns the outputs at the end. On `Err` the state is untouched.
    ///
    /// The step is cut at every switch of the schedule (no substep ever spans one), and each
    /// piece of constant drive (a "segment") is advanced by one of:
    /// - the overdamped settle ([`Self::settle_rotor`]) when the segment is longer than 10 rotor
    ///   relaxation times and the rotor ends it within [`MAX_SETTLE_RESIDUAL`] of its
    ///   equilibrium, on the exponential tail (agrees with resolved integration within 3e-7 rad
    ///   for the default schedule), at the cost of one substep;
    /// - otherwise exponential substeps sized by the embedded (or step-doubling) error estimate
    ///   (growth and shrink at most 5x per substep). The minimum substep is `remaining time / remaining
    ///   budget`, 2^30 times less while more than half the budget is left (so that a short stiff
    ///   transient inside a step, such as the Gilbert onion's ringing after a switch, is
    ///   resolved); a substep at that minimum is accepted even if its error exceeds the tolerance
    ///   (flagged), and cannot amplify (see [`Self::rhs_jacobian`]). A substep across a snap of
    ///   the quasi-static onion to its other branch is cut at the snap (located by bisection),
    ///   since the torque jumps there and no error estimate shrinks with a substep across it;
    /// - a slipping rotor (no equilibrium ahead) advances by whole overdamped turns
    ///   ([`Self::slip_turns`], flagged);
    /// - a Gilbert onion, once relaxed after a switch, follows its quasi-static branch to the
    ///   segment's end by all of the above ([`Self::relaxed_onion`]).
    ///
    /// Each segment may use at most 1/16 of the substeps left. With the stepping schedule, once
    /// three consecutive whole periods have ended in the same state relative to the strain
    /// direction (within `tolerance / 100` and then `tolerance / 1000`), every later whole period
    /// repeats the last one turned by `step_angle` (the equations are invariant under a common
    /// rotation of rotor, onion and strain), so those periods are advanced at once. This covers
    /// periods that let the rotor settle and faster ones where it turns continuously on a
    /// periodic orbit. Where the strain holds the onion at an end of its axis and the rotor is
    /// locked or drifts (the ring cannot move it over the rest of the step), the rest of the
    /// step's periods are taken at once too ([`Self::skip_strain_held_periods`]), and so are a
    /// spinning rotor's while the onion's cycle turned with the strain is known
    /// ([`Self::advance_spinning`]). Hence what "accurate" means for a long step: the state at its end, and at
    /// every switch inside it, is the resolved trajectory's within the tolerance; the transients
    /// inside it are not reported.
    ///
    /// Costs (release): a 1 s step of a steady rotor takes one settle; a 1 s step over the
    /// 10 000 switches of the default schedule a few settles (~0.1 ms); with 25-60 us periods a
    /// few hundred to two thousand substeps (~6 ms). A step whose switches outnumber the budget
    /// and never repeat (a schedule too fast for the rotor, which loses steps) is refused.
    pub fn step(
        &self,
        state: &mut MotorState,
        inputs: &MotorInputs,
        h: f64,
    ) -> Result<StepReport, String> {
        self.validate_inputs(inputs)?;
        Self::validate_state(state)?;
        if !(h.is_finite() && h > 0.0 && h <= MAX_STEP) {
            return Err(format!(
                "communication step must be positive and at most {MAX_STEP} s, got {h}"
            ));
        }
        if !inputs.rotor_locked {
            self.check_burst_speed(state.rotor_speed, inputs.load_torque, h)?;
        }
        let budget = self.params.max_substeps;
        let mut run = StepRun::new(state, h);
        run.schedule = inputs.schedule.get().copied();
        // Built on the first pass that follows the branch: a Gilbert step whose onion never
        // relaxes does not clone the motor.
        let twin = std::cell::OnceCell::new();
        let long_segment = 10.0 * self.rotor_relaxation_time();
        // Each pass accepts a substep, counts a rejected attempt, settles a segment or jumps over
        // repeated periods; the minimum substep reaches the segment's end once the budget is
        // spent, so the cap ends the loop early only when the switches outnumber the budget.
        for _ in 0..(2 * budget as u64 + 16) {
            if run.t >= run.t_end {
                break;
            }
            if let (Some(s), true) = (inputs.schedule.get(), run.t == run.segment_end) {
                if self.skip_repeated_periods(&mut run, s) {
                    continue;
                }
            }
            let d = self.drive_at(inputs, run.t);
            let segment_end = match inputs.schedule.get() {
                Some(s) => s.next_switch_after(run.t).min(run.t_end),
                None => run.t_end,
            };
            let model = if !self.quasi_static() && self.follows_branch(&mut run, &d, segment_end) {
                twin.get_or_init(|| self.quasi_static_twin())
            } else {
                self
            };
            if !run.is_settled(&d) {
                run.angles = Some(model.constrain(&mut run.y, &d, run.angles.as_ref()));
                run.settled = model.quasi_static();
            }
            run.enter_segment(segment_end, d.direction);
            if self.skip_strain_held_periods(&mut run, &d, segment_end) {
                continue;
            }
            if model.advance_spinning(&mut run, &d, segment_end) {
                continue;
            }
            if model.quasi_static()
                && run.settle_tried_for != segment_end
                && segment_end - run.t > long_segment
            {
                run.settle_tried_for = segment_end;
                if model.advance_overdamped(&mut run, &d, segment_end) {
                    continue;
                }
            }
            model.substep(&mut run, &d, segment_end, budget);
        }
        if run.t < run.t_end {
            return Err(format!(
                "the step from t = {} s by {h} s spans more schedule switches than \
                 max_substeps = {budget} allows to resolve (the rotor cannot settle within a \
                 period of the schedule); shorten the step or raise max_substeps",
                state.time
            ));
        }
        let d = self.drive_at(inputs, run.t_end);
        if !run.is_settled(&d) {
            self.constrain(&mut run.y, &d, run.angles.as_ref());
        }
        let y = run.y;
        *state = MotorState {
            time: run.t_end,
            rotor_angle: y[0],
            rotor_speed: y[1],
            onion_angle: y[2],
            onion_tilt: y[3],
            substep_hint: run.dt.clamp(1e-300, MAX_STEP),
        };
        Ok(StepReport {
            // As [`Self::outputs`] gives them at this state, bit for bit (a restored state's
            // outputs are recomputed so).
            outputs: self.outputs_of(state, &d),
            substeps: run.attempts,
            accuracy_limited: run.limited,
        })
    }

    /// The Gilbert motor's quasi-static twin: the same motor with the onion settled, which
    /// follows a relaxed Gilbert onion (see [`Self::relaxed_onion`]).
    fn quasi_static_twin(&self) -> Motor {
        let mut twin = self.clone();
        twin.params.onion_model = super::OnionModel::QuasiStatic;
        twin
    }

    /// Whether the Gilbert onion follows its quasi-static branch for the rest of the segment
    /// ending at `segment_end`: it does from the first pass at which it is relaxed, and then
    /// starts on the branch (no tilt, the onion settled).
    ///
    /// It also does once the step is accuracy-limited (a substep was forced beyond the tolerance
    /// at the budget's minimum size), or is about to be (the budget left cannot pay for another
    /// Gilbert substep): the ringing that the budget cannot resolve is dropped, the
    /// onion settled into the minimum it rings about. Forced exponential substeps spanning several
    /// precession periods could otherwise carry a weakly damped onion into the wrong minimum (at
    /// `gilbert_damping` 1e-4 the rotor then missed its step); the rotor answers the ringing's
    /// alternating torque by at most `A tau_o / (tau_rotor sqrt(1 + (omega_p tau_o)^2))` to first
    /// order, far less than the step it would lose. The step stays flagged. (Only for an onion
    /// that relaxes at all within a tenth of the rotor's time, as in [`Self::relaxed_onion`].)
    fn follows_branch(&self, run: &mut StepRun, d: &Drive, segment_end: f64) -> bool {
        if run.following == segment_end {
            return true;
        }
        // The budget left cannot pay for another Gilbert substep: the next one would be forced
        // across the rest of the segment, where its linearization (about an onion far from its
        // minimum after a switch) can drive the rotor past its drag-limited speed. Drop the
        // ringing now instead, as once forced, and flag the step.
        let spent = run.attempts.saturating_add(run.extra_cost);
        let broke = spent.saturating_add(GILBERT_SUBSTEP_WEIGHT) > self.params.max_substeps;
        let dropped = (run.limited || broke) && self.onion_relaxes_fast();
        run.limited |= dropped;
        if !dropped {
            // The check settles the onion (a march as in a quasi-static substep): it counts as
            // one substep in the budget.
            run.extra_cost = run.extra_cost.saturating_add(1);
            if run.rim_barrier.0 != segment_end {
                run.rim_barrier = (segment_end, Rims::NONE);
            }
            // The averaging's check costs about half a Gilbert substep: it is tried at attempts
            // spaced by an eighth of those made (the ringing decays geometrically in time).
            let average = run.attempts >= run.average_check_at;
            if average {
                run.average_check_at = run.attempts + 1 + run.attempts / 8;
            }
            let rims = average.then_some(&mut run.rim_barrier.1);
            match self.relaxed_onion(&run.y, d, rims, segment_end - run.t) {
                // The averaged ringing's impulse on the rotor.
                Some(kick) => run.y[1] += kick,
                None => return false,
            }
        }
        run.following = segment_end;
        run.y[3] = 0.0;
        run.angles = None;
        run.settled = false;
        run.settle_tried_for = f64::NAN;
        true
    }

    /// Whether the Gilbert onion at `y` has relaxed onto its quasi-static branch, with the speed
    /// kick (rad/s) that its averaged ringing gives the rotor: either its tilt and its distance to
    /// the minimum of eq. 3.4 it would settle into are within `tolerance` plus the larger of its
    /// lag behind a turning rotor and the ringing that no longer matters, and below
    /// [`MAX_FOLLOWED_LAG`] (no kick), or its ringing is trapped about that minimum and averages
    /// out ([`Self::averaged_ringing`]).
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
    pub(super) fn relaxed_onion(
        &self,
        y: &Vector,
        d: &Drive,
        rim_barrier: Option<&mut Rims>,
        remaining: f64,
    ) -> Option<f64> {
        // Without the averaged ringing only the first test can pass, and its slack is at most
        // the tolerance plus MAX_FOLLOWED_LAG: a larger tilt fails it before the settle.
        let small_tilt = y[3].abs() <= self.params.tolerance + MAX_FOLLOWED_LAG;
        if rim_barrier.is_none() && !small_tilt {
            return None;
        }
        let settled = self.settle(y, d);
        if self.onion_relaxes_fast() {
            let lag_time = self.onion_relaxation_time();
            let rate = if d.locked { 0.0 } else { y[1].abs() };
            // Ringing of amplitude A left behind moves the rotor by at most A tau_o / tau_rotor.
            let ringing = 0.1 * self.params.tolerance * self.rotor_relaxation_time() / lag_time;
            let slack =
                self.params.tolerance + (4.0 * lag_time * rate).max(ringing).min(MAX_FOLLOWED_LAG);
            if y[3].abs() <= slack && (settled - y[2]).abs() <= slack {
                return Some(0.0);
            }
        }
        self.averaged_ringing(y, d, settled, rim_barrier?, remaining)
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
    /// its slow creep; [`RIM_SLOWDOWN`] times slower for ringing out to the rims). Near the
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
    /// A locked rotor feels no ringing: trapped ringing is also dropped there when it decays to
    /// within the tolerance of the minimum in the `remaining` time of its segment (s), at its
    /// bound on the decay rate, so that the onion meets the segment's end (the step's end or the
    /// next switch) where the resolved one does.
    pub(super) fn averaged_ringing(
        &self,
        y: &Vector,
        d: &Drive,
        settled: f64,
        rim_barrier: &mut Rims,
        remaining: f64,
    ) -> Option<f64> {
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
        let (amplitude, rate) = (trap.amplitude, trap.rate);
        if d.locked && amplitude * (-rate * remaining).exp() <= self.params.tolerance {
            return Some(0.0);
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
                if d.locked {
                    return Some(0.0);
                }
                let offset = (alpha * (y[2] - settled) - y[3]) / (g * k * (1.0 + alpha * alpha));
                return Some(k_bar * offset / self.inertia);
            }
        }
        // The ring-bar stiffness anywhere the ringing reaches (its slope is bounded).
        let stiffness = k_bar.abs() + self.ring_bar_slope_bound * amplitude;
        (amplitude * stiffness <= limit * rate).then_some(0.0)
    }

    /// The Gilbert onion's ringing about `settled` when it is trapped in that minimum's well and
    /// relaxes within a tenth of the rotor's relaxation time (see [`Self::averaged_ringing`]).
    ///
    /// Out of the window about the minimum, the rims are looked for when `rims` is given, none
    /// were found yet in this segment (the search, a march over the well both ways, records
    /// them) or, for a locked rotor, they were found for another minimum, and the decay rate
    /// that the ringing out to the rims is held to ([`RIM_SLOWDOWN`] times slower than at the
    /// minimum) is at least its second value (1/s). A locked rotor's rims found for this minimum
    /// are used again (its landscape is frozen).
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
        if !(rate > 0.0 && rate * self.rotor_relaxation_time() >= 10.0) {
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
        };
        if near < window {
            return Some(trap(near, rate, true));
        }
        let found = match rims {
            Some((found, least_rate)) if rate >= least_rate * RIM_SLOWDOWN => found,
            _ => return None,
        };
        // A locked rotor's landscape is frozen: the well found in this segment stays the same
        // as long as the onion settles into the same minimum.
        let same_well = d.locked && (found.minimum - settled).abs() <= 1e-9;
        if !same_well {
            if found.barrier.is_finite() && !d.locked {
                return None;
            }
            let (below, above) = land.well_rims(settled, 0.5 * window);
            *found = Rims {
                barrier: land.energy(below).min(land.energy(above)) - land.energy(settled),
                minimum: settled,
                below,
                above,
            };
        }
        let Rims {
            barrier,
            below,
            above,
            ..
        } = *found;
        (below < y[2] && y[2] < above && excess < 0.99 * barrier).then(|| {
            let reach = (above - settled).max(settled - below);
            trap(reach, rate / RIM_SLOWDOWN, false)
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
    fn onion_relaxes_fast(&self) -> bool {
        self.onion_relaxation_time() <= 0.1 * self.rotor_relaxation_time()
    }

    /// The constraints that hold at every instant: a locked rotor does not turn, and the
    /// quasi-static onion sits settled for the present drive.
    /// Returns the angles at the constrained state (turned from `hint` when close).
    pub(super) fn constrain(&self, y: &mut Vector, d: &Drive, hint: Option<&Angles>) -> Angles {
        if d.locked {
            y[1] = 0.0;
        }
        if self.quasi_static() {
            let a = self.settle_angles(y, d, hint);
            y[2] = a.onion;
            a
        } else {
            Self::angles_at(y, d, hint)
        }
    }
}

/// A Gilbert substep's share of the budget `max_substeps`, in substeps of the quasi-static onion:
/// its embedded pair ([`Motor::gilbert_embedded_step`]: one 5x5 exponential, two Jacobians, a 4x4
/// solve) costs up to 1.5 us in the steps that spend their whole budget (0.6-0.8 us for Table
/// 3.1) against 0.32 us per budget unit of the quasi-static onion's (release, x86-64, loaded
/// 2-core machine), so the budget bounds a step's cost alike in both onion models.
pub const GILBERT_SUBSTEP_WEIGHT: u32 = 4;

/// The rims of the Gilbert onion's well found in a segment (see [`Motor::trapped_ringing`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Rims {
    /// The lowest rim's height above the minimum (J); infinite before the search.
    pub(super) barrier: f64,
    /// The minimum whose well it is, and the well's rims (rad).
    pub(super) minimum: f64,
    pub(super) below: f64,
    pub(super) above: f64,
}

impl Rims {
    pub(super) const NONE: Rims = Rims {
        barrier: f64::INFINITY,
        minimum: f64::NAN,
        below: f64::NAN,
        above: f64::NAN,
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
}

/// How much slower than its linearization's at the minimum ringing that reaches out to the rims of
/// its well may decay (see [`Motor::averaged_ringing`]): the curvature falls to zero on the way
/// and the orbit lingers near the rims.
const RIM_SLOWDOWN: f64 = 100.0;

/// The largest lag of the Gilbert onion behind its branch (rad) that following the branch may
/// drop (see [`Motor::relaxed_onion`]).
const MAX_FOLLOWED_LAG: f64 = 1e-3;
