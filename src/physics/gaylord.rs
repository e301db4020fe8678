//! Ideal McKibben sleeve: the volume potential-energy (Gaylord) model, dissertation section 2.2.1.
//!
//! A strand of fixed length `b` makes `n` turns around the cylinder at angle theta to its axis, so
//! `L = b cos(theta)` and `D = b sin(theta) / (n pi)`. Strands and bladder have no thickness.

use crate::physics::bladder::SleeveGeometry;
use std::f64::consts::PI;

/// Sleeve geometry: strand length `b` (m) and turns `n`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sleeve {
    pub strand_length: f64,
    pub turns: f64,
    /// [`Sleeve::scale`], computed once: a division per evaluation otherwise.
    scale: f64,
    /// `b^2`, eq. 2.2-2.3's constant term.
    strand_length_sq: f64,
}

impl Sleeve {
    /// Checks that the geometry is physical (finite, positive).
    pub fn new(strand_length: f64, turns: f64) -> Result<Self, String> {
        if !(strand_length.is_finite() && strand_length > 0.0) {
            return Err(format!(
                "strand_length must be positive and finite, got {strand_length} m"
            ));
        }
        if !(turns.is_finite() && turns > 0.0) {
            return Err(format!("turns must be positive and finite, got {turns}"));
        }
        Ok(Self {
            strand_length,
            turns,
            scale: 1.0 / (4.0 * PI * turns * turns),
            strand_length_sq: strand_length * strand_length,
        })
    }

    /// `1 / (4 pi n^2)`, the common factor of eq. 2.2 and 2.3.
    #[inline]
    fn scale(&self) -> f64 {
        self.scale
    }

    /// Cylinder diameter at length `L`: `D = b sin(theta) / (n pi)` with `cos(theta) = L / b`.
    pub fn diameter(&self, length: f64) -> f64 {
        let b = self.strand_length;
        (b * b - length * length).max(0.0).sqrt() / (self.turns * PI)
    }

    // Eq. 2.2, 2.3 and the stiffness are grouped around the products they share, `L^2` and
    // `P / (4 pi n^2)`: evaluated together (the bare muscle's FMI step), each is computed once.

    /// Eq. 2.2: `V = (b^2 L - L^3) / (4 pi n^2)`.
    #[inline]
    pub fn volume(&self, length: f64) -> f64 {
        (length * self.scale()) * (self.strand_length_sq - length * length)
    }

    /// Eq. 2.3: `F = P (3 L^2 - b^2) / (4 pi n^2)`, tension positive; equals `-P dV/dL` (eq. 2.1).
    #[inline]
    pub fn force(&self, pressure: f64, length: f64) -> f64 {
        (pressure * self.scale()) * (3.0 * (length * length) - self.strand_length_sq)
    }

    /// `dF/dL = 6 P L / (4 pi n^2)`.
    #[inline]
    pub fn stiffness(&self, pressure: f64, length: f64) -> f64 {
        (pressure * self.scale()) * (6.0 * length)
    }

    /// The length of zero force and largest volume, `b / sqrt(3)` (57.7% of b).
    pub fn free_contraction_length(&self) -> f64 {
        self.strand_length / 3f64.sqrt()
    }

    /// The ideal sleeve's reach: its diameter vanishes at `L = b`.
    pub fn max_length(&self) -> f64 {
        self.strand_length
    }
}

/// The helical sleeve as the bladder sees it (eq. 2.2, 2.7, 2.16).
impl SleeveGeometry for Sleeve {
    #[inline]
    fn diameter_and_slope(&self, length: f64) -> (f64, f64) {
        let npi = self.turns * PI;
        let d = self.diameter(length);
        // D = sqrt(b^2 - L^2)/(n pi)  =>  dD/dL = -L / ((n pi)^2 D); d > 0 inside the range.
        (d, -length / (npi * npi * d))
    }
    #[inline]
    fn diameter_sq(&self, length: f64) -> f64 {
        let (b, n) = (self.strand_length, self.turns);
        (b * b - length * length) / (n * n * PI * PI)
    }
    #[inline]
    fn strand_area(&self, length: f64) -> (f64, f64) {
        // pi/4 (b^2 - L^2)/(n pi)^2 - (b^2 - 3 L^2)/(4 pi n^2) = L^2 / (2 pi n^2) (eq. 2.16).
        let k = 1.0 / (2.0 * PI * self.turns * self.turns);
        (length * length * k, 2.0 * length * k)
    }
    fn curvatures(&self, length: f64) -> (f64, f64) {
        // D^2 = (b^2 - L^2)/(n pi)^2: D D'' = (D^2)''/2 - D'^2; strand area L^2 / (2 pi n^2).
        let npi_sq = (self.turns * PI).powi(2);
        let (d, slope) = self.diameter_and_slope(length);
        (
            (-1.0 / npi_sq - slope * slope) / d,
            1.0 / (PI * self.turns * self.turns),
        )
    }
    fn fill_lengths(&self, rubber_volume: f64) -> Option<(f64, f64)> {
        rubber_fill_lengths(self, rubber_volume)
    }
    fn largest_volume(&self) -> f64 {
        self.volume(self.free_contraction_length())
    }
}

/// The two positive roots of `L^3 - b^2 L + 4 pi n^2 V_R = 0` (eq. 2.7's inner diameter is zero),
/// by the trigonometric formula and two Newton polishes; `None` if the rubber never fits.
fn rubber_fill_lengths(sleeve: &Sleeve, rubber_volume: f64) -> Option<(f64, f64)> {
    let b = sleeve.strand_length;
    let n = sleeve.turns;
    let q = 4.0 * PI * n * n * rubber_volume;
    let p = -b * b;
    // Three real roots iff 4 p^3 + 27 q^2 < 0.
    if 4.0 * p * p * p + 27.0 * q * q >= 0.0 {
        return None;
    }
    let m = 2.0 * (-p / 3.0).sqrt();
    let phi = ((3.0 * q / (p * m)).clamp(-1.0, 1.0)).acos() / 3.0;
    let root = |k: f64| m * (phi - 2.0 * PI * k / 3.0).cos();
    let polish = |mut l: f64| {
        for _ in 0..2 {
            let f = l * l * l + p * l + q;
            let df = 3.0 * l * l + p;
            if df != 0.0 {
                l -= f / df;
            }
        }
        l
    };
    let max = polish(root(0.0));
    let min = polish(root(1.0));
    (min > 0.0 && max > min && max < b).then_some((min, max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Table 2.1, muscle A.
    fn muscle_a() -> Sleeve {
        Sleeve::new(0.1113, 3.74).unwrap()
    }

    #[test]
    fn force_is_minus_pressure_times_volume_slope() {
        // Eq. 2.1 with eq. 2.2 must give eq. 2.3: check by central differences.
        let s = muscle_a();
        let p = 4.0e5;
        for i in 1..100 {
            let l = s.strand_length * i as f64 / 100.0;
            let h = 1e-7;
            let dv = (s.volume(l + h) - s.volume(l - h)) / (2.0 * h);
            assert_relative_eq!(s.force(p, l), -p * dv, max_relative = 1e-6, epsilon = 1e-9);
            let df = (s.force(p, l + h) - s.force(p, l - h)) / (2.0 * h);
            assert_relative_eq!(s.stiffness(p, l), df, max_relative = 1e-6);
        }
    }

    #[test]
    fn zero_force_at_largest_volume() {
        let s = muscle_a();
        let l0 = s.free_contraction_length();
        assert_relative_eq!(l0 / s.strand_length, 0.57735, max_relative = 1e-5);
        assert!(s.force(6e5, l0).abs() < 1e-12);
        assert!(s.volume(l0) > s.volume(l0 * 0.99) && s.volume(l0) > s.volume(l0 * 1.01));
    }

    #[test]
    fn volume_is_the_sleeve_cylinder() {
        let s = muscle_a();
        let l = 0.09;
        let d = s.diameter(l);
        assert_relative_eq!(s.volume(l), PI * d * d / 4.0 * l, max_relative = 1e-12);
        assert_eq!(s.diameter(s.max_length()), 0.0);
    }

    #[test]
    fn peak_force_at_full_length() {
        // At L = b: F = 2 P b^2 / (4 pi n^2), the normalisation of Fig. 2.3.
        let s = muscle_a();
        let f = s.force(1e5, s.strand_length);
        assert_relative_eq!(
            f,
            2.0 * 1e5 * 0.1113f64.powi(2) / (4.0 * PI * 3.74f64.powi(2)),
            max_relative = 1e-12
        );
        // About 14 N per 100 kPa for muscle A.
        assert!((f - 14.09).abs() < 0.01, "{f}");
    }

    #[test]
    fn rejects_unphysical_geometry() {
        assert!(Sleeve::new(0.0, 3.0).is_err());
        assert!(Sleeve::new(0.1, -1.0).is_err());
        assert!(Sleeve::new(f64::NAN, 3.0).is_err());
        assert!(Sleeve::new(0.1, f64::INFINITY).is_err());
    }
}
