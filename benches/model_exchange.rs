//! Native cost of Model Exchange's right-hand side against a co-simulation step, through the
//! packaged PulleyJoint's C ABI: fmi2SetTime + fmi2SetContinuousStates + fmi2GetDerivatives (one
//! integrator evaluation) and the Jacobian column of one state (fmi2GetDirectionalDerivative over
//! both derivatives), against fmi2SetReal(forces) + fmi2DoStep + fmi2GetReal(angle).

#[path = "../tests/common/mod.rs"]
mod common;

use actuator_fmus::variables::pulley_joint::real;
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::ffi::c_int;
use std::time::Duration;

type Component = common::Component;

#[repr(C)]
#[derive(Default)]
struct EventInfo {
    flags: [c_int; 5],
    next_event_time: f64,
}

fn cost(c: &mut Criterion) {
    let so = common::extract_binary("PulleyJoint");
    let api = common::Api::load(&so);
    // The Model Exchange functions of the same binary.
    let lib = unsafe { libloading::Library::new(&so) }.expect("load");
    let symbol = |name: &str| {
        let name = format!("{name}\0");
        name.into_bytes()
    };
    unsafe {
        let set_time: libloading::Symbol<unsafe extern "C" fn(Component, f64) -> c_int> =
            lib.get(&symbol("fmi2SetTime")).expect("fmi2SetTime");
        let set_states: libloading::Symbol<
            unsafe extern "C" fn(Component, *const f64, usize) -> c_int,
        > = lib
            .get(&symbol("fmi2SetContinuousStates"))
            .expect("fmi2SetContinuousStates");
        let derivatives: libloading::Symbol<
            unsafe extern "C" fn(Component, *mut f64, usize) -> c_int,
        > = lib
            .get(&symbol("fmi2GetDerivatives"))
            .expect("fmi2GetDerivatives");
        let new_discrete_states: libloading::Symbol<
            unsafe extern "C" fn(Component, *mut EventInfo) -> c_int,
        > = lib
            .get(&symbol("fmi2NewDiscreteStates"))
            .expect("fmi2NewDiscreteStates");
        let continuous_time: libloading::Symbol<unsafe extern "C" fn(Component) -> c_int> = lib
            .get(&symbol("fmi2EnterContinuousTimeMode"))
            .expect("fmi2EnterContinuousTimeMode");

        let mut group = c.benchmark_group("PulleyJoint");
        let guid = common::guid_of("PulleyJoint");
        let forces = [real::FLEXOR_FORCE as u32, real::EXTENSOR_FORCE as u32];

        let Ok(cs) = api.instantiate("cs", &guid) else {
            panic!("instantiate")
        };
        cs.initialize();
        let (mut t, mut out) = (0.0, [0.0]);
        group.bench_function(
            "Co-Simulation: set(forces) + doStep(1 ms) + get(angle)",
            |b| {
                b.iter(|| {
                    cs.set_real(&forces, &[10.0, 5.0]);
                    (api.fmi2DoStep)(cs.c, t, 1e-3, 1);
                    t += 1e-3;
                    (api.fmi2GetReal)(
                        cs.c,
                        [real::JOINT_ANGLE as u32].as_ptr(),
                        1,
                        out.as_mut_ptr(),
                    );
                    black_box(out[0])
                })
            },
        );

        let Ok(me) = api.instantiate_as("me", &guid, 0) else {
            panic!("instantiate")
        };
        me.initialize();
        me.set_real(&forces, &[10.0, 5.0]);
        let mut info = EventInfo::default();
        assert_eq!(new_discrete_states(me.c, &mut info), common::OK);
        assert_eq!(continuous_time(me.c), common::OK);
        let (mut time, mut x, mut dx) = (0.0, [0.1, 0.2], [0.0; 2]);
        group.bench_function(
            "Model Exchange: setTime + setContinuousStates + getDerivatives",
            |b| {
                b.iter(|| {
                    time += 1e-6;
                    x[0] += 1e-9;
                    set_time(me.c, time);
                    set_states(me.c, x.as_ptr(), 2);
                    derivatives(me.c, dx.as_mut_ptr(), 2);
                    black_box(dx)
                })
            },
        );
        let unknowns = [
            real::DER_JOINT_ANGLE as u32,
            real::DER_JOINT_VELOCITY as u32,
        ];
        let knowns = [real::JOINT_ANGLE as u32];
        let mut column = [0.0; 2];
        group.bench_function(
            "Model Exchange: d(derivatives)/d(joint_angle) (one directional derivative)",
            |b| {
                b.iter(|| {
                    (api.fmi2GetDirectionalDerivative)(
                        me.c,
                        unknowns.as_ptr(),
                        2,
                        knowns.as_ptr(),
                        1,
                        [1.0].as_ptr(),
                        column.as_mut_ptr(),
                    );
                    black_box(column)
                })
            },
        );
        group.finish();
    }
}

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30)
}

criterion_group! { name = benches; config = config(); targets = cost }
criterion_main!(benches);
