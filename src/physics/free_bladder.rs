//! The McKibben muscle's bladder on its own: a thin-walled Mooney-Rivlin tube (dissertation
//! section 2.2.2, eq. 2.6-2.12, 2.17, 2.18) whose ends are clamped a given length apart and which
//! is inflated by a gauge pressure, with no sleeve around it. This is the muscle's free branch
//! (`P_eff = 0`) as a component of its own: a pneumatic capacitance whose volume, stretches,
//! stresses and clamp force follow the pressure.
//!
//! Eq. 2.18, divided by `lambda_2` and written in `w = lambda_1 lambda_2^2`, is
//! `P (r w^2 + w) = A (w^2 - 1)` with `A = 2 (C1/lambda_1 + C2 lambda_1)` and
//! `r = D_RI / (D_RO - D_RI)`: a quadratic in `w` with exactly one positive root for
//! `P < A / r`, so the free diameter has a closed form and no root finder is needed. Its
//! equilibrium pressure `A (w^2 - 1) / (r w^2 + w)` rises monotonically in `w` towards `A / r`
//! without reaching it: above that ballooning pressure eq. 2.18 has no solution and the thin
//! tube inflates without bound.
//!
//! The fluid volume is `pi/4 D_in^2 L = V_0 w` with `V_0 = pi/4 D_RI^2 L_R0` the relaxed cavity
//! (incompressibility, eq. 2.8c), so `w` is the volume ratio and `dV/dP` follows from the
//! quadratic's slope.

use crate::physics::bladder::BladderTube;
use std::f64::consts::PI;

/// A thin-walled Mooney-Rivlin tube, free of any sleeve, with its parameter-only constants.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FreeBladder {
    tube: BladderTube,
    /// `r = D_RI / (D_RO - D_RI)` of eq. 2.12 (the wall's slenderness).
    slenderness: f64,
    /// Rubber volume `V_R`, m^3 (eq. 2.6).
    rubber_volume: f64,
    /// Relaxed cavity volume `V_0 = pi/4 D_RI^2 L_R0`, m^3.
    relaxed_volume: f64,
}

/// Everything the free bladder says at one pressure and length. Stresses are true stresses of
/// the thin wall with `sigma_33 = -P` (eq. 2.9).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeBladderState {
    /// Inner diameter `D_in = lambda_2 D_RI`, m (eq. 2.8b, 2.18).
    pub inner_diameter: f64,
    /// Outer diameter, m (the rubber's volume is conserved, eq. 2.6).
    pub outer_diameter: f64,
    /// Gas volume inside the tube, `pi/4 D_in^2 L`, m^3.
    pub fluid_volume: f64,
    /// `dV/dP` at fixed length, m^3/Pa: the tube as a pneumatic capacitance.
    pub compliance: f64,
    /// `lambda_1 = L / L_R0` (eq. 2.8a).
    pub stretch_axial: f64,
    /// `lambda_2 = D_in / D_RI` (eq. 2.8b).
    pub stretch_hoop: f64,
    /// `lambda_3 = 1 / (lambda_1 lambda_2)` (eq. 2.8c).
    pub stretch_radial: f64,
    /// `sigma_11`, Pa (eq. 2.9a).
    pub stress_axial: f64,
    /// `sigma_22`, Pa (eq. 2.9b; equals eq. 2.11 with `P_eff = 0`).
    pub stress_hoop: f64,
    /// Axial force the clamps hold, N: the rubber's `sigma_11 V_R / L` (eq. 2.17) minus the
    /// pressure on the closed ends, `P pi/4 D_in^2` (eq. 2.5).
    pub force: f64,
    /// See [`FreeBladder::ballooning_pressure`], Pa.
    pub ballooning_pressure: f64,
}

impl FreeBladder {
    /// `Err` names the parameter that is not positive and finite (Mooney-Rivlin constants may be
    /// zero, not both).
    pub fn new(tube: BladderTube) -> Result<Self, String> {
        for (name, v) in [
            ("inner_diameter (m)", tube.inner_diameter),
            ("thickness (m)", tube.thickness),
            ("unstretched_length (m)", tube.unstretched_length),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!(
                    "bladder {name} must be positive and finite, got {v}"
                ));
            }
        }
        let (c1, c2) = (tube.mooney_c1, tube.mooney_c2);
        if !(c1.is_finite() && c2.is_finite() && c1 >= 0.0 && c2 >= 0.0 && c1 + c2 > 0.0) {
            return Err(format!(
                "mooney_c1 and mooney_c2 must be finite and >= 0 Pa, not both zero, got {c1} and {c2}"
            ));
        }
        let d_ri = tube.inner_diameter;
        let d_ro = d_ri + 2.0 * tube.thickness;
        let rubber_volume = PI / 4.0 * (d_ro * d_ro - d_ri * d_ri) * tube.unstretched_length;
        let relaxed_volume = PI / 4.0 * d_ri * d_ri * tube.unstretched_length;
        if !(rubber_volume.is_finite() && relaxed_volume.is_finite()) {
            return Err("bladder geometry gives a non-finite volume".into());
        }
        Ok(Self {
            tube,
            slenderness: d_ri / (d_ro - d_ri),
            rubber_volume,
            relaxed_volume,
        })
    }

    pub fn tube(&self) -> &BladderTube {
        &self.tube
    }

    /// Rubber volume `V_R`, m^3 (eq. 2.6).
    pub fn rubber_volume(&self) -> f64 {
        self.rubber_volume
    }

    /// `A = 2 (C1 / lambda_1 + C2 lambda_1)`, Pa: eq. 2.18's stiffness at axial stretch `l1`.
    fn modulus(&self, l1: f64) -> f64 {
        2.0 * (self.tube.mooney_c1 / l1 + self.tube.mooney_c2 * l1)
    }

    /// The pressure eq. 2.18 approaches as the tube's diameter grows without bound at `length`,
    /// `2 (C1/lambda_1 + C2 lambda_1) (D_RO - D_RI) / D_RI`, Pa. Below it the free tube has one
    /// equilibrium diameter; at and above it none.
    pub fn ballooning_pressure(&self, length: f64) -> f64 {
        self.modulus(length / self.tube.unstretched_length) / self.slenderness
    }

    /// `d ballooning_pressure / d length`, Pa/m: `2 (C2 - C1/lambda_1^2) / (r L_R0)`.
    pub fn ballooning_pressure_slope(&self, length: f64) -> f64 {
        let l1 = length / self.tube.unstretched_length;
        let da_dl1 = 2.0 * (self.tube.mooney_c2 - self.tube.mooney_c1 / (l1 * l1));
        da_dl1 / (self.slenderness * self.tube.unstretched_length)
    }

    /// The gauge pressure (Pa) that holds the tube at hoop stretch `stretch_hoop` when its axial
    /// stretch is `stretch_axial`: eq. 2.18 solved for `P`.
    pub fn equilibrium_pressure(&self, stretch_axial: f64, stretch_hoop: f64) -> f64 {
        let w = stretch_axial * stretch_hoop * stretch_hoop;
        self.modulus(stretch_axial) * (w * w - 1.0) / (self.slenderness * w * w + w)
    }

    /// Eq. 2.18's modulus `A` and its root `w = lambda_1 lambda_2^2` at `pressure` and `length`
    /// (checked finite and positive by the caller). `Err` at or above the ballooning pressure.
    fn volume_ratio(&self, pressure: f64, length: f64) -> Result<(f64, f64), String> {
        let a = self.modulus(length / self.tube.unstretched_length);
        let r = self.slenderness;
        // (A - P r) w^2 - P w - A = 0: the positive root, in the form without cancellation.
        let lead = a - pressure * r;
        if lead <= 0.0 {
            return Err(format!(
                "pressure {pressure} Pa is at or above the ballooning pressure {} Pa at length \
                 {length} m: eq. 2.18 has no equilibrium, the free tube inflates without bound",
                a / r
            ));
        }
        let root = (pressure * pressure + 4.0 * a * lead).sqrt();
        let w = if pressure > 0.0 {
            (pressure + root) / (2.0 * lead)
        } else {
            2.0 * a / (root - pressure)
        };
        Ok((a, w))
    }

    /// The tube at gauge pressure `pressure` (Pa) with its ends `length` (m) apart. `Err` for a
    /// non-finite input, a length that is not positive, or a pressure at or above the ballooning
    /// pressure (no equilibrium: the tube inflates without bound).
    pub fn evaluate(&self, pressure: f64, length: f64) -> Result<FreeBladderState, String> {
        if !pressure.is_finite() {
            return Err(format!("pressure must be finite, got {pressure} Pa"));
        }
        if !(length.is_finite() && length > 0.0) {
            return Err(format!(
                "length must be positive and finite, got {length} m"
            ));
        }
        let l1 = length / self.tube.unstretched_length;
        let (a, w) = self.volume_ratio(pressure, length)?;
        let r = self.slenderness;
        let ballooning = a / r;
        let l2 = (w / l1).sqrt();
        let l3 = 1.0 / (l1 * l2);
        let (c1, c2) = (self.tube.mooney_c1, self.tube.mooney_c2);
        let mooney =
            |s: f64| 2.0 * c1 * (s * s - l3 * l3) - 2.0 * c2 * (1.0 / (s * s) - 1.0 / (l3 * l3));
        // Eq. 2.9 with sigma_33 = -P.
        let stress_axial = mooney(l1) - pressure;
        let stress_hoop = mooney(l2) - pressure;
        let d_in = l2 * self.tube.inner_diameter;
        let fluid_area = PI / 4.0 * d_in * d_in;
        let fluid_volume = self.relaxed_volume * w;
        // dP/dw = A (w^2 + 2 r w + 1) / (r w^2 + w)^2 > 0.
        let denominator = r * w * w + w;
        let dp_dw = a * (w * w + 2.0 * r * w + 1.0) / (denominator * denominator);
        let state = FreeBladderState {
            inner_diameter: d_in,
            outer_diameter: (d_in * d_in + 4.0 * self.rubber_volume / (PI * length)).sqrt(),
            fluid_volume,
            compliance: self.relaxed_volume / dp_dw,
            stretch_axial: l1,
            stretch_hoop: l2,
            stretch_radial: l3,
            stress_axial,
            stress_hoop,
            force: stress_axial * self.rubber_volume / length - pressure * fluid_area,
            ballooning_pressure: ballooning,
        };
        let all = [
            state.inner_diameter,
            state.outer_diameter,
            state.fluid_volume,
            state.compliance,
            state.stretch_hoop,
            state.stretch_radial,
            state.stress_axial,
            state.stress_hoop,
            state.force,
            state.ballooning_pressure,
        ];
        if all.iter().all(|v| v.is_finite()) {
            Ok(state)
        } else {
            Err(format!(
                "free bladder overflows at pressure {pressure} Pa and length {length} m"
            ))
        }
    }
}

#[path = "free_bladder_partials.rs"]
mod partials;
pub use partials::FreeBladderPartials;

#[cfg(test)]
#[path = "free_bladder_tests.rs"]
mod tests;
