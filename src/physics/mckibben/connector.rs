//! The series connector of section 2.4: the muscle's own length `L` that a reported length
//! `L + F(L)/k` gives, and the longest reported length the connector reaches.

use super::LIMIT_MARGIN;
use super::{BranchEnd, Core, McKibben, McKibbenOutput, BRACKET_STEPS, ROOT_ITERATIONS};
use crate::physics::friction::HysteresisState;
use crate::physics::numerics::root::{newton_bisection, RootOptions, Sample};

impl McKibben {
    /// The muscle lengths the connector solve searches: the muscle's range, inset by 1e-9 of
    /// it where a bladder makes its ends singular.
    pub(super) fn connector_edges(&self) -> (f64, f64) {
        match &self.bladder {
            Some(_) => {
                let (a, b) = (self.min_length(), self.max_length());
                let margin = 1e-9 * (b - a);
                (a + margin, b - margin)
            }
            None => (0.0, self.sleeve.strand_length),
        }
    }

    /// The longest reported length the connector reaches at `pressure` on the branch through
    /// the muscle length `from` (where it has a solution), with the outputs there (series
    /// stiffness, as [`Self::evaluate`]). `None` without a connector, or where the muscle does not
    /// rise at `from`. See [`Self::branch_end`]; the branch from the shortest length is taken
    /// from (or stored in) `branch` when it passes `from`.
    pub(super) fn connector_reach(
        &self,
        pressure: f64,
        from: f64,
        history: &HysteresisState,
        branch: &BranchEnd,
    ) -> Option<(f64, McKibbenOutput)> {
        let c = self.connector_compliance?;
        let (lo_edge, _) = self.connector_edges();
        let from_shortest = *branch.get_or_init(|| self.branch_end(pressure, lo_edge, history, c));
        let reported = |(l, core): &(f64, Core)| l + c * core.out.force;
        // The branch from the shortest length passes `from` only if it ends further in both
        // lengths: past a jump of the force it may end further in `L` but short of `from`'s
        // reported length.
        let passes = |end: &(f64, Core)| {
            end.0 > from
                && !self
                    .at_actual_length(pressure, from, history)
                    .is_ok_and(|at| reported(end) <= from + c * at.out.force)
        };
        let (l, core) = from_shortest
            .filter(passes)
            .or_else(|| self.branch_end(pressure, from, history, c))?;
        let reported = reported(&(l, core));
        let mut out = core.out;
        let k_m = out.stiffness;
        out.stiffness = k_m / (1.0 + c * k_m);
        (reported.is_finite() && out.stiffness.is_finite()).then_some((reported, out))
    }

    /// The end of the branch on which the reported length `L + c F(L)` rises with the muscle's
    /// own length `L` (`1 + c dF/dL > 0`), from `from`: at a fold (`dF/dL = -1/c`), where the
    /// force jumps (a vacuum the free bladder can no longer hold), or at the longest length the
    /// connector solve searches. Found in `L` by bisection to 1e-9 of the muscle's length range
    /// (about 30 muscle evaluations, where bisecting the reported length took a whole connector
    /// solve per step), and on a steep wall until the reported length is resolved too (down to
    /// adjacent floats, where a wall topping out between two of them ends the branch past its
    /// top, which the connector solve meets with the relation's force): the end returned rises
    /// or tops out such a wall, so the connector solve and the strands' transition agree on it
    /// exactly; short of a fold it moves the reach by second order, short
    /// of a jump by `1 + c dF/dL` times at most 1e-9 of the range. `None` where the reported
    /// length does not rise at `from`.
    fn branch_end(
        &self,
        pressure: f64,
        from: f64,
        history: &HysteresisState,
        c: f64,
    ) -> Option<(f64, Core)> {
        let (lo_edge, hi_edge) = self.connector_edges();
        let rising = |l: f64| {
            self.at_actual_length(pressure, l, history)
                .ok()
                .filter(|core| 1.0 + c * core.newton_slope > 0.0)
        };
        let reported = |(l, core): &(f64, Core)| l + c * core.out.force;
        // On the branch past `end`: rising there, and not below `end`'s reported length (the
        // force may jump between two rising stretches, where the slope alone does not show it).
        let on_branch = |l: f64, end: &(f64, Core)| {
            rising(l)
                .map(|core| (l, core))
                .filter(|at| reported(at) >= reported(end))
        };
        let mut end = (from, rising(from)?);
        if let Some(at_edge) = on_branch(hi_edge, &end) {
            return Some(at_edge);
        }
        let tolerance = 1e-9 * (hi_edge - lo_edge);
        // Resolved in the reported length too: next to the muscle's singular ends the wall
        // rises through all of its reported lengths (1e10 m and more) within 1e-9 of the range,
        // so the end is narrowed until its slope moves the reported length by less than
        // LIMIT_MARGIN of the range across what is left.
        let resolved = |end: &(f64, Core), width: f64| {
            width <= tolerance
                && (1.0 + c * end.1.newton_slope) * width <= LIMIT_MARGIN * (hi_edge - lo_edge)
        };
        let mut past = hi_edge;
        for _ in 0..1100 {
            let mid = 0.5 * (end.0 + past);
            if resolved(&end, past - end.0) || mid <= end.0 || mid >= past {
                break;
            }
            match on_branch(mid, &end) {
                Some(at) => end = at,
                None => past = mid,
            }
        }
        // At adjacent floats (only a steep wall narrows the end that far) the wall's force
        // scatters by rounding over a few floats: the branch goes on over the next few where
        // it rises again, and a wall that tops out between two of them (its slope steps from
        // rising to falling) reaches the length past the top, where the connector solve meets
        // the reported lengths in between with the relation's force ([`Self::steep_root`]'s
        // test, the step explained by the steeper end's slope).
        if past == end.0.next_up() {
            let mut x = past;
            for _ in 0..8 {
                if x >= hi_edge {
                    break;
                }
                let Ok(at) = self.at_actual_length(pressure, x, history) else {
                    break;
                };
                let step = reported(&(x, at)) - reported(&end);
                let steeper = 1.0 + c * f64::max(end.1.newton_slope, at.newton_slope);
                if 1.0 + c * at.newton_slope > 0.0 && step >= 0.0 {
                    end = (x, at);
                } else if step > 0.0 && step <= 4.0 * steeper * (x - end.0) {
                    return Some((x, at));
                }
                x = x.next_up();
            }
        }
        Some(end)
    }

    /// Solves `reported = L + c F(L)` for the muscle length `L` (c = 1/k): bracket by doubling
    /// steps inside the muscle's length range (from a first guess on a steep rising wall, by
    /// steps that double from a fraction of Newton's, [`Self::bracket_on_wall`]), then
    /// safeguarded Newton-bisection. Hand-written, capped loops for robustness on the per-step
    /// path. Where that finds no bracket from a first
    /// guess past a fold or a jump of the force (the reported length falls with `L` there), it
    /// brackets on the branch rising from the muscle's shortest length (up to its end,
    /// [`Self::branch_end`], kept in `branch`), and so it does where the bracket holds a jump of
    /// the force instead of a root (the reported length falls in the jump's gap); where that
    /// branch does not reach it either, the length is out of reach. What it returns solves the
    /// relation, to [`LIMIT_MARGIN`] of the muscle's length range at worst (a wall's rounding
    /// noise), tested on the residual itself; where the wall is steeper than the floats of `L`
    /// resolve, with the relation's force ([`Self::steep_root`]).
    pub(super) fn through_connector(
        &self,
        pressure: f64,
        reported: f64,
        history: &HysteresisState,
        c: f64,
        branch: &BranchEnd,
    ) -> Result<Core, String> {
        let solved = self.solve_connector(pressure, reported, history, c, branch);
        #[cfg(test)]
        if let Ok(core) = &solved {
            sampled::record(reported, core.out.actual_length, core.out.force, c);
        }
        solved
    }

    fn solve_connector(
        &self,
        pressure: f64,
        reported: f64,
        history: &HysteresisState,
        c: f64,
        branch: &BranchEnd,
    ) -> Result<Core, String> {
        let (lo_edge, hi_edge) = self.connector_edges();
        let eval = |l: f64| -> Result<(f64, Core), String> {
            let core = self.at_actual_length(pressure, l, history)?;
            Ok((l + c * core.out.force - reported, core))
        };
        let unreachable = || {
            format!(
                "reported length {reported} m cannot be reached through the connector: the \
                 muscle's length range is ({}, {}) m",
                self.min_length(),
                self.max_length()
            )
        };
        let x0 = crate::physics::numerics::bounds::limit(reported, lo_edge, hi_edge);
        let (h0, core0) = eval(x0)?;
        if h0 == 0.0 {
            return Ok(core0);
        }
        // The bracket on the branch rising from the shortest length, up to its end.
        let on_shortest_branch = || -> Result<Bracket, String> {
            let found = branch.get_or_init(|| self.branch_end(pressure, lo_edge, history, c));
            let (end, core) = found.ok_or_else(unreachable)?;
            let h_end = end + c * core.out.force - reported;
            if h_end == 0.0 {
                return Ok(Bracket::Root(core));
            }
            let (h_lo, core_lo) = eval(lo_edge)?;
            if h_lo == 0.0 {
                return Ok(Bracket::Root(core_lo));
            }
            if !(h_lo < 0.0 && h_end > 0.0) {
                return Err(unreachable());
            }
            Ok(Bracket::Between(lo_edge, end))
        };
        let (mut bracket, mut shortest) = match self.bracket(x0, h0, &eval)? {
            Bracket::None if 1.0 + c * core0.newton_slope > 0.0 => {
                match self.bracket_on_wall((x0, h0, 1.0 + c * core0.newton_slope), c, &eval)? {
                    Bracket::None => return Err(unreachable()),
                    found => (found, false),
                }
            }
            Bracket::None => (on_shortest_branch()?, true),
            found => (found, false),
        };
        // A solution satisfies the relation to LIMIT_MARGIN of the muscle's length range (the
        // rounding noise of a nearly stress-free wall's force, 1e-8 to 1e-4 of the range, which
        // the solve's first guess may have landed across), beyond the rounding of the sum
        // `L + c F`. Checked on the residual itself: a jump of the force, or a wall too steep
        // for any float of `L` to meet it, leaves no solution there.
        let noise = LIMIT_MARGIN * (hi_edge - lo_edge);
        let on_relation = |h: f64, core: &Core| {
            let sum = reported.abs() + core.out.actual_length.abs() + (c * core.out.force).abs();
            h.abs() <= noise + 4.0 * f64::EPSILON * sum
        };
        // h rises with L (slope 1 + c dF/dL > 0 on the stable branch). Converged when the length
        // moves by less than rounding; F then changes by K times that. A sign change that the
        // slope cannot explain within 1e-9 of the range is a jump of the force, which the
        // reported length falls in: no root there.
        let options = RootOptions {
            absolute: 1e-17,
            relative: 1e-14,
            max_iterations: ROOT_ITERATIONS,
            jump_width: 1e-9 * (hi_edge - lo_edge),
        };
        loop {
            let (lo, hi) = match bracket {
                Bracket::Root(core) => return Ok(core),
                Bracket::Between(lo, hi) => (lo, hi),
                Bracket::None => return Err(unreachable()),
            };
            // The narrowest sign change the finder has seen, where the bisection below starts.
            let seen = std::cell::Cell::new((lo, hi));
            let root = newton_bisection(lo, hi, 0.5 * (lo + hi), true, options, |x| {
                let (value, core) = eval(x)?;
                let (a, b) = seen.get();
                if value < 0.0 && x > a {
                    seen.set((x, b));
                } else if value > 0.0 && x < b {
                    seen.set((a, x));
                }
                let slope = 1.0 + c * core.newton_slope;
                Ok::<_, String>(Some(Sample {
                    value,
                    slope,
                    payload: core,
                }))
            })?;
            let core = root
                .payload
                .ok_or_else(|| "connector solve did not run".to_string())?;
            let h = core.out.actual_length + c * core.out.force - reported;
            if on_relation(h, &core) {
                return Ok(core);
            }
            // The finder also stops where its Newton step is below rounding far from the root
            // (a slope that misjudges the steep wall next to the muscle's singular ends): what
            // is left of its bracket is bisected on the residual alone.
            if !root.jump {
                let (a, b) = seen.get();
                if let Some(core) =
                    self.steep_root((a, b), c, reported, options.jump_width, &eval, &on_relation)?
                {
                    return Ok(core);
                }
            }
            if shortest {
                return Err(format!(
                    "{}; the muscle's force jumps across it at muscle length {} m",
                    unreachable(),
                    core.out.actual_length
                ));
            }
            // Past a jump the branch from the shortest length may still reach it.
            (bracket, shortest) = (on_shortest_branch()?, true);
        }
    }

    /// The root of the connector residual `h` in `(a, b)`, where `h(a) < 0 < h(b)`, by bisection
    /// on `h` alone: the first length on a rising stretch (`1 + c dF/dL > 0`, a stable
    /// equilibrium of muscle and connector) that satisfies the relation (`on_relation`), else, at
    /// adjacent floats of the muscle's length, the wall's own step across the root (the slopes
    /// there explain the residual's step, to the factor 4 of the finder's jump test): the muscle
    /// is steeper than the floats of `L` resolve (next to its singular ends, `dF/dL` up to
    /// 1e15 N/m and more: 0.01 N between adjacent floats), and the state at the float nearer
    /// the root carries the relation's force `(reported - L) / c`, which lies between the
    /// muscle's forces at the two floats. `None` at a jump of the force (no solution there).
    fn steep_root(
        &self,
        (a, b): (f64, f64),
        c: f64,
        reported: f64,
        jump_width: f64,
        eval: &impl Fn(f64) -> Result<(f64, Core), String>,
        on_relation: &impl Fn(f64, &Core) -> bool,
    ) -> Result<Option<Core>, String> {
        let (mut a, mut b) = (a, b);
        let (mut at_a, mut at_b) = (None::<(f64, Core)>, None::<(f64, Core)>);
        // Across the bracket the residual rises (bisection keeps `h(a) < 0 < h(b)`); a step
        // that the steeper end's slope does not explain is a jump of the force, told once the
        // bracket is narrower than `jump_width` (as the finder tells it).
        let explained = |(h_a, at_a): &(f64, Core), (h_b, at_b): &(f64, Core), width: f64| {
            let steeper = f64::max(c * at_a.newton_slope, c * at_b.newton_slope) + 1.0;
            h_b - h_a <= 4.0 * steeper * width
        };
        // Capped as the branch's end is: halvings down to adjacent floats, subnormals included.
        for _ in 0..1100 {
            let mid = 0.5 * (a + b);
            if !(mid > a && mid < b) {
                break;
            }
            if let (Some(lo), Some(hi), true) = (&at_a, &at_b, b - a <= jump_width) {
                if !explained(lo, hi, b - a) {
                    return Ok(None);
                }
            }
            let (h, core) = eval(mid)?;
            if on_relation(h, &core) && 1.0 + c * core.newton_slope > 0.0 {
                return Ok(Some(core));
            }
            if h < 0.0 {
                (a, at_a) = (mid, Some((h, core)));
            } else {
                (b, at_b) = (mid, Some((h, core)));
            }
        }
        let (h_a, core_a) = match at_a {
            Some(at) => at,
            None => eval(a)?,
        };
        let (h_b, core_b) = match at_b {
            Some(at) => at,
            None => eval(b)?,
        };
        if !(h_a < 0.0 && h_b > 0.0 && explained(&(h_a, core_a), &(h_b, core_b), b - a)) {
            return Ok(None);
        }
        let mut core = if -h_a <= h_b { core_a } else { core_b };
        core.out.force = (reported - core.out.actual_length) / c;
        Ok(Some(core))
    }

    /// Brackets the root of the connector residual `h` from `x0` (where `h = h0 != 0`) by
    /// doubling steps towards it, inside the connector solve's lengths.
    fn bracket(
        &self,
        x0: f64,
        h0: f64,
        eval: &impl Fn(f64) -> Result<(f64, Core), String>,
    ) -> Result<Bracket, String> {
        let (lo_edge, hi_edge) = self.connector_edges();
        let upward = h0 < 0.0;
        let (mut inner, mut step) = (x0, h0.abs());
        for _ in 0..BRACKET_STEPS {
            let cand = if upward {
                (inner + step).min(hi_edge)
            } else {
                (inner - step).max(lo_edge)
            };
            let (h, core) = eval(cand)?;
            if h == 0.0 {
                return Ok(Bracket::Root(core));
            }
            if (h > 0.0) == upward {
                return Ok(Bracket::crossed(upward, inner, cand));
            }
            let at_edge = cand == if upward { hi_edge } else { lo_edge };
            if at_edge {
                break;
            }
            inner = cand;
            step *= 2.0;
        }
        Ok(Bracket::None)
    }
}

impl McKibben {
    /// Brackets the root of the connector residual `h` on the rising stretch through `x0`
    /// (`h = h0 != 0`, slope `rise0 = 1 + c dF/dL` there) where [`Self::bracket`] found no
    /// sign change: its first step, `|h0|`, is `rise0` times Newton's, and on a steep wall next
    /// to a singular end (`rise0` 1e17 and more) it crosses the whole range to the far end's
    /// wall, of the same sign, past a root 1e-9 of the range away. Only there (`rise0 > 1`):
    /// from a sixteenth of Newton's step the distance doubles while `|h|` falls towards the
    /// root, up to `|h0|`; off the wall (`1 + c dF/dL <= 1`) [`Self::bracket`] goes on from
    /// there, and a rise of `|h|` (past a fold or a jump of the force) ends the stretch.
    fn bracket_on_wall(
        &self,
        (x0, h0, rise0): (f64, f64, f64),
        c: f64,
        eval: &impl Fn(f64) -> Result<(f64, Core), String>,
    ) -> Result<Bracket, String> {
        if rise0.is_nan() || rise0 <= 1.0 {
            return Ok(Bracket::None);
        }
        let (lo_edge, hi_edge) = self.connector_edges();
        let upward = h0 < 0.0;
        let span = if upward { hi_edge - x0 } else { x0 - lo_edge };
        let reach = span.min(h0.abs());
        let mut d = (h0.abs() / rise0 / 16.0).max(f64::EPSILON * x0.abs());
        let (mut inner, mut h_inner) = (x0, h0);
        // Doublings from a float's spacing span the range in about 60 steps.
        for _ in 0..128 {
            if d.is_nan() || d >= reach {
                break;
            }
            let cand = if upward { x0 + d } else { x0 - d };
            d *= 2.0;
            if cand == inner {
                continue;
            }
            let Ok((h, core)) = eval(cand) else {
                break;
            };
            if h == 0.0 {
                return Ok(Bracket::Root(core));
            }
            if (h > 0.0) == upward {
                return Ok(Bracket::crossed(upward, inner, cand));
            }
            if h.abs() > h_inner.abs() {
                break;
            }
            if 1.0 + c * core.newton_slope <= 1.0 {
                return self.bracket(cand, h, eval);
            }
            (inner, h_inner) = (cand, h);
        }
        Ok(Bracket::None)
    }
}

/// Where the connector solve's bracket search ended.
enum Bracket {
    /// On the root itself.
    Root(Core),
    /// Between `(lo, hi)` with `h(lo) < 0 < h(hi)`.
    Between(f64, f64),
    /// No sign change inside the muscle's lengths.
    None,
}

impl Bracket {
    /// The bracket between the last length `inner` without a sign change and `cand`, the first
    /// with one, searching up (`upward`) or down.
    fn crossed(upward: bool, inner: f64, cand: f64) -> Self {
        if upward {
            Bracket::Between(inner, cand)
        } else {
            Bracket::Between(cand, inner)
        }
    }
}

#[cfg(test)]
#[path = "connector_sampled.rs"]
pub(super) mod sampled;

#[cfg(test)]
mod tests {
    use super::super::{BladderModel, FrictionParams, MuscleGeometry};
    use super::*;
    use crate::physics::bladder::BladderTube;

    /// Table 2.1's muscle C with a soft rubber and friction under a vacuum, its friction
    /// history far out: near `max_length` the bladder is pressed on the sleeve by a negative
    /// effective pressure and the force jumps from a small tension to a large push, so the
    /// reported length `L + F/k` rises, then falls, and the connector reaches no further than
    /// the top of the rise.
    fn vacuum_muscle() -> (McKibben, f64, HysteresisState) {
        let g = MuscleGeometry::muscle_c();
        let tube = BladderTube {
            mooney_c1: 1326.9,
            mooney_c2: 0.0196,
            ..g.tube()
        };
        let model = BladderModel::DissertationContinuum { nodes: 58 };
        let friction = FrictionParams {
            coefficient: 0.04,
            presliding_length: 0.26,
        };
        let m = McKibben::new(g.sleeve().unwrap(), tube, model, Some(friction), 923.0).unwrap();
        (m, -3482.7, HysteresisState::at_rest(9.5))
    }

    /// The reach is the largest reported length on the rising branch, found independently here
    /// by scanning the muscle's own length; every reported length below it is solved on that
    /// branch (`L + F/k` equals it), also where the first guess lies past the jump, and none
    /// above it.
    #[test]
    fn reach_is_the_top_of_the_rising_branch() {
        let (m, p, rest) = vacuum_muscle();
        let c = 1.0 / 923.0;
        let (lo, hi) = m.connector_edges();
        let reported = |l: f64| {
            m.at_actual_length(p, l, &rest)
                .ok()
                .map(|core| l + c * core.out.force)
        };
        // The scan (steps of 2.5e-5 of the range in L, where L + F/k rises by about as much): the
        // reported length's largest value before it first falls.
        let mut top = f64::NEG_INFINITY;
        for i in 0..=40_000 {
            let l = lo + (hi - lo) * f64::from(i) / 40_000.0;
            match reported(l) {
                Some(r) if r >= top => top = r,
                _ => break,
            }
        }
        let (reach, out) = m.connector_reach(p, lo, &rest, &BranchEnd::new()).unwrap();
        assert!(
            reach >= top && reach - top < 5e-5 * (hi - lo),
            "{reach} vs {top}"
        );
        assert!(out.force > 0.0);
        // The first guess L = reported lands past the jump for these reported lengths.
        for below in [1e-3, 1e-6, 1e-9] {
            let r = reach - below * (hi - lo);
            let o = m.evaluate(p, r, &rest).unwrap();
            let residual = o.actual_length + c * o.force - r;
            assert!(residual.abs() < 1e-12 * r, "{below}: {residual}");
            assert!(o.actual_length < out.actual_length && o.force > 0.0);
        }
        assert!(m.evaluate(p, reach * (1.0 + 1e-12), &rest).is_err());
    }

    /// Table 2.1's muscle D with an almost stress-free rubber (`C1` 0.28 Pa) of one quadrature
    /// node under a vacuum: the free bladder's force jumps between rising stretches of the
    /// reported length `L + F/k`, where the slope alone does not show the jump. From any muscle
    /// length on a rising stretch the connector reaches at least that length's own reported
    /// length (a reach below it belongs to another stretch); and the strands' transition past
    /// `max_length` is that reach, found without bisecting through connector solves.
    #[test]
    fn reach_from_a_length_is_not_below_its_reported_length() {
        let g = MuscleGeometry::muscle_d();
        let tube = BladderTube {
            mooney_c1: 0.2847,
            mooney_c2: 3.127e-3,
            ..g.tube()
        };
        let model = BladderModel::DissertationContinuum { nodes: 1 };
        let m = McKibben::new(g.sleeve().unwrap(), tube, model, None, 16553.48).unwrap();
        let (p, rest, c) = (-36058.86, HysteresisState::at_rest(0.1), 1.0 / 16553.48);
        let (lo, hi) = m.connector_edges();
        let mut rising = 0;
        for i in 1..200 {
            let l = lo + (hi - lo) * f64::from(i) / 200.0;
            let Ok(core) = m.at_actual_length(p, l, &rest) else {
                continue;
            };
            if 1.0 + c * core.newton_slope <= 0.0 {
                continue;
            }
            rising += 1;
            let own = l + c * core.out.force;
            let (reach, out) = m.connector_reach(p, l, &rest, &BranchEnd::new()).unwrap();
            assert!(reach >= own, "from {l}: reach {reach} below {own}");
            assert_eq!(reach, out.actual_length + c * out.force);
        }
        assert!(rising > 100, "{rising}");
        let t = m
            .strand_transition(p, m.breaking_length(), 327396.4, &rest)
            .unwrap();
        assert_eq!(t.length, t.rigid.actual_length + c * t.rigid.force);
        assert!(!t.interior && t.rigid.force < 0.0 && t.length < m.max_length());
    }

    /// Table 2.1's muscle A with an almost stress-free rubber (`mooney_c2` 1.7e-4 Pa, no
    /// `mooney_c1`, 14 layers as written) and friction, through a soft connector of `k` N/m.
    fn soft_rubber_muscle_a(k: f64) -> McKibben {
        let g = MuscleGeometry::muscle_a();
        let tube = BladderTube {
            mooney_c1: 0.0,
            mooney_c2: 1.716e-4,
            ..g.tube()
        };
        let model = BladderModel::DissertationLayers { layers: 14 };
        let friction = FrictionParams {
            coefficient: 6.289e-3,
            presliding_length: 2.683e-8,
        };
        McKibben::new(g.sleeve().unwrap(), tube, model, Some(friction), k).unwrap()
    }

    /// That muscle under a vacuum that pulls its bladder's bore nearly closed: near the top of
    /// its range a solve returns a root of the connector relation `L + F/k = reported` (to
    /// `LIMIT_MARGIN` of the range at worst) or an error, never a length off it.
    #[test]
    fn a_solve_returns_a_root_or_nothing_where_the_bore_is_pulled_in() {
        let k = 0.1609;
        let m = soft_rubber_muscle_a(k);
        let (p, rest) = (-1.371e4, HysteresisState::at_rest(3.094));
        let (lo, hi) = (m.min_length(), m.max_length());
        let (mut roots, mut gaps) = (0, 0);
        // The top 1% of the range, where the strands' transition searches.
        for i in 0..400 {
            let reported = hi - 0.01 * (hi - lo) * f64::from(i) / 400.0;
            match m.evaluate(p, reported, &rest) {
                Ok(out) => {
                    let h = out.actual_length + out.force / k - reported;
                    assert!(
                        h.abs() <= LIMIT_MARGIN * (hi - lo),
                        "{reported}: residual {h} m"
                    );
                    roots += 1;
                }
                Err(_) => gaps += 1,
            }
        }
        assert!(gaps > 0, "{roots} roots, {gaps} gaps");
    }

    /// The same muscle's evaluation anywhere from a 1 kPa to a 100 kPa vacuum, at lengths up to
    /// 30 times past the breaking length, with the friction history at either end: with the free
    /// bladder's force smooth where its bore is pulled in (the layers' pressures taken from the
    /// outside in), every connector solve converges or ends out of reach on a smooth residual,
    /// at most 2,000 wall evaluations in all (a force left to the root's rounding, newtons there,
    /// makes each transition probe a connector solve that bisects through its jumps: 27,700).
    #[test]
    fn a_collapsed_bladder_through_a_soft_connector_is_evaluated_in_bounded_work() {
        let g = MuscleGeometry::muscle_a();
        let m = soft_rubber_muscle_a(0.1609);
        let k_s = 2.359e11 / g.strand_length;
        let kernels = crate::physics::bladder::kernel_count;
        for p in [-1e3, -1e4, -1.371e4, -2e4, -1e5] {
            for length in [0.05, 0.09, 0.1, 0.105, 0.5, 3.094] {
                for from in [0.05, 3.094] {
                    let before = kernels();
                    let (out, _) =
                        m.evaluate_with_strands(p, length, k_s, &HysteresisState::at_rest(from));
                    let cost = kernels() - before;
                    assert!(cost <= 2000, "{p} Pa, {length} m from {from} m: {cost}");
                    if let Some(o) = out {
                        assert!(o.force.is_finite() && o.stiffness.is_finite());
                    }
                }
            }
        }
    }

    /// Past the reach the strands take over at the reach itself: the force is continuous there
    /// and rises with the strands' stiffness beyond.
    #[test]
    fn strands_take_over_at_the_reach() {
        let (m, p, rest) = vacuum_muscle();
        let (reach, at) = m
            .connector_reach(p, m.min_length(), &rest, &BranchEnd::new())
            .unwrap();
        let k_s = 1e5;
        let force = |l: f64| m.evaluate_with_strands(p, l, k_s, &rest).0.unwrap().force;
        let d = 1e-9;
        assert!((force(reach - d) - at.force).abs() < 1e-6);
        assert!((force(reach + d) - at.force - k_s * d).abs() < 1e-6);
        let t = m.strand_transition(p, reach + 1e-3, k_s, &rest).unwrap();
        assert_eq!(t.length, reach);
        assert!(!t.interior);
    }
}
