//! The fast path of the table: plain Newton on the KKT system with a primal-dual active set.
//!
//! [`Solver::solve`] is robust but slow on long sleeves: it restores the length after every step,
//! line-searches on the volume and releases one ring (and its twin) per converged solve, so the
//! pocket's edge, which crosses about `segments / nodes` rings per table node, costs a full
//! re-convergence per ring: quadratic in `segments` overall. Here the active set is updated in
//! every Newton step from the complementarity of `r_j >= r_min` and `z_j = dV/dr_j - lambda
//! dL/dr_j <= 0` (a ring is held when `(r_j - r_min) + z_j / |H_jj| < 0`: its Newton move would
//! take it below the floor; one the step takes to the ceiling `S_row / (2 pi)` stays there while
//! `z_j >= 0`), and the length constraint enters the step itself, so a warm start
//! from the tangent predictor converges in a few O(segments) iterations wherever the pocket's
//! edge is. Anything unusual (no convergence, a saddle, a non-finite value) returns `None`, and
//! the caller falls back to the robust solve from the same start.

// `!(x > y)` is deliberate: it also rejects NaN. Index loops walk several coupled arrays.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]
use super::geometry::ShapeGeometry;
use super::solver::{PathPoint, Solver};

/// Newton iterations on the path before giving up to the robust solve; a warm start needs 2-5.
pub(super) const MAX_PATH_ITERATIONS: usize = 40;
/// Releases of one ring from the floor within a solve before it stays there.
const MAX_RELEASES: u8 = 3;
/// Consecutive steps that move no ring beyond roundoff before the fast path gives up.
const MAX_IDLE_STEPS: usize = 3;
/// Pocket edges put back on the floor in one solve when Newton heads for a saddle.
const MAX_EDGE_HOLDS: usize = 2;
/// Steps towards a saddle (one ascent, active set unchanged) before its edge is put down.
const SADDLE_STEPS: usize = 2;
/// Step halvings when a step leaves a segment unable to close.
const MAX_BACKTRACKS: usize = 30;

/// What the fast path's steps after a release from a profile at its bounds depend on, beside
/// the multiplier the release sets.
struct Exchange {
    radii: Vec<f64>,
    releases: Vec<u8>,
    /// Backtracks, edge holds and idle steps so far.
    counters: (usize, usize, usize),
    /// The last inertia-correcting shift and the solver's hint, as bits.
    shifts: (u64, u64),
}

impl Solver {
    /// Maximizes `V` at `L = target` from the current rings and multiplier (the predictor).
    /// Converged to the robust solve's residual (`1e-10 S_row^2` per ring) with the length exact
    /// to `1e-13 L_max`; leaves `dr/dL` in `y` as [`Solver::sensitivity`] does. `None` if the
    /// start does not close or Newton does not reach a maximum. Leaves in
    /// [`Solver::shift_mattered`] whether `shift` changed (or, unset, would have changed) a step.
    pub(super) fn solve_newton(
        &mut self,
        geom: &ShapeGeometry,
        target: f64,
        max_iterations: usize,
        shift: bool,
    ) -> Option<PathPoint> {
        let rings = self.radii.len();
        let r_min = geom.min_radius;
        let r_ceiling = geom.radius_ceiling();
        let s_row = geom.row_strand_length;
        let grad_tol = 1e-10 * s_row * s_row;
        let length_tol = 1e-13 * geom.max_length();
        let step_cap = 0.05 * s_row;
        let mut lambda = self.lambda;
        if !lambda.is_finite() {
            return None;
        }
        // The last step (base radii in `base`, direction in `x`), halved while it does not close.
        let mut step: Option<(f64, f64, f64)> = None;
        let mut backtracks = 0;
        let mut last_residual = f64::INFINITY;
        self.releases.iter_mut().for_each(|n| *n = 0);
        let mut idle = 0;
        let mut last_shift = self.shift_hint;
        let mut edge_holds = 0;
        let mut saddle_run = 0;
        self.shift_mattered = false;
        // The last release from a profile with every ring at a bound: the ring, the iteration,
        // and what the steps after it depend on.
        let mut exchange: Option<(usize, usize, Exchange)> = None;
        let budget = max_iterations + MAX_BACKTRACKS;
        let mut next_iteration = 0;
        while next_iteration < budget {
            let mut iteration = next_iteration;
            next_iteration += 1;
            #[cfg(test)]
            super::solver::ITERATIONS.with(|c| c.set(c.get() + 1));
            let Some((length, volume)) = self.assemble(geom) else {
                let (alpha, lambda0, dlambda) = step?;
                backtracks += 1;
                if backtracks > MAX_BACKTRACKS {
                    return None;
                }
                let alpha = 0.5 * alpha;
                self.take_step(alpha, r_min, r_ceiling);
                lambda = lambda0 + alpha * dlambda;
                step = Some((alpha, lambda0, dlambda));
                continue;
            };
            // Active set from the complementarity function; a ring newly held above the floor is
            // put on it and the system re-assembled. The first step keeps the predicted set:
            // rings released at the floor ahead of the pocket's edge have no pull yet.
            let first = iteration == 0;
            let mut set_changed = first;
            let mut projected = false;
            let mut residual = 0.0f64;
            let mut largest_term = 0.0f64;
            // Slices of one length: the loop indexes them without bounds checks.
            let (gv, gl) = (&self.gv[..rings], &self.gl[..rings]);
            let (dv, dl) = (&self.dv[..rings], &self.dl[..rings]);
            let (radii, held) = (&mut self.radii[..rings], &mut self.held[..rings]);
            let releases = &mut self.releases[..rings];
            for j in 1..rings - 1 {
                let z = gv[j] - lambda * gl[j];
                let curvature = (dv[j] - lambda * dl[j]).abs();
                // The bound a ring is held at: the floor, or the ceiling where a bead's ring on a
                // thin strand would take more than the row's strand as circumference.
                let stuck = held[j] && releases[j] >= MAX_RELEASES;
                let bound = if first {
                    held[j].then_some(radii[j])
                } else if radii[j] <= r_min {
                    // A ring that keeps falling back to the floor (its pull is at roundoff) is
                    // left there, as in the robust solve.
                    (z <= grad_tol || stuck).then_some(r_min)
                } else if radii[j] >= r_ceiling {
                    (z >= -grad_tol || stuck).then_some(r_ceiling)
                } else if (radii[j] - r_min) * curvature + z < 0.0 {
                    Some(r_min)
                } else {
                    None
                };
                let hold = bound.is_some();
                if hold != held[j] {
                    set_changed = true;
                    held[j] = hold;
                    if !hold {
                        releases[j] = releases[j].saturating_add(1);
                    }
                }
                if let Some(r) = bound {
                    if radii[j] != r {
                        radii[j] = r;
                        projected = true;
                    }
                }
                if !hold {
                    residual = residual.max(z.abs());
                    largest_term = largest_term.max(gv[j].abs());
                }
            }
            step = None;
            if projected {
                continue;
            }
            if self.held.iter().all(|&h| h) && (1..rings - 1).any(|j| self.at_ceiling(j)) {
                // Every ring at a bound (a thin strand's one-ring beads capped at the ceiling):
                // the rings no longer fix the multiplier. A shorter length is reached by raising
                // the floor ring that gains the most volume per length lost (the exchange of
                // section 1.3.5); its ratio is the multiplier.
                if !(target < length) {
                    return None;
                }
                let state = Exchange {
                    radii: self.radii.clone(),
                    releases: self.releases.clone(),
                    counters: (backtracks, edge_holds, idle),
                    shifts: (last_shift.to_bits(), self.shift_hint.to_bits()),
                };
                if let Some((ring, at, before)) = exchange.take() {
                    // The last release came back to the same profile with the same counts (its
                    // ring on the floor again): releasing that ring again would repeat the same
                    // iterations, up to its last release. They are counted, not taken.
                    let mut expected = before.releases.clone();
                    expected[ring] = self.releases[ring];
                    if state.radii == before.radii
                        && state.releases == expected
                        && state.counters == before.counters
                        && state.shifts == before.shifts
                    {
                        let repeats = usize::from(MAX_RELEASES - self.releases[ring]);
                        iteration += repeats * (iteration - at);
                        next_iteration = iteration + 1;
                        self.releases[ring] = MAX_RELEASES;
                        if iteration >= budget {
                            return None;
                        }
                    }
                }
                let ratio = |j: usize| self.gv[j] / self.gl[j];
                let j = (1..rings - 1)
                    .filter(|&j| {
                        self.on_floor(j) && self.gl[j] < 0.0 && self.releases[j] < MAX_RELEASES
                    })
                    .min_by(|&a, &b| ratio(a).total_cmp(&ratio(b)))?;
                lambda = ratio(j);
                self.held[j] = false;
                let mut state = state;
                state.releases.clone_from(&self.releases);
                exchange = Some((j, iteration, state));
                self.releases[j] += 1;
                set_changed = true;
            }
            if !residual.is_finite() {
                return None;
            }
            let pos = self.shifted_solve(lambda, 0.0)?;
            let (mut gx, mut gy) = self.border_products();
            if !(gy.abs() > 0.0) {
                return None;
            }
            // Converged at the tolerance, or at the roundoff floor: near-radial segments at the
            // clamps (`L = sqrt(s^2 - d^2)` losing digits) hold the residual above it, at a part
            // in 1e9 or less of their gradient, where the robust solve also stalls.
            let floor = grad_tol.max(1e-9 * largest_term);
            let stalled = residual <= 1e3 * floor && residual > 0.5 * last_residual;
            last_residual = residual;
            let converged = !set_changed
                && (residual <= grad_tol || stalled)
                && (length - target).abs() <= length_tol;
            // Steps that keep one ascent with the set unchanged are converging on a saddle.
            let bordered = pos + usize::from(gy < 0.0);
            saddle_run = if !set_changed && bordered == 2 {
                saddle_run + 1
            } else {
                0
            };
            let checked = converged || saddle_run >= SADDLE_STEPS;
            // A maximum has a negative definite reduced Hessian: the bordered matrix has exactly
            // one positive eigenvalue. The pocket centred on the lattice can instead be a saddle
            // whose one ascent is antisymmetric (a shift by part of a segment, worth far less
            // volume than the table's accuracy); the robust solve, which releases rings in
            // mirror pairs, stays on it too, so a symmetric profile is accepted if it is a
            // maximum among symmetric profiles.
            let maximum = checked
                && (bordered == 1
                    || (self.is_mirror_symmetric(r_ceiling)
                        && self.symmetric_ascents(lambda) == Some(1)));
            // On a thin strand the saddle is often a pocket one ring too wide: its edge ring
            // sits just off the floor, where the cone's volume (eq. 1.18) is still convex in its
            // radius, and the ascent puts it down. That ring goes back on the floor and Newton
            // goes on from there (the robust solve would start over from the prediction).
            if checked && !maximum && edge_holds < MAX_EDGE_HOLDS {
                if let Some(j) = self.lowest_edge_ring() {
                    edge_holds += 1;
                    // A mirror-symmetric profile stays symmetric: the twin goes down too.
                    let twin = rings - 1 - j;
                    if self.is_mirror_symmetric(r_ceiling) {
                        self.held[twin] = true;
                        self.radii[twin] = r_min;
                    }
                    self.held[j] = true;
                    self.radii[j] = r_min;
                    last_residual = f64::INFINITY;
                    saddle_run = 0;
                    continue;
                }
            }
            if converged {
                if !maximum {
                    return None;
                }
                self.lambda = self.multiplier()?;
                let curvature = 1.0 / gy;
                for yj in self.y.iter_mut() {
                    *yj *= curvature;
                }
                let max_radius = self.radii.iter().cloned().fold(r_min, f64::max);
                return curvature.is_finite().then_some(PathPoint {
                    length,
                    volume,
                    slope: self.lambda,
                    curvature,
                    max_radius,
                });
            }
            // Away from a maximum the plain step heads for a saddle: a ring just off the floor
            // of a thin-strand sleeve, where the cone's volume (eq. 1.18) is still convex in its
            // radius and the slant's concavity (eq. 1.17) small, would be sent back below the
            // floor. The Hessian is then shifted until the reduced one is negative definite
            // (bordered inertia one), as in the robust solve, so the step ascends.
            // Without the shift the same test is made (until it first holds) so that the caller
            // knows whether the other setting would take any other step.
            if (shift || !self.shift_mattered)
                && pos + usize::from(gy < 0.0) != 1
                && !(self.is_mirror_symmetric(r_ceiling)
                    && self.symmetric_ascents(lambda) == Some(1))
            {
                self.shift_mattered = true;
                if shift {
                    (gx, gy) = self.shifted_products(lambda, s_row, &mut last_shift)?;
                }
            }
            // Newton step on (r, lambda): H dr - g dlambda = -R, g . dr = target - L.
            let dlambda = (target - length + gx) / gy;
            let mut largest = 0.0f64;
            let (held, x, y) = (&self.held[..rings], &mut self.x[..rings], &self.y[..rings]);
            for j in 0..rings {
                if !held[j] {
                    x[j] = -x[j] + dlambda * y[j];
                    largest = largest.max(x[j].abs());
                }
            }
            if !largest.is_finite() || !dlambda.is_finite() {
                return None;
            }
            let alpha = if largest > step_cap {
                step_cap / largest
            } else {
                1.0
            };
            self.base.copy_from_slice(&self.radii);
            self.take_step(alpha, r_min, r_ceiling);
            // A step the floor clips to roundoff (free rings at `r_min` that Newton moves below
            // it) leaves the state where it was: after a few such steps the fast path gives up
            // instead of spending its remaining iterations there. The robust solve restarts from
            // the same prediction either way, so the table does not change.
            let moved = self
                .radii
                .iter()
                .zip(&self.base)
                .map(|(r, b)| (r - b).abs())
                .fold(0.0, f64::max);
            idle = if moved <= 1e-13 * r_ceiling {
                idle + 1
            } else {
                0
            };
            if idle >= MAX_IDLE_STEPS {
                return None;
            }
            step = Some((alpha, lambda, dlambda));
            lambda += alpha * dlambda;
        }
        None
    }

    /// `g_L . x` and `g_L . y` of [`Solver::shifted_solve`] at the smallest shift (from
    /// `1e-8 S_row`, by factors of 4) whose bordered matrix has exactly one positive eigenvalue.
    fn shifted_products(
        &mut self,
        lambda: f64,
        s_row: f64,
        last_shift: &mut f64,
    ) -> Option<(f64, f64)> {
        let mut mu = (1e-8 * s_row).max(*last_shift / 4.0);
        let scale = self.pivot_scale(lambda);
        for _ in 0..80 {
            if let Some(pos) = self.shifted_solve_scaled(lambda, mu, scale) {
                let (gx, gy) = self.border_products();
                if pos + usize::from(gy < 0.0) == 1 && gy != 0.0 {
                    *last_shift = mu;
                    self.shift_hint = mu;
                    return Some((gx, gy));
                }
            }
            mu *= 4.0;
        }
        None
    }

    /// Positive eigenvalues of the bordered KKT matrix at the current rings, over all moves of
    /// the free rings (one at a maximum: the reduced Hessian is negative definite). Overwrites
    /// the solve's scratch (`x`, `y`).
    pub(super) fn bordered_ascents(&mut self, geom: &ShapeGeometry) -> Option<usize> {
        self.assemble(geom)?;
        let lambda = self.multiplier()?;
        let pos = self.shifted_solve(lambda, 0.0)?;
        let (_, gy) = self.border_products();
        Some(pos + usize::from(gy < 0.0))
    }

    /// `g_L . x` and `g_L . y` over the free rings.
    fn border_products(&self) -> (f64, f64) {
        let (mut gx, mut gy) = (0.0, 0.0);
        let rings = self.radii.len();
        let (held, gl) = (&self.held[..rings], &self.gl[..rings]);
        let (x, y) = (&self.x[..rings], &self.y[..rings]);
        for j in 0..rings {
            if !held[j] {
                gx += gl[j] * x[j];
                gy += gl[j] * y[j];
            }
        }
        (gx, gy)
    }

    /// Free rings at `base + alpha x`, kept within `[r_min, r_ceiling]`.
    fn take_step(&mut self, alpha: f64, r_min: f64, r_ceiling: f64) {
        let rings = self.radii.len();
        let (held, base, x) = (&self.held[..rings], &self.base[..rings], &self.x[..rings]);
        for (j, radius) in self.radii.iter_mut().enumerate() {
            if !held[j] {
                let r = base[j] + alpha * x[j];
                *radius = crate::physics::numerics::bounds::limit(r, r_min, r_ceiling);
            }
        }
    }

    /// The lowest free ring next to an interior ring on the floor (a pocket's edge, not a
    /// clamp's).
    fn lowest_edge_ring(&self) -> Option<usize> {
        let rings = self.radii.len();
        (1..rings - 1)
            .filter(|&j| {
                !self.held[j]
                    && ((j > 1 && self.on_floor(j - 1)) || (j + 2 < rings && self.on_floor(j + 1)))
            })
            .min_by(|&a, &b| self.radii[a].total_cmp(&self.radii[b]))
    }

    /// First ring off the floor from the left clamp (the pocket's edge); the last ring if none.
    pub(super) fn first_free(&self) -> usize {
        let rings = self.radii.len();
        (1..rings - 1)
            .find(|&j| !self.on_floor(j))
            .unwrap_or(rings - 1)
    }

    /// Whether the profile equals its mirror image to roundoff.
    fn is_mirror_symmetric(&self, scale: f64) -> bool {
        let n = self.radii.len();
        (0..n / 2).all(|j| {
            self.held[j] == self.held[n - 1 - j]
                && (self.radii[j] - self.radii[n - 1 - j]).abs() <= 1e-10 * scale
        })
    }

    /// Positive eigenvalues of the bordered KKT matrix restricted to mirror-symmetric moves
    /// (as assembled): the Hessian folded onto the first half of the rings. With `N` segments
    /// and `m` the last ring of the half, the quadratic form halves to the same tridiagonal
    /// entries except at the middle: for even `N` the middle ring pairs with itself (diagonal
    /// and constraint entry halved), for odd `N` rings `m` and `m + 1` move together (the
    /// middle segment's coupling joins the diagonal). Counted by an LDL^T sweep, which also
    /// gives `g^T H^-1 g` (Haynsworth: the border adds one positive eigenvalue where it is
    /// negative).
    pub(super) fn symmetric_ascents(&self, lambda: f64) -> Option<usize> {
        let rings = self.radii.len();
        let segments = rings - 1;
        let m = segments / 2;
        let even = segments.is_multiple_of(2);
        let entry = |j: usize| -> (f64, f64, f64) {
            // (diagonal, coupling to j + 1, constraint gradient) of the folded system.
            if self.held[j] {
                return (1.0, 0.0, 0.0);
            }
            let diag = self.dv[j] - lambda * self.dl[j];
            let couple = self.ov[j] - lambda * self.ol[j];
            let next_free = j + 1 < rings && !self.held[j + 1];
            match (j == m, even) {
                (true, true) => (0.5 * diag, 0.0, 0.5 * self.gl[j]),
                (true, false) => (diag + couple, 0.0, self.gl[j]),
                _ => (diag, if next_free { couple } else { 0.0 }, self.gl[j]),
            }
        };
        let mut positive = 0;
        let (mut prev_d, mut prev_off, mut prev_w) = (1.0, 0.0, 0.0);
        let mut quad = 0.0;
        for j in 0..=m {
            let (diag, off, g) = entry(j);
            let l = prev_off / prev_d;
            let d = diag - l * prev_off;
            let w = g - l * prev_w;
            if !(d.abs() > 0.0) || !d.is_finite() {
                return None;
            }
            if !self.held[j] && d > 0.0 {
                positive += 1;
            }
            quad += w * w / d;
            (prev_d, prev_off, prev_w) = (d, off, w);
        }
        quad.is_finite()
            .then_some(positive + usize::from(quad < 0.0))
    }
}
