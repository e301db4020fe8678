//! The non-cylindrical table's build time over the KnittedMuscle's declared sleeve space
//! (`cargo bench --bench knitted_table_space`): `stitches_per_row`, `rows`, `row_strand_length`,
//! `strand_thickness` and `shape_segments` drawn log-uniform over their declared ranges as
//! `benches/worst_case.rs` draws them (a quarter of the thicknesses zero, the others across 15
//! decades below the top; `shape_segments` up to `KNITTED_MAX_SEGMENTS`, the declared 98), until
//! `KNITTED_SLEEVES` (2,000) sleeves build. Times
//! `KnittedSleeve::new` in thread CPU time, refusals included, and prints the median, p99 and
//! maximum, the share over 10 ms, the tables that end with tension left above the strands'
//! shortest length (`dV/dL < 0` at their last node) and the slowest sleeves with their
//! parameters, each timed again `KNITTED_REPEAT` (5) times. `KNITTED_DUMP=<file>` writes every
//! built sleeve: seconds, m, n, S_row, thickness, segments, table nodes, whether it ends early.

#[path = "cpu_clock.rs"]
mod cpu_clock;
#[path = "../tests/common/rng.rs"]
#[allow(dead_code)]
mod rng;

use actuator_fmus::physics::knitted::{KnittedParams, KnittedSleeve, ShapeKind, ShapeModel};
use cpu_clock::thread_cpu;
use rng::Rng;

struct Case {
    params: KnittedParams,
    segments: usize,
    seconds: f64,
    built: bool,
    /// Table nodes, and whether the table ends with tension left (`dV/dL < 0` at its last node)
    /// above the sleeve's shortest length.
    nodes: usize,
    early: bool,
}

/// Nodes of a non-cylindrical sleeve's table and whether it ends early: with tension left at its
/// last node, above the strands' shortest length.
fn table_end(sleeve: &KnittedSleeve) -> (usize, bool) {
    match sleeve.shape() {
        ShapeModel::NonCylindrical(t) => {
            let nodes = t.lengths().count();
            let tension = t.evaluate(t.min_length()).1 < 0.0;
            let above = t.min_length() > sleeve.params().min_length_thickness() * (1.0 + 1e-12);
            (nodes, tension && above)
        }
        _ => (0, false),
    }
}

fn main() {
    let wanted: usize = std::env::var("KNITTED_SLEEVES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let max_segments: f64 = std::env::var("KNITTED_MAX_SEGMENTS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(98.0);
    // `KNITTED_SEED` draws another set of sleeves.
    let seed: u64 = std::env::var("KNITTED_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x6b6e_6974);
    let mut rng = Rng(seed);
    let mut cases = Vec::new();
    let mut built = 0;
    while built < wanted {
        let params = KnittedParams {
            stitches_per_row: rng.log_uniform(1.0, 1e6),
            rows: rng.log_uniform(1.0, 1e7),
            row_strand_length: rng.log_uniform(1e-6, 1e3),
            strand_thickness: if rng.uniform() < 0.25 {
                0.0
            } else {
                rng.log_uniform(0.1e-15, 0.1)
            },
            bladder_outer_radius: 0.0,
        };
        let segments = rng.log_uniform(2.0, max_segments + 0.5).floor() as usize;
        let start = thread_cpu();
        let sleeve = KnittedSleeve::new(params, ShapeKind::NonCylindrical { segments });
        let seconds = thread_cpu() - start;
        built += sleeve.is_ok() as usize;
        let (nodes, early) = sleeve.as_ref().map(table_end).unwrap_or((0, false));
        cases.push(Case {
            params,
            segments,
            seconds,
            built: sleeve.is_ok(),
            nodes,
            early,
        });
    }
    if let Ok(f) = std::env::var("KNITTED_DUMP") {
        let mut o = String::new();
        for c in cases.iter().filter(|c| c.built) {
            let p = c.params;
            o += &format!(
                "{} {:e} {:e} {:e} {:e} {} {} {}\n",
                c.seconds,
                p.stitches_per_row,
                p.rows,
                p.row_strand_length,
                p.strand_thickness,
                c.segments,
                c.nodes,
                c.early
            );
        }
        std::fs::write(f, o).unwrap();
    }
    let mut times: Vec<f64> = cases
        .iter()
        .filter(|c| c.built)
        .map(|c| c.seconds)
        .collect();
    times.sort_by(f64::total_cmp);
    let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
    let slow = times.iter().filter(|&&t| t > 10e-3).count();
    let refused_max = cases
        .iter()
        .filter(|c| !c.built)
        .map(|c| c.seconds)
        .fold(0.0, f64::max);
    println!(
        "{} sleeves built ({} refused): median {:.3} ms, p99 {:.2} ms, max {:.2} ms; {} ({:.1}%) \
         over 10 ms; slowest refusal {:.3} ms",
        times.len(),
        cases.len() - times.len(),
        1e3 * at(0.5),
        1e3 * at(0.99),
        1e3 * at(1.0),
        slow,
        100.0 * slow as f64 / times.len() as f64,
        1e3 * refused_max
    );
    let early: Vec<&Case> = cases.iter().filter(|c| c.early).collect();
    println!(
        "{} tables end with tension left above the shortest length",
        early.len()
    );
    for c in &early {
        let p = c.params;
        println!(
            "  {} nodes: m {:e} n {:e} S_row {:e} t {:e} segments {}",
            c.nodes,
            p.stitches_per_row,
            p.rows,
            p.row_strand_length,
            p.strand_thickness,
            c.segments
        );
    }
    cases.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
    // The slowest sleeves again, each timed `KNITTED_REPEAT` (5) more times: the least of the
    // times excludes preemption and a busy sibling core.
    let repeat: usize = std::env::var("KNITTED_REPEAT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let shown = 12.min(cases.len());
    let least: Vec<f64> = cases[..shown]
        .iter()
        .map(|c| {
            (0..repeat).fold(c.seconds, |best, _| {
                let start = thread_cpu();
                let _ = KnittedSleeve::new(
                    c.params,
                    ShapeKind::NonCylindrical {
                        segments: c.segments,
                    },
                );
                best.min(thread_cpu() - start)
            })
        })
        .collect();
    println!(
        "slowest (ms, least of {} timings in ms, built, m, n, S_row, thickness, segments, \
         2 pi r_min / S_row):",
        repeat + 1
    );
    for (c, least) in cases.iter().zip(&least) {
        let p = c.params;
        println!(
            "{:8.2} {:8.2} {} m {:e} n {:e} S_row {:e} t {:e} segments {} ratio {:.4e}",
            1e3 * c.seconds,
            1e3 * least,
            c.built,
            p.stitches_per_row,
            p.rows,
            p.row_strand_length,
            p.strand_thickness,
            c.segments,
            4.0 * p.stitches_per_row * p.strand_thickness / p.row_strand_length
        );
    }
}
