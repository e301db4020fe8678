//! The free tube's stress field through its wall (FMI 3.0 array outputs, as the muscle's bladder
//! has them, [`crate::physics::bladder::WallPoint`]): radius and true stresses at material circles
//! evenly spaced through the relaxed wall, inner surface first. The free tube's radial
//! equilibrium has a closed form: with `u = lambda_z lambda_theta^2` of a circle (`w` at the inner
//! wall), `sigma_33(u) = -P + (A/2) (ln(w/u) + 1/u - 1/w)` (see `free_bladder.rs`), which is 0 at
//! the outer wall because that is the pressure the wall holds; the hoop and axial stresses add
//! eq. 2.9's differences at the circle's stretches.

use super::FreeBladder;
use crate::physics::bladder::WallPoint;

impl FreeBladder {
    /// The wall's field at gauge pressure `pressure` (Pa) and length `length` (m) into `out`
    /// (first element the inner surface, last the outer one). `Err` where
    /// [`FreeBladder::evaluate`] has no equilibrium.
    pub fn wall_field(
        &self,
        pressure: f64,
        length: f64,
        out: &mut [WallPoint],
    ) -> Result<(), String> {
        let state = self.evaluate(pressure, length)?;
        let l1 = state.stretch_axial;
        let w = l1 * state.stretch_hoop * state.stretch_hoop;
        let a = self.modulus(l1);
        let (c1, c2) = (self.tube.mooney_c1, self.tube.mooney_c2);
        let r_i = 0.5 * self.tube.inner_diameter;
        let r_o = r_i + self.tube.thickness;
        let intervals = out.len().saturating_sub(1).max(1) as f64;
        for (k, point) in out.iter_mut().enumerate() {
            let r = r_i + (r_o - r_i) * k as f64 / intervals;
            // Incompressibility (eq. 2.20): u = 1 + (w - 1) R_i^2 / R^2.
            let u = 1.0 + (w - 1.0) * (r_i / r).powi(2);
            let (l2, l3) = ((u / l1).sqrt(), 1.0 / (l1 * (u / l1).sqrt()));
            // Eq. 2.9: sigma_ii - sigma_33 at stretch s.
            let mooney = |s: f64| {
                2.0 * c1 * (s * s - l3 * l3) - 2.0 * c2 * (1.0 / (s * s) - 1.0 / (l3 * l3))
            };
            let radial = -pressure + 0.5 * a * ((w / u).ln() + 1.0 / u - 1.0 / w);
            *point = WallPoint {
                radius: r * l2,
                stress_radial: radial,
                stress_hoop: radial + mooney(l2),
                stress_axial: radial + mooney(l1),
            };
        }
        WallPoint::check_field(out, length)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::bladder::{BladderTube, MOONEY_C1, MOONEY_C2};

    #[test]
    fn a_free_tube_holds_its_pressure_with_a_free_outer_surface() {
        // Table 2.1's thick tube (A) and thin tube (D).
        for (l0, d_ri, t) in [(0.1005, 1.6e-3, 1.6e-3), (0.1336, 3.8e-3, 0.25e-3)] {
            let tube = BladderTube {
                inner_diameter: d_ri,
                thickness: t,
                unstretched_length: l0,
                mooney_c1: MOONEY_C1,
                mooney_c2: MOONEY_C2,
            };
            let b = FreeBladder::new(tube).unwrap();
            for (stretch, fraction) in [(0.8, 0.5), (1.0, 0.9), (1.3, 0.3)] {
                let length = stretch * l0;
                let pressure = fraction * b.ballooning_pressure(length);
                let s = b.evaluate(pressure, length).unwrap();
                let mut f = vec![WallPoint::default(); 4001];
                b.wall_field(pressure, length, &mut f).unwrap();
                let (inner, outer) = (f[0], f[4000]);
                assert_eq!(inner.stress_radial, -pressure);
                assert!(
                    outer.stress_radial.abs() < 1e-9 * pressure,
                    "{}",
                    outer.stress_radial
                );
                assert!((inner.radius - 0.5 * s.inner_diameter).abs() < 1e-12 * inner.radius);
                assert!((outer.radius - 0.5 * s.outer_diameter).abs() < 1e-12 * outer.radius);
                assert!((inner.stress_hoop - s.stress_hoop).abs() < 1e-9 * pressure);
                assert!((inner.stress_axial - s.stress_axial).abs() < 1e-9 * pressure);
                // Half a tube: int sigma_22 dr = P r_in (nothing outside), by the trapezoid rule.
                let hoop: f64 = f
                    .windows(2)
                    .map(|p| {
                        0.5 * (p[0].stress_hoop + p[1].stress_hoop) * (p[1].radius - p[0].radius)
                    })
                    .sum();
                let balance = pressure * inner.radius;
                assert!(
                    (hoop - balance).abs() < 1e-6 * balance,
                    "{hoop} vs {balance}"
                );
            }
        }
    }
}
