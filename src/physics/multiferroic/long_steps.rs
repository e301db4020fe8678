//! Long steps in the overdamped limit: settling a rotor and whole slipping turns.

use super::angles::turned_back;
use super::spin::SETTLES_PER_SUBSTEP;
use super::{Drive, Motor, StepRun, SteppingSchedule, Vector};
use std::cell::Cell;
use std::f64::consts::PI;

impl Motor {
    /// Force on the rotor at `phi` with the onion settled at `psi`, `F = tau_bar + load`, and its
    /// reduced stiffness `k = -dF/dphi` (the bar spring in series with the magnetoelastic one,
    /// bounded near a fold as in [`Self::rhs_jacobian`]).
    pub(super) fn rotor_force(&self, phi: f64, psi: f64, d: &Drive) -> (f64, f64) {
        let beta = psi - phi;
        let (tau, k_bar) = self.ring_bar.torque_stiffness(beta);
        let k_me = 2.0
            * self.magnetoelastic_per_stress
            * d.stress
            * turned_back(2.0 * (psi - d.direction)).cos();
        let sum = (k_bar + k_me).max(0.05 * (k_bar.abs() + k_me.abs()));
        let k = if sum > 0.0 { k_bar * k_me / sum } else { 0.0 };
        (tau + d.load, k)
    }

    /// The rotor after `available` seconds at constant drive, in the overdamped limit, when by
    /// then it has come within [`MAX_SETTLE_RESIDUAL`] of its equilibrium; `None` when it has not
    /// or that limit does not apply (locked rotor, Gilbert onion, no drag, a fast initial speed,
    /// a rotor that slips without end, or a degenerate equilibrium).
    ///
    /// The rotor is strongly overdamped (`I/c` ~ 2 ns against `c/k` ~ 3 us), so after its speed's
    /// initial layer (`omega I / c` of coasting, a few `I/c`) it moves as `c phi' = F(phi)`, a
    /// gradient flow: it goes downhill from where it is and stops at the first zero of `F`, i.e.
    /// the same memory rule as the onion's, with the onion re-settled (memory and folds included)
    /// at every point of the path. The march follows `F` in strides that change `F` by at most a
    /// quarter (and at most [`MAX_ROTOR_STRIDE`]) and adds up the travel time `int c / |F| dphi`
    /// (trapezoid in `1/F`). Once the root is bracketed, the rest is the linear exponential
    /// approach: the distance `d` left decays as `d exp(-k t / c)` with the stiffness `k` at the
    /// root, which gives the end state and speed (an error of `delta` in the travel time moves the
    /// end by `residual k delta / c`, below the tolerance for the residuals allowed). A fold that flips the force's sign (the onion jumps) turns the
    /// rotor back and the march goes on from the jumped state. Hand-written for the hot path:
    /// every loop is capped.
    pub(super) fn settle_rotor(
        &self,
        y: &Vector,
        d: &Drive,
        available: f64,
        settles: &Cell<u32>,
    ) -> Option<Vector> {
        let settle = |at: f64, from: f64| {
            settles.set(settles.get().saturating_add(1));
            self.landscape(at, d.direction, d.stress).settle(from)
        };
        let (i, c) = (self.inertia, self.drag);
        if d.locked || !self.quasi_static() || c <= 0.0 {
            return None;
        }
        let coast = y[1] * i / c;
        if coast.abs() > MAX_ROTOR_STRIDE {
            return None;
        }
        let eps = 1e-2 * self.params.tolerance;
        // Torque scale (N m): the alignment stiffness times one radian, plus the load.
        let force_scale = self.alignment_stiffness.abs() + d.load.abs();
        let continuous = 1e-6 * force_scale;
        let mut phi = y[0] + coast;
        let mut psi = settle(phi, y[2]);
        // The initial layer: the speed has decayed by e^-20 after 20 I/c.
        let mut time = 20.0 * i / c;
        let mut travelled = 0.0;
        let mut turnarounds = 0;
        for _ in 0..MAX_ROTOR_MARCH {
            let (force, k) = self.rotor_force(phi, psi, d);
            if force == 0.0 && k > 0.0 {
                return (time < available).then_some([phi, 0.0, psi, 0.0]);
            }
            let dir = force.signum();
            let stride = if k > 0.0 && force.abs() <= k * MAX_ROTOR_STRIDE {
                // Near the root: aim past it to bracket it.
                (1.5 * force.abs() / k).max(eps)
            } else if k != 0.0 {
                crate::physics::numerics::bounds::limit(
                    0.25 * force.abs() / k.abs(),
                    eps,
                    MAX_ROTOR_STRIDE,
                )
            } else {
                MAX_ROTOR_STRIDE
            };
            let next_phi = phi + dir * stride;
            let next_psi = settle(next_phi, psi);
            let (next_force, _) = self.rotor_force(next_phi, next_psi, d);
            if dir * next_force > 0.0 {
                time += 0.5 * c * stride * (1.0 / force.abs() + 1.0 / next_force.abs());
                travelled += stride;
                if travelled > MAX_ROTOR_TRAVEL {
                    return None; // slipping: no equilibrium ahead
                }
                phi = next_phi;
                psi = next_psi;
                continue;
            }
            // The force changed sign within the stride: refine by false position (Illinois),
            // the onion settled from the near side each time.
            let (mut lo, mut hi) = (phi, next_phi);
            let (mut f_lo, mut f_hi) = (force, next_force);
            let (mut psi_hi, mut psi_root, mut f_root) = (next_psi, psi, force);
            let mut root = phi;
            for _ in 0..MAX_ROOT_STEPS {
                let mut x = hi - f_hi * (hi - lo) / (f_hi - f_lo);
                let width = (hi - lo).abs();
                if !(x - lo).is_finite()
                    || (x - lo).abs() < 0.01 * width
                    || (hi - x).abs() < 0.01 * width
                {
                    x = 0.5 * (lo + hi);
                }
                let x_psi = settle(x, psi);
                let (fx, _) = self.rotor_force(x, x_psi, d);
                root = x;
                psi_root = x_psi;
                f_root = fx;
                if fx.abs() <= 1e-14 * force_scale {
                    break;
                }
                if fx * f_lo > 0.0 {
                    lo = x;
                    f_lo = fx;
                    f_hi *= 0.5;
                } else {
                    hi = x;
                    f_hi = fx;
                    psi_hi = x_psi;
                    f_lo *= 0.5;
                }
                if (hi - lo).abs() <= 1e-15 * (1.0 + x.abs()) {
                    break;
                }
            }
            if f_root.abs() <= continuous {
                let (_, k_root) = self.rotor_force(root, psi_root, d);
                if k_root <= 0.0 {
                    return None; // tangential equilibrium: no exponential approach
                }
                // The last stretch, from `phi` at `time`, is the linear exponential approach.
                let rate = k_root / c;
                let residual = (root - phi).abs() * (-(available - time) * rate).exp();
                if !(time < available && residual <= MAX_SETTLE_RESIDUAL) {
                    return None;
                }
                let end = root + (phi - root).signum() * residual;
                let end_psi = settle(end, psi_root);
                let speed = (root - end) * rate;
                return Some([end, speed, end_psi, 0.0]);
            }
            // A jump of the onion flipped the force: the rotor turns back from the fold.
            turnarounds += 1;
            if turnarounds > MAX_TURNAROUNDS {
                return None;
            }
            let reached = (hi - phi).abs();
            time += c * reached / force.abs();
            travelled += reached;
            phi = hi;
            psi = psi_hi;
        }
        None
    }

    /// Time for one turn (2 pi) of a rotor that slips (its force never vanishes) from `phi`, in
    /// the overdamped limit, and the onion angle after it; `None` if the force vanishes on the
    /// way. `int c / |F| dphi` by Simpson's rule on strides that change `F` by at most a quarter;
    /// a stride over which the onion jumps (a fold: `F` is discontinuous there) is halved down to
    /// 1e-7 rad, so the jump costs no accuracy. The first inertial correction to the turn time is
    /// `(I/c) [ln F]` over the turn, which vanishes on a periodic orbit; the next is of order
    /// `(I k / c^2)^2` ~ 1e-6.
    pub(super) fn slip_turn(
        &self,
        phi0: f64,
        psi0: f64,
        d: &Drive,
        settles: &Cell<u32>,
    ) -> Option<(f64, f64)> {
        let c = self.drag;
        let (f0, _) = self.rotor_force(phi0, psi0, d);
        if f0 == 0.0 {
            return None;
        }
        let dir = f0.signum();
        let target = phi0 + dir * 2.0 * PI;
        let (mut phi, mut psi, mut force) = (phi0, psi0, f0);
        let mut stride = MAX_ROTOR_STRIDE;
        let mut time = 0.0;
        let settle = |at: f64, from: f64| {
            settles.set(settles.get().saturating_add(1));
            self.landscape(at, d.direction, d.stress).settle(from)
        };
        for _ in 0..MAX_SLIP_STRIDES {
            let left = dir * (target - phi);
            if left <= 0.0 {
                return Some((time, psi));
            }
            let h = stride.min(left);
            let mid = phi + 0.5 * dir * h;
            let end = if h == left { target } else { phi + dir * h };
            let psi_mid = settle(mid, psi);
            let psi_end = settle(end, psi_mid);
            let (f_mid, _) = self.rotor_force(mid, psi_mid, d);
            let (f_end, k_end) = self.rotor_force(end, psi_end, d);
            if dir * f_mid <= 0.0 || dir * f_end <= 0.0 {
                return None;
            }
            // A jump moves the onion by tenths of a radian; the continuous branch moves by
            // its slope times the stride, which grows without bound only right at a fold.
            let jump = (5.0 * h).max(1e-3);
            if ((psi_mid - psi).abs() > jump || (psi_end - psi_mid).abs() > jump) && h > 1e-7 {
                stride = 0.5 * h;
                continue;
            }
            time += c * h / 6.0 * (1.0 / force.abs() + 4.0 / f_mid.abs() + 1.0 / f_end.abs());
            phi = end;
            psi = psi_end;
            force = f_end;
            let smooth = if k_end != 0.0 {
                0.25 * force.abs() / k_end.abs()
            } else {
                MAX_ROTOR_STRIDE
            };
            stride = (2.0 * h).min(smooth).clamp(1e-7, MAX_ROTOR_STRIDE);
        }
        None
    }

    /// A slipping rotor over `available` seconds at constant drive: one overdamped turn from the
    /// present state (its start shifted by the speed's coast `omega I / c`), then, when a second
    /// turn repeats it (onion back to the same place modulo 2 pi within `tolerance / 1000`), as
    /// many more such turns as fit while leaving at least one turn of the interval to the error-
    /// controlled integrator. Returns the time advanced and the state; `None` if the rotor does
    /// not slip, too little time is left, or its speed's initial layer (`20 I/c`) does not fit in
    /// the interval.
    pub(super) fn slip_turns(
        &self,
        y: &Vector,
        d: &Drive,
        available: f64,
        settles: &Cell<u32>,
    ) -> Option<(f64, Vector)> {
        let (i, c) = (self.inertia, self.drag);
        // The overdamped limit holds after the speed's initial layer (20 I/c, as in
        // `settle_rotor`): a rotor whose inertial time is not far below the interval speeds up
        // along `I phi'' = F - c phi'`, not at once to `F / c`.
        if d.locked || !self.quasi_static() || c <= 0.0 || 20.0 * i / c >= available {
            return None;
        }
        let coast = y[1] * i / c;
        if coast.abs() > MAX_ROTOR_STRIDE {
            return None;
        }
        let phi0 = y[0] + coast;
        settles.set(settles.get().saturating_add(1));
        let psi0 = self.landscape(phi0, d.direction, d.stress).settle(y[2]);
        let (first, psi1) = self.slip_turn(phi0, psi0, d, settles)?;
        let (f0, _) = self.rotor_force(phi0, psi0, d);
        let turn = f0.signum() * 2.0 * PI;
        let (period, psi2) = self.slip_turn(phi0 + turn, psi1, d, settles)?;
        let onion_turn = psi2 - psi1;
        let winding = (onion_turn / (2.0 * PI)).round() * 2.0 * PI;
        if (onion_turn - winding).abs() > 1e-3 * self.params.tolerance || period <= 0.0 {
            return None;
        }
        // Turns after the first, leaving at least one period for the integrator.
        let repeats = ((available - first) / period).floor() - 1.0;
        if !(1.0..1e12).contains(&repeats) {
            return None;
        }
        let phi = phi0 + turn * (1.0 + repeats);
        let psi = psi1 + winding * repeats;
        let (force, _) = self.rotor_force(phi, psi, d);
        Some((first + repeats * period, [phi, force / c, psi, 0.0]))
    }

    /// At a switch of the schedule: once whole periods end in the same state relative to the
    /// strain direction, advances every later whole period at once and returns `true`.
    ///
    /// The equations are invariant under a common rotation of rotor, onion and strain, so once
    /// whole periods end in the same relative state, every later period repeats the last one
    /// turned by step_angle. Required: three period ends within tolerance / 100 and then
    /// tolerance / 1000 of each other, i.e. the period map has converged onto its fixed point (a
    /// settled end state, or the rotor's periodic orbit) and contracts towards it.
    pub(super) fn skip_repeated_periods(&self, run: &mut StepRun, s: &SteppingSchedule) -> bool {
        let y = run.y;
        let relative = [
            y[0] - run.segment_direction,
            y[2] - run.segment_direction,
            y[1] / self.speed_scale,
        ];
        let tol = self.params.tolerance;
        if run.whole_period {
            let mismatch = run.period_end.map_or(f64::INFINITY, |p| {
                (0..3)
                    .map(|i| (p[i] - relative[i]).abs())
                    .fold(0.0, f64::max)
            });
            let periods = s.step_index(run.t_end) - s.step_index(run.t);
            if mismatch <= 1e-3 * tol && run.period_mismatch <= 1e-2 * tol && periods >= 1.0 {
                run.y[0] += periods * s.step_angle;
                run.y[2] += periods * s.step_angle;
                run.t = (s.step_index(run.t_end) * s.step_period).min(run.t_end);
                run.segment_end = f64::NAN;
                run.period_end = None;
                run.period_mismatch = f64::INFINITY;
                return true;
            }
            run.period_mismatch = mismatch;
        }
        run.period_end = Some(relative);
        false
    }

    /// A long segment of constant drive in the overdamped limit: the rotor settled to its
    /// equilibrium ([`Self::settle_rotor`]) or advanced by whole slipping turns
    /// ([`Self::slip_turns`]); `false` when neither applies.
    pub(super) fn advance_overdamped(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
    ) -> bool {
        // The marches are charged by their settles, also when they do not apply.
        let settles = Cell::new(0u32);
        let charge = |run: &mut StepRun| {
            run.extra_cost = run
                .extra_cost
                .saturating_add(settles.get().div_ceil(SETTLES_PER_SUBSTEP));
        };
        if let Some(settled) = self.settle_rotor(&run.y, d, segment_end - run.t, &settles) {
            charge(run);
            run.attempts = run.attempts.saturating_add(1);
            run.y = settled;
            run.t = segment_end;
            return true;
        }
        let slipped = self.slip_turns(&run.y, d, segment_end - run.t, &settles);
        charge(run);
        if let Some((advanced, slipped)) = slipped {
            // The turns' phase is only as good as their quadrature and the overdamped limit
            // (~1e-6 relative against resolved steps, see the tests): over thousands of turns
            // that is beyond the tolerance in angle, so flagged.
            run.attempts = run.attempts.saturating_add(1);
            run.limited = true;
            run.y = slipped;
            run.t = (run.t + advanced).min(segment_end);
            return true;
        }
        false
    }
}

/// Largest stride of the rotor march in [`Motor::settle_rotor`] (rad), as the onion's.
const MAX_ROTOR_STRIDE: f64 = 0.05;
/// Rotor march caps: strides, travel (two turns: farther means it slips) and fold turnarounds.
const MAX_ROTOR_MARCH: usize = 1000;
const MAX_ROTOR_TRAVEL: f64 = 4.0 * PI;
const MAX_TURNAROUNDS: usize = 8;
const MAX_ROOT_STEPS: usize = 100;
/// Strides of one slipping turn in [`Motor::slip_turn`]: 126 at the largest stride, plus the
/// halvings at folds.
const MAX_SLIP_STRIDES: usize = 20_000;
/// Largest distance from its equilibrium (rad) at which [`Motor::settle_rotor`] may leave the
/// rotor at the end of an interval: close enough that the exponential tail is linear.
const MAX_SETTLE_RESIDUAL: f64 = 1e-4;
