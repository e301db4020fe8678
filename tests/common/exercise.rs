//! Drives any packaged FMU the same way in the load test, the restore test and the native memcheck
//! harness: "all effects on" parameters and deterministic inputs inside the declared ranges.
#![allow(dead_code)]

use super::common::*;
use actuator_fmus::fmi2::REGISTRY;
use actuator_fmus::variables::{Causality, ModelInfo, Start, VarType};
use std::ffi::{c_char, c_int};

/// Every model in the binary (the generated registry): its name and variable tables.
pub fn models() -> Vec<&'static ModelInfo> {
    REGISTRY.iter().map(|f| f.info()).collect()
}

pub fn info_of(model: &str) -> &'static ModelInfo {
    models()
        .into_iter()
        .find(|i| i.name == model)
        .unwrap_or_else(|| panic!("no model {model}"))
}

/// The effect switches of `info` turned to their most elaborate setting: each `*_model` and
/// `schedule` option at its max, `friction` on. KnittedMuscle's non-cylindrical shape (2) has no
/// single bladder diameter, so with the bladder on it takes the tubular knit (1).
pub fn all_effects_on(i: &Instance, info: &ModelInfo) {
    for v in info.variables {
        if v.causality != Causality::Parameter {
            continue;
        }
        let status = match v.kind {
            VarType::Integer if v.name.ends_with("_model") || v.name == "schedule" => {
                let mut x = v.max.unwrap() as c_int;
                if info.name == "KnittedMuscle" && v.name == "shape_model" {
                    x = 1;
                }
                unsafe { (i.api.fmi2SetInteger)(i.c, &v.vr, 1, &x) }
            }
            VarType::Boolean if v.name == "friction" => {
                let x: c_int = 1;
                unsafe { (i.api.fmi2SetBoolean)(i.c, &v.vr, 1, &x) }
            }
            _ => continue,
        };
        assert_eq!(status, OK, "{}.{}: {:?}", info.name, v.name, i.log.lines());
    }
}

/// Integrator substeps per communication step (`max_substeps`, where a model has it). The
/// inputs below spin the motor's rotor hard (a load torque of 5e-8 N m, legal but far above its
/// 2e-18 N m), so a 1 us step used the default budget of 20,000 substeps: 0.2-0.6 s each, hours
/// for the load test and half a minute a step under valgrind. A small budget runs the same code,
/// the budget-exhausted warning included, in about 2 ms.
pub const EXERCISE_SUBSTEPS: c_int = 50;

/// Instantiates, sets all effects on (if asked), bounds the substep budget and initializes.
pub fn ready<'a>(api: &'a Api, info: &ModelInfo, effects: bool) -> Instance<'a> {
    ready_as(api, info, effects, 1)
}

/// As [`ready`], for `fmu_type` 0 (Model Exchange: the instance ends in event mode) or 1.
pub fn ready_as<'a>(
    api: &'a Api,
    info: &ModelInfo,
    effects: bool,
    fmu_type: c_int,
) -> Instance<'a> {
    let i = api
        .instantiate_as("exercise", info.guid, fmu_type)
        .unwrap_or_else(|log| panic!("{} refused: {:?}", info.name, log.lines()));
    assert_eq!(i.setup(), OK);
    assert_eq!(i.enter(), OK);
    if effects {
        all_effects_on(&i, info);
    }
    if let Some(v) = info.by_name("max_substeps") {
        assert_eq!(i.set_integer(&[v.vr], &[EXERCISE_SUBSTEPS]), OK);
    }
    assert_eq!(i.exit(), OK, "{}: {:?}", info.name, i.log.lines());
    i
}

/// Real inputs of `info` with their values for step `n` of run `k`: around the start value
/// (or a tenth of the range when it starts at zero), kept inside the declared range.
pub fn inputs(info: &ModelInfo, k: usize, n: usize) -> (Vec<u32>, Vec<f64>) {
    info.variables
        .iter()
        .filter(|v| v.causality == Causality::Input && v.kind == VarType::Real)
        .enumerate()
        .map(|(j, v)| {
            let wave = (0.37 * n as f64 + 1.3 * (k + j) as f64).sin();
            let start = match v.start {
                Start::Real(s) => s,
                _ => 0.0,
            };
            let x = if start != 0.0 {
                start * (1.0 + 0.1 * wave)
            } else if info.name == "MultiferroicMotor" && v.name == "load_torque" {
                // Up to 1e-13 N m (5e4 times Table 3.1's torque): a tenth of the declared
                // maximum would spin its 350 nm bar past its burst speed, which is refused.
                5e-14 * (1.0 + wave)
            } else {
                0.05 * v.max.unwrap_or(1.0).min(1e6) * (1.0 + wave)
            };
            (
                v.vr,
                x.max(v.min.unwrap_or(f64::MIN))
                    .min(v.max.unwrap_or(f64::MAX)),
            )
        })
        .unzip()
}

/// A communication step that every model takes in a few substeps.
pub fn step_of(info: &ModelInfo) -> f64 {
    if info.name == "MultiferroicMotor" {
        1e-6
    } else {
        1e-3
    }
}

/// Value references of every Real variable.
pub fn all_reals(info: &ModelInfo) -> Vec<u32> {
    (0..info.counts[0] as u32).collect()
}

/// Sets the inputs of step `n` of run `k`, steps, and returns every Real as bits.
pub fn step_and_read(i: &Instance, info: &ModelInfo, k: usize, n: usize) -> Vec<u64> {
    let (vrs, values) = inputs(info, k, n);
    let s = i.set_real(&vrs, &values);
    assert!(
        s <= WARNING,
        "{} set inputs: {:?}",
        info.name,
        i.log.lines()
    );
    let h = step_of(info);
    let s = i.do_step(n as f64 * h, h);
    assert!(
        s <= WARNING,
        "{} step {n}: {s} {:?}",
        info.name,
        i.log.lines()
    );
    let (s, out) = i.get_real(&all_reals(info));
    assert!(s <= WARNING, "{}: {s}", info.name);
    assert!(out.iter().all(|x| x.is_finite()), "{}: {out:?}", info.name);
    out.iter().map(|x| x.to_bits()).collect()
}

/// The serialized bytes of a new FMU state of `i`.
pub fn serialized_state(i: &Instance) -> Vec<c_char> {
    unsafe {
        let mut s = std::ptr::null_mut();
        assert_eq!((i.api.fmi2GetFMUstate)(i.c, &mut s), OK);
        let mut size = 0;
        assert_eq!((i.api.fmi2SerializedFMUstateSize)(i.c, s, &mut size), OK);
        let mut bytes = vec![0 as c_char; size];
        assert_eq!(
            (i.api.fmi2SerializeFMUstate)(i.c, s, bytes.as_mut_ptr(), size),
            OK
        );
        assert_eq!((i.api.fmi2FreeFMUstate)(i.c, &mut s), OK);
        bytes
    }
}

/// Recomputes the trailing FNV-1a checksum of a serialized state after a deliberate edit: a
/// crafted state with a valid checksum, so that the checks behind it are what must refuse it.
pub fn reseal(data: &mut [c_char]) {
    let n = data.len() - 8;
    let sum = data[..n].iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b as u8)).wrapping_mul(0x100_0000_01b3)
    });
    for (k, b) in sum.to_le_bytes().iter().enumerate() {
        data[n + k] = *b as c_char;
    }
}
