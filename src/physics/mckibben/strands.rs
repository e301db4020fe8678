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
    /// holds. Bisection between a length where the rigid braid holds and softer than `k_s` and
    /// one where it does not (at most 30 + 60 evaluations, only in this regime).
    pub fn strand_transition(
        &self,
        pressure: f64,
        length: f64,
        strand_stiffness: f64,
        history: &HysteresisState,
    ) -> Option<StrandTransition> {
        let holds = |l: f64| {
            self.evaluate(pressure, l, history)
                .ok()
                .filter(|o| !(o.force > 0.0 && o.stiffness > strand_stiffness))
        };
        let (lo, hi) = (self.min_length(), self.max_length());
        if !(length > 0.5 * (lo + hi)) || holds(length).is_some() {
            return None;
        }
        let mut stiff = length.min(hi);
        let mut soft = None;
        for k in 1..=30 {
            let l = stiff - (stiff - lo) * 0.5f64.powi(k);
            if let Some(out) = holds(l) {
                soft = Some((l, out));
                break;
            }
        }
        let (mut l, mut rigid) = soft?;
        for _ in 0..60 {
            let mid = 0.5 * (l + stiff);
            if mid <= l || mid >= stiff {
                break;
            }
            match holds(mid) {
                Some(out) => (l, rigid) = (mid, out),
                None => stiff = mid,
            }
        }
        let interior = (rigid.stiffness - strand_stiffness).abs() <= 1e-6 * strand_stiffness;
        Some(StrandTransition {
            length: l,
            rigid,
            interior,
        })
    }
}
