//! The strands' own elasticity, which the dissertation's inextensible braid leaves out.
//!
//! Eq. 2.1-2.3 take the strands as inextensible: the braid reaches no further than its strands
//! are long (`L = b`), and with a bladder the incompressible rubber fills the sleeve before that
//! (the force grows without bound towards `max_length`). A real strand stretches: once the rigid
//! braid is as stiff as its strands, or its strands are straight, further stretch is taken by
//! the strands, `F = F(L_t) + k_s (L - L_t)`, with `k_s = E A_total / b` the straight strands'
//! axial stiffness. At an interior transition the rigid slope equals `k_s`, so the force and its
//! slope are continuous; at the braid's reach the force is continuous and its slope rises to
//! `k_s`.

use super::{BranchEnd, McKibben, McKibbenOutput};
use crate::physics::friction::HysteresisState;

/// Strain of the strands past the braid's reach beyond which no muscle survives: aramid breaks
/// near 3.5%, polyester near 12%; 5% of `b` is where the out-of-range policy takes over.
pub const SURVIVABLE_STRAND_STRAIN: f64 = 0.05;

/// Kevlar 49's modulus (112 GPa) over a working stress of a tenth of its strength (0.3 GPa).
const ARAMID_MODULUS_PER_WORKING_STRESS: f64 = 112e9 / 0.3e9;

/// `E A` of all strands together, N: the user's `rigidity` if `set`; else, for a Festo muscle
/// whose datasheet's largest force is `festo_largest_force`, aramid strands working at a tenth of
/// their strength there; else `rigidity` (the default for Table 2.1's polyester strands).
pub fn strand_rigidity(
    rigidity: f64,
    set: bool,
    festo_largest_force: Option<f64>,
) -> Result<f64, String> {
    let rigidity = match festo_largest_force {
        Some(force) if !set => ARAMID_MODULUS_PER_WORKING_STRESS * force,
        _ => rigidity,
    };
    if rigidity.is_finite() && rigidity > 0.0 {
        Ok(rigidity)
    } else {
        Err(format!(
            "strand_rigidity must be positive and finite, got {rigidity} N"
        ))
    }
}

/// Where the strands take over at one pressure.
#[derive(Clone, Copy, Debug)]
pub struct StrandTransition {
    /// Input length `L_t` up to which the rigid braid holds, m.
    pub length: f64,
    /// The rigid muscle's outputs at `L_t`.
    pub rigid: McKibbenOutput,
    /// The rigid slope reaches `k_s` at `L_t` (else `L_t` is the braid's reach, fixed).
    pub interior: bool,
    /// The rigid force turns from a push to a pull at `L_t`, stiffer than the strands on both
    /// sides: `L_t` is where that force is zero, and moves with the pressure.
    pub force_zero: bool,
}

impl McKibben {
    /// The strands' axial stiffness `k_s = E A_total / b`, N/m, from the rigidity of all strands
    /// together `E A_total` (N).
    pub fn strand_stiffness(&self, rigidity: f64) -> f64 {
        rigidity / self.sleeve().strand_length
    }

    /// The input length past which no muscle survives: [`SURVIVABLE_STRAND_STRAIN`] of `b`
    /// beyond the braid's reach.
    pub fn breaking_length(&self) -> f64 {
        self.max_length() + SURVIVABLE_STRAND_STRAIN * self.sleeve().strand_length
    }

    /// The transition at `pressure` for an input `length` where the rigid muscle is out of reach
    /// or under tension and stiffer than the strands (`k_s`, N/m); `None` where the rigid model
    /// holds (see [`transition`]).
    pub fn strand_transition(
        &self,
        pressure: f64,
        length: f64,
        strand_stiffness: f64,
        history: &HysteresisState,
    ) -> Option<StrandTransition> {
        self.strand_transition_on(
            pressure,
            length,
            strand_stiffness,
            history,
            &BranchEnd::new(),
        )
    }

    /// [`Self::strand_transition`] sharing the connector's rising branch `branch` with the
    /// other evaluations at this pressure and history.
    pub(super) fn strand_transition_on(
        &self,
        pressure: f64,
        length: f64,
        strand_stiffness: f64,
        history: &HysteresisState,
        branch: &BranchEnd,
    ) -> Option<StrandTransition> {
        let rigid = |l: f64| {
            self.evaluate_on(pressure, l, history, branch)
                .ok()
                .map(|o| (o.force, o.stiffness, o))
        };
        let range = (self.min_length(), self.max_length());
        let reach = |soft: Option<&McKibbenOutput>| {
            let from = soft.map_or(self.min_length(), |s| s.actual_length);
            self.connector_reach(pressure, from, history, branch)
                .map(|(l, o)| (l, (o.force, o.stiffness, o)))
        };
        transition_within_reach(range, reach, length, strand_stiffness, rigid).map(|t| {
            StrandTransition {
                length: t.length,
                rigid: t.rigid,
                interior: t.interior,
                force_zero: t.force_zero,
            }
        })
    }
}

/// Where the strands take over, for any muscle whose rigid model `rigid(L)` gives force, stiffness
/// and its outputs (`None` where it has no solution).
#[derive(Clone, Copy, Debug)]
pub struct Transition<T> {
    /// Input length `L_t` up to which the rigid model holds, m.
    pub length: f64,
    /// The rigid outputs at `L_t`.
    pub rigid: T,
    /// The rigid slope reaches `k_s` at `L_t` (else `L_t` is the reach, fixed).
    pub interior: bool,
    /// `L_t` is where the rigid force, stiffer than the strands, turns from a push to a pull.
    pub force_zero: bool,
}

/// The transition for an input `length` in the upper half of the rigid model's `range` where
/// that model does not hold; `None` where it holds. At or past the reach, the reach itself when
/// the rigid model holds there (a closed range, as the knitted sleeve's); otherwise the boundary
/// between a length where it holds and one where it does not, narrowed until the two are
/// adjacent floats (the same point bisection reaches): ITP where both ends have a value to
/// interpolate, else bisection (at most 30 + 60-odd evaluations; 15-25 instead of bisection's
/// 50-odd where the rigid model's stiffness or force crosses over; only in this regime). No
/// transition where the rigid model already pulls stiffer than the strands at the first length
/// below the stiff end where it has a solution.
pub fn transition<T>(
    range: (f64, f64),
    length: f64,
    k_s: f64,
    rigid: impl Fn(f64) -> Option<(f64, f64, T)>,
) -> Option<Transition<T>> {
    transition_within_reach(range, |_: Option<&T>| None, length, k_s, rigid)
}

/// [`transition`] for a rigid model whose solutions end at a reach it can find itself from a
/// length where it has one (a series connector's, [`McKibben::connector_reach`]): `reach(soft)`
/// gives the longest length with a solution past the soft end's outputs `soft` (`None`: from
/// the shortest length), and the rigid model's value there. Where the search's stiff end has no
/// solution and the reach lies inside the bracket, the boundary is the reach itself if the
/// rigid model holds there (instead of bisecting through failed solves, each a whole connector
/// solve), else it lies below and is found by ITP from the reach. Where no halving below the
/// stiff end has a solution (they fall in gaps where the force jumps), the boundary is the reach
/// from the shortest length, if the rigid model holds there.
pub fn transition_within_reach<T>(
    range: (f64, f64),
    reach: impl Fn(Option<&T>) -> Option<(f64, (f64, f64, T))>,
    length: f64,
    k_s: f64,
    rigid: impl Fn(f64) -> Option<(f64, f64, T)>,
) -> Option<Transition<T>> {
    search(range, reach, length, k_s, rigid, |_, _| None)
}

/// [`transition`] for a rigid model with a switch that a cheaper, smooth quantity locates (a
/// bladder's contact, where the rigid stiffness jumps): `locate(soft, stiff)` gives, for the
/// bracket the search starts from (both ends with a solution), the length `x` such that the
/// switch lies between `x` and the next float up, or `None` where the bracket holds no switch.
/// The rigid model is evaluated at the next float up, then at `x`: where the switch is the
/// boundary (the model fails above it and holds at `x`) the search ends there, in two
/// evaluations instead of 50-odd; otherwise it goes on exactly as [`transition`]'s.
pub fn transition_located<T>(
    range: (f64, f64),
    length: f64,
    k_s: f64,
    rigid: impl Fn(f64) -> Option<(f64, f64, T)>,
    locate: impl FnOnce(f64, f64) -> Option<f64>,
) -> Option<Transition<T>> {
    search(range, |_: Option<&T>| None, length, k_s, rigid, locate)
}

fn search<T>(
    (lo, hi): (f64, f64),
    reach: impl Fn(Option<&T>) -> Option<(f64, (f64, f64, T))>,
    length: f64,
    k_s: f64,
    rigid: impl Fn(f64) -> Option<(f64, f64, T)>,
    locate: impl FnOnce(f64, f64) -> Option<f64>,
) -> Option<Transition<T>> {
    if length <= 0.5 * (lo + hi) {
        return None;
    }
    let pulls_stiffer = |(force, stiffness, _): &(f64, f64, T)| *force > 0.0 && *stiffness > k_s;
    let mut at_stiff = rigid(length);
    if at_stiff.as_ref().is_some_and(|o| !pulls_stiffer(o)) {
        return None;
    }
    if length >= hi {
        at_stiff = rigid(hi);
        if let Some((_, _, out)) = at_stiff.take_if(|o| !pulls_stiffer(o)) {
            return Some(Transition {
                length: hi,
                rigid: out,
                interior: false,
                force_zero: false,
            });
        }
    }
    let mut stiff = length.min(hi);
    // The soft end: the first length, halving the way from `lo` towards the stiff end, where the
    // rigid model holds. Lengths without a solution are passed over (a connector's reported
    // lengths below its shortest muscle's); one with a solution that pulls stiffer than the
    // strands ends the search: the rigid model stiffens towards the stiff end, so the lengths
    // above it would not hold either (each a whole solve: 30 of them through a connector).
    let mut soft = None;
    for k in 1..=30 {
        let l = stiff - (stiff - lo) * 0.5f64.powi(k);
        match rigid(l) {
            Some(at) if !pulls_stiffer(&at) => {
                soft = Some((l, at));
                break;
            }
            Some(_) => return None,
            None => {}
        }
    }
    let Some((mut l, (force, mut slope, mut out))) = soft else {
        let (at, found) = reach(None).filter(|(r, _)| at_stiff.is_none() && *r < stiff)?;
        return (!pulls_stiffer(&found)).then_some(Transition {
            length: at,
            rigid: found.2,
            interior: (found.1 - k_s).abs() <= 1e-6 * k_s,
            force_zero: false,
        });
    };
    if at_stiff.is_none() {
        if let Some((at, found)) = reach(Some(&out)).filter(|(r, _)| *r > l && *r < stiff) {
            if !pulls_stiffer(&found) {
                return Some(Transition {
                    length: at,
                    rigid: found.2,
                    interior: (found.1 - k_s).abs() <= 1e-6 * k_s,
                    force_zero: false,
                });
            }
            stiff = at;
            at_stiff = Some(found);
        }
    }
    // ITP (interpolate, truncate, project; Oliveira and Takahashi, ACM TOMS 47, 2020) on the
    // quantity whose sign change ends the rigid model: `g = stiffness - k_s` where the soft end
    // pulls below `k_s`, else its force (it holds because it pushes); bisection where the stiff
    // end has no solution. It converges superlinearly on a smooth function and never takes more
    // than two evaluations beyond bisection's count. It stops only at adjacent floats, not at a
    // tolerance: the boundary must be as exact as bisection's (the partials through it are
    // differentiated against central differences).
    let half_ulp = 0.5 * f64::EPSILON * stiff.abs();
    // ITP's parameters from the bracket it starts on (after any steps towards `end`, below):
    // its evaluation count, and `0.2 / width` of the truncation.
    let itp = |width: f64, taken: u32| {
        (
            (width / half_ulp).log2().ceil() + 2.0 + f64::from(taken),
            0.2 / width,
        )
    };
    let (mut most, mut truncation) = itp(stiff - l, 0);
    // (force, stiffness) at each end; the soft end's force is only needed where it pushes.
    let mut soft_end = (force, slope);
    let mut stiff_end = at_stiff.map(|(force, stiffness, _)| (force, stiffness));
    // Illinois: an end kept twice in a row has its value halved in the interpolation, so that a
    // secant stuck next to the other end (a value that saturates, as a connector's series
    // stiffness does towards `max_length`) moves across within a few steps.
    let (mut weights, mut soft_moved_last) = ((1.0, 1.0), None);
    // A located switch `x` is the boundary where the rigid model fails at the next float up and
    // holds at `x`: the bracket is then closed. Otherwise the evaluations are set aside (only
    // the first where the model holds past the switch) and the search goes on as without them.
    let located = stiff_end
        .is_some()
        .then(|| locate(l, stiff))
        .flatten()
        .filter(|x| *x > l && x.next_up() < stiff);
    if let Some(x) = located {
        if let Some(above) = rigid(x.next_up()).filter(pulls_stiffer) {
            if let Some(below) = rigid(x).filter(|o| !pulls_stiffer(o)) {
                (l, slope, out) = (x, below.1, below.2);
                soft_end = (below.0, below.1);
                (stiff, stiff_end) = (x.next_up(), Some((above.0, above.1)));
            }
        }
    }
    // A stiff end without solution, `end`, may be where the rigid force diverges (a bladder's
    // `max_length`), the boundary anywhere from next to it to far below: the search halves the
    // logarithm of the distance to `end` until the bracket spans less than a factor 2 of it (a
    // boundary 1e-9 of the range below `end` takes 6-odd probes, not 30 halvings of the way),
    // unless a probe short of `end` has no solution either (then it bisects).
    let (end, mut towards_end) = (stiff, stiff_end.is_none());
    for taken in 0..120 {
        let mid = 0.5 * (l + stiff);
        if mid <= l || mid >= stiff {
            break;
        }
        let width = stiff - l;
        let ends = stiff_end.map(|(force, stiffness)| {
            if soft_end.1 < k_s {
                stiffness_ends(soft_end.1, stiffness, k_s)
            } else {
                (soft_end.0, force)
            }
        });
        let geometric = towards_end && taken > 0 && end - l > 2.0 * (end - stiff);
        if towards_end && taken > 0 && !geometric {
            towards_end = false;
            (most, truncation) = itp(width, taken);
        }
        let next = match ends {
            _ if geometric => end - ((end - l) * (end - stiff)).sqrt(),
            Some((a, b)) if a <= 0.0 && b > 0.0 => {
                let (a, b) = (a * weights.0, b * weights.1);
                let falsi = l - a * width / (b - a);
                let toward_mid = (mid - falsi).signum();
                // At least a few ulps: else, once one end sits on the boundary, the other
                // closes in by bisection alone.
                let shift = (truncation * width * width).max(8.0 * half_ulp);
                let truncated = if shift <= (mid - falsi).abs() {
                    falsi + toward_mid * shift
                } else {
                    mid
                };
                let radius = half_ulp * (most - f64::from(taken)).exp2() - 0.5 * width;
                if (truncated - mid).abs() <= radius {
                    truncated
                } else {
                    mid - toward_mid * radius.max(0.0)
                }
            }
            // No solution at the stiff end: first try just below it (the common case of a
            // transition at the rigid model's reach), then bisect.
            _ if taken == 0 => stiff - 8.0 * half_ulp,
            _ => mid,
        };
        let next = if next > l && next < stiff { next } else { mid };
        match rigid(next) {
            Some((force, stiffness, o)) if !(force > 0.0 && stiffness > k_s) => {
                (l, slope, out) = (next, stiffness, o);
                soft_end = (force, stiffness);
                if soft_moved_last == Some(true) {
                    weights.1 *= 0.5;
                }
                (weights.0, soft_moved_last) = (1.0, Some(true));
            }
            evaluated => {
                stiff = next;
                // Not the probe just below a reach without solution: its values, next to a
                // singularity, would only slow the interpolation.
                let probe = taken == 0 && stiff_end.is_none();
                towards_end &= probe || evaluated.is_some();
                stiff_end = evaluated
                    .filter(|_| !probe)
                    .map(|(force, stiffness, _)| (force, stiffness));
                if soft_moved_last == Some(false) {
                    weights.0 *= 0.5;
                }
                (weights.1, soft_moved_last) = (1.0, Some(false));
            }
        }
    }
    let interior = (slope - k_s).abs() <= 1e-6 * k_s;
    Some(Transition {
        length: l,
        rigid: out,
        interior,
        // The soft end holds only because it pushes, the stiff end pulls: a sign change of the
        // force (not the end of the rigid model's solutions).
        force_zero: !interior && soft_end.1 >= k_s && stiff_end.is_some(),
    })
}

/// The values `(soft, stiff)` the interpolation of [`transition_within_reach`] takes from the
/// rigid stiffness `K` at each end: `ln(K / k_s)` where both are positive, else `K - k_s`. Towards
/// a bladder's `max_length` the stiffness grows like a pole, `(hi - L)^-m`, on which the secant
/// through `K - k_s` lands next to the soft end every time (the search then gains little over
/// bisection); its logarithm is nearly linear in `L` there. Both change sign where `K = k_s`, and
/// the search stops at adjacent floats whichever it interpolates: the boundary is the same float.
fn stiffness_ends(soft: f64, stiff: f64, k_s: f64) -> (f64, f64) {
    if soft > 0.0 && stiff > 0.0 {
        ((soft / k_s).ln(), (stiff / k_s).ln())
    } else {
        (soft - k_s, stiff - k_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rigid model holds at `L` unless it has no solution there or pulls and is stiffer than the
    /// strands (`k_s`, N/m).
    /// Returns its force, stiffness and outputs there.
    fn holds<T>(
        rigid: &impl Fn(f64) -> Option<(f64, f64, T)>,
        l: f64,
        k_s: f64,
    ) -> Option<(f64, f64, T)> {
        rigid(l).filter(|(force, stiffness, _)| !(*force > 0.0 && *stiffness > k_s))
    }

    /// A rigid model singular at its reach, `F = a / (hi - L)`, stiffness `a / (hi - L)^2`:
    /// the strands (`k_s`) take over exactly where that stiffness is `k_s`,
    /// `L_t = hi - sqrt(a / k_s)`.
    #[test]
    fn transition_is_where_the_rigid_stiffness_reaches_the_strands() {
        let (lo, hi, a, k_s) = (0.05, 0.1, 2.0, 1e5);
        let rigid = |l: f64| (l < hi).then(|| (a / (hi - l), a / (hi - l).powi(2), l));
        let exact = hi - (a / k_s).sqrt();
        for length in [exact + 1e-6, hi, hi + 0.01] {
            let t = transition((lo, hi), length, k_s, rigid).unwrap();
            assert!((t.length - exact).abs() < 1e-12, "{}", t.length);
            assert!(t.interior && t.rigid == t.length);
        }
        assert!(transition((lo, hi), exact - 1e-6, k_s, rigid).is_none());
    }

    /// The last length where `holds` is true by plain bisection to adjacent floats, from the
    /// soft point `l` and the stiff point `stiff`.
    fn bisected(mut l: f64, mut stiff: f64, holds: impl Fn(f64) -> bool) -> f64 {
        loop {
            let mid = 0.5 * (l + stiff);
            if mid <= l || mid >= stiff {
                return l;
            }
            if holds(mid) {
                l = mid;
            } else {
                stiff = mid;
            }
        }
    }

    /// The boundary is the very float bisection reaches, in fewer evaluations, for rigid models
    /// that stiffen past `k_s` smoothly, steeply, or end without a solution before stiffening.
    #[test]
    fn boundary_is_bisections_to_the_last_float() {
        let (lo, hi) = (0.05, 0.1);
        type Model = fn(f64) -> Option<(f64, f64, f64)>;
        // Bisection to adjacent floats takes 50-odd evaluations; where the stiff end has no
        // stiffness ("ends") the search is bisection.
        let models: [(&str, Model, f64, usize); 8] = [
            // Pushes (holds) up to the end of its solutions.
            ("reach", |l| (l < 0.1).then_some((-1.0, 1e9, l)), 1e3, 25),
            // Stiffer than the strands throughout: ends where its force turns to a pull.
            ("pulls", |l| Some((1e3 * (l - 0.08), 1e9, l)), 1e3, 25),
            (
                "pole",
                |l| (l < 0.1).then(|| (2.0 / (0.1 - l), 2.0 / (0.1 - l).powi(2), l)),
                1e5,
                25,
            ),
            // Strands as stiff as the pole 3e-8 m short of it: the boundary is found from the
            // distance to the pole's end, not by halving the way there.
            (
                "near pole",
                |l| (l < 0.1).then(|| (2.0 / (0.1 - l), 2.0 / (0.1 - l).powi(2), l)),
                2e15,
                25,
            ),
            (
                "cubic",
                |l| Some((1e6 * (l - 0.05).powi(3), 3e6 * (l - 0.05).powi(2), l)),
                2e3,
                25,
            ),
            (
                "exp",
                |l| Some(((l * 200.0).exp(), 200.0 * (l * 200.0).exp(), l)),
                1e10,
                25,
            ),
            ("ends", |l| (l < 0.083).then_some((10.0, 1.0, l)), 1e3, 60),
            // The pole through a connector of 1e4 N/m: the series stiffness saturates at it.
            (
                "series",
                |l| {
                    (l < 0.1).then(|| {
                        let k = 2.0 / (0.1 - l).powi(2);
                        (2.0 / (0.1 - l), k / (1.0 + k / 1e4), l)
                    })
                },
                9e3,
                25,
            ),
        ];
        for (name, model, k_s, most) in models {
            let calls = std::cell::Cell::new(0);
            let counted = |l: f64| {
                calls.set(calls.get() + 1);
                model(l)
            };
            let holds_at = |l: f64| holds(&model, l, k_s).is_some();
            for length in [0.097, hi, hi + 0.01] {
                calls.set(0);
                let Some(t) = transition((lo, hi), length, k_s, counted) else {
                    assert!(holds_at(length), "{name} at {length}");
                    continue;
                };
                let stiff = length.min(hi);
                let soft = (1..=30)
                    .map(|k| stiff - (stiff - lo) * 0.5f64.powi(k))
                    .find(|l| holds_at(*l))
                    .unwrap();
                let reference = bisected(soft, stiff, holds_at);
                assert_eq!(t.length, reference, "{name} at {length}");
                assert!(
                    calls.get() <= most,
                    "{name} at {length}: {} evaluations",
                    calls.get()
                );
            }
        }
    }

    /// A rigid model that holds up to and including its reach, softer than the strands there
    /// (the knitted sleeve): the strands take over at the reach itself.
    #[test]
    fn closed_range_hands_over_at_its_reach() {
        let (lo, hi, k_s) = (0.05, 0.1, 1e5);
        let rigid = |l: f64| (lo..=hi).contains(&l).then_some((1e3 * l, 1e3, l));
        let t = transition((lo, hi), hi + 0.01, k_s, rigid).unwrap();
        assert_eq!(t.length, hi);
        assert!(!t.interior);
        assert!(transition((lo, hi), hi, k_s, rigid).is_none());
    }

    /// A rigid model that pulls stiffer than the strands from mid-range up to its reach (soft
    /// strands): no transition in the upper half, found from the first length with a solution
    /// instead of halving the way to the reach 30 times (each a whole solve). Lengths without a
    /// solution are passed over: below the first one with a solution, the boundary is found.
    #[test]
    fn stiffer_than_the_strands_from_mid_range_has_no_transition() {
        let (lo, hi, k_s) = (0.05, 0.1, 1e3);
        let calls = std::cell::Cell::new(0);
        let stiff = |l: f64| {
            calls.set(calls.get() + 1);
            (l < hi).then_some((1e3 * l, 1e9, l))
        };
        for length in [0.097, hi, hi + 0.01] {
            calls.set(0);
            assert!(transition((lo, hi), length, k_s, stiff).is_none());
            assert!(calls.get() <= 3, "{length}: {} evaluations", calls.get());
        }
        // No solution below 0.09 (as a connector's reported lengths short of its shortest
        // muscle's), then pushing up to 0.095 and pulling stiffer past it.
        let gap = |l: f64| (l >= 0.09).then_some((l - 0.095, 1e9, l));
        let t = transition((lo, hi), hi, k_s, gap).unwrap();
        let reference = bisected(0.09375, hi, |l| gap(l).is_some_and(|(f, _, _)| f <= 0.0));
        assert_eq!(t.length, reference);
        assert!(t.force_zero);
    }

    #[test]
    fn festo_strands_are_aramid_unless_set() {
        let aramid = strand_rigidity(9400.0, false, Some(630.0)).unwrap();
        assert!((aramid - 112e9 / 0.3e9 * 630.0).abs() < 1e-6);
        assert_eq!(strand_rigidity(5e4, true, Some(630.0)).unwrap(), 5e4);
        assert_eq!(strand_rigidity(9400.0, false, None).unwrap(), 9400.0);
        assert!(strand_rigidity(0.0, true, None).is_err());
    }
}
