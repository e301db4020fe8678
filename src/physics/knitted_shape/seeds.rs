//! Starting shapes of the table's path: every ring raised just off the minimum radius, a small
//! centred pocket where the instability nucleates (section 1.3.5), and a copy of the highest
//! pocket where one pocket can no longer take the contraction.

use super::geometry::ShapeGeometry;
use super::solver::Solver;
use std::f64::consts::PI;

impl Solver {
    /// Places a copy of the highest pocket (a run of rings off the floor) in the middle of the
    /// longest run of interior rings on the floor, leaving a floor ring on each side of it.
    /// `false` if there is no room. On a thin strand a pocket gains volume convexly at first and
    /// its top ring meets the ceiling soon after: past that, the maximum shares the contraction
    /// among more pockets, which Newton cannot reach from one pocket (a ring on the floor has no
    /// pull until the new pocket is already large).
    pub(super) fn add_pocket(&mut self) -> bool {
        let rings = self.radii.len();
        let runs = |floor: bool| {
            let mut out: Vec<(usize, usize)> = Vec::new();
            let mut j = 1;
            while j < rings - 1 {
                if self.on_floor(j) == floor {
                    let start = j;
                    while j < rings - 1 && self.on_floor(j) == floor {
                        j += 1;
                    }
                    out.push((start, j - 1));
                } else {
                    j += 1;
                }
            }
            out
        };
        let peak = |&(a, b): &(usize, usize)| self.radii[a..=b].iter().cloned().fold(0.0, f64::max);
        let Some((a, b)) = runs(false)
            .into_iter()
            .max_by(|x, y| peak(x).total_cmp(&peak(y)))
        else {
            return false;
        };
        let width = b - a + 1;
        // The rings a new pocket may take in a floor run: all but the ends that border another
        // pocket (a clamp needs no floor ring beside it).
        let usable = |&(lo, hi): &(usize, usize)| {
            let first = if lo == 1 { lo } else { lo + 1 };
            let last = if hi == rings - 2 { hi } else { hi - 1 };
            (first, (last + 1).saturating_sub(first))
        };
        let Some((first, room)) = runs(true).iter().map(usable).max_by_key(|&(_, room)| room)
        else {
            return false;
        };
        if room < width {
            return false;
        }
        let first = first + (room - width) / 2;
        for i in 0..width {
            self.radii[first + i] = self.radii[a + i];
            self.held[first + i] = self.held[a + i];
        }
        true
    }

    /// Puts the rings of the right half on the floor: of two mirror-image pockets, the left one
    /// alone. `false` (unchanged) unless a floor ring in the middle parts two pockets.
    pub(super) fn keep_left_half(&mut self, r_min: f64) -> bool {
        let rings = self.radii.len();
        let mid = rings / 2;
        let parted = (1..mid).any(|j| !self.on_floor(j)) && self.on_floor(mid);
        if !parted {
            return false;
        }
        for j in mid..rings - 1 {
            self.radii[j] = r_min;
            self.held[j] = true;
        }
        true
    }

    /// Frees every interior ring just above the minimum radius (the dissertation's uniform raise).
    pub(super) fn seed_uniform(&mut self, geom: &ShapeGeometry) {
        let rings = self.radii.len();
        for j in 1..rings - 1 {
            self.radii[j] = geom.min_radius * (1.0 + 1e-9);
            self.held[j] = false;
        }
        self.lambda = 0.0;
    }

    /// Seeds a small centred pocket of length deficit `deficit` (section 1.3.5: the instability
    /// nucleates a pocket of finite width; near onset its profile is one period of a cosine).
    pub(super) fn seed_pocket(&mut self, geom: &ShapeGeometry, deficit: f64) {
        let m = geom.stitches_per_row;
        let s = geom.row_strand_length;
        let r = geom.min_radius;
        let n = geom.rows;
        // Small-amplitude period (rows) of the first integral of the continuum problem.
        let denom = PI * (s - 6.0 * PI * r);
        let period = if denom > 0.0 {
            2.0 * PI * m * (2.0 * r / denom).sqrt()
        } else {
            n
        };
        let mut period =
            crate::physics::numerics::bounds::limit(period, 2.0 * geom.rows_per_segment(), n);
        let k = geom.rows_per_segment();
        let rings = self.radii.len();
        let centre = 0.5 * n;
        // On a thin strand the period is a ring or two, and the amplitude that takes up the
        // deficit there would tilt a segment past radial (eq. 1.17): the pocket is widened
        // until every segment closes.
        loop {
            let amplitude = deficit * m / (PI * period);
            for j in 0..rings {
                let pos = j as f64 * k - centre;
                let inside = pos.abs() < 0.5 * period && j > 0 && j < rings - 1;
                self.radii[j] = if inside {
                    r + amplitude * (1.0 + (2.0 * PI * pos / period).cos())
                } else {
                    r
                };
                self.held[j] = !inside;
            }
            if period >= n || geom.length_and_volume(&self.radii).is_some() {
                break;
            }
            period = (2.0 * period).min(n);
        }
        self.lambda = 3.0 * PI * r * r - r * s;
    }
}
