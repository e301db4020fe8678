//! Quasi-static onion state (section 3.2.2): it settles at the minimum of eq. 3.4 that it reaches
//! by going downhill from its previous orientation, i.e. the minimum of the basin it is in (the
//! nearest one, as the text says, unless a barrier lies between). When that minimum disappears
//! (a fold), the same rule carries it downhill to the next one.
//!
//! Hand-written (expanding downhill bracket, then safeguarded Newton) rather than a library
//! minimizer: it runs on the per-substep hot path, must respect the memory rule (a global
//! minimizer would not), and every loop is capped.

use super::magnetics::RingBar;

/// Largest bracket stride (rad): small enough not to stride over a basin of the eq. 3.4 landscape
/// (features are tens of degrees wide) except right at a fold, where the basin is vanishing.
const MAX_STRIDE: f64 = 0.05;
/// Expanding-search cap: more than a full turn at the largest stride.
const MAX_BRACKET_STEPS: usize = 200;
const MAX_REFINE_STEPS: usize = 100;

/// Energy landscape of eq. 3.4 in the onion angle, for a fixed bar angle and strain.
#[derive(Clone, Copy, Debug)]
pub struct Landscape<'a> {
    pub ring_bar: &'a RingBar,
    /// Bar (rotor) angle (rad).
    pub bar_angle: f64,
    /// Direction of the principal tension (rad).
    pub strain_direction: f64,
    /// `(3/2) lambda_s sigma V_wall` (J): the magnetoelastic energy is `E sin^2(psi - gamma)`.
    pub magnetoelastic: f64,
}

impl Landscape<'_> {
    /// `dU/dpsi` (J/rad).
    #[inline]
    pub fn gradient(&self, onion: f64) -> f64 {
        self.ring_bar.torque(onion - self.bar_angle)
            + self.magnetoelastic * (2.0 * (onion - self.strain_direction)).sin()
    }

    /// `d^2U/dpsi^2` (J/rad^2).
    #[inline]
    pub fn curvature(&self, onion: f64) -> f64 {
        self.ring_bar.stiffness(onion - self.bar_angle)
            + 2.0 * self.magnetoelastic * (2.0 * (onion - self.strain_direction)).cos()
    }

    /// The minimum reached downhill from `previous` (rad, unwrapped: the result stays on the same
    /// branch, so the onion angle is continuous).
    pub fn settle(&self, previous: f64) -> f64 {
        let g0 = self.gradient(previous);
        let c0 = self.curvature(previous);
        // Gradients below this are zero to rounding: the torques involved are ~1e-18 N m.
        let tiny = 1e-12 * (self.ring_bar.coupling / self.ring_bar.wall_radius).abs()
            + 1e-12 * self.magnetoelastic.abs();
        if g0.abs() <= tiny && c0 > 0.0 {
            return previous;
        }
        // Downhill direction; from a maximum (zero gradient, negative curvature) go forward.
        let dir = if g0 > tiny { -1.0 } else { 1.0 };
        let mut stride = if c0 > 0.0 {
            (1.5 * g0.abs() / c0).clamp(1e-9, MAX_STRIDE)
        } else {
            1e-3
        };
        let mut lo = previous;
        let mut hi = previous;
        let mut bracketed = false;
        for _ in 0..MAX_BRACKET_STEPS {
            hi = lo + dir * stride;
            if dir * self.gradient(hi) >= 0.0 {
                bracketed = true;
                break;
            }
            lo = hi;
            stride = (2.0 * stride).min(MAX_STRIDE);
        }
        if !bracketed {
            // A landscape flat to rounding over a full turn: nothing pulls the onion state.
            return previous;
        }
        self.refine(lo, hi, dir)
    }

    /// Root of the gradient between `lo` (downhill side, `dir * g < 0`) and `hi` (`dir * g >= 0`).
    fn refine(&self, mut lo: f64, mut hi: f64, dir: f64) -> f64 {
        let mut x = 0.5 * (lo + hi);
        for _ in 0..MAX_REFINE_STEPS {
            let g = self.gradient(x);
            let c = self.curvature(x);
            let converged = c > 0.0 && (g / c).abs() <= 1e-15 * (1.0 + x.abs());
            if converged || (hi - lo).abs() <= 1e-15 * (1.0 + x.abs()) {
                return x;
            }
            if dir * g < 0.0 {
                lo = x;
            } else {
                hi = x;
            }
            let newton = x - g / c;
            let inside = (newton - lo) * (newton - hi) < 0.0;
            x = if c > 0.0 && newton.is_finite() && inside {
                newton
            } else {
                0.5 * (lo + hi)
            };
        }
        x
    }
}
