//! Which volume maximum the table holds where several exist (section 1.3.5).

use super::*;
use std::f64::consts::PI;

/// The slowest sleeves of the table-space bench's draws: thin strands on 75-90 segments whose
/// nucleation ends on a mirror-symmetric pair of pockets. (m, n, S_row, strand thickness,
/// segments.)
pub(super) const PAIRED_NUCLEATION: [(f64, f64, f64, f64, usize); 5] = [
    (
        4.071564298488666e2,
        6.314500038072768e1,
        1.920368134882888e-2,
        3.930666914766833e-15,
        90,
    ),
    (
        7.232877696854794e2,
        1.8574609855364474e2,
        1.2165512223995123e-2,
        6.221929277575029e-9,
        88,
    ),
    (
        1.6570114017837312e1,
        3.7787727029796563e0,
        1.8182028286355717e-5,
        1.6879724902338345e-10,
        86,
    ),
    (
        7.499796958343161e2,
        1.727341322131412e2,
        7.4060454191027e-5,
        8.968545713717185e-14,
        76,
    ),
    (
        1.3895779956115504e2,
        1.7603594043675177e1,
        2.2122976703924505e-2,
        3.5156105808250572e-15,
        75,
    ),
];

pub(super) fn sleeve(c: (f64, f64, f64, f64, usize)) -> (ShapeGeometry, f64) {
    let (m, n, s, t, segments) = c;
    let g = ShapeGeometry::new(m, n, s, 4.0 * m * t / (2.0 * PI), segments).unwrap();
    // `KnittedSleeve::new`'s end: a little below the cylinder's free contraction.
    let l_free = n * s / (6.0 * m);
    (g, l_free - 0.1 * (g.max_length() - l_free))
}

/// The most volume a single cosine pocket holds at `length`, scanned over every width (rings)
/// and position on the sleeve: the pocket's height is set by bisection so that the profile's
/// length (eq. 1.17) is `length`, and its volume is eq. 1.18 summed.
fn best_scanned_pocket(g: &ShapeGeometry, length: f64) -> f64 {
    let rings = g.segments + 1;
    let ceiling = g.radius_ceiling();
    let profile = |first: usize, width: usize, height: f64| -> Vec<f64> {
        (0..rings)
            .map(|j| {
                if j <= first || j >= first + width {
                    return g.min_radius;
                }
                let phase = 2.0 * PI * (j - first) as f64 / width as f64;
                (g.min_radius + 0.5 * height * (1.0 - phase.cos())).min(ceiling)
            })
            .collect()
    };
    let mut best = 0.0f64;
    for width in 2..rings {
        for first in 0..rings - width {
            let at = |h: f64| g.length_and_volume(&profile(first, width, h));
            // Raise the pocket until it is short enough (or stops closing).
            let mut hi = 1e-6 * ceiling;
            while matches!(at(hi), Some((l, _)) if l > length) && hi < ceiling {
                hi *= 2.0;
            }
            let Some((l_hi, _)) = at(hi) else { continue };
            if l_hi > length {
                continue;
            }
            let mut lo = 0.0;
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                match at(mid) {
                    Some((l, _)) if l > length => lo = mid,
                    _ => hi = mid,
                }
            }
            if let Some((l, v)) = at(hi) {
                if (l - length).abs() <= 1e-9 * g.max_length() {
                    best = best.max(v);
                }
            }
        }
    }
    best
}

#[test]
fn a_table_starts_on_the_greater_of_paired_and_single_pockets() {
    // The table follows a volume maximum by continuation from full extension (the shape of
    // greatest V at each length, section 1.3.5, stays a maximum as the length shortens), so its
    // start decides the branch. On these thin strands the nucleation seeds end on two
    // mirror-image pockets, which is a saddle: moving length from one pocket to the other gains
    // volume (a pocket's volume is convex in the length it takes up early on, eq. 1.17-1.18).
    // The table must hold at least as much volume as every single cosine pocket of any width
    // and position scanned at the same length (an independent lower bound on the greatest
    // maximum): the pair holds 35-60% less at the first nodes.
    for c in PAIRED_NUCLEATION {
        let (g, end) = sleeve(c);
        let t = ShapeTable::build(g, end, DEFAULT_TABLE_NODES).unwrap();
        let lengths: Vec<f64> = t.lengths().collect();
        for k in [1, 5, 10, 20] {
            let scanned = best_scanned_pocket(&g, lengths[k]);
            assert!(
                t.volume[k] >= scanned * (1.0 - 1e-9),
                "m {}: node {k}: table V {:e} below a scanned pocket's {scanned:e}",
                c.0,
                t.volume[k]
            );
        }
    }
}

#[test]
fn paired_nucleation_sleeves_build_in_bounded_work() {
    // Started on the pair, these tables spent 35-90 iterations on each of their first 25-30
    // nodes (2,744-2,951 in all) before the pair gave way to one pocket; started on one pocket,
    // 3-11 a node.
    for c in PAIRED_NUCLEATION {
        let (g, end) = sleeve(c);
        super::solver::ITERATIONS.with(|n| n.set(0));
        let t = ShapeTable::build(g, end, DEFAULT_TABLE_NODES).unwrap();
        let work = super::solver::ITERATIONS.with(|n| n.get());
        assert!(t.volume.len() > 120, "m {}: {} nodes", c.0, t.volume.len());
        assert!(work <= 2000, "m {}: {work} iterations", c.0);
    }
}
