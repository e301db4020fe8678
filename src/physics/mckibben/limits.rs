//! The muscle at both ends of its stroke: the strands stretching past the rigid braid's reach
//! (see [`super::strands`]), the out-of-range policy for lengths no muscle survives, and the
//! partials on the branch each takes. Shared by the McKibbenMuscle and McKibbenJoint FMUs.

use super::SURVIVABLE_STRAND_STRAIN;
use super::{BranchEnd, McKibben, McKibbenOutput, StrandTransition};
use crate::physics::by_pressure_length::ByPressureLength;
use crate::physics::friction::HysteresisState;

/// With a bladder the force grows without bound at both length limits; an out-of-range length
/// the strands do not take is evaluated this fraction of the range inside the limit (finite,
/// steep force).
pub const LIMIT_MARGIN: f64 = 1e-3;

/// An input without a solution, and the point evaluated instead.
#[derive(Clone, Debug, PartialEq)]
pub struct OutOfRange {
    /// Why the input has no solution.
    pub reason: String,
    /// The lengths the model evaluates, m.
    pub range: (f64, f64),
    /// `(pressure, length)` evaluated instead; `None` if none could be.
    pub point: Option<(f64, f64)>,
}

impl OutOfRange {
    /// The log message, explaining what is evaluated until the inputs return.
    pub fn message(&self) -> String {
        let (lo, hi) = self.range;
        let what = match self.point {
            Some((p, l)) => format!("evaluating at pressure {p} Pa and length {l} m"),
            None => "holding the previous outputs".into(),
        };
        format!(
            "{} (lengths the model evaluates: {lo} .. {hi} m); {what} until the inputs return",
            self.reason
        )
    }
}

/// Whether a muscle with this signed force is slack: a braid cannot push, so past its free
/// contraction (signed force < 0) its strands buckle and it carries no force and has no
/// stiffness, unless the dissertation's `signed` force is asked for.
#[inline]
pub fn is_slack(force: f64, signed: bool) -> bool {
    !signed && force < 0.0
}

impl McKibben {
    /// The muscle with strands of axial stiffness `k_s` (N/m) at `(pressure, length)`: the rigid
    /// model where it holds, else on the stretching strands up to the breaking length; beyond
    /// it, or for a length without a solution below the strands, the nearest point inside the
    /// range (returned with why). `None` only if no point can be evaluated.
    pub fn evaluate_with_strands(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> (Option<McKibbenOutput>, Option<OutOfRange>) {
        let branch = BranchEnd::new();
        let (reason, rigid) = match self.evaluate_on(pressure, length, history, &branch) {
            Ok(out) if !(out.force > 0.0 && out.stiffness > k_s) => return (Some(out), None),
            Ok(out) => (String::new(), Some(out)),
            Err(reason) => (reason, None),
        };
        // Out of the rigid braid's reach, or stiffer than its strands: the strands stretch.
        let breaking = self.breaking_length();
        let on_strands = length.min(breaking);
        if let Some(t) = self.strand_transition_on(pressure, on_strands, k_s, history, &branch) {
            let clamp = self.past_breaking(pressure, length);
            let mut out = t.rigid;
            out.force += k_s * (on_strands - t.length);
            out.stiffness = k_s;
            return (Some(out), clamp);
        }
        if let Some(out) = rigid {
            return (Some(out), None);
        }
        let (out, clamp) = self.clamped(pressure, length, history, reason);
        (out, Some(clamp))
    }

    /// Out of range below the strands (no rigid solution at `length`, for `reason`): the
    /// outputs at the nearest length with one, under a vacuum the muscle cannot hold there at
    /// zero pressure.
    fn clamped(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
        reason: String,
    ) -> (Option<McKibbenOutput>, OutOfRange) {
        let clamped = self.solvable_length(length);
        let fallback = [(pressure, clamped), (pressure.max(0.0), clamped)]
            .into_iter()
            .find_map(|(p, l)| self.evaluate(p, l, history).ok().map(|o| (p, l, o)));
        let clamp = OutOfRange {
            reason,
            range: (self.min_length(), self.max_length()),
            point: fallback.as_ref().map(|(p, l, _)| (*p, *l)),
        };
        (fallback.map(|(_, _, out)| out), clamp)
    }

    /// Why a length past the breaking length is evaluated at it, `None` up to it.
    fn past_breaking(&self, pressure: f64, length: f64) -> Option<OutOfRange> {
        let breaking = self.breaking_length();
        (length > breaking).then(|| OutOfRange {
            reason: format!(
                "length {length} m stretches the strands more than {}% of their length past max_length, which no muscle survives",
                100.0 * SURVIVABLE_STRAND_STRAIN
            ),
            range: (self.min_length(), breaking),
            point: Some((pressure, breaking)),
        })
    }

    /// For a caller that refuses an out-of-range input instead of evaluating it: why
    /// [`Self::evaluate_with_strands`] would evaluate `length` at another point, decided without
    /// the strands' transition where one rigid evaluation decides it. Past the breaking length
    /// with no rigid solution at `length` (always so without a connector, whose reported length
    /// never exceeds the muscle's), that evaluation is at the breaking length, or at the nearest
    /// solvable length where the strands do not take over: out of range either way. `None` where
    /// this does not decide it (the whole evaluation does). The point is `None`: nothing is
    /// evaluated.
    pub fn refused_past_breaking(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
    ) -> Option<OutOfRange> {
        let out_of_range = self.past_breaking(pressure, length)?;
        self.evaluate(pressure, length, history)
            .is_err()
            .then_some(OutOfRange {
                point: None,
                ..out_of_range
            })
    }

    /// The nearest length the rigid model evaluates: inside the muscle's limits, and by
    /// [`LIMIT_MARGIN`] of the stroke inside them when a bladder makes the limits singular.
    pub fn solvable_length(&self, length: f64) -> f64 {
        let (lo, hi) = (self.min_length(), self.max_length());
        let margin = if self.bladder().is_some() {
            LIMIT_MARGIN * (hi - lo)
        } else {
            0.0
        };
        // max/min rather than clamp: never panics, even on limits from a crafted FMU state.
        length.max(lo + margin).min(hi - margin)
    }

    /// The transition [`Self::evaluate_with_strands`] uses at these inputs, if on the strands.
    pub fn strand_point(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Option<StrandTransition> {
        let branch = BranchEnd::new();
        match self.evaluate_on(pressure, length, history, &branch) {
            Ok(out) if !(out.force > 0.0 && out.stiffness > k_s) => None,
            _ => {
                let on_strands = length.min(self.breaking_length());
                self.strand_transition_on(pressure, on_strands, k_s, history, &branch)
            }
        }
    }

    /// The signed force on the branch [`Self::evaluate_with_strands`] takes below the strands
    /// (at the clamped length out of range); on the strands the force is positive.
    pub fn signed_force_on_branch(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
    ) -> Result<f64, String> {
        let at = |p: f64, l: f64| self.evaluate(p, l, history);
        self.on_branch(pressure, length, at)
            .map(|(o, _, _)| o.force)
    }

    /// The partials of the signed outputs on the branch [`Self::evaluate_with_strands`] takes:
    /// on the strands see [`Self::strand_partials`]; out of range it evaluates at a clamped
    /// length (and, under a vacuum it cannot hold, at zero pressure), which the input no longer
    /// moves, so those columns are zero.
    pub fn partials_with_strands(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Result<ByPressureLength, String> {
        if let Some(d) = self.strand_partials(pressure, length, k_s, history)? {
            return Ok(d);
        }
        self.partials_below_strands(pressure, length, history)
    }

    /// [`Self::partials_with_strands`] off the strands.
    fn partials_below_strands(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
    ) -> Result<ByPressureLength, String> {
        let at = |p: f64, l: f64| self.partials(p, l, history).map(|(_, d)| d);
        let (mut d, by_l, by_p) = self.on_branch(pressure, length, at)?;
        for y in d.rows_mut() {
            y[0] *= f64::from(u8::from(by_p));
            y[1] *= f64::from(u8::from(by_l));
        }
        Ok(d)
    }

    /// The signed force of [`Self::evaluate_with_strands`] with [`Self::partials_with_strands`]:
    /// where the rigid model holds, one pass of [`McKibben::partials`] (the torque solver's
    /// per-iteration cost).
    pub fn force_and_partials_with_strands(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Result<(f64, ByPressureLength), String> {
        if let Ok((out, d)) = self.partials(pressure, length, history) {
            if !(out.force > 0.0 && out.stiffness > k_s) {
                return Ok((out.force, d));
            }
        }
        // On the strands: one transition for the force and the partials (as
        // `evaluate_with_strands` and `strand_partials` find it).
        if let Some(t) = self.strand_point(pressure, length, k_s, history) {
            let force = t.rigid.force + k_s * (length.min(self.breaking_length()) - t.length);
            return Ok((
                force,
                self.partials_at_transition(&t, pressure, length, k_s, history)?,
            ));
        }
        // Off the strands, without searching for their transition again: the rigid model at the
        // inputs, or out of range at the clamped point (`evaluate_with_strands`'s fallback).
        let at = |p: f64, l: f64| self.partials(p, l, history);
        let ((out, mut d), by_l, by_p) = self.on_branch(pressure, length, at)?;
        for y in d.rows_mut() {
            y[0] *= f64::from(u8::from(by_p));
            y[1] *= f64::from(u8::from(by_l));
        }
        Ok((out.force, d))
    }

    /// [`Self::evaluate_with_strands`] with the partials of [`Self::partials_with_strands`],
    /// searching for the strands' transition once (the torque solver evaluates both at every
    /// iteration).
    pub fn evaluate_and_partials_with_strands(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> (
        Option<McKibbenOutput>,
        Option<OutOfRange>,
        Result<ByPressureLength, String>,
    ) {
        let rigid = match self.partials(pressure, length, history) {
            Ok((out, d)) if !(out.force > 0.0 && out.stiffness > k_s) => {
                return (Some(out), None, Ok(d))
            }
            Ok(rigid) => Some(rigid),
            Err(_) => None,
        };
        let reason = if rigid.is_some() {
            String::new()
        } else {
            match self.evaluate(pressure, length, history) {
                Err(reason) => reason,
                // Outputs where their partials overflow: each on its own branch.
                Ok(_) => {
                    let (out, clamp) = self.evaluate_with_strands(pressure, length, k_s, history);
                    let d = self.partials_with_strands(pressure, length, k_s, history);
                    return (out, clamp, d);
                }
            }
        };
        let on_strands = length.min(self.breaking_length());
        let branch = BranchEnd::new();
        if let Some(t) = self.strand_transition_on(pressure, on_strands, k_s, history, &branch) {
            let d = self.partials_at_transition(&t, pressure, length, k_s, history);
            let mut out = t.rigid;
            out.force += k_s * (on_strands - t.length);
            out.stiffness = k_s;
            return (Some(out), self.past_breaking(pressure, length), d);
        }
        if let Some((out, d)) = rigid {
            return (Some(out), None, Ok(d));
        }
        let (out, clamp) = self.clamped(pressure, length, history, reason);
        let d = self.partials_below_strands(pressure, length, history);
        (out, Some(clamp), d)
    }

    /// `[d/dpressure, d/dlength]` of the signed stiffness on the branch
    /// [`Self::evaluate_with_strands`] takes: 0 on the strands (their constant `k_s`), else
    /// [`McKibben::stiffness_partials`] (a second-order pass through the bladder).
    pub fn stiffness_partials_with_strands(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Result<[f64; 2], String> {
        if self.strand_point(pressure, length, k_s, history).is_some() {
            return Ok([0.0; 2]);
        }
        let at = |p: f64, l: f64| self.stiffness_partials(p, l, history);
        let (row, by_l, by_p) = self.on_branch(pressure, length, at)?;
        Ok([
            if by_p { row[0] } else { 0.0 },
            if by_l { row[1] } else { 0.0 },
        ])
    }

    /// On the strands `F = F(P, L_t(P)) + k_s (L - L_t(P))` and every other output is the
    /// rigid muscle's at `L_t`: by the chain rule with `dL_t/dP = -K_P / K_L` at an interior
    /// transition (where the rigid stiffness `K` equals `k_s`), `-F_P / F_L` where the rigid
    /// force turns to a pull (`F(P, L_t) = 0`, so `dF/dP = k_s F_P / F_L`), 0 at the braid's
    /// reach. The length moves only the force, by `k_s`, up to the breaking length. `None` off
    /// the strands.
    pub fn strand_partials(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Result<Option<ByPressureLength>, String> {
        let Some(t) = self.strand_point(pressure, length, k_s, history) else {
            return Ok(None);
        };
        self.partials_at_transition(&t, pressure, length, k_s, history)
            .map(Some)
    }

    /// [`Self::strand_partials`] on the strands, from their transition `t` at these inputs.
    fn partials_at_transition(
        &self,
        t: &StrandTransition,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Result<ByPressureLength, String> {
        let (_, mut d) = self.partials(pressure, t.length, history)?;
        let [fp, fl] = d.force;
        let dlt = if t.interior {
            let [kp, kl] = self.stiffness_partials(pressure, t.length, history)?;
            if kl != 0.0 {
                -kp / kl
            } else {
                0.0
            }
        } else if t.force_zero && fl != 0.0 {
            -fp / fl
        } else {
            0.0
        };
        for y in d.rows_mut() {
            *y = [y[0] + y[1] * dlt, 0.0];
        }
        let moves = length <= self.breaking_length();
        d.force = [fp + (fl - k_s) * dlt, if moves { k_s } else { 0.0 }];
        Ok(d)
    }

    /// Runs `at` on the branch [`Self::evaluate_with_strands`] takes below the strands: at the
    /// inputs, or out of range at the clamped length (whose column the input no longer moves)
    /// and, under a vacuum the muscle cannot hold there, at zero pressure (neither column
    /// moves). Returns `at`'s result with whether the length and the pressure columns move.
    fn on_branch<T>(
        &self,
        pressure: f64,
        length: f64,
        at: impl Fn(f64, f64) -> Result<T, String>,
    ) -> Result<(T, bool, bool), String> {
        if let Ok(d) = at(pressure, length) {
            return Ok((d, true, true));
        }
        let clamped = self.solvable_length(length);
        if let Ok(d) = at(pressure, clamped) {
            return Ok((d, false, true));
        }
        at(pressure.max(0.0), clamped).map(|d| (d, false, false))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::mckibben::{BladderModel, MuscleGeometry};

    /// A length past the breaking length that the rigid model cannot reach is refused without
    /// the strands' transition, and the whole evaluation puts it out of range too; one that a
    /// connector reaches on the rigid branch (a long reported length, a short muscle) is left to
    /// the whole evaluation, which evaluates it there. The thin wall's force grows without bound
    /// towards `max_length`, so through either connector every length is reached, on a stretch
    /// where the reported length rises (the connector of 923 N/m at 1.001 times the breaking
    /// length: 7.63 N at 0.0947 m; its bracket's first step crossed the range to the shortest
    /// length's wall, and the length was refused). Up to the breaking length nothing is
    /// refused.
    #[test]
    fn refusal_past_breaking_agrees_with_the_evaluation() {
        let rest = HysteresisState::at_rest(0.1);
        let g = MuscleGeometry::muscle_a();
        let k_s = 1e6;
        for (stiffness, pressure) in [(0.0, 3e5), (923.0, 3e5), (923.0, -5e3), (1.0, 3e5)] {
            let m = McKibben::from_geometry(&g, BladderModel::ThinWall, None, stiffness).unwrap();
            let breaking = m.breaking_length();
            for l in [
                0.5 * breaking,
                breaking,
                1.001 * breaking,
                2.0 * breaking,
                30.0,
            ] {
                let refused = m.refused_past_breaking(pressure, l, &rest);
                let (out, clamp) = m.evaluate_with_strands(pressure, l, k_s, &rest);
                if l <= breaking {
                    assert!(refused.is_none(), "{stiffness} N/m, {l} m");
                    continue;
                }
                match refused {
                    Some(why) => {
                        assert!(clamp.is_some(), "{stiffness} N/m, {l} m: {out:?}");
                        assert!(why.point.is_none() && why.reason.contains("past max_length"));
                    }
                    None => {
                        assert!(stiffness > 0.0, "{l} m");
                        let out = out.unwrap();
                        assert!(clamp.is_none() && out.actual_length < m.max_length());
                        let h = out.actual_length + out.force / stiffness - l;
                        assert!(h.abs() < 1e-9 * l, "{stiffness} N/m, {l} m: {h} m");
                        let own = m.at_actual_length(pressure, out.actual_length, &rest);
                        assert!(1.0 + own.unwrap().newton_slope / stiffness > 0.0);
                    }
                }
            }
        }
    }

    /// Where the rigid muscle is stiffer than soft strands (`k_s`) even where its force turns
    /// from a push to a pull, the strands take over at that force's zero `L_0(P)`:
    /// `F = k_s (L - L_0(P))`. `L_0` is bisected here on the rigid model's sign alone; the
    /// force and `dF/dP` (a central difference of that closed form) are the strands' branch's.
    #[test]
    fn strands_from_the_force_zero_move_with_the_pressure() {
        let rest = HysteresisState::at_rest(0.09);
        let mut checked = 0;
        for g in [MuscleGeometry::muscle_a(), MuscleGeometry::muscle_c()] {
            for model in [BladderModel::ThinWall, BladderModel::Exact { nodes: 8 }] {
                let m = McKibben::from_geometry(&g, model, None, 0.0).unwrap();
                let (lo, hi) = (m.min_length(), m.max_length());
                for k_s in [1.0, 10.0] {
                    for p in [2e4, 1e5, 3e5] {
                        let force = |p: f64, l: f64| m.evaluate(p, l, &rest).unwrap().force;
                        // The rigid force's zero between mid-stroke and the limit.
                        let (from, to) = (0.5 * (lo + hi), hi - 1e-9 * (hi - lo));
                        if !(force(p, from) < 0.0 && force(p, to) > 0.0) {
                            continue;
                        }
                        let zero = |p: f64| {
                            let (mut a, mut b) = (from, to);
                            while b - a > 1e-15 * b {
                                let mid = 0.5 * (a + b);
                                if force(p, mid) > 0.0 {
                                    b = mid;
                                } else {
                                    a = mid;
                                }
                            }
                            a
                        };
                        let l0 = zero(p);
                        let l = l0 + 1e-3 * (hi - l0);
                        let t = m.strand_point(p, l, k_s, &rest);
                        let Some(t) = t.filter(|t| t.force_zero) else {
                            continue;
                        };
                        assert!((t.length - l0).abs() < 1e-12 * l0, "{} vs {l0}", t.length);
                        let (f, d) = m.force_and_partials_with_strands(p, l, k_s, &rest).unwrap();
                        // The rigid force at the last float of `L_t` is zero to within its stiffness times
                        // that float's spacing.
                        assert!((f - k_s * (l - l0)).abs() < 1e-6 * f, "{f}");
                        let h = 1e-4 * p;
                        let closed = k_s * (zero(p - h) - zero(p + h)) / (2.0 * h);
                        assert!(
                            (d.force[0] - closed).abs() < 1e-4 * closed.abs(),
                            "{model:?} P {p} k_s {k_s}: dF/dP {} vs {closed}",
                            d.force[0]
                        );
                        let full = m.partials_with_strands(p, l, k_s, &rest).unwrap();
                        assert_eq!(full.force, d.force);
                        assert_eq!(d.force[1], k_s);
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked >= 4, "{checked}");
    }

    /// The one-search evaluation gives exactly what the two separate ones give, on every
    /// branch: the rigid model, the strands (interior, at the reach, past breaking) and the
    /// clamped lengths out of range.
    #[test]
    fn evaluation_with_partials_is_the_separate_evaluations() {
        let rest = HysteresisState::at_rest(0.09);
        let mut on_strands = 0;
        for model in [
            BladderModel::None,
            BladderModel::ThinWall,
            BladderModel::Exact { nodes: 8 },
        ] {
            let m = McKibben::from_geometry(&MuscleGeometry::muscle_a(), model, None, 0.0).unwrap();
            let (lo, top) = (m.min_length(), m.breaking_length());
            for k_s in [1.0, 1e3, 1e5] {
                for p in [-2e4, 0.0, 1e5, 6e5] {
                    for i in 0..=60 {
                        let l = lo - 0.01 + (top + 0.02 - lo) * f64::from(i) / 60.0;
                        let (out, clamp, d) =
                            m.evaluate_and_partials_with_strands(p, l, k_s, &rest);
                        let (out_alone, clamp_alone) = m.evaluate_with_strands(p, l, k_s, &rest);
                        assert_eq!(out, out_alone, "{model:?} k_s {k_s} P {p} L {l}");
                        assert_eq!(clamp, clamp_alone, "{model:?} k_s {k_s} P {p} L {l}");
                        let d_alone = m.partials_with_strands(p, l, k_s, &rest);
                        assert_eq!(d, d_alone, "{model:?} k_s {k_s} P {p} L {l}");
                        on_strands += usize::from(m.strand_point(p, l, k_s, &rest).is_some());
                    }
                }
            }
        }
        assert!(on_strands > 100, "{on_strands}");
    }
}
