//! The stress field through the bladder's wall: radius and true (Cauchy) stresses at material
//! circles evenly spaced through the relaxed wall, from the inner surface to the outer one (the
//! FMI 3.0 FMUs' array outputs).
//!
//! The wall is deformed as the selected wall computed it (axial stretch `lambda_1 = L / L_R0`,
//! outer diameter `x`); each circle of relaxed diameter `s` then has the deformed diameter
//! `d^2 = x^2 - (D_RO^2 - s^2) / lambda_1` (eq. 2.20, incompressibility), its stretches
//! `lambda_2 = d / s`, `lambda_3 = 1 / (lambda_1 lambda_2)` (eq. 2.8) and the Mooney-Rivlin
//! differences `h = sigma_22 - sigma_33` and `g = sigma_11 - sigma_33` (eq. 2.9b, 2.9a). The radial
//! stress `sigma_33 = -p` follows from the wall's balance, integrated from `p = P` at the inner
//! surface, in the continuous form of the selected wall's family:
//! - the exact wall and the layers balanced by their stress difference (`bladder_model` 1-3):
//!   radial equilibrium `dp/dr = -h / r` (`exact.rs`), so `p = P - int h dr / r`;
//! - the dissertation's walls (4-6): the limit of eq. 2.12 per layer, `dp/dr = (p - h) / r`
//!   (`continuum.rs`), so `p = d (P / d_in - int h dd / d^2)`.
//!
//! For the quadrature walls (3 and 6) this is the wall's own field: the outer surface carries the
//! contact pressure, `sigma_33 = -P_eff` (0 for a free bladder). For the layered walls it is their
//! family's limit of infinitely many layers at the deformation they computed, so its outer value
//! shows how far their `P_eff` is from that limit.
//!
//! In `u = d^2` the integrals are `int h du / (2u)` and `int h du / (2 u^(3/2))` with smooth
//! integrands (`s^2 = D_RO^2 - lambda_1 (x^2 - u)` stays positive through the wall), taken by a
//! Gauss-Legendre rule between consecutive circles.

use super::continuum::gauss_legendre;
use super::{Bladder, SleeveGeometry, Wall};

/// Gauss-Legendre nodes between two consecutive circles: the integrands are smooth rational
/// functions of `u` over a fraction of the wall, so this is exact to rounding.
const NODES: usize = 16;

/// The wall at one material circle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallPoint {
    /// Deformed radius, m.
    pub radius: f64,
    /// True radial stress `sigma_33`, Pa (`-P` at the inner surface).
    pub stress_radial: f64,
    /// True hoop stress `sigma_22`, Pa.
    pub stress_hoop: f64,
    /// True axial stress `sigma_11`, Pa.
    pub stress_axial: f64,
}

impl WallPoint {
    fn is_finite(&self) -> bool {
        [
            self.radius,
            self.stress_radial,
            self.stress_hoop,
            self.stress_axial,
        ]
        .iter()
        .all(|v| v.is_finite())
    }

    /// `Ok` if every point of a field computed at muscle length `length` (m) is finite, else why
    /// not: near a length limit the stretches, and with them the stresses, overflow.
    pub fn check_field(field: &[WallPoint], length: f64) -> Result<(), String> {
        if field.iter().all(WallPoint::is_finite) {
            Ok(())
        } else {
            Err(format!(
                "the wall's stress field overflows at length {length} m (too close to a length limit)"
            ))
        }
    }
}

impl<S: SleeveGeometry> Bladder<S> {
    /// The wall's stress field at gauge pressure `pressure` (Pa) and muscle length `length` (m),
    /// written to `out`: its first element is the inner surface, its last the outer one (one
    /// element: the inner surface). `Err` where [`Bladder::evaluate`] has no solution.
    pub fn wall_field(
        &self,
        pressure: f64,
        length: f64,
        out: &mut [WallPoint],
    ) -> Result<(), String> {
        let state = self.evaluate(pressure, length)?;
        self.field_at(pressure, state.stretch_axial, state.outer_diameter, out);
        WallPoint::check_field(out, length)
    }

    /// The field at axial stretch `lambda1` and outer diameter `x`.
    fn field_at(&self, pressure: f64, lambda1: f64, x: f64, out: &mut [WallPoint]) {
        let (c1x2, c2x2) = (2.0 * self.tube.mooney_c1, 2.0 * self.tube.mooney_c2);
        let (lambda1_sq, inv_lambda1_sq) = (lambda1 * lambda1, 1.0 / (lambda1 * lambda1));
        // Eq. 2.9b and 2.9a with l3^2 = 1 / (lambda_1^2 l2^2), as in `exact.rs`.
        let (hoop_a, hoop_b) = (c1x2 + c2x2 * lambda1_sq, c1x2 * inv_lambda1_sq + c2x2);
        let axial_const = c1x2 * lambda1_sq - c2x2 * inv_lambda1_sq;
        let d_ri = self.tube.inner_diameter;
        let d_ro = self.outer_diameter;
        let x_sq = x * x;
        let l2_sq = |u: f64| u / (d_ro * d_ro - lambda1 * (x_sq - u));
        let hoop = |u: f64| {
            let l2 = l2_sq(u);
            l2 * hoop_a - hoop_b / l2
        };
        let axial = |u: f64| {
            let l2 = l2_sq(u);
            axial_const + l2 * c2x2 * lambda1_sq - c1x2 * inv_lambda1_sq / l2
        };
        let as_written = matches!(
            self.wall,
            Wall::DissertationLayers(_) | Wall::DissertationContinuum(_)
        );
        // The balance's integrand: h / (2u) (radial equilibrium) or h / (2 u^(3/2)).
        let integrand = |u: f64| {
            if as_written {
                hoop(u) / (2.0 * u * u.sqrt())
            } else {
                hoop(u) / (2.0 * u)
            }
        };
        let rule = gauss_legendre(NODES);
        let intervals = out.len().saturating_sub(1).max(1) as f64;
        let u_at = |k: usize| {
            let s = d_ri + (d_ro - d_ri) * k as f64 / intervals;
            x_sq - (d_ro * d_ro - s * s) / lambda1
        };
        let u_in = u_at(0);
        let (mut integral, mut u_prev) = (0.0, u_in);
        for (k, point) in out.iter_mut().enumerate() {
            let u = u_at(k);
            let (mid, half) = (0.5 * (u + u_prev), 0.5 * (u - u_prev));
            integral += half
                * rule
                    .iter()
                    .map(|&(t, w)| w * integrand(mid + half * t))
                    .sum::<f64>();
            u_prev = u;
            let p = if as_written {
                u.sqrt() * (pressure / u_in.sqrt() - integral)
            } else {
                pressure - integral
            };
            *point = WallPoint {
                radius: 0.5 * u.sqrt(),
                stress_radial: -p,
                stress_hoop: hoop(u) - p,
                stress_axial: axial(u) - p,
            };
        }
    }
}
