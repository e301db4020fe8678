//! Exact first partial derivatives of the bladder's outputs with respect to the gauge pressure and
//! the muscle length, for the FMUs' directional derivatives.
//!
//! In contact the outer diameter is the sleeve's `D(L)` (eq. 2.7, 2.20), independent of `P`, and
//! every layer's pressure is affine in `P` (eq. 2.12, 2.19), so `dP_eff/dP = a` and the elastic
//! force's `P`-slope is summed in the same layer pass. When free, the diameter `x` solves
//! `P_eff(P, L, x) = 0` (eq. 2.18): the implicit function theorem gives `dx/dP = -a / (dP_eff/dx)`
//! and `dx/dL = -(dP_eff/dL) / (dP_eff/dx)`. At the contact threshold (`P_eff = 0`) the force
//! kinks; the partials are those of the contact branch, which [`Bladder::evaluate`] selects there.
//!
//! The innermost layer's stretches and stresses (eq. 2.8a-c, 2.9a-b) and the threshold pressure
//! `c/a` are functions of `(L, x)` (and `-P` for the stresses), so the same chain rule through
//! `x(P, L)` gives them; the threshold is always taken at the contact diameter `D(L)`.

use super::{check_state, Bladder, BladderState, Dual, Kernel, SleeveGeometry};
use crate::physics::by_pressure_length::ByPressureLength;

/// `[d/dP, d/dL]` of a function of `(L, x)` through `x = x(P, L)`.
fn chain(q: Dual, dx_dp: f64, dx_dl: f64) -> [f64; 2] {
    [q.dx * dx_dp, q.dl + q.dx * dx_dl]
}

impl<S: SleeveGeometry> Bladder<S> {
    /// The partials at `pressure` and `length`, on the branch [`Bladder::evaluate`] takes there.
    pub fn partials(&self, pressure: f64, length: f64) -> Result<ByPressureLength, String> {
        self.evaluate_with_partials(pressure, length)
            .map(|(_, d)| d)
    }

    /// [`Bladder::evaluate`] and [`Bladder::partials`] from one pass: one kernel in contact, one
    /// root of eq. 2.18 when free (what a directional derivative costs beyond a step).
    pub fn evaluate_with_partials(
        &self,
        pressure: f64,
        length: f64,
    ) -> Result<(BladderState, ByPressureLength), String> {
        let (x, contact) = self.contact_point(pressure, length)?;
        if contact.p_eff.v >= 0.0 {
            // The dual numbers seeded by `contact_seed` carry the contact branch's total d/dL in `dl`.
            let (g, g_slope) = self.sleeve.strand_area(length);
            let area = self.fluid_area(contact.inner.l2_sq);
            let a = contact.a.v;
            // Along the contact branch the seed's `dl` is already the total d/dL (x = D(L)).
            let kinematics = self.kinematic_partials(length, &contact, &contact, 0.0, 0.0);
            let state = check_state(self.contact_state(pressure, length, &contact), length)?;
            return Ok((
                state,
                ByPressureLength {
                    // F = P_eff g - P A_fluid + elastic (eq. 2.16, 2.17).
                    force: [
                        a * g - area.v + contact.elastic_dp_value(),
                        contact.p_eff.dl * g + contact.p_eff.v * g_slope - pressure * area.dl
                            + contact.elastic.dl,
                    ],
                    effective_pressure: [a, contact.p_eff.dl],
                    volume: [0.0, area.dl * length + area.v],
                    ..kinematics
                },
            ));
        }
        let k = self.free_kernel(pressure, length, x.v, &contact)?;
        let area = self.fluid_area(k.inner.l2_sq);
        let (dx_dp, dx_dl) = if k.p_eff.dx != 0.0 {
            (-k.a.v / k.p_eff.dx, -k.p_eff.dl / k.p_eff.dx)
        } else {
            (0.0, 0.0)
        };
        // F = -P A_fluid(L, x) + elastic(P, L, x) with x = x(P, L).
        let force_dx = -pressure * area.dx + k.elastic.dx;
        let force_dl = -pressure * area.dl + k.elastic.dl;
        let kinematics = self.kinematic_partials(length, &contact, &k, dx_dp, dx_dl);
        let state = check_state(
            self.free_state(pressure, length, &k, contact.threshold),
            length,
        )?;
        Ok((
            state,
            ByPressureLength {
                force: [
                    -area.v + k.elastic_dp_value() + force_dx * dx_dp,
                    force_dl + force_dx * dx_dl,
                ],
                effective_pressure: [0.0, 0.0],
                volume: [
                    area.dx * dx_dp * length,
                    area.v + (area.dl + area.dx * dx_dl) * length,
                ],
                ..kinematics
            },
        ))
    }

    /// Threshold (from the `contact` kernel), stretches and stresses (from `k`, at the diameter
    /// the branch uses, whose partials are `dx_dp`, `dx_dl`); the other fields zero.
    fn kinematic_partials(
        &self,
        length: f64,
        contact: &Kernel,
        k: &Kernel,
        dx_dp: f64,
        dx_dl: f64,
    ) -> ByPressureLength {
        let (a, c) = (contact.a, contact.c);
        let threshold = [0.0, (c.dl * a.v - c.v * a.dl) / (a.v * a.v)];
        // lambda_1 = L / L_R0, lambda_2 = sqrt(l2_sq), lambda_3 = 1 / (lambda_1 lambda_2).
        let lambda1 = length / self.tube.unstretched_length;
        let lambda1_d = [0.0, 1.0 / self.tube.unstretched_length];
        let l2_sq = chain(k.inner.l2_sq, dx_dp, dx_dl);
        let lambda2 = k.inner.l2_sq.v.sqrt();
        let lambda2_d = l2_sq.map(|d| d / (2.0 * lambda2));
        let product = lambda1 * lambda2;
        let radial = [0, 1]
            .map(|i| -(lambda1_d[i] * lambda2 + lambda1 * lambda2_d[i]) / (product * product));
        let stress = |q: Dual| {
            let [dp, dl] = chain(q, dx_dp, dx_dl);
            [dp - 1.0, dl]
        };
        ByPressureLength {
            threshold_pressure: threshold,
            stretch_axial: lambda1_d,
            stretch_hoop: lambda2_d,
            stretch_radial: radial,
            stress_axial: stress(k.inner.axial),
            stress_hoop: stress(k.inner.hoop),
            stress_radial: [-1.0, 0.0],
            ..Default::default()
        }
    }
}
