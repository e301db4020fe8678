//! The volume-length table read per step, and the path that builds it.

// `!(x > y)` is deliberate: it also rejects NaN. Index loops walk several coupled arrays.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]
use super::geometry::ShapeGeometry;
use super::newton::MAX_PATH_ITERATIONS;
use super::solver::{PathPoint, Solver, MAX_SUBSTEP_HALVINGS};
use std::f64::consts::PI;

/// Volume-length curve of the non-cylindrical sleeve, built once per parameter set and read per
/// step. Nodes are uniform in length from `max_length` downward.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ShapeTable {
    pub(super) geometry: ShapeGeometry,
    /// Node spacing (m); node `i` is at `max_length - i * spacing`.
    pub(super) spacing: f64,
    pub(super) max_length: f64,
    /// Per node: volume (m^3), `dV/dL` (m^2), `d2V/dL2` (m), largest radius (m).
    pub(super) volume: Vec<f64>,
    pub(super) slope: Vec<f64>,
    pub(super) curvature: Vec<f64>,
    pub(super) max_radius: Vec<f64>,
}

/// Table nodes used by [`ShapeTable::build`] over the stroke.
pub const DEFAULT_TABLE_NODES: usize = 160;

impl ShapeTable {
    /// Follows the volume maximum from full extension (all rings at `r_min`, the cylinder's
    /// volume and slope) down to `end_length` (clamped to the reachable range) with `nodes`
    /// uniform steps, sub-stepping when Newton struggles. The path ends early, with a shorter
    /// table, if the maximum cannot be followed further; `Err` if not even one step succeeds.
    pub fn build(geometry: ShapeGeometry, end_length: f64, nodes: usize) -> Result<Self, String> {
        let mut solver = Solver::new(&geometry);
        let pts = follow_path(&geometry, &mut solver, end_length, nodes, None)?;
        let max_length = geometry.max_length();
        let spacing = if pts.len() > 1 {
            (max_length - pts[pts.len() - 1].length) / (pts.len() - 1) as f64
        } else {
            0.0
        };
        Ok(Self {
            geometry,
            spacing,
            max_length,
            volume: pts.iter().map(|p| p.volume).collect(),
            slope: pts.iter().map(|p| p.slope).collect(),
            curvature: pts.iter().map(|p| p.curvature).collect(),
            max_radius: pts.iter().map(|p| p.max_radius).collect(),
        })
    }

    pub fn geometry(&self) -> &ShapeGeometry {
        &self.geometry
    }

    /// Full extension (m).
    pub fn max_length(&self) -> f64 {
        self.max_length
    }

    /// Shortest tabulated length (m).
    pub fn min_length(&self) -> f64 {
        self.max_length - self.spacing * (self.volume.len().saturating_sub(1)) as f64
    }

    /// Node lengths, longest first.
    pub fn lengths(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.volume.len()).map(|i| self.max_length - i as f64 * self.spacing)
    }

    /// Interval index and local coordinate for a length, clamped into the table.
    #[inline]
    pub(super) fn locate(&self, length: f64) -> (usize, f64) {
        let last = self.volume.len().saturating_sub(1);
        if last == 0 || !(self.spacing > 0.0) {
            return (0, 0.0);
        }
        let u = crate::physics::numerics::bounds::limit(
            (self.max_length - length) / self.spacing,
            0.0,
            last as f64,
        );
        let i = (u.floor() as usize).min(last - 1);
        (i, u - i as f64)
    }

    /// Quintic Hermite on one interval from node values, slopes and curvatures: exact data at
    /// the nodes and C2 between intervals. Hand-written for speed on the per-step path.
    /// Returns `(V, dV/dL, d2V/dL2)`.
    #[inline]
    pub fn evaluate(&self, length: f64) -> (f64, f64, f64) {
        let (i, t) = self.locate(length);
        if self.volume.len() < 2 {
            let v = self.volume.first().copied().unwrap_or(0.0);
            let s = self.slope.first().copied().unwrap_or(0.0);
            let c = self.curvature.first().copied().unwrap_or(0.0);
            return (v, s, c);
        }
        // Local variable runs with t; length decreases, so x-derivatives carry h = -spacing.
        let h = -self.spacing;
        let (y0, y1) = (self.volume[i], self.volume[i + 1]);
        let d0 = h * self.slope[i];
        let d1 = h * self.slope[i + 1];
        let a0 = h * h * self.curvature[i];
        let a1 = h * h * self.curvature[i + 1];
        let delta = y1 - y0;
        let c2 = 0.5 * a0;
        let c3 = 10.0 * delta - 6.0 * d0 - 4.0 * d1 - 1.5 * a0 + 0.5 * a1;
        let c4 = -15.0 * delta + 8.0 * d0 + 7.0 * d1 + 1.5 * a0 - a1;
        let c5 = 6.0 * delta - 3.0 * d0 - 3.0 * d1 - 0.5 * a0 + 0.5 * a1;
        let p = y0 + t * (d0 + t * (c2 + t * (c3 + t * (c4 + t * c5))));
        let dp = d0 + t * (2.0 * c2 + t * (3.0 * c3 + t * (4.0 * c4 + t * 5.0 * c5)));
        let ddp = 2.0 * c2 + t * (6.0 * c3 + t * (12.0 * c4 + t * 20.0 * c5));
        (p, dp / h, ddp / (h * h))
    }

    /// Largest ring radius at a length (m), linear between nodes.
    pub fn max_radius(&self, length: f64) -> f64 {
        let (i, t) = self.locate(length);
        match (self.max_radius.get(i), self.max_radius.get(i + 1)) {
            (Some(a), Some(b)) => a + t * (b - a),
            (Some(a), None) => *a,
            _ => self.geometry.min_radius,
        }
    }

    /// Length of largest volume (zero force) if the table reaches it (m).
    pub fn free_contraction_length(&self) -> Option<f64> {
        let lengths: Vec<f64> = self.lengths().collect();
        for i in 0..self.slope.len().saturating_sub(1) {
            let (s0, s1) = (self.slope[i], self.slope[i + 1]);
            if s0 < 0.0 && s1 >= 0.0 {
                // Refine on the interpolant by bisection (capped).
                let (mut hi, mut lo) = (lengths[i], lengths[i + 1]);
                for _ in 0..60 {
                    let mid = 0.5 * (hi + lo);
                    if self.evaluate(mid).1 < 0.0 {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                return Some(0.5 * (hi + lo));
            }
        }
        None
    }

    /// Ring profile at a length: `(axial position from one clamp, radius)` pairs, in metres.
    /// Re-follows the path from full extension (cost of one table build), for plots.
    pub fn profile(&self, length: f64) -> Result<Vec<(f64, f64)>, String> {
        if !length.is_finite() {
            return Err(format!("length must be finite, got {length}"));
        }
        let length =
            crate::physics::numerics::bounds::limit(length, self.min_length(), self.max_length);
        let mut solver = Solver::new(&self.geometry);
        let nodes = self.volume.len().saturating_sub(1).max(1);
        follow_path(&self.geometry, &mut solver, length, nodes, Some(length))?;
        let mut out = Vec::with_capacity(solver.radii.len());
        let mut z = 0.0;
        out.push((0.0, solver.radii[0]));
        for pair in solver.radii.windows(2) {
            let seg = self
                .geometry
                .segment(pair[0], pair[1])
                .ok_or("profile: a segment does not close")?;
            z += seg.l;
            out.push((z, pair[1]));
        }
        Ok(out)
    }
}

/// Follows the maximum from full extension to `end_length` in uniform steps of
/// `(max - end) / nodes`, or in steps of the same size up to `stop_at` if given (the last step
/// lands on it). Returns the converged nodes, full extension first.
///
/// Each step starts from a prediction: the rings move along the tangent `dr/dL` of the last
/// solve, and the pocket's edge, which the tangent cannot move (held rings stay held), moves on
/// by the rings it crossed per metre over the last step. The fast Newton path
/// ([`Solver::solve_newton`]) then converges in a few O(segments) sweeps; the robust solve is
/// the fallback, then a copy of the highest pocket beside the others ([`Solver::add_pocket`]),
/// then shorter steps.
fn follow_path(
    geom: &ShapeGeometry,
    solver: &mut Solver,
    end_length: f64,
    nodes: usize,
    stop_at: Option<f64>,
) -> Result<Vec<PathPoint>, String> {
    let l_max = geom.max_length();
    let r = geom.min_radius;
    let s = geom.row_strand_length;
    let end = crate::physics::numerics::bounds::limit(end_length, 0.0, l_max);
    let nodes = nodes.clamp(2, 100_000);
    let step = (l_max - end) / nodes as f64;
    let mut pts = Vec::with_capacity(nodes + 1);
    // Full extension: the cylinder at r_min (eq. 1.5-1.7 with r = r_min).
    pts.push(PathPoint {
        length: l_max,
        volume: PI * r * r * l_max,
        slope: 3.0 * PI * r * r - r * s,
        curvature: 0.0,
        max_radius: r,
    });
    if !(step > 0.0) {
        return Ok(pts);
    }
    let mut current = l_max;
    let mut started = false;
    // d2V/dL2 of the last solve, and its pocket's left edge `(length, first free ring)` with
    // the one before.
    let mut last_curvature = f64::NAN;
    let mut edges: [Option<(f64, usize)>; 2] = [None, None];
    let targets: Vec<f64> = match stop_at {
        Some(stop) => {
            let k = ((l_max - stop) / step).ceil().max(0.0) as usize;
            (1..=k)
                .map(|i| (l_max - i as f64 * step).max(stop))
                .collect()
        }
        None => (1..=nodes).map(|i| l_max - i as f64 * step).collect(),
    };
    // The last converged state (restored on failure) and the prediction (the fallback's start).
    let mut backup = solver.clone();
    let mut predicted = solver.clone();
    let mut spare = solver.clone();
    // The state at the first node, from which full extension's curvature is taken.
    let mut first_node: Option<(Solver, f64)> = None;
    'nodes: for &target in &targets {
        let mut sub = target - current;
        let mut halvings = 0;
        while current > target {
            let aim = (current + sub).max(target);
            backup.copy_from(solver);
            let outcome = if started {
                predict(geom, solver, &backup, aim - current, last_curvature, &edges);
                // Late in the stroke the edge runs out to the clamps faster than predicted
                // and moves about one ring per iteration; allow for a share of the rings.
                let iterations = MAX_PATH_ITERATIONS + solver.radii.len() / 16;
                // After a failure only the fast paths retry the shorter steps: where they fail
                // the path has often ended (the clamps' segments turned radial, eq. 1.17), and
                // a dozen failed robust solves there cost several ms on fine sleeves.
                if halvings == 0 {
                    full_step(
                        geom,
                        solver,
                        [&mut predicted, &mut spare],
                        &backup,
                        aim,
                        iterations,
                    )
                } else {
                    predicted.copy_from(solver);
                    fast_solve(geom, solver, &predicted, aim, iterations).ok_or("fast")
                }
            } else {
                nucleate(geom, solver, aim)
            };
            match outcome {
                Ok(p) => {
                    current = aim;
                    started = true;
                    // A step that converged lets the next one grow back towards the node
                    // spacing: a single hard solve would otherwise leave the rest of the node to
                    // steps up to 2^12 times shorter.
                    sub = (2.0 * sub).max(-step);
                    last_curvature = p.curvature;
                    edges = [Some((aim, solver.first_free())), edges[0]];
                    if current <= target {
                        pts.push(p);
                        if pts.len() == 2 {
                            first_node = Some((solver.clone(), p.length));
                        }
                        // Past the free contraction (dV/dL >= 0: no tension left) the volume
                        // maximum soon stops being a maximum and the solves fail; a table that
                        // reaches zero force has all the stroke, so it ends at the first node
                        // there instead of spending its time on a failed tail.
                        if stop_at.is_none() && p.slope >= 0.0 {
                            break 'nodes;
                        }
                    }
                }
                Err(_why) => {
                    solver.copy_from(&backup);
                    halvings += 1;
                    if halvings > MAX_SUBSTEP_HALVINGS {
                        break 'nodes;
                    }
                    // Half of what failed: the regrown step may have been cut to the node.
                    sub = 0.5 * sub.max(target - current);
                }
            }
        }
    }
    if pts.len() < 2 {
        return Err(
            "non-cylindrical shape: the volume maximum could not be followed from full \
                    extension"
                .to_string(),
        );
    }
    // Full extension's curvature: the right-hand limit of the maximum the path follows, from
    // its first node solved back up to just below full extension (a new nucleation there can
    // land on another pocket). Taken where that maximum meets the cylinder's slope there, so
    // that the curvature is the slope's rate; where the slope jumps at full extension (a
    // pocket nucleating at finite depth) no curvature is, and a nucleation there is kept, else
    // the secant through the first node.
    let probe_length = l_max - 1e-3 * step;
    let slope_at_full = pts[0].slope;
    let climbed = first_node
        .and_then(|(mut state, length)| {
            climb_towards_full(geom, &mut state, length, pts[1].curvature, step)
        })
        .filter(|p| {
            let below = l_max - p.length;
            let rate = (slope_at_full - p.slope) / below;
            let roundoff = 64.0 * f64::EPSILON * slope_at_full.abs() / below;
            (rate - p.curvature).abs() <= 0.02 * p.curvature.abs() + roundoff
        });
    let mut probe = Solver::new(geom);
    pts[0].curvature = match climbed
        .ok_or(())
        .or_else(|_| nucleate(geom, &mut probe, probe_length).map_err(|_| ()))
    {
        Ok(p) if p.curvature.is_finite() => p.curvature,
        _ => {
            let p1 = pts[1];
            let c0 = 2.0 * (p1.slope - pts[0].slope) / (p1.length - pts[0].length) - p1.curvature;
            if c0.is_finite() {
                c0
            } else {
                p1.curvature
            }
        }
    };
    Ok(pts)
}

/// From the first node's converged `state` at `length`, follows the same maximum back up to
/// `step / 1000` below full extension, halving the distance each solve: the tangent predictor
/// stays on the branch where one jump of a whole step may not. `None` if a solve fails.
fn climb_towards_full(
    geom: &ShapeGeometry,
    state: &mut Solver,
    length: f64,
    curvature: f64,
    step: f64,
) -> Option<PathPoint> {
    let l_max = geom.max_length();
    let (mut current, mut curvature) = (length, curvature);
    let mut last = state.clone();
    let mut start = state.clone();
    let iterations = MAX_PATH_ITERATIONS + state.radii.len() / 16;
    let mut found = None;
    for k in 1..=10 {
        let below = if k < 10 {
            step / f64::powi(2.0, k)
        } else {
            1e-3 * step
        };
        let aim = l_max - below;
        last.copy_from(state);
        predict(geom, state, &last, aim - current, curvature, &[None, None]);
        start.copy_from(state);
        let p = match fast_solve(geom, state, &start, aim, iterations) {
            Some(p) => p,
            None => {
                state.copy_from(&start);
                state.solve(geom, aim).ok()?
            }
        };
        (current, curvature) = (aim, p.curvature);
        found = Some(p);
    }
    found
}

/// Sets the start of the next solve, `dl` (negative) from the last: every free ring moves along
/// `dr/dL` (left in `y` by the last solve) and `lambda` along `d2V/dL2`, shortened while a
/// segment cannot close (near the clamps late in the stroke); the held rings that the pocket's
/// edge is predicted to cross are released (the fast path holds them again if not).
fn predict(
    geom: &ShapeGeometry,
    solver: &mut Solver,
    last: &Solver,
    dl: f64,
    curvature: f64,
    edges: &[Option<(f64, usize)>; 2],
) {
    if !curvature.is_finite() {
        return;
    }
    let rings = solver.radii.len();
    let mut dl_taken = dl;
    for _ in 0..8 {
        for j in 0..rings {
            if !solver.held[j] {
                solver.radii[j] = (last.radii[j] + last.y[j] * dl_taken)
                    .clamp(geom.min_radius, geom.radius_ceiling());
            }
        }
        if geom.length_and_volume(&solver.radii).is_some() {
            break;
        }
        dl_taken *= 0.5;
    }
    solver.lambda = last.lambda + curvature * dl_taken;
    if let [Some((l1, e1)), Some((l0, e0))] = *edges {
        // Rings crossed per metre over the last step, extrapolated (the edge moves outward).
        if e1 < e0 && l0 > l1 && e1 > 1 {
            let crossed = (e0 - e1) as f64 * (-dl_taken) / (l0 - l1);
            let edge = e1.saturating_sub(crossed.floor() as usize).max(1);
            for j in (edge..e1).flat_map(|j| [j, rings - 1 - j]) {
                if solver.on_floor(j) {
                    solver.held[j] = false;
                }
            }
        }
    }
}

/// The fast Newton path from `start` (a copy of `solver`): plain Newton and Newton with the
/// inertia-correcting shift, the one the last solve succeeded with first. The second is skipped
/// where the shift applied at no iterate of the first: it would repeat the first step for step
/// (often a full budget of iterations, late on thin strands).
fn fast_solve(
    geom: &ShapeGeometry,
    solver: &mut Solver,
    start: &Solver,
    aim: f64,
    max_iterations: usize,
) -> Option<PathPoint> {
    let first = solver.prefer_shift;
    for shift in [first, !first] {
        solver.copy_from(start);
        if let Some(p) = solver.solve_newton(geom, aim, max_iterations, shift) {
            solver.prefer_shift = shift;
            return Some(p);
        }
        if !solver.shift_mattered {
            return None;
        }
    }
    None
}

/// One solve on the path: the fast Newton path from the prediction, else the robust solve from
/// the same start.
fn solve_from(
    geom: &ShapeGeometry,
    solver: &mut Solver,
    start: &mut Solver,
    aim: f64,
    max_iterations: usize,
) -> Result<PathPoint, &'static str> {
    start.copy_from(solver);
    if let Some(p) = fast_solve(geom, solver, start, aim, max_iterations) {
        return Ok(p);
    }
    solver.copy_from(start);
    solver.solve(geom, aim)
}

/// Robust-solve iterations where a ring is at the ceiling and a new pocket did not converge:
/// where it succeeds there it takes a few (measured on a thin strand with 70 segments), and
/// where it fails its full budget was a quarter of that sleeve's table.
const CAPPED_ROBUST_ITERATIONS: usize = 60;

/// A full step from the prediction in `solver`: the fast Newton path, then the robust solve,
/// then a copy of the highest pocket beside the others ([`Solver::add_pocket`]) from the last
/// converged state `last`. Where a ring of `last` is at the ceiling the copy comes first: a thin
/// strand's beads capped there cannot take up more length. `buffers` hold the prediction and a
/// spare.
fn full_step(
    geom: &ShapeGeometry,
    solver: &mut Solver,
    buffers: [&mut Solver; 2],
    last: &Solver,
    aim: f64,
    max_iterations: usize,
) -> Result<PathPoint, &'static str> {
    let [prediction, spare] = buffers;
    prediction.copy_from(solver);
    if let Some(p) = fast_solve(geom, solver, prediction, aim, max_iterations) {
        return Ok(p);
    }
    let mut with_pocket = |solver: &mut Solver| {
        solver.copy_from(last);
        if !solver.add_pocket() {
            return None;
        }
        spare.copy_from(solver);
        fast_solve(geom, solver, spare, aim, max_iterations)
    };
    if (1..last.radii.len() - 1).any(|j| last.at_ceiling(j)) {
        if let Some(p) = with_pocket(solver) {
            return Ok(p);
        }
        solver.copy_from(prediction);
        return solver.solve_within(geom, aim, CAPPED_ROBUST_ITERATIONS);
    }
    solver.copy_from(prediction);
    solver
        .solve(geom, aim)
        .or_else(|why| with_pocket(solver).ok_or(why))
}

/// Nucleation just below full extension: a centred pocket and a near-uniform bulge are solved
/// from their seeds and the larger volume is kept; where that is a mirror-symmetric pair of
/// pockets (a saddle), one pocket of the pair alone where it holds more. Leaves the winner in
/// `solver`.
fn nucleate(
    geom: &ShapeGeometry,
    solver: &mut Solver,
    aim: f64,
) -> Result<PathPoint, &'static str> {
    // The seeded pocket's edge moves out about one ring per Newton iteration while it finds
    // its width, a share of the rings.
    let iterations = MAX_PATH_ITERATIONS + solver.radii.len() / 8;
    let mut bulge_solver = solver.clone();
    let mut start = solver.clone();
    solver.seed_pocket(geom, geom.max_length() - aim);
    let pocket = solve_from(geom, solver, &mut start, aim, iterations);
    bulge_solver.seed_uniform(geom);
    // Where neither Newton path reaches the bulge but the pocket is found, the pocket is kept:
    // the robust solve's crawl from the uniform seed takes tens of ms on thin strands.
    let bulge = if pocket.is_ok() {
        start.copy_from(&bulge_solver);
        fast_solve(geom, &mut bulge_solver, &start, aim, iterations).ok_or("bulge")
    } else {
        solve_from(geom, &mut bulge_solver, &mut start, aim, iterations)
    };
    let found = match (pocket, bulge) {
        (Ok(p), Ok(b)) if b.volume > p.volume => {
            *solver = bulge_solver;
            Ok(b)
        }
        (Err(_), Ok(b)) => {
            *solver = bulge_solver;
            Ok(b)
        }
        (p, _) => p,
    }?;
    // Both seeds can end on a mirror-symmetric saddle, two pockets of which the fast path
    // accepts the pair (a maximum among symmetric profiles): its ascent moves length from one
    // pocket to the other. The path must start on a maximum, so one pocket of the pair is
    // solved alone and taken where it holds more volume (its mirror image has the same).
    let mut check = solver.clone();
    if check.bordered_ascents(geom) == Some(1) {
        return Ok(found);
    }
    check.copy_from(solver);
    if !check.keep_left_half(geom.min_radius) {
        return Ok(found);
    }
    start.copy_from(&check);
    match fast_solve(geom, &mut check, &start, aim, iterations) {
        Some(one) if one.volume > found.volume => {
            *solver = check;
            Ok(one)
        }
        _ => Ok(found),
    }
}

#[cfg(test)]
mod first_curvature_tests;
