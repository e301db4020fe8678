//! Exact partial derivatives of the free bladder's outputs with respect to its gauge pressure and
//! clamp length, by the implicit function theorem on eq. 2.18 (dissertation section 2.2.2).
//!
//! In `w = lambda_1 lambda_2^2`, eq. 2.18 is `G(w, P, A) = (A - P r) w^2 - P w - A = 0` with
//! `A = 2 (C1/lambda_1 + C2 lambda_1)`. At the positive root `dG/dw = 2 (A - P r) w - P` equals
//! the quadratic's square root `sqrt(P^2 + 4 A (A - P r))` > 0, so
//! `dw = ((r w^2 + w) dP - (w^2 - 1) dA) / sqrt(...)` everywhere below the ballooning pressure.
//! The stretches (eq. 2.8), stresses (eq. 2.9), volume, diameters and clamp force (eq. 2.5, 2.17)
//! are explicit in `w` and `lambda_1`; the compliance `V_0 dw/dP` is differentiated in the form
//! [`FreeBladder::evaluate`] computes it, `V_0 (r w^2 + w)^2 / (A (w^2 + 2 r w + 1))`.

use super::{FreeBladder, FreeBladderState};
use std::f64::consts::PI;

/// The partial derivatives of every field of [`FreeBladderState`] at one point, each stored in the
/// field it differentiates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeBladderPartials {
    /// With respect to the gauge pressure at fixed length (per Pa).
    pub by_pressure: FreeBladderState,
    /// With respect to the clamp length at fixed pressure (per m).
    pub by_length: FreeBladderState,
}

impl FreeBladderPartials {
    /// The directional derivative along `(dp, dl)` (Pa, m): `dp by_pressure + dl by_length`.
    pub fn along(&self, dp: f64, dl: f64) -> FreeBladderState {
        let (p, l) = (&self.by_pressure, &self.by_length);
        let mix = |a: f64, b: f64| dp * a + dl * b;
        FreeBladderState {
            inner_diameter: mix(p.inner_diameter, l.inner_diameter),
            outer_diameter: mix(p.outer_diameter, l.outer_diameter),
            fluid_volume: mix(p.fluid_volume, l.fluid_volume),
            compliance: mix(p.compliance, l.compliance),
            stretch_axial: mix(p.stretch_axial, l.stretch_axial),
            stretch_hoop: mix(p.stretch_hoop, l.stretch_hoop),
            stretch_radial: mix(p.stretch_radial, l.stretch_radial),
            stress_axial: mix(p.stress_axial, l.stress_axial),
            stress_hoop: mix(p.stress_hoop, l.stress_hoop),
            force: mix(p.force, l.force),
            ballooning_pressure: mix(p.ballooning_pressure, l.ballooning_pressure),
        }
    }
}

impl FreeBladder {
    /// [`FreeBladder::evaluate`] and the exact partials of every field with respect to `pressure`
    /// and `length` (no finite differences). `Err` where `evaluate` refuses.
    pub fn evaluate_with_partials(
        &self,
        pressure: f64,
        length: f64,
    ) -> Result<(FreeBladderState, FreeBladderPartials), String> {
        let state = self.evaluate(pressure, length)?;
        let (a, w) = self.volume_ratio(pressure, length)?;
        let partials = FreeBladderPartials {
            by_pressure: self.tangent(&state, pressure, length, a, w, 1.0, 0.0),
            by_length: self.tangent(&state, pressure, length, a, w, 0.0, 1.0),
        };
        let finite = [partials.by_pressure, partials.by_length].iter().all(|t| {
            [
                t.inner_diameter,
                t.outer_diameter,
                t.fluid_volume,
                t.compliance,
                t.stretch_hoop,
                t.stretch_radial,
                t.stress_axial,
                t.stress_hoop,
                t.force,
            ]
            .iter()
            .all(|v| v.is_finite())
        });
        if finite {
            Ok((state, partials))
        } else {
            Err(format!(
                "the free bladder's partial derivatives overflow at pressure {pressure} Pa and \
                 length {length} m"
            ))
        }
    }

    /// Forward-mode tangent of `state` (at `pressure`, `length`, with eq. 2.18's `A` and root `w`)
    /// along `(dp, dl)`.
    #[allow(clippy::too_many_arguments)]
    fn tangent(
        &self,
        state: &FreeBladderState,
        pressure: f64,
        length: f64,
        a: f64,
        w: f64,
        dp: f64,
        dl: f64,
    ) -> FreeBladderState {
        let t = &self.tube;
        let (c1, c2, r) = (t.mooney_c1, t.mooney_c2, self.slenderness);
        let (l1, l2, l3) = (
            state.stretch_axial,
            state.stretch_hoop,
            state.stretch_radial,
        );
        let dl1 = dl / t.unstretched_length;
        let da = r * self.ballooning_pressure_slope(length) * dl;
        // Implicit function theorem on eq. 2.18 (module comment).
        let lead = a - pressure * r;
        let root = (pressure * pressure + 4.0 * a * lead).sqrt();
        let n = r * w * w + w;
        let dw = (n * dp - (w * w - 1.0) * da) / root;
        // Eq. 2.8: lambda_2 = sqrt(w / lambda_1), lambda_3 = 1 / (lambda_1 lambda_2).
        let dl2 = 0.5 * l2 * (dw / w - dl1 / l1);
        let dl3 = -l3 * (dl1 / l1 + dl2 / l2);
        // Eq. 2.9's Mooney-Rivlin difference for stretch s against lambda_3, differentiated.
        let dmooney = |s: f64, ds: f64| {
            4.0 * c1 * (s * ds - l3 * dl3) + 4.0 * c2 * (ds / (s * s * s) - dl3 / (l3 * l3 * l3))
        };
        let d_stress_axial = dmooney(l1, dl1) - dp;
        let d_inner = dl2 * t.inner_diameter;
        let d_in = state.inner_diameter;
        let rubber = self.rubber_volume;
        // Compliance V_0 n^2 / (A q): d ln C = 2 dn/n - dA/A - dq/q.
        let q = w * w + 2.0 * r * w + 1.0;
        let dn = (2.0 * r * w + 1.0) * dw;
        let dq = 2.0 * (w + r) * dw;
        FreeBladderState {
            inner_diameter: d_inner,
            outer_diameter: (d_in * d_inner - 2.0 * rubber / (PI * length * length) * dl)
                / state.outer_diameter,
            fluid_volume: self.relaxed_volume * dw,
            compliance: state.compliance * (2.0 * dn / n - da / a - dq / q),
            stretch_axial: dl1,
            stretch_hoop: dl2,
            stretch_radial: dl3,
            stress_axial: d_stress_axial,
            stress_hoop: dmooney(l2, dl2) - dp,
            force: d_stress_axial * rubber / length
                - state.stress_axial * rubber / (length * length) * dl
                - dp * PI / 4.0 * d_in * d_in
                - pressure * PI / 2.0 * d_in * d_inner,
            ballooning_pressure: da / r,
        }
    }
}
