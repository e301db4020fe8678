//! Newton steps on the KKT system of the volume maximum (tridiagonal Hessian, eq. 1.19-1.20).

// `!(x > y)` is deliberate: it also rejects NaN. Index loops walk several coupled arrays.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]
use super::geometry::{Segment, ShapeGeometry};

#[cfg(test)]
thread_local! {
    /// Iterations of both solves on this thread: the tests bound a table's work with it.
    pub(super) static ITERATIONS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Newton iterations per solve; the warm start usually converges in 3-5.
pub(super) const MAX_NEWTON: usize = 60;
/// Active-set passes per solve (rings released from the minimum radius).
pub(super) const MAX_ACTIVE_PASSES: usize = 40;
/// Halvings of a length step before the path is declared ended.
pub(super) const MAX_SUBSTEP_HALVINGS: usize = 12;

/// Working state of the constrained maximization: radii, multiplier and active set.
#[derive(Clone, Debug)]
pub(super) struct Solver {
    pub(super) radii: Vec<f64>,
    /// `lambda = dV/dL` at the optimum (negative in the stroke: tension).
    pub(super) lambda: f64,
    /// `true` for rings held at a bound: the minimum radius (and the two clamped ends) or the
    /// ceiling `S_row / (2 pi)`, where a row's whole strand is its circumference (eq. 1.4 with
    /// `h = 0`). A held ring's radius says which.
    pub(super) held: Vec<bool>,
    /// The ceiling `S_row / (2 pi)` (m).
    pub(super) ceiling: f64,
    // Gradients and tridiagonal Hessians of V and L over the rings.
    pub(super) gv: Vec<f64>,
    pub(super) gl: Vec<f64>,
    pub(super) dv: Vec<f64>,
    pub(super) dl: Vec<f64>,
    pub(super) ov: Vec<f64>,
    pub(super) ol: Vec<f64>,
    // Scratch of the bordered tridiagonal solve.
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) c: Vec<f64>,
    /// Radii before the fast path's last Newton step.
    pub(super) base: Vec<f64>,
    /// Releases of each ring from the floor in the current fast solve.
    pub(super) releases: Vec<u8>,
    /// Whether the last fast solve needed the inertia-correcting shift (the next tries it first).
    pub(super) prefer_shift: bool,
    /// The last inertia-correcting shift the fast path used: the next solve's search for one
    /// starts a little below it (it changes slowly along the path).
    pub(super) shift_hint: f64,
    /// Whether the last fast solve met an iterate where the inertia-correcting shift applies:
    /// if not, the same solve with the other setting takes the same steps.
    pub(super) shift_mattered: bool,
    /// The segment between two rings on the floor (`None` if it cannot close): the same for
    /// every such pair, and most segments of a pocket's early stroke.
    floor_segment: Option<Segment>,
    /// Per segment, the end radii it was last evaluated at and the result: between rings held
    /// at their bounds (beads at the ceiling beside rings on the floor, late on thin strands)
    /// a segment stays the same over many iterations.
    segment_cache: Vec<(f64, f64, Segment)>,
}

/// Converged point on the path.
#[derive(Clone, Copy, Debug)]
pub(super) struct PathPoint {
    pub(super) length: f64,
    pub(super) volume: f64,
    pub(super) slope: f64,
    pub(super) curvature: f64,
    pub(super) max_radius: f64,
}

impl Solver {
    pub(super) fn new(geom: &ShapeGeometry) -> Self {
        let rings = geom.segments + 1;
        let mut held = vec![false; rings];
        held[0] = true;
        held[rings - 1] = true;
        let z = vec![0.0; rings];
        Self {
            radii: vec![geom.min_radius; rings],
            lambda: 0.0,
            held,
            ceiling: geom.radius_ceiling(),
            gv: z.clone(),
            gl: z.clone(),
            dv: z.clone(),
            dl: z.clone(),
            ov: z.clone(),
            ol: z.clone(),
            x: z.clone(),
            y: z.clone(),
            c: z.clone(),
            base: z,
            releases: vec![0; rings],
            prefer_shift: false,
            shift_hint: 0.0,
            shift_mattered: false,
            floor_segment: geom.segment(geom.min_radius, geom.min_radius),
            // No radius equals NaN: every entry misses until it is first evaluated.
            segment_cache: geom
                .segment(geom.min_radius, geom.min_radius)
                .map(|seg| vec![(f64::NAN, f64::NAN, seg); rings - 1])
                .unwrap_or_default(),
        }
    }

    /// Becomes a copy of `other`, reusing this solver's buffers (the path copies its state
    /// twice per step; fresh allocations were a fifth of the table's time on long sleeves).
    pub(super) fn copy_from(&mut self, other: &Solver) {
        self.lambda = other.lambda;
        self.ceiling = other.ceiling;
        self.prefer_shift = other.prefer_shift;
        self.shift_hint = other.shift_hint;
        self.floor_segment = other.floor_segment;
        for (to, from) in [
            (&mut self.radii, &other.radii),
            (&mut self.gv, &other.gv),
            (&mut self.gl, &other.gl),
            (&mut self.dv, &other.dv),
            (&mut self.dl, &other.dl),
            (&mut self.ov, &other.ov),
            (&mut self.ol, &other.ol),
            (&mut self.x, &other.x),
            (&mut self.y, &other.y),
            (&mut self.c, &other.c),
            (&mut self.base, &other.base),
        ] {
            to.clone_from(from);
        }
        self.held.clone_from(&other.held);
        self.releases.clone_from(&other.releases);
    }

    /// Whether ring `j` is held at the ceiling (else, if held, at the floor).
    #[inline]
    pub(super) fn at_ceiling(&self, j: usize) -> bool {
        self.held[j] && self.radii[j] >= self.ceiling
    }

    /// Whether ring `j` is held at the minimum radius (a clamp or a ring outside the pockets).
    #[inline]
    pub(super) fn on_floor(&self, j: usize) -> bool {
        self.held[j] && self.radii[j] < self.ceiling
    }

    /// Gradients and tridiagonal Hessians of `V` and `L` (eq. 1.19-1.20 and their second
    /// derivatives). Returns `(L, V)`, `None` if a segment cannot close.
    pub(super) fn assemble(&mut self, geom: &ShapeGeometry) -> Option<(f64, f64)> {
        let rings = self.radii.len();
        let k = geom.segment_constants();
        let (mut l, mut v) = (0.0, 0.0);
        // Ring `j` sums its share of segment `j` (ending at it) and of segment `j + 1` (starting
        // at it), in that order; the end rings have one segment each.
        let (mut gv, mut gl, mut dv, mut dl) = (0.0, 0.0, 0.0, 0.0);
        let r_min = geom.min_radius;
        // Slices of one length: the loop indexes them without bounds checks.
        let radii = &self.radii[..rings];
        let (sgv, sgl) = (&mut self.gv[..rings], &mut self.gl[..rings]);
        let (sdv, sdl) = (&mut self.dv[..rings], &mut self.dl[..rings]);
        let (sov, sol) = (&mut self.ov[..rings], &mut self.ol[..rings]);
        for i in 1..rings {
            let (ra, rb) = (radii[i - 1], radii[i]);
            let seg = match (self.floor_segment, self.segment_cache.get_mut(i - 1)) {
                (Some(floor), _) if ra == r_min && rb == r_min => floor,
                (_, Some(&mut (a, b, seg))) if a == ra && b == rb => seg,
                (_, cached) => {
                    let seg = k.segment(ra, rb)?;
                    if let Some(entry) = cached {
                        *entry = (ra, rb, seg);
                    }
                    seg
                }
            };
            l += seg.l;
            v += seg.v;
            let a = i - 1;
            sgv[a] = gv + seg.va;
            sgl[a] = gl + seg.la;
            sdv[a] = dv + seg.vaa;
            sdl[a] = dl + seg.laa;
            sov[a] = seg.vab;
            sol[a] = seg.lab;
            (gv, gl, dv, dl) = (seg.vb, seg.lb, seg.vbb, seg.lbb);
        }
        let last = rings - 1;
        (self.gv[last], self.gl[last], self.dv[last], self.dl[last]) = (gv, gl, dv, dl);
        self.ov[last] = 0.0;
        self.ol[last] = 0.0;
        Some((l, v))
    }

    /// Least-squares multiplier `lambda = (g_L . g_V) / (g_L . g_L)` over the free rings.
    pub(super) fn multiplier(&self) -> Option<f64> {
        let (mut num, mut den) = (0.0, 0.0);
        for j in 0..self.radii.len() {
            if !self.held[j] {
                num += self.gl[j] * self.gv[j];
                den += self.gl[j] * self.gl[j];
            }
        }
        (den > 0.0).then(|| num / den)
    }

    /// Solves `(H - mu I) x = R` and `(H - mu I) y = g_L` on the free rings, with
    /// `H = Hess V - lambda Hess L` and `R = grad V - lambda grad L`, by the Thomas algorithm
    /// (hand-written: two right-hand sides per factorization, on the hot path of the table build).
    /// Returns the number of positive pivots (Sylvester inertia of `H - mu I`), `None` on a
    /// vanishing pivot.
    pub(super) fn shifted_solve(&mut self, lambda: f64, mu: f64) -> Option<usize> {
        let scale = self.pivot_scale(lambda);
        self.shifted_solve_scaled(lambda, mu, scale)
    }

    /// The largest `|Hess V - lambda Hess L|` on the diagonal, the scale of a vanishing pivot.
    pub(super) fn pivot_scale(&self, lambda: f64) -> f64 {
        let mut scale = 0.0f64;
        let rings = self.radii.len();
        let (dv, dl) = (&self.dv[..rings], &self.dl[..rings]);
        for j in 0..rings {
            scale = scale.max((dv[j] - lambda * dl[j]).abs());
        }
        scale
    }

    /// [`Solver::shifted_solve`] with the [`Solver::pivot_scale`] of `lambda` (the same for every
    /// shift tried at one iterate).
    pub(super) fn shifted_solve_scaled(
        &mut self,
        lambda: f64,
        mu: f64,
        scale: f64,
    ) -> Option<usize> {
        let rings = self.radii.len();
        let tiny = 1e-14 * scale.max(f64::MIN_POSITIVE) + mu * 1e-14;
        let mut positive = 0;
        let mut prev_off = 0.0;
        let (mut cp, mut xp, mut yp) = (0.0, 0.0, 0.0);
        // Slices of one length: the loops index them without bounds checks.
        let held = &self.held[..rings];
        let (gv, gl) = (&self.gv[..rings], &self.gl[..rings]);
        let (dv, dl) = (&self.dv[..rings], &self.dl[..rings]);
        let (ov, ol) = (&self.ov[..rings], &self.ol[..rings]);
        let (c, x, y) = (
            &mut self.c[..rings],
            &mut self.x[..rings],
            &mut self.y[..rings],
        );
        for j in 0..rings {
            let free = !held[j];
            let diag = if free {
                dv[j] - lambda * dl[j] - mu
            } else {
                1.0
            };
            let off_here = if free && j + 1 < rings && !held[j + 1] {
                ov[j] - lambda * ol[j]
            } else {
                0.0
            };
            let (rx, ry) = if free {
                (gv[j] - lambda * gl[j], gl[j])
            } else {
                (0.0, 0.0)
            };
            let denom = diag - prev_off * cp;
            if !(denom.abs() > tiny) || !denom.is_finite() {
                return None;
            }
            if free && denom > 0.0 {
                positive += 1;
            }
            // A held ring's row is the identity (no coupling reaches it): its pivot is exactly 1.
            let inv = if free { 1.0 / denom } else { 1.0 };
            (cp, xp, yp) = (
                off_here * inv,
                (rx - prev_off * xp) * inv,
                (ry - prev_off * yp) * inv,
            );
            (c[j], x[j], y[j]) = (cp, xp, yp);
            prev_off = off_here;
        }
        for j in (0..rings - 1).rev() {
            xp = x[j] - c[j] * xp;
            yp = y[j] - c[j] * yp;
            (x[j], y[j]) = (xp, yp);
        }
        Some(positive)
    }

    /// Moves the free rings along the length gradient until `L = target` (1-D Newton, capped),
    /// holding any ring that reaches the minimum radius or the ceiling. Returns `(L, V)`.
    pub(super) fn restore_length(
        &mut self,
        geom: &ShapeGeometry,
        target: f64,
    ) -> Option<(f64, f64)> {
        let r_min = geom.min_radius;
        let mut lv = geom.length_and_volume(&self.radii)?;
        for _ in 0..30 {
            if (lv.0 - target).abs() <= 1e-14 * geom.max_length() {
                return Some(lv);
            }
            self.assemble(geom)?;
            let gg: f64 = (0..self.radii.len())
                .filter(|&j| !self.held[j])
                .map(|j| self.gl[j] * self.gl[j])
                .sum();
            if !(gg > 0.0) {
                return None;
            }
            let mut beta = (target - lv.0) / gg;
            let base = self.radii.clone();
            let mut ok = false;
            for _ in 0..40 {
                for j in 0..self.radii.len() {
                    if !self.held[j] {
                        self.radii[j] = (base[j] + beta * self.gl[j]).clamp(r_min, self.ceiling);
                    }
                }
                if let Some(x) = geom.length_and_volume(&self.radii) {
                    lv = x;
                    ok = true;
                    break;
                }
                beta *= 0.5;
            }
            if !ok {
                self.radii.copy_from_slice(&base);
                return None;
            }
            self.hold_touching(r_min);
        }
        ((lv.0 - target).abs() <= 1e-10 * geom.max_length()).then_some(lv)
    }

    /// Holds the free rings that reached a bound, at that bound.
    pub(super) fn hold_touching(&mut self, r_min: f64) {
        let rings = self.radii.len();
        for j in 1..rings - 1 {
            if !self.held[j] && self.radii[j] <= r_min {
                self.radii[j] = r_min;
                self.held[j] = true;
            } else if !self.held[j] && self.radii[j] >= self.ceiling {
                self.radii[j] = self.ceiling;
                self.held[j] = true;
            }
        }
    }

    /// Maximizes `V` at `L = target` from the current rings: a Newton step on the KKT system
    /// whose Hessian is shifted until its reduced form is negative definite (so every step is
    /// an ascent direction, never towards a saddle), a line search on `V` after restoring the
    /// length, and release of held rings that want to grow. `Err` names the failure; the caller
    /// then takes a shorter length step.
    pub(super) fn solve(
        &mut self,
        geom: &ShapeGeometry,
        target: f64,
    ) -> Result<PathPoint, &'static str> {
        self.solve_within(geom, target, MAX_NEWTON * MAX_ACTIVE_PASSES)
    }

    /// [`Solver::solve`] within `max_iterations` iterations.
    pub(super) fn solve_within(
        &mut self,
        geom: &ShapeGeometry,
        target: f64,
        max_iterations: usize,
    ) -> Result<PathPoint, &'static str> {
        let rings = self.radii.len();
        let r_min = geom.min_radius;
        let r_ceiling = geom.radius_ceiling();
        let s_row = geom.row_strand_length;
        let step_cap = 0.05 * s_row;
        let (_, mut volume) = self.restore_length(geom, target).ok_or("restore")?;
        let mut quiet = 0;
        let mut stalled = false;
        let mut releases = vec![0u8; rings];
        let mut last_mu = 0.0;
        for _it in 0..max_iterations {
            #[cfg(test)]
            ITERATIONS.with(|c| c.set(c.get() + 1));
            self.assemble(geom).ok_or("assemble")?;
            let lambda = self.multiplier().ok_or("multiplier")?;
            self.lambda = lambda;
            let mut res = 0.0f64;
            for j in 0..rings {
                if !self.held[j] {
                    res = res.max((self.gv[j] - lambda * self.gl[j]).abs());
                }
            }
            // Held rings that pull away from their bound (KKT sign) are released one at a time,
            // once the free rings are converged or the ascent has stalled.
            let grad_tol = 1e-10 * s_row * s_row;
            // Near a symmetric saddle of the pocket's lattice position the shifted steps crawl;
            // a residual this small changes the volume by far less than roundoff of the table.
            let saddle_ok = last_mu > 0.0 && res <= 1e3 * grad_tol;
            if res <= grad_tol || stalled || saddle_ok {
                if stalled && res > 1e-7 * s_row * s_row {
                    return Err("line search");
                }
                stalled = false;
                quiet = 0;
                let mut release = None;
                let mut worst = grad_tol;
                for j in 1..rings - 1 {
                    // A ring on the floor is released if it wants to grow, one at the ceiling if
                    // it wants to shrink (KKT sign of `z = dV/dr - lambda dL/dr`).
                    let z = self.gv[j] - lambda * self.gl[j];
                    let pull = if self.at_ceiling(j) { -z } else { z };
                    // A ring that keeps falling back to its bound is left there (bounded work).
                    if self.held[j] && pull > worst && releases[j] < 3 {
                        worst = pull;
                        release = Some(j);
                    }
                }
                match release {
                    Some(j) => {
                        self.held[j] = false;
                        releases[j] += 1;
                        let twin = rings - 1 - j;
                        if twin != 0 && twin != rings - 1 && twin != j {
                            self.held[twin] = false;
                            releases[twin] += 1;
                        }
                        continue;
                    }
                    None => {
                        let curvature = self.sensitivity(geom).ok_or("sensitivity")?;
                        let (length, _) = geom.length_and_volume(&self.radii).ok_or("segment")?;
                        let max_radius = self.radii.iter().cloned().fold(r_min, f64::max);
                        return Ok(PathPoint {
                            length,
                            volume,
                            slope: lambda,
                            curvature,
                            max_radius,
                        });
                    }
                }
            }
            // Inertia-corrected bordered Newton step (tangent to the length constraint).
            let mut mu = 0.0;
            let mut step_ok = false;
            for _ in 0..80 {
                if let Some(pos) = self.shifted_solve(lambda, mu) {
                    let mut gx = 0.0;
                    let mut gy = 0.0;
                    for j in 0..rings {
                        if !self.held[j] {
                            gx += self.gl[j] * self.x[j];
                            gy += self.gl[j] * self.y[j];
                        }
                    }
                    // Positive eigenvalues of the bordered matrix: pos(H) + [g' H^-1 g < 0];
                    // exactly one means the reduced Hessian is negative definite.
                    let bordered_pos = pos + usize::from(gy < 0.0);
                    if bordered_pos == 1 && gy != 0.0 {
                        let dlam = gx / gy;
                        for j in 0..rings {
                            self.x[j] = -self.x[j] + dlam * self.y[j];
                        }
                        step_ok = true;
                        break;
                    }
                }
                // After the plain step, the search resumes a little below the last step's
                // shift: the shift needed changes slowly from step to step.
                mu = if mu == 0.0 {
                    (1e-8 * s_row.max(1e-300)).max(last_mu / 16.0)
                } else {
                    mu * 4.0
                };
            }
            if !step_ok {
                return Err("inertia");
            }
            last_mu = mu;
            let max_step = self.x.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if !max_step.is_finite() {
                return Err("nonfinite");
            }
            let mut alpha = if max_step > step_cap {
                step_cap / max_step
            } else {
                1.0
            };
            let base = self.radii.clone();
            let base_held = self.held.clone();
            let mut accepted = false;
            for _ in 0..40 {
                for j in 0..rings {
                    self.radii[j] = if self.held[j] {
                        base[j]
                    } else {
                        crate::physics::numerics::bounds::limit(
                            base[j] + alpha * self.x[j],
                            r_min,
                            r_ceiling,
                        )
                    };
                }
                self.hold_touching(r_min);
                if let Some((_, v)) = self.restore_length(geom, target) {
                    if v >= volume - 1e-15 * volume.abs() {
                        accepted = true;
                        let gain = v - volume;
                        volume = v;
                        if gain <= 1e-15 * v.abs() {
                            quiet += 1;
                        } else {
                            quiet = 0;
                        }
                        break;
                    }
                }
                self.radii.copy_from_slice(&base);
                self.held.copy_from_slice(&base_held);
                alpha *= 0.5;
            }
            if !accepted || quiet > 5 {
                // No further ascent at this residual: roundoff floor, go to the release check.
                stalled = true;
            }
        }
        Err("iteration cap")
    }

    /// `d lambda / dL = d2V/dL2` at a converged point (implicit function theorem on the KKT
    /// system: `H dr = g dlambda`, `g . dr = 1`); leaves `dr/dL` in `y`.
    pub(super) fn sensitivity(&mut self, geom: &ShapeGeometry) -> Option<f64> {
        self.assemble(geom)?;
        let lambda = self.multiplier()?;
        self.shifted_solve(lambda, 0.0)?;
        let gy: f64 = (0..self.radii.len())
            .filter(|&j| !self.held[j])
            .map(|j| self.gl[j] * self.y[j])
            .sum();
        if !(gy.abs() > 0.0) {
            return None;
        }
        let dlam = 1.0 / gy;
        for yj in self.y.iter_mut() {
            *yj *= dlam;
        }
        dlam.is_finite().then_some(dlam)
    }
}
