//! A Gilbert onion whose tilt leaves the small-tilt model's bounds, under a free or a locked
//! rotor: found at the substep that carries it out ([`Motor::onion_leaves_bounds`]) rather than
//! by substeps that shrink towards the bound until the budget's smallest one is forced.

use super::etd_blocks::{etd_rk4_blocks, Blocks, ETD_REACH, WEAK_COUPLING};
use super::gilbert::{Linearized, EXPLICIT_REACH};
use super::step::StepRun;
use super::{Angles, Drive, Motor, Vector};
use crate::physics::numerics::dormand_prince;

impl Motor {
    /// Whether the resolved Gilbert onion leaves its bounds (a tilt beyond 10 rad, see
    /// [`Self::onion_sane`]) within the substep of `dt` from `y` (angles `angles`), whose end
    /// beyond them the integrator refused: a substep with the bounds lifted
    /// ([`Self::unbounded_substep`]) ends with its error estimate within the tolerance and the
    /// tilt beyond the bound by more than the tolerance, so the resolved onion crosses the bound
    /// inside the substep; and the onion settles into the same minimum from both ends, so that
    /// dropping its ringing from `y` ([`Self::follows_branch`], as where the budget's smallest
    /// substep leaves the bounds) places it where dropping it at the bound would.
    ///
    /// A soft tilt (`T` far below the well's curvature) lets an onion released near a rim reach
    /// its bound, `sqrt(2 E / T) > 10`, on the way down. Refused substeps cut to a fifth, with
    /// accepted ones between them, would creep up to the bound over ten orders of magnitude of
    /// substep size (two thirds of such a first step's substeps) before the budget's smallest
    /// one is forced and the onion escapes there, in the same well. A locked rotor's onion is
    /// dropped from either point into the same minimum too (its landscape does not move), and
    /// its creep, each refused attempt a failed exponential pair and step doubling, was most
    /// of such a first step's cost.
    pub(super) fn onion_leaves_bounds(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        angles: &Angles,
    ) -> bool {
        if self.quasi_static() || !self.onion_relaxes_fast() {
            return false;
        }
        #[cfg(test)]
        if d.locked && LOCKED_EXIT_OFF.with(|c| c.get()) {
            return false;
        }
        let start = self.linearized(y, d, dt, angles);
        let Some((u, err)) = self.unbounded_substep(y, dt, d, &start) else {
            return false;
        };
        let tol = self.params.tolerance;
        let beyond = u[3].abs() > MAX_TILT + tol;
        if !(err <= 1.0 && beyond && self.rotor_sane(&u) && u[2].abs() <= super::MAX_ANGLE) {
            return false;
        }
        let (from, to) = (self.settle(y, d), self.settle(&u, d));
        (from - to).abs() <= SAME_MINIMUM
    }

    /// The end of a substep of `dt` from `y` (linearized there as `start`) with the onion's
    /// bounds not enforced, and its error estimate relative to the tolerance: the explicit
    /// Dormand-Prince pair's within its reach, else, on a stiff rotor, the exponential RK4 of
    /// the Jacobian's diagonal blocks within its own ([`Self::gilbert_block_etd_step`]); `None`
    /// where neither applies or the substep fails.
    fn unbounded_substep(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        start: &Linearized,
    ) -> Option<(Vector, f64)> {
        let j = &start.j;
        let rate =
            |z: &Vector| self.gilbert_rate(z, d, &start.angles.moved(z[2], z[0], d.direction));
        // (False for a NaN rate too.)
        if dt * self.fastest_rate(j) <= EXPLICIT_REACH {
            let (u, k) = dormand_prince::step(y, &start.f, dt, |z| Some(rate(z)))?;
            let err = self.error_norm(|i| dormand_prince::error(dt, &k, i), y, &u);
            return Some((u, err));
        }
        let coupling = self.coupling_rate_bound(j);
        let onion =
            (j[2][2] + j[3][3]).abs() + (j[2][2] * j[3][3] - j[2][3] * j[3][2]).abs().sqrt();
        if !(dt * coupling <= ETD_REACH && coupling <= WEAK_COUPLING * onion) {
            return None;
        }
        let quarter = Blocks::new(j, 0.25 * dt)?;
        let half = quarter.doubled();
        let full = half.doubled();
        let whole = etd_rk4_blocks(y, start.f, dt, j, &half, &full, rate);
        let first = etd_rk4_blocks(y, start.f, 0.5 * dt, j, &quarter, &half, rate);
        let two = etd_rk4_blocks(&first, rate(&first), 0.5 * dt, j, &quarter, &half, rate);
        let err = self.error_norm(|i| two[i] - whole[i], y, &two);
        Some((two, err))
    }

    /// The onion leaves its bounds within the substep of `dt` from `run`'s state
    /// ([`Self::onion_leaves_bounds`]). The first time at this state, the ringing's own checks
    /// come first ([`Self::follows_branch`] at the next pass, the averaged ringing's included):
    /// ringing trapped in its well that decays within the segment is dropped there unflagged,
    /// the tilt's excursion beyond the bound being transient. If they do not drop it, the same
    /// substep is refused again and the onion escapes: the step is flagged and the next pass
    /// drops its ringing from here, as where the smallest substep leaves the bounds.
    pub(super) fn leave_bounds(run: &mut StepRun, dt: f64) {
        run.dt = dt;
        if run.bounds_exit_at != run.t {
            run.bounds_exit_at = run.t;
            run.average_check_at = run.attempts;
            return;
        }
        run.limited = true;
        run.settled = false;
        run.onion_escaped = true;
    }
}

/// The onion's tilt bound (rad), as [`Motor::onion_sane`] holds it.
const MAX_TILT: f64 = 10.0;

/// Two settles closer than this (rad) found the same minimum (minima are at least a fraction
/// of a turn apart; the rotor's turn over a substep moves one far less).
const SAME_MINIMUM: f64 = 1e-3;

#[cfg(test)]
thread_local! {
    /// Turns the exit off for a locked rotor (tests compare it with the smallest substep's).
    pub(super) static LOCKED_EXIT_OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}
