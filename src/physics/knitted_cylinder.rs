//! The cylindrical knitted sleeves of chapter 1 as the bladder sees them (section 1.3.6).

use crate::physics::bladder::{Bladder, BladderTube, SleeveGeometry, Wall};
use crate::physics::knitted::{KnittedSleeve, ShapeModel};
use std::f64::consts::PI;

/// Iteration cap of the bisection for the knitted sleeve's fill lengths (at initialization only;
/// 200 halvings reach any f64 bracket).
const FILL_BISECTIONS: usize = 200;

/// A cylindrical knitted sleeve (chapter 1, `shape_model` 0 ideal, eq. 1.5-1.8, or 1 tubular knit,
/// eq. 1.11-1.14) as the bladder sees it. For both, `D^2` is a quadratic in `L`:
/// ideal `pi^2 D^2 = (S - 2 m L/n)^2` (eq. 1.5), tubular `pi^2 D^2 = S^2 - 4 m S L/n +
/// (4 m^2 - 1) L^2/n^2` (eq. 1.12), and the volume is exactly `pi D^2 L / 4` (eq. 1.6, 1.13), so
/// `A - dV/dL = -L dA/dL`. The sleeve's own length range (strand thickness, eq. 1.16) is kept.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KnittedCylinder {
    /// `D^2 = d_sq[0] + d_sq[1] L + d_sq[2] L^2`, m^2.
    d_sq: [f64; 3],
    /// The sleeve's shortest valid length (`2 n t`), m.
    sleeve_min_length: f64,
    /// The sleeve's full extension (radius `r_min`, eq. 1.16), m.
    sleeve_max_length: f64,
}

/// Why a bladder is refused in the non-cylindrical sleeve (see [`KnittedCylinder::new`]).
pub const NON_CYLINDRICAL_BLADDER: &str = "the hyperelastic bladder (section 1.3.6 with eq. \
     2.6-2.20) needs a cylindrical sleeve: use shape_model 0 (ideal) or 1 (tubular knit); the \
     non-cylindrical shape has no single bladder diameter";

impl KnittedCylinder {
    /// The cylinder of a built knitted sleeve. `Err` for the non-cylindrical shape (eq. 1.17-1.20):
    /// its rows have different radii (clamped ends, a pocket), so there is no single bladder
    /// diameter for eq. 2.7 / 2.20 and no single `P_eff`; a mean-area stand-in would be a number
    /// with no derivation behind it, so it is refused rather than approximated.
    pub fn new(sleeve: &KnittedSleeve) -> Result<Self, String> {
        let p = sleeve.params();
        let (m, n, s) = (p.stitches_per_row, p.rows, p.row_strand_length);
        let pi_sq = PI * PI;
        let quadratic = match sleeve.shape() {
            ShapeModel::Ideal => 4.0 * m * m,
            ShapeModel::Tubular => 4.0 * m * m - 1.0,
            ShapeModel::NonCylindrical(_) => return Err(NON_CYLINDRICAL_BLADDER.into()),
        };
        let d_sq = [
            s * s / pi_sq,
            -4.0 * m * s / (n * pi_sq),
            quadratic / (n * n * pi_sq),
        ];
        Ok(Self {
            d_sq,
            sleeve_min_length: sleeve.min_length(),
            sleeve_max_length: sleeve.max_length(),
        })
    }

    /// `pi/4 L D^2 - V_R`: sleeve volume minus rubber volume, m^3.
    #[inline]
    fn spare_volume(&self, length: f64, rubber_volume: f64) -> f64 {
        PI / 4.0 * length * self.diameter_sq(length) - rubber_volume
    }

    /// Length of largest sleeve volume: the smaller root of `d(L D^2)/dL = 0`, in the sleeve's range.
    fn largest_volume_length(&self) -> f64 {
        let [c0, c1, c2] = self.d_sq;
        let disc = c1 * c1 - 3.0 * c2 * c0;
        let l = if c2 > 0.0 && disc >= 0.0 {
            (-c1 - disc.sqrt()) / (3.0 * c2)
        } else {
            self.sleeve_max_length
        };
        if l.is_finite() {
            crate::physics::numerics::bounds::limit(
                l,
                self.sleeve_min_length,
                self.sleeve_max_length,
            )
        } else {
            self.sleeve_max_length
        }
    }
}

impl Bladder<KnittedCylinder> {
    /// The bladder inside a cylindrical knitted sleeve (section 1.3.6); `Err` for the
    /// non-cylindrical shape (see [`KnittedCylinder::new`]) or a tube that does not fit. The
    /// length range is the sleeve's own (strand thickness) intersected with where the rubber fits.
    pub fn knitted(
        sleeve: &KnittedSleeve,
        tube: BladderTube,
        layers: usize,
    ) -> Result<Self, String> {
        Self::dissertation_layers(KnittedCylinder::new(sleeve)?, tube, layers)
    }

    /// As [`Self::knitted`] with any [`Wall`].
    pub fn knitted_wall(
        sleeve: &KnittedSleeve,
        tube: BladderTube,
        wall: Wall,
    ) -> Result<Self, String> {
        Self::with_wall(KnittedCylinder::new(sleeve)?, tube, wall)
    }
}

impl SleeveGeometry for KnittedCylinder {
    #[inline]
    fn diameter_and_slope(&self, length: f64) -> (f64, f64) {
        let [_, c1, c2] = self.d_sq;
        let d = self.diameter_sq(length).max(0.0).sqrt();
        (d, (c1 + 2.0 * c2 * length) / (2.0 * d))
    }
    #[inline]
    fn diameter_sq(&self, length: f64) -> f64 {
        let [c0, c1, c2] = self.d_sq;
        c0 + (c1 + c2 * length) * length
    }
    #[inline]
    fn strand_area(&self, length: f64) -> (f64, f64) {
        // A - dV/dL = -L dA/dL with dA/dL = pi/4 (c1 + 2 c2 L).
        let [_, c1, c2] = self.d_sq;
        (
            -PI / 4.0 * length * (c1 + 2.0 * c2 * length),
            -PI / 4.0 * (c1 + 4.0 * c2 * length),
        )
    }
    #[inline]
    fn curvatures(&self, length: f64) -> (f64, f64) {
        // D D'' = (D^2)''/2 - D'^2 with (D^2)'' = 2 c2; the strand area's is -pi c2.
        let c2 = self.d_sq[2];
        let (d, slope) = self.diameter_and_slope(length);
        ((c2 - slope * slope) / d, -PI * c2)
    }
    /// Bracketed bisection on the spare volume on each side of its maximum (it rises, then falls,
    /// over the sleeve's range); at initialization only. A side where the sleeve's own limit comes
    /// first keeps that limit.
    fn fill_lengths(&self, rubber_volume: f64) -> Option<(f64, f64)> {
        let peak = self.largest_volume_length();
        let f = |l: f64| self.spare_volume(l, rubber_volume);
        let spare_at_peak = f(peak);
        if spare_at_peak.is_nan() || spare_at_peak <= 0.0 {
            return None;
        }
        // Root of f between `bad` (f <= 0) and `good` (f > 0).
        let root = |mut bad: f64, mut good: f64| {
            for _ in 0..FILL_BISECTIONS {
                let mid = 0.5 * (bad + good);
                if mid == bad || mid == good {
                    break;
                }
                if f(mid) > 0.0 {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            good
        };
        let lo = self.sleeve_min_length;
        let hi = self.sleeve_max_length;
        let min = if f(lo) > 0.0 && lo > 0.0 {
            lo
        } else {
            root(lo, peak)
        };
        let max = if f(hi) > 0.0 { hi } else { root(hi, peak) };
        (min > 0.0 && max > min).then_some((min, max))
    }
    fn largest_volume(&self) -> f64 {
        let l = self.largest_volume_length();
        PI / 4.0 * l * self.diameter_sq(l)
    }
}
