//! Reference tables from the one-ring-at-a-time solver, kept as fixtures so
//! that the faster path is tested against the tables it replaced. The `slow_*` fixtures come from
//! the path before the shifted Newton step (plain Newton, the robust solve as its fallback), on
//! sleeves that it built in over 10 ms.
//!
//! Regenerate only deliberately: `cargo test --release --lib write_reference_tables --
//! --ignored` overwrites `reference/*.csv` with the current solver's output.

use super::*;
use std::f64::consts::PI;

/// A sleeve of the comparison: name, geometry, end length (the path stops at the first node
/// past zero force before reaching it), nodes.
pub(super) struct Case {
    pub(super) name: &'static str,
    pub(super) geometry: ShapeGeometry,
    pub(super) end: f64,
    pub(super) nodes: usize,
}

/// `KnittedSleeve::new`'s end length: a little below the cylinder's free contraction.
fn sleeve_end(g: &ShapeGeometry) -> f64 {
    let l_free = g.rows * g.row_strand_length / (6.0 * g.stitches_per_row);
    l_free - 0.1 * (g.max_length() - l_free)
}

fn case(name: &'static str, m: f64, n: f64, s: f64, r_min: f64, segments: usize) -> Case {
    let geometry = ShapeGeometry::new(m, n, s, r_min, segments).unwrap();
    Case {
        name,
        end: sleeve_end(&geometry),
        geometry,
        nodes: DEFAULT_TABLE_NODES,
    }
}

pub(super) fn cases() -> Vec<Case> {
    // Section 1.4 prototype (knitted.rs `prototype`): m = 22, n = 49, S = pi 153 mm, r_min from
    // the strand thickness that gives the 514 mm stretched length.
    let s = PI * 0.153;
    let t = (s - 0.514 * 2.0 * 22.0 / 49.0) / (4.0 * 22.0);
    let r = 4.0 * 22.0 * t / (2.0 * PI);
    // Fig. 1.16 muscle with the 0.2 mm strand (knitted.rs `fig_1_16`).
    let s16 = 1.5 * PI * 0.0146;
    let n16 = 8.0 * 2.0 * 0.110 / s16;
    let r16 = 4.0 * 8.0 * 0.2e-3 / (2.0 * PI);
    vec![
        case("prototype_49", 22.0, 49.0, s, r, 49),
        case("prototype_98", 22.0, 49.0, s, r, 98),
        case("prototype_196", 22.0, 49.0, s, r, 196),
        case("prototype_392", 22.0, 49.0, s, r, 392),
        case("prototype_1568", 22.0, 49.0, s, r, 1568),
        case("fig_1_16_40", 8.0, n16, s16, r16, 40),
        // A thick strand (r_min 8% of the largest radius) on few rows, coarse.
        case(
            "thick_short_12",
            6.0,
            14.0,
            0.3,
            0.08 * 0.3 / (2.0 * PI),
            12,
        ),
        // Sleeves whose build took over 10 ms before the shifted Newton path (thin strands on
        // many segments); `S_row` 1 m, `r_min` from `4 m t / S_row`.
        case(
            "slow_wide_142",
            1610.1449364868288,
            74.90568975501913,
            1.0,
            0.0016143462847681193 / (2.0 * PI),
            142,
        ),
        case(
            "slow_few_stitches_76",
            3.60314,
            100.084,
            1.0,
            0.00130517 / (2.0 * PI),
            76,
        ),
        case(
            "slow_long_134",
            187.83,
            190.716,
            1.0,
            0.00922519 / (2.0 * PI),
            134,
        ),
    ]
}

/// The two slowest table builds among 2,000 sleeves drawn over the KnittedMuscle's declared space
/// (`benches/knitted_table_space.rs`, `KNITTED_SEED=8`), `r_min = 4 m t / (2 pi)` from their
/// strand thickness `t`: a short wide sleeve (full extension 1.6 mm, ceiling radius 1.9 mm) whose
/// path ends where the clamps' segments turn radial (eq. 1.17), and a thin strand on 90 segments
/// whose pocket sits against one clamp and reaches zero force.
pub(super) fn slowest_sampled() -> Vec<Case> {
    let sleeve = |name, m: f64, n, s, t: f64, segments| {
        case(name, m, n, s, 4.0 * m * t / (2.0 * PI), segments)
    };
    vec![
        sleeve(
            "sampled_radial_end_88",
            7.232877696854794e2,
            1.8574609855364474e2,
            1.2165512223995123e-2,
            6.221929277575029e-9,
            88,
        ),
        sleeve(
            "sampled_thin_90",
            2.0919603768608237e1,
            1.0608952247092475e2,
            6.854262142174964e-4,
            8.871632718064084e-15,
            90,
        ),
    ]
}

pub(super) struct Row {
    pub(super) length: f64,
    pub(super) volume: f64,
    pub(super) slope: f64,
    pub(super) curvature: f64,
    pub(super) max_radius: f64,
}

pub(super) fn parse(text: &str) -> Vec<Row> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let x: Vec<f64> = l.split(',').map(|f| f.trim().parse().unwrap()).collect();
            Row {
                length: x[0],
                volume: x[1],
                slope: x[2],
                curvature: x[3],
                max_radius: x[4],
            }
        })
        .collect()
}

/// The fixture's text for a case.
pub(super) fn fixture(name: &str) -> &'static str {
    match name {
        "prototype_49" => include_str!("reference/prototype_49.csv"),
        "prototype_98" => include_str!("reference/prototype_98.csv"),
        "prototype_196" => include_str!("reference/prototype_196.csv"),
        "prototype_392" => include_str!("reference/prototype_392.csv"),
        "prototype_1568" => include_str!("reference/prototype_1568.csv"),
        "fig_1_16_40" => include_str!("reference/fig_1_16_40.csv"),
        "thick_short_12" => include_str!("reference/thick_short_12.csv"),
        "slow_wide_142" => include_str!("reference/slow_wide_142.csv"),
        "slow_few_stitches_76" => include_str!("reference/slow_few_stitches_76.csv"),
        "slow_long_134" => include_str!("reference/slow_long_134.csv"),
        "sampled_radial_end_88" => include_str!("reference/sampled_radial_end_88.csv"),
        "sampled_thin_90" => include_str!("reference/sampled_thin_90.csv"),
        _ => unreachable!("no fixture {name}"),
    }
}

#[test]
#[ignore = "writes the fixtures; run deliberately"]
fn write_reference_tables() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src/physics/knitted_shape/reference");
    std::fs::create_dir_all(&dir).unwrap();
    for c in cases().into_iter().chain(slowest_sampled()) {
        let t = ShapeTable::build(c.geometry, c.end, c.nodes).unwrap();
        let mut out = format!(
            "# {}: m {}, n {}, S_row {:e} m, r_min {:e} m, {} segments, end {:e} m, {} nodes\n\
             # length (m), volume (m^3), dV/dL (m^2), d2V/dL2 (m), largest radius (m)\n",
            c.name,
            c.geometry.stitches_per_row,
            c.geometry.rows,
            c.geometry.row_strand_length,
            c.geometry.min_radius,
            c.geometry.segments,
            c.end,
            c.nodes
        );
        for (i, l) in t.lengths().enumerate() {
            out += &format!(
                "{:.17e},{:.17e},{:.17e},{:.17e},{:.17e}\n",
                l, t.volume[i], t.slope[i], t.curvature[i], t.max_radius[i]
            );
        }
        std::fs::write(dir.join(format!("{}.csv", c.name)), out).unwrap();
    }
}

/// Largest differences of a fresh table from a fixture over the fixture's stroke: volume as a
/// share of the largest volume, `dV/dL` (force per pressure) as a share of the peak, `d2V/dL2`
/// as a share of its largest magnitude, largest radius as a share of the largest.
pub(super) fn differences(c: &Case) -> [f64; 4] {
    let reference = parse(fixture(c.name));
    let t = ShapeTable::build(c.geometry, c.end, c.nodes).unwrap();
    let peak = |f: fn(&Row) -> f64| reference.iter().map(|r| f(r).abs()).fold(0.0, f64::max);
    let (v_max, s_max, c_max, r_max) = (
        peak(|r| r.volume),
        peak(|r| r.slope),
        peak(|r| r.curvature),
        peak(|r| r.max_radius),
    );
    let mut worst = [0.0f64; 4];
    for row in &reference {
        let (v, s, k) = t.evaluate(row.length);
        let r = t.max_radius(row.length);
        for (w, e) in worst.iter_mut().zip([
            (v - row.volume) / v_max,
            (s - row.slope) / s_max,
            (k - row.curvature) / c_max,
            (r - row.max_radius) / r_max,
        ]) {
            *w = w.max(e.abs());
        }
    }
    worst
}

/// The new path against the one-ring-at-a-time solver's tables, node by node over the stroke.
///
/// Tolerances (shares of each quantity's largest magnitude): volume 1e-9, `dV/dL` 3e-5,
/// `d2V/dL2` 1e-4, largest radius 3e-5. Measured: volume <= 3.2e-10, force <= 2.0e-5 (98
/// segments), curvature <= 3.1e-5, radius <= 1.6e-5. The force differences sit at nodes where a
/// pair of rings has just left the floor: the profile is then a saddle for a shift of the pocket
/// by part of a segment, and the old solver stopped its crawl there at a residual up to 1e3 times
/// its tolerance (`1e-7 S_row^2`), where the new one converges to `1e-10 S_row^2`. For scale,
/// halving the segments from 98 to 49 moves the volume by 1.5e-4.
///
/// The coarse `thick_short_12` (12 segments for 14 rows) is the exception: at 15 of its 141
/// nodes, in three runs where the pocket's edge crosses a ring, the old solver's roundoff let
/// one ring of a pair fall back to the floor, off the symmetric saddle, to a lopsided pocket
/// (measured: up to 5.2e-4 of the largest volume more, at two nodes 1.8e-4 less). The new path
/// stays on the symmetric profile, the old one's choice at every other node and sleeve;
/// elsewhere it agrees as closely as on the fine sleeves.
#[test]
fn tables_agree_with_the_reference_solver() {
    for c in cases() {
        let reference = parse(fixture(c.name));
        let t = ShapeTable::build(c.geometry, c.end, c.nodes).unwrap();
        // The same nodes, ending at the same first node past zero force.
        assert_eq!(t.volume.len(), reference.len(), "{}", c.name);
        assert!((t.min_length() - reference[reference.len() - 1].length).abs() < 1e-12);
        let d = differences(&c);
        println!(
            "{}: volume {:.1e}, force {:.1e}, curvature {:.1e}, radius {:.1e}",
            c.name, d[0], d[1], d[2], d[3]
        );
        if c.name == "thick_short_12" {
            let v_max = reference.iter().map(|r| r.volume).fold(0.0, f64::max);
            let mut lopsided = 0;
            for row in &reference {
                let v = t.evaluate(row.length).0;
                if (v - row.volume).abs() > 1e-9 * v_max {
                    println!(
                        "  at {:.5} m: {:+.2e} of the largest volume",
                        row.length,
                        (v - row.volume) / v_max
                    );
                    assert!((row.volume - v).abs() < 6e-4 * v_max);
                    lopsided += 1;
                }
            }
            assert!(lopsided <= 15, "{lopsided}");
        } else {
            assert!(
                d[0] < 1e-9 && d[1] < 3e-5 && d[2] < 1e-4 && d[3] < 3e-5,
                "{}: {d:?}",
                c.name
            );
        }
    }
}
