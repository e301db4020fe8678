//! Native cost of one co-simulation step through the packaged FMU's C ABI: set the inputs, step,
//! get the output, as a master does every communication step. No Python in the loop.

#[path = "../tests/common/mod.rs"]
mod common;

use actuator_fmus::export::REGISTRY;
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

/// The ideal McKibben step against eq. 2.3 hand-inlined behind the same FMI calls. Both
/// FMUs get one fmi2SetReal of one value, one fmi2DoStep and one fmi2GetReal of one value; the
/// PassThrough FMU's step is the FMI layer alone, and eq. 2.3 itself costs about 1 ns on top.
fn ideal_against_inlined(c: &mut Criterion) {
    let mut group = c.benchmark_group("same FMI calls: set one input, step, get one output");
    for (model, input, output, value) in [
        ("PassThrough", "u", "y", 0.5),
        ("McKibbenMuscle", "length", "force", 0.09),
    ] {
        let info = REGISTRY
            .iter()
            .find(|f| f.info().name == model)
            .expect("model")
            .info();
        let api = common::Api::load(&common::extract_binary(model));
        let inst = api
            .instantiate("bench", info.guid)
            .unwrap_or_else(|_| panic!("instantiate"));
        inst.initialize();
        if model == "McKibbenMuscle" {
            assert_eq!(inst.set_real(&[PRESSURE], &[4e5]), common::OK);
        }
        let (vin, vout) = (
            info.by_name(input).expect("input").vr,
            info.by_name(output).expect("output").vr,
        );
        let (mut t, mut k, mut out) = (0.0, 0u32, [0.0]);
        group.bench_function(model, |bench| {
            bench.iter(|| unsafe {
                k = k.wrapping_add(1);
                let x = value + 1e-6 * (k % 1000) as f64;
                (api.fmi2SetReal)(inst.c, &vin, 1, &x);
                (api.fmi2DoStep)(inst.c, t, 1e-3, 1);
                t += 1e-3;
                (api.fmi2GetReal)(inst.c, &vout, 1, out.as_mut_ptr());
                black_box(out[0])
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = mckibben, motor, ideal_against_inlined
}
criterion_main!(benches);
