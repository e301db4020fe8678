//! Inverse McKibben problems: the pressure that gives a force at a length, and the antagonistic
//! pressure pair that gives a joint torque. Both invert the forward model (eq. 2.3, or eq. 2.4
//! with the bladder of eq. 2.6-2.20) at a fixed length, where the force is monotonic in pressure:
//! linear for the ideal sleeve, and in contact the effective pressure rises with `P - threshold`
//! (eq. 2.12, 2.19) while below the threshold the force does not depend on `P` at all.

use crate::physics::friction::HysteresisState;
use crate::physics::mckibben::McKibben;
use crate::physics::numerics::root::{newton_bisection, RootOptions, Sample};

/// Stopping rule of the inversions: the Newton correction of the argument (Pa) below 1e-13 of
/// it plus 1e-9 Pa, or 200 evaluations (bisection alone would halve any bracket that often).
const OPTIONS: RootOptions = RootOptions {
    absolute: 1e-9,
    relative: 1e-13,
    max_iterations: 200,
    jump_width: 0.0,
};

/// The result of an inversion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inversion {
    /// The argument found (a pressure, or a pressure difference), inside the bracket.
    pub argument: f64,
    /// The value the forward model gives there (force, torque).
    pub achieved: f64,
    /// Whether the target cannot be reached: it lies outside the range (`argument` is then the
    /// nearer end) or inside a jump of the forward model (`argument` is then at the jump).
    pub saturated: bool,
}

/// Solves `f(x) = target` for `x` in `[lo, hi]` when `f` is monotonic there (either direction;
/// flat stretches allowed); `f` returns its value and slope. Out of reach, returns the end whose
/// value is nearer, flagged `saturated`. Inside, the shared safeguarded Newton-bisection
/// ([`newton_bisection`]): every step stays in the shrinking bracket, so it cannot diverge. A
/// target inside a jump of `f` (the bracket closes on the jump, the value there still off by more
/// than its slope over the bracket allows) is flagged `saturated` too. `Err` if `f` fails.
pub fn invert_monotonic(
    mut f: impl FnMut(f64) -> Result<(f64, f64), String>,
    target: f64,
    lo: f64,
    hi: f64,
) -> Result<Inversion, String> {
    if !(target.is_finite() && lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(format!(
            "cannot invert for target {target} on [{lo}, {hi}]: not finite or empty"
        ));
    }
    let (f_lo, f_hi) = (f(lo)?.0, f(hi)?.0);
    let rising = f_hi >= f_lo;
    let (min, max) = if rising { (f_lo, f_hi) } else { (f_hi, f_lo) };
    let (x_min, x_max) = if rising { (lo, hi) } else { (hi, lo) };
    let end = |x: f64, y: f64, saturated| Inversion {
        argument: x,
        achieved: y,
        saturated,
    };
    if target <= min {
        return Ok(end(x_min, min, target < min));
    }
    if target >= max {
        return Ok(end(x_max, max, target > max));
    }
    // Start from the secant through the ends (exact for eq. 2.3, linear in P).
    let start = x_min + (target - min) / (max - min) * (x_max - x_min);
    let root = newton_bisection(lo, hi, start, rising, OPTIONS, |x| {
        f(x).map(|(value, slope)| {
            Some(Sample {
                value: value - target,
                slope,
                payload: (value, slope),
            })
        })
    })?;
    let (achieved, slope) = root.payload.ok_or("no evaluation inside the bracket")?;
    // Met, the residual is at most the slope times the bracket the finder closed (its stopping
    // rule); a larger one is a jump of `f` across the target, which no argument meets.
    let closed = OPTIONS.absolute + OPTIONS.relative * root.x.abs();
    let met = (achieved - target).abs() <= 4.0 * slope.abs() * closed + 1e-12 * (max - min);
    Ok(end(root.x, achieved, !met))
}

/// The gauge pressure in `0 ..= max_pressure` at which `muscle` at input length `length` (from
/// friction history `history`) pulls with `force`. Out of reach: the pressure of the nearest
/// force, `saturated`. `Err` if the muscle cannot be evaluated at `length`.
pub fn pressure_for_force(
    muscle: &McKibben,
    length: f64,
    force: f64,
    max_pressure: f64,
    history: &HysteresisState,
) -> Result<Inversion, String> {
    invert_monotonic(
        |p| {
            muscle
                .partials(p, length, history)
                .map(|(o, d)| (o.force, d.force[0]))
        },
        force,
        0.0,
        max_pressure,
    )
}

/// The pressures `[flexor, extensor]` from a pressure difference around the common mode, each
/// clipped to `0 ..= max_pressure` (max/min so that a NaN maps to a bound).
pub fn pair_pressures(common_mode: f64, difference: f64, max_pressure: f64) -> [f64; 2] {
    [
        (common_mode + 0.5 * difference).max(0.0).min(max_pressure),
        (common_mode - 0.5 * difference).max(0.0).min(max_pressure),
    ]
}

/// The pressure difference whose clipped pair ([`pair_pressures`]) gives `torque`, where
/// `torque_of(difference)` is the pair's torque and its slope; out of reach, the nearest torque (`saturated`).
/// The torque of an antagonistic pair is monotonic in the difference while each muscle's force
/// is monotonic in its pressure; the search covers every difference that changes a clipped
/// pressure, `-2 max_pressure ..= 2 max_pressure`.
pub fn difference_for_torque(
    torque_of: impl FnMut(f64) -> Result<(f64, f64), String>,
    torque: f64,
    max_pressure: f64,
) -> Result<Inversion, String> {
    let span = 2.0 * max_pressure;
    invert_monotonic(torque_of, torque, -span, span)
}

// The pressure solver: the gauge pressure at which the muscle pulls with a target force at a
// length, and its partials (the implicit function theorem on the forward model).
impl McKibben {
    /// The pressure in `0 ..= max_pressure` that gives `force` at the input `length` from
    /// `history`; at a length without a solution, at the nearest one
    /// ([`McKibben::solvable_length`]), as the forward model is clamped. `None` if neither can
    /// be evaluated.
    pub fn target_pressure(
        &self,
        max_pressure: f64,
        history: &HysteresisState,
        length: f64,
        force: f64,
    ) -> Option<Inversion> {
        let inside = self.solvable_length(length);
        pressure_for_force(self, length, force, max_pressure, history)
            .or_else(|_| pressure_for_force(self, inside, force, max_pressure, history))
            .ok()
    }

    /// `[d/dlength, d/dforce]` of [`Self::target_pressure`]: by the implicit function theorem on
    /// `F(P*, L) = force`, `dP*/dF = 1/F_P` and `dP*/dL = -F_L/F_P`, at the point and length the
    /// solver used. Saturated (`P*` at 0 or `max_pressure`) the pressure does not move: zero. At
    /// a clamped length the length column is zero.
    pub fn target_pressure_partials(
        &self,
        max_pressure: f64,
        history: &HysteresisState,
        length: f64,
        force: f64,
    ) -> [f64; 2] {
        let solve = |l: f64| pressure_for_force(self, l, force, max_pressure, history);
        let (solved, l, inside) = match solve(length) {
            Ok(s) => (s, length, true),
            Err(_) => {
                let clamped = self.solvable_length(length);
                match solve(clamped) {
                    Ok(s) => (s, clamped, false),
                    Err(_) => return [0.0; 2],
                }
            }
        };
        if solved.saturated {
            return [0.0; 2];
        }
        match self.partials(solved.argument, l, history) {
            Ok((_, d)) if d.force[0] != 0.0 => {
                let per_force = 1.0 / d.force[0];
                let per_length = if inside { -d.force[1] * per_force } else { 0.0 };
                [per_length, per_force]
            }
            _ => [0.0; 2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::mckibben::{BladderModel, MuscleGeometry};

    #[test]
    fn inverts_rising_falling_and_flat_stretches_and_saturates() {
        let cube = |x: f64| Ok((x * x * x, 3.0 * x * x));
        let r = invert_monotonic(cube, 0.3, -1.0, 2.0).unwrap();
        assert!((r.achieved - 0.3).abs() < 1e-13 && !r.saturated);
        assert!((r.argument - 0.3f64.cbrt()).abs() < 1e-9);
        let falling = |x: f64| Ok((-x.max(0.5), if x > 0.5 { -1.0 } else { 0.0 }));
        let r = invert_monotonic(falling, -0.75, 0.0, 1.0).unwrap();
        assert!((r.argument - 0.75).abs() < 1e-12, "{r:?}");
        let r = invert_monotonic(cube, 9.0, -1.0, 2.0).unwrap();
        assert!(r.saturated && r.argument == 2.0 && r.achieved == 8.0);
        let r = invert_monotonic(cube, -3.0, -1.0, 2.0).unwrap();
        assert!(r.saturated && r.argument == -1.0);
    }

    /// A target inside a jump of the forward model is out of reach: flagged, at the jump. Either
    /// side of the jump, and a steep but continuous stretch, are met.
    #[test]
    fn a_target_inside_a_jump_is_flagged_out_of_reach() {
        let jump = |x: f64| Ok((x + if x > 0.5 { 10.0 } else { 0.0 }, 1.0));
        let r = invert_monotonic(jump, 5.0, 0.0, 1.0).unwrap();
        assert!(r.saturated && (r.argument - 0.5).abs() < 1e-8, "{r:?}");
        for target in [0.3, 10.8] {
            let r = invert_monotonic(jump, target, 0.0, 1.0).unwrap();
            assert!(!r.saturated && (r.achieved - target).abs() < 1e-12, "{r:?}");
        }
        let steep = |x: f64| {
            Ok((
                (1e6 * (x - 0.5)).atan(),
                1e6 / (1.0 + (1e6 * (x - 0.5)).powi(2)),
            ))
        };
        let r = invert_monotonic(steep, 1.0, 0.0, 1.0).unwrap();
        // Met to its slope (2.9e5 there) times the finder's 1e-9 in the argument.
        assert!(!r.saturated && (r.achieved - 1.0).abs() < 3e-4, "{r:?}");
        let falling_jump = |x: f64| Ok((-x - if x > 0.25 { 3.0 } else { 0.0 }, -1.0));
        let r = invert_monotonic(falling_jump, -2.0, 0.0, 1.0).unwrap();
        assert!(r.saturated && (r.argument - 0.25).abs() < 1e-8, "{r:?}");
    }

    #[test]
    fn pressure_for_force_inverts_eq_2_3_and_every_bladder() {
        let g = MuscleGeometry::muscle_a();
        let rest = HysteresisState::at_rest(0.09);
        for model in [
            BladderModel::None,
            BladderModel::DissertationThinWall,
            BladderModel::DissertationLayers { layers: 16 },
        ] {
            let m = McKibben::from_geometry(&g, model, None, 0.0).unwrap();
            for length in [0.085, 0.09, 0.095] {
                let top = m.evaluate(6e5, length, &rest).unwrap().force;
                let target = 0.6 * top;
                let r = pressure_for_force(&m, length, target, 6e5, &rest).unwrap();
                let f = m.evaluate(r.argument, length, &rest).unwrap().force;
                assert!(
                    !r.saturated && (f - target).abs() <= 1e-9 * top.abs(),
                    "{model:?} {f} {target}"
                );
                let over = pressure_for_force(&m, length, 2.0 * top, 6e5, &rest).unwrap();
                assert!(over.saturated && over.argument == 6e5);
            }
        }
        // Eq. 2.3 is linear in P: the exact answer is known.
        let m = McKibben::from_geometry(&g, BladderModel::None, None, 0.0).unwrap();
        let s = m.sleeve();
        let p = pressure_for_force(&m, 0.1, 50.0, 1e6, &rest)
            .unwrap()
            .argument;
        assert!((p - 50.0 / s.force(1.0, 0.1)).abs() < 1e-6 * p);
    }
}
