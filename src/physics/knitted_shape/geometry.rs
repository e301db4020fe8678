//! The discretized sleeve: segment lengths and volumes with their derivatives (eq. 1.17-1.18).

// `!(x > y)` is deliberate: it also rejects NaN. Index loops walk several coupled arrays.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]
use std::f64::consts::PI;

/// Most axial segments accepted: the section 1.4 prototype's 49 rows at 32 segments each
/// (1,568), rounded up. The table's cost grows about linearly (0.04 s of CPU at 1,568 segments),
/// but finer sleeves reach the eq. 1.17 limit at the clamps before free contraction.
pub const MAX_SEGMENTS: usize = 1600;

/// Most axial segments per row accepted: finer, the segments at the clamps turn radial (eq. 1.17:
/// the slant is all radius step) before free contraction, so the table ends with tension left
/// (measured on the prototype at 32 segments per row, and on random sleeves at 50-80).
pub const MAX_SEGMENTS_PER_ROW: f64 = 32.0;

/// Most rows accepted (see [`ShapeGeometry::new`]).
pub const MAX_ROWS: f64 = 200.0;

/// Most rows per axial segment accepted (see [`ShapeGeometry::new`]).
pub const MAX_ROWS_PER_SEGMENT: f64 = 8.0;

/// Geometry of the discretized sleeve. All lengths in metres.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapeGeometry {
    /// Stitches per row `m`.
    pub stitches_per_row: f64,
    /// Rows `n` of the real sleeve.
    pub rows: f64,
    /// Strand length in one row `S_row` (m).
    pub row_strand_length: f64,
    /// Radius of the clamped ends and the floor of every ring (m), eq. 1.16.
    pub min_radius: f64,
    /// Number of axial segments of the discretization (>= 2).
    pub segments: usize,
}

impl ShapeGeometry {
    /// Validates the geometry: the clamped radius must be positive (the pocket nucleates from it)
    /// and leave strand for a positive stitch height.
    pub fn new(
        stitches_per_row: f64,
        rows: f64,
        row_strand_length: f64,
        min_radius: f64,
        segments: usize,
    ) -> Result<Self, String> {
        if !(stitches_per_row.is_finite() && stitches_per_row >= 1.0) {
            return Err(format!(
                "stitches_per_row must be finite and at least 1, got {stitches_per_row}"
            ));
        }
        if !(rows.is_finite() && rows >= 1.0) {
            return Err(format!("rows must be finite and at least 1, got {rows}"));
        }
        if !(row_strand_length.is_finite() && row_strand_length > 0.0) {
            return Err(format!(
                "row_strand_length must be positive and finite, got {row_strand_length} m"
            ));
        }
        if !(min_radius.is_finite() && min_radius > 0.0) {
            return Err(format!(
                "the non-cylindrical shape needs a positive minimum radius (strand_thickness or \
                 bladder radius), got {min_radius} m"
            ));
        }
        if 2.0 * PI * min_radius >= row_strand_length {
            return Err(format!(
                "minimum circumference 2 pi r_min = {} m leaves no strand for stitch height \
                 (row_strand_length {row_strand_length} m)",
                2.0 * PI * min_radius
            ));
        }
        if !(2..=MAX_SEGMENTS).contains(&segments) {
            return Err(format!(
                "segments must be in 2..={MAX_SEGMENTS}, got {segments}: finer than about 32 \
                 segments per row, the segments at the clamps turn radial (eq. 1.17 slant \
                 length all radius step) before free contraction and the table would end \
                 short of zero force"
            ));
        }
        if segments as f64 > MAX_SEGMENTS_PER_ROW * rows {
            return Err(format!(
                "shape_segments = {segments} on rows = {rows} is {} segments per row; finer than \
                 {MAX_SEGMENTS_PER_ROW} per row, the segments at the clamps turn radial (eq. 1.17 \
                 slant length all radius step) before free contraction and the table would end \
                 short of zero force: set shape_segments to at most {}",
                segments as f64 / rows,
                ((MAX_SEGMENTS_PER_ROW * rows).floor() as usize).max(2)
            ));
        }
        // The table's solver resolves the contraction pocket ring by ring: its cost grows
        // faster than the square of the rows (at 49 segments 7 ms at 196 rows, 0.23 s at 784,
        // 2.3 s at 1,568), so longer sleeves and coarser discretizations are refused rather
        // than left to run.
        if rows > MAX_ROWS {
            return Err(format!(
                "rows = {rows}: the non-cylindrical shape's table is built in bounded time for at \
                 most {MAX_ROWS} rows; use shape_model 1 (tubular) for a longer sleeve"
            ));
        }
        if rows > MAX_ROWS_PER_SEGMENT * segments as f64 {
            return Err(format!(
                "rows = {rows} on shape_segments = {segments} is {} rows per segment; the \
                 non-cylindrical shape needs at most {MAX_ROWS_PER_SEGMENT}: set shape_segments \
                 to at least {} (at most {MAX_SEGMENTS}), or use shape_model 1",
                rows / segments as f64,
                (rows / MAX_ROWS_PER_SEGMENT).ceil()
            ));
        }
        Ok(Self {
            stitches_per_row,
            rows,
            row_strand_length,
            min_radius,
            segments,
        })
    }

    /// Rows per segment `k`.
    #[inline]
    pub(super) fn rows_per_segment(&self) -> f64 {
        self.rows / self.segments as f64
    }

    /// Stitch height of a row of radius `r`, eq. 1.4: `h = (S_row - 2 pi r) / (2m)`.
    #[inline]
    pub fn stitch_height(&self, radius: f64) -> f64 {
        (self.row_strand_length - 2.0 * PI * radius) / (2.0 * self.stitches_per_row)
    }

    /// Full extension: every ring at the minimum radius, `L = n h(r_min)`.
    pub fn max_length(&self) -> f64 {
        self.rows * self.stitch_height(self.min_radius)
    }

    /// Slope of a segment's slant length with either end radius, `-k pi / (2m)`.
    #[inline]
    pub(super) fn slant_slope(&self) -> f64 {
        -self.rows_per_segment() * PI / (2.0 * self.stitches_per_row)
    }

    /// Largest radius a ring may take: half the strand circumference (zero stitch height).
    #[inline]
    pub(super) fn radius_ceiling(&self) -> f64 {
        self.row_strand_length / (2.0 * PI)
    }

    /// One segment's axial length and volume with their first and second derivatives.
    /// `None` if the segment cannot close (slant shorter than the radius step).
    #[inline]
    pub(super) fn segment(&self, a: f64, b: f64) -> Option<Segment> {
        self.segment_constants().segment(a, b)
    }

    /// The sleeve's constants of [`ShapeGeometry::segment`], for the loops over all rings.
    #[inline]
    pub(super) fn segment_constants(&self) -> SegmentConstants {
        SegmentConstants {
            rows_per_segment: self.rows_per_segment(),
            slant_slope: self.slant_slope(),
            row_strand_length: self.row_strand_length,
            two_m: 2.0 * self.stitches_per_row,
        }
    }

    /// Total axial length and volume of a ring profile.
    pub fn length_and_volume(&self, radii: &[f64]) -> Option<(f64, f64)> {
        let k = self.segment_constants();
        // Every segment between two rings on the floor is the same one.
        let r_min = self.min_radius;
        let floor = k.segment(r_min, r_min);
        let mut l = 0.0;
        let mut v = 0.0;
        for pair in radii.windows(2) {
            let seg = match floor {
                Some(floor) if pair[0] == r_min && pair[1] == r_min => floor,
                _ => k.segment(pair[0], pair[1])?,
            };
            l += seg.l;
            v += seg.v;
        }
        Some((l, v))
    }

    /// Gradients of length and volume with each interior ring (eq. 1.19 and 1.20: a ring's
    /// segment and the following one). Entries for the clamped end rings are zero.
    pub(super) fn gradients(
        &self,
        radii: &[f64],
        dl: &mut [f64],
        dv: &mut [f64],
    ) -> Option<(f64, f64)> {
        let rings = radii.len();
        dl.iter_mut().for_each(|x| *x = 0.0);
        dv.iter_mut().for_each(|x| *x = 0.0);
        let k = self.segment_constants();
        let (mut l, mut v) = (0.0, 0.0);
        for i in 1..rings {
            let seg = k.segment(radii[i - 1], radii[i])?;
            l += seg.l;
            v += seg.v;
            if i - 1 > 0 {
                dl[i - 1] += seg.la;
                dv[i - 1] += seg.va;
            }
            if i < rings - 1 {
                dl[i] += seg.lb;
                dv[i] += seg.vb;
            }
        }
        Some((l, v))
    }
}

/// Axial length `l` and volume `v` of one segment with derivatives in its end radii `a`, `b`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Segment {
    pub(super) l: f64,
    pub(super) la: f64,
    pub(super) lb: f64,
    pub(super) laa: f64,
    pub(super) lbb: f64,
    pub(super) lab: f64,
    pub(super) v: f64,
    pub(super) va: f64,
    pub(super) vb: f64,
    pub(super) vaa: f64,
    pub(super) vbb: f64,
    pub(super) vab: f64,
}

/// What [`ShapeGeometry::segment`] needs of the sleeve, computed once per sweep over the rings:
/// the segment is evaluated per ring in every Newton iteration, and these divisions were a large
/// share of its cost.
#[derive(Clone, Copy, Debug)]
pub(super) struct SegmentConstants {
    rows_per_segment: f64,
    slant_slope: f64,
    row_strand_length: f64,
    two_m: f64,
}

impl SegmentConstants {
    /// [`ShapeGeometry::segment`].
    #[inline(always)]
    pub(super) fn segment(&self, a: f64, b: f64) -> Option<Segment> {
        let sig = self.slant_slope;
        // `k h(r)` at the mean radius, eq. 1.4, operation for operation as
        // `ShapeGeometry::stitch_height` computes it: on thin strands the path's choice among
        // nearly equal maxima follows the last bits of these values.
        let s = self.rows_per_segment
            * ((self.row_strand_length - 2.0 * PI * (0.5 * (a + b))) / self.two_m);
        let d = b - a;
        let w = s * s - d * d;
        if !(s > 0.0 && w > 1e-300 * s * s + f64::MIN_POSITIVE) {
            return None;
        }
        let l = w.sqrt();
        // W = s^2 - d^2; L = sqrt(W); derivatives of W with a and b.
        let wa = 2.0 * (s * sig + d);
        let wb = 2.0 * (s * sig - d);
        let waa = 2.0 * (sig * sig - 1.0);
        let wbb = waa;
        let wab = 2.0 * (sig * sig + 1.0);
        // Two divisions instead of eight: the segment is evaluated per ring in every Newton
        // iteration, and divisions were most of its cost.
        let half_inv = 0.5 / l;
        let inv_l3 = half_inv / (2.0 * w);
        let la = wa * half_inv;
        let lb = wb * half_inv;
        let laa = waa * half_inv - wa * wa * inv_l3;
        let lbb = wbb * half_inv - wb * wb * inv_l3;
        let lab = wab * half_inv - wa * wb * inv_l3;
        // V = Q L with the cone factor Q = pi/3 (a^2 + ab + b^2).
        let c = PI / 3.0;
        let q = c * (a * a + a * b + b * b);
        let qa = c * (2.0 * a + b);
        let qb = c * (a + 2.0 * b);
        let (qaa, qbb, qab) = (2.0 * c, 2.0 * c, c);
        Some(Segment {
            l,
            la,
            lb,
            laa,
            lbb,
            lab,
            v: q * l,
            va: qa * l + q * la,
            vb: qb * l + q * lb,
            vaa: qaa * l + 2.0 * qa * la + q * laa,
            vbb: qbb * l + 2.0 * qb * lb + q * lbb,
            vab: qab * l + qa * lb + qb * la + q * lab,
        })
    }
}
