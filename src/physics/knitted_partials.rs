//! Length derivatives of the knitted sleeve beyond [`KnittedSleeve::volume_derivatives`], for the
//! KnittedMuscle FMU's exact partials: `d3V/dL3` (the length slope of the stiffness `-P V''`) and
//! the slope of the largest radius (eq. 1.5, 1.12, or the table's interpolant).

use crate::physics::knitted::{KnittedSleeve, ShapeModel};
use std::f64::consts::PI;

impl KnittedSleeve {
    /// `d3V/dL3` at the (clamped) length: eq. 1.6 and 1.13 differentiated three times, or the
    /// table interpolant's.
    pub fn volume_third_derivative(&self, length: f64) -> f64 {
        let l = self.clamp_length(length);
        let p = self.params();
        let (m, n) = (p.stitches_per_row, p.rows);
        match self.shape() {
            ShapeModel::Ideal => 6.0 * m * m / (PI * n * n),
            ShapeModel::Tubular => 6.0 * (4.0 * m * m - 1.0) / (n * n) / (4.0 * PI),
            ShapeModel::NonCylindrical(table) => table.volume_third_derivative(l),
        }
    }

    /// `d(max_radius)/dL` at the (clamped) length; zero where the radius sits at its minimum
    /// (the branch [`KnittedSleeve::max_radius`] takes there).
    pub fn max_radius_slope(&self, length: f64) -> f64 {
        let l = self.clamp_length(length);
        if self.max_radius(l) <= self.min_radius() {
            return 0.0;
        }
        let p = self.params();
        let (m, n, s) = (p.stitches_per_row, p.rows, p.row_strand_length);
        let h = l / n;
        match self.shape() {
            // Eq. 1.5: r = (S - 2 m h) / (2 pi).
            ShapeModel::Ideal => -m / (PI * n),
            // Eq. 1.12: r = sqrt(q) / (2 pi), q = S^2 - 4 m h S + (4 m^2 - 1) h^2.
            ShapeModel::Tubular => {
                let q = s * s - 4.0 * m * h * s + (4.0 * m * m - 1.0) * h * h;
                if q > 0.0 {
                    (-4.0 * m * s + 2.0 * (4.0 * m * m - 1.0) * h) / (4.0 * PI * q.sqrt() * n)
                } else {
                    0.0
                }
            }
            ShapeModel::NonCylindrical(table) => table.max_radius_slope(l),
        }
    }
}
