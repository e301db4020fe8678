//! Native cost of one co-simulation step through the packaged FMU's C ABI: set the inputs, step,
//! get the output, as a master does every communication step. No Python in the loop.

#[path = "../tests/common/mod.rs"]
mod common;

use actuator_fmus::physics::gaylord::Sleeve;
use common::mckibben::*;
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Duration;

fn mckibben_ideal(c: &mut Criterion) {
    let api = common::Api::load(&common::extract_binary("McKibbenMuscle"));
    let inst = api
        .instantiate("bench", &common::guid_of("McKibbenMuscle"))
        .unwrap_or_else(|_| panic!("instantiate"));
    inst.initialize();
    let mut group = c.benchmark_group("McKibbenMuscle");
    let mut t = 0.0;
    let mut k = 0u32;
    let (set, step, get) = (api.fmi2SetReal, api.fmi2DoStep, api.fmi2GetReal);
    let inputs = [PRESSURE, LENGTH];
    let mut force = [0.0];
    group.bench_function(
        "ideal: fmi2SetReal(P, L) + fmi2DoStep + fmi2GetReal(F)",
        |bench| {
            bench.iter(|| unsafe {
                k = k.wrapping_add(1);
                let l = 0.06 + 1e-6 * (k % 1000) as f64;
                let s1 = set(inst.c, inputs.as_ptr(), 2, [4e5, l].as_ptr());
                let s2 = step(inst.c, t, 1e-3, 1);
                t += 1e-3;
                let s3 = get(inst.c, [FORCE].as_ptr(), 1, force.as_mut_ptr());
                debug_assert!(s1 == 0 && s2 == 0 && s3 == 0);
                black_box(force[0])
            })
        },
    );
    // The physics alone, for the share of the step that is FMI plumbing.
    let sleeve = Sleeve::new(0.1113, 3.74).unwrap();
    group.bench_function("ideal: eq. 2.3 alone (no FMI)", |bench| {
        bench.iter(|| black_box(sleeve.force(black_box(4e5), black_box(0.09))))
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = mckibben_ideal
}
criterion_main!(benches);
