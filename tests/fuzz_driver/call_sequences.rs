//! The fuzz harness's logic, shared by `fuzz/fuzz_targets/call_sequences.rs` (libFuzzer) and
//! `tests/all/fuzz_corpus.rs` (the committed corpus replayed in `make test`).
//!
//! Interprets the fuzzer's bytes as a sequence of FMI 2.0 calls, Co-Simulation and Model Exchange,
//! on up to four instances of any model in the binary (named by a stable id, [`MODEL_IDS`]), with
//! random value references, NaN/inf/huge values and states, right and wrong vector sizes, NULL or
//! valid buffers, and random call order. The FMU must never crash or hang, never return fmi2Fatal
//! (a caught panic), never refuse without logging why, and never hand out a NaN or infinity with
//! an OK or Warning status (fmi2GetReal, the state-sized Model Exchange getters, directional
//! derivatives, the next event time).
//!
//! Pointers passed are only NULL or valid buffers of the declared size, live instances and live
//! FMU states: anything else would be undefined behaviour on the importer's side, not ours.
#![allow(dead_code)]

use actuator_fmus::fmi2::runtime::Factory;
use actuator_fmus::fmi2::types::*;
use actuator_fmus::fmi2::REGISTRY;
use actuator_fmus::variables::{Causality, ModelInfo, Start, VarType};
use arbitrary::{Result, Unstructured};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicUsize, Ordering};

// The exported functions, linked from the crate (not loaded): the fuzzer sees their coverage.
extern "C" {
    fn fmi2Instantiate(
        name: fmi2String,
        kind: c_int,
        guid: fmi2String,
        resources: fmi2String,
        functions: *const fmi2CallbackFunctions,
        visible: fmi2Boolean,
        logging_on: fmi2Boolean,
    ) -> fmi2Component;
    fn fmi2FreeInstance(c: fmi2Component);
    fn fmi2SetDebugLogging(
        c: fmi2Component,
        on: fmi2Boolean,
        n: usize,
        cats: *const fmi2String,
    ) -> fmi2Status;
    fn fmi2SetupExperiment(
        c: fmi2Component,
        tol_def: fmi2Boolean,
        tol: f64,
        start: f64,
        stop_def: fmi2Boolean,
        stop: f64,
    ) -> fmi2Status;
    fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status;
    fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status;
    fn fmi2Terminate(c: fmi2Component) -> fmi2Status;
    fn fmi2Reset(c: fmi2Component) -> fmi2Status;
    fn fmi2GetReal(c: fmi2Component, vr: *const u32, n: usize, v: *mut f64) -> fmi2Status;
    fn fmi2GetInteger(c: fmi2Component, vr: *const u32, n: usize, v: *mut c_int) -> fmi2Status;
    fn fmi2GetBoolean(c: fmi2Component, vr: *const u32, n: usize, v: *mut c_int) -> fmi2Status;
    fn fmi2GetString(c: fmi2Component, vr: *const u32, n: usize, v: *mut fmi2String) -> fmi2Status;
    fn fmi2SetReal(c: fmi2Component, vr: *const u32, n: usize, v: *const f64) -> fmi2Status;
    fn fmi2SetInteger(c: fmi2Component, vr: *const u32, n: usize, v: *const c_int) -> fmi2Status;
    fn fmi2SetBoolean(c: fmi2Component, vr: *const u32, n: usize, v: *const c_int) -> fmi2Status;
    fn fmi2SetString(
        c: fmi2Component,
        vr: *const u32,
        n: usize,
        v: *const fmi2String,
    ) -> fmi2Status;
    fn fmi2GetFMUstate(c: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status;
    fn fmi2SetFMUstate(c: fmi2Component, s: fmi2FMUstate) -> fmi2Status;
    fn fmi2FreeFMUstate(c: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status;
    fn fmi2SerializedFMUstateSize(
        c: fmi2Component,
        s: fmi2FMUstate,
        size: *mut usize,
    ) -> fmi2Status;
    fn fmi2SerializeFMUstate(
        c: fmi2Component,
        s: fmi2FMUstate,
        b: *mut c_char,
        size: usize,
    ) -> fmi2Status;
    fn fmi2DeSerializeFMUstate(
        c: fmi2Component,
        b: *const c_char,
        size: usize,
        s: *mut fmi2FMUstate,
    ) -> fmi2Status;
    fn fmi2DoStep(c: fmi2Component, t: f64, h: f64, no_prior: fmi2Boolean) -> fmi2Status;
    fn fmi2CancelStep(c: fmi2Component) -> fmi2Status;
    fn fmi2GetStatus(c: fmi2Component, kind: c_int, v: *mut c_int) -> fmi2Status;
    fn fmi2GetRealStatus(c: fmi2Component, kind: c_int, v: *mut f64) -> fmi2Status;
    fn fmi2GetIntegerStatus(c: fmi2Component, kind: c_int, v: *mut c_int) -> fmi2Status;
    fn fmi2GetBooleanStatus(c: fmi2Component, kind: c_int, v: *mut c_int) -> fmi2Status;
    fn fmi2GetStringStatus(c: fmi2Component, kind: c_int, v: *mut fmi2String) -> fmi2Status;
    fn fmi2GetDirectionalDerivative(
        c: fmi2Component,
        unknown: *const u32,
        n_unknown: usize,
        known: *const u32,
        n_known: usize,
        dv_known: *const f64,
        dv_unknown: *mut f64,
    ) -> fmi2Status;
    fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status;
    fn fmi2NewDiscreteStates(c: fmi2Component, info: *mut EventInfo) -> fmi2Status;
    fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status;
    fn fmi2CompletedIntegratorStep(
        c: fmi2Component,
        no_prior: fmi2Boolean,
        enter_event_mode: *mut fmi2Boolean,
        terminate: *mut fmi2Boolean,
    ) -> fmi2Status;
    fn fmi2SetTime(c: fmi2Component, t: f64) -> fmi2Status;
    fn fmi2SetContinuousStates(c: fmi2Component, x: *const f64, nx: usize) -> fmi2Status;
    fn fmi2GetContinuousStates(c: fmi2Component, x: *mut f64, nx: usize) -> fmi2Status;
    fn fmi2GetDerivatives(c: fmi2Component, dx: *mut f64, nx: usize) -> fmi2Status;
    fn fmi2GetEventIndicators(c: fmi2Component, z: *mut f64, ni: usize) -> fmi2Status;
    fn fmi2GetNominalsOfContinuousStates(c: fmi2Component, x: *mut f64, nx: usize) -> fmi2Status;
}

/// `fmi2EventInfo` as the importer declares it (fmi2FunctionTypes.h).
#[repr(C)]
#[derive(Default)]
struct EventInfo {
    new_discrete_states_needed: fmi2Boolean,
    terminate_simulation: fmi2Boolean,
    nominals_of_continuous_states_changed: fmi2Boolean,
    values_of_continuous_states_changed: fmi2Boolean,
    next_event_time_defined: fmi2Boolean,
    next_event_time: f64,
}

/// The Model Exchange sizes of a model, (continuous states, event indicators), read once from
/// the model description it ships: the harness knows only what an importer knows.
pub fn me_sizes(info: &ModelInfo) -> (usize, usize) {
    static SIZES: std::sync::OnceLock<Vec<(&'static str, usize, usize)>> =
        std::sync::OnceLock::new();
    let sizes = SIZES.get_or_init(|| {
        REGISTRY
            .iter()
            .map(|f| {
                let xml = f.info().model_description_xml;
                // A state's derivative declares it: derivative="<index>".
                let nx = xml
                    .match_indices("derivative=\"")
                    .filter(|(at, m)| xml[at + m.len()..].starts_with(|c: char| c.is_ascii_digit()))
                    .count();
                let ni = xml
                    .split_once("numberOfEventIndicators=\"")
                    .and_then(|(_, rest)| rest.split('"').next()?.parse().ok())
                    .unwrap_or(0);
                (f.info().name, nx, ni)
            })
            .collect()
    });
    sizes
        .iter()
        .find(|s| s.0 == info.name)
        .map_or((0, 0), |s| (s.1, s.2))
}

/// Messages logged for one instance.
#[derive(Default)]
struct Counter(AtomicUsize);

unsafe extern "C" fn count(
    env: *mut c_void,
    name: fmi2String,
    _status: c_int,
    category: fmi2String,
    message: fmi2String,
) {
    assert!(!name.is_null() && !category.is_null() && !message.is_null());
    // Reading them proves they are NUL-terminated.
    let _ = (
        CStr::from_ptr(name),
        CStr::from_ptr(category),
        CStr::from_ptr(message),
    );
    if let Some(counter) = (env as *const Counter).as_ref() {
        counter.0.fetch_add(1, Ordering::Relaxed);
    }
}

fn logger() -> fmi2CallbackLogger {
    // SAFETY: the FMU calls its logger as C-variadic with exactly these five arguments and no
    // variadic ones, which x86-64 and AArch64 Linux pass like this fixed signature.
    unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(*mut c_void, fmi2String, c_int, fmi2String, fmi2String),
            fmi2CallbackLogger,
        >(count)
    }
}

struct Slot {
    c: fmi2Component,
    info: &'static ModelInfo,
    /// The communication point this driver believes the instance is at.
    time: f64,
    /// Live FMU states of this instance.
    states: Vec<fmi2FMUstate>,
    log: Box<Counter>,
    /// Whether the importer gave a logger (without one, refusals cannot be logged).
    logging: bool,
    /// Instantiated for Model Exchange.
    model_exchange: bool,
    _callbacks: Box<fmi2CallbackFunctions>,
}

const SLOTS: usize = 4;

struct Driver {
    slots: [Option<Slot>; SLOTS],
    calls: usize,
}

impl Drop for Driver {
    fn drop(&mut self) {
        for slot in self.slots.iter_mut().filter_map(Option::take) {
            // Some states are freed explicitly, the rest with the instance.
            unsafe { fmi2FreeInstance(slot.c) };
        }
    }
}

fn real(u: &mut Unstructured, hint: Option<(&Start, Option<f64>, Option<f64>)>) -> Result<f64> {
    let special = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e300,
        -1e300,
        f64::MAX,
        f64::MIN_POSITIVE,
        f64::from_bits(1),
        1e-12,
        1e6,
    ];
    Ok(match u.int_in_range(0..=5)? {
        0 => special[u.choose_index(special.len())?],
        1 => f64::from_bits(u.arbitrary()?),
        2 => match hint {
            Some((Start::Real(s), _, _)) => *s * (1.0 + f64::from(u.arbitrary::<i8>()?) / 64.0),
            _ => f64::from(u.arbitrary::<i16>()?) * 1e-3,
        },
        3 => hint.and_then(|h| h.1).unwrap_or(0.0),
        4 => hint.and_then(|h| h.2).unwrap_or(1.0),
        _ => f64::from(u.arbitrary::<i16>()?) * 1e-3,
    })
}

fn integer(u: &mut Unstructured) -> Result<c_int> {
    // Small values only: a valid but huge substep budget would make a legal step slow, not wrong.
    let special = [-1, 0, 1, 2, 3, 4, 5, 16, c_int::MIN, c_int::MAX];
    Ok(if u.arbitrary()? {
        special[u.choose_index(special.len())?]
    } else {
        c_int::from(u.arbitrary::<u8>()?)
    })
}

/// Keeps the cost of a sequence low without losing a class of input: a KnittedMuscle with
/// `shape_model` 2 builds its shape table (tens of ms for the default 49 segments, more for
/// more) each time its parameters change, which made such sequences thousands of times dearer
/// than the rest and cut the fuzzing rate to a few hundred sequences a second. Valid segment
/// counts above 8 are therefore folded to [`few_segments`], except one time in 64; refused values
/// (below 2, above the maximum) pass as they are, since refusing is cheap.
fn cheap_integer(u: &mut Unstructured, name: &str, x: c_int) -> Result<c_int> {
    Ok(match name {
        "shape_segments" if (9..=20_000).contains(&x) && !u.ratio(1, 64)? => few_segments(x),
        // Even a 2-segment table costs a whole sequence's time or more under the fuzzer's
        // instrumentation: the table is asked for at a quarter of the rate, the sleeve's
        // cylinder (1) otherwise.
        "shape_model" if x == 2 && !u.ratio(1, 4)? => 1,
        _ => x,
    })
}

/// A cheap segment count for a KnittedMuscle shape table: 2 (about 0.05 ms a table for the
/// prototype sleeve, uninstrumented), and 3..=8 (0.05-0.5 ms, some sleeves 10x more) one time in
/// 16. The default 49 segments take 3.5 ms, and libFuzzer favours the table builds (their many
/// comparisons are many features): with every count 2..=8 alike, table builds took half of the
/// fuzzing time.
fn few_segments(x: c_int) -> c_int {
    let x = x.unsigned_abs();
    (if x.is_multiple_of(16) {
        3 + (x / 16) % 6
    } else {
        2
    }) as c_int
}

fn time_step(u: &mut Unstructured) -> Result<f64> {
    let steps = [
        1e-6,
        1e-3,
        1e-9,
        1e-12,
        0.1,
        1.0,
        0.0,
        -1e-3,
        f64::NAN,
        f64::INFINITY,
        1e300,
        2e3,
    ];
    Ok(steps[u.choose_index(steps.len())?])
}

/// The models by stable id. A model is chosen by one byte of the input, `b % 8` its id here, so
/// that each committed seed keeps driving the model it was found with when models are added (the
/// registry is in name order: FreeBladder's arrival once shifted every seed to another model).
/// Never reorder or remove an entry. The reserved id (`None`) is a GUID that no model has, which
/// must be refused, or, with the byte's high nibble set, a model added after this table (by name
/// order, [`later_models`]): a new model needs no entry, and the seeds of the tabled models keep
/// them (a seed on a later model may move to another later model when one is added). Bit 3
/// of the byte asks `ready` for Model Exchange (the committed seeds from before Model Exchange
/// was fuzzed have it clear).
pub const MODEL_IDS: [Option<&str>; 8] = [
    Some("KnittedMuscle"),
    Some("McKibbenJoint"),
    Some("McKibbenMuscle"),
    Some("MultiferroicMotor"),
    Some("PassThrough"),
    Some("PulleyJoint"),
    Some("FreeBladder"),
    None,
];

/// The model an input byte names (None for the reserved id), and whether `ready` is to
/// instantiate it for Model Exchange.
fn model(u: &mut Unstructured) -> Result<(Option<&'static dyn Factory>, bool)> {
    let b: u8 = u.arbitrary()?;
    let factory = match MODEL_IDS[usize::from(b % 8)] {
        Some(name) => Some(
            *REGISTRY
                .iter()
                .find(|f| f.info().name == name)
                .unwrap_or_else(|| panic!("MODEL_IDS names {name}, which the registry lacks")),
        ),
        None => {
            let later = later_models();
            let k = usize::from(b >> 4);
            (k > 0 && !later.is_empty()).then(|| later[(k - 1) % later.len()])
        }
    };
    Ok((factory, b & 8 != 0))
}

/// The models of the registry that [`MODEL_IDS`] does not name, in name order.
pub fn later_models() -> Vec<&'static dyn Factory> {
    REGISTRY
        .iter()
        .copied()
        .filter(|f| !MODEL_IDS.contains(&Some(f.info().name)))
        .collect()
}

impl Driver {
    fn slot(&mut self, u: &mut Unstructured) -> Result<usize> {
        u.choose_index(SLOTS)
    }

    /// A live instance or NULL.
    fn component(&self, k: usize) -> fmi2Component {
        self.slots[k].as_ref().map_or(null_mut(), |s| s.c)
    }

    fn logged(&self, k: usize) -> usize {
        self.slots[k]
            .as_ref()
            .map_or(0, |s| s.log.0.load(Ordering::Relaxed))
    }

    /// Checks the status of a call on slot `k` given the log count before it.
    fn check(&mut self, k: usize, before: usize, status: fmi2Status, what: &str) {
        self.calls += 1;
        assert_ne!(
            status,
            fmi2Status::Fatal,
            "{what}: fmi2Fatal (a panic inside the FMU)"
        );
        if status >= fmi2Status::Discard && self.slots[k].as_ref().is_some_and(|s| s.logging) {
            assert!(
                self.logged(k) > before,
                "{what}: status {status:?} without a logged reason"
            );
        }
    }

    /// The reserved model id: instantiation with a GUID that no model has must be refused,
    /// with a logged reason.
    fn unknown_model(&mut self, k: usize) -> Result<()> {
        let log = Counter::default();
        let callbacks = fmi2CallbackFunctions {
            logger: Some(logger()),
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: &log as *const Counter as *mut c_void,
        };
        let c = unsafe {
            fmi2Instantiate(
                c"unknown".as_ptr(),
                1,
                c"{00000000-0000-0000-0000-000000000000}".as_ptr(),
                null(),
                &callbacks,
                0,
                0,
            )
        };
        self.calls += 1;
        assert!(c.is_null(), "an unknown GUID was instantiated (slot {k})");
        assert!(
            log.0.load(Ordering::Relaxed) > 0,
            "unknown GUID refused without a logged reason"
        );
        Ok(())
    }

    fn instantiate(&mut self, u: &mut Unstructured) -> Result<()> {
        let k = self.slot(u)?;
        if let Some(old) = self.slots[k].take() {
            unsafe { fmi2FreeInstance(old.c) };
        }
        let Some(factory) = model(u)?.0 else {
            return self.unknown_model(k);
        };
        let info = factory.info();
        let guid = match u.int_in_range(0..=7)? {
            0 => None,
            1 => Some(CString::new("{not-a-guid}").unwrap()),
            2 => Some(CString::new(&info.guid[1..]).unwrap()),
            _ => Some(CString::new(info.guid).unwrap()),
        };
        let name = match u.int_in_range(0..=7)? {
            0 => None,
            1 => Some(CString::new("").unwrap()),
            _ => Some(CString::new("fuzz").unwrap()),
        };
        let kind = if u.ratio(1, 8)? { u.arbitrary()? } else { 1 };
        let resources = match u.int_in_range(0..=3)? {
            0 => Some(CString::new("http://example.org/").unwrap()),
            1 => Some(CString::new("file:///tmp/bad%zz").unwrap()),
            2 => Some(CString::new("file:///tmp/").unwrap()),
            _ => None,
        };
        let log = Box::new(Counter::default());
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: if u.ratio(1, 16)? {
                None
            } else {
                Some(logger())
            },
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: &*log as *const Counter as *mut c_void,
        });
        let no_callbacks = u.ratio(1, 16)?;
        let ptr = |s: &Option<CString>| s.as_ref().map_or(null(), |s| s.as_ptr());
        let c = unsafe {
            fmi2Instantiate(
                ptr(&name),
                kind,
                ptr(&guid),
                ptr(&resources),
                if no_callbacks { null() } else { &*callbacks },
                0,
                c_int::from(u.arbitrary::<bool>()?),
            )
        };
        self.calls += 1;
        let valid = name.as_ref().is_some_and(|n| !n.is_empty())
            && guid.as_ref().is_some_and(|g| g.to_str() == Ok(info.guid))
            // Co-Simulation always; Model Exchange for the models that serve it.
            && (kind == 1 || (kind == 0 && factory.model_exchange()))
            && !no_callbacks;
        assert_eq!(
            !c.is_null(),
            valid,
            "fmi2Instantiate accepted or refused wrongly"
        );
        if !valid && !no_callbacks && callbacks.logger.is_some() {
            assert!(
                log.0.load(Ordering::Relaxed) > 0,
                "refused instantiation not logged"
            );
        }
        if !c.is_null() {
            self.bound_motor_budget(c, info);
            self.slots[k] = Some(Slot {
                c,
                info,
                time: 0.0,
                states: Vec::new(),
                log,
                logging: callbacks.logger.is_some(),
                model_exchange: kind == FMI2_MODEL_EXCHANGE,
                _callbacks: callbacks,
            });
        }
        Ok(())
    }

    /// Throughput, as [`cheap_integer`] for the shape tables: a motor step may spend its whole
    /// substep budget (20,000 by default: tens of ms for a long step of a fast rotor), and motor
    /// steps took three quarters of the fuzzing time. So a new motor instance gets a budget of
    /// 64 (the load test's bound is 50), except where the calls made so far are a multiple of 16;
    /// a budget set later by the input still applies. No input byte is read, so the committed
    /// seeds keep their meaning, and the rule depends on the input alone.
    fn bound_motor_budget(&mut self, c: fmi2Component, info: &ModelInfo) {
        if info.name != "MultiferroicMotor" || self.calls.is_multiple_of(16) {
            return;
        }
        if let Some(v) = info.variables.iter().find(|v| v.name == "max_substeps") {
            let budget: c_int = 64;
            let status = unsafe { fmi2SetInteger(c, &v.vr, 1, &budget) };
            assert_eq!(status, fmi2Status::OK, "max_substeps = 64 refused");
        }
    }

    /// Value references of `kind` for slot `k`: mostly valid, some not.
    fn vrs(&self, u: &mut Unstructured, k: usize, kind: VarType) -> Result<Vec<u32>> {
        let count = self.slots[k].as_ref().map_or(4, |s| {
            s.info.counts[match kind {
                VarType::Real => 0,
                VarType::Integer => 1,
                VarType::Boolean => 2,
                VarType::String => 3,
            }]
        }) as u32;
        let n = u.int_in_range(0..=6)?;
        (0..n)
            .map(|_| {
                Ok(match u.int_in_range(0..=9)? {
                    0 => u.arbitrary()?,
                    1 => count,
                    _ if count > 0 => u.int_in_range(0..=count - 1)?,
                    _ => 0,
                })
            })
            .collect()
    }

    fn set(&mut self, u: &mut Unstructured, kind: VarType) -> Result<()> {
        let k = self.slot(u)?;
        let vrs = self.vrs(u, k, kind)?;
        let info = self.slots[k].as_ref().map(|s| s.info);
        let null_vr = u.ratio(1, 16)?;
        let null_value = u.ratio(1, 16)?;
        let c = self.component(k);
        let vr_ptr = if null_vr { null() } else { vrs.as_ptr() };
        let before = self.logged(k);
        let status = unsafe {
            match kind {
                VarType::Real => {
                    let values = vrs
                        .iter()
                        .map(|&vr| {
                            let var = info.and_then(|i| i.variable(VarType::Real, vr));
                            real(u, var.map(|v| (&v.start, v.min, v.max)))
                        })
                        .collect::<Result<Vec<f64>>>()?;
                    let p = if null_value { null() } else { values.as_ptr() };
                    fmi2SetReal(c, vr_ptr, vrs.len(), p)
                }
                VarType::Integer | VarType::Boolean => {
                    let values = vrs
                        .iter()
                        .map(|&vr| {
                            let x = integer(u)?;
                            let var = info.and_then(|i| i.variable(kind, vr));
                            cheap_integer(u, var.map_or("", |v| v.name), x)
                        })
                        .collect::<Result<Vec<_>>>()?;
                    let p = if null_value { null() } else { values.as_ptr() };
                    if kind == VarType::Integer {
                        self.fewer_shape_segments(u, k, &vrs, &values)?;
                    }
                    if kind == VarType::Integer {
                        fmi2SetInteger(c, vr_ptr, vrs.len(), p)
                    } else {
                        fmi2SetBoolean(c, vr_ptr, vrs.len(), p)
                    }
                }
                VarType::String => {
                    let s = CString::new("a % string %s").unwrap();
                    let values: Vec<fmi2String> = vrs
                        .iter()
                        .map(|_| Ok(if u.ratio(1, 8)? { null() } else { s.as_ptr() }))
                        .collect::<Result<_>>()?;
                    let p = if null_value { null() } else { values.as_ptr() };
                    fmi2SetString(c, vr_ptr, vrs.len(), p)
                }
            }
        };
        self.check(k, before, status, &format!("fmi2Set{kind:?}"));
        Ok(())
    }

    /// Before `shape_model` 2 is set on a KnittedMuscle, sets `shape_segments` to [`few_segments`] too
    /// (15 times in 16), so that the default 49-segment table is built only at a low rate (see
    /// `cheap_integer`).
    fn fewer_shape_segments(
        &mut self,
        u: &mut Unstructured,
        k: usize,
        vrs: &[u32],
        values: &[c_int],
    ) -> Result<()> {
        let Some(info) = self.slots[k].as_ref().map(|s| s.info) else {
            return Ok(());
        };
        let (Some(model), Some(segments)) =
            (info.by_name("shape_model"), info.by_name("shape_segments"))
        else {
            return Ok(());
        };
        let selects_table = vrs
            .iter()
            .zip(values)
            .any(|(&vr, &x)| model.kind == VarType::Integer && vr == model.vr && x == 2);
        if selects_table && !u.ratio(1, 16)? {
            let n = few_segments(c_int::from(u.arbitrary::<u8>()?));
            let before = self.logged(k);
            let status = unsafe { fmi2SetInteger(self.component(k), &segments.vr, 1, &n) };
            self.check(k, before, status, "fmi2SetInteger(shape_segments)");
        }
        Ok(())
    }

    fn get(&mut self, u: &mut Unstructured, kind: VarType) -> Result<()> {
        let k = self.slot(u)?;
        let vrs = self.vrs(u, k, kind)?;
        let null_buffers = u.ratio(1, 16)?;
        let c = self.component(k);
        let n = vrs.len();
        let vr_ptr = if null_buffers { null() } else { vrs.as_ptr() };
        let before = self.logged(k);
        let status = unsafe {
            match kind {
                VarType::Real => {
                    let mut out = vec![0.0f64; n];
                    let p = if null_buffers {
                        null_mut()
                    } else {
                        out.as_mut_ptr()
                    };
                    let s = fmi2GetReal(c, vr_ptr, n, p);
                    if s <= fmi2Status::Warning {
                        assert!(
                            out.iter().all(|x| x.is_finite()),
                            "fmi2GetReal({vrs:?}) gave {out:?} with {s:?}"
                        );
                    }
                    s
                }
                VarType::Integer | VarType::Boolean => {
                    let mut out = vec![0 as c_int; n];
                    let p = if null_buffers {
                        null_mut()
                    } else {
                        out.as_mut_ptr()
                    };
                    if kind == VarType::Integer {
                        fmi2GetInteger(c, vr_ptr, n, p)
                    } else {
                        fmi2GetBoolean(c, vr_ptr, n, p)
                    }
                }
                VarType::String => {
                    let mut out = vec![null::<c_char>(); n];
                    let p = if null_buffers {
                        null_mut()
                    } else {
                        out.as_mut_ptr()
                    };
                    let s = fmi2GetString(c, vr_ptr, n, p);
                    if s <= fmi2Status::Warning {
                        for q in out {
                            assert!(!q.is_null());
                            let _ = CStr::from_ptr(q);
                        }
                    }
                    s
                }
            }
        };
        self.check(k, before, status, &format!("fmi2Get{kind:?}"));
        Ok(())
    }

    fn do_step(&mut self, u: &mut Unstructured) -> Result<()> {
        let k = self.slot(u)?;
        if self.slots[k].as_ref().is_some_and(|s| s.model_exchange) {
            return self.model_exchange(u, k);
        }
        let h = time_step(u)?;
        let believed = self.slots[k].as_ref().map_or(0.0, |s| s.time);
        let t = match u.int_in_range(0..=7)? {
            0 => real(u, None)?,
            1 => 0.0,
            _ => believed,
        };
        let before = self.logged(k);
        let status = unsafe { fmi2DoStep(self.component(k), t, h, 0) };
        self.check(k, before, status, "fmi2DoStep");
        if status <= fmi2Status::Warning {
            if let Some(s) = self.slots[k].as_mut() {
                s.time = t + h;
            }
        }
        Ok(())
    }

    fn simple(&mut self, u: &mut Unstructured) -> Result<()> {
        let k = self.slot(u)?;
        let c = self.component(k);
        let before = self.logged(k);
        // One byte, `% 7` for the seven calls below as before Model Exchange was fuzzed; the four
        // values that `% 7` over-represents (252..=255) make the Model Exchange calls and the
        // directional derivative on any instance (also Co-Simulation ones, and NULL), so that the
        // committed seeds keep their meaning.
        let which: u8 = u.arbitrary()?;
        match which {
            252 | 253 => return self.directional_derivative(u, k),
            254 | 255 => return self.model_exchange(u, k),
            _ => {}
        }
        let (status, what) = unsafe {
            match which % 7 {
                0 => {
                    let stop_def = u.arbitrary::<bool>()?;
                    let (tol, start, stop) = (real(u, None)?, real(u, None)?, real(u, None)?);
                    let s = fmi2SetupExperiment(
                        c,
                        c_int::from(u.arbitrary::<bool>()?),
                        tol,
                        start,
                        c_int::from(stop_def),
                        stop,
                    );
                    if s == fmi2Status::OK {
                        if let Some(slot) = self.slots[k].as_mut() {
                            slot.time = start;
                        }
                    }
                    (s, "fmi2SetupExperiment")
                }
                1 => (
                    fmi2EnterInitializationMode(c),
                    "fmi2EnterInitializationMode",
                ),
                2 => (fmi2ExitInitializationMode(c), "fmi2ExitInitializationMode"),
                3 => (fmi2Terminate(c), "fmi2Terminate"),
                4 => {
                    let s = fmi2Reset(c);
                    if s == fmi2Status::OK {
                        if let Some(slot) = self.slots[k].as_mut() {
                            slot.time = 0.0;
                        }
                    }
                    (s, "fmi2Reset")
                }
                5 => (fmi2CancelStep(c), "fmi2CancelStep"),
                _ => {
                    let cats = [
                        c"logCalls".as_ptr(),
                        c"logStatusError".as_ptr(),
                        c"bogus".as_ptr(),
                        null(),
                    ];
                    let n = u.int_in_range(0..=4)?;
                    let p = if u.ratio(1, 8)? {
                        null()
                    } else {
                        cats.as_ptr()
                    };
                    (
                        fmi2SetDebugLogging(c, c_int::from(u.arbitrary::<bool>()?), n, p),
                        "fmi2SetDebugLogging",
                    )
                }
            }
        };
        self.check(k, before, status, what);
        Ok(())
    }

    fn status(&mut self, u: &mut Unstructured) -> Result<()> {
        let k = self.slot(u)?;
        let c = self.component(k);
        let kind = c_int::from(u.int_in_range(-1i8..=4)?);
        let null_value = u.ratio(1, 8)?;
        let before = self.logged(k);
        let status = unsafe {
            let (mut i, mut r, mut s) = (0 as c_int, 0.0, null::<c_char>());
            let pi: *mut c_int = if null_value { null_mut() } else { &mut i };
            match u.int_in_range(0..=4)? {
                0 => fmi2GetStatus(c, kind, pi),
                1 => {
                    let st =
                        fmi2GetRealStatus(c, kind, if null_value { null_mut() } else { &mut r });
                    assert!(st > fmi2Status::Warning || r.is_finite());
                    st
                }
                2 => fmi2GetIntegerStatus(c, kind, pi),
                3 => fmi2GetBooleanStatus(c, kind, pi),
                _ => fmi2GetStringStatus(c, kind, if null_value { null_mut() } else { &mut s }),
            }
        };
        self.check(k, before, status, "status");
        Ok(())
    }

    fn fmu_state(&mut self, u: &mut Unstructured) -> Result<()> {
        let k = self.slot(u)?;
        let c = self.component(k);
        let before = self.logged(k);
        // A live state of any instance (foreign ones must be refused), or NULL.
        let all: Vec<fmi2FMUstate> = self
            .slots
            .iter()
            .flatten()
            .flat_map(|s| s.states.clone())
            .collect();
        let any_state = if all.is_empty() || u.ratio(1, 8)? {
            null_mut()
        } else {
            all[u.choose_index(all.len())?]
        };
        let own = self.slots[k]
            .as_ref()
            .is_some_and(|s| s.states.contains(&any_state));
        let which = u.int_in_range(0..=4)?;
        if std::env::var_os("CALL_SEQUENCES_TRACE").is_some() {
            eprintln!("  fmu state call {which} on slot {k}");
        }
        let status = unsafe {
            match which {
                0 => {
                    // Overwrite an own state or create a new one.
                    let mut slot = if own { any_state } else { null_mut() };
                    let st = fmi2GetFMUstate(
                        c,
                        if u.ratio(1, 16)? {
                            null_mut()
                        } else {
                            &mut slot
                        },
                    );
                    if st == fmi2Status::OK && !own {
                        if let Some(s) = self.slots[k].as_mut() {
                            s.states.push(slot);
                        }
                    }
                    st
                }
                1 => {
                    let st = fmi2SetFMUstate(c, any_state);
                    if st == fmi2Status::OK {
                        // The clock came back with the state; the driver no longer knows it.
                        let mut t = 0.0;
                        if fmi2GetRealStatus(c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) == fmi2Status::OK
                        {
                            self.slots[k].as_mut().unwrap().time = t;
                        }
                    }
                    st
                }
                2 => {
                    let mut slot = any_state;
                    let st = fmi2FreeFMUstate(c, &mut slot);
                    if st == fmi2Status::OK && own {
                        self.slots[k]
                            .as_mut()
                            .unwrap()
                            .states
                            .retain(|&s| s != any_state);
                    }
                    st
                }
                3 => {
                    let mut size = 0usize;
                    let st = fmi2SerializedFMUstateSize(c, any_state, &mut size);
                    if st != fmi2Status::OK {
                        st
                    } else {
                        let short = if u.ratio(1, 8)? {
                            u.int_in_range(0..=size)?
                        } else {
                            size
                        };
                        let mut bytes = vec![0 as c_char; size];
                        let st = fmi2SerializeFMUstate(c, any_state, bytes.as_mut_ptr(), short);
                        self.check(k, before, st, "fmi2SerializeFMUstate");
                        if st != fmi2Status::OK {
                            return Ok(());
                        }
                        // Corrupt some bytes, and/or write a special double (random bytes rarely
                        // spell a NaN) where a variable's value is or anywhere; then read them back
                        // anywhere, maybe cut short.
                        for _ in 0..u.int_in_range(0..=3)? {
                            if size > 0 {
                                let at = u.choose_index(size)?;
                                bytes[at] = u.arbitrary::<u8>()? as c_char;
                            }
                        }
                        if size >= 8 && u.ratio(1, 4)? {
                            // Structure-aware: where a variable's current value is, if it can be
                            // read and found; anywhere otherwise.
                            let info = self.slots[k].as_ref().map(|s| s.info);
                            let nr = info.map_or(0, |i| i.counts[0]);
                            let mut at = u.choose_index(size - 7)?;
                            if nr > 0 {
                                let vr = u.int_in_range(0..=nr - 1)? as u32;
                                let mut x = 0.0;
                                if fmi2GetReal(c, &vr, 1, &mut x) <= fmi2Status::Warning {
                                    let pattern = x.to_le_bytes().map(|b| b as c_char);
                                    if let Some(found) = bytes.windows(8).position(|w| w == pattern)
                                    {
                                        at = found;
                                    }
                                }
                            }
                            let x = real(u, None)?;
                            for (k, b) in x.to_le_bytes().iter().enumerate() {
                                bytes[at + k] = *b as c_char;
                            }
                        }
                        // Half the states are resealed deliberately, whatever was changed above:
                        // their checksum holds, so the decoding, the declared ranges and each
                        // model's own invariants behind it are what must refuse them (or the
                        // state must be a valid model). The other half keep the old checksum,
                        // which must refuse them if any byte changed.
                        if size >= 8 && u.arbitrary()? {
                            reseal(&mut bytes);
                        }
                        if std::env::var_os("CALL_SEQUENCES_TRACE").is_some() {
                            eprintln!("  serialized {size} bytes, now {:?}", bytes);
                        }
                        let len = if u.ratio(1, 8)? {
                            u.int_in_range(0..=size)?
                        } else {
                            size
                        };
                        let target = self.slot(u)?;
                        let tc = self.component(target);
                        let tbefore = self.logged(target);
                        let mut out = null_mut();
                        let st = fmi2DeSerializeFMUstate(tc, bytes.as_ptr(), len, &mut out);
                        self.check(target, tbefore, st, "fmi2DeSerializeFMUstate");
                        if st == fmi2Status::OK {
                            self.slots[target].as_mut().unwrap().states.push(out);
                            // Often go on at once: restore it and read every Real.
                            if u.arbitrary()? {
                                let before = self.logged(target);
                                let st = fmi2SetFMUstate(tc, out);
                                self.check(target, before, st, "fmi2SetFMUstate");
                                let nr = self.slots[target].as_ref().unwrap().info.counts[0] as u32;
                                let vrs: Vec<u32> = (0..nr).collect();
                                let mut values = vec![0.0; vrs.len()];
                                let before = self.logged(target);
                                let st =
                                    fmi2GetReal(tc, vrs.as_ptr(), vrs.len(), values.as_mut_ptr());
                                self.check(target, before, st, "fmi2GetReal");
                                if st <= fmi2Status::Warning {
                                    assert!(
                                        values.iter().all(|x| x.is_finite()),
                                        "fmi2GetReal after a deserialized state gave {values:?} with {st:?}"
                                    );
                                }
                            }
                        }
                        return Ok(());
                    }
                }
                _ => {
                    let mut size = 0usize;
                    fmi2SerializedFMUstateSize(
                        c,
                        any_state,
                        if u.ratio(1, 4)? {
                            null_mut()
                        } else {
                            &mut size
                        },
                    )
                }
            }
        };
        self.check(k, before, status, "FMU state");
        Ok(())
    }

    fn free(&mut self, u: &mut Unstructured) -> Result<()> {
        let k = self.slot(u)?;
        if let Some(s) = self.slots[k].take() {
            unsafe { fmi2FreeInstance(s.c) };
        } else {
            unsafe { fmi2FreeInstance(null_mut()) };
        }
        self.calls += 1;
        Ok(())
    }

    /// A start that reaches the interesting states quickly: instantiate, set, initialize.
    fn ready(&mut self, u: &mut Unstructured) -> Result<()> {
        let k = self.slot(u)?;
        if let Some(old) = self.slots[k].take() {
            unsafe { fmi2FreeInstance(old.c) };
        }
        let (Some(factory), model_exchange) = model(u)? else {
            return self.unknown_model(k);
        };
        let model_exchange = model_exchange && factory.model_exchange();
        let info = factory.info();
        let log = Box::new(Counter::default());
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(logger()),
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: &*log as *const Counter as *mut c_void,
        });
        let guid = CString::new(info.guid).unwrap();
        let c = unsafe {
            fmi2Instantiate(
                c"ready".as_ptr(),
                if model_exchange {
                    FMI2_MODEL_EXCHANGE
                } else {
                    FMI2_CO_SIMULATION
                },
                guid.as_ptr(),
                null(),
                &*callbacks,
                0,
                0,
            )
        };
        assert!(!c.is_null());
        self.slots[k] = Some(Slot {
            c,
            info,
            time: 0.0,
            states: Vec::new(),
            log,
            logging: true,
            model_exchange,
            _callbacks: callbacks,
        });
        unsafe {
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::OK);
            assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::OK);
        }
        self.calls += 3;
        Ok(())
    }

    fn one(&mut self, u: &mut Unstructured) -> Result<()> {
        let op = u.int_in_range(0..=15)?;
        if std::env::var_os("CALL_SEQUENCES_TRACE").is_some() {
            const OPS: [&str; 16] = [
                "instantiate",
                "ready",
                "free",
                "simple",
                "simple",
                "setReal",
                "setInteger",
                "setBoolean/String",
                "getReal",
                "getReal",
                "get",
                "doStep",
                "doStep",
                "status",
                "fmuState",
                "fmuState",
            ];
            eprintln!("op {}", OPS[op as usize]);
        }
        match op {
            0 => self.instantiate(u),
            1 => self.ready(u),
            2 => self.free(u),
            3 | 4 => self.simple(u),
            5 => self.set(u, VarType::Real),
            6 => self.set(u, VarType::Integer),
            7 => {
                let kind = [VarType::Boolean, VarType::String][u.choose_index(2)?];
                self.set(u, kind)
            }
            8 | 9 => self.get(u, VarType::Real),
            10 => {
                let kind =
                    [VarType::Integer, VarType::Boolean, VarType::String][u.choose_index(3)?];
                self.get(u, kind)
            }
            11 | 12 => self.do_step(u),
            13 => self.status(u),
            _ => self.fmu_state(u),
        }
    }
}

/// Model Exchange and directional derivatives: on ME instances (with and without continuous
/// states), on Co-Simulation ones and on NULL, in any state, with right and wrong vector sizes
/// (the buffer always holds the size passed), NULL vectors, and NaN/inf/huge states and times.
impl Driver {
    /// A vector size for slot `k`: mostly the model's own, sometimes any small one.
    fn size(&self, u: &mut Unstructured, right: usize) -> Result<usize> {
        Ok(if u.ratio(1, 4)? {
            u.int_in_range(0..=8)?
        } else {
            right
        })
    }

    fn sizes(&self, k: usize) -> (usize, usize) {
        self.slots[k].as_ref().map_or((0, 0), |s| me_sizes(s.info))
    }

    /// A state-sized getter; every value it hands out with OK or Warning must be finite.
    fn get_vector(
        &mut self,
        k: usize,
        n: usize,
        null_buffer: bool,
        (getter, what): (
            unsafe extern "C" fn(fmi2Component, *mut f64, usize) -> fmi2Status,
            &str,
        ),
    ) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![0.0; n];
        let p = if null_buffer {
            null_mut()
        } else {
            out.as_mut_ptr()
        };
        let before = self.logged(k);
        let status = unsafe { getter(self.component(k), p, n) };
        self.check(k, before, status, what);
        if status <= fmi2Status::Warning {
            assert!(
                out.iter().all(|x| x.is_finite()),
                "{what} gave {out:?} with {status:?}"
            );
        }
        (status, out)
    }

    fn set_time(&mut self, k: usize, t: f64) -> fmi2Status {
        let before = self.logged(k);
        let status = unsafe { fmi2SetTime(self.component(k), t) };
        self.check(k, before, status, "fmi2SetTime");
        if status <= fmi2Status::Warning {
            if let Some(s) = self.slots[k].as_mut() {
                s.time = t;
            }
        }
        status
    }

    fn set_states(&mut self, k: usize, x: &[f64], null_buffer: bool) -> fmi2Status {
        let p = if null_buffer { null() } else { x.as_ptr() };
        let before = self.logged(k);
        let status = unsafe { fmi2SetContinuousStates(self.component(k), p, x.len()) };
        self.check(k, before, status, "fmi2SetContinuousStates");
        status
    }

    /// An event iteration as an importer runs it (at most 4 rounds); returns its last status.
    fn event_iteration(&mut self, k: usize) -> fmi2Status {
        let mut status = fmi2Status::OK;
        for _ in 0..4 {
            let mut info = EventInfo::default();
            let before = self.logged(k);
            status = unsafe { fmi2NewDiscreteStates(self.component(k), &mut info) };
            self.check(k, before, status, "fmi2NewDiscreteStates");
            if status <= fmi2Status::Warning && info.next_event_time_defined != 0 {
                assert!(
                    info.next_event_time.is_finite(),
                    "fmi2NewDiscreteStates gave the next event at {} with {status:?}",
                    info.next_event_time
                );
            }
            if status > fmi2Status::Warning || info.new_discrete_states_needed == 0 {
                break;
            }
        }
        status
    }

    fn model_exchange(&mut self, u: &mut Unstructured, k: usize) -> Result<()> {
        let (nx, ni) = self.sizes(k);
        let null_buffer = u.ratio(1, 16)?;
        let which = u.int_in_range(0..=12)?;
        let c = self.component(k);
        let before = self.logged(k);
        let (status, what) = unsafe {
            match which {
                0 => {
                    let believed = self.slots[k].as_ref().map_or(0.0, |s| s.time);
                    let t = match u.int_in_range(0..=3)? {
                        0 => real(u, None)?,
                        _ => believed + time_step(u)?,
                    };
                    self.set_time(k, t);
                    return Ok(());
                }
                1 => {
                    // The current states (when they can be had), each kept, nudged or replaced.
                    let n = self.size(u, nx)?;
                    let (_, mut x) = self.get_vector(
                        k,
                        n,
                        false,
                        (fmi2GetContinuousStates, "fmi2GetContinuousStates"),
                    );
                    for x in x.iter_mut() {
                        *x = match u.int_in_range(0..=3)? {
                            0 => real(u, None)?,
                            1 => *x * (1.0 + f64::from(u.arbitrary::<i8>()?) / 64.0),
                            _ => *x,
                        };
                    }
                    self.set_states(k, &x, null_buffer);
                    return Ok(());
                }
                2..=5 => {
                    let (right, getter) = match which {
                        2 => (
                            nx,
                            (fmi2GetContinuousStates as _, "fmi2GetContinuousStates"),
                        ),
                        3 => (nx, (fmi2GetDerivatives as _, "fmi2GetDerivatives")),
                        4 => (ni, (fmi2GetEventIndicators as _, "fmi2GetEventIndicators")),
                        _ => (
                            nx,
                            (
                                fmi2GetNominalsOfContinuousStates as _,
                                "fmi2GetNominalsOfContinuousStates",
                            ),
                        ),
                    };
                    let n = self.size(u, right)?;
                    self.get_vector(k, n, null_buffer, getter);
                    return Ok(());
                }
                6 => (fmi2EnterEventMode(c), "fmi2EnterEventMode"),
                7 => {
                    if null_buffer {
                        (
                            fmi2NewDiscreteStates(c, null_mut()),
                            "fmi2NewDiscreteStates",
                        )
                    } else {
                        self.event_iteration(k);
                        return Ok(());
                    }
                }
                8 => (
                    fmi2EnterContinuousTimeMode(c),
                    "fmi2EnterContinuousTimeMode",
                ),
                9 => {
                    let (mut enter, mut terminate) = (0, 0);
                    let p = |b: &mut fmi2Boolean| {
                        if null_buffer {
                            null_mut()
                        } else {
                            b as *mut _
                        }
                    };
                    (
                        fmi2CompletedIntegratorStep(
                            c,
                            c_int::from(u.arbitrary::<bool>()?),
                            p(&mut enter),
                            p(&mut terminate),
                        ),
                        "fmi2CompletedIntegratorStep",
                    )
                }
                10 => return self.directional_derivative(u, k),
                11 => return self.integrate(u, k),
                _ => {
                    // A Co-Simulation call on a Model Exchange instance.
                    let t = self.slots[k].as_ref().map_or(0.0, |s| s.time);
                    (fmi2DoStep(c, t, time_step(u)?, 0), "fmi2DoStep")
                }
            }
        };
        self.check(k, before, status, what);
        Ok(())
    }

    /// What an importer's explicit Euler integrator does: (leave initialization, event
    /// iteration, continuous-time mode,) then up to 8 steps of states, derivatives, time, new
    /// states, indicators and completed step, with an event iteration where the FMU asks for
    /// one. Stops at the first refusal.
    fn integrate(&mut self, u: &mut Unstructured, k: usize) -> Result<()> {
        let (nx, ni) = self.sizes(k);
        let c = self.component(k);
        if u.arbitrary()? {
            let before = self.logged(k);
            let status = unsafe { fmi2ExitInitializationMode(c) };
            self.check(k, before, status, "fmi2ExitInitializationMode");
            self.event_iteration(k);
            let before = self.logged(k);
            let status = unsafe { fmi2EnterContinuousTimeMode(c) };
            self.check(k, before, status, "fmi2EnterContinuousTimeMode");
        }
        let h = [1e-6, 1e-4, 1e-3, 1e-2, 1e-9, 0.1][u.choose_index(6)?];
        for _ in 0..u.int_in_range(1..=8)? {
            let (s1, x) = self.get_vector(
                k,
                nx,
                false,
                (fmi2GetContinuousStates, "fmi2GetContinuousStates"),
            );
            let (s2, dx) =
                self.get_vector(k, nx, false, (fmi2GetDerivatives, "fmi2GetDerivatives"));
            if s1.max(s2) > fmi2Status::Warning {
                return Ok(());
            }
            let t = self.slots[k].as_ref().map_or(0.0, |s| s.time) + h;
            let x: Vec<f64> = x.iter().zip(&dx).map(|(x, dx)| x + h * dx).collect();
            if self.set_time(k, t) > fmi2Status::Warning
                || self.set_states(k, &x, false) > fmi2Status::Warning
            {
                return Ok(());
            }
            self.get_vector(
                k,
                ni,
                false,
                (fmi2GetEventIndicators, "fmi2GetEventIndicators"),
            );
            let (mut enter, mut terminate) = (0, 0);
            let before = self.logged(k);
            let status = unsafe { fmi2CompletedIntegratorStep(c, 1, &mut enter, &mut terminate) };
            self.check(k, before, status, "fmi2CompletedIntegratorStep");
            if status > fmi2Status::Warning {
                return Ok(());
            }
            if enter != 0 {
                let before = self.logged(k);
                let status = unsafe { fmi2EnterEventMode(c) };
                self.check(k, before, status, "fmi2EnterEventMode");
                self.event_iteration(k);
                let before = self.logged(k);
                let status = unsafe { fmi2EnterContinuousTimeMode(c) };
                self.check(k, before, status, "fmi2EnterContinuousTimeMode");
            }
        }
        Ok(())
    }

    /// Value references for a directional derivative: mostly Reals of the right causality
    /// (unknowns: outputs and locals such as state derivatives; knowns: inputs and locals such
    /// as states), sometimes any.
    fn derivative_vrs(&self, u: &mut Unstructured, k: usize, unknown: bool) -> Result<Vec<u32>> {
        let Some(info) = self.slots[k].as_ref().map(|s| s.info) else {
            return self.vrs(u, k, VarType::Real);
        };
        if u.ratio(1, 4)? {
            return self.vrs(u, k, VarType::Real);
        }
        let wanted: Vec<u32> = info
            .variables
            .iter()
            .filter(|v| {
                v.kind == VarType::Real
                    && match v.causality {
                        Causality::Output => unknown,
                        Causality::Input => !unknown,
                        Causality::Local => true,
                        _ => false,
                    }
            })
            .map(|v| v.vr)
            .collect();
        if wanted.is_empty() {
            return Ok(Vec::new());
        }
        (0..u.int_in_range(0..=4)?)
            .map(|_| Ok(wanted[u.choose_index(wanted.len())?]))
            .collect()
    }

    fn directional_derivative(&mut self, u: &mut Unstructured, k: usize) -> Result<()> {
        let unknown = self.derivative_vrs(u, k, true)?;
        let known = self.derivative_vrs(u, k, false)?;
        let seeds = known
            .iter()
            .map(|_| Ok(if u.ratio(1, 4)? { real(u, None)? } else { 1.0 }))
            .collect::<Result<Vec<f64>>>()?;
        let mut out = vec![0.0; unknown.len()];
        let null_buffers = u.ratio(1, 16)?;
        let p = |v: &[u32]| if null_buffers { null() } else { v.as_ptr() };
        let before = self.logged(k);
        let status = unsafe {
            fmi2GetDirectionalDerivative(
                self.component(k),
                p(&unknown),
                unknown.len(),
                p(&known),
                known.len(),
                seeds.as_ptr(),
                out.as_mut_ptr(),
            )
        };
        self.check(k, before, status, "fmi2GetDirectionalDerivative");
        if status <= fmi2Status::Warning {
            assert!(
                out.iter().all(|x| x.is_finite()),
                "fmi2GetDirectionalDerivative({unknown:?} by {known:?}, {seeds:?}) gave {out:?} \
                 with {status:?}"
            );
        }
        Ok(())
    }
}

/// Recomputes the trailing FNV-1a checksum of a serialized state (format 2).
fn reseal(data: &mut [c_char]) {
    let n = data.len() - 8;
    let sum = data[..n].iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b as u8)).wrapping_mul(0x100_0000_01b3)
    });
    for (k, b) in sum.to_le_bytes().iter().enumerate() {
        data[n + k] = *b as c_char;
    }
}

/// Runs the call sequence that `data` spells (at most 256 calls, each bounded by the FMU's own
/// step budget) and returns how many FMI calls it made. Panics on any finding.
pub fn run(data: &[u8]) -> usize {
    let mut u = Unstructured::new(data);
    let mut driver = Driver {
        slots: Default::default(),
        calls: 0,
    };
    for _ in 0..256 {
        if u.is_empty() || driver.one(&mut u).is_err() {
            break;
        }
    }
    driver.calls
}
