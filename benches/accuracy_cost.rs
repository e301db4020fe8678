//! Time per communication step of every fidelity configuration, natively through each packaged
//! FMU's C ABI (criterion; no Python in the loop). `benches/report.py` pairs these times with each
//! configuration's error against a converged reference and writes docs/accuracy-cost.md.
//!
//! Each configuration is named `<FMU>/<knob>/<value>`; its inputs follow the same scenario as the
//! report's accuracy runs, so time and error describe the same work. Times are the benchmark
//! thread's CPU time (`cpu_clock.rs`), so that they reproduce on a loaded machine.

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "cpu_clock.rs"]
mod cpu_clock;

use actuator_fmus::export::REGISTRY;
use actuator_fmus::variables::VarType;
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Duration;

/// A fidelity configuration: parameter start values by name.
struct Config {
    fmu: &'static str,
    knob: &'static str,
    value: String,
    parameters: Vec<(&'static str, f64)>,
}

fn config(
    fmu: &'static str,
    knob: &'static str,
    value: impl ToString,
    parameters: &[(&'static str, f64)],
) -> Config {
    Config {
        fmu,
        knob,
        value: value.to_string(),
        parameters: parameters.to_vec(),
    }
}

/// The scenarios of the report (benches/report.py SCENARIOS): the inputs at iteration k.
fn inputs(fmu: &str, k: u64) -> Vec<(&'static str, f64)> {
    let phase = (k % 200) as f64 / 200.0;
    match fmu {
        // Muscle A at 690 kPa over 0.75-0.93 of its listed length (in contact, below the limit).
        "McKibbenMuscle" => vec![
            ("pressure", 6.9e5),
            ("length", 0.10325 * (0.75 + 0.18 * phase)),
        ],
        // The prototype at 14 kPa over 40-95% of its 514 mm.
        "KnittedMuscle" => vec![
            ("pressure", 1.4e4),
            ("length", 0.514 * (0.40 + 0.55 * phase)),
        ],
        "PassThrough" => vec![("u", phase)],
        // The schedule drives the motor; the load input is set so that every FMU's step sets one.
        "MultiferroicMotor" => vec![("load_torque", 0.0)],
        _ => vec![],
    }
}

fn configurations() -> Vec<Config> {
    let mut c = vec![config("PassThrough", "baseline", "y = u", &[])];
    let a = [("preset", 1.0)];
    c.push(config(
        "McKibbenMuscle",
        "bladder_model",
        "none",
        &[a[0], ("bladder_model", 0.0)],
    ));
    c.push(config(
        "McKibbenMuscle",
        "bladder_model",
        "thin",
        &[a[0], ("bladder_model", 1.0)],
    ));
    for layers in [1, 2, 4, 8, 16, 32, 64] {
        c.push(config(
            "McKibbenMuscle",
            "bladder_layers",
            layers,
            &[
                a[0],
                ("bladder_model", 2.0),
                ("bladder_layers", layers as f64),
            ],
        ));
    }
    for nodes in [2, 4, 8, 16] {
        c.push(config(
            "McKibbenMuscle",
            "bladder_exact",
            nodes,
            &[
                a[0],
                ("bladder_model", 3.0),
                ("bladder_layers", nodes as f64),
            ],
        ));
    }
    c.push(config(
        "McKibbenMuscle",
        "friction",
        "on (thin)",
        &[a[0], ("bladder_model", 1.0), ("friction", 1.0)],
    ));
    c.push(config(
        "KnittedMuscle",
        "shape_model",
        "ideal",
        &[("shape_model", 0.0)],
    ));
    c.push(config(
        "KnittedMuscle",
        "shape_model",
        "tubular",
        &[("shape_model", 1.0)],
    ));
    for segments in [12, 24, 49, 98] {
        c.push(config(
            "KnittedMuscle",
            "shape_segments",
            segments,
            &[("shape_model", 2.0), ("shape_segments", segments as f64)],
        ));
    }
    c.push(config(
        "KnittedMuscle",
        "friction",
        "on (ideal)",
        &[("shape_model", 0.0), ("friction", 1.0)],
    ));
    let stepping = [("schedule", 1.0)];
    for tolerance in ["1e-3", "1e-4", "1e-5", "1e-6", "1e-7", "1e-8"] {
        let value: f64 = tolerance.parse().expect("a number");
        c.push(config(
            "MultiferroicMotor",
            "tolerance",
            tolerance,
            &[stepping[0], ("tolerance", value)],
        ));
    }
    c.push(config(
        "MultiferroicMotor",
        "onion_model",
        "gilbert",
        &[stepping[0], ("onion_model", 1.0)],
    ));
    c
}

fn accuracy_cost(c: &mut Criterion<cpu_clock::ThreadCpuTime>) {
    let mut apis = std::collections::BTreeMap::new();
    let mut group = c.benchmark_group("accuracy_cost");
    for cfg in configurations() {
        let Some(factory) = REGISTRY.iter().find(|f| f.info().name == cfg.fmu) else {
            eprintln!("skipping {}: no such FMU in this build", cfg.fmu);
            continue;
        };
        let info = factory.info();
        let api = apis
            .entry(cfg.fmu)
            .or_insert_with(|| common::Api::load(&common::extract_binary(cfg.fmu)));
        let api: &common::Api = api;
        let inst = api
            .instantiate("bench", info.guid)
            .unwrap_or_else(|log| panic!("{}: {:?}", cfg.fmu, log.lines()));
        for (name, value) in &cfg.parameters {
            let var = info
                .by_name(name)
                .unwrap_or_else(|| panic!("{}: no parameter {name}", cfg.fmu));
            let status = unsafe {
                match var.kind {
                    VarType::Real => (api.fmi2SetReal)(inst.c, &var.vr, 1, value),
                    VarType::Integer => (api.fmi2SetInteger)(inst.c, &var.vr, 1, &(*value as i32)),
                    _ => (api.fmi2SetBoolean)(inst.c, &var.vr, 1, &(*value as i32)),
                }
            };
            assert_eq!(
                status,
                common::OK,
                "{}: setting {name}: {:?}",
                cfg.fmu,
                inst.log.lines()
            );
        }
        let set: Vec<(u32, &str)> = inputs(cfg.fmu, 0)
            .iter()
            .map(|(n, _)| (info.by_name(n).expect("input").vr, *n))
            .collect();
        let first: Vec<f64> = inputs(cfg.fmu, 0).iter().map(|(_, v)| *v).collect();
        inst.set_real(&set.iter().map(|(vr, _)| *vr).collect::<Vec<_>>(), &first);
        inst.initialize();
        let out_vr = info
            .variables
            .iter()
            .find(|v| v.causality == actuator_fmus::variables::Causality::Output)
            .expect("an output")
            .vr;
        let vrs: Vec<u32> = set.iter().map(|(vr, _)| *vr).collect();
        // The motor's communication step is 1 us; the muscles' 1 ms.
        let h = if cfg.fmu == "MultiferroicMotor" {
            1e-6
        } else {
            1e-3
        };
        let (mut t, mut k) = (0.0, 0u64);
        let mut values = vec![0.0; vrs.len()];
        let mut out = [0.0];
        group.bench_function(format!("{}/{}/{}", cfg.fmu, cfg.knob, cfg.value), |bench| {
            bench.iter(|| unsafe {
                k += 1;
                for (slot, (_, v)) in values.iter_mut().zip(inputs(cfg.fmu, k)) {
                    *slot = v;
                }
                (api.fmi2SetReal)(inst.c, vrs.as_ptr(), vrs.len(), values.as_ptr());
                let status = (api.fmi2DoStep)(inst.c, t, h, 1);
                t += h;
                (api.fmi2GetReal)(inst.c, &out_vr, 1, out.as_mut_ptr());
                black_box((status, out[0]))
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .with_measurement(cpu_clock::ThreadCpuTime)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500))
        .sample_size(30);
    targets = accuracy_cost
}
criterion_main!(benches);
