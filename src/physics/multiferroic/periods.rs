//! A fast schedule's periods taken at once: where the onion's turn at every switch is known
//! (held by the strain at an end of its axis, or a cycle that is its own half turn), the rotor's
//! state after the remaining periods follows without a march or settle at each switch.

use super::cycle::OnionCycle;
use super::spin::SETTLES_PER_SUBSTEP;
use super::{Drive, Motor, StepRun};
use std::f64::consts::PI;

impl Motor {
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
    pub(super) fn strain_held_reach(&self, d: &Drive) -> Option<f64> {
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
}

impl Motor {
    /// The rest of the step's whole periods of the schedule at once when the strain holds the
    /// onion at an end of its axis ([`Self::strain_held_turn`]) and the rotor is locked or the
    /// ring's torque cannot move it by a tenth of the tolerance over them (as in
    /// [`Self::advance_drifting`], over all of them): the rotor follows load and drag alone, and
    /// the onion, which turns by the same angle at every switch whatever the rotor does, ends at
    /// the one minimum of eq. 3.4 within `w` of the end of the last period's strain axis, settled
    /// from the present onion turned by as many of those angles (within `w` of that end). A
    /// locked rotor or a drifting one otherwise costs a settle or a march at every switch
    /// (hundreds in a 1 us step of a nanosecond schedule). Returns whether it advanced.
    pub(super) fn skip_strain_held_periods(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
    ) -> bool {
        let Some(s) = run.schedule else {
            return false;
        };
        if !self.quasi_static() || segment_end >= run.t_end {
            return false;
        }
        let first = s.step_index(segment_end);
        let last = s.step_index(run.t_end);
        let end = (last * s.step_period).min(run.t_end);
        if last - first < 1.0 || end <= segment_end {
            return false;
        }
        let Some(turn) = self.strain_held_turn(d, s.step_angle) else {
            return d.locked && self.settle_locked_periods(run, d, &s, first, last);
        };
        let h = end - run.t;
        let [phi, omega] = if d.locked {
            [run.y[0], 0.0]
        } else {
            let c = self.drag;
            let (coast, torque_speed, torque_angle) = self.drift_response(h);
            if !self.ring_is_negligible(torque_speed, torque_angle) {
                return false;
            }
            [
                run.y[0] + run.y[1] * coast + d.load * torque_angle,
                run.y[1] * (1.0 - c * torque_speed) + d.load * torque_speed,
            ]
        };
        let periods = last - first;
        let applied = s.direction(end - 0.5 * s.step_period);
        let psi = self
            .landscape(phi, super::reduced_direction(applied), d.stress)
            .settle(run.y[2] + periods * turn);
        if !(phi.is_finite() && phi.abs() <= super::MAX_ANGLE && psi.is_finite()) {
            return false;
        }
        run.y = [phi, omega, psi, 0.0];
        run.t = end;
        run.settled = false;
        run.angles = None;
        run.attempts = run.attempts.saturating_add(1);
        true
    }

    /// A locked rotor through the rest of the step's whole periods (segments `first` to
    /// `last - 1`) where the strain does not hold the onion: nothing moves but the onion, which
    /// settles into each period's landscape from where the last one left it (its memory rule,
    /// section 3.2.2), one settle a switch and nothing else (each pass of [`Motor::step`]'s loop
    /// added its checks and a substep's bookkeeping, a third of the cost). Charged by its
    /// settles as the other marches; `false` when the budget left does not cover them (the loop
    /// then goes on, and refuses the step when the switches outnumber its passes).
    fn settle_locked_periods(
        &self,
        run: &mut StepRun,
        d: &Drive,
        s: &super::SteppingSchedule,
        first: f64,
        last: f64,
    ) -> bool {
        let periods = last - first;
        let spent = run.attempts.saturating_add(run.extra_cost);
        let left = self.params.max_substeps.saturating_sub(spent);
        if !(periods >= 1.0 && periods <= f64::from(left) * f64::from(SETTLES_PER_SUBSTEP)) {
            return false;
        }
        let phi = run.y[0];
        let mut psi = run.y[2];
        for k in 0..periods as u32 {
            let applied = s.direction((first + f64::from(k) + 0.5) * s.step_period);
            psi = self
                .landscape(phi, super::reduced_direction(applied), d.stress)
                .settle(psi);
        }
        if !psi.is_finite() {
            return false;
        }
        run.y = [phi, 0.0, psi, 0.0];
        run.t = (last * s.step_period).min(run.t_end);
        run.settled = false;
        run.angles = None;
        run.attempts = run.attempts.saturating_add(1);
        run.extra_cost = run
            .extra_cost
            .saturating_add((periods as u32).div_ceil(SETTLES_PER_SUBSTEP));
        true
    }
}
