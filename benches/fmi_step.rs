//! Native cost of one co-simulation step through the packaged FMU's C ABI: set the inputs, step,
//! get the output, as a master does every communication step. No Python in the loop.

#[path = "../tests/common/mod.rs"]
mod common;

use actuator_fmus::physics::gaylord::Sleeve;
use common::mckibben::*;
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Duration;

/// Effect combinations of McKibbenMuscle: (label, integer parameters, boolean parameters).
const COMBINATIONS: &[(&str, [i32; 3], [i32; 1])] = &[
    ("ideal", [1, 0, 16], [0]),
    ("thin wall", [1, 1, 16], [0]),
    ("thick wall, 16 layers", [1, 2, 16], [0]),
    ("thin wall + friction", [1, 1, 16], [1]),
    ("thick wall, 16 layers + friction", [1, 2, 16], [1]),
];

fn mckibben(c: &mut Criterion) {
    use actuator_fmus::variables::mckibben_muscle::{boolean, integer};
    let api = common::Api::load(&common::extract_binary("McKibbenMuscle"));
    let mut group = c.benchmark_group("McKibbenMuscle step");
    let (set, step, get) = (api.fmi2SetReal, api.fmi2DoStep, api.fmi2GetReal);
    let inputs = [PRESSURE, LENGTH];
    for (label, ints, bools) in COMBINATIONS {
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
            assert_eq!(
                (api.fmi2SetBoolean)(
                    inst.c,
                    [boolean::FRICTION as u32].as_ptr(),
                    1,
                    bools.as_ptr()
                ),
                common::OK
            );
        }
        inst.initialize();
        let mut t = 0.0;
        let mut k = 0u32;
        let mut force = [0.0];
        // Muscle A (preset 1) at 400 kPa, the length sweeping 0.70-0.79 of its 103.25 mm, in contact.
        group.bench_function(format!("{label}: set(P, L) + doStep + get(F)"), |bench| {
            bench.iter(|| unsafe {
                k = k.wrapping_add(1);
                let l = 0.072 + 1e-5 * (k % 1000) as f64;
                let s1 = set(inst.c, inputs.as_ptr(), 2, [4e5, l].as_ptr());
                let s2 = step(inst.c, t, 1e-3, 1);
                t += 1e-3;
                let s3 = get(inst.c, [FORCE].as_ptr(), 1, force.as_mut_ptr());
                debug_assert!(s1 == 0 && s2 == 0 && s3 == 0);
                black_box(force[0])
            })
        });
    }
    group.finish();
    // The physics alone, for the share of the ideal step that is FMI plumbing.
    let sleeve = Sleeve::new(0.1113, 3.74).unwrap();
    c.bench_function("eq. 2.3 alone (no FMI)", |bench| {
        bench.iter(|| black_box(sleeve.force(black_box(4e5), black_box(0.09))))
    });
}

/// The motor under its stepping schedule, one 1 us communication step per iteration.
fn motor(c: &mut Criterion) {
    use actuator_fmus::variables::multiferroic_motor::{integer, real};
    let api = common::Api::load(&common::extract_binary("MultiferroicMotor"));
    let inst = api
        .instantiate("bench", &common::guid_of("MultiferroicMotor"))
        .unwrap_or_else(|_| panic!("instantiate"));
    unsafe {
        assert_eq!(
            (api.fmi2SetInteger)(inst.c, [integer::SCHEDULE as u32].as_ptr(), 1, [1].as_ptr()),
            common::OK
        );
    }
    inst.initialize();
    let mut t = 0.0;
    let mut angle = [0.0];
    c.bench_function(
        "MultiferroicMotor step/stepping schedule: doStep(1 us) + get(rotor_angle)",
        |bench| {
            bench.iter(|| unsafe {
                let s1 = (api.fmi2DoStep)(inst.c, t, 1e-6, 1);
                t += 1e-6;
                let s2 = (api.fmi2GetReal)(
                    inst.c,
                    [real::ROTOR_ANGLE as u32].as_ptr(),
                    1,
                    angle.as_mut_ptr(),
                );
                debug_assert!(s1 <= 1 && s2 <= 1);
                black_box(angle[0])
            })
        },
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = mckibben, motor
}
criterion_main!(benches);
