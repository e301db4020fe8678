//! The sleeve as the bladder sees it (eq. 2.7, 2.16). The sleeves implement it beside their own
//! geometry, so that the bladder names none of them.

/// A cylindrical sleeve as the bladder sees it: diameter `D(L)`, the strand factor `A - dV/dL`
/// of eq. 2.16, and where the rubber fits (eq. 2.7). Implemented by the helical McKibben sleeve
/// ([`Sleeve`](crate::physics::gaylord::Sleeve)) and the knitted cylinders
/// ([`KnittedCylinder`](crate::physics::knitted_cylinder::KnittedCylinder)).
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
