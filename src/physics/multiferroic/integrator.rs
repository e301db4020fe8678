//! Exponential Rosenbrock substeps with an embedded error estimate (each onion model its own pair;
//! step doubling where neither applies); see [`Motor::step`].

use super::pass_trace::{trace_error, trace_label};
use super::{phi, Angles, Drive, Motor, StepRun, Vector, MAX_ANGLE};
use crate::physics::numerics::expm;

impl Motor {
    /// One exponential Rosenbrock-Euler substep: `y + dt phi1(dt J) f(y)`, the last column of the
    /// exponential of the augmented matrix `dt [[J, f], [0, 0]]`. Exact for linear
    /// dynamics; the quasi-static onion is re-settled at the new rotor angle.
    pub(super) fn exponential_step(&self, y: &Vector, dt: f64, d: &Drive) -> Option<Vector> {
        let (_, increments) = self.exponential_increments(y, dt, d, false)?;
        self.finish_exponential_step(y, &increments, d)
    }

    /// The increments of [`Self::exponential_step`] over `dt` and, if `half`, over `dt / 2` from
    /// the same `y`: the linearization is the same for both (unless [`Self::bounded_stiffness`]
    /// drops a negative stiffness for `dt` only), so `exp(dt A) = exp(dt A / 2)^2` and the pair
    /// costs one exponential and one product instead of two.
    ///
    /// The matrix is balanced first by a power of two `s` near the rotor's undamped
    /// frequency, with the speed measured in units of `s` (`D^-1 A D`, `D = diag(1, s, 1, ...)`,
    /// exact in binary): the rotor row `k / I` (~1e14 1/s^2 for Table 3.1) otherwise sets the
    /// matrix norm, and with it ten more squarings than the onion's and the rotor's own rates
    /// (~1e11 and ~5e8 1/s) need.
    fn exponential_increments(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        half: bool,
    ) -> Option<(Option<Vector>, Vector)> {
        let (f, j) = self.rhs_jacobian(y, d, dt);
        let shared = half && self.rhs_jacobian(y, d, 0.5 * dt).1 == j;
        let speed_unit = self.speed_unit();
        // The onion rows are zero in the quasi-static option (it is re-settled afterwards), so
        // the rotor block evolves alone: its 2x2 exponential gives the same increments as the
        // full 4x4 one at a fraction of the cost.
        if self.quasi_static() {
            self.increments_of::<2>(&f, &j, dt, shared, speed_unit)
        } else {
            self.increments_of::<4>(&f, &j, dt, shared, speed_unit)
        }
        .and_then(|(halved, full)| match (half, halved) {
            (true, None) => {
                let (_, h) = self.exponential_increments(y, 0.5 * dt, d, false)?;
                Some((Some(h), full))
            }
            (_, h) => Some((h, full)),
        })
    }

    /// [`Self::exponential_increments`] on the `M` first states: from `exp(dt A / 2)` when
    /// `shared`, else from `exp(dt A)` alone ([`expm::expm_affine`]: the augmented matrix's
    /// blocks).
    pub(super) fn increments_of<const M: usize>(
        &self,
        f: &Vector,
        j: &[[f64; 4]; 4],
        dt: f64,
        shared: bool,
        speed_unit: f64,
    ) -> Option<(Option<Vector>, Vector)> {
        let unit = |i: usize| if i == 1 { speed_unit } else { 1.0 };
        let h = if shared { 0.5 * dt } else { dt };
        let a: expm::Mat<M> =
            std::array::from_fn(|i| std::array::from_fn(|k| h * j[i][k] * unit(k) / unit(i)));
        let b: [f64; M] = std::array::from_fn(|i| h * f[i] / unit(i));
        let column = |x: &[f64; M]| {
            let mut increments = [0.0; 4];
            for (i, v) in increments.iter_mut().enumerate().take(M) {
                *v = x[i] * unit(i);
            }
            increments
        };
        let (e, x) = expm::expm_affine(&a, &b)?;
        if shared {
            // [[E, x], [0, 1]]^2 = [[E^2, E x + x], [0, 1]].
            let full: [f64; M] =
                std::array::from_fn(|i| x[i] + (0..M).map(|k| e[i][k] * x[k]).sum::<f64>());
            full.iter()
                .all(|v| v.is_finite())
                .then(|| (Some(column(&x)), column(&full)))
        } else {
            Some((None, column(&x)))
        }
    }

    /// A power of two near the rotor's undamped angular frequency (rad/s): the speed's unit in
    /// the balanced exponential (1 when that frequency is not a finite positive number).
    pub(super) fn speed_unit(&self) -> f64 {
        let exponent = self.speed_scale.log2().round();
        if exponent.is_finite() && exponent.abs() < 1000.0 {
            2f64.powi(exponent as i32)
        } else {
            1.0
        }
    }

    /// The state after [`Self::exponential_increments`]: a locked rotor stays, the quasi-static
    /// onion is re-settled; `None` when it left the bounds.
    pub(super) fn finish_exponential_step(
        &self,
        y: &Vector,
        increments: &Vector,
        d: &Drive,
    ) -> Option<Vector> {
        let mut out = *y;
        let states = if self.quasi_static() { 2 } else { 4 };
        for (x, dx) in out.iter_mut().zip(increments).take(states) {
            *x += dx;
        }
        if d.locked {
            out[0] = y[0];
            out[1] = 0.0;
        }
        if !self.rotor_sane(&out) {
            return None;
        }
        if self.quasi_static() {
            out[2] = self.settle(&out, d);
            out[3] = 0.0;
        }
        Self::onion_sane(&out).then_some(out)
    }

    /// One error-controlled substep: the new state, its error relative to the tolerance and the
    /// time it advances (`dt`, or less when the quasi-static onion snaps inside it, see
    /// [`Self::step_to_onion_snap`]). The quasi-static rotor uses the embedded pair
    /// ([`Self::embedded_step`]), the Gilbert onion its own ([`Self::gilbert_embedded_step`];
    /// unless `forced`, first a locked rotor's creeping onion's exponential RK4 near the explicit
    /// pair's stability limit ([`Self::locked_stiff_step`]), then the explicit [`Self::gilbert_explicit_step`] within its reach, else
    /// the exponential RK4 [`Self::gilbert_exponential_rk4_step`] within its own, where the
    /// exponential pair takes over what it rejects); step doubling remains where none applies.
    /// `angles` are those at `y`; the result carries those at the new state when known.
    pub(super) fn controlled_step(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        angles: &Angles,
        forced: bool,
        bisections: &mut u32,
    ) -> Option<(Vector, f64, f64, Option<Angles>)> {
        if self.quasi_static() && !d.locked {
            match self.embedded_step(y, dt, d, angles) {
                Some(Some((u, err, _))) if self.onion_snapped(y, &u) => {
                    return self
                        .step_to_onion_snap(y, dt, d, angles, bisections)
                        .map(|(u, err, taken)| (u, err, taken, None))
                        .or(Some((u, err, dt, None)));
                }
                Some(result) => return result.map(|(u, err, a)| (u, err, dt, Some(a))),
                None => {}
            }
        }
        if !self.quasi_static() {
            // A forced substep takes the exponential pair, which cannot amplify. All three start
            // from the same right-hand side and Jacobian.
            let start = self.linearized(y, d, dt, angles);
            // A locked rotor's creeping onion near the explicit pair's stability limit.
            if let Some((u, err)) = (!forced)
                .then(|| self.locked_stiff_step(y, dt, d, &start))
                .flatten()
            {
                trace_label("stiff");
                return Some((u, err, dt, None));
            }
            let explicit = (!forced)
                .then(|| self.gilbert_explicit_step(y, dt, d, &start))
                .flatten();
            if let Some((u, err)) = explicit {
                // Where the explicit pair rejects, the exponential pair may still take the
                // substep: an onion far from its minimum that barely moves over it (a strain
                // turning past a slow onion every nanosecond) is nearly linear there, and the
                // tilt's transient after each switch, which holds the explicit pair to a third of
                // a period, is followed exactly (one substep a switch instead of 3.5). Under a
                // free rotor only: it gains nothing for a locked rotor's onion.
                if err <= 1.0 || d.locked {
                    trace_label("dp5");
                    return Some((u, err, dt, None));
                }
                return match self.gilbert_embedded_step(y, dt, d, &start) {
                    Some((v, e)) if e <= 1.0 => Some((v, e, dt, None)),
                    _ => Some((u, err, dt, None)),
                };
            }
            // Where the exponential RK4 substep rejects, the exponential pair may still take it:
            // near its minimum the onion's ringing is nearly linear, which the exponential pair
            // follows exactly over many precession periods.
            let rk4 = (!forced)
                .then(|| self.gilbert_exponential_rk4_step(y, dt, d, &start))
                .flatten();
            if let Some((u, err, _)) = rk4.filter(|(_, err, _)| *err <= 1.0) {
                trace_label("exprk4");
                return Some((u, err, dt, None));
            }
            // A rejection by little is the step-size rule's overshoot, which the exponential pair
            // does not take either ([`super::etd_blocks::RETRY_ABOVE`]).
            if let Some((u, err, false)) = rk4 {
                return Some((u, err, dt, None));
            }
            #[cfg(test)]
            PAIR_AFTER_RK4.with(|c| c.set(c.get() + 1));
            match self.gilbert_embedded_step(y, dt, d, &start) {
                Some((u, err)) if err <= 1.0 || rk4.is_none() => {
                    trace_label("pair");
                    return Some((u, err, dt, None));
                }
                _ => {}
            }
            if let Some((u, err, _)) = rk4 {
                return Some((u, err, dt, None));
            }
        }
        trace_label("doubled");
        self.doubled_step(y, dt, d)
            .map(|(u, err)| (u, err, dt, None))
    }

    /// Whether the quasi-static onion left its branch between `y` and `u`: its minimum of eq. 3.3
    /// plus eq. 3.4 vanished at a fold and it fell into the other one (the jump far out of
    /// alignment of Figure 3.3a). Along a branch it turns with the rotor, by
    /// `k_bar / (k_bar + k_me)` times the rotor's turn (a few times it except at the fold itself),
    /// so a turn beyond that plus `ONION_SNAP` rad is a jump.
    fn onion_snapped(&self, y: &Vector, u: &Vector) -> bool {
        (u[2] - y[2]).abs() > ONION_SNAP + 4.0 * (u[0] - y[0]).abs()
    }

    /// A substep across an onion snap, cut at the snap. The torque jumps there, so the pair's
    /// defect (and step doubling's difference) stays of the order of the jump however short the
    /// substep: the error control alone can only shrink the substep to the budget's minimum and
    /// accept it flagged, with the snap misplaced by up to that substep (4.8 ns against the
    /// rotor's 2 ns inertial time `I/c`). Instead the snap is located by bisection on the substep
    /// length, the rotor advanced on the old branch to just before it (error-controlled as
    /// usual), and the onion put on its new branch; the substep after it starts from the new
    /// torque. The substep ends at the prefix's end, the time of the state it returns: ending it
    /// at the first snapped length instead left a rotor turning at `omega` behind by `omega`
    /// times the bracket's width (up to 0.15 rad over a 2 ns step at 1e-11 N m). `None` if no
    /// snap-free prefix is found. `bisections` counts the embedded steps it takes (each a
    /// substep's work).
    fn step_to_onion_snap(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        angles: &Angles,
        bisections: &mut u32,
    ) -> Option<(Vector, f64, f64)> {
        let (mut before, mut after) = (0.0, dt);
        let mut last_before: Option<(Vector, f64)> = None;
        let mut snapped = None;
        // The snap is placed within SNAP_RESOLUTION of the rotor's inertial time: the rotor
        // turns by less than that times its speed in the gap (~1e-8 rad at 5e4 rad/s).
        let resolution = SNAP_RESOLUTION * self.inertia / self.drag;
        for _ in 0..60 {
            if after - before <= resolution {
                break;
            }
            let mid = 0.5 * (before + after);
            *bisections += 1;
            match self.embedded_step(y, mid, d, angles) {
                Some(Some((u, err, _))) if !self.onion_snapped(y, &u) => {
                    before = mid;
                    last_before = Some((u, err));
                }
                Some(Some((u, _, _))) => {
                    after = mid;
                    snapped = Some(u);
                }
                _ => return None,
            }
        }
        let (mut u, err) = last_before?;
        let snapped = match snapped {
            Some(v) => v,
            None => self.embedded_step(y, dt, d, angles)??.0,
        };
        // The rotor state at the snap, the onion on the branch it fell into there.
        u[2] = self
            .landscape(u[0], d.direction, d.stress)
            .settle(snapped[2]);
        self.sane(&u).then_some((u, err, before))
    }

    /// The exponential Rosenbrock pair of order 2(3) of Hochbruck, Ostermann and Schweitzer
    /// (exprb32, SIAM J. Numer. Anal. 47, 2009) on the rotor's 2x2 block: the exponential Euler
    /// step `u1 = y + h phi_1(hJ) F(y)`, then with the linearization's defect
    /// `D = F(u1) - F(y) - J (u1 - y)` the third-order `u3 = u1 + 2 h phi_3(hJ) D`, whose
    /// correction is the error estimate of `u1`. Both `phi` functions come in closed form
    /// ([`phi::Phi2x2`]). One right-hand side and two onion settles per substep, where step
    /// doubling took three 3x3 matrix exponentials and three settles. `None` (use step doubling)
    /// when the block's eigenvalues are complex or nearly equal; `Some(None)` if the step fails.
    ///
    /// `angles` are those at `y`; every later evaluation turns them (see [`Angles::moved`]), and
    /// the result carries the angles at `u3`.
    fn embedded_step(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        angles: &Angles,
    ) -> Option<Option<(Vector, f64, Angles)>> {
        let (tau, k_bar) = self
            .ring_bar
            .torque_stiffness_of(angles.sin_offset, angles.cos_offset);
        let (f0, j) = self.rhs_jacobian_of(y, d, dt, angles, tau, k_bar);
        // The onion's turn per rotor turn along its branch, k_bar / (k_bar + k_me) (implicit
        // function theorem on dU/dpsi = 0), and how far that prediction may be trusted.
        let curvature = k_bar + 2.0 * self.magnetoelastic_per_stress * d.stress * angles.cos_double;
        let bound =
            self.ring_bar_slope_bound + 4.0 * (self.magnetoelastic_per_stress * d.stress).abs();
        let predict = |from: &Angles, rotor: f64| -> Angles {
            let turn = k_bar / curvature * (rotor - from.bar);
            let onion = if curvature > 0.0 && turn.abs() <= PREDICTION_WINDOW * curvature / bound {
                from.onion + turn
            } else {
                from.onion
            };
            from.moved(onion, rotor, d.direction)
        };
        let a = [[dt * j[0][0], dt * j[0][1]], [dt * j[1][0], dt * j[1][1]]];
        let phi = phi::Phi2x2::new(&a)?;
        let step = phi.apply(1, &a, [dt * f0[0], dt * f0[1]]);
        let mut u1 = *y;
        u1[0] += step[0];
        u1[1] += step[1];
        if !self.rotor_sane(&u1) {
            return Some(None);
        }
        let a1 = self
            .landscape(u1[0], d.direction, d.stress)
            .settle_from(predict(angles, u1[0]));
        u1[2] = a1.onion;
        u1[3] = 0.0;
        if !Self::onion_sane(&u1) {
            return Some(None);
        }
        let (f1, _) = self.rhs_jacobian_at(&u1, d, dt, &a1);
        let defect = [
            f1[0] - f0[0] - (j[0][0] * step[0] + j[0][1] * step[1]),
            f1[1] - f0[1] - (j[1][0] * step[0] + j[1][1] * step[1]),
        ];
        let correction = phi.apply(3, &a, [2.0 * dt * defect[0], 2.0 * dt * defect[1]]);
        let mut u3 = u1;
        u3[0] += correction[0];
        u3[1] += correction[1];
        if !self.rotor_sane(&u3) {
            return Some(None);
        }
        let a3 = self
            .landscape(u3[0], d.direction, d.stress)
            .settle_from(predict(&a1, u3[0]));
        u3[2] = a3.onion;
        if !Self::onion_sane(&u3) {
            return Some(None);
        }
        let inv_tol = 1.0 / self.params.tolerance;
        let err =
            (correction[0].abs() * inv_tol).max(correction[1].abs() * inv_tol / self.speed_scale);
        Some(Some((u3, err, a3)))
    }

    fn sane(&self, y: &Vector) -> bool {
        self.rotor_sane(y) && Self::onion_sane(y)
    }

    /// The onion half of [`Self::sane`], for a state whose rotor was checked before its settle
    /// (the comparisons are false for NaN, so they also test finiteness).
    pub(super) fn onion_sane(y: &Vector) -> bool {
        y[2].abs() <= MAX_ANGLE && y[3].abs() <= 10.0
    }

    /// The rotor half of [`Self::sane`], checked before the quasi-static onion is settled at a
    /// new rotor angle: beyond `MAX_ANGLE` (or at infinity) the offset `psi - phi` has lost the
    /// onion's angle to rounding, the landscape is flat and the settle's march ran to its cap of
    /// 2,000 strides for a substep that was rejected anyway (fuzzing found 4 s steps so).
    pub(super) fn rotor_sane(&self, y: &Vector) -> bool {
        y[0].is_finite() && y[0].abs() <= MAX_ANGLE && y[1].is_finite()
    }

    /// Step doubling: returns the two-half-step result and its error relative to the tolerance.
    /// The full step and the first half step share one exponential
    /// ([`Self::exponential_increments`]): two exponentials per attempt instead of three.
    pub(super) fn doubled_step(&self, y: &Vector, dt: f64, d: &Drive) -> Option<(Vector, f64)> {
        let (half, whole) = self.exponential_increments(y, dt, d, true)?;
        let full = self.finish_exponential_step(y, &whole, d)?;
        let mid = self.finish_exponential_step(y, &half?, d)?;
        let two = self.exponential_step(&mid, 0.5 * dt, d)?;
        let tol = self.params.tolerance;
        let scales = [tol, tol * self.speed_scale, tol, tol];
        let err = (0..4)
            .map(|i| (two[i] - full[i]).abs() / scales[i])
            .fold(0.0, f64::max);
        Some((two, err))
    }

    /// One attempted substep of the error-controlled integration towards `segment_end`.
    ///
    /// The budget is shared over the rest of the step, but each segment may use at most 1/16 of
    /// what is left, so that the first periods of a schedule are resolved well enough for their
    /// repetition to be detected (and then the rest costs nothing).
    pub(super) fn substep(&self, run: &mut StepRun, d: &Drive, segment_end: f64, budget: u32) {
        let t = run.t;
        let remaining = run.t_end - t;
        let left = budget
            .saturating_sub(run.attempts.saturating_add(run.extra_cost))
            .max(1);
        let per_segment = (left / SEGMENT_BUDGET_SHARE).max(1);
        // While more than half the budget is left, the floor is FINE_FLOOR times finer than an
        // even spread: the short stiff transients inside a step (the Gilbert onion's ringing
        // after every switch, ~2 ns at picosecond substeps, at communication steps up to 1 s)
        // are resolved there, and the even spread of the half left still ends the step.
        let spread = if 2 * u64::from(left) > u64::from(budget) + 1 {
            FINE_FLOOR * left as f64
        } else {
            left as f64
        };
        let dt_min = (remaining / spread).min((segment_end - t) / per_segment as f64);
        let mut dt_try = run.dt.max(dt_min).min(segment_end - t);
        let clipped = dt_try < run.dt;
        if dt_try < 1e-300 {
            dt_try = segment_end - t;
        }
        run.attempts = run.attempts.saturating_add(1);
        if !self.quasi_static() {
            run.extra_cost = run
                .extra_cost
                .saturating_add(super::GILBERT_SUBSTEP_WEIGHT - 1);
        }
        if d.locked && self.quasi_static() {
            // Nothing moves but the onion, which follows the inputs: jump to the next switch.
            run.t = segment_end.max(t + dt_try).min(run.t_end);
            return;
        }
        let forced = dt_try <= dt_min * (1.0 + 1e-12);
        let angles = Self::angles_at(&run.y, d, run.angles.as_ref());
        run.angles = Some(angles);
        // A substep across a snap of the onion is charged its bisection's substeps too.
        let mut bisections = 0;
        let result = self
            .controlled_step(&run.y, dt_try, d, &angles, forced, &mut bisections)
            .map(|(u, err, taken, a)| {
                let err = if d.locked {
                    self.energy_checked_error(&mut run.rim_ledger, (&run.y, &u), taken, d, err)
                } else {
                    self.free_energy_checked_error(
                        &mut run.free_ledger,
                        (&run.y, &u),
                        taken,
                        d,
                        err,
                    )
                };
                trace_error(err);
                (u, err, taken, a)
            });
        run.extra_cost = run.extra_cost.saturating_add(bisections);
        match result {
            Some((y_new, err, _, _))
                if forced && err > 1.0 && self.forced_out_of_well(&run.y, &y_new, err, d) =>
            {
                // Not taken: the next pass drops the ringing from here, as for an onion that left
                // its bounds.
                run.limited = true;
                run.settled = false;
                run.onion_escaped = true;
                run.dt = dt_try;
            }
            Some((y_new, err, taken, new_angles)) if err <= 1.0 || forced => {
                if err > 1.0 {
                    run.limited = true;
                } else if !self.quasi_static() {
                    self.record_amplification(&mut run.amplification, taken, d, &angles, err);
                }
                run.y = y_new;
                // The embedded pair's state is settled, with its angles; the others are not.
                run.settled = new_angles.is_some();
                if new_angles.is_some() {
                    run.angles = new_angles;
                }
                let end = t + taken;
                run.t = if end >= segment_end || segment_end - end < 1e-15 * run.t_end {
                    segment_end.max(end).min(run.t_end)
                } else {
                    end
                };
                // A substep cut short at the segment's end says little about the size the
                // error allows: keep the uncut proposal, or every communication step shorter
                // than two substeps would take two (its stub's small size seeding the next).
                let proposal = taken * step_factor(err);
                run.dt = if clipped && err <= 1.0 {
                    proposal.max(run.dt)
                } else {
                    proposal
                };
            }
            Some((_, err, _, _)) => run.dt = (dt_try * step_factor(err)).max(dt_min),
            None if forced && !self.quasi_static() && self.onion_relaxes_fast() => {
                // The Gilbert onion left its bounds (its tilt beyond 10 rad on a steep landscape)
                // even at the smallest allowed substep: flagged, the next pass drops its ringing
                // and follows its branch from here ([`Motor::follows_branch`]), the rotor's speed
                // kept (zeroing it would lose its coasting distance `omega I / c` each time).
                run.limited = true;
                run.settled = false;
                run.onion_escaped = true;
                run.dt = dt_try;
            }
            None if forced => {
                // The linearization overflowed (or the rotor left `MAX_ANGLE`) even at the
                // smallest allowed substep: hold the state over it rather than produce garbage.
                // From rest every later attempt in this segment is the same one (same state,
                // drive and minimum substep) and fails alike, so hold to the segment's end: the
                // budget's 20,000 failed attempts took seconds per step under fuzzing.
                let from_rest = run.y[1] == 0.0;
                run.limited = true;
                run.settled = false;
                run.y[1] = 0.0;
                run.t = if from_rest { segment_end } else { t + dt_try }.min(run.t_end);
                run.dt = dt_try;
            }
            None if self.onion_leaves_bounds(&run.y, dt_try, d, &angles) => {
                Self::leave_bounds(run, dt_try);
            }
            None => run.dt = (0.2 * dt_try).max(dt_min),
        }
    }
}

#[cfg(test)]
thread_local! {
    /// The exponential pair's substeps after the exponential RK4's (tests count them).
    pub(super) static PAIR_AFTER_RK4: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// The onion's predicted turn along its branch is used as the settle's start only when it stays
/// within this fraction of the monotone window `curvature / M` of the last minimum (see the onion
/// module): the start then lies in the same basin, so the memory rule holds, and far from a fold.
const PREDICTION_WINDOW: f64 = 0.1;

/// Next-substep factor for a second-order method (local error ~ dt^3), bounded to [0.2, 5].
pub(super) fn step_factor(err: f64) -> f64 {
    // 0.9 err^(-1/3) reaches the bounds at err = (0.9/5)^3 and (0.9/0.2)^3.
    if err.is_nan() || err >= 91.125 {
        0.2
    } else if err <= 0.005_832 {
        5.0
    } else {
        0.9 / cube_root(err)
    }
}

/// `x^(1/3)` for `x` in [0.005, 92] to about 1e-7 relative (a step-size factor needs no more):
/// the exponent divided by 3 in the bits, then two Newton steps. libm's `cbrt` was 4% of a
/// motor step.
fn cube_root(x: f64) -> f64 {
    let mut y = f64::from_bits(x.to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
    for _ in 0..3 {
        y = (2.0 * y + x / (y * y)) * (1.0 / 3.0);
    }
    y
}

/// A turn of the quasi-static onion beyond its branch's (rad) that marks a snap to the other
/// branch ([`Motor::onion_snapped`]); the snaps seen are about 1 rad.
const ONION_SNAP: f64 = 0.05;

/// The snap is located within this fraction of the rotor's inertial time `I/c`.
const SNAP_RESOLUTION: f64 = 1e-4;

/// While more than half the budget is left, the minimum substep is the even spread of the
/// budget over the rest of the step divided by this (2^30; see [`Motor::substep`]).
const FINE_FLOOR: f64 = 1_073_741_824.0;

/// A segment of constant drive may use at most 1/this of the substeps left (see [`Motor::step`]).
const SEGMENT_BUDGET_SHARE: u32 = 16;

#[cfg(test)]
mod tests;
