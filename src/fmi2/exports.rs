//! Every common and Co-Simulation function of FMI 2.0 (FMPy resolves all of them when it loads a
//! binary). Each body runs inside `catch_unwind`: a panic is logged and becomes `fmi2Fatal`, it
//! never unwinds into the importer. Pointers are checked here and turned into slices.

use super::instance::{FmuState, Instance, MAGIC};
use super::logger::Logger;
use super::registry::REGISTRY;
use super::types::*;
use std::ffi::{c_char, c_int, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

/// The instance behind `c`, if `c` is a live instance of ours.
///
/// # Safety
/// `c` must be NULL or a pointer returned by `fmi2Instantiate` (freed ones are caught by the magic
/// number as long as the memory was not reused).
unsafe fn instance<'a>(c: fmi2Component) -> Option<&'a mut Instance> {
    let ptr = c as *mut Instance;
    if ptr.is_null() || !ptr.is_aligned() || (*ptr).magic != MAGIC {
        return None;
    }
    Some(&mut *ptr)
}

fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Runs `body` on the instance `c`; a panic is logged, the instance becomes fatal.
fn guarded(
    c: fmi2Component,
    function: &str,
    body: impl FnOnce(&mut Instance) -> fmi2Status,
) -> fmi2Status {
    // SAFETY: see `instance`.
    let Some(inst) = (unsafe { instance(c) }) else {
        return fmi2Status::Error;
    };
    let ptr: *mut Instance = inst;
    // SAFETY: `ptr` is live for the whole call; the closure's borrow ends before the panic arm.
    match catch_unwind(AssertUnwindSafe(|| body(unsafe { &mut *ptr }))) {
        Ok(status) => status,
        Err(payload) => {
            let inst = unsafe { &mut *ptr };
            inst.state = super::instance::MachineState::Fatal;
            inst.logger.log(
                fmi2Status::Fatal,
                &format!("{function}: internal error: {}", panic_text(&*payload)),
            );
            fmi2Status::Fatal
        }
    }
}

/// A slice from a C array; NULL is accepted only for an empty array.
///
/// # Safety
/// A non-null `ptr` must point to `n` readable elements.
unsafe fn slice<'a, T>(ptr: *const T, n: usize) -> Option<&'a [T]> {
    match (ptr.is_null(), n) {
        (_, 0) => Some(&[]),
        (true, _) => None,
        (false, _) => Some(std::slice::from_raw_parts(ptr, n)),
    }
}

/// # Safety
/// As [`slice`], for `n` writable elements.
unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize) -> Option<&'a mut [T]> {
    match (ptr.is_null(), n) {
        (_, 0) => Some(&mut []),
        (true, _) => None,
        (false, _) => Some(std::slice::from_raw_parts_mut(ptr, n)),
    }
}

/// # Safety
/// A non-null `s` must be NUL-terminated.
unsafe fn text(s: fmi2String) -> Option<String> {
    (!s.is_null()).then(|| CStr::from_ptr(s).to_string_lossy().into_owned())
}

fn null_argument(inst: &Instance, function: &str, argument: &str) -> fmi2Status {
    inst.error(&format!("{function}: {argument} must not be NULL"))
}

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// Accepts `file:///path`, `file:/path` and `file://localhost/path`, percent-encoded.
fn resource_path(uri: &str) -> Result<PathBuf, String> {
    let rest = uri
        .strip_prefix("file://localhost/")
        .map(|r| format!("/{r}"))
        .or_else(|| uri.strip_prefix("file:///").map(|r| format!("/{r}")))
        .or_else(|| {
            uri.strip_prefix("file:/")
                .filter(|r| !r.starts_with('/'))
                .map(|r| format!("/{r}"))
        })
        .ok_or_else(|| format!("resourceLocation '{uri}' is not a file URI"))?;
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok());
            let byte = hex
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent-encoding in '{uri}'"))?;
            out.push(byte);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    Ok(PathBuf::from(String::from_utf8_lossy(&out).into_owned()))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: fmi2String,
    fmu_type: c_int,
    fmu_guid: fmi2String,
    fmu_resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    let result = catch_unwind(|| {
        // Without callbacks there is nowhere to say what went wrong: refuse quietly.
        let callbacks = functions.as_ref()?;
        let name = text(instance_name);
        let logger = Logger::new(
            callbacks.logger,
            callbacks.component_environment,
            name.as_deref().unwrap_or("?"),
        );
        let refuse = |why: String| {
            logger.log(fmi2Status::Error, &format!("fmi2Instantiate: {why}"));
            None
        };
        if name.as_deref().is_none_or(str::is_empty) {
            return refuse("instanceName must be a non-empty string".into());
        }
        if fmu_type != FMI2_CO_SIMULATION {
            return refuse(format!(
                "fmuType {fmu_type} is not supported: this FMU is Co-Simulation only (fmuType 1)"
            ));
        }
        let Some(guid) = text(fmu_guid) else {
            return refuse("fmuGUID must not be NULL".into());
        };
        let Some(factory) = REGISTRY.iter().find(|f| f.info().guid == guid) else {
            let known: Vec<String> = REGISTRY
                .iter()
                .map(|f| format!("{} {}", f.info().name, f.info().guid))
                .collect();
            return refuse(format!(
                "wrong GUID {guid}: the model description and the binary do not match (this binary implements {})",
                known.join(", ")
            ));
        };
        let mut logger = logger;
        logger.debug = logging_on != FMI2_FALSE;
        // No model reads resources yet; a location that is not a file URI is still worth a word.
        if let Some(uri) = text(fmu_resource_location) {
            match resource_path(&uri) {
                Ok(path) if logger.debug => logger.log(
                    fmi2Status::OK,
                    &format!("fmi2Instantiate: resources at {}", path.display()),
                ),
                Ok(_) => {}
                Err(why) => logger.log(
                    fmi2Status::Warning,
                    &format!("fmi2Instantiate: {why}; resources are unavailable"),
                ),
            }
        }
        Some(Box::into_raw(Box::new(Instance::new(*factory, logger))) as fmi2Component)
    });
    result.ok().flatten().unwrap_or(std::ptr::null_mut())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    let Some(inst) = instance(c) else { return };
    let ptr: *mut Instance = inst;
    // Dropping clears the magic number and frees the instance's FMU states.
    let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(ptr))));
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n_categories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    guarded(c, "fmi2SetDebugLogging", |inst| {
        let Some(list) = slice(categories, n_categories) else {
            return null_argument(inst, "fmi2SetDebugLogging", "categories");
        };
        let names: Option<Vec<String>> = list.iter().map(|&s| text(s)).collect();
        let Some(names) = names else {
            return null_argument(inst, "fmi2SetDebugLogging", "a category name");
        };
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        inst.set_debug_logging(logging_on != FMI2_FALSE, &refs)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: fmi2Real,
    start_time: fmi2Real,
    stop_time_defined: fmi2Boolean,
    stop_time: fmi2Real,
) -> fmi2Status {
    guarded(c, "fmi2SetupExperiment", |inst| {
        let tolerance = (tolerance_defined != FMI2_FALSE).then_some(tolerance);
        let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
        inst.setup_experiment(tolerance, start_time, stop)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    guarded(c, "fmi2EnterInitializationMode", |inst| {
        inst.enter_initialization_mode()
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    guarded(c, "fmi2ExitInitializationMode", |inst| {
        inst.exit_initialization_mode()
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    guarded(c, "fmi2Terminate", |inst| inst.terminate())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    guarded(c, "fmi2Reset", |inst| inst.reset())
}

/// The shared body of fmi2SetReal/Integer/Boolean: checks the arrays and sets, without copying.
unsafe fn set_values<T: super::instance::Value>(
    c: fmi2Component,
    function: &'static str,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const T,
) -> fmi2Status {
    guarded(c, function, |inst| {
        let (Some(vrs), Some(values)) = (slice(vr, nvr), slice(value, nvr)) else {
            return null_argument(inst, function, "vr and value");
        };
        inst.set(function, vrs, values)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    set_values(c, "fmi2SetReal", vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    set_values(c, "fmi2SetInteger", vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    // CBoolean is a transparent wrapper of the C int.
    set_values(
        c,
        "fmi2SetBoolean",
        vr,
        nvr,
        value as *const super::instance::CBoolean,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    guarded(c, "fmi2SetString", |inst| {
        let (Some(vrs), Some(values)) = (slice(vr, nvr), slice(value, nvr)) else {
            return null_argument(inst, "fmi2SetString", "vr and value");
        };
        let Some(strings) = values
            .iter()
            .map(|&s| text(s))
            .collect::<Option<Vec<String>>>()
        else {
            return null_argument(inst, "fmi2SetString", "a string value");
        };
        inst.set("fmi2SetString", vrs, &strings)
    })
}

unsafe fn get_values<C: Copy + Default>(
    c: fmi2Component,
    function: &'static str,
    kind: crate::variables::VarType,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut C,
    pick: impl Fn(&super::runtime::Vars, usize) -> C,
) -> fmi2Status {
    guarded(c, function, |inst| {
        let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
            return null_argument(inst, function, "vr and value");
        };
        inst.get(function, kind, vrs, out, pick)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    get_values(
        c,
        "fmi2GetReal",
        crate::variables::VarType::Real,
        vr,
        nvr,
        value,
        |v, i| v.real[i],
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    get_values(
        c,
        "fmi2GetInteger",
        crate::variables::VarType::Integer,
        vr,
        nvr,
        value,
        |v, i| v.integer[i],
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    get_values(
        c,
        "fmi2GetBoolean",
        crate::variables::VarType::Boolean,
        vr,
        nvr,
        value,
        |v, i| v.boolean[i] as fmi2Boolean,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    guarded(c, "fmi2GetString", |inst| {
        let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
            return null_argument(inst, "fmi2GetString", "vr and value");
        };
        match inst.get_strings(vrs) {
            Ok(ptrs) => {
                out.copy_from_slice(&ptrs);
                fmi2Status::OK
            }
            Err(status) => status,
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    guarded(c, "fmi2GetFMUstate", |inst| {
        let Some(slot) = state.as_mut() else {
            return null_argument(inst, "fmi2GetFMUstate", "FMUstate");
        };
        match inst.get_fmu_state(*slot as *mut FmuState) {
            Ok(ptr) => {
                *slot = ptr as fmi2FMUstate;
                fmi2Status::OK
            }
            Err(status) => status,
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    guarded(c, "fmi2SetFMUstate", |inst| {
        inst.set_fmu_state(state as *mut FmuState)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    guarded(c, "fmi2FreeFMUstate", |inst| {
        let Some(slot) = state.as_mut() else {
            return null_argument(inst, "fmi2FreeFMUstate", "FMUstate");
        };
        let status = inst.free_fmu_state(*slot as *mut FmuState);
        if status == fmi2Status::OK {
            *slot = std::ptr::null_mut();
        }
        status
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializedFMUstateSize";
    guarded(c, F, |inst| {
        let Some(size) = size.as_mut() else {
            return null_argument(inst, F, "size");
        };
        match inst.serialize_fmu_state(F, state as *mut FmuState) {
            Ok(bytes) => {
                *size = bytes.len();
                fmi2Status::OK
            }
            Err(status) => status,
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializeFMUstate";
    guarded(c, F, |inst| {
        let Some(out) = slice_mut(bytes as *mut u8, size) else {
            return null_argument(inst, F, "serializedState");
        };
        match inst.serialize_fmu_state(F, state as *mut FmuState) {
            Ok(data) if data.len() <= out.len() => {
                out[..data.len()].copy_from_slice(&data);
                fmi2Status::OK
            }
            Ok(data) => inst.error(&format!(
                "{F}: size {size} is too small, the state needs {} bytes",
                data.len()
            )),
            Err(status) => status,
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2DeSerializeFMUstate";
    guarded(c, F, |inst| {
        let (Some(data), Some(slot)) = (slice(bytes as *const u8, size), state.as_mut()) else {
            return null_argument(inst, F, "serializedState and FMUstate");
        };
        match inst.deserialize_fmu_state(data, *slot as *mut FmuState) {
            Ok(ptr) => {
                *slot = ptr as fmi2FMUstate;
                fmi2Status::OK
            }
            Err(status) => status,
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    _unknown: *const fmi2ValueReference,
    _n_unknown: usize,
    _known: *const fmi2ValueReference,
    _n_known: usize,
    _dv_known: *const fmi2Real,
    _dv_unknown: *mut fmi2Real,
) -> fmi2Status {
    guarded(c, "fmi2GetDirectionalDerivative", |inst| {
        inst.unsupported(
            "fmi2GetDirectionalDerivative",
            "providesDirectionalDerivative is false",
        )
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *const fmi2Real,
) -> fmi2Status {
    guarded(c, "fmi2SetRealInputDerivatives", |inst| {
        inst.unsupported(
            "fmi2SetRealInputDerivatives",
            "canInterpolateInputs is false",
        )
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    guarded(c, "fmi2GetRealOutputDerivatives", |inst| {
        inst.unsupported(
            "fmi2GetRealOutputDerivatives",
            "maxOutputDerivativeOrder is 0",
        )
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    current_communication_point: fmi2Real,
    communication_step_size: fmi2Real,
    _no_set_fmu_state_prior_to_current_point: fmi2Boolean,
) -> fmi2Status {
    guarded(c, "fmi2DoStep", |inst| {
        inst.do_step(current_communication_point, communication_step_size)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    guarded(c, "fmi2CancelStep", |inst| {
        inst.unsupported(
            "fmi2CancelStep",
            "steps are never asynchronous (canRunAsynchronuously is false)",
        )
    })
}

/// Status kinds this FMU cannot report give `fmi2Discard`, as FMI 2.0 section 4.2.3 asks.
fn status_unavailable(inst: &Instance, function: &str, kind: c_int) -> fmi2Status {
    inst.logger.log(
        fmi2Status::Discard,
        &format!("{function}: status kind {kind} is not available from this FMU"),
    );
    fmi2Status::Discard
}

/// The status kinds nobody asks this FMU for: checked, then `fmi2Discard` with a log line.
unsafe fn unavailable_status<T>(
    c: fmi2Component,
    function: &'static str,
    kind: c_int,
    value: *mut T,
) -> fmi2Status {
    guarded(c, function, |inst| {
        if value.is_null() {
            return null_argument(inst, function, "value");
        }
        if !inst.status_check(function) {
            return fmi2Status::Error;
        }
        status_unavailable(inst, function, kind)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut c_int,
) -> fmi2Status {
    unavailable_status(c, "fmi2GetStatus", kind, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealStatus";
    guarded(c, F, |inst| {
        let Some(value) = value.as_mut() else {
            return null_argument(inst, F, "value");
        };
        if kind != FMI2_LAST_SUCCESSFUL_TIME {
            return if inst.status_check(F) {
                status_unavailable(inst, F, kind)
            } else {
                fmi2Status::Error
            };
        }
        match inst.last_successful_time() {
            Ok(t) => {
                *value = t;
                fmi2Status::OK
            }
            Err(status) => status,
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unavailable_status(c, "fmi2GetIntegerStatus", kind, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBooleanStatus";
    guarded(c, F, |inst| {
        let Some(value) = value.as_mut() else {
            return null_argument(inst, F, "value");
        };
        if !inst.status_check(F) {
            return fmi2Status::Error;
        }
        if kind != FMI2_TERMINATED {
            return status_unavailable(inst, F, kind);
        }
        // The models never ask to end the simulation early.
        *value = FMI2_FALSE;
        fmi2Status::OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2String,
) -> fmi2Status {
    unavailable_status(c, "fmi2GetStringStatus", kind, value)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    type Log = Mutex<Vec<(c_int, String)>>;

    unsafe extern "C" fn record(
        env: *mut std::ffi::c_void,
        _: fmi2String,
        status: c_int,
        _: fmi2String,
        msg: fmi2String,
    ) {
        let log = &*(env as *const Log);
        if let Ok(mut lines) = log.lock() {
            lines.push((status, CStr::from_ptr(msg).to_string_lossy().into_owned()));
        }
    }

    fn line(log: &Log, i: usize) -> (c_int, String) {
        log.lock().map(|lines| lines[i].clone()).unwrap_or_default()
    }

    #[test]
    fn a_panic_is_logged_and_becomes_fatal() {
        let log: Log = Mutex::new(Vec::new());
        // SAFETY (test only): the FMU calls the logger with exactly these five arguments.
        let callback = unsafe {
            std::mem::transmute::<
                unsafe extern "C" fn(
                    *mut std::ffi::c_void,
                    fmi2String,
                    c_int,
                    fmi2String,
                    fmi2String,
                ),
                fmi2CallbackLogger,
            >(record)
        };
        let env = &log as *const _ as *mut std::ffi::c_void;
        let instance = Instance::new(REGISTRY[0], Logger::new(Some(callback), env, "t"));
        let c = Box::into_raw(Box::new(instance)) as fmi2Component;
        assert_eq!(
            guarded(c, "fmi2Test", |_| panic!("boom")),
            fmi2Status::Fatal
        );
        assert_eq!(
            line(&log, 0),
            (4, "fmi2Test: internal error: boom".to_string())
        );
        // Only freeing is left to do, and it works.
        unsafe {
            assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::Error);
            assert!(line(&log, 1).1.contains("illegal call in state Fatal"));
            fmi2FreeInstance(c);
        }
    }

    #[test]
    fn resource_locations() {
        let path = |s: &str| Some(PathBuf::from(s));
        assert_eq!(
            resource_path("file:///tmp/a%20b/resources").ok(),
            path("/tmp/a b/resources")
        );
        assert_eq!(resource_path("file:/tmp/x").ok(), path("/tmp/x"));
        assert_eq!(resource_path("file://localhost/tmp/x").ok(), path("/tmp/x"));
        assert!(resource_path("http://example.org/x").is_err());
        assert!(resource_path("file:///bad%zz").is_err());
    }
}
