//! A rotor that turns many times within a step: the ring's torque averaged over the onion's
//! hysteresis cycle, with the periodic deviation from the mean motion added back (the method of
//! averaging to first order in `tau_max / |load|`, its secular drift to second order).

use super::{Drive, Motor, StepRun};
use std::f64::consts::PI;

/// The quasi-static onion's hysteresis cycle as the rotor turns without end in one direction.
#[derive(Clone)]
pub(super) struct OnionCycle {
    /// Whole turns of rotor and onion taken off the state the cycle was found from, so that its
    /// march works near zero (rad).
    turns: f64,
    onion_turns: f64,
    /// A rotor angle on the cycle and the onion angle there (rad), less `turns` and
    /// `turns + onion_turns`.
    rotor: f64,
    onion: f64,
    /// Onion turns per rotor turn (0 when the onion swings back and forth, +-1 when it follows).
    winding: f64,
    /// `int tau dphi` over one turn (J): the energy the onion's snaps dissipate, `<= 0`.
    work: f64,
    /// The ring's torque along one turn of the cycle, in the direction of motion: pairs
    /// `(s, tau_s)` with `s = dir (phi - rotor)` from 0 to 2 pi, both sides of every snap.
    torque: Vec<(f64, f64)>,
    /// The onion angle at each of those samples (rad), less the turns as `onion`.
    onion_samples: Vec<f64>,
    /// The rotor's deviation at its terminal mean speed (with drag and a positive mean force).
    terminal: Option<Wobble>,
    /// Whether the cycle is its own turn by half a turn (see [`Self::half_turn_symmetric`]),
    /// once found.
    half_turn: std::cell::Cell<Option<bool>>,
}

/// The rotor's periodic deviation from its mean motion at one mean speed, sampled where
/// [`OnionCycle::torque`] is, in the direction of motion.
#[derive(Clone)]
struct Wobble {
    /// Angle `delta(s)` (rad, zero mean over a turn) and speed `u(s)` (rad/s) deviations.
    angle: Vec<f64>,
    speed: Vec<f64>,
    /// The second-order mean force `<tau'(s) delta(s)> = -<tau(s) u(s)> / Omega` (N m).
    drift_force: f64,
    /// The mean speed (rad/s), the decay per radian `kappa` and the cycle's mean torque (N m).
    omega: f64,
    kappa: f64,
    mean: f64,
}

impl Wobble {
    fn amplitude(&self) -> f64 {
        self.angle.iter().fold(0.0, |a: f64, x| a.max(x.abs()))
    }

    /// One stride `h` (rad) of `I omega du/ds + c u = tau~(s)` for `tau~` linear over it:
    /// `u_end = e u_0 + a tau~_0 + b tau~_end`.
    fn stride(&self, h: f64, c: f64) -> (f64, f64, f64) {
        let x = self.kappa * h;
        let one_minus_e = -(-x).exp_m1();
        // 1 - (1 - e^-x) / x, by its series where it cancels.
        let ramp = if x < 1e-3 {
            x / 2.0 - x * x / 6.0 + x * x * x / 24.0
        } else {
            1.0 - one_minus_e / x
        };
        (1.0 - one_minus_e, (one_minus_e - ramp) / c, ramp / c)
    }

    /// Angle and speed deviation at phase `s`: from the sample below it, the same exact stride
    /// (so no interpolation error between samples).
    fn at(&self, cycle: &OnionCycle, s: f64, c: f64) -> (f64, f64) {
        let tau = &cycle.torque;
        let s = OnionCycle::phase(s);
        let j = tau
            .partition_point(|&(x, _)| x <= s)
            .clamp(1, tau.len() - 1)
            - 1;
        let (s0, t0) = tau[j];
        let (s1, t1) = tau[j + 1];
        let h = (s - s0).max(0.0);
        let t_s = if s1 > s0 {
            t0 + (t1 - t0) * (h / (s1 - s0)).min(1.0)
        } else {
            t1
        };
        let (e, a, b) = self.stride(h, c);
        let u = e * self.speed[j] + a * (t0 - self.mean) + b * (t_s - self.mean);
        let delta = self.angle[j] + 0.5 * h * (self.speed[j] + u) / self.omega;
        (delta, u)
    }
}

/// What [`Motor::spin`] did.
enum Spin {
    /// Not near enough its terminal speed yet: the integrator goes on.
    NotYet,
    /// The averaged spin does not apply in this step.
    Failed,
    Ended(super::Vector),
}

impl OnionCycle {
    /// Turn `s` modulo one turn.
    fn phase(s: f64) -> f64 {
        s.rem_euclid(2.0 * PI)
    }

    /// The cycle for a strain direction turned by `angle`: eq. 3.3-3.4 depend only on `psi - phi`
    /// and `psi - gamma`, so rotor and onion turn with the strain and the torque along the cycle
    /// is the same. A schedule's segments then share one march.
    fn rotate(&mut self, angle: f64) {
        let rotor = self.rotor + angle;
        let whole = (rotor / (2.0 * PI)).round() * 2.0 * PI;
        let shift = angle - whole;
        self.rotor += shift;
        self.onion += shift;
        for psi in &mut self.onion_samples {
            *psi += shift;
        }
        self.turns += whole;
    }

    /// Whether the state's onion is the cycle's at the state's rotor angle (modulo whole turns,
    /// within 1e-9 rad).
    fn holds(&self, motor: &Motor, y: &super::Vector, dir: f64, d: &Drive) -> bool {
        let s = Self::phase(dir * (y[0] - self.turns - self.rotor));
        let onion = self.onion_at(motor, s, dir, d) + self.turns + self.onion_turns;
        super::wrap_angle(onion - y[2]).abs() <= 1e-9
    }

    /// Whether the cycle turned by half a turn is itself: eq. 3.4 depends on the strain direction
    /// modulo pi, so rotor and onion turned by pi make a cycle of the same drive, the same one
    /// when the onion half a turn on is the onion turned by pi (modulo a turn; checked within
    /// 1e-9 rad at 16 samples of the first half turn). Otherwise the drive may have two cycles,
    /// and which one the onion lands on after a switch depends on where the rotor is then.
    fn half_turn_symmetric(&self, motor: &Motor, dir: f64, d: &Drive) -> bool {
        if let Some(known) = self.half_turn.get() {
            return known;
        }
        let n = self.torque.len();
        let symmetric = (0..n)
            .step_by((n / 32).max(1))
            .filter(|&j| self.torque[j].0 < PI)
            .all(|j| {
                let onion = self.onion_at(motor, self.torque[j].0 + PI, dir, d);
                super::wrap_angle(onion - self.onion_samples[j] - PI).abs() <= 1e-9
            });
        self.half_turn.set(Some(symmetric));
        symmetric
    }

    /// The onion angle on the cycle at `s` (in the direction of motion, from `rotor`) for the
    /// drive `d`: settled from the sample at or below `s`, with no snap in between.
    fn onion_at(&self, motor: &Motor, s: f64, dir: f64, d: &Drive) -> f64 {
        let j = self
            .torque
            .partition_point(|&(x, _)| x <= s)
            .clamp(1, self.torque.len())
            - 1;
        motor
            .landscape(self.rotor + dir * s, d.direction, d.stress)
            .settle(self.onion_samples[j])
    }
}

impl Motor {
    /// A rotor driven by a load torque far beyond anything the ring can exert, turning many times
    /// within the segment. The ring's torque, periodic in the rotor angle along the onion's
    /// hysteresis cycle, is then a small perturbation `epsilon = tau_max / |load|` of a uniform
    /// spin (`tau_max` a bound of eq. 3.3's torque). With `phi = theta + delta(theta)` and
    /// `omega = Omega + u(theta)` the mean angle and speed obey
    /// `I Omega' = load + <tau> + <tau' delta> - c Omega` (section 3.2.2's rotor averaged over a
    /// turn), solved exactly over the segment, where `<tau>` is the ring's mean torque over the
    /// cycle (the energy its snaps dissipate per turn over 2 pi, see [`Self::onion_cycle`]) and
    /// `<tau' delta>` the second-order drift; `u` is the periodic solution of
    /// `I Omega du/dtheta + c u = tau - <tau>` and `delta' = u / Omega` ([`Self::wobble`]).
    /// The deviation is taken off at the start and added back at the end, so the rotor angle and
    /// speed stay right at any phase. The onion ends on its cycle at the end angle.
    ///
    /// Applies (else `false`) with a quasi-static onion and a free rotor, in either of:
    /// - `epsilon <= 0.5 tolerance`, also from rest: the speed's rise through the first turns
    ///   leaves a phase error of about `epsilon` (against a fine RK4 from rest, Table 3.1:
    ///   8.5e-8, 1.9e-6 and 1.1e-5 rad at `epsilon` = 1e-7, 1e-6 and 1e-5, i.e. loads of 1e-10,
    ///   1e-11 and 1e-12 N m, where the error-controlled integrator was 0.12, 0.92 and 0.43 rad
    ///   off), and later the periodic part moves it by at most `tau_max / (I omega^2)`;
    /// - with drag, `epsilon <= MAX_SPIN_EPSILON`, the rotor already turning with the load at
    ///   least [`MIN_SPIN_TURNS`] turns within the segment, near enough its terminal speed
    ///   (the deviation's amplitude times the speed's relative distance to it below `tol / 10`),
    ///   and the third-order drift `epsilon^3` times the angle turned below `tol / 10`. Before
    ///   that (a rotor starting from rest), the error-controlled integrator resolves the few
    ///   turns of its speed's rise.
    ///
    /// On a schedule, the spin goes on through the following switches while the cycle each
    /// segment's onion follows is known and the periodic deviation's phase jumps at the switches
    /// stay within a tenth of the tolerance ([`Self::periods_ahead`]).
    ///
    /// Resolving every turn took the whole substep budget here (20,000 substeps, 11-40 ms per
    /// 1 us step for loads of 1e-14 to 1e-10 N m on Table 3.1).
    pub(super) fn advance_spinning(&self, run: &mut StepRun, d: &Drive, segment_end: f64) -> bool {
        if self.advance_drifting(run, d, segment_end) {
            return true;
        }
        let (i, c) = (self.inertia, self.drag);
        let load = d.load;
        if run.spin_failed || d.locked || !self.quasi_static() || load == 0.0 {
            return false;
        }
        let dir = load.signum();
        let tol = self.params.tolerance;
        let bound = self.torque_bound();
        let epsilon = bound / load.abs();
        let h = segment_end - run.t;
        let speed = dir * run.y[1];
        // From rest, or once the integrator has had to force a substep beyond the tolerance
        // while the rotor speeds up (the spin from there is far closer to the resolved motion:
        // see the tests), as long as the periodic part stays small against the load.
        let resolved_free = speed >= 0.0
            && (epsilon <= LOAD_DOMINATED * tol || (run.limited && epsilon <= MAX_SPIN_EPSILON));
        // Near enough its terminal speed: the deviation (at most `2 tau_max / (omega
        // sqrt(c^2 + I^2 omega^2))`) times the mean speed's relative distance to the terminal
        // one below tol / 10 (here the speed's own deviation, up to `2 epsilon`, allowed for;
        // checked precisely in `spin`); a rotor still speeding up from rest is resolved until
        // then.
        let corrected = c > 0.0
            && speed > 0.0
            && epsilon <= MAX_SPIN_EPSILON
            && h * speed >= MIN_SPIN_TURNS * 2.0 * PI
            && 2.0 * bound / (speed * c.hypot(i * speed))
                * ((1.0 - load.abs() / (c * speed)).abs() - 2.0 * epsilon).max(0.0)
                <= 0.1 * tol;
        if !(resolved_free || corrected) {
            return false;
        }
        // Within a step only the schedule's strain direction changes (the load and the stress
        // are held): the cycle marched for one segment, turned with the strain, serves the next
        // when the onion is on it (after a switch it may sit on the other branch of the
        // bistable stretch until the next fold; then the cycle is marched again from the state).
        if let Some((direction, cycle)) = &mut run.spin_cycle {
            if *direction != d.direction {
                cycle.rotate(d.direction - *direction);
                *direction = d.direction;
            }
            if !cycle.holds(self, &run.y, dir, d) {
                run.spin_cycle = None;
            }
        }
        if run.spin_cycle.is_none() {
            // The march costs at least SPIN_CYCLE_WEIGHT substeps of the budget, or is not
            // started; it is charged by its settles.
            let spent = run.attempts.saturating_add(run.extra_cost);
            if spent.saturating_add(SPIN_CYCLE_WEIGHT) > self.params.max_substeps {
                run.spin_failed = true;
                return false;
            }
            let mut settles = 0;
            let cycle = self.onion_cycle(&run.y, d, dir, &mut settles);
            run.extra_cost = run
                .extra_cost
                .saturating_add(settles.div_ceil(SETTLES_PER_SUBSTEP));
            match cycle {
                Some(cycle) => run.spin_cycle = Some((d.direction, cycle)),
                None => {
                    run.spin_failed = true;
                    return false;
                }
            }
        }
        let Some((direction, cycle)) = run.spin_cycle.take() else {
            return false;
        };
        if let Some((end, end_drive, end_cycle)) = self.periods_ahead(run, &cycle, d, segment_end) {
            let y = self.spin(
                &run.y,
                &cycle,
                (&end_cycle, &end_drive),
                d,
                end - run.t,
                !resolved_free,
            );
            if let Spin::Ended(y) = y {
                run.y = y;
                run.t = end;
                run.spin_cycle = Some((end_drive.direction, end_cycle));
                run.settled = false;
                run.attempts = run.attempts.saturating_add(1);
                return true;
            }
        }
        let spun = self.spin(&run.y, &cycle, (&cycle, d), d, h, !resolved_free);
        run.spin_cycle = Some((direction, cycle));
        match spun {
            Spin::NotYet => false,
            Spin::Failed => {
                run.spin_failed = true;
                false
            }
            Spin::Ended(y) => {
                run.y = y;
                run.t = segment_end;
                run.settled = false;
                run.attempts = run.attempts.saturating_add(1);
                true
            }
        }
    }

    /// Whole periods of the schedule after the segment ending at `segment_end` that the averaged
    /// spin takes together with it: the end of the last of them (a switch, within the step), its
    /// drive, and the cycle turned with its strain; `None` when not even one.
    ///
    /// The equations are invariant under a common rotation of rotor, onion and strain, so every
    /// segment's cycle is this one turned with the strain and has the same mean torque (its snaps
    /// dissipate the same work per turn): the mean motion goes on through the switches unchanged.
    /// The strain turns by `step_angle` at a switch, which eq. 3.4 sees modulo pi: the cycle turned
    /// by it is the one the onion follows when the cycle is its own turn by half a turn
    /// ([`OnionCycle::half_turn_symmetric`]); when the strain holds the onion at an end of its
    /// axis, the cycle turned by the onion's own turn at a switch
    /// ([`Self::strain_held_turn`]); otherwise which of two cycles it lands on may depend on the
    /// rotor's phase at each switch, and the segments are taken one by one.
    /// What a switch changes is the phase of the periodic deviation, `delta` and `u`: the mean
    /// angle and speed jump by at most twice their amplitudes `A` and `U` at the switch, which the
    /// single spin leaves out; and the onion, settled into the turned landscape, reaches the
    /// turned cycle within a turn (as the segment-by-segment spin assumes), before which the
    /// ring's torque differs from the cycle's by at most `2 tau_max` over `2 pi / omega`, an
    /// impulse of at most `J = 4 pi tau_max / omega`. The deviation's torque `tau - <tau>` is at
    /// most `2 tau_max`, so `U <= 2 tau_max min(1 / c, 2 pi / (I omega))` (the drag's filter; `u`
    /// has zero mean and `|u'| <= 4 tau_max / I`) and `A <= pi U / omega` (`delta` has zero mean
    /// and `|delta'| <= U / omega` per radian). A speed jump `du` moves the rotor by at most
    /// `I du / c` as it decays, an impulse by `J / c`; so each switch costs at most
    /// `2 A + 2 U I / c + J / c` in angle, held to a tenth of the tolerance over the switches
    /// taken, and its speed jumps, decaying by `e = exp(-c T / I)` a period `T`, leave at most
    /// `(2 U + J / I) e / (1 - e)` at the end, which, as it decays, moves the rotor by a tenth of
    /// the tolerance at most (its `I / c` times). `A`,
    /// `U` and `J` are taken at the lower of the present and the terminal mean speed (they fall
    /// as the speed rises).
    pub(super) fn periods_ahead(
        &self,
        run: &StepRun,
        cycle: &OnionCycle,
        d: &Drive,
        segment_end: f64,
    ) -> Option<(f64, Drive, OnionCycle)> {
        let s = run.schedule.as_ref()?;
        let (i, c) = (self.inertia, self.drag);
        if segment_end >= run.t_end || c <= 0.0 {
            return None;
        }
        // The segment starting at `segment_end` and the last switch within the step.
        let first = s.step_index(segment_end);
        let available = s.step_index(run.t_end) - first;
        if available < 1.0 {
            return None;
        }
        let dir = d.load.signum();
        let force = d.load.abs() + cycle.work / (2.0 * PI);
        let slowest = (dir * run.y[1]).min(force / c);
        if slowest.is_nan() || slowest <= 0.0 {
            return None;
        }
        let tau = self.torque_bound();
        let speed_amplitude = 2.0 * tau * (1.0 / c).min(2.0 * PI / (i * slowest));
        let amplitude = PI * speed_amplitude / slowest;
        let impulse = 4.0 * PI * tau / slowest;
        let kick = 2.0 * speed_amplitude + impulse / i;
        let angle = 2.0 * amplitude + kick * i / c;
        // What is left at the end of the kicks at the switches before the last period.
        let decay = (-s.step_period * c / i).exp();
        let speed = kick * decay / (1.0 - decay);
        let tol = self.params.tolerance;
        let periods = (0.1 * tol / angle).floor().min(available);
        if !(speed * i / c <= 0.1 * tol && periods >= 1.0) {
            return None;
        }
        let turn = match self.strain_held_turn(d, s.step_angle) {
            Some(turn) => turn,
            None if cycle.half_turn_symmetric(self, dir, d) => s.step_angle,
            None => return None,
        };
        let end = ((first + periods) * s.step_period).min(run.t_end);
        let applied = s.direction(end - 0.5 * s.step_period);
        let end_drive = Drive {
            direction: super::reduced_direction(applied),
            applied_direction: applied,
            ..*d
        };
        let mut turned = cycle.clone();
        turned.rotate(periods * turn);
        Some((end, end_drive, turned))
    }

    /// The turn of the onion at every switch of the schedule (`step_angle` brought within a
    /// quarter turn, modulo pi) when the strain holds it near an end of its axis whatever the
    /// rotor does; `None` otherwise. With `E sin^2(psi - gamma)` the magnetoelastic energy (eq.
    /// 3.4), `|tau| <= tau_max` the ring's torque and `k_max` its stiffness's bound, the gradient
    /// `E sin 2x + tau` (`x = psi - gamma`) has the sign of `E sin 2x` but within
    /// `w = asin(tau_max / |E|) / 2` of the axis's ends and of its midpoints, and the curvature
    /// `2 E cos 2x + k` keeps the sign of `E` near the ends and the opposite near the midpoints
    /// while `2 |E| cos 2w > k_max`: each end (the minima of `E sin^2`) holds one minimum within
    /// `w`, and no other exists. The onion sits there (two cycles, one at either end, without
    /// snaps); after a switch by `a` (within a quarter turn modulo pi) it is within `w + |a|` of an
    /// end of the new axis, so with `|a| + 2 w < pi / 2` it goes downhill to that end's minimum:
    /// the cycle turned by `a`. (`k_max = pi M` with `M` the bound of its slope: the stiffness
    /// has zero mean over a turn.)
    pub(super) fn strain_held_turn(&self, d: &Drive, step_angle: f64) -> Option<f64> {
        let w = self.strain_held_reach(d)?;
        let turn = step_angle - PI * (step_angle / PI).round();
        (turn.abs() + 2.0 * w < 0.5 * PI - 1e-6).then_some(turn)
    }

    /// How far from an end of the strain's axis the onion can be (`w`, rad) when the strain holds
    /// it there whatever the rotor does (see [`Self::strain_held_turn`]); `None` when it does not.
    fn strain_held_reach(&self, d: &Drive) -> Option<f64> {
        let e = self
            .landscape(0.0, d.direction, d.stress)
            .magnetoelastic
            .abs();
        let tau = self.torque_bound();
        if tau.is_nan() || tau >= e {
            return None;
        }
        let w = 0.5 * (tau / e).asin();
        (2.0 * e * (2.0 * w).cos() > PI * self.ring_bar_slope_bound).then_some(w)
    }

    /// The state `y` advanced by `h` on the averaged spin of `cycle`, with the periodic deviation
    /// taken off at the start (`correct_start`) and added back at the end on `end`'s cycle and
    /// drive (those of the start, or of a later segment of the schedule, see
    /// [`Self::periods_ahead`]).
    fn spin(
        &self,
        y: &super::Vector,
        cycle: &OnionCycle,
        end: (&OnionCycle, &Drive),
        d: &Drive,
        h: f64,
        correct_start: bool,
    ) -> Spin {
        let (end_cycle, end_drive) = end;
        let (i, c) = (self.inertia, self.drag);
        let dir = d.load.signum();
        let tol = self.params.tolerance;
        let speed = dir * y[1];
        // In the direction of motion, from the cycle's reference angle.
        let s_of = |phi: f64| dir * (phi - cycle.turns - cycle.rotor);
        let force = d.load.abs() + cycle.work / (2.0 * PI);
        // The mean motion at constant force over `h`: advance and end speed.
        let mean_motion = |omega0: f64, force: f64| -> (f64, f64) {
            if c > 0.0 {
                let rate = c / i;
                let terminal = force / c;
                // 1 - exp(-h c / I) without cancellation.
                let approach = -(-h * rate).exp_m1();
                (
                    terminal * h + (omega0 - terminal) * approach / rate,
                    terminal + (omega0 - terminal) * (1.0 - approach),
                )
            } else {
                (omega0 * h + 0.5 * force / i * h * h, omega0 + force / i * h)
            }
        };
        // The deviation at a mean speed this close to the terminal one is the terminal one's
        // within tol / 100 (it and its drift scale with the speed's inverse).
        let near_terminal = |omega: f64| {
            cycle.terminal.as_ref().filter(|w| {
                let relative = (1.0 - omega / w.omega).abs();
                (w.amplitude() + h * w.drift_force.abs() / c) * relative <= 0.01 * tol
            })
        };
        let (mut theta, mut speed0) = (y[0], speed);
        if correct_start {
            // The error against resolved integration (see the tests) at the speed it will spin
            // at: the second-order periodic terms left out, `amplitude (epsilon + 1e-3)`, and the
            // third-order drift, `epsilon^3` per radian turned.
            let computed;
            let terminal = match &cycle.terminal {
                Some(w) => w,
                None => {
                    computed = self.wobble(cycle, force / c);
                    &computed
                }
            };
            let amplitude = terminal.amplitude();
            let epsilon = cycle
                .torque
                .iter()
                .fold(0.0, |a: f64, t| a.max((t.1 - terminal.mean).abs()))
                / force;
            let turned = h * force / c;
            if amplitude * (epsilon + 1e-3) + epsilon.powi(3) * turned > tol {
                return Spin::Failed;
            }
            // The deviation's dependence on the mean speed, neglected while that approaches its
            // terminal value, stays below tol / 10.
            let computed;
            let start = match near_terminal(speed) {
                Some(w) => w,
                None => {
                    computed = self.wobble(cycle, speed);
                    &computed
                }
            };
            let (delta, u) = start.at(cycle, s_of(y[0]), c);
            theta -= dir * delta;
            speed0 -= u;
            if start.amplitude() * (1.0 - force / (c * speed0)).abs() > 0.1 * tol {
                return Spin::NotYet;
            }
        }
        let (mut advance, mut omega) = mean_motion(speed0, force);
        let mut end_wobble = None;
        if c > 0.0 && omega > 0.0 {
            let end = match near_terminal(omega) {
                Some(w) => std::borrow::Cow::Borrowed(w),
                None => std::borrow::Cow::Owned(self.wobble(cycle, omega)),
            };
            (advance, omega) = mean_motion(speed0, force + end.drift_force);
            end_wobble = Some(end);
        }
        theta += dir * advance;
        let (mut phi, mut omega) = (theta, dir * omega);
        let s_of_end = |phi: f64| dir * (phi - end_cycle.turns - end_cycle.rotor);
        if let Some(end) = &end_wobble {
            let (delta, u) = end.at(end_cycle, s_of_end(theta), c);
            phi += dir * delta;
            omega += dir * u;
        }
        if !(phi.is_finite() && phi.abs() <= super::MAX_ANGLE && omega.is_finite()) {
            return Spin::Failed;
        }
        // The onion on its cycle at the end angle: whole turns shift it by the winding, the rest
        // is settled from the cycle's sample below it.
        let from_cycle = phi - end_cycle.turns - end_cycle.rotor;
        let whole = (dir * from_cycle / (2.0 * PI)).floor();
        let rest = from_cycle - dir * whole * 2.0 * PI;
        let onion = end_cycle.onion_at(self, dir * rest, dir, end_drive);
        let psi = onion
            + end_cycle.turns
            + end_cycle.onion_turns
            + end_cycle.winding * dir * whole * 2.0 * PI;
        if !(psi.is_finite() && psi.abs() <= super::MAX_ANGLE) {
            return Spin::Failed;
        }
        Spin::Ended([phi, omega, psi, 0.0])
    }

    /// The periodic deviation from the mean motion at mean speed `omega` (> 0, in the direction
    /// of motion), for a drag `c > 0`: `I omega du/ds + c u = tau~(s)` with `tau~` the cycle's
    /// torque less its mean, solved exactly for `tau~` linear between samples (an exponential
    /// integrator over the phase, decay `kappa = c / (I omega)` per radian) and made periodic by
    /// `u(0) = u_1(2 pi) / (1 - exp(-2 pi kappa))` (`u_1` started from 0). `delta` integrates
    /// `u / omega` (trapezoid) less its mean.
    fn wobble(&self, cycle: &OnionCycle, omega: f64) -> Wobble {
        let (i, c) = (self.inertia, self.drag);
        let tau = &cycle.torque;
        let n = tau.len();
        let mut mean = 0.0;
        for w in tau.windows(2) {
            mean += 0.5 * (w[1].0 - w[0].0) * (w[0].1 + w[1].1);
        }
        mean /= 2.0 * PI;
        let mut wobble = Wobble {
            angle: vec![0.0; n],
            speed: vec![0.0; n],
            drift_force: 0.0,
            omega,
            kappa: c / (i * omega),
            mean,
        };
        let sweep = |w: &mut Wobble, u0: f64| {
            w.speed[0] = u0;
            for j in 1..n {
                let (e, a, b) = w.stride(tau[j].0 - tau[j - 1].0, c);
                w.speed[j] = e * w.speed[j - 1] + a * (tau[j - 1].1 - mean) + b * (tau[j].1 - mean);
            }
        };
        sweep(&mut wobble, 0.0);
        let period_decay = -(-2.0 * PI * wobble.kappa).exp_m1();
        let periodic_start = wobble.speed[n - 1] / period_decay;
        sweep(&mut wobble, periodic_start);
        let (speed, angle) = (&wobble.speed, &mut wobble.angle);
        let (mut angle_mean, mut drift) = (0.0, 0.0);
        for j in 1..n {
            let h = tau[j].0 - tau[j - 1].0;
            angle[j] = angle[j - 1] + 0.5 * h * (speed[j - 1] + speed[j]) / omega;
            angle_mean += 0.5 * h * (angle[j - 1] + angle[j]);
            drift +=
                0.5 * h * ((tau[j - 1].1 - mean) * speed[j - 1] + (tau[j].1 - mean) * speed[j]);
        }
        angle_mean /= 2.0 * PI;
        for a in angle.iter_mut() {
            *a -= angle_mean;
        }
        wobble.drift_force = -drift / (2.0 * PI * omega);
        wobble
    }

    /// An upper bound of eq. 3.3's torque on the bar (N m): `K a r (1/(r - a)^3 + 1/(r + a)^3)`.
    pub(super) fn torque_bound(&self) -> f64 {
        let rb = &self.ring_bar;
        let (a, r) = (rb.bar_charge_radius, rb.wall_radius);
        (rb.coupling * a * r * ((r - a).powi(-3) + (r + a).powi(-3))).abs()
    }

    /// The onion's cycle for a rotor turning in direction `dir` from `phi0` with the onion at
    /// `psi0`: one turn to land on it (none where the strain holds the onion), one to measure it
    /// (and sample its torque). `None` if it does not close.
    fn onion_cycle(
        &self,
        y: &super::Vector,
        d: &Drive,
        dir: f64,
        settles: &mut u32,
    ) -> Option<OnionCycle> {
        // The landscape depends on psi - phi and psi - gamma (mod pi): turn rotor and onion back
        // by whole turns so that the march works near zero (the onion by its own turns too, for
        // a state whose onion is far from its rotor).
        let turns = (y[0] / (2.0 * PI)).round() * 2.0 * PI;
        let onion_turns = ((y[2] - y[0]) / (2.0 * PI)).round() * 2.0 * PI;
        let phi0 = y[0] - turns;
        let psi0 = self
            .landscape(phi0, d.direction, d.stress)
            .settle(y[2] - turns - onion_turns);
        *settles += 1;
        // A turn to land on the cycle; none where the strain holds the onion, whose minimum then
        // follows the rotor without a snap (the cycle is where the onion is).
        let (start, psi1) = if self.strain_held_reach(d).is_some() {
            (phi0, psi0)
        } else {
            let start = phi0 + dir * 2.0 * PI;
            (
                start,
                self.march_onion(phi0, psi0, start, d, None, settles)?.0,
            )
        };
        let mut samples = Vec::with_capacity(160);
        let (psi2, work) = self.march_onion(
            start,
            psi1,
            start + dir * 2.0 * PI,
            d,
            Some(&mut samples),
            settles,
        )?;
        let winding = ((psi2 - psi1) / (2.0 * PI)).round();
        if (psi2 - psi1 - winding * 2.0 * PI).abs() > 1e-6 {
            return None;
        }
        let torque = samples
            .iter()
            .map(|&(phi, _, tau)| (dir * (phi - start), dir * tau))
            .collect();
        let onion_samples = samples.iter().map(|&(_, psi, _)| psi).collect();
        let mut cycle = OnionCycle {
            turns,
            onion_turns,
            rotor: start,
            onion: psi1,
            winding: winding * dir,
            work,
            torque,
            onion_samples,
            terminal: None,
            half_turn: std::cell::Cell::new(None),
        };
        let force = d.load.abs() + work / (2.0 * PI);
        if self.drag > 0.0 && force > 0.0 {
            cycle.terminal = Some(self.wobble(&cycle, force / self.drag));
        }
        Some(cycle)
    }

    /// The quasi-static onion while the rotor turns from `from` to `to` (its memory rule, snaps
    /// included), and the energy the snaps changed `U` by on the way (J). Strides of at most
    /// [`CYCLE_STRIDE`]; a snap is placed by bisection within [`SNAP_PLACEMENT`] rad, where its
    /// energy change is taken. `samples`, if given, receives `(phi, psi, tau)`, the ring's torque at
    /// every stride's end and on both sides of every snap.
    fn march_onion(
        &self,
        from: f64,
        psi: f64,
        to: f64,
        d: &Drive,
        mut samples: Option<&mut Vec<(f64, f64, f64)>>,
        settles: &mut u32,
    ) -> Option<(f64, f64)> {
        let count = std::cell::Cell::new(0u32);
        let settle = |at: f64, onion: f64| {
            count.set(count.get() + 1);
            self.landscape(at, d.direction, d.stress).settle(onion)
        };
        let energy = |at: f64, onion: f64| self.landscape(at, d.direction, d.stress).energy(onion);
        let mut record = |at: f64, onion: f64| {
            if let Some(s) = samples.as_deref_mut() {
                s.push((at, onion, self.ring_bar.torque_stiffness(onion - at).0));
            }
        };
        let strides = ((to - from).abs() / CYCLE_STRIDE).ceil().max(1.0);
        if strides > 1e6 {
            return None;
        }
        let (mut phi, mut psi, mut work) = (from, psi, 0.0);
        record(phi, psi);
        for k in 1..=strides as usize {
            let next = from + (to - from) * k as f64 / strides;
            let psi_next = settle(next, psi);
            if (psi_next - psi).abs() <= ONION_JUMP + 4.0 * (next - phi).abs() {
                (phi, psi) = (next, psi_next);
                record(phi, psi);
                continue;
            }
            // A snap inside the stride: bisect for it on the rotor angle.
            let (mut lo, mut psi_lo, mut hi, mut psi_hi) = (phi, psi, next, psi_next);
            for _ in 0..64 {
                if (hi - lo).abs() <= SNAP_PLACEMENT {
                    break;
                }
                let mid = 0.5 * (lo + hi);
                let psi_mid = settle(mid, psi_lo);
                if (psi_mid - psi_lo).abs() <= ONION_JUMP + 4.0 * (mid - lo).abs() {
                    (lo, psi_lo) = (mid, psi_mid);
                } else {
                    (hi, psi_hi) = (mid, psi_mid);
                }
            }
            work += energy(hi, psi_hi) - energy(lo, psi_lo);
            record(lo, psi_lo);
            record(hi, psi_hi);
            (phi, psi) = (next, settle(next, psi_hi));
            record(phi, psi);
        }
        *settles = settles.saturating_add(count.get());
        (psi.is_finite() && work.is_finite()).then_some((psi, work))
    }
}

/// The regime of [`Motor::advance_spinning`] from rest: `tau_max / |load|` at most this times the
/// tolerance.
const LOAD_DOMINATED: f64 = 0.5;
/// The corrected regime of [`Motor::advance_spinning`]: `tau_max / |load|` at most this, and at
/// least this many turns within the segment (fewer cost less resolved than the cycle's march).
const MAX_SPIN_EPSILON: f64 = 0.05;
const MIN_SPIN_TURNS: f64 = 2.0;
/// The onion's cycle ([`Motor::onion_cycle`], two turns of 126 strides with their settles, about
/// 25 us in release) counts as at least this many quasi-static substeps (about 0.32 us each) in
/// `max_substeps`, so that the budget bounds a step that marches it again at every switch of a
/// fast schedule (at 40, such steps took up to 9.6 ms with the budget at its declared maximum).
pub(super) const SPIN_CYCLE_WEIGHT: u32 = 80;
/// Settles of the quasi-static onion per substep of the budget: the cycle's march of about 320
/// settles costs about 80 substeps (about 0.08 us a settle against 0.32 us a substep). Marches
/// (the cycle's, the drifting onion's, the overdamped rotor's) are charged by their settles.
pub(super) const SETTLES_PER_SUBSTEP: u32 = 4;
/// Rotor stride of the onion's cycle march (rad), and the placement of its snaps.
const CYCLE_STRIDE: f64 = 0.05;
const SNAP_PLACEMENT: f64 = 1e-10;
/// An onion turn beyond its branch's that marks a snap (rad), as in the integrator.
const ONION_JUMP: f64 = 0.05;
