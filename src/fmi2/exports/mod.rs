//! Every common and Co-Simulation function of FMI 2.0 (FMPy resolves all of them when it loads a
//! binary). Each body runs inside `catch_unwind`: a panic is logged and becomes `fmi2Fatal`, it
//! never unwinds into the importer. Pointers are checked here and turned into slices. The Model
//! Exchange functions are in `model_exchange.rs`.
//!
//! Every `unsafe` block below relies on the importer keeping the FMI 2.0 calling convention: a
//! component from `fmi2Instantiate` (or NULL), arrays of the length it passes (or NULL), and
//! NUL-terminated strings. `guarded` and the slice helpers check what can be checked (the
//! instance handle, `handles`; a NULL array of non-zero length).

use super::instance::Instance;
use super::logger::Logger;
use super::registry::REGISTRY;
use super::types::*;
use std::ffi::{c_char, c_int, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

/// The instance behind `c`, if `c` is the handle of a live instance of ours ([`handles`]).
///
/// # Safety
/// No other reference to the instance may be alive (FMI 2.0: one call at a time per instance).
unsafe fn instance<'a>(c: fmi2Component) -> Option<&'a mut Instance> {
    // SAFETY: a live instance of ours, owned by the handle table until fmi2FreeInstance.
    handles::resolve(c).map(|ptr| unsafe { &mut *ptr })
}

fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Every export's one path: checks the instance pointer, then runs `body` on it; a panic is
/// logged and the instance becomes fatal, it never unwinds into the importer.
///
/// # Safety
/// As [`instance`].
pub(crate) unsafe fn guarded(
    c: fmi2Component,
    function: &str,
    body: impl FnOnce(&mut Instance) -> fmi2Status,
) -> fmi2Status {
    // SAFETY: see `instance`.
    let Some(inst) = (unsafe { instance(c) }) else {
        return fmi2Status::Error;
    };
    // One handle table serves both FMI versions: an instance answers only its own version's calls.
    if function.starts_with("fmi3") != inst.logger.is_fmi3() {
        return inst.error(&format!(
            "{function}: the instance was instantiated through the other FMI version's API"
        ));
    }
    let ptr: *mut Instance = inst;
    // SAFETY: `ptr` is live for the whole call; the closure's borrow ends before the panic arm.
    match catch_unwind(AssertUnwindSafe(|| body(unsafe { &mut *ptr }))) {
        Ok(status) => status,
        Err(payload) => {
            // SAFETY: as above; nothing else borrows the instance now.
            let inst = unsafe { &mut *ptr };
            inst.set_state(super::instance::MachineState::Fatal);
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
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, n: usize) -> Option<&'a [T]> {
    match (ptr.is_null(), n) {
        (_, 0) => Some(&[]),
        (true, _) => None,
        // SAFETY: the caller promises `n` readable elements at a non-null `ptr`.
        (false, _) => Some(unsafe { std::slice::from_raw_parts(ptr, n) }),
    }
}

/// # Safety
/// As [`slice`], for `n` writable elements.
pub(crate) unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize) -> Option<&'a mut [T]> {
    match (ptr.is_null(), n) {
        (_, 0) => Some(&mut []),
        (true, _) => None,
        // SAFETY: the caller promises `n` writable elements at a non-null `ptr`.
        (false, _) => Some(unsafe { std::slice::from_raw_parts_mut(ptr, n) }),
    }
}

/// # Safety
/// A non-null `s` must be NUL-terminated.
pub(crate) unsafe fn text(s: fmi2String) -> Option<String> {
    // SAFETY: non-null, and the caller promises NUL termination.
    (!s.is_null()).then(|| unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
}

#[cold]
#[inline(never)]
pub(crate) fn null_argument(inst: &Instance, function: &str, argument: &str) -> fmi2Status {
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
        // SAFETY: the importer passes NULL or its callback struct, and NULL or NUL-terminated
        // strings (FMI 2.0 section 2.1.5).
        let callbacks = unsafe { functions.as_ref() }?;
        let name = unsafe { text(instance_name) };
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
        if fmu_type != FMI2_CO_SIMULATION && fmu_type != FMI2_MODEL_EXCHANGE {
            return refuse(format!(
                "fmuType {fmu_type} is not supported: not an fmi2Type (0 Model Exchange, 1 Co-Simulation)"
            ));
        }
        let Some(guid) = (unsafe { text(fmu_guid) }) else {
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
        let model_exchange = fmu_type == FMI2_MODEL_EXCHANGE;
        if model_exchange && !factory.model_exchange() {
            return refuse(format!(
                "fmuType 0 is not supported: {} is Co-Simulation only (fmuType 1)",
                factory.info().name
            ));
        }
        let mut logger = logger;
        logger.debug = logging_on != FMI2_FALSE;
        // No model reads resources yet; a location that is not a file URI is still worth a word.
        if let Some(uri) = unsafe { text(fmu_resource_location) } {
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
        let mut instance = Box::new(Instance::new(*factory, logger));
        instance.model_exchange = model_exchange;
        let handle = handles::register(instance);
        if handle.is_none() {
            // The instance and its logger are gone; say why through the importer's callback.
            Logger::new(
                callbacks.logger,
                callbacks.component_environment,
                name.as_deref().unwrap_or("?"),
            )
            .log(
                fmi2Status::Error,
                &format!(
                    "fmi2Instantiate: {} instances are alive in this process, the most it holds",
                    handles::SLOTS
                ),
            );
        }
        handle
    });
    result.ok().flatten().unwrap_or(std::ptr::null_mut())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    // A freed or unknown handle finds nothing: nothing is read, nothing freed.
    let Some(inst) = handles::release(c) else {
        return;
    };
    // Dropping frees the instance's FMU states.
    let _ = catch_unwind(AssertUnwindSafe(|| drop(inst)));
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n_categories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    unsafe {
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
    unsafe {
        guarded(c, "fmi2SetupExperiment", |inst| {
            let tolerance = (tolerance_defined != FMI2_FALSE).then_some(tolerance);
            let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
            inst.setup_experiment(tolerance, start_time, stop)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2EnterInitializationMode", |inst| {
            inst.enter_initialization_mode()
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2ExitInitializationMode", |inst| {
            inst.exit_initialization_mode()
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    unsafe { guarded(c, "fmi2Terminate", |inst| inst.terminate()) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    unsafe { guarded(c, "fmi2Reset", |inst| inst.reset()) }
}

mod fmu_state;
pub(crate) mod handles;
mod model_exchange;
#[cfg(test)]
mod tests;
mod values;

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    unknown: *const fmi2ValueReference,
    n_unknown: usize,
    known: *const fmi2ValueReference,
    n_known: usize,
    dv_known: *const fmi2Real,
    dv_unknown: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetDirectionalDerivative";
    unsafe {
        guarded(c, F, |inst| {
            // SAFETY: the importer passes arrays of the stated lengths (or NULL, refused here).
            let (Some(unknown), Some(known), Some(dv_known), Some(dv_unknown)) = (
                slice(unknown, n_unknown),
                slice(known, n_known),
                slice(dv_known, n_known),
                slice_mut(dv_unknown, n_unknown),
            ) else {
                return null_argument(inst, F, "vUnknown_ref, vKnown_ref, dvKnown or dvUnknown");
            };
            inst.get_directional_derivative(unknown, known, dv_known, dv_unknown)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *const fmi2Real,
) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2SetRealInputDerivatives", |inst| {
            inst.unsupported(
                "fmi2SetRealInputDerivatives",
                "canInterpolateInputs is false",
            )
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2GetRealOutputDerivatives", |inst| {
            inst.unsupported(
                "fmi2GetRealOutputDerivatives",
                "maxOutputDerivativeOrder is 0",
            )
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    current_communication_point: fmi2Real,
    communication_step_size: fmi2Real,
    _no_set_fmu_state_prior_to_current_point: fmi2Boolean,
) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2DoStep", |inst| {
            inst.do_step(current_communication_point, communication_step_size)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2CancelStep", |inst| {
            inst.unsupported(
                "fmi2CancelStep",
                "steps are never asynchronous (canRunAsynchronuously is false)",
            )
        })
    }
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
    unsafe {
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
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut c_int,
) -> fmi2Status {
    unsafe { unavailable_status(c, "fmi2GetStatus", kind, value) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealStatus";
    unsafe {
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
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unsafe { unavailable_status(c, "fmi2GetIntegerStatus", kind, value) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBooleanStatus";
    unsafe {
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
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2String,
) -> fmi2Status {
    unsafe { unavailable_status(c, "fmi2GetStringStatus", kind, value) }
}
