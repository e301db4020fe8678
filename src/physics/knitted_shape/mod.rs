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
//!
//! Which maximum, where several exist: the table follows one by continuation. With `lambda =
//! dV/dL` the KKT conditions are `dV/dr_j = lambda dL/dr_j` on the free rings (eq. 1.19-1.20),
//! and a maximum also has a negative definite Hessian of `V - lambda L` on the moves that keep
//! `L` (the bordered KKT matrix has exactly one positive eigenvalue). A maximum is a stable
//! shape of the quasi-static muscle (section 1.3.5: the fluid leads it to the least potential
//! energy at the given length), so as the length shortens the sleeve stays on it while it
//! exists; the path does the same from the tangent predictor. The start decides the branch:
//! just below full extension the pocket and uniform-raise seeds are each solved (the latter by
//! the fast path only, where the pocket is found), and the path starts on the one of greater
//! volume (the pocket on a tie); where that is a mirror-symmetric pair of pockets, a
//! saddle (moving length from one pocket to the other gains volume, the pocket's cone of eq.
//! 1.18 being convex in the length it takes up at first), one pocket of the pair is solved alone
//! and taken where it holds more (its mirror image holds the same volume and gives the same
//! table). Where the followed maximum ends before zero force (a fold, or a ring reaching the
//! ceiling), the path takes the maximum its fallbacks reach (the robust solve, an added pocket).
//!
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
