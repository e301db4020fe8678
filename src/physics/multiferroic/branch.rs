//! Following one branch of the quasi-static onion (section 3.2.2) without ever jumping to another:
//! what Model Exchange needs between events, where an integrator evaluates the right-hand side at
//! trial states and must see a smooth function of them.
//!
//! [`Landscape::settle`] goes downhill from where the onion was to whatever minimum lies there,
//! crossing a vanished minimum's remains (a fold) to the next one: the jump. [`Landscape::follow`]
//! goes downhill from the same starting point (an anchor: a minimum of the branch at a nearby
//! state) but stops where the branch's minimum no longer exists. Write `h(s) = dir U'(psi0 + dir s)`
//! (negative downhill). Past a fold, the minimum and the maximum that bounded its basin have
//! merged and left a "ghost": a local maximum of `h` that stays below zero, i.e. an inflection
//! (`U'' = 0`, curvature turning from positive to negative) with the gradient still downhill.
//! Before the fold, the march reaches the minimum (`h = 0`) while the curvature is still positive.
//! So the branch exists exactly when the march meets `h = 0` before such an inflection.
//!
//! The fold's event indicator ([`Branch::fold_distance`]) is the curvature at the minimum
//! (positive, falling like the square root of the distance to the fold) and, past the fold,
//! `-sqrt(2 M |U'|)` at the ghost (`M` the third-derivative bound): the two meet at zero, so the
//! indicator is continuous and changes sign exactly at the fold.

use super::onion::Landscape;

/// Cap on the strides of one [`Landscape::follow`] (as for the settle's march).
const MAX_STRIDES: usize = 2000;
/// Look-back strides from a concave anchor (rad), and how far back to look.
const LOOK_BACK_STRIDE: f64 = 2e-3;
const LOOK_BACK_RANGE: f64 = 0.5;

/// Where the branch of the quasi-static onion is, for one landscape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Branch {
    /// The branch's minimum of eq. 3.3 plus eq. 3.4: `dU/dpsi = 0`, `curvature = d2U/dpsi2 > 0`.
    Minimum { angle: f64, curvature: f64 },
    /// The minimum has vanished at a fold; `ghost` is the inflection it left (`d2U/dpsi2 = 0`)
    /// and `gradient` the nonzero `dU/dpsi` there.
    Vanished { ghost: f64, gradient: f64 },
}

impl Branch {
    /// The onion angle the branch gives: the minimum, or past the fold its ghost (the continuous
    /// extension until the event moves the onion).
    pub fn angle(&self) -> f64 {
        match *self {
            Branch::Minimum { angle, .. } => angle,
            Branch::Vanished { ghost, .. } => ghost,
        }
    }

    /// Signed distance to the fold (J/rad^2): the curvature at the minimum, `-sqrt(2 M |U'|)` at the
    /// ghost. Zero at the fold and continuous across it; `third_derivative_bound` is `M`.
    pub fn fold_distance(&self, third_derivative_bound: f64) -> f64 {
        match *self {
            Branch::Minimum { curvature, .. } => curvature,
            Branch::Vanished { gradient, .. } => {
                -(2.0 * third_derivative_bound * gradient.abs()).sqrt()
            }
        }
    }
}

impl Landscape<'_> {
    /// The branch's minimum reached downhill from `anchor`, or the ghost if it vanished (see the
    /// module documentation). Strides are those of [`Landscape::settle`]: no root of the gradient
    /// is stepped over; in addition, while the curvature is positive the stride stays where it
    /// provably remains positive, and a stride that may leave that region checks its end, so an
    /// inflection on the way is found.
    pub fn follow(&self, anchor: f64) -> Branch {
        let g0 = self.gradient(anchor);
        let c0 = self.curvature(anchor);
        let tiny = self.gradient_tolerance();
        let m = self.third_derivative_bound();
        if (g0.abs() <= tiny && c0 > 0.0) || !(m.is_finite() && m > 0.0) {
            return Branch::Minimum {
                angle: anchor,
                curvature: c0,
            };
        }
        let dir = if g0 > tiny { -1.0 } else { 1.0 };
        if c0 <= 0.0 {
            if let Some(ghost) = self.ghost_behind(anchor, dir) {
                return ghost;
            }
        }
        let (mut x, mut g, mut c) = (anchor, g0, c0);
        for _ in 0..MAX_STRIDES {
            let a = (-dir * g).max(0.0);
            // Inside the window the curvature stays positive and `h` rises: a stride that ends
            // uphill holds exactly the minimum. Outside it only `safe` is sure not to hold a root.
            let (stride, in_window) = super::onion::downhill_stride(a, c, m);
            if !(stride.is_finite() && stride > 0.0) {
                break;
            }
            let end = x + dir * stride;
            if end == x {
                break;
            }
            let g_end = self.gradient(end);
            let c_end = self.curvature(end);
            if !in_window && c > 0.0 && c_end <= 0.0 && dir * g_end < 0.0 {
                // The curvature turned negative with the gradient still downhill: a ghost.
                return self.ghost_between(x, end);
            }
            if dir * g_end >= 0.0 {
                let angle = self.refine_minimum(x, end);
                return Branch::Minimum {
                    angle,
                    curvature: self.curvature(angle),
                };
            }
            (x, g, c) = (end, g_end, c_end);
        }
        Branch::Minimum {
            angle: x,
            curvature: self.curvature(x),
        }
    }

    /// From a concave anchor, looks uphill (against `dir`): reaching the maximum first (the
    /// gradient changes sign) means the anchor is on its basin's shoulder and the march ahead
    /// finds the minimum; reaching positive curvature with the gradient still downhill means the
    /// anchor is just past a ghost.
    fn ghost_behind(&self, anchor: f64, dir: f64) -> Option<Branch> {
        let mut x = anchor;
        let steps = (LOOK_BACK_RANGE / LOOK_BACK_STRIDE) as usize;
        for _ in 0..steps {
            let back = x - dir * LOOK_BACK_STRIDE;
            if dir * self.gradient(back) >= 0.0 {
                return None;
            }
            if self.curvature(back) > 0.0 {
                return Some(self.ghost_between(back, x));
            }
            x = back;
        }
        None
    }

    /// The inflection between `a` (positive curvature) and `b` (not positive), by bisection.
    fn ghost_between(&self, a: f64, b: f64) -> Branch {
        let (mut lo, mut hi) = (a, b);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            if self.curvature(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let ghost = 0.5 * (lo + hi);
        Branch::Vanished {
            ghost,
            gradient: self.gradient(ghost),
        }
    }
}
