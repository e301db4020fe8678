//! The free bladder: below the threshold pressure it does not touch the sleeve and its outer
//! diameter solves eq. 2.18 (generalised to the layers); whether losing contact is gradual.

use super::{Bladder, Kernel, SleeveGeometry};
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
    /// `P_eff(x) = 0` for `x` below the sleeve's diameter `x_contact`, where `P_eff < 0`, with the
    /// wall's kernel there when the last evaluation was at the root. `contact` is the kernel at
    /// `x_contact` (its `P_eff` and `dP_eff/dx` give the first Newton step, from the sleeve's
    /// side). Hand-written safeguarded Newton-bisection on the analytic slope, for speed on the
    /// per-step path; every loop is capped.
    pub(super) fn free_outer_diameter(
        &self,
        pressure: f64,
        length: f64,
        x_contact: f64,
        contact: &Kernel,
    ) -> Result<(f64, Option<Kernel>), String> {
        let lambda1 = length / self.tube.unstretched_length;
        let d_ro = self.outer_diameter;
        let d_ri = self.tube.inner_diameter;
        // Inner wall collapses at x_min; all layers are unstrained at x_rest = D_RO/sqrt(lambda_1),
        // where P_eff = P (a = 1... times P, c = 0), so for P > 0 the root lies above x_rest.
        let x_min = ((d_ro * d_ro - d_ri * d_ri) / lambda1).sqrt();
        let x_rest = d_ro / lambda1.sqrt();
        let residual = |x: f64| self.kernel(pressure, Dual::var_l(length), Dual::var_x(x));
        let options = RootOptions {
            absolute: 0.0,
            relative: 1e-14,
            max_iterations: ROOT_ITERATIONS,
            jump_width: 0.0,
        };
        // Converged where the Newton correction is within the tolerance, as in newton_bisection.
        let converged = |x: f64, k: &Kernel| {
            let newton = x - k.p_eff.v / k.p_eff.dx;
            k.p_eff.v == 0.0
                || (newton.is_finite()
                    && k.p_eff.dx < 0.0
                    && (newton - x).abs() <= options.relative * x.abs())
        };
        // One Newton step from the sleeve's diameter, where P_eff < 0: just below the contact
        // threshold the root lies just inside the sleeve and the step lands on it; where P_eff is
        // convex in x the step stays on the root's unstrained side and brackets it at once, else
        // it narrows the bracket.
        let mut hi = x_contact;
        let (r_hi, s_hi) = (contact.p_eff.v, contact.p_eff.dx);
        let step = x_contact - r_hi / s_hi;
        let mut bracket = None;
        if s_hi < 0.0 && step > x_min && step < x_contact {
            if let Some(k) = residual(step) {
                if converged(step, &k) {
                    return Ok((step, Some(k)));
                }
                if k.p_eff.v >= 0.0 {
                    bracket = Some((step, k));
                } else {
                    hi = step;
                }
            }
        }
        let (lo, at_lo) = match bracket {
            Some(b) => b,
            None => {
                let found = |x: f64, k: &Kernel| k.p_eff.v >= 0.0 || converged(x, k);
                self.collapsed_side(pressure, length, (x_min, x_rest, hi), &residual, found)?
            }
        };
        // Newton from the unstrained side (seen to approach monotonically, ~6 steps); P_eff falls
        // from positive at `lo` to negative at `hi`. Its first iteration, at `lo`, is taken here
        // from the sample already at hand.
        if converged(lo, &at_lo) {
            return Ok((lo, Some(at_lo)));
        }
        let newton = lo - at_lo.p_eff.v / at_lo.p_eff.dx;
        let newton_ok = newton.is_finite() && at_lo.p_eff.dx < 0.0;
        let start = if newton_ok && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let root = newton_bisection(lo, hi, start, false, options, |x| {
            Ok::<_, ()>(residual(x).map(|k| Sample {
                value: k.p_eff.v,
                slope: k.p_eff.dx,
                payload: k,
            }))
        });
        Ok(match root {
            Ok(r) if r.converged => (r.x, r.payload),
            Ok(r) => (r.x, None),
            Err(()) => (0.5 * (lo + hi), None),
        })
    }

    /// The collapsed side of the free-bladder bracket below `hi`: the first of the points halving
    /// the way from `start` (`x_rest`, or `hi` if lower) to `x_min` where `found` (`P_eff >= 0`,
    /// or the root itself), with the kernel there. P_eff falls as x grows, so "P_eff >= 0, or
    /// x_min reached" holds from that point on: found by doubling then bisecting the halving
    /// count (about 2 log2 of it evaluations, not one per halving: under a deep vacuum the root
    /// sits dozens of halvings deep).
    fn collapsed_side(
        &self,
        pressure: f64,
        length: f64,
        (x_min, x_rest, hi): (f64, f64, f64),
        residual: &impl Fn(f64) -> Option<Kernel>,
        found: impl Fn(f64, &Kernel) -> bool,
    ) -> Result<(f64, Kernel), String> {
        let start = if x_rest < hi { x_rest } else { hi };
        let point = |j: usize| {
            if j == 0 {
                start
            } else {
                x_min + (start - x_min) * 0.5f64.powi(j as i32)
            }
        };
        // Ok(Some(kernel)) with P_eff >= 0 where found, Ok(None) where not yet (P_eff < 0), Err
        // at x_min.
        let probe = |j: usize| -> Result<Option<Kernel>, ()> {
            let x = point(j);
            match residual(x) {
                Some(k) if found(x, &k) => Ok(Some(k)),
                _ if x > x_min => Ok(None),
                _ => Err(()),
            }
        };
        let past = |p: &Result<Option<Kernel>, ()>| !matches!(p, Ok(None));
        let last = BRACKET_HALVINGS - 1;
        let (mut below, mut first) = (None, None);
        let mut j = 0;
        loop {
            let p = probe(j);
            if past(&p) {
                first = Some((j, p));
                break;
            }
            below = Some(j);
            if j == last {
                break;
            }
            j = (2 * j).clamp(1, last);
        }
        // Bisect between the last count short of it and the first past it.
        if let (Some(mut short), Some((mut at, mut p))) =
            (below, first.take_if(|_| below.is_some()))
        {
            while at - short > 1 {
                let mid = short + (at - short) / 2;
                let q = probe(mid);
                if past(&q) {
                    (at, p) = (mid, q);
                } else {
                    short = mid;
                }
            }
            first = Some((at, p));
        }
        match first {
            Some((j, Ok(Some(k)))) => Ok((point(j), k)),
            _ => Err(format!(
                "pressure {pressure} Pa at length {length} m: the free bladder has no equilibrium \
                 short of collapse (vacuum too deep; collapse is not modelled)"
            )),
        }
    }
}
