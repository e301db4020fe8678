//! Quasi-static onion state (section 3.2.2): it settles at the minimum of eq. 3.4 that it reaches
//! by going downhill from its previous orientation, i.e. the minimum of the basin it is in (the
//! nearest one, as the text says, unless a barrier lies between). When that minimum disappears
//! (a fold), the same rule carries it downhill to the next one.
//!
//! Hand-written (a downhill march whose strides provably cannot cross a root of the gradient,
//! then the shared safeguarded Newton-bisection) rather than a library minimizer: it runs on the
//! per-substep hot path, must respect the memory rule (a global minimizer would not), and every
//! loop is capped.
//!
//! Why the march is safe (a fixed 0.05 rad stride would step over basins less than 1 degree
//! wide near a fold, leaving the onion at a far minimum). Write `h(s) = dir U'(psi0 + dir s)`,
//! negative while going downhill, with `h'(s) = U''(psi0 + dir s)` and `|h''| <= M`, a bound on
//! the third derivative of U. With `a = -h(0)` and `c = h'(0)`:
//! - `h` stays negative for `s < s_safe = (sqrt(c^2 + 2 M a) - c) / M`;
//! - `h` is increasing on `[0, c / M)`, so a trial stride inside that window that ends with
//!   `h >= 0` holds exactly one root (the first minimum), and one that ends with `h < 0` none.
//!
//! Either way no minimum is ever stepped over, and near a simple minimum `s_safe` is the Newton
//! step to second order, so the march costs one or two evaluations in the usual case.

use super::angles::turned_back;
use super::angles::Angles;
use super::magnetics::RingBar;

/// Cap on the downhill march (a full turn far from any minimum takes a few dozen strides).
const MAX_MARCH_STEPS: usize = 2000;
/// Cap on the Newton-bisection refinement of a bracketed minimum.
const MAX_REFINE_ITERATIONS: usize = 100;
/// Samples per turn for [`curvature_slope_bound`].
const BOUND_SAMPLES: usize = 7200;

/// An upper bound of the third derivative of eq. 3.3's ring-bar energy in the offset (J/rad^3):
/// the sampled maximum of the stiffness's finite-difference slope with a 25% margin (the function
/// is smooth on a scale of `(r - a) / r` rad, far coarser than the 0.05 degree samples).
pub fn curvature_slope_bound(ring_bar: &RingBar) -> f64 {
    let h = 2.0 * std::f64::consts::PI / BOUND_SAMPLES as f64;
    let mut max = 0.0f64;
    let mut previous = ring_bar.stiffness(-h);
    for i in 0..=BOUND_SAMPLES {
        let k = ring_bar.stiffness(i as f64 * h);
        max = max.max((k - previous).abs() / h);
        previous = k;
    }
    1.25 * max
}

#[cfg(test)]
thread_local! {
    /// Settles ([`Landscape::settle_from`], [`Landscape::settle_from_slope`]; tests count them).
    pub(super) static SETTLES: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    /// Evaluations of the landscape's gradient or curvature (tests count them).
    pub(super) static EVALUATIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Counts one evaluation of the landscape in tests.
#[inline]
fn count_evaluation() {
    #[cfg(test)]
    EVALUATIONS.with(|c| c.set(c.get() + 1));
}

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
    /// [`curvature_slope_bound`] of `ring_bar` (J/rad^3).
    pub ring_bar_slope_bound: f64,
}

impl Landscape<'_> {
    /// `dU/dpsi` (J/rad).
    #[inline]
    pub fn gradient(&self, onion: f64) -> f64 {
        count_evaluation();
        self.ring_bar.torque(onion - self.bar_angle)
            + self.magnetoelastic * turned_back(2.0 * (onion - self.strain_direction)).sin()
    }

    /// `d^2U/dpsi^2` (J/rad^2).
    #[inline]
    pub fn curvature(&self, onion: f64) -> f64 {
        count_evaluation();
        self.ring_bar.stiffness(onion - self.bar_angle)
            + 2.0 * self.magnetoelastic * turned_back(2.0 * (onion - self.strain_direction)).cos()
    }

    /// [`Self::gradient`] and [`Self::curvature`] together, from one `sin_cos` of each angle.
    #[inline]
    pub fn gradient_curvature(&self, onion: f64) -> (f64, f64) {
        self.gradient_curvature_of(&self.angles(onion))
    }

    /// [`Self::gradient_curvature`] from the angles' sines and cosines (no trigonometry).
    #[inline]
    pub fn gradient_curvature_of(&self, a: &Angles) -> (f64, f64) {
        count_evaluation();
        let (tau, k) = self
            .ring_bar
            .torque_stiffness_of(a.sin_offset, a.cos_offset);
        (
            tau + self.magnetoelastic * a.sin_double,
            k + 2.0 * self.magnetoelastic * a.cos_double,
        )
    }

    /// The angles of this landscape at `onion`, fresh from libm.
    pub fn angles(&self, onion: f64) -> Angles {
        Angles::exact(onion, self.bar_angle, self.strain_direction)
    }

    /// Energy relative to an arbitrary constant (J): eq. 3.3 plus eq. 3.4's wall term.
    pub fn energy(&self, onion: f64) -> f64 {
        let s = turned_back(onion - self.strain_direction).sin();
        self.ring_bar.energy(onion - self.bar_angle) + self.magnetoelastic * s * s
    }

    /// Bound on the third derivative of U in psi (J/rad^3): the ring-bar's plus `4 |E|`.
    pub(super) fn third_derivative_bound(&self) -> f64 {
        self.ring_bar_slope_bound + 4.0 * self.magnetoelastic.abs()
    }

    /// Gradients below this are zero to rounding (J/rad): the torques involved are ~1e-18 N m.
    pub(super) fn gradient_tolerance(&self) -> f64 {
        1e-12 * (self.ring_bar.coupling / self.ring_bar.wall_radius).abs()
            + 1e-12 * self.magnetoelastic.abs()
    }

    /// The onion angle's root tolerance (rad): 1e-15 absolute plus relative to the largest of the
    /// angles. The gradient sees the onion only through `psi - phi` and `psi - gamma`, whose
    /// spacing is that of the larger angle: with a rotor 1e12 rad out (a restored or fuzzed state)
    /// the gradient is a staircase of 1e-4 rad treads, where a tolerance relative to `psi` alone
    /// sent every refinement through 35 bisections.
    #[inline]
    pub(super) fn root_tolerance(&self, onion: f64) -> f64 {
        let largest = onion
            .abs()
            .max(self.bar_angle.abs())
            .max(self.strain_direction.abs());
        1e-15 * (1.0 + largest)
    }

    /// The minimum reached downhill from `previous` (rad, unwrapped: the result stays on the same
    /// branch, so the onion angle is continuous). Never steps over a minimum (see the module
    /// documentation), so the onion settles in the basin it is in, however narrow.
    ///
    /// Inside the monotone window (positive curvature, `h` increasing) a stride up to the window's
    /// edge is safe, so the march takes the Newton step there: each evaluation is then a Newton
    /// iteration, and the usual settle (the rotor moved a little) costs two or three evaluations.
    pub fn settle(&self, previous: f64) -> f64 {
        self.settle_from(self.angles(previous)).onion
    }

    /// [`Self::settle`] from `start`, the angles at the previous onion angle for this landscape,
    /// returning the angles at the minimum: each evaluation turns the last one's angles (see
    /// [`Angles::moved`]) instead of calling libm.
    pub fn settle_from(&self, start: Angles) -> Angles {
        let (g0, c0) = self.gradient_curvature_of(&start);
        self.march_from(start, g0, c0)
    }

    /// [`Self::settle_from`] where the gradient `g0` and curvature `c0` at `start` are known
    /// ([`Self::gradient_curvature_of`] of it): the same march, without evaluating them again.
    pub(super) fn settle_from_slope(&self, start: Angles, g0: f64, c0: f64) -> Angles {
        self.march_from(start, g0, c0)
    }

    /// The settle's march and refinement from `start`, where the gradient is `g0` and the
    /// curvature `c0` (inlined into both entries, so the common one keeps its code).
    #[inline(always)]
    fn march_from(&self, start: Angles, g0: f64, c0: f64) -> Angles {
        #[cfg(test)]
        SETTLES.with(|c| c.set(c.get() + 1));
        let tiny = self.gradient_tolerance();
        if g0.abs() <= tiny && c0 > 0.0 {
            return start;
        }
        // Downhill direction; from a maximum (zero gradient, negative curvature) go forward.
        let dir = if g0 > tiny { -1.0 } else { 1.0 };
        let m = self.third_derivative_bound();
        if !(m.is_finite() && m > 0.0) {
            return start;
        }
        let (mut x, mut g, mut c) = (start, g0, c0);
        for _ in 0..MAX_MARCH_STEPS {
            // h(0) = dir g = -a <= 0 (downhill), h'(0) = c.
            let a = (-dir * g).max(0.0);
            let newton = a / c;
            let stride = if c > 0.0 && newton < 0.99 * c / m {
                // Newton's next error is at most M s^2 / (2 c') with c' >= c / 100 in the window:
                // below the root finder's tolerance, the step lands on the minimum.
                if m * newton * newton <= 0.02 * c * self.root_tolerance(x.onion) {
                    return x.at_onion(x.onion + dir * newton);
                }
                newton
            } else {
                downhill_stride(a, c, m).0
            };
            if !(stride.is_finite() && stride > 0.0) {
                break;
            }
            let end = x.at_onion(x.onion + dir * stride);
            if end.onion == x.onion {
                break;
            }
            let (g_end, c_end) = self.gradient_curvature_of(&end);
            if dir * g_end >= 0.0 {
                let (lo, hi) = if dir > 0.0 {
                    (x.onion, end.onion)
                } else {
                    (end.onion, x.onion)
                };
                return self.refine(lo, hi, end, g_end, c_end);
            }
            (x, g, c) = (end, g_end, c_end);
        }
        // A landscape flat to rounding, or a degenerate fold: stay where the march stopped.
        x
    }

    /// The maxima of eq. 3.4 on either side of the minimum `minimum` (rad), the rims of its well
    /// (below then above it): the downhill settle of the reversed landscape, started `inside` rad
    /// from the minimum on either side, where the slope must already rise away from it. With a
    /// single well per turn both are the same maximum, a turn apart.
    pub(super) fn well_rims(&self, minimum: f64, inside: f64) -> (f64, f64) {
        let ring_bar = RingBar {
            coupling: -self.ring_bar.coupling,
            ..*self.ring_bar
        };
        let reversed = Landscape {
            ring_bar: &ring_bar,
            magnetoelastic: -self.magnetoelastic,
            ..*self
        };
        (
            reversed.settle(minimum - inside),
            reversed.settle(minimum + inside),
        )
    }

    /// The minimum between `a` and `b`, where the gradient changes sign from downhill to uphill.
    pub(super) fn refine_minimum(&self, a: f64, b: f64) -> f64 {
        let x = self.angles(0.5 * (a + b));
        let (g, c) = self.gradient_curvature_of(&x);
        self.refine(a.min(b), a.max(b), x, g, c).onion
    }

    /// Safeguarded Newton-bisection for the minimum in `[lo, hi]` (the gradient rises through
    /// zero there) from `x` in it, where the gradient is `g` and the curvature `c`. A Newton step
    /// whose successor's error (`M s^2 / (2 c)`) is below the tolerance is taken without a
    /// further evaluation.
    fn refine(&self, mut lo: f64, mut hi: f64, mut x: Angles, mut g: f64, mut c: f64) -> Angles {
        let m = self.third_derivative_bound();
        for _ in 0..MAX_REFINE_ITERATIONS {
            if g == 0.0 {
                return x;
            }
            if g < 0.0 {
                lo = x.onion;
            } else {
                hi = x.onion;
            }
            let tolerance = self.root_tolerance(x.onion);
            let step = -g / c;
            let next = x.onion + step;
            let newton_ok = c > 0.0 && next > lo && next < hi;
            // A converged step may end on the bracket's end: the march hands over its last point,
            // often the root itself (its gradient rounding to either sign), as `hi` or `lo`.
            // Testing it against the open bracket sent such calls through ~25 bisections.
            let converged = step.abs() <= tolerance || m * step * step <= c * tolerance;
            if converged && c > 0.0 && next >= lo && next <= hi {
                return x.at_onion(next);
            }
            if hi - lo <= tolerance {
                return x.at_onion(0.5 * (lo + hi));
            }
            x = x.at_onion(if newton_ok { next } else { 0.5 * (lo + hi) });
            (g, c) = self.gradient_curvature_of(&x);
        }
        x
    }
}

/// The stride a downhill march may take from a point where the gradient along the march is `-a`
/// (`a >= 0`) and the curvature `c`, when the third derivative is bounded by `m`: `safe` is the
/// root of `-a + c s + m s^2 / 2`, the shortest distance at which the minimum could lie. Inside
/// the monotone window (the curvature stays positive) twice that is still safe, so the second
/// value says whether the stride lies inside it.
pub(super) fn downhill_stride(a: f64, c: f64, m: f64) -> (f64, bool) {
    let safe = ((c * c + 2.0 * m * a).sqrt() - c) / m;
    let window = 0.99 * c / m;
    let in_window = c > 0.0 && window > safe;
    let stride = if in_window {
        (2.0 * safe).min(window)
    } else {
        safe
    };
    (stride, in_window)
}
