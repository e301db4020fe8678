//! The knit's yarn stretching at full extension, which chapter 1's inextensible yarn leaves out.
//!
//! At `max_length` the knitted sleeve is pulled straight (eq. 1.10: its radius reaches `r_min`)
//! and, with a bladder, the rubber may fill it before that (the force then grows without bound).
//! A real yarn stretches. Fully extended, each row's strand `S_row` lies along the axis as `2 m`
//! legs of `L_max / n` (eq. 1.10: `L_max = n S_row / (2 m)` for the ideal sleeve), so a
//! cross-section cuts `2 m` legs in parallel and the `n` rows are in series: the yarn is a spring
//! of stiffness `k_s = 2 m E A / L_max`, with `E A` the axial rigidity of the yarn. The same
//! transition as the braid's strands ([`crate::physics::mckibben::transition`]) takes over where
//! the rigid knit is as stiff as its yarn or at its reach, whichever comes first:
//! `F = F(L_t) + k_s (L - L_t)`.

use crate::physics::by_pressure_length::ByPressureLength;
use crate::physics::friction::HysteresisState;
use crate::physics::knitted_muscle::{KnittedAssembly, KnittedOutput};
use crate::physics::mckibben::{transition, OutOfRange, Transition, SURVIVABLE_STRAND_STRAIN};

/// `E A` of the section 1.4 prototype's yarn, N: Spectra (UHMWPE) braided line rated 220 N,
/// breaking near 3.5% strain (`E A = 220 N / 0.035`, rounded).
pub const SPECTRA_LINE_RIGIDITY: f64 = 6300.0;

/// The knit's outputs on the yarn, or the rigid knit's, with why a vacuum was evaluated at zero
/// pressure (a bladder that would collapse) and why the length was out of range.
pub struct YarnOutput {
    pub out: KnittedOutput,
    pub collapsed: Option<String>,
    pub out_of_range: Option<OutOfRange>,
}

type Rigid = (KnittedOutput, Option<String>);

impl KnittedAssembly {
    /// The straight yarn's axial stiffness `k_s = 2 m E A / L_max`, N/m, from the yarn's axial
    /// rigidity `E A` (N).
    pub fn yarn_stiffness(&self, rigidity: f64) -> f64 {
        let sleeve = self.sleeve();
        2.0 * sleeve.params().stitches_per_row * rigidity / sleeve.max_length()
    }

    /// The input length past which no muscle survives: [`SURVIVABLE_STRAND_STRAIN`] of the
    /// sleeve's full extension beyond `max_length`.
    pub fn breaking_length(&self) -> f64 {
        self.length_range().1 + SURVIVABLE_STRAND_STRAIN * self.sleeve().max_length()
    }

    /// Where the yarn takes over at `pressure` for an input `length`; `None` where the rigid
    /// knit holds.
    fn yarn_transition(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Option<Transition<Rigid>> {
        let (lo, hi) = self.valid_lengths();
        let rigid = |l: f64| {
            if !(lo..=hi).contains(&l) {
                return None;
            }
            let (out, collapsed) = self.evaluate(pressure, l, history).ok()?;
            Some((out.force, out.stiffness, (out, collapsed)))
        };
        transition((lo, hi), length.min(self.breaking_length()), k_s, rigid)
    }

    /// The knit with a yarn of axial stiffness `k_s` (N/m) at `(pressure, length)`: the rigid
    /// knit where it holds, else on the stretching yarn up to the breaking length; beyond it, or
    /// below `min_length`, the nearest point inside (with why). `Err` when the sleeve has no
    /// finite state there (not with finite inputs).
    pub fn evaluate_with_yarn(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Result<YarnOutput, String> {
        let on_yarn = (!length.is_nan())
            .then(|| self.yarn_transition(pressure, length, k_s, history))
            .flatten();
        if let Some(t) = on_yarn {
            let breaking = self.breaking_length();
            let out_of_range = (length > breaking).then(|| OutOfRange {
                reason: format!(
                    "length {length} m stretches the yarn more than {}% of the sleeve's full extension past max_length, which no muscle survives",
                    100.0 * SURVIVABLE_STRAND_STRAIN
                ),
                range: (self.valid_lengths().0, breaking),
                point: Some((pressure, breaking)),
            });
            let (mut out, collapsed) = t.rigid;
            out.force += k_s * (length.min(breaking) - t.length);
            out.stiffness = k_s;
            return Ok(YarnOutput {
                out,
                collapsed,
                out_of_range,
            });
        }
        let (lo, hi) = self.valid_lengths();
        let l = if length.is_nan() {
            hi
        } else {
            length.max(lo).min(hi)
        };
        let out_of_range = (l != length).then(|| OutOfRange {
            reason: format!(
                "length {length} m is outside the valid lengths {lo} .. {hi} m (max_length {} m)",
                self.length_range().1
            ),
            range: (lo, hi),
            point: Some((pressure, l)),
        });
        let (out, collapsed) = self.evaluate(pressure, l, history)?;
        Ok(YarnOutput {
            out,
            collapsed,
            out_of_range,
        })
    }

    /// `[d/dP, d/dL]` of the signed outputs on the branch [`Self::evaluate_with_yarn`] takes
    /// (with a bladder, the stiffness's row only if `stiffness`). On the yarn every output but
    /// the force is the rigid knit's at `L_t`, moved by the pressure through
    /// `dL_t/dP = -K_P / K_L` at an interior transition (rigid stiffness `K = k_s`), 0 at the
    /// reach; the force moves with the length by `k_s` up to the breaking length, and the
    /// stiffness is the constant `k_s`. At a clamped length the length column is 0.
    pub fn rows_with_yarn(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
        stiffness: bool,
    ) -> Result<ByPressureLength, String> {
        if !(pressure.is_finite() && length.is_finite()) {
            return Err(format!(
                "partials need finite inputs, got pressure {pressure} Pa and length {length} m"
            ));
        }
        let direction = |l: f64| if l >= history.position { 1.0 } else { -1.0 };
        if let Some(t) = self.yarn_transition(pressure, length, k_s, history) {
            let at = t.length;
            let mut r = self.partial_rows(pressure, at, history, direction(at), t.interior)?;
            let dlt = match r.stiffness {
                Some([kp, kl]) if t.interior && kl != 0.0 => -kp / kl,
                _ => 0.0,
            };
            let [fp, fl] = r.force;
            for y in r.rows_mut() {
                *y = [y[0] + y[1] * dlt, 0.0];
            }
            let moves = length <= self.breaking_length();
            r.force = [fp + (fl - k_s) * dlt, if moves { k_s } else { 0.0 }];
            r.stiffness = (stiffness || r.stiffness.is_some()).then_some([0.0; 2]);
            return Ok(r);
        }
        let (lo, hi) = self.valid_lengths();
        let l = length.max(lo).min(hi);
        let mut r = self.partial_rows(pressure, l, history, direction(l), stiffness)?;
        if l != length {
            // A clamped length no longer moves with the input.
            for y in r.rows_mut() {
                y[1] = 0.0;
            }
            if let Some(s) = r.stiffness.as_mut() {
                s[1] = 0.0;
            }
        }
        Ok(r)
    }
}
