//! The McKibben muscle's bladder on its own: an incompressible Mooney-Rivlin tube (dissertation
//! section 2.2.2, eq. 2.6-2.9) whose ends are clamped a given length apart and which is inflated
//! by a gauge pressure, with no sleeve around it. This is the muscle's free branch (`P_eff = 0`)
//! as a component of its own: a pneumatic capacitance whose volume, stretches, stresses and clamp
//! force follow the pressure.
//!
//! The wall is the exact thick tube (Rivlin's integral, as the muscle's exact wall), which for a
//! free tube has a closed form. With `lambda_z = L / L_R0` every material circle has
//! `u = lambda_z lambda_theta^2 = 1 + (w - 1) R_i^2 / R^2` (incompressibility, eq. 2.20), with
//! `w` the inner wall's `u`, i.e. the volume ratio `V / V_0`. The hoop difference of eq. 2.9b is
//! `h = 2 (C1 + C2 lambda_z^2)(u - 1/u) / lambda_z` and `dr / r = -du / (2 u (u - 1))`, so the
//! pressure the wall holds, `P = int h dr / r`, is
//!
//! `P = (A / 2) (ln(w / u_o) + 1/u_o - 1/w)`, `A = 2 (C1 / lambda_z + C2 lambda_z)`,
//! `u_o = 1 + (w - 1) rho`, `rho = (D_RI / D_RO)^2`,
//!
//! which rises monotonically in `w` towards the ballooning pressure `A ln(D_RO / D_RI)` without
//! reaching it (the dissertation's thin wall, eq. 2.18, gives `A (D_RO - D_RI) / D_RI` instead:
//! 52.6 against 49.5 kPa for muscle D's tube, 800 against 439 kPa for muscles A-C's). The clamp
//! force is `F = int (2 g - h) pi r dr` (the rubber's axial force `int (g - p) 2 pi r dr` with
//! `g` of eq. 2.9a, less the pressure on the closed ends, integrated by parts), and with
//! `2 g - h = G + alpha (u + 1/u)` this is, in `s = R^2`,
//!
//! `F = pi / (2 lambda_z) ((G + 2 alpha)(R_o^2 - R_i^2) + alpha (w - 1) R_i^2 ln(w / u_o))`,
//!
//! `G = 4 C1 lambda_z^2 - 4 C2 / lambda_z^2`, `alpha = 2 C2 lambda_z - 2 C1 / lambda_z`. The
//! volume ratio is the root of the pressure equation by a safeguarded Newton-bisection; `dV/dP`
//! follows from its slope.

use crate::physics::bladder::BladderTube;
use crate::physics::numerics::root::{newton_bisection, RootOptions, Sample};
use std::f64::consts::PI;

/// Iteration cap of the volume-ratio root (Newton-bisection on a monotone smooth function).
const ROOT_ITERATIONS: usize = 200;
/// Doublings (halvings) allowed when bracketing the volume ratio above (below) 1.
const BRACKET_STEPS: usize = 2100;

/// A thick-walled Mooney-Rivlin tube, free of any sleeve, with its parameter-only constants.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FreeBladder {
    tube: BladderTube,
    /// `rho = (D_RI / D_RO)^2`.
    rho: f64,
    /// `ln(D_RO / D_RI)`: the ballooning pressure per unit of eq. 2.18's modulus.
    log_ratio: f64,
    /// `(R_o^2 - R_i^2, R_i^2)`, m^2.
    radii_sq: (f64, f64),
    /// Rubber volume `V_R`, m^3 (eq. 2.6).
    rubber_volume: f64,
    /// Relaxed cavity volume `V_0 = pi/4 D_RI^2 L_R0`, m^3.
    relaxed_volume: f64,
}

/// Everything the free bladder says at one pressure and length. Stretches and stresses are the
/// inner wall's (eq. 2.8-2.9, where `sigma_33 = -P` exactly).
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
            rho: (d_ri / d_ro).powi(2),
            log_ratio: (d_ro / d_ri).ln(),
            radii_sq: ((d_ro * d_ro - d_ri * d_ri) / 4.0, d_ri * d_ri / 4.0),
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

    /// The pressure the tube approaches as its diameter grows without bound at `length`,
    /// `2 (C1/lambda_1 + C2 lambda_1) ln(D_RO / D_RI)`, Pa. Below it the free tube has one
    /// equilibrium diameter; at and above it none.
    pub fn ballooning_pressure(&self, length: f64) -> f64 {
        self.modulus(length / self.tube.unstretched_length) * self.log_ratio
    }

    /// `d ballooning_pressure / d length`, Pa/m: `2 (C2 - C1/lambda_1^2) ln(D_RO/D_RI) / L_R0`.
    pub fn ballooning_pressure_slope(&self, length: f64) -> f64 {
        let l1 = length / self.tube.unstretched_length;
        let da_dl1 = 2.0 * (self.tube.mooney_c2 - self.tube.mooney_c1 / (l1 * l1));
        da_dl1 * self.log_ratio / self.tube.unstretched_length
    }

    /// `(f, f', f'')` of `P = (A/2) f(w)` (module comment), written without cancellation
    /// near the relaxed tube `w = 1`.
    fn shape(&self, w: f64) -> (f64, f64, f64) {
        let rho = self.rho;
        let u_o = 1.0 + (w - 1.0) * rho;
        // ln(w / u_o) = ln(1 + e), 1/u_o - 1/w = e / w, with e = (w - u_o) / u_o.
        let e = (w - 1.0) * (1.0 - rho) / u_o;
        let f = e.ln_1p() + e / w;
        let slope = (1.0 - rho) / (w * u_o) + (u_o * u_o - rho * w * w) / (w * w * u_o * u_o);
        let (w2, u2) = (w * w, u_o * u_o);
        let curvature = -1.0 / w2 - 2.0 / (w2 * w) + rho * rho / u2 + 2.0 * rho * rho / (u2 * u_o);
        (f, slope, curvature)
    }

    /// `ln(w / u_o)`, the clamp force's logarithm.
    fn log_volume_ratio(&self, w: f64) -> f64 {
        let u_o = 1.0 + (w - 1.0) * self.rho;
        ((w - 1.0) * (1.0 - self.rho) / u_o).ln_1p()
    }

    /// The gauge pressure (Pa) that holds the tube at inner hoop stretch `stretch_hoop` when its
    /// axial stretch is `stretch_axial` (Rivlin's integral, module comment).
    pub fn equilibrium_pressure(&self, stretch_axial: f64, stretch_hoop: f64) -> f64 {
        let w = stretch_axial * stretch_hoop * stretch_hoop;
        0.5 * self.modulus(stretch_axial) * self.shape(w).0
    }

    /// The modulus `A` and the volume ratio `w` at `pressure` and `length` (checked finite and
    /// positive by the caller). `Err` at or above the ballooning pressure.
    fn volume_ratio(&self, pressure: f64, length: f64) -> Result<(f64, f64), String> {
        let a = self.modulus(length / self.tube.unstretched_length);
        let top = a * self.log_ratio;
        if pressure >= top {
            return Err(format!(
                "pressure {pressure} Pa is at or above the ballooning pressure {top} Pa at length \
                 {length} m: the free tube has no equilibrium and inflates without bound"
            ));
        }
        let target = 2.0 * pressure / a;
        let residual = |w: f64| self.shape(w).0 - target;
        // f(1) = 0, f rises from -inf at w = 0 to ln(1/rho): bracket from w = 1 outwards.
        let (mut lo, mut hi) = (1.0, 1.0);
        for _ in 0..BRACKET_STEPS {
            if residual(hi) >= 0.0 {
                break;
            }
            lo = hi;
            hi *= 2.0;
        }
        for _ in 0..BRACKET_STEPS {
            if residual(lo) <= 0.0 {
                break;
            }
            hi = lo;
            lo *= 0.5;
        }
        if !(residual(lo) <= 0.0 && residual(hi) >= 0.0 && lo > 0.0 && hi.is_finite()) {
            return Err(format!(
                "no free equilibrium found at pressure {pressure} Pa and length {length} m"
            ));
        }
        let options = RootOptions {
            absolute: 0.0,
            relative: 1e-15,
            max_iterations: ROOT_ITERATIONS,
            jump_width: 0.0,
        };
        let root = newton_bisection(lo, hi, 1.0, true, options, |w| {
            let (f, slope, _) = self.shape(w);
            Ok::<_, ()>(Some(Sample {
                value: f - target,
                slope,
                payload: (),
            }))
        });
        Ok((a, root.map_or(0.5 * (lo + hi), |r| r.x)))
    }

    /// The clamp force (module comment), N, at axial stretch `l1` and volume ratio `w`.
    fn clamp_force(&self, l1: f64, w: f64) -> f64 {
        let (c1, c2) = (self.tube.mooney_c1, self.tube.mooney_c2);
        let (g0, alpha) = Self::force_constants(c1, c2, l1);
        let (ring, inner) = self.radii_sq;
        PI / (2.0 * l1)
            * ((g0 + 2.0 * alpha) * ring + alpha * (w - 1.0) * inner * self.log_volume_ratio(w))
    }

    /// `(G, alpha)` of the clamp force at axial stretch `l1` (module comment).
    fn force_constants(c1: f64, c2: f64, l1: f64) -> (f64, f64) {
        (
            4.0 * c1 * l1 * l1 - 4.0 * c2 / (l1 * l1),
            2.0 * c2 * l1 - 2.0 * c1 / l1,
        )
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
        let ballooning = a * self.log_ratio;
        let l2 = (w / l1).sqrt();
        let l3 = 1.0 / (l1 * l2);
        let (c1, c2) = (self.tube.mooney_c1, self.tube.mooney_c2);
        let mooney =
            |s: f64| 2.0 * c1 * (s * s - l3 * l3) - 2.0 * c2 * (1.0 / (s * s) - 1.0 / (l3 * l3));
        // Eq. 2.9 at the inner wall, where sigma_33 = -P.
        let stress_axial = mooney(l1) - pressure;
        let stress_hoop = mooney(l2) - pressure;
        let d_in = l2 * self.tube.inner_diameter;
        let fluid_volume = self.relaxed_volume * w;
        // dP/dw = (A/2) f'(w) > 0.
        let dp_dw = 0.5 * a * self.shape(w).1;
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
            force: self.clamp_force(l1, w),
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
#[path = "free_bladder_wall.rs"]
mod wall;
pub use partials::FreeBladderPartials;

#[cfg(test)]
#[path = "free_bladder_tests.rs"]
mod tests;
