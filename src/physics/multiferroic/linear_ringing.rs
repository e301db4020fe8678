//! A locked rotor's Gilbert onion ringing at small amplitude about its well's minimum, advanced
//! over the rest of the segment by the exact propagator of eq. 3.4's linearization
//! ([`Motor::advance_linear_ringing`]).

use super::onion_linear::{apply, flow, M2};
use super::step::StepRun;
use super::{Drive, Motor};

/// Part of the tolerance the stated bound of the dropped anharmonic terms may take.
const BOUND_SHARE: f64 = 0.1;
/// Largest `|U'''| a / U''` (and `|U''''| a^2 / U''`) taken: the expansion's terms fall by at
/// least this factor each, so the first dropped ones dominate their bound.
const MAX_EXPANSION: f64 = 1e-3;
/// Step (rad) of the central differences of `U''` giving `U'''` and `U''''` at the minimum.
const DIFFERENCE_STEP: f64 = 1e-3;
/// The propagator is tried where at least this many of the shortest orbits
/// ([`Motor::period_floor`]) are left in the segment.
const MIN_ORBITS: f64 = 8.0;
/// Margin on the finite-difference derivatives (their truncation is `O(s^2)` of the next one).
const DERIVATIVE_MARGIN: f64 = 2.0;

#[cfg(test)]
thread_local! {
    /// Segments ended by [`Motor::advance_linear_ringing`] on this thread (for tests).
    pub(super) static TAKEN: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Turns [`Motor::advance_linear_ringing`] off on this thread (for tests: the other paths).
    pub(super) static OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

impl Motor {
    /// Ends the segment at once when the rotor is locked and the Gilbert onion rings about its
    /// well's minimum `psi*` so little that eq. 3.4 is linear there to within a tenth of the
    /// tolerance over the rest of the segment. `true` if taken.
    ///
    /// With `delta = psi - psi*`, `U'(psi) = g0 + k delta + R` (`k = U''(psi*)`, `g0` the gradient
    /// left at the computed minimum), the macrospin's rates `psi' = -g (a U' + T theta)`,
    /// `theta' = g (U' - a T theta)` (eq. 3.4's Gilbert form) are an exact affine flow in
    /// `(delta, theta)` once `R` is dropped ([`flow`]). The linear ringing's energy
    /// `k delta^2 / 2 + T theta^2 / 2` only falls, so `|delta| <= A = sqrt(2 E / k)` on it. The
    /// dropped `R = U''' delta^2 / 2 + U'''' delta^3 / 6 + ...` acts on the oscillator
    /// `delta'' = -g^2 T U'` (`a = 0`, `omega^2 = g^2 T k`); by Lindstedt-Poincare its bounded
    /// response is the quadratic term's offset `U''' A^2 / (4 k)` and second harmonic
    /// `U''' A^2 / (12 k)` plus the fundamental matching the start (at most 0.37 of
    /// `U''' A^2 / k`), and the cubic's third harmonic `U'''' A^3 / (192 k)` plus its match (at
    /// most three times that); its resonant part shifts the frequency by
    /// `(U'''' / (16 k) - 5 U'''^2 / (48 k^2)) A^2` relative, which moves the onion by at most `A`
    /// times that over the `omega t` radians left, and the damping's loss (rate
    /// `g a (k + T) / 2`) by a like relative part. The bound taken is `|U'''| A^2 / k +
    /// |U''''| A^3 / (48 k) + (omega + g a (k + T) / 2) t A^3 (|U''''| / (8 k) +
    /// U'''^2 / (4 k^2))`, times `1 + a` (the damping's share of `R`) and `max(1, sqrt(k / T))`
    /// for the tilt (`theta = -delta' / (g T)` at `a = 0`), with `U'''`, `U''''` central
    /// differences of `U''` at the minimum taken twice over ([`DERIVATIVE_MARGIN`]); only where
    /// the expansion's next terms are smaller still by [`MAX_EXPANSION`].
    pub(super) fn advance_linear_ringing(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
    ) -> bool {
        #[cfg(test)]
        if OFF.with(|c| c.get()) {
            return false;
        }
        if !d.locked || self.quasi_static() || segment_end.is_nan() || segment_end <= run.t {
            return false;
        }
        if run.linear_wait.0 == segment_end && run.t < run.linear_wait.1 {
            return false;
        }
        // Fewer orbits than this left are resolved at about the cost of the try.
        let land = self.landscape(run.y[0], d.direction, d.stress);
        if segment_end - run.t < MIN_ORBITS * self.period_floor(&land) {
            return false;
        }
        let y = match self.linear_ringing_end(&run.y, d, segment_end - run.t) {
            Ok(y) => y,
            Err(wait) => {
                run.linear_wait = (segment_end, run.t + wait);
                return false;
            }
        };
        if !Self::onion_sane(&y) {
            return false;
        }
        run.jump_onion_to(y, segment_end, segment_end);
        run.following = f64::NAN;
        #[cfg(test)]
        TAKEN.with(|c| c.set(c.get() + 1));
        true
    }

    /// The state `h` seconds on by the linear propagator, where its bound (see
    /// [`Self::advance_linear_ringing`]) is within [`BOUND_SHARE`] of the tolerance; else the
    /// time the ringing takes at least to fall to where the bound would hold over `h` (it grows
    /// at least as `A^2`, the expansion's check as `A`), with `A` falling at most at
    /// `2 g a max(k, T)`: twice the linear ringing's fastest instantaneous rate, four times its
    /// orbits' rate, which the nonlinear orbits' approaches from below (`locked_ringing.rs`).
    /// (The shorter time left may let it hold earlier; that chance is given up.)
    pub(super) fn linear_ringing_end(
        &self,
        y: &super::Vector,
        d: &Drive,
        h: f64,
    ) -> Result<super::Vector, f64> {
        let land = self.landscape(y[0], d.direction, d.stress);
        let (g, a, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let minimum = land.settle(y[2]);
        let (g0, k) = land.gradient_curvature(minimum);
        if !(k > 0.0 && t > 0.0 && g > 0.0 && k.is_finite() && g0.is_finite()) {
            return Err(0.0);
        }
        let w = [y[2] - minimum, y[3]];
        let amplitude = ((w[0] * w[0] * k + w[1] * w[1] * t) / k).sqrt();
        let s = DIFFERENCE_STEP;
        let (up, down) = (land.curvature(minimum + s), land.curvature(minimum - s));
        let u3 = DERIVATIVE_MARGIN * (up - down).abs() / (2.0 * s);
        let u4 = DERIVATIVE_MARGIN * (up - 2.0 * k + down).abs() / (s * s);
        // (The margin also covers the differences' truncation, `O(s^2)` of the next derivative.)
        let expansion = (u3 * amplitude / k).max(u4 * amplitude * amplitude / k);
        let decay = 0.5 * g * a * (k + t);
        let fastest = 2.0 * g * a * k.max(t);
        // (`0` where the rate vanishes or anything is not finite: tried again at the next pass.)
        let wait = |ln_ratio: f64| {
            let w = ln_ratio / fastest;
            if w.is_finite() && w > 0.0 {
                w
            } else {
                0.0
            }
        };
        if expansion.is_nan() || expansion > MAX_EXPANSION {
            return Err(wait((expansion / MAX_EXPANSION).ln()));
        }
        let omega = g * (k * t).sqrt();
        let a2 = amplitude * amplitude;
        let bounded = u3 * a2 / k + u4 * a2 * amplitude / (48.0 * k);
        let secular =
            (omega + decay) * h * a2 * amplitude * (u4 / (8.0 * k) + u3 * u3 / (4.0 * k * k));
        let bound = (bounded + secular) * (1.0 + a) * (k / t).sqrt().max(1.0);
        let target = BOUND_SHARE * self.params.tolerance;
        if bound.is_nan() || bound > target {
            return Err(wait(0.5 * (bound / target).ln()));
        }
        let am: M2 = [[-g * a * k, -g * t], [g * k, -g * a * t]];
        let b = [-g * a * g0, g * g0];
        let f = flow(&am, h).ok_or(0.0)?;
        let (ew, jb) = (apply(&f.e, w), apply(&f.j, b));
        let end = [y[0], y[1], minimum + ew[0] + jb[0], ew[1] + jb[1]];
        if end.iter().all(|v| v.is_finite()) {
            Ok(end)
        } else {
            Err(0.0)
        }
    }
}
