//! The native half of `make memcheck`: every packaged FMU loaded through its C ABI (no Python),
//! run under valgrind with a leak check that counts definite and indirect leaks as errors.
//!
//! - every model twice, with default parameters and with all effects on, over 40 steps of inputs
//!   inside their declared ranges, through an FMU state get / serialize / deserialize / set (the
//!   motor's substep budget bounded, see `exercise::EXERCISE_SUBSTEPS`), with directional
//!   derivatives of every output;
//! - every model twice more through Model Exchange (`model_exchange::me_run`): event iteration,
//!   states, derivatives, event indicators, nominals, Euler steps, completed integrator steps,
//!   a time event (the motor's schedule switch, the pulley reference's segment end), directional
//!   derivatives of outputs and state derivatives, an FMU state round trip;
//! - every catalogue scene (`scenes/*.json`, fast variant) with its parameters, inputs and every
//!   sweep value;
//! - every instance and FMU state freed, so anything left is a leak of ours.
//!
//! `cargo run --release --example memcheck_native` runs it without valgrind (a few seconds).

#[path = "../../tests/common/mod.rs"]
mod common;
#[path = "../../tests/common/exercise.rs"]
mod exercise;
#[path = "../../tests/common/model_exchange.rs"]
mod model_exchange;

use actuator_fmus::variables::{ModelInfo, VarType};
use actuator_fmus_tools::scene::{Scene, Value};
use common::*;
use exercise::*;
use model_exchange::*;
use std::ffi::c_int;
use std::path::Path;
use std::ptr::null_mut;

fn models_run(api: &Api, info: &ModelInfo, effects: bool) -> usize {
    let i = ready(api, info, effects);
    let mut steps = 0;
    for n in 0..20 {
        step_and_read(&i, info, 0, n);
        steps += 1;
    }
    directional_derivatives(&i, info, None);
    // Through a serialized state and back, then on.
    let bytes = serialized_state(&i);
    unsafe {
        let mut s = null_mut();
        let st = (api.fmi2DeSerializeFMUstate)(i.c, bytes.as_ptr(), bytes.len(), &mut s);
        assert_eq!(st, OK, "{}: {:?}", info.name, i.log.lines());
        assert_eq!((api.fmi2SetFMUstate)(i.c, s), OK);
        // One state left for fmi2FreeInstance to free.
        let mut kept = null_mut();
        assert_eq!((api.fmi2GetFMUstate)(i.c, &mut kept), OK);
        assert_eq!((api.fmi2FreeFMUstate)(i.c, &mut s), OK);
    }
    for n in 20..40 {
        step_and_read(&i, info, 0, n);
        steps += 1;
    }
    unsafe {
        assert_eq!((api.fmi2Terminate)(i.c), OK);
        assert_eq!((api.fmi2Reset)(i.c), OK);
    }
    steps
}

/// One run of `scene` (with the sweep value `sweep` if any): parameters, inputs at t, a step.
fn scene_run(api: &Api, info: &ModelInfo, scene: &Scene, sweep: Option<usize>) -> usize {
    let i = api
        .instantiate("memcheck", info.guid)
        .unwrap_or_else(|l| panic!("{:?}", l.lines()));
    assert_eq!(i.setup(), OK);
    assert_eq!(i.enter(), OK);
    let var = |name: &str| {
        info.variables
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("{}: no variable {name}", info.name))
    };
    let set = |name: &str, x: f64| {
        let v = var(name);
        let s = unsafe {
            match v.kind {
                VarType::Real => (api.fmi2SetReal)(i.c, &v.vr, 1, &x),
                VarType::Integer => (api.fmi2SetInteger)(i.c, &v.vr, 1, &(x as c_int)),
                VarType::Boolean => (api.fmi2SetBoolean)(i.c, &v.vr, 1, &c_int::from(x != 0.0)),
                VarType::String => panic!("string parameter {name}"),
            }
        };
        assert!(s <= WARNING, "{name} = {x}: {:?}", i.log.lines());
    };
    for (name, value) in &scene.parameters {
        set(
            name,
            match value {
                Value::Bool(b) => f64::from(u8::from(*b)),
                Value::Number(x) => *x,
            },
        );
    }
    if let (Some(sw), Some(k)) = (&scene.sweep, sweep) {
        set(&sw.variable, sw.values[k]);
        for (name, values) in &sw.also {
            set(name, values[k]);
        }
    }
    for (name, signal) in &scene.inputs {
        if let Some(x) = signal.at(0.0, scene.stop_time) {
            set(name, x);
        }
    }
    // A Warning (an input outside the valid range, logged) is a legal outcome of a scene.
    assert!(i.exit() <= WARNING, "{}: {:?}", info.name, i.log.lines());
    let outputs: Vec<u32> = scene.outputs.iter().map(|n| var(n).vr).collect();
    let n = (scene.stop_time / scene.step).round() as usize;
    for k in 0..n {
        let t = k as f64 * scene.step;
        for (name, signal) in &scene.inputs {
            if let Some(x) = signal.at(t, scene.stop_time) {
                set(name, x);
            }
        }
        let s = i.do_step(t, scene.step);
        assert!(s <= WARNING, "{} step {k}: {:?}", info.name, i.log.lines());
        let (s, values) = i.get_real(&outputs);
        assert!(s <= WARNING && values.iter().all(|x| x.is_finite()));
    }
    n
}

fn main() {
    // The repository root (this example is built in tools/).
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let apis: Vec<(&ModelInfo, Api, MeApi)> = models()
        .into_iter()
        .map(|info| {
            let path = extract_binary(info.name);
            (info, Api::load(&path), MeApi::load(&path))
        })
        .collect();
    let api_of = |name: &str| {
        apis.iter()
            .find(|(i, _, _)| i.name == name)
            .map(|(i, api, _)| (i, api))
            .unwrap_or_else(|| panic!("no FMU {name}"))
    };
    for (info, api, me) in &apis {
        let t0 = std::time::Instant::now();
        let steps = models_run(api, info, false);
        let t1 = t0.elapsed();
        let steps = steps + models_run(api, info, true);
        println!(
            "{}: default and all effects on, {steps} steps ({:.2?} + {:.2?})",
            info.name,
            t1,
            t0.elapsed() - t1
        );
        let t0 = std::time::Instant::now();
        const ME_STEPS: usize = 40;
        let runs = [
            me_run(api, me, info, false, 0, ME_STEPS),
            me_run(api, me, info, true, 1, ME_STEPS),
        ];
        println!(
            "{}: Model Exchange, {} states, default and all effects on, {} steps, {} time and {} \
             state events ({:.2?})",
            info.name,
            me_shape(info).states.len(),
            2 * ME_STEPS,
            runs.iter().map(|r| r.time_events).sum::<usize>(),
            runs.iter().map(|r| r.state_events).sum::<usize>(),
            t0.elapsed()
        );
    }
    let mut paths: Vec<_> = std::fs::read_dir(root.join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    for path in &paths {
        let scene = Scene::from_json(&std::fs::read_to_string(path).unwrap())
            .unwrap()
            .fast();
        let (info, api) = api_of(&scene.fmu);
        let sweeps: Vec<Option<usize>> = match &scene.sweep {
            Some(s) => (0..s.values.len()).map(Some).collect(),
            None => vec![None],
        };
        let steps: usize = sweeps
            .iter()
            .map(|&k| scene_run(api, info, &scene, k))
            .sum();
        println!(
            "{}: {} runs, {steps} steps",
            path.file_name().unwrap().to_string_lossy(),
            sweeps.len()
        );
    }
    println!(
        "memcheck_native: {} FMUs and {} scenes done",
        apis.len(),
        paths.len()
    );
}
