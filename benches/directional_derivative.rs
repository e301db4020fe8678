//! Native cost of `fmi2GetDirectionalDerivative` against a co-simulation step, through the packaged
//! McKibbenMuscle's C ABI, for each bladder model: set(P, L) + doStep + get(F), set(P, L) + one
//! directional derivative dF/dP, and set(P, L) + the two directional derivatives dF/dP and dF/dL
//! (one seed each, a full 1x2 Jacobian row: the second reuses the first's partials).

#[path = "../tests/common/mod.rs"]
mod common;

use common::mckibben::*;
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Duration;

/// (label, preset, bladder_model, bladder_layers).
const COMBINATIONS: &[(&str, [i32; 3])] = &[
    ("ideal", [1, 0, 16]),
    ("thin wall", [1, 1, 16]),
    ("thick wall, 16 layers", [1, 2, 16]),
    ("continuum wall, 16 nodes", [1, 3, 16]),
];

fn cost(c: &mut Criterion) {
    use actuator_fmus::variables::mckibben_muscle::integer;
    let api = common::Api::load(&common::extract_binary("McKibbenMuscle"));
    let mut group = c.benchmark_group("McKibbenMuscle");
    let inputs = [PRESSURE, LENGTH];
    for (label, ints) in COMBINATIONS {
        let inst = api
            .instantiate("bench", &common::guid_of("McKibbenMuscle"))
            .unwrap_or_else(|_| panic!("instantiate"));
        let int_vrs = [
            integer::PRESET as u32,
            integer::BLADDER_MODEL as u32,
            integer::BLADDER_LAYERS as u32,
        ];
        unsafe {
            assert_eq!(
                (api.fmi2SetInteger)(inst.c, int_vrs.as_ptr(), 3, ints.as_ptr()),
                common::OK
            );
        }
        inst.initialize();
        let (mut t, mut k) = (0.0, 0u32);
        let mut out = [0.0];
        // Muscle A at 400 kPa, the length sweeping 0.70-0.79 of its 103.25 mm, in contact.
        group.bench_function(format!("{label}: set(P, L) + doStep + get(F)"), |bench| {
            bench.iter(|| unsafe {
                k = k.wrapping_add(1);
                let l = 0.072 + 1e-5 * (k % 1000) as f64;
                (api.fmi2SetReal)(inst.c, inputs.as_ptr(), 2, [4e5, l].as_ptr());
                (api.fmi2DoStep)(inst.c, t, 1e-3, 1);
                t += 1e-3;
                (api.fmi2GetReal)(inst.c, [FORCE].as_ptr(), 1, out.as_mut_ptr());
                black_box(out[0])
            })
        });
        let mut one = [0.0];
        group.bench_function(
            format!("{label}: set(P, L) + dF/dP (1 directional derivative)"),
            |bench| {
                bench.iter(|| unsafe {
                    k = k.wrapping_add(1);
                    let l = 0.072 + 1e-5 * (k % 1000) as f64;
                    (api.fmi2SetReal)(inst.c, inputs.as_ptr(), 2, [4e5, l].as_ptr());
                    let status = (api.fmi2GetDirectionalDerivative)(
                        inst.c,
                        [FORCE].as_ptr(),
                        1,
                        inputs.as_ptr(),
                        2,
                        [1.0, 0.0].as_ptr(),
                        one.as_mut_ptr(),
                    );
                    debug_assert_eq!(status, 0);
                    black_box(one)
                })
            },
        );
        let mut row = [0.0; 2];
        group.bench_function(
            format!("{label}: set(P, L) + dF/dP + dF/dL (2 directional derivatives)"),
            |bench| {
                bench.iter(|| unsafe {
                    k = k.wrapping_add(1);
                    let l = 0.072 + 1e-5 * (k % 1000) as f64;
                    (api.fmi2SetReal)(inst.c, inputs.as_ptr(), 2, [4e5, l].as_ptr());
                    for (j, seed) in [[1.0, 0.0], [0.0, 1.0]].iter().enumerate() {
                        let status = (api.fmi2GetDirectionalDerivative)(
                            inst.c,
                            [FORCE].as_ptr(),
                            1,
                            inputs.as_ptr(),
                            2,
                            seed.as_ptr(),
                            row[j..].as_mut_ptr(),
                        );
                        debug_assert_eq!(status, 0);
                    }
                    black_box(row)
                })
            },
        );
    }
    group.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30)
}

criterion_group! { name = benches; config = config(); targets = cost }
criterion_main!(benches);
