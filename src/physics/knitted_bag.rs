//! The section 1.4 prototype's bladder: a thin polyethylene bag of about 85 mm diameter inside a
//! 153 mm sleeve. The bag is flexible (it folds, so it neither resists length changes nor carries
//! end-cap load) but inextensible in hoop: the fluid can fill the sleeve only up to the bag's
//! radius. For the cylindrical sleeves the pressurized volume is therefore
//! `V(L) = min(V_sleeve(L), pi R^2 L)`, and the tension stays `F = -P dV/dL` (the virtual work of
//! eq. 1.8). Where the bag binds, `F = -P pi R^2` pushes the clamps apart, so the free contraction
//! stops where the sleeve's radius equals the bag's, `L = n (S_row - 2 pi R) / (2 m)` for the ideal
//! sleeve (eq. 1.4).
//!
//! Stretching, as an option: a linear membrane of hoop stiffness `E t` (N/m) grows to
//! `R = R0 (1 + P R0 / (E t))` (thin-wall hoop strain `P R / (E t)` at small strain). It is the
//! explanation section 1.4.2 offers for the stroke's growth with pressure.

use crate::physics::knitted::{FluidContainer, KnittedSleeve};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bag {
    /// Relaxed radius (m).
    pub radius: f64,
    /// Hoop membrane stiffness `E t` (N/m); infinite for an inextensible bag.
    pub membrane_stiffness: f64,
}

impl Bag {
    /// `diameter` (m) > 0; `membrane_stiffness` (N/m) > 0, or 0 for inextensible.
    pub fn new(diameter: f64, membrane_stiffness: f64) -> Result<Self, String> {
        if !(diameter > 0.0 && diameter <= 1e3) {
            return Err(format!(
                "bag_diameter must be positive and at most 1000 m, got {diameter} m"
            ));
        }
        if !(membrane_stiffness.is_finite() && membrane_stiffness >= 0.0) {
            return Err(format!(
                "bag_membrane_stiffness must be finite and non-negative (0 = inextensible), got \
                 {membrane_stiffness} N/m"
            ));
        }
        Ok(Self {
            radius: 0.5 * diameter,
            membrane_stiffness: if membrane_stiffness == 0.0 {
                f64::INFINITY
            } else {
                membrane_stiffness
            },
        })
    }

    /// Radius at gauge pressure `pressure` (Pa): the relaxed one for a vacuum or an inextensible
    /// bag.
    pub fn radius_at(&self, pressure: f64) -> f64 {
        self.radius * (1.0 + pressure.max(0.0) * self.radius / self.membrane_stiffness)
    }

    /// `dR/dP` at gauge pressure `pressure` (Pa), m/Pa: `R0^2 / (E t)` above zero, zero for a
    /// vacuum (the branch [`Self::radius_at`] takes at zero) or an inextensible bag.
    pub fn radius_slope(&self, pressure: f64) -> f64 {
        if pressure > 0.0 {
            self.radius * self.radius / self.membrane_stiffness
        } else {
            0.0
        }
    }

    /// `(V, dV/dL, d2V/dL2)` of the fluid at `pressure` (Pa): the sleeve's, capped at the bag's
    /// cylinder `pi R^2 L`.
    pub fn volume_derivatives(
        &self,
        sleeve: &KnittedSleeve,
        pressure: f64,
        length: f64,
    ) -> (f64, f64, f64) {
        let l = sleeve.clamp_length(length);
        let sleeve_volume = sleeve.volume_derivatives(l);
        let r = self.radius_at(pressure);
        let area = PI * r * r;
        if area * l < sleeve_volume.0 {
            (area * l, area, 0.0)
        } else {
            sleeve_volume
        }
    }

    /// Shortest length at which the sleeve's radius fits inside the bag (m): below it the bag
    /// binds (the free contraction cannot pass it).
    pub fn binding_length(&self, sleeve: &KnittedSleeve, pressure: f64) -> f64 {
        let r = self.radius_at(pressure);
        let (mut lo, mut hi) = (sleeve.min_length(), sleeve.max_length());
        if sleeve.max_radius(lo) <= r {
            return lo;
        }
        // max_radius falls with length on the cylinders.
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if sleeve.max_radius(mid) > r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }
}

impl FluidContainer for Bag {
    fn volume_derivatives(&self, sleeve: &KnittedSleeve, pressure: f64, l: f64) -> (f64, f64, f64) {
        Bag::volume_derivatives(self, sleeve, pressure, l)
    }
    fn radius_at(&self, pressure: f64) -> f64 {
        Bag::radius_at(self, pressure)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::knitted::{KnittedParams, ShapeKind};
    use approx::assert_relative_eq;

    #[test]
    fn the_85_mm_bag_stops_the_prototype_where_the_sleeve_reaches_its_radius() {
        let sleeve = KnittedSleeve::new(KnittedParams::prototype(), ShapeKind::Ideal).unwrap();
        let bag = Bag::new(0.085, 0.0).unwrap();
        let p = KnittedParams::prototype();
        // Eq. 1.4: 2 pi R = S_row - 2 m L / n.
        let expected =
            p.rows * (p.row_strand_length - 2.0 * PI * 0.0425) / (2.0 * p.stitches_per_row);
        let l = bag.binding_length(&sleeve, 14e3);
        assert_relative_eq!(l, expected, max_relative = 1e-12);
        // 53.7% stroke of the 514 mm prototype, whatever the pressure, above the ideal third.
        assert!((1.0 - l / sleeve.max_length() - 0.537).abs() < 0.001, "{l}");
        for pressure in [14e3, 100e3] {
            let f = |l: f64| -pressure * bag.volume_derivatives(&sleeve, pressure, l).1;
            assert!(f(l * 1.001) > 0.0 && f(l * 0.999) < 0.0);
            assert_relative_eq!(
                f(0.5 * l),
                -pressure * PI * 0.0425f64.powi(2),
                max_relative = 1e-12
            );
            // Longer than the binding length the sleeve alone sets the volume.
            assert_eq!(
                bag.volume_derivatives(&sleeve, pressure, 0.4),
                sleeve.volume_derivatives(0.4)
            );
        }
    }

    #[test]
    fn a_stretching_bag_grows_with_pressure_and_lengthens_the_stroke() {
        let sleeve = KnittedSleeve::new(KnittedParams::prototype(), ShapeKind::Ideal).unwrap();
        // 50 um polyethylene, E ~ 0.2 GPa: E t = 1e4 N/m.
        let bag = Bag::new(0.085, 1e4).unwrap();
        assert_relative_eq!(bag.radius_at(14e3), 0.0425 * (1.0 + 14e3 * 0.0425 / 1e4));
        assert_eq!(bag.radius_at(-5e3), 0.0425);
        assert!(bag.binding_length(&sleeve, 100e3) < bag.binding_length(&sleeve, 14e3));
        assert!(Bag::new(0.0, 0.0).is_err() && Bag::new(0.085, -1.0).is_err());
        assert!(Bag::new(f64::NAN, 0.0).is_err());
    }
}
