//! The benchmark of the non-cylindrical volume-length table of the section 1.4 prototype
//! (n = 49 rows) built by our solver, against the dissertation's row-by-row gradient algorithm
//! (section 1.3.5), each with the volume error it reaches against a fine reference table.

use actuator_fmus::physics::knitted::KnittedParams;
use actuator_fmus::physics::knitted_shape::{
    seed_gradient_volume_curve, SeedAlgorithmOptions, ShapeGeometry, ShapeTable,
    DEFAULT_TABLE_NODES,
};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Duration;

fn geometry(segments: usize) -> ShapeGeometry {
    let p = KnittedParams::prototype();
    ShapeGeometry::new(
        p.stitches_per_row,
        p.rows,
        p.row_strand_length,
        p.min_radius(),
        segments,
    )
    .expect("geometry")
}

fn shape(c: &mut Criterion) {
    let end = 0.2; // past the non-cylindrical free contraction (0.1875 m)
    let ours = ShapeTable::build(geometry(49), end, DEFAULT_TABLE_NODES).expect("table");
    let seed = seed_gradient_volume_curve(&geometry(49), end, &SeedAlgorithmOptions::default())
        .expect("seed");
    // Both solve the same 49-row discretization: compare their volumes where both have points.
    let worst = seed
        .iter()
        .filter(|(l, _)| *l >= ours.min_length() && *l <= ours.max_length())
        .map(|&(l, v)| ((ours.evaluate(l).0 - v) / v).abs())
        .fold(0.0, f64::max);
    println!(
        "seed algorithm vs our table, same 49 rows: {} points, largest relative volume difference {worst:.2e}",
        seed.len()
    );
    let mut group = c.benchmark_group("knitted shape table, n = 49");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5));
    group.bench_function("ours: maximum volume by bordered Newton, 160 nodes", |b| {
        b.iter(|| {
            black_box(ShapeTable::build(geometry(49), end, DEFAULT_TABLE_NODES).expect("table"))
        })
    });
    group.bench_function("seed: row-by-row gradient exchange, 80 lengths", |b| {
        b.iter(|| {
            black_box(
                seed_gradient_volume_curve(&geometry(49), end, &SeedAlgorithmOptions::default())
                    .expect("seed"),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, shape);
criterion_main!(benches);
