use super::*;

/// Slopes of the path's own maximum at `l_max - step / 2^k`, k = 1..=9: from its first node
/// (a path stopped there) solved back up towards full extension, halving the distance.
fn slopes_towards_full(geom: &ShapeGeometry, end: f64, nodes: usize) -> Vec<(f64, f64)> {
    let l_max = geom.max_length();
    let step = (l_max - end) / nodes as f64;
    let mut solver = Solver::new(geom);
    let pts = follow_path(geom, &mut solver, end, nodes, Some(l_max - step)).unwrap();
    let (mut current, mut curvature) = (pts[1].length, pts[1].curvature);
    let mut out = vec![];
    for k in 1..=9 {
        let below = step / f64::powi(2.0, k);
        let last = solver.clone();
        predict(
            geom,
            &mut solver,
            &last,
            l_max - below - current,
            curvature,
            &[None, None],
        );
        let start = solver.clone();
        let p = fast_solve(geom, &mut solver, &start, l_max - below, 200).unwrap();
        (current, curvature) = (p.length, p.curvature);
        out.push((below, p.slope));
    }
    out
}

/// A sleeve whose pocket grows from full extension with the slope leaving the cylinder's
/// (4.385 stitches per row, 198.7 rows, S_row 579.6 m, t 1.19e-12 m, 86 segments): the
/// table's first curvature is the rate of that slope, d2V/dL2 = -(dV/dL - dV/dL(L_max)) / dL,
/// Richardson-extrapolated from the path's own solves just below full extension. A nucleation
/// there lands on another pocket with twice the curvature.
#[test]
fn first_curvature_is_the_rate_of_the_followed_slope() {
    let (m, n, s, t) = (
        4.385142330347021,
        1.9869529304511673e2,
        5.7957341522366e2,
        1.1856727797939724e-12,
    );
    let geom = ShapeGeometry::new(m, n, s, 4.0 * m * t / (2.0 * PI), 86).unwrap();
    let l_max = geom.max_length();
    let l_free = n * s / (6.0 * m);
    let end = l_free - 0.1 * (l_max - l_free);
    let table = ShapeTable::build(geom, end, DEFAULT_TABLE_NODES).unwrap();
    let cylinder_slope = table.slope[0];
    let rate = |(below, slope): (f64, f64)| (cylinder_slope - slope) / below;
    let slopes = slopes_towards_full(&geom, end, DEFAULT_TABLE_NODES);
    let (coarse, fine) = (rate(slopes[7]), rate(slopes[8]));
    let truth = 2.0 * fine - coarse;
    // The slope leaves the cylinder's smoothly: the rates converge at first order.
    assert!(
        (fine - coarse).abs() < 1e-2 * truth.abs(),
        "{coarse} {fine}"
    );
    let first = table.curvature[0];
    assert!(
        (first - truth).abs() < 5e-3 * truth.abs(),
        "{first} vs {truth}"
    );
}
