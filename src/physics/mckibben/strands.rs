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

use super::{McKibben, McKibbenOutput};
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
        let rigid = |l: f64| {
            self.evaluate(pressure, l, history)
                .ok()
                .map(|o| (o.force, o.stiffness, o))
        };
        let range = (self.min_length(), self.max_length());
        transition(range, length, strand_stiffness, rigid).map(|t| StrandTransition {
            length: t.length,
            rigid: t.rigid,
            interior: t.interior,
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
}

/// The rigid model holds at `L` unless it has no solution there or pulls and is stiffer than the
/// strands (`k_s`, N/m).
/// Returns its stiffness and outputs there.
fn holds<T>(rigid: &impl Fn(f64) -> Option<(f64, f64, T)>, l: f64, k_s: f64) -> Option<(f64, T)> {
    rigid(l)
        .filter(|(force, stiffness, _)| !(*force > 0.0 && *stiffness > k_s))
        .map(|(_, stiffness, out)| (stiffness, out))
}

/// The transition for an input `length` in the upper half of the rigid model's `range` where
/// that model does not hold; `None` where it holds. At or past the reach, the reach itself when
/// the rigid model holds there (a closed range, as the knitted sleeve's); otherwise bisection
/// between a length where it holds and one where it does not (at most 30 + 60 evaluations, only
/// in this regime).
pub fn transition<T>(
    (lo, hi): (f64, f64),
    length: f64,
    k_s: f64,
    rigid: impl Fn(f64) -> Option<(f64, f64, T)>,
) -> Option<Transition<T>> {
    let upper_half = length > 0.5 * (lo + hi);
    if !upper_half || holds(&rigid, length, k_s).is_some() {
        return None;
    }
    if length >= hi {
        if let Some((_, out)) = holds(&rigid, hi, k_s) {
            return Some(Transition {
                length: hi,
                rigid: out,
                interior: false,
            });
        }
    }
    let mut stiff = length.min(hi);
    let mut soft = None;
    for k in 1..=30 {
        let l = stiff - (stiff - lo) * 0.5f64.powi(k);
        if let Some(out) = holds(&rigid, l, k_s) {
            soft = Some((l, out));
            break;
        }
    }
    let (mut l, (mut slope, mut out)) = soft?;
    for _ in 0..60 {
        let mid = 0.5 * (l + stiff);
        if mid <= l || mid >= stiff {
            break;
        }
        match holds(&rigid, mid, k_s) {
            Some((s, o)) => (l, slope, out) = (mid, s, o),
            None => stiff = mid,
        }
    }
    Some(Transition {
        length: l,
        rigid: out,
        interior: (slope - k_s).abs() <= 1e-6 * k_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn festo_strands_are_aramid_unless_set() {
        let aramid = strand_rigidity(9400.0, false, Some(630.0)).unwrap();
        assert!((aramid - 112e9 / 0.3e9 * 630.0).abs() < 1e-6);
        assert_eq!(strand_rigidity(5e4, true, Some(630.0)).unwrap(), 5e4);
        assert_eq!(strand_rigidity(9400.0, false, None).unwrap(), 9400.0);
        assert!(strand_rigidity(0.0, true, None).is_err());
    }
}
