//! The continuum wall against the layered wall's limit, its convergence, and its safety.

use super::*;
use crate::physics::gaylord::Sleeve;
use proptest::prelude::*;

/// Table 2.1's muscle C (the thickest wall relative to its bore, with pre-strain) and muscle D
/// (thin wall): (muscle length, bladder length, inner diameter, thickness, b, n), SI units.
const MUSCLE_C: (f64, f64, f64, f64, f64, f64) = (0.0989, 0.0541, 1.6e-3, 1.6e-3, 0.1051, 3.40);
const MUSCLE_D: (f64, f64, f64, f64, f64, f64) = (0.1358, 0.1336, 3.8e-3, 0.25e-3, 0.1423, 4.53);

fn bladder(m: (f64, f64, f64, f64, f64, f64), wall: Wall) -> Bladder<Sleeve> {
    let (_, lr0, d_ri, t, b, n) = m;
    let tube = BladderTube::latex(d_ri, t, lr0);
    Bladder::with_wall(Sleeve::new(b, n).unwrap(), tube, wall).unwrap()
}

/// Lengths across the whole range to within 0.5% of the fill limits, where the inner wall
/// nearly collapses and the force diverges.
fn stroke(bl: &Bladder<Sleeve>, count: usize) -> Vec<f64> {
    let (lo, hi) = (bl.min_length(), bl.max_length());
    (0..count)
        .map(|i| lo + (hi - lo) * (0.005 + 0.99 * i as f64 / (count - 1) as f64))
        .collect()
}

/// The infinite-layer limit of eq. 2.19-2.20, independently of the quadrature: Richardson
/// extrapolation of the layered model (a left Riemann sum through the wall, so its error is a
/// series in `1/n`) from 256, 512, 1024 and 2048 layers, cancelling the `1/n`, `1/n^2` and
/// `1/n^3` terms.
fn layered_limit(m: (f64, f64, f64, f64, f64, f64), p: f64, lengths: &[f64]) -> Vec<f64> {
    let forces: Vec<Vec<f64>> = [256, 512, 1024, 2048]
        .iter()
        .map(|&n| {
            let bl = bladder(m, Wall::DissertationLayers(n));
            lengths
                .iter()
                .map(|&l| bl.evaluate(p, l).unwrap().force)
                .collect()
        })
        .collect();
    (0..lengths.len())
        .map(|j| {
            let f: Vec<f64> = forces.iter().map(|row| row[j]).collect();
            let r1: Vec<f64> = (0..3).map(|i| 2.0 * f[i + 1] - f[i]).collect();
            let r2: Vec<f64> = (0..2).map(|i| (4.0 * r1[i + 1] - r1[i]) / 3.0).collect();
            (8.0 * r2[1] - r2[0]) / 7.0
        })
        .collect()
}

fn lengths_of(bl: &Bladder<Sleeve>) -> Vec<f64> {
    stroke(bl, 41)
}

fn largest_error(bl: &Bladder<Sleeve>, p: f64, lengths: &[f64], limit: &[f64]) -> f64 {
    let peak = limit.iter().fold(0.0f64, |a, f| a.max(f.abs()));
    lengths
        .iter()
        .zip(limit)
        .map(|(&l, f)| (bl.evaluate(p, l).unwrap().force - f).abs() / peak)
        .fold(0.0, f64::max)
}

#[test]
fn eight_nodes_reach_the_layered_limit_within_1e_6_of_peak_force() {
    // The hardest case: muscle C at 450 kPa (the thickest wall for its bore, pre-strained).
    let p = 450e3;
    let probe = bladder(MUSCLE_C, Wall::DissertationContinuum(8));
    let lengths = stroke(&probe, 41);
    let limit = layered_limit(MUSCLE_C, p, &lengths);
    let err8 = largest_error(&probe, p, &lengths, &limit);
    assert!(err8 <= 1e-6, "8 nodes: {err8:e} of peak force");
    // The same measure separates the layered walls clearly (16 layers are ~17% off here).
    let err16_layers = largest_error(
        &bladder(MUSCLE_C, Wall::DissertationLayers(16)),
        p,
        &lengths,
        &limit,
    );
    assert!(err16_layers > 0.1, "{err16_layers}");
    // And muscle D, whose thin wall nearly collapses towards its fill limit.
    let probe = bladder(MUSCLE_D, Wall::DissertationContinuum(8));
    let limit = layered_limit(MUSCLE_D, p, &lengths_of(&probe));
    let err = largest_error(&probe, p, &lengths_of(&probe), &limit);
    assert!(err <= 1e-6, "muscle D, 8 nodes: {err:e} of peak force");
}

#[test]
fn quadrature_converges_geometrically_where_layers_converge_at_first_order() {
    let p = 450e3;
    let probe = bladder(MUSCLE_C, Wall::DissertationContinuum(32));
    let lengths = stroke(&probe, 21);
    let reference: Vec<f64> = lengths
        .iter()
        .map(|&l| probe.evaluate(p, l).unwrap().force)
        .collect();
    let err = |wall| largest_error(&bladder(MUSCLE_C, wall), p, &lengths, &reference);
    // Layers: doubling halves the error (first order).
    let (l64, l128) = (
        err(Wall::DissertationLayers(64)),
        err(Wall::DissertationLayers(128)),
    );
    assert!((l64 / l128 - 2.0).abs() < 0.1, "layers {l64:e} {l128:e}");
    // Nodes: each doubling gains far more than a factor of 2 (at least 20x per doubling until
    // the rounding floor).
    let (n2, n4, n8) = (
        err(Wall::DissertationContinuum(2)),
        err(Wall::DissertationContinuum(4)),
        err(Wall::DissertationContinuum(8)),
    );
    assert!(
        n2 / n4 > 20.0 && n4 / n8 > 20.0,
        "nodes {n2:e} {n4:e} {n8:e}"
    );
}

#[test]
fn one_node_meets_the_thin_wall_as_the_wall_thins() {
    // The thin wall of eq. 2.12 samples the wall at its inner surface, one node inside it, so
    // they are equal only in the limit of a thin wall: their difference must vanish at least in
    // proportion to the thickness.
    let p = 400e3;
    let diff = |t: f64| {
        let m = (0.1358, 0.1336, 3.8e-3, t, 0.1423, 4.53);
        let thin = bladder(m, Wall::DissertationLayers(1));
        let one = bladder(m, Wall::DissertationContinuum(1));
        let l = 0.5 * (thin.min_length() + thin.max_length());
        let (a, b) = (thin.evaluate(p, l).unwrap(), one.evaluate(p, l).unwrap());
        (a.force - b.force).abs() / a.force.abs()
    };
    let d: Vec<f64> = [0.4e-3, 0.2e-3, 0.1e-3, 0.05e-3]
        .iter()
        .map(|&t| diff(t))
        .collect();
    for pair in d.windows(2) {
        assert!(pair[1] <= 0.55 * pair[0], "{d:?}");
    }
    assert!(d[3] < 2e-3, "{d:?}");
}

#[test]
fn continuum_stiffness_is_the_slope_and_threshold_switches_contact() {
    let bl = bladder(MUSCLE_C, Wall::DissertationContinuum(8));
    for &p in &[0.0, 100e3, 450e3] {
        for &l in &stroke(&bl, 9)[1..8] {
            // (The finite difference needs the force smooth over 2e-7 m: away from the limits.)
            let s = bl.evaluate(p, l).unwrap();
            let h = 1e-7;
            let fd = (bl.evaluate(p, l + h).unwrap().force - bl.evaluate(p, l - h).unwrap().force)
                / (2.0 * h);
            assert!(
                (s.stiffness - fd).abs() <= 1e-5 * fd.abs().max(1.0),
                "p {p} l {l}: {} vs {fd}",
                s.stiffness
            );
            let threshold = bl.threshold_pressure(l).unwrap();
            assert_eq!(s.contact, p >= threshold);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Wherever the layered model is finite, so is the continuum: no NaN, never a panic.
    #[test]
    fn finite_wherever_the_layered_wall_is(which in 0usize..2, nodes in 1usize..24,
                                            p in -80e3f64..800e3, u in 0.0f64..1.0) {
        let m = [MUSCLE_C, MUSCLE_D][which];
        let layered = bladder(m, Wall::DissertationLayers(64));
        let cont = bladder(m, Wall::DissertationContinuum(nodes));
        let l = layered.min_length() + u * (layered.max_length() - layered.min_length());
        if let Ok(ls) = layered.evaluate(p, l) {
            prop_assert!(ls.force.is_finite());
            let cs = cont.evaluate(p, l);
            prop_assert!(cs.is_ok(), "{cs:?}");
            let cs = cs.unwrap();
            prop_assert!(cs.force.is_finite() && cs.stiffness.is_finite());
        }
    }
}

#[test]
fn continuum_pressure_partial_is_the_slope_in_pressure() {
    // The directional derivatives (Model Exchange) use d(elastic)/dP of the wall: check the
    // continuum's against central differences in pressure, in contact and free.
    let bl = bladder(MUSCLE_C, Wall::DissertationContinuum(8));
    for &p in &[20e3, 100e3, 450e3] {
        for &l in &stroke(&bl, 9)[1..8] {
            let dp = 1.0;
            let (Ok(hi), Ok(lo)) = (bl.evaluate(p + dp, l), bl.evaluate(p - dp, l)) else {
                continue;
            };
            if hi.contact != lo.contact {
                continue;
            }
            let fd = (hi.force - lo.force) / (2.0 * dp);
            let partial = bl.partials(p, l).unwrap().force[0];
            assert!(
                (partial - fd).abs() <= 1e-5 * fd.abs().max(1e-6),
                "p {p} l {l}: {partial} vs {fd}"
            );
        }
    }
}

#[test]
fn exp_pairs_is_exp_to_rounding_over_its_range() {
    // The Dual path's hand-written exp, against libm over |y| <= 700 (where it is used): dense
    // near 0 (the usual spans) and across the whole range (every power of two it builds).
    use super::continuum::exp_pairs;
    let mut worst = 0.0f64;
    for i in 0..=200_000 {
        let f = i as f64 / 200_000.0;
        for y in [700.0 * (2.0 * f - 1.0), 8.0 * (2.0 * f - 1.0), 1e-3 * f] {
            let (plus, minus) = exp_pairs([y, -y, 0.5 * y, 0.0]);
            for (got, arg) in plus.iter().zip([y, -y, 0.5 * y, 0.0]) {
                worst = worst.max((got / arg.exp() - 1.0).abs());
            }
            for (got, arg) in minus.iter().zip([-y, y, -0.5 * y, 0.0]) {
                worst = worst.max((got / arg.exp() - 1.0).abs());
            }
        }
    }
    // A few ulp (an error in a coefficient or in the reduction shows as 1e-13 or worse).
    assert!(worst < 1e-15, "{worst:e}");
}

#[test]
fn dual_node_sums_agree_with_the_generic_path() {
    // The kernel on Dual numbers (vectorized node sums) against the same kernel on hyper-dual
    // numbers (the generic node by node sums), value and first derivatives, over both muscles,
    // node counts with and without a middle node and past one block, in contact and below it.
    use crate::physics::numerics::hyper_dual::HyperDual;
    for m in [MUSCLE_C, MUSCLE_D] {
        for nodes in [1, 2, 3, 7, 8, 9, 16, 17, 23] {
            let bl = bladder(m, Wall::DissertationContinuum(nodes));
            for &l in &stroke(&bl, 13) {
                for shrink in [1.0, 0.97, 0.9] {
                    let x = bl.sleeve.diameter_sq(l).sqrt() * shrink;
                    let one = bl.kernel(450e3, Dual::var_l(l), Dual::var_x(x));
                    let two = bl.kernel(
                        450e3,
                        HyperDual::seed(l, [1.0, 0.0], [0.0; 3]),
                        HyperDual::seed(x, [0.0, 1.0], [0.0; 3]),
                    );
                    assert_eq!(one.is_some(), two.is_some(), "{nodes} nodes l {l} x {x}");
                    let (Some(one), Some(two)) = (one, two) else {
                        continue;
                    };
                    let close = |a: Dual, b: HyperDual, what: &str| {
                        for (p, q) in [(a.v, b.v), (a.dl, b.d[0]), (a.dx, b.d[1])] {
                            assert!(
                                (p - q).abs() <= 1e-11 * q.abs().max(1e-300),
                                "{what}, {nodes} nodes, l {l}, x {x}: {p:e} vs {q:e}"
                            );
                        }
                    };
                    close(one.c, two.c, "c");
                    close(one.a, two.a, "a");
                    close(one.elastic, two.elastic, "elastic");
                }
            }
        }
    }
}
