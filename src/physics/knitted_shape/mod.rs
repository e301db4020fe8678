//! Non-cylindrical knitted sleeve, dissertation section 1.3.5 (eq. 1.17-1.20).
//!
//! The sleeve is cut into `segments` axial segments, each holding `rows / segments` rows of
//! stitches (one segment per row is the dissertation's own discretization). Rings `0..=segments` carry
//! the radii; the clamped end rings stay at the minimum radius. Segment `i` joins ring `i-1`
//! (radius `a`) to ring `i` (radius `b`):
//! - its slanted strand length is the rows' stitch height, `k h(r)` with `h(r) = (S_row - 2 pi r) /
//!   (2m)` from eq. 1.4 (equally eq. 1.15: the thick strand keeps `C = S_row - 2mh`), taken at the
//!   segment's mean radius so that the discrete problem is mirror-symmetric and second order;
//! - eq. 1.17: its axial length is `sqrt(s^2 - (b - a)^2)`;
//! - eq. 1.18: its volume is the truncated cone `pi/3 L (a^2 + ab + b^2)` (the dissertation's form
//!   divided through by `b - a`, which is singular for a cylinder).
//!
//! At every length the shape maximizes the volume under the strand constraint with
//! `r_min <= r <= S_row / (2 pi)` (eq. 1.1: the fluid's potential energy is least; at the
//! ceiling a row's whole strand is its circumference, eq. 1.4 with `h = 0`).
//! [`ShapeTable::build`] follows that maximum from full extension down past free contraction with Newton steps on the Karush-Kuhn-Tucker system,
//! whose Hessian is tridiagonal (eq. 1.19-1.20: a radius touches only its two segments), so a
//! step costs O(segments); the rings held at a bound are updated within each step (`newton.rs`,
//! with the slower line-searched solve of `solver.rs` as its fallback). The
//! multiplier is `dV/dL` itself, and the sensitivity of the same system gives `d2V/dL2`, so the
//! table holds exact `V`, `V'`, `V''` and is read through a quintic Hermite interpolant (C2).
//! [`seed_gradient_volume_curve`] is the dissertation's slow one-row-at-a-time gradient exchange, kept as
//! the baseline that the benchmarks and a test compare against.

mod baseline;
#[cfg(test)]
mod choice_tests;
mod geometry;
mod newton;
mod partials;
#[cfg(test)]
mod reference;
mod seeds;
mod solver;
mod table;
#[cfg(test)]
mod tests;

pub use baseline::{seed_gradient_volume_curve, SeedAlgorithmOptions};
pub use geometry::{ShapeGeometry, MAX_ROWS_PER_SEGMENT, MAX_SEGMENTS, MAX_SEGMENTS_PER_ROW};
pub use table::{ShapeTable, DEFAULT_TABLE_NODES};
