//! The free bladder: below the threshold pressure it does not touch the sleeve and its outer
//! diameter solves eq. 2.18 (generalised to the layers); whether losing contact is gradual.

use super::{Bladder, SleeveGeometry};
use crate::physics::numerics::dual::Dual;
use crate::physics::numerics::root::{newton_bisection, RootOptions, Sample};

/// Iteration cap of the free-bladder root finder (safeguarded Newton-bisection converges in <10).
const ROOT_ITERATIONS: usize = 100;
/// Halvings of the way to collapse searched for the collapsed side of the free-bladder bracket
/// under vacuum.
const BRACKET_HALVINGS: usize = 200;

impl<S: SleeveGeometry> Bladder<S> {
    /// Whether the free bladder's equilibrium pressure rises with its diameter at the sleeve's
    /// diameter (at `length`), i.e. whether losing contact is gradual rather than a snap.
    ///
    /// For one layer this always holds: eq. 2.18 gives the free equilibrium pressure
    /// `P = 2 (C1/l1 + C2 l1) (u - a/u) / (c + r u)` with `u = l2^2`, `a = 1/l1^2`, `c = 1/l1`,
    /// `r = D_RI/(D_RO - D_RI)`, whose `u`-derivative has the sign of `c + a c/u^2 + 2 r a/u > 0`.
    /// (With the sleeve's clamps fixing `l1`, the tube has no balloon limit point.) For layered
    /// walls it is checked by a property test over random tubes. `Err` outside the length range.
    pub fn free_contact_is_stable(&self, length: f64) -> Result<bool, String> {
        self.check_length(length)?;
        let (_, x) = self.contact_seed(length);
        // P_hold = c/a; its x-slope has the sign of (c' a - c a').
        let k = self
            .kernel(0.0, Dual::var_l(length), Dual::var_x(x.v))
            .ok_or_else(|| self.domain_error(length))?;
        Ok(k.c.dx * k.a.v - k.c.v * k.a.dx > 0.0)
    }

    /// Outer diameter of the free bladder (eq. 2.18 generalised to the layers): the root of
    /// `P_eff(x) = 0` for `x` below the sleeve's diameter `x_contact`, where `P_eff < 0`.
    /// Hand-written safeguarded Newton-bisection on the analytic slope, for speed on the per-step
    /// path; every loop is capped.
    pub(super) fn free_outer_diameter(
        &self,
        pressure: f64,
        length: f64,
        x_contact: f64,
    ) -> Result<f64, String> {
        let lambda1 = length / self.tube.unstretched_length;
        let d_ro = self.outer_diameter;
        let d_ri = self.tube.inner_diameter;
        // Inner wall collapses at x_min; all layers are unstrained at x_rest = D_RO/sqrt(lambda_1),
        // where P_eff = P (a = 1... times P, c = 0), so for P > 0 the root lies above x_rest.
        let x_min = ((d_ro * d_ro - d_ri * d_ri) / lambda1).sqrt();
        let x_rest = d_ro / lambda1.sqrt();
        let residual = |x: f64| {
            self.kernel(pressure, Dual::var_l(length), Dual::var_x(x))
                .map(|k| (k.p_eff.v, k.p_eff.dx))
        };
        let hi = x_contact;
        let start = if x_rest < hi { x_rest } else { hi };
        // The collapsed side of the bracket: the first of the points halving the way from `start`
        // to x_min where P_eff >= 0. P_eff falls as x grows, so "P_eff >= 0, or x_min reached"
        // holds from that point on: found by doubling then bisecting the halving count (about
        // 2 log2 of it evaluations, not one per halving: under a deep vacuum the root sits
        // dozens of halvings deep).
        let point = |j: usize| {
            if j == 0 {
                start
            } else {
                x_min + (start - x_min) * 0.5f64.powi(j as i32)
            }
        };
        // Some(r) with r >= 0 where found, None where not yet (P_eff < 0), Err at x_min.
        let probe = |j: usize| -> Result<Option<f64>, ()> {
            let x = point(j);
            match residual(x) {
                Some((r, _)) if r >= 0.0 => Ok(Some(r)),
                _ if x > x_min => Ok(None),
                _ => Err(()),
            }
        };
        let past = |p: &Result<Option<f64>, ()>| !matches!(p, Ok(None));
        let last = BRACKET_HALVINGS - 1;
        let (mut below, mut found) = (None, None);
        let mut j = 0;
        loop {
            let p = probe(j);
            if past(&p) {
                found = Some((j, p));
                break;
            }
            below = Some(j);
            if j == last {
                break;
            }
            j = (2 * j).clamp(1, last);
        }
        // Bisect between the last count short of it and the first past it.
        if let (Some(mut short), Some((mut at, mut p))) = (below, found) {
            while at - short > 1 {
                let mid = short + (at - short) / 2;
                let q = probe(mid);
                if past(&q) {
                    (at, p) = (mid, q);
                } else {
                    short = mid;
                }
            }
            found = Some((at, p));
        }
        let Some((lo, r_lo)) = found.and_then(|(j, p)| Some((point(j), p.ok()??))) else {
            return Err(format!(
                "pressure {pressure} Pa at length {length} m: the free bladder has no equilibrium \
                 short of collapse (vacuum too deep; collapse is not modelled)"
            ));
        };
        if r_lo == 0.0 {
            return Ok(lo);
        }
        // Newton from the unstrained side (seen to approach monotonically, ~6 steps); P_eff falls
        // from positive at `lo` to negative at `hi`.
        let options = RootOptions {
            absolute: 0.0,
            relative: 1e-14,
            max_iterations: ROOT_ITERATIONS,
        };
        let root = newton_bisection(lo, hi, lo, false, options, |x| {
            Ok::<_, ()>(residual(x).map(|(value, slope)| Sample {
                value,
                slope,
                payload: (),
            }))
        });
        Ok(root.map_or(0.5 * (lo + hi), |r| r.x))
    }
}
