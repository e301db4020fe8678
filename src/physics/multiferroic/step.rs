//! One communication step of the motor: the loop that cuts it at the schedule's switches and
//! advances each piece of constant drive (see [`Motor::step`]).

use super::branch_settle::Relaxed;
use super::locked_ringing::ORBIT_WEIGHT;
use super::pass_trace::{trace_label, trace_pass};
use super::ringing::Rims;
use super::{Angles, Drive, Motor, MotorInputs, MotorState, StepReport, Vector, MAX_STEP};

/// Progress through one call of [`Motor::step`].
pub(super) struct StepRun {
    pub(super) y: Vector,
    pub(super) t: f64,
    pub(super) t_end: f64,
    /// The step's start (s).
    pub(super) start: f64,
    /// Attempted substeps (accepted and rejected), settles and turn jumps.
    pub(super) attempts: u32,
    /// Budget spent beyond `attempts`: a Gilbert substep costs [`GILBERT_SUBSTEP_WEIGHT`].
    pub(super) extra_cost: u32,
    /// The step is accuracy-limited and will be flagged (a substep forced beyond the tolerance,
    /// ringing dropped, errors amplified, an averaged return that missed its turning point);
    /// from then on the budget's drops may end the ringing at once ([`Motor::follows_branch`]).
    pub(super) limited: bool,
    /// Next substep size to try (s).
    pub(super) dt: f64,
    /// The segment whose settle was tried.
    pub(super) settle_tried_for: f64,
    /// The averaged spin ([`Motor::advance_spinning`]) was tried in this call
    /// and did not apply: its onion cycle (two turns of strides) is not tried again on every pass.
    pub(super) spin_failed: bool,
    /// The onion's cycle of the averaged spin for the segment ending at the given time.
    pub(super) spin_cycle: Option<(f64, super::cycle::OnionCycle)>,
    /// The segment in progress: its end, strain direction, and whether it began at a switch (a
    /// whole period of the schedule).
    pub(super) segment_end: f64,
    pub(super) segment_direction: f64,
    pub(super) whole_period: bool,
    /// The state at the end of the last whole period relative to its strain direction (rotor,
    /// onion, speed) and how far it was from the one before (rad).
    pub(super) period_end: Option<[f64; 3]>,
    pub(super) period_mismatch: f64,
    /// As `period_end` and `period_mismatch` for the Gilbert onion alone (offset from the strain,
    /// tilt, angle, 1 if on its branch), and whether the ring-bar torque is negligible over the step (see
    /// [`Motor::skip_onion_periods`]).
    pub(super) onion_period_end: Option<[f64; 4]>,
    pub(super) onion_period_mismatch: f64,
    pub(super) onion_decoupled: Option<bool>,
    /// The Gilbert onion's linear macro spans in this step (see [`Motor::advance_onion_linear`]).
    pub(super) onion_linear: super::onion_linear::LinearSpan,
    /// The last switch at which the Gilbert onion had relaxed (see [`Motor::skip_onion_cycles`]).
    pub(super) relaxed_switch: Option<super::onion_cycles::RelaxedSwitch>,
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
    /// The attempt from which the orbit-averaged ringing is tried next.
    pub(super) orbit_check_at: u32,
    /// The segment (its end) and the time before which the linear ringing's bound cannot hold
    /// (see [`Motor::advance_linear_ringing`]).
    pub(super) linear_wait: (f64, f64),
    /// The well in which the orbit-averaged advance last refused a locked rotor's onion too near
    /// its rim (see [`Motor::rim_refusal_holds`]).
    pub(super) rim_refusal: super::orbit_rim_refusal::RimRefusal,
    /// The wells that the orbit-averaged advance's checks found in the last landscape they
    /// searched (see [`Motor::kept_onion_well`]).
    pub(super) kept_well: super::orbit_kept_well::KeptWell,
    /// The Gilbert onion left its bounds at the smallest substep allowed, or within a substep
    /// ([`Motor::leave_bounds`]): the next pass drops its ringing however slowly it decays
    /// ([`Motor::follows_branch`]).
    pub(super) onion_escaped: bool,
    /// The time at which the Gilbert onion was last found to leave its bounds within a
    /// refused substep (see [`Motor::leave_bounds`]).
    pub(super) bounds_exit_at: f64,
    /// The stepping schedule switching inside this step, if any.
    pub(super) schedule: Option<super::SteppingSchedule>,
    /// A locked rotor's ringing onion outlasts what the budget left can resolve (see
    /// [`Motor::locked_budget_drop`]): the step is refused.
    pub(super) unresolvable: bool,
    /// The segments (their ends) over which that refusal was put off for a repeat of the
    /// onion's periods (see [`Motor::locked_budget_drop`]).
    pub(super) refusal_put_off: (f64, u32),
    /// The energy bound of a locked rotor's Gilbert onion (see [`Motor::energy_checked_error`]).
    pub(super) rim_ledger: super::rim_energy::RimLedger,
    /// The energy bound of a free rotor's Gilbert onion (see
    /// [`Motor::free_energy_checked_error`]).
    pub(super) free_ledger: super::free_energy::FreeLedger,
    /// The resolved Gilbert substeps' propagators (see [`Motor::errors_amplified`]).
    pub(super) amplification: super::amplification::Amplification,
    /// The present segment's spending (see [`Motor::budget_forecast_drops`]).
    pub(super) segment_spending: super::budget_forecast::SegmentSpending,
    /// A locked rotor's step spending (see [`Motor::locked_budget_forecast_drops`]).
    pub(super) locked_spending: super::locked_budget_forecast::LockedSpending,
    /// The minimum that the onion at the present state settles into, for the checks of its
    /// branch that each need it ([`Motor::settled_minimum`]).
    pub(super) settle_memo: super::settle_memo::SettleMemo,
    /// The decoupled onion's segments tried (see [`Motor::advance_decoupled_segment`]).
    pub(super) decoupled_tries: super::decoupled_segment::DecoupledTries,
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
            start: state.time,
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
            onion_period_end: None,
            onion_period_mismatch: f64::INFINITY,
            onion_decoupled: None,
            onion_linear: Default::default(),
            relaxed_switch: None,
            angles: None,
            settled: false,
            following: f64::NAN,
            rim_barrier: (f64::NAN, Rims::NONE),
            average_check_at: 0,
            orbit_check_at: 0,
            linear_wait: (f64::NAN, f64::NAN),
            rim_refusal: super::orbit_rim_refusal::RimRefusal::NONE,
            kept_well: super::orbit_kept_well::KeptWell::NONE,
            onion_escaped: false,
            bounds_exit_at: f64::NAN,
            schedule: None,
            unresolvable: false,
            refusal_put_off: (f64::NAN, 0),
            rim_ledger: super::rim_energy::RimLedger::NONE,
            free_ledger: super::free_energy::FreeLedger::NONE,
            amplification: Default::default(),
            segment_spending: super::budget_forecast::SegmentSpending::NONE,
            locked_spending: super::locked_budget_forecast::LockedSpending::NONE,
            settle_memo: Default::default(),
            decoupled_tries: Default::default(),
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

    /// Moves the run to the Gilbert onion's state `y` at `t`, reached by a shortcut over whole
    /// switches (one attempt): the periods compared so far and the onion's last relaxed switch
    /// no longer precede it, and its angles are evaluated afresh.
    pub(super) fn jump_onion_to(&mut self, y: Vector, t: f64, segment_end: f64) {
        self.y = y;
        self.t = t;
        self.segment_end = segment_end;
        self.period_end = None;
        self.period_mismatch = f64::INFINITY;
        self.onion_period_end = None;
        self.onion_period_mismatch = f64::INFINITY;
        self.relaxed_switch = None;
        self.angles = None;
        self.settled = false;
        self.attempts = self.attempts.saturating_add(1);
    }
}

impl Motor {
    /// Advances `state` by `h` seconds with `inputs` held (the schedule, if any, switching inside
    /// the step) and returns the outputs at the end. On `Err` the state is untouched.
    ///
    /// The step is cut at every switch of the schedule (no substep ever spans one), and each
    /// piece of constant drive (a "segment") is advanced by one of:
    /// - the overdamped settle ([`Self::settle_rotor`]) when the segment is longer than 10 rotor
    ///   relaxation times and the rotor ends it within `long_steps.rs`'s `MAX_SETTLE_RESIDUAL`
    ///   of its equilibrium, on the exponential tail (agrees with resolved integration within
    ///   3e-7 rad for the default schedule), at the cost of one substep;
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
    /// step's periods are taken at once too ([`Self::skip_strain_held_periods`]), as are whole
    /// cycles of periods between two switches at which a Gilbert onion that the ring barely
    /// moves had relaxed with the same offset from the strain ([`Self::skip_onion_cycles`]), and
    /// so are a
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
        let passes = 2 * u64::from(budget) + 16;
        let too_many_switches = || {
            format!(
                "the step from t = {} s by {h} s spans more schedule switches than \
                 max_substeps = {budget} allows to resolve (the rotor cannot settle within a \
                 period of the schedule); shorten the step or raise max_substeps",
                state.time
            )
        };
        let outnumbered = self.switches_outnumber_passes(&run, inputs, passes);
        // Each pass accepts a substep, counts a rejected attempt, settles a segment or jumps over
        // repeated periods; the minimum substep reaches the segment's end once the budget is
        // spent, so the cap ends the loop early only when the switches outnumber the budget.
        for pass in 0..passes {
            if run.t >= run.t_end {
                break;
            }
            if outnumbered && self.passes_run_out(&run, inputs, passes - pass) {
                return Err(too_many_switches());
            }
            #[cfg(test)]
            super::locked_switches::PASSES.with(|c| c.set(c.get() + 1));
            trace_pass(run.t, run.y, run.limited, run.t_end);
            if let (Some(s), true) = (inputs.schedule.get(), run.t == run.segment_end) {
                if self.skip_repeated_periods(&mut run, s)
                    || self.skip_onion_periods(&mut run, s, inputs)
                    || self.advance_onion_linear(&mut run, s, inputs)
                {
                    trace_label("periods/linear");
                    continue;
                }
            }
            let d = self.drive_at(inputs, run.t);
            let segment_end = match inputs.schedule.get() {
                Some(s) => s.next_switch_after(run.t).min(run.t_end),
                None => run.t_end,
            };
            if run.following != segment_end
                && self.advance_decoupled_segment(&mut run, &d, segment_end, budget, true)
            {
                trace_label("decoupled");
                continue;
            }
            #[cfg(test)]
            let was_following = run.following == segment_end;
            let model = if !self.quasi_static() && self.follows_branch(&mut run, &d, segment_end) {
                twin.get_or_init(|| self.quasi_static_twin())
            } else {
                self
            };
            #[cfg(test)]
            if !was_following && run.following == segment_end {
                trace_label(if run.limited { "drop" } else { "relaxed" });
            }
            if run.unresolvable {
                // A step whose switches outnumber its passes is refused for them, whichever
                // refusal comes first.
                return Err(if outnumbered {
                    too_many_switches()
                } else {
                    self.unresolvable_message(state.time, h)
                });
            }
            if !run.is_settled(&d) {
                // The branch checks may have computed these angles afresh already.
                let fresh = run.settle_memo.fresh_hint(run.angles.as_ref(), &run.y, &d);
                let hint = fresh.as_ref().or(run.angles.as_ref());
                run.angles = Some(model.constrain(&mut run.y, &d, hint));
                run.settled = model.quasi_static();
            }
            run.enter_segment(segment_end, d.direction);
            if self.skip_strain_held_periods(&mut run, &d, segment_end) {
                trace_label("strain_held");
                continue;
            }
            if model.advance_spinning(&mut run, &d, segment_end) {
                trace_label("spinning");
                continue;
            }
            if model.quasi_static()
                && run.settle_tried_for != segment_end
                && segment_end - run.t > long_segment
            {
                run.settle_tried_for = segment_end;
                if model.advance_overdamped(&mut run, &d, segment_end) {
                    trace_label("overdamped");
                    continue;
                }
            }
            if !model.quasi_static() && run.attempts >= run.orbit_check_at {
                if self.advance_linear_ringing(&mut run, &d, segment_end) {
                    trace_label("linear_ringing");
                    continue;
                }
                // Tried at attempts spaced by an eighth of those made, as the averaged ringing.
                // (Not repeated in full while a locked rotor's onion stays too near its rim.)
                let advance = if self.rim_refusal_holds(&run.rim_refusal, &run.y, &d, segment_end) {
                    None
                } else {
                    self.advance_orbits(&mut run, &d, segment_end)
                };
                run.orbit_check_at = run.attempts + 1 + run.attempts / 8;
                if let Some(a) = advance {
                    run.attempts = run.attempts.saturating_add(a.steps);
                    run.extra_cost = run.extra_cost.saturating_add(a.extra_cost());
                    trace_label("orbits");
                    continue;
                }
            }
            if model.advance_held_torque(&mut run, &d, segment_end) {
                trace_label("held_torque");
                continue;
            }
            if model.advance_decoupled_segment(&mut run, &d, segment_end, budget, false) {
                trace_label("decoupled2");
                continue;
            }
            trace_label(if model.quasi_static() {
                "branch"
            } else {
                "substep"
            });
            model.substep(&mut run, &d, segment_end, budget);
        }
        trace_pass(run.t, run.y, run.limited, run.t_end);
        if run.t < run.t_end {
            return Err(too_many_switches());
        }
        run.limited = run.limited || self.errors_amplified(&run.amplification);
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
    /// It also does once the step is accuracy-limited (a substep was forced beyond the tolerance at
    /// the budget's minimum size), or is about to be (the budget left cannot pay for another
    /// Gilbert substep, or a free rotor's persisting ringing is forecast to spend the budget's fine
    /// half within the segment, [`Self::budget_forecast_drops`], or a locked rotor's trapped one
    /// within a step without switches, [`Self::locked_budget_forecast_drops`]): the ringing that
    /// the budget cannot resolve is dropped, the onion settled into the minimum it rings about.
    /// Forced exponential substeps spanning several precession periods could otherwise carry a
    /// weakly damped onion into the wrong minimum (at `gilbert_damping` 1e-4 the rotor then missed
    /// its step); the rotor answers the ringing's alternating torque by at most `A tau_o /
    /// (tau_rotor sqrt(1 + (omega_p tau_o)^2))` to first order, far less than the step it would
    /// lose. The step stays flagged. (Only for an onion that relaxes at all within a tenth of the
    /// rotor's time, as in [`Self::relaxed_onion`], and, under a free rotor, that heads for its
    /// minimum within the step, [`Self::heads_for_minimum`], or, once forced beyond the tolerance,
    /// is trapped in its well with the ring unable to move the rotor and no switch left in the
    /// step, [`Self::decoupled_budget_drop`], unless it left its bounds; a locked rotor's as
    /// [`Self::locked_budget_drop`] says, which refuses the step where neither dropping nor forced
    /// substeps can follow the onion through the schedule's switches.) Otherwise it follows once
    /// relaxed ([`Self::relaxed_onion`]) and, under a free rotor, ends the rest of the step within
    /// the tolerance of its minimum ([`Self::ends_at_minimum`]): ringing that barely moves the
    /// rotor still places the onion.
    pub(super) fn follows_branch(&self, run: &mut StepRun, d: &Drive, segment_end: f64) -> bool {
        if run.following == segment_end {
            return true;
        }
        // The budget left cannot pay for another Gilbert substep: the next one would be forced
        // across the rest of the segment, where its linearization (about an onion far from its
        // minimum after a switch) can drive the rotor past its drag-limited speed. Drop the
        // ringing now instead, as once forced, and flag the step.
        let spent = run.attempts.saturating_add(run.extra_cost);
        let broke = spent.saturating_add(GILBERT_SUBSTEP_WEIGHT) > self.params.max_substeps;
        let out_of_budget = (run.limited
            || broke
            || self.budget_forecast_drops(run, d, segment_end)
            || self.locked_budget_forecast_drops(run, d))
            && self.onion_relaxes_fast();
        // The minimum an onion heading for it settles into, where the branch then starts.
        let mut minimum = None;
        let dropped = out_of_budget
            && (run.onion_escaped
                || if d.locked {
                    self.locked_budget_drop(run, d, segment_end)
                } else {
                    let to_switch = run
                        .schedule
                        .map_or(f64::INFINITY, |s| s.next_switch_after(run.t) - run.t);
                    let horizon = run.t_end - run.start;
                    minimum = self.heads_for_settled(&run.y, d, horizon, &run.settle_memo);
                    minimum.is_some()
                        || run.limited
                            && self.decoupled_budget_drop(
                                &run.y,
                                d,
                                (run.t_end - run.t, to_switch),
                                &run.settle_memo,
                            )
                });
        if run.unresolvable {
            return false;
        }
        run.onion_escaped = false;
        run.limited |= dropped;
        if !dropped {
            // The check settles the onion (a march as in a quasi-static substep): it counts as
            // one substep in the budget.
            run.extra_cost = run.extra_cost.saturating_add(1);
            if run.rim_barrier.0 != segment_end {
                let ends_step = segment_end >= run.t_end;
                run.rim_barrier = (
                    segment_end,
                    Rims {
                        ends_step,
                        ..Rims::NONE
                    },
                );
            }
            // The averaging's check costs about half a Gilbert substep: it is tried at attempts
            // spaced by an eighth of those made (the ringing decays geometrically in time).
            let average = run.attempts >= run.average_check_at;
            if average {
                run.average_check_at = run.attempts + 1 + run.attempts / 8;
            }
            let orbits_before = run.rim_barrier.1.decay_orbits;
            let rims = average.then_some(&mut run.rim_barrier.1);
            // Ringing that does not end the step within the tolerance of the minimum is kept,
            // whatever its effect on a free rotor: the onion itself would be off by it.
            let horizon = run.t_end - run.t;
            let decays = |r: &Relaxed| {
                d.locked || self.ends_at_minimum(&run.y, r.settled.onion, r.curvature, horizon)
            };
            // Dropped ringing carries over a switch; before it, it only shifts the reported
            // onion from the centre of its ringing, which it decays to.
            let switches = run.schedule.map_or((f64::INFINITY, f64::INFINITY), |s| {
                (s.next_switch_after(run.t) - run.t, s.step_period)
            });
            let memo = &run.settle_memo;
            let relaxed = self.relaxed_onion(&run.y, d, rims, segment_end - run.t, switches, memo);
            // The decay check's orbits are charged on top of the check's own unit.
            let orbits = run.rim_barrier.1.decay_orbits.saturating_sub(orbits_before);
            let units = orbits.saturating_mul(ORBIT_WEIGHT);
            run.extra_cost = run.extra_cost.saturating_add(units);
            #[cfg(test)]
            super::locked_ringing::DECAY_CHARGE.with(|c| {
                let (o, u) = c.get();
                c.set((o + u64::from(orbits), u + u64::from(units)));
            });
            match relaxed {
                // The averaged ringing's impulse on the rotor (the constrain settles a free
                // rotor's onion from the same angles, so the branch starts at that minimum).
                Some(r) if decays(&r) => {
                    run.y[1] += r.kick;
                    minimum = (!d.locked).then_some(r.settled);
                }
                _ => return false,
            }
        }
        run.following = segment_end;
        run.y[3] = 0.0;
        run.angles = None;
        run.settled = false;
        run.settle_tried_for = f64::NAN;
        if let Some(a) = minimum {
            // What the next constrain would settle the onion into (the same march from the
            // same angles).
            run.y[2] = a.onion;
            run.angles = Some(a);
            run.settled = true;
        }
        true
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
/// its embedded pair ([`Motor::gilbert_embedded_step`]: one 4x4 exponential, two Jacobians, a 4x4
/// solve) costs up to 1.5 us in the steps that spend their whole budget (0.6-0.8 us for Table
/// 3.1) against 0.32 us per budget unit of the quasi-static onion's (release, x86-64, loaded
/// 2-core machine), so the budget bounds a step's cost alike in both onion models.
pub const GILBERT_SUBSTEP_WEIGHT: u32 = 4;
