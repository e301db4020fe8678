//! The pressure solver: the gauge pressure at which the muscle pulls with a target force at a
//! length, and its partials (the implicit function theorem on the forward model).

use super::McKibben;
use crate::physics::friction::HysteresisState;
use crate::physics::inverse::{pressure_for_force, Inversion};

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
