//! The bare sleeve (eq. 2.2-2.3 alone: no bladder, friction or connector) with stretching strands
//! (see [`super::strands`]): the McKibbenMuscle FMU's fastest path, in closed form.

use super::limits::OutOfRange;
use super::SURVIVABLE_STRAND_STRAIN;
use crate::physics::by_pressure_length::ByPressureLength;
use crate::physics::gaylord::Sleeve;

/// The bare sleeve's outputs at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SleeveState {
    /// Signed tension, N (eq. 2.3; on the strands `F(L_t) + k_s (L - L_t)`).
    pub force: f64,
    /// Gas volume, m^3 (eq. 2.2).
    pub volume: f64,
    /// `max(P, 0)`, Pa: under vacuum the bladder leaves the sleeve.
    pub effective_pressure: f64,
    /// `dF/dL`, N/m.
    pub stiffness: f64,
    /// The bladder presses on the sleeve (`P > 0`).
    pub contact: bool,
}

/// Where the bare sleeve's strands take over at `p_eff`: at `b` (straight strands) or where eq.
/// 2.3's stiffness `6 P L / (4 pi n^2)` reaches the strands' `k_s`, whichever comes first.
#[inline(always)]
pub fn reach(sleeve: &Sleeve, k_s: f64, p_eff: f64) -> f64 {
    sleeve.max_length().min(k_s / sleeve.stiffness(p_eff, 1.0))
}

/// The input length past which no muscle survives: [`SURVIVABLE_STRAND_STRAIN`] of `b` beyond `b`.
pub fn breaking_length(sleeve: &Sleeve) -> f64 {
    sleeve.max_length() * (1.0 + SURVIVABLE_STRAND_STRAIN)
}

/// Eq. 2.3 for the bare sleeve with strands of stiffness `k_s` (N/m) at `(pressure, length)`;
/// past the breaking length, evaluated there (returned with why).
#[inline(always)]
pub fn evaluate(
    sleeve: &Sleeve,
    k_s: f64,
    pressure: f64,
    length: f64,
) -> (SleeveState, Option<OutOfRange>) {
    match below_the_strands(sleeve, k_s, pressure, length) {
        Some(state) => (state, None),
        None => on_the_strands_state(sleeve, k_s, pressure, length),
    }
}

/// Eq. 2.3 where the strands have not taken over (`None` where they have): the per-step path of
/// the ideal muscle, small enough to inline.
#[inline(always)]
pub fn below_the_strands(
    sleeve: &Sleeve,
    k_s: f64,
    pressure: f64,
    length: f64,
) -> Option<SleeveState> {
    let p_eff = pressure.max(0.0);
    if length > reach(sleeve, k_s, p_eff) {
        return None;
    }
    Some(SleeveState {
        force: sleeve.force(p_eff, length),
        volume: sleeve.volume(length),
        effective_pressure: p_eff,
        stiffness: sleeve.stiffness(p_eff, length),
        contact: pressure > 0.0,
    })
}

/// The bare sleeve past `reach`, where its strands stretch: `F = F(reach) + k_s (L - reach)`;
/// past the breaking length no muscle survives: evaluated there.
pub fn on_the_strands_state(
    sleeve: &Sleeve,
    k_s: f64,
    pressure: f64,
    requested: f64,
) -> (SleeveState, Option<OutOfRange>) {
    let reach = reach(sleeve, k_s, pressure.max(0.0));
    let b = sleeve.max_length();
    let breaking = breaking_length(sleeve);
    let clamp = (requested > breaking).then(|| OutOfRange {
        reason: format!(
            "length {requested} m stretches the strands more than {}% past b = {b} m, which no muscle survives",
            100.0 * SURVIVABLE_STRAND_STRAIN
        ),
        range: (0.0, breaking),
        point: Some((pressure, breaking)),
    });
    let length = requested.min(breaking);
    let p_eff = pressure.max(0.0);
    let state = SleeveState {
        force: sleeve.force(p_eff, reach) + k_s * (length - reach),
        volume: sleeve.volume(reach),
        effective_pressure: p_eff,
        stiffness: k_s,
        contact: pressure > 0.0,
    };
    (state, clamp)
}

/// The signed force below the strands (eq. 2.3 at `min(L, b)`).
pub fn signed_force(sleeve: &Sleeve, pressure: f64, length: f64) -> f64 {
    sleeve.force(pressure.max(0.0), length.min(sleeve.max_length()))
}

/// Whether `(pressure, length)` lies on the stretching strands.
pub fn on_the_strands(sleeve: &Sleeve, k_s: f64, pressure: f64, length: f64) -> bool {
    length > reach(sleeve, k_s, pressure.max(0.0))
}

/// `[d/dP, d/dL]` of the signed outputs of [`evaluate`]. On the strands, with
/// `reach = k_s / (6 P / (4 pi n^2))` inside `b`: `dreach/dP = -reach / P`, and the force
/// `F(P, reach(P)) + k_s (L - reach(P))` moves with the length by `k_s` up to the breaking
/// length. The bare sleeve's stretches and stresses are constants (no bladder).
pub fn partials(sleeve: &Sleeve, k_s: f64, pressure: f64, length: f64) -> ByPressureLength {
    let p_eff = pressure.max(0.0);
    let on = if pressure > 0.0 { 1.0 } else { 0.0 };
    let reach = reach(sleeve, k_s, p_eff);
    if length > reach {
        let moves = length <= breaking_length(sleeve);
        let dreach = if reach < sleeve.max_length() && p_eff > 0.0 {
            -reach / p_eff
        } else {
            0.0
        };
        let per_pa = sleeve.force(1.0, reach);
        return ByPressureLength {
            force: [
                on * (per_pa + (sleeve.stiffness(p_eff, reach) - k_s) * dreach),
                if moves { k_s } else { 0.0 },
            ],
            effective_pressure: [on, 0.0],
            volume: [-on * per_pa * dreach, 0.0],
            ..Default::default()
        };
    }
    let inside = length <= sleeve.max_length();
    let l = length.min(sleeve.max_length());
    let per_pa = sleeve.force(1.0, l);
    let dl = if inside { 1.0 } else { 0.0 };
    ByPressureLength {
        force: [on * per_pa, dl * sleeve.stiffness(p_eff, l)],
        effective_pressure: [on, 0.0],
        volume: [0.0, -dl * per_pa],
        ..Default::default()
    }
}

/// `[d/dP, d/dL]` of the signed stiffness of [`evaluate`]: 0 on the strands (their constant
/// `k_s`); below them eq. 2.3's stiffness `6 P_eff L / (4 pi n^2)`, bilinear in `P_eff` and `L`.
pub fn stiffness_partials(sleeve: &Sleeve, k_s: f64, pressure: f64, length: f64) -> [f64; 2] {
    if on_the_strands(sleeve, k_s, pressure, length) {
        return [0.0; 2];
    }
    let on = if pressure > 0.0 { 1.0 } else { 0.0 };
    let inside = if length <= sleeve.max_length() {
        1.0
    } else {
        0.0
    };
    let l = length.min(sleeve.max_length());
    [
        on * sleeve.stiffness(1.0, l),
        inside * sleeve.stiffness(pressure.max(0.0), 1.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Eq. 2.3 written out here, with the straight strands' `E A / b` past `b`.
    #[test]
    fn eq_2_3_then_the_strands_in_closed_form() {
        let (b, n, rigidity, pressure) = (0.1113, 3.74, 9400.0, 3e5);
        let sleeve = Sleeve::new(b, n).unwrap();
        let k_s = rigidity / b;
        let eq_2_3 = |l: f64| pressure * (3.0 * l * l - b * b) / (4.0 * PI * n * n);
        for (l, expected) in [
            (0.9 * b, eq_2_3(0.9 * b)),
            (1.02 * b, eq_2_3(b) + k_s * 0.02 * b),
            (1.2 * b, eq_2_3(b) + k_s * 0.05 * b),
        ] {
            let (state, excursion) = evaluate(&sleeve, k_s, pressure, l);
            assert!((state.force - expected).abs() < 1e-12 * expected, "{l}");
            assert_eq!(excursion.is_some(), l > 1.05 * b);
        }
    }

    /// The partials are central differences of [`evaluate`], below and on the strands, also
    /// where soft strands (`k_s` 1 kN/m, taking over at 97.7 mm) take over inside `b`.
    #[test]
    fn partials_are_central_differences() {
        let sleeve = Sleeve::new(0.1113, 3.74).unwrap();
        for (k_s, pressure, l) in [
            (84_456.0, 3e5, 0.1),
            (84_456.0, 3e5, 0.113),
            (1e3, 3e5, 0.1),
        ] {
            let d = partials(&sleeve, k_s, pressure, l);
            let dk = stiffness_partials(&sleeve, k_s, pressure, l);
            let at = |p: f64, l: f64| {
                let s = evaluate(&sleeve, k_s, p, l).0;
                [s.force, s.volume, s.stiffness]
            };
            for (column, h) in [(0, 1.0), (1, 1e-8)] {
                let (dp, dl) = if column == 0 { (h, 0.0) } else { (0.0, h) };
                let (up, down) = (at(pressure + dp, l + dl), at(pressure - dp, l - dl));
                let exact = [d.force[column], d.volume[column], dk[column]];
                for k in 0..3 {
                    let fd = (up[k] - down[k]) / (2.0 * h);
                    let scale = fd.abs().max(exact[k].abs()).max(1e-12);
                    assert!(
                        (fd - exact[k]).abs() < 1e-5 * scale,
                        "k_s {k_s} L {l} output {k} column {column}: {} vs {fd}",
                        exact[k]
                    );
                }
            }
        }
    }
}
