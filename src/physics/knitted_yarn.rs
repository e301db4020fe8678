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
use crate::physics::mckibben::{
    transition_located, OutOfRange, Transition, SURVIVABLE_STRAND_STRAIN,
};

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
    /// knit holds. The rigid stiffness jumps where the bladder meets the sleeve: a bracket
    /// across that switch is narrowed on the smooth contact pressure, not the rigid knit.
    fn yarn_transition(
        &self,
        pressure: f64,
        length: f64,
        k_s: f64,
        history: &HysteresisState,
    ) -> Option<Transition<Rigid>> {
        let length = length.min(self.breaking_length());
        transition_located(
            self.valid_lengths(),
            length,
            k_s,
            self.rigid(pressure, history),
            |a, b| {
                let rigid = self.rigid(pressure, history);
                let fails = |l: f64| rigid(l).is_none_or(|(f, k, _)| f > 0.0 && k > k_s);
                self.contact_switch(pressure, a, b, fails)
            },
        )
    }

    /// The rigid knit as the yarn's transition searches it: force, stiffness and outputs at a
    /// length within [`Self::valid_lengths`], `None` outside or where it has no state.
    fn rigid<'a>(
        &'a self,
        pressure: f64,
        history: &'a HysteresisState,
    ) -> impl Fn(f64) -> Option<(f64, f64, Rigid)> + 'a {
        let (lo, hi) = self.valid_lengths();
        move |l: f64| {
            if !(lo..=hi).contains(&l) {
                return None;
            }
            let (out, collapsed) = self.evaluate(pressure, l, history).ok()?;
            Some((out.force, out.stiffness, (out, collapsed)))
        }
    }

    /// The length `x` between `a < b` such that the bladder's contact at `pressure` differs
    /// between `x` and the next float up; `None` without a bladder, where `a` and `b` are on the
    /// same side, where the contact test has no value, or under vacuum. Regula falsi (Illinois)
    /// on the contact pressure `P_eff` at the sleeve's diameter (the sign
    /// [`crate::physics::bladder::Bladder::evaluate`] tests, smooth in `L`), bisecting whenever
    /// two steps have not halved the bracket, down to adjacent floats.
    ///
    /// `None` as well where the switch is not where the rigid knit stops holding: where it holds
    /// on the contact side of a bracket narrowed to 1e-4 of the length (`holds_not(L)` false),
    /// its stiffness meets the yarn's in contact, not at the jump.
    fn contact_switch(
        &self,
        pressure: f64,
        a: f64,
        b: f64,
        holds_not: impl Fn(f64) -> bool,
    ) -> Option<f64> {
        let bladder = self.bladder()?;
        // Under vacuum the rigid knit may evaluate a collapsing bladder at zero pressure instead.
        if !(pressure > 0.0 && pressure.is_finite()) {
            return None;
        }
        // Negative in contact (`P_eff >= 0`, the test's `-0.0` included).
        let excess = |l: f64| bladder.contact_pressure(pressure, l).ok().map(|p| -p);
        let (mut a, mut b) = (a, b);
        let (mut fa, mut fb) = (excess(a)?, excess(b)?);
        let contact_a = fa <= 0.0;
        if contact_a == (fb <= 0.0) {
            return None;
        }
        let (mut widths, mut a_moved_last) = ([f64::INFINITY; 2], None);
        let mut checked = false;
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                return Some(a);
            }
            if !checked && b - a <= 1e-4 * b {
                checked = true;
                if !holds_not(if contact_a { a } else { b }) {
                    return None;
                }
            }
            let falsi = a - fa * (b - a) / (fb - fa);
            let x = if b - a > 0.5 * widths[0] || !(falsi > a && falsi < b) {
                mid
            } else {
                falsi
            };
            widths = [widths[1], b - a];
            let fx = excess(x)?;
            if (fx <= 0.0) == contact_a {
                (a, fa) = (x, fx);
                if a_moved_last == Some(true) {
                    fb *= 0.5;
                }
                a_moved_last = Some(true);
            } else {
                (b, fb) = (x, fx);
                if a_moved_last == Some(false) {
                    fa *= 0.5;
                }
                a_moved_last = Some(false);
            }
        }
        None
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::bladder::{Bladder, BladderTube, Wall};
    use crate::physics::knitted::{KnittedParams, KnittedSleeve, ShapeKind};
    use crate::physics::mckibben::transition;
    use std::cell::Cell;

    /// The section 1.4 prototype with a thin, stiff bladder of wall `wall`.
    fn prototype_with(wall: Wall) -> KnittedAssembly {
        let sleeve = KnittedSleeve::new(KnittedParams::prototype(), ShapeKind::Ideal).unwrap();
        let tube = BladderTube {
            inner_diameter: 3.080e-2,
            thickness: 2.845e-5,
            unstretched_length: 6.699e-2,
            mooney_c1: 4.033e6,
            mooney_c2: 0.0,
        };
        let bladder = Bladder::knitted_wall(&sleeve, tube, wall).unwrap();
        KnittedAssembly::new(sleeve, Some(bladder), None, None).unwrap()
    }

    /// Past the breaking length at low pressures the yarn's transition lies where the bladder
    /// meets the sleeve (the rigid stiffness jumps there); at higher ones the rigid stiffness
    /// reaches the yarn's in contact. Located from the contact pressure, the first is a
    /// boundary of the rigid knit next to the plain search's, in 2 rigid evaluations after the
    /// bracket instead of 50-odd; the second is the plain search's own, bit for bit.
    #[test]
    fn contact_switch_gives_the_plain_searchs_transition() {
        let (mut taken, mut passed_over) = (0, 0);
        for wall in [
            Wall::DissertationContinuum(61),
            Wall::DissertationLayers(8),
            Wall::Layers(1),
            Wall::Exact(16),
        ] {
            let a = prototype_with(wall);
            let k_s = a.yarn_stiffness(8.069);
            let history = HysteresisState::at_rest(a.valid_lengths().1);
            let length = a.breaking_length();
            let contact = |x: f64, p: f64| a.bladder().unwrap().evaluate(p, x).unwrap().contact;
            for pressure in (0..40).map(|i| 10f64.powf(0.1 * f64::from(i))) {
                let count = Cell::new(0);
                let rigid = a.rigid(pressure, &history);
                let counted = |l: f64| {
                    count.set(count.get() + 1);
                    rigid(l)
                };
                let plain = transition(a.valid_lengths(), length, k_s, counted);
                let plain_count = count.replace(0);
                let (switch, across) = (Cell::new(None), Cell::new(false));
                let located =
                    transition_located(a.valid_lengths(), length, k_s, counted, |lo, hi| {
                        let fails = |l: f64| rigid(l).is_none_or(|(f, k, _)| f > 0.0 && k > k_s);
                        across.set(contact(lo, pressure) != contact(hi, pressure));
                        switch.set(a.contact_switch(pressure, lo, hi, fails));
                        switch.get()
                    });
                let located_count = count.get();
                let case = format!("{wall:?} {pressure} Pa: {plain_count} / {located_count}");
                assert_eq!(plain.is_some(), located.is_some(), "{case}");
                let (Some(plain), Some(located)) = (plain, located) else {
                    continue;
                };
                let (p, l) = (plain.length, located.length);
                // Closed on the switch: the bracket's first evaluations and two more.
                if located_count < plain_count {
                    taken += 1;
                    let x = switch.get().unwrap();
                    assert!(
                        l == x && contact(x, pressure) != contact(x.next_up(), pressure),
                        "{case}"
                    );
                    assert!(located_count <= plain_count - 40, "{case}");
                    // A boundary of the rigid knit: it holds at `l`, not at the next float up.
                    let holds = |x: f64| rigid(x).is_some_and(|(f, k, _)| !(f > 0.0 && k > k_s));
                    assert!(holds(l) && !holds(l.next_up()), "{case}: {l}");
                    // The plain search's, or another within a few floats only because the contact
                    // flickers there (rounding in `P_eff`): the bladder meets the sleeve, and
                    // leaves it, more than once between them.
                    let (mut x, mut crossings) = (p.min(l), 0);
                    while x < p.max(l) {
                        let next = x.next_up();
                        crossings += usize::from(contact(x, pressure) != contact(next, pressure));
                        x = next;
                    }
                    assert!(
                        p == l || (crossings >= 2 && (p - l).abs() <= 16.0 * f64::EPSILON * p),
                        "{case}: {p} vs {l}, {crossings} crossings"
                    );
                    assert_eq!(plain.interior, located.interior, "{case}");
                    let (fp, fl) = (plain.rigid.0.force, located.rigid.0.force);
                    assert!((fp - fl).abs() <= 1e-12 * fp.abs(), "{case}: {fp} vs {fl}");
                } else {
                    // Across the switch, it is not the boundary (located or not).
                    passed_over += usize::from(across.get());
                    assert!(located_count <= plain_count + 2, "{case}");
                    assert_eq!(p.to_bits(), l.to_bits(), "{case}");
                    assert_eq!(
                        plain.rigid.0.force.to_bits(),
                        located.rigid.0.force.to_bits(),
                        "{case}"
                    );
                }
            }
        }
        assert!(
            taken >= 40 && passed_over >= 10,
            "{taken} closed on the switch, {passed_over} passed over"
        );
    }
}
