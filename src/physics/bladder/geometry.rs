//! The sleeve as the bladder sees it (eq. 2.7, 2.16), and the helical McKibben sleeve's case.

use crate::physics::gaylord::Sleeve;
use std::f64::consts::PI;

/// A cylindrical sleeve as the bladder sees it: diameter `D(L)`, the strand factor `A - dV/dL`
/// of eq. 2.16, and where the rubber fits (eq. 2.7). Implemented by the helical McKibben sleeve
/// ([`Sleeve`]) and the knitted cylinders ([`KnittedCylinder`](super::KnittedCylinder)).
pub trait SleeveGeometry {
    /// `(D, dD/dL)` at `length` inside the bladder's range, m and m/m.
    fn diameter_and_slope(&self, length: f64) -> (f64, f64);
    /// `D(L)^2`, m^2 (may be negative outside the sleeve's geometry).
    fn diameter_sq(&self, length: f64) -> f64;
    /// `(A - dV/dL, d/dL of it)` with `A = pi D^2/4`, m^2 and m: the strand force per unit
    /// effective pressure (eq. 2.16 generalised).
    fn strand_area(&self, length: f64) -> (f64, f64);
    /// `(d2D/dL2, d2(A - dV/dL)/dL2)` at `length`, 1/m and 1: the second derivatives the
    /// partials of the stiffness need.
    fn curvatures(&self, length: f64) -> (f64, f64);
    /// `(min, max)` lengths, m, between which the rubber of volume `V_R` fits the sleeve (eq. 2.7's
    /// inner diameter is positive) and the sleeve itself is valid; `None` if nowhere.
    fn fill_lengths(&self, rubber_volume: f64) -> Option<(f64, f64)>;
    /// The largest volume the sleeve encloses, m^3 (for error messages).
    fn largest_volume(&self) -> f64;
}

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
        fill_lengths(self, rubber_volume)
    }
    fn largest_volume(&self) -> f64 {
        self.volume(self.free_contraction_length())
    }
}

/// The two positive roots of `L^3 - b^2 L + 4 pi n^2 V_R = 0` (eq. 2.7's inner diameter is zero),
/// by the trigonometric formula and two Newton polishes; `None` if the rubber never fits.
fn fill_lengths(sleeve: &Sleeve, rubber_volume: f64) -> Option<(f64, f64)> {
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
