//! Rate-independent friction hysteresis: the `± C_f P_eff` term of eq. 2.4 (and the knitted
//! muscle's friction of eq. 1.21), made chatter-free.
//!
//! The sign of Coulomb friction follows the direction of sliding. Taking that sign literally
//! (`sign(dL/dt)`) flips the force on any numerical jitter of a length that holds still. Instead
//! a normalized friction state `z` in [-1, 1] follows a stop (elastic-perfectly-plastic, Prandtl)
//! operator of the position: `z <- clamp(z + dx / presliding_length, -1, 1)`. Within a reversal
//! the friction force grows linearly over `presliding_length` (elastic presliding, as in Dahl's
//! model with a linear stress-strain law), then saturates at full sliding friction. The state
//! depends only on the path of the position, never on time or on how finely a monotone path is
//! sampled: on a monotone path the clamped sum equals the clamp of the total.

/// Stop-operator parameters: the presliding displacement over which friction reverses, m
/// (or whatever unit the driving position has).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StopOperator {
    presliding_length: f64,
}

/// Friction history: the normalized friction `z` in [-1, 1] (+1 = full friction resisting
/// extension, i.e. adding tension while the position grows) and the position it was last at.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HysteresisState {
    pub z: f64,
    pub position: f64,
}

impl HysteresisState {
    /// At rest (no friction force) at `position`; a non-finite position is taken as 0.
    pub fn at_rest(position: f64) -> Self {
        Self {
            z: 0.0,
            position: if position.is_finite() { position } else { 0.0 },
        }
    }

    /// Why this history cannot come from [`StopOperator::advance`] (eq. 1.21, 2.4): `z` outside
    /// [-1, 1] or a non-finite position. For histories restored from an importer's bytes.
    pub fn check(&self, name: &str) -> Result<(), String> {
        if !(self.z.abs() <= 1.0 && self.position.is_finite()) {
            return Err(format!(
                "{name}: z = {} must be in [-1, 1] and position = {} m finite",
                self.z, self.position
            ));
        }
        Ok(())
    }
}

impl StopOperator {
    /// `presliding_length` must be positive and finite: zero would be the discontinuous
    /// sign function that chatters.
    pub fn new(presliding_length: f64) -> Result<Self, String> {
        if !(presliding_length.is_finite() && presliding_length > 0.0) {
            return Err(format!(
                "presliding_length must be positive and finite, got {presliding_length}"
            ));
        }
        Ok(Self { presliding_length })
    }

    pub fn presliding_length(&self) -> f64 {
        self.presliding_length
    }

    /// The state after moving from `state.position` to `position`. A non-finite position leaves
    /// the state unchanged (no NaN can enter the history).
    #[inline]
    pub fn advance(&self, state: &HysteresisState, position: f64) -> HysteresisState {
        if !position.is_finite() {
            return *state;
        }
        let z = state.z + (position - state.position) / self.presliding_length;
        // clamp() passes NaN through; z is finite or ±inf here, and ±inf clamps to ±1.
        HysteresisState {
            z: z.clamp(-1.0, 1.0),
            position,
        }
    }

    /// `dz/dx` for a small further move from `state` in the direction of `direction` (sign):
    /// `1/presliding_length` unless saturated in that direction. For Newton slopes.
    #[inline]
    pub fn slope(&self, state: &HysteresisState, direction: f64) -> f64 {
        let saturated = (direction > 0.0 && state.z >= 1.0) || (direction < 0.0 && state.z <= -1.0);
        if saturated {
            0.0
        } else {
            1.0 / self.presliding_length
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn op() -> StopOperator {
        StopOperator::new(1e-4).unwrap()
    }

    #[test]
    fn extension_and_contraction_follow_different_curves() {
        // A length cycle 0 -> 1 mm -> 0: z goes to +1 on extension, -1 on contraction; in the
        // middle of the stroke the two branches differ by the full width 2 (eq. 2.4's ± term).
        let o = op();
        let mut s = HysteresisState::at_rest(0.0);
        let mut up = vec![];
        for i in 0..=100 {
            s = o.advance(&s, 1e-3 * i as f64 / 100.0);
            up.push(s.z);
        }
        let mut down = vec![];
        for i in (0..=100).rev() {
            s = o.advance(&s, 1e-3 * i as f64 / 100.0);
            down.push(s.z);
        }
        down.reverse();
        assert_eq!(up[50], 1.0);
        assert_eq!(down[50], -1.0);
        // Presliding: a reversal moves z linearly, by 1 per presliding length (1e-4 = 10 samples).
        assert!((down[95] - 0.5).abs() < 1e-9, "{}", down[95]);
        assert!(down[90].abs() < 1e-9, "{}", down[90]);
        assert_eq!(down[80], -1.0);
        assert!((up[5] - 0.5).abs() < 1e-9);
    }

    #[test]
    fn holding_still_or_jitter_never_flips() {
        let o = op();
        let mut s = o.advance(&HysteresisState::at_rest(0.0), 1e-3);
        assert_eq!(s.z, 1.0);
        for i in 0..10_000 {
            let jitter = if i % 2 == 0 { 1e-12 } else { -1e-12 };
            s = o.advance(&s, 1e-3 + jitter);
            assert!(s.z > 1.0 - 2e-8, "{}", s.z);
        }
        for _ in 0..100 {
            s = o.advance(&s, 1e-3);
        }
        assert!(s.z > 1.0 - 2e-8);
    }

    #[test]
    fn rejects_bad_presliding() {
        for bad in [0.0, -1e-4, f64::NAN, f64::INFINITY] {
            assert!(StopOperator::new(bad).is_err());
        }
    }

    #[test]
    fn non_finite_position_keeps_state() {
        let o = op();
        let s = o.advance(&HysteresisState::at_rest(0.0), 3e-5);
        assert_eq!(o.advance(&s, f64::NAN), s);
        assert_eq!(o.advance(&s, f64::INFINITY), s);
        // Huge finite jumps saturate, no NaN.
        assert_eq!(o.advance(&s, 1e300).z, 1.0);
        assert_eq!(o.advance(&s, -1e300).z, -1.0);
    }

    #[test]
    fn slope_is_zero_only_when_saturated_in_that_direction() {
        let o = op();
        let s = o.advance(&HysteresisState::at_rest(0.0), 1.0);
        assert_eq!(o.slope(&s, 1.0), 0.0);
        assert_eq!(o.slope(&s, -1.0), 1e4);
        assert_eq!(o.slope(&HysteresisState::at_rest(0.0), 1.0), 1e4);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// Rate-independence: any subdivision of a monotone move gives the same state as one
        /// step, and the state stays in [-1, 1] on any path.
        #[test]
        fn monotone_paths_are_sample_independent(
            z0 in -1.0f64..1.0, x0 in -1e-2f64..1e-2, dx in -1e-3f64..1e-3,
            cuts in prop::collection::vec(0.0f64..1.0, 0..40),
        ) {
            let o = op();
            let start = HysteresisState { z: z0, position: x0 };
            let one = o.advance(&start, x0 + dx);
            let mut fractions = cuts.clone();
            fractions.sort_by(|a, b| a.total_cmp(b));
            let mut s = start;
            for f in fractions {
                s = o.advance(&s, x0 + f * dx);
            }
            s = o.advance(&s, x0 + dx);
            prop_assert!((s.z - one.z).abs() < 1e-9);
            prop_assert!(s.z.abs() <= 1.0);
        }

        #[test]
        fn any_path_stays_bounded(path in prop::collection::vec(-1e-2f64..1e-2, 1..60)) {
            let o = op();
            let mut s = HysteresisState::at_rest(0.0);
            for x in path {
                s = o.advance(&s, x);
                prop_assert!(s.z.is_finite() && s.z.abs() <= 1.0);
            }
        }
    }
}
