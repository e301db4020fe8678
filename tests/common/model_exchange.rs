//! Drives any packaged FMU through Model Exchange the way an importer's integrator does, for the
//! load test and the native memcheck harness: event iteration, continuous-time mode with states,
//! derivatives, event indicators and nominals, explicit Euler steps, completed integrator steps,
//! time events (the motor's schedule switches, the pulley reference's segments) and state events,
//! directional derivatives, an FMU state saved, serialized, restored and one left for
//! `fmi2FreeInstance`. Also the directional derivatives of a Co-Simulation instance.
#![allow(dead_code, non_snake_case)]

use super::common::*;
use super::exercise::*;
use actuator_fmus::variables::{Causality, ModelInfo, VarType};
use std::ffi::c_int;
use std::path::Path;
use std::ptr::null_mut;

/// `fmi2EventInfo`.
#[repr(C)]
#[derive(Default, Debug, Clone, Copy)]
pub struct EventInfo {
    pub new_discrete_states_needed: c_int,
    pub terminate_simulation: c_int,
    pub nominals_changed: c_int,
    pub values_changed: c_int,
    pub next_event_time_defined: c_int,
    pub next_event_time: f64,
}

macro_rules! me_api {
    ($($name:ident: fn($($arg:ty),*) -> c_int;)*) => {
        /// The Model Exchange functions of one loaded binary (or of the crate linked into the
        /// test), beside the common and Co-Simulation ones of [`Api`].
        pub struct MeApi {
            _lib: Option<libloading::Library>,
            $(pub $name: unsafe extern "C" fn($($arg),*) -> c_int,)*
        }
        impl MeApi {
            pub fn load(path: &Path) -> MeApi {
                unsafe {
                    let lib = libloading::Library::new(path).unwrap();
                    $(let $name = *lib.get::<unsafe extern "C" fn($($arg),*) -> c_int>(concat!(stringify!($name), "\0").as_bytes())
                        .unwrap_or_else(|e| panic!("missing symbol {}: {e}", stringify!($name)));)*
                    MeApi { _lib: Some(lib), $($name,)* }
                }
            }
            pub fn linked() -> MeApi {
                extern "C" {
                    $(fn $name($(_: $arg),*) -> c_int;)*
                }
                MeApi { _lib: None, $($name,)* }
            }
        }
    };
}

me_api! {
    fmi2EnterEventMode: fn(Component) -> c_int;
    fmi2NewDiscreteStates: fn(Component, *mut EventInfo) -> c_int;
    fmi2EnterContinuousTimeMode: fn(Component) -> c_int;
    fmi2CompletedIntegratorStep: fn(Component, c_int, *mut c_int, *mut c_int) -> c_int;
    fmi2SetTime: fn(Component, f64) -> c_int;
    fmi2SetContinuousStates: fn(Component, *const f64, usize) -> c_int;
    fmi2GetContinuousStates: fn(Component, *mut f64, usize) -> c_int;
    fmi2GetDerivatives: fn(Component, *mut f64, usize) -> c_int;
    fmi2GetEventIndicators: fn(Component, *mut f64, usize) -> c_int;
    fmi2GetNominalsOfContinuousStates: fn(Component, *mut f64, usize) -> c_int;
}

/// The continuous states of a model as its shipped description declares them: the value
/// references of the states and of their derivatives (`derivative="n"` names the n-th
/// ScalarVariable), and `numberOfEventIndicators`.
pub struct MeShape {
    pub states: Vec<u32>,
    pub derivatives: Vec<u32>,
    pub event_indicators: usize,
}

pub fn me_shape(info: &ModelInfo) -> MeShape {
    let xml = info.model_description_xml;
    let attribute = |text: &str, name: &str| -> Option<String> {
        let start = text.find(&format!(" {name}=\""))? + name.len() + 3;
        let end = text[start..].find('"')? + start;
        Some(text[start..end].to_string())
    };
    let variables = xml
        .split("<ScalarVariable")
        .skip(1)
        .map(|chunk| &chunk[..chunk.find("</ScalarVariable>").unwrap_or(chunk.len())]);
    let mut vrs = Vec::new();
    let mut pairs = Vec::new();
    for (k, v) in variables.enumerate() {
        vrs.push(
            attribute(v, "valueReference")
                .unwrap()
                .parse::<u32>()
                .unwrap(),
        );
        if let Some(n) = attribute(v, "derivative").and_then(|n| n.parse::<usize>().ok()) {
            pairs.push((n - 1, k));
        }
    }
    MeShape {
        states: pairs.iter().map(|&(s, _)| vrs[s]).collect(),
        derivatives: pairs.iter().map(|&(_, d)| vrs[d]).collect(),
        event_indicators: attribute(xml, "numberOfEventIndicators")
            .map_or(0, |n| n.parse().unwrap()),
    }
}

/// One directional derivative per unknown (the outputs, and the state derivatives with
/// `states`), seeded with every input (and state): a model that lacks a row refuses that call
/// with fmi2Error and a logged reason, never fmi2Fatal, and the instance goes on. Returns the
/// computed values as bits (refused rows as NaN's bits).
pub fn directional_derivatives(
    i: &Instance,
    info: &ModelInfo,
    shape: Option<&MeShape>,
) -> Vec<u64> {
    let of = |c: Causality| {
        info.variables
            .iter()
            .filter(move |v| v.kind == VarType::Real && v.causality == c)
            .map(|v| v.vr)
    };
    let mut known: Vec<u32> = of(Causality::Input).collect();
    let mut unknown: Vec<u32> = of(Causality::Output).collect();
    if let Some(shape) = shape {
        known.extend(&shape.states);
        unknown.extend(&shape.derivatives);
    }
    let seed = vec![1.0; known.len()];
    unknown
        .iter()
        .map(|u| {
            let mut out = f64::NAN;
            let s = unsafe {
                (i.api.fmi2GetDirectionalDerivative)(
                    i.c,
                    u,
                    1,
                    known.as_ptr(),
                    known.len(),
                    seed.as_ptr(),
                    &mut out,
                )
            };
            assert!(s <= ERROR, "{} d/d{u}: {s} {:?}", info.name, i.log.lines());
            if s == ERROR {
                assert!(
                    i.log.contains("fmi2GetDirectionalDerivative"),
                    "{}",
                    info.name
                );
                out = f64::NAN;
            } else {
                assert!(out.is_finite(), "{} d/d{u}: {out}", info.name);
            }
            out.to_bits()
        })
        .collect()
}

/// The Model Exchange integration step of `info`. The motor's Gilbert onion tilts at up to
/// 1e10 rad/s under the exercise's inputs (its states are refused beyond 10 rad), so explicit
/// Euler needs picoseconds there; the other models take the Co-Simulation step.
pub fn me_step_of(info: &ModelInfo) -> f64 {
    if info.name == "MultiferroicMotor" {
        1e-12
    } else {
        step_of(info)
    }
}

/// Event mode: iterates `fmi2NewDiscreteStates` to a fixed point (bounded), rereads the states if
/// they changed, returns the last event info.
fn event_iteration(i: &Instance, me: &MeApi, info: &ModelInfo, x: &mut [f64]) -> EventInfo {
    let mut event = EventInfo::default();
    for _ in 0..10 {
        let s = unsafe { (me.fmi2NewDiscreteStates)(i.c, &mut event) };
        assert!(s <= WARNING, "{}: {s} {:?}", info.name, i.log.lines());
        if event.new_discrete_states_needed == 0 {
            break;
        }
    }
    assert_eq!(event.terminate_simulation, 0, "{}", info.name);
    if event.values_changed != 0 {
        let s = unsafe { (me.fmi2GetContinuousStates)(i.c, x.as_mut_ptr(), x.len()) };
        assert!(s <= WARNING, "{}: {:?}", info.name, i.log.lines());
    }
    event
}

/// What a Model Exchange run saw: every value read, as bits (for comparisons between runs), and
/// the events it handled after the initial one.
pub struct MeRun {
    pub values: Vec<u64>,
    pub time_events: usize,
    pub state_events: usize,
}

/// A Model Exchange run of `info` (run `k`, all effects on if `effects`): `steps` Euler steps of
/// the states with the inputs of [`inputs`], halfway a jump to the next time event if there is
/// one, an FMU state round trip, every Real read after each step.
pub fn me_run(
    api: &Api,
    me: &MeApi,
    info: &ModelInfo,
    effects: bool,
    k: usize,
    steps: usize,
) -> MeRun {
    me_run_with(api, me, info, effects, k, steps, &|_| {})
}

/// As [`me_run`], calling `before_step(n)` before step `n` (threads wait at a barrier there).
pub fn me_run_with(
    api: &Api,
    me: &MeApi,
    info: &ModelInfo,
    effects: bool,
    k: usize,
    steps: usize,
    before_step: &dyn Fn(usize),
) -> MeRun {
    let shape = me_shape(info);
    let i = ready_as(api, info, effects, 0);
    let (nx, nz) = (shape.states.len(), shape.event_indicators);
    let (mut x, mut dx, mut z, mut nominal) =
        (vec![0.0; nx], vec![0.0; nx], vec![0.0; nz], vec![0.0; nx]);
    let mut out = Vec::new();
    let (mut time_events, mut state_events) = (0, 0);
    let (vrs, values) = inputs(info, k, 0);
    assert!(i.set_real(&vrs, &values) <= WARNING, "{}", info.name);
    let mut event = event_iteration(&i, me, info, &mut x);
    let check = |s: c_int, what: &str| {
        assert!(
            s <= WARNING,
            "{} {what}: {s} {:?}",
            info.name,
            i.log.lines()
        )
    };
    unsafe {
        check(
            (me.fmi2EnterContinuousTimeMode)(i.c),
            "continuous time mode",
        );
        check(
            (me.fmi2GetContinuousStates)(i.c, x.as_mut_ptr(), nx),
            "states",
        );
        check(
            (me.fmi2GetNominalsOfContinuousStates)(i.c, nominal.as_mut_ptr(), nx),
            "nominals",
        );
        check(
            (me.fmi2GetEventIndicators)(i.c, z.as_mut_ptr(), nz),
            "event indicators",
        );
    }
    assert!(
        nominal.iter().all(|n| *n > 0.0),
        "{}: {nominal:?}",
        info.name
    );
    let h = me_step_of(info);
    let mut t = 0.0;
    for n in 0..steps {
        before_step(n);
        let time_event = event.next_event_time_defined != 0
            && (n == steps / 2 || t + h >= event.next_event_time);
        t = if time_event {
            event.next_event_time
        } else {
            t + h
        };
        let (vrs, values) = inputs(info, k, n);
        let z_before = z.clone();
        unsafe {
            check((me.fmi2SetTime)(i.c, t), "time");
            check(i.set_real(&vrs, &values), "inputs");
            // An explicit Euler step from the last accepted point.
            check(
                (me.fmi2GetDerivatives)(i.c, dx.as_mut_ptr(), nx),
                "derivatives",
            );
            for (x, dx) in x.iter_mut().zip(&dx) {
                *x += h * dx;
            }
            check(
                (me.fmi2SetContinuousStates)(i.c, x.as_ptr(), nx),
                "set states",
            );
            check(
                (me.fmi2GetDerivatives)(i.c, dx.as_mut_ptr(), nx),
                "derivatives",
            );
            check(
                (me.fmi2GetEventIndicators)(i.c, z.as_mut_ptr(), nz),
                "event indicators",
            );
        }
        let state_event = z
            .iter()
            .zip(&z_before)
            .any(|(a, b)| a.signum() != b.signum());
        let (mut enter, mut terminate) = (0, 0);
        unsafe {
            check(
                (me.fmi2CompletedIntegratorStep)(i.c, 1, &mut enter, &mut terminate),
                "completed integrator step",
            );
        }
        assert_eq!(terminate, 0, "{}", info.name);
        time_events += usize::from(time_event);
        state_events += usize::from(state_event || enter != 0);
        if time_event || state_event || enter != 0 {
            unsafe { check((me.fmi2EnterEventMode)(i.c), "event mode") };
            event = event_iteration(&i, me, info, &mut x);
            unsafe {
                check(
                    (me.fmi2EnterContinuousTimeMode)(i.c),
                    "continuous time mode",
                );
                check(
                    (me.fmi2GetEventIndicators)(i.c, z.as_mut_ptr(), nz),
                    "event indicators",
                );
            }
        }
        let (s, reals) = i.get_real(&all_reals(info));
        check(s, "outputs");
        assert!(
            reals.iter().all(|x| x.is_finite()),
            "{}: {reals:?}",
            info.name
        );
        out.extend(reals.iter().chain(&x).chain(&dx).map(|v| v.to_bits()));
        if n == 1 || n == steps / 2 + 1 {
            out.extend(directional_derivatives(&i, info, Some(&shape)));
        }
        if n == steps / 4 {
            fmu_state_round_trip(&i, info);
        }
    }
    unsafe { check((i.api.fmi2Terminate)(i.c), "terminate") };
    MeRun {
        values: out,
        time_events,
        state_events,
    }
}

/// Saves, serializes, deserializes and restores an FMU state of `i`, and leaves one saved state
/// for `fmi2FreeInstance` to free.
pub fn fmu_state_round_trip(i: &Instance, info: &ModelInfo) {
    let bytes = serialized_state(i);
    unsafe {
        let mut s = null_mut();
        let st = (i.api.fmi2DeSerializeFMUstate)(i.c, bytes.as_ptr(), bytes.len(), &mut s);
        assert_eq!(st, OK, "{}: {:?}", info.name, i.log.lines());
        assert_eq!(
            (i.api.fmi2SetFMUstate)(i.c, s),
            OK,
            "{}: {:?}",
            info.name,
            i.log.lines()
        );
        assert_eq!((i.api.fmi2FreeFMUstate)(i.c, &mut s), OK);
        let mut kept = null_mut();
        assert_eq!((i.api.fmi2GetFMUstate)(i.c, &mut kept), OK);
    }
}
