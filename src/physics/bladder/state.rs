//! The bladder's outputs at one operating point: forces, contact pressure, diameters, stretches
//! and the stresses of the innermost layer, on the contact branch and on the free one.

use super::continuum::KernelScalar;
use super::{Bladder, Kernel, SleeveGeometry};
use crate::physics::numerics::dual::Dual;
use std::f64::consts::PI;

/// Everything the bladder model says at one pressure and muscle length.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BladderState {
    /// Muscle tension, N: strands + pressure end force + bladder elastic force (eq. 2.4 without
    /// friction, eq. 2.16 + 2.17).
    pub force: f64,
    /// `F_strands = P_eff (A - dV/dL)`, N (eq. 2.16; `P_eff L^2 / (2 pi n^2)` for the helical
    /// sleeve): the sleeve's strand tension.
    pub strand_force: f64,
    /// `dF_strands/dL` along the current branch, N/m (zero when free).
    pub strand_stiffness: f64,
    /// `F_pressure = -P A_fluid`, N (eq. 2.5).
    pub pressure_force: f64,
    /// `F_elastic`, the axial force carried by the rubber, summed over layers, N (eq. 2.17).
    pub elastic_force: f64,
    /// Contact pressure of bladder on sleeve, Pa, never negative (eq. 2.12, 2.19).
    pub effective_pressure: f64,
    /// `dP_eff/dL` along the current branch, Pa/m (zero when free).
    pub effective_pressure_slope: f64,
    /// Whether the bladder presses on the sleeve (`P >= threshold_pressure`).
    pub contact: bool,
    /// See [`Bladder::threshold_pressure`], Pa.
    pub threshold_pressure: f64,
    /// Gas volume inside the bladder, `pi/4 D_in^2 L`, m^3.
    pub fluid_volume: f64,
    /// Inner diameter of the bladder, m (eq. 2.7 in contact, eq. 2.18 when free).
    pub inner_diameter: f64,
    /// Outer diameter of the bladder, m (the sleeve's diameter in contact).
    pub outer_diameter: f64,
    /// `lambda_1 = L / L_R0` (eq. 2.8a).
    pub stretch_axial: f64,
    /// `lambda_2` of the inner wall, `D_in / D_RI` (eq. 2.8b).
    pub stretch_hoop: f64,
    /// `lambda_3 = 1 / (lambda_1 lambda_2)` of the inner wall (eq. 2.8c).
    pub stretch_radial: f64,
    /// True axial stress of the innermost layer, Pa (eq. 2.9a; the thin-wall value for one layer).
    pub stress_axial: f64,
    /// True hoop stress of the innermost layer, Pa (eq. 2.9b, 2.11).
    pub stress_hoop: f64,
    /// True radial stress of the innermost layer, `-P`, Pa.
    pub stress_radial: f64,
    /// `dF/dL`, N/m, analytic (forward-mode derivative through the layer recursion; when free,
    /// through the root of eq. 2.18 by the implicit function theorem).
    pub stiffness: f64,
}

impl<S: SleeveGeometry> Bladder<S> {
    pub(super) fn fluid_area<T: KernelScalar>(&self, inner_l2_sq: T) -> T {
        let d_ri = self.tube.inner_diameter;
        inner_l2_sq * (PI / 4.0 * d_ri * d_ri)
    }

    pub(super) fn contact_state(&self, pressure: f64, length: f64, k: &Kernel) -> BladderState {
        let (g, g_slope) = self.sleeve.strand_area(length);
        let strand_area = Dual {
            v: g,
            dl: g_slope,
            dx: 0.0,
        };
        // Eq. 2.16: P_eff (A - dV/dL) - P A_fluid, plus eq. 2.17.
        let strands = k.p_eff * strand_area;
        let area = self.fluid_area(k.inner.l2_sq);
        let pressure_force = area * (-pressure);
        let force = strands + pressure_force + k.elastic;
        // The dual-number seed carried the contact branch's total d/dL in `dl`.
        self.state(
            pressure,
            length,
            k,
            Parts {
                force: force.v,
                strand: strands.v,
                strand_slope: strands.dl,
                pressure_force: pressure_force.v,
                p_eff: k.p_eff.v,
                p_eff_slope: k.p_eff.dl,
                contact: true,
                threshold: k.threshold,
                area: area.v,
                stiffness: force.dl,
            },
        )
    }

    pub(super) fn free_state(
        &self,
        pressure: f64,
        length: f64,
        k: &Kernel,
        threshold: f64,
    ) -> BladderState {
        let area = self.fluid_area(k.inner.l2_sq);
        let pressure_force = area * (-pressure);
        let force = pressure_force + k.elastic;
        // Implicit function theorem on P_eff(L, x) = 0: dx/dL = -dP_eff/dL / dP_eff/dx.
        let dx_dl = if k.p_eff.dx != 0.0 {
            -k.p_eff.dl / k.p_eff.dx
        } else {
            0.0
        };
        self.state(
            pressure,
            length,
            k,
            Parts {
                force: force.v,
                strand: 0.0,
                strand_slope: 0.0,
                pressure_force: pressure_force.v,
                p_eff: 0.0,
                p_eff_slope: 0.0,
                contact: false,
                threshold,
                area: area.v,
                stiffness: force.dl + force.dx * dx_dl,
            },
        )
    }

    fn state(&self, pressure: f64, length: f64, k: &Kernel, p: Parts) -> BladderState {
        let lambda1 = length / self.tube.unstretched_length;
        let lambda2 = k.inner.l2_sq.v.sqrt();
        let d_in = lambda2 * self.tube.inner_diameter;
        let d_out = (d_in * d_in + 4.0 * self.rubber_volume / (PI * length)).sqrt();
        BladderState {
            force: p.force,
            strand_force: p.strand,
            strand_stiffness: p.strand_slope,
            pressure_force: p.pressure_force,
            elastic_force: k.elastic.v,
            effective_pressure: p.p_eff,
            effective_pressure_slope: p.p_eff_slope,
            contact: p.contact,
            threshold_pressure: p.threshold,
            fluid_volume: p.area * length,
            inner_diameter: d_in,
            outer_diameter: d_out,
            stretch_axial: lambda1,
            stretch_hoop: lambda2,
            stretch_radial: 1.0 / (lambda1 * lambda2),
            stress_axial: k.inner.axial.v - pressure,
            stress_hoop: k.inner.hoop.v - pressure,
            stress_radial: -pressure,
            stiffness: p.stiffness,
        }
    }
}

pub(super) fn check_state(s: BladderState, length: f64) -> Result<BladderState, String> {
    let all = [
        s.force,
        s.strand_force,
        s.strand_stiffness,
        s.pressure_force,
        s.elastic_force,
        s.effective_pressure,
        s.effective_pressure_slope,
        s.threshold_pressure,
        s.fluid_volume,
        s.inner_diameter,
        s.outer_diameter,
        s.stretch_axial,
        s.stretch_hoop,
        s.stretch_radial,
        s.stress_axial,
        s.stress_hoop,
        s.stress_radial,
        s.stiffness,
    ];
    if all.iter().all(|v| v.is_finite()) {
        Ok(s)
    } else {
        Err(format!(
            "bladder state overflows at length {length} m (too close to a length limit)"
        ))
    }
}

struct Parts {
    force: f64,
    strand: f64,
    strand_slope: f64,
    pressure_force: f64,
    p_eff: f64,
    p_eff_slope: f64,
    contact: bool,
    threshold: f64,
    area: f64,
    stiffness: f64,
}
