//! Exact partial derivatives of the free bladder's outputs with respect to its gauge pressure and
//! clamp length, by the implicit function theorem on the tube's pressure equation
//! `P = (A/2) f(w)` (see the module comment of `free_bladder.rs`): `dw = (dP - f dA / 2) / (A f' / 2)`
//! with `f' > 0` everywhere below the ballooning pressure. The stretches (eq. 2.8), stresses
//! (eq. 2.9), volume, diameters and clamp force are explicit in `w` and `lambda_1`; the compliance
//! `V_0 / (A f' / 2)` is differentiated through `f''`.

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
            by_pressure: self.tangent(&state, length, a, w, 1.0, 0.0),
            by_length: self.tangent(&state, length, a, w, 0.0, 1.0),
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

    /// Forward-mode tangent of `state` (at `length`, with the modulus `A` and the
    /// volume ratio `w`) along `(dp, dl)`.
    #[allow(clippy::too_many_arguments)]
    fn tangent(
        &self,
        state: &FreeBladderState,
        length: f64,
        a: f64,
        w: f64,
        dp: f64,
        dl: f64,
    ) -> FreeBladderState {
        let t = &self.tube;
        let (c1, c2) = (t.mooney_c1, t.mooney_c2);
        let (l1, l2, l3) = (
            state.stretch_axial,
            state.stretch_hoop,
            state.stretch_radial,
        );
        let dl1 = dl / t.unstretched_length;
        let da = 2.0 * (c2 - c1 / (l1 * l1)) * dl1;
        // Implicit function theorem on P = (A/2) f(w) (module comment).
        let (f, slope, curvature) = self.shape(w);
        let dw = (dp - 0.5 * f * da) / (0.5 * a * slope);
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
        // Clamp force pi/(2 l1) ((G + 2 alpha) ring + alpha (w - 1) inner ln(w/u_o)).
        let (_, alpha) = Self::force_constants(c1, c2, l1);
        let dg0 = (8.0 * c1 * l1 + 8.0 * c2 / (l1 * l1 * l1)) * dl1;
        let dalpha = (2.0 * c2 + 2.0 * c1 / (l1 * l1)) * dl1;
        let (ring, inner) = self.radii_sq;
        let log = self.log_volume_ratio(w);
        let u_o = 1.0 + (w - 1.0) * self.rho;
        let dlog = (1.0 - self.rho) / (w * u_o) * dw;
        let d_force = -state.force * dl1 / l1
            + PI / (2.0 * l1)
                * ((dg0 + 2.0 * dalpha) * ring
                    + dalpha * (w - 1.0) * inner * log
                    + alpha * inner * (dw * log + (w - 1.0) * dlog));
        FreeBladderState {
            inner_diameter: d_inner,
            outer_diameter: (d_in * d_inner - 2.0 * rubber / (PI * length * length) * dl)
                / state.outer_diameter,
            fluid_volume: self.relaxed_volume * dw,
            compliance: state.compliance * (-da / a - curvature * dw / slope),
            stretch_axial: dl1,
            stretch_hoop: dl2,
            stretch_radial: dl3,
            stress_axial: d_stress_axial,
            stress_hoop: dmooney(l2, dl2) - dp,
            force: d_force,
            ballooning_pressure: da * self.log_ratio,
        }
    }
}
