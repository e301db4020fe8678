//! Length derivatives of the table's interpolants beyond those it stores, for the KnittedMuscle
//! FMU's exact partials: the derivative of the interpolant the model evaluates, not of the
//! underlying shape.

use super::ShapeTable;

impl ShapeTable {
    /// `d3V/dL3` of the quintic Hermite interpolant of [`ShapeTable::evaluate`] (m^0), on the
    /// interval it evaluates at `length`.
    pub fn volume_third_derivative(&self, length: f64) -> f64 {
        if self.volume.len() < 2 {
            return 0.0;
        }
        let (i, t) = self.locate(length);
        let h = -self.spacing;
        let delta = self.volume[i + 1] - self.volume[i];
        let (d0, d1) = (h * self.slope[i], h * self.slope[i + 1]);
        let (a0, a1) = (h * h * self.curvature[i], h * h * self.curvature[i + 1]);
        let c3 = 10.0 * delta - 6.0 * d0 - 4.0 * d1 - 1.5 * a0 + 0.5 * a1;
        let c4 = -15.0 * delta + 8.0 * d0 + 7.0 * d1 + 1.5 * a0 - a1;
        let c5 = 6.0 * delta - 3.0 * d0 - 3.0 * d1 - 0.5 * a0 + 0.5 * a1;
        (6.0 * c3 + t * (24.0 * c4 + t * 60.0 * c5)) / (h * h * h)
    }

    /// `d(max_radius)/dL` of the linear interpolant of [`ShapeTable::max_radius`], on the interval
    /// it evaluates at `length` (at a node, the interval towards shorter lengths).
    pub fn max_radius_slope(&self, length: f64) -> f64 {
        if self.max_radius.len() < 2 || self.spacing <= 0.0 || self.spacing.is_nan() {
            return 0.0;
        }
        let (i, _) = self.locate(length);
        // t = (max_length - L) / spacing - i, so dt/dL = -1/spacing.
        -(self.max_radius[i + 1] - self.max_radius[i]) / self.spacing
    }
}
