//! The FMI 3.0 functions of every interface: instantiation, the mode changes, `fmi3DoStep` (FMU
//! states are in `fmu_state`, derivatives and dependencies in `derivatives`). Each body runs under
//! the version-neutral panic guard ([`crate::export::guard`]) on the shared `Instance`.
//!
//! Every `unsafe` block relies on the importer keeping the FMI 3.0 calling convention: an
//! instance from `fmi3Instantiate*` (or NULL), arrays of the length it passes (or NULL), and
//! NUL-terminated strings. The shared helpers check what can be checked.

use super::logger::{self, Fmi3LogMessageCallback};
use super::{fmi3Boolean, fmi3Instance, fmi3Status, fmi3String, fmi3ValueReference};
use crate::export::guard::{self, null_argument, slice, text};
use crate::export::handles;
use crate::export::instance::{Api, Instance};
use crate::export::logger::Logger;
pub(super) use crate::export::Status;
use crate::export::REGISTRY;
use std::ffi::{c_char, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// How an FMI 3.0 instance names what its messages mention.
static API: Api = Api {
    version: "FMI 3.0",
    step_state: "StepMode",
    get_fmu_state: "fmi3GetFMUState",
    serialize_fmu_state: "fmi3SerializeFMUState",
};

/// Runs `body` on the FMI 3.0 instance behind `instance` under the panic guard
/// ([`guard::guarded`]).
///
/// # Safety
/// As [`guard::guarded`].
pub(super) unsafe fn guarded(
    instance: fmi3Instance,
    function: &str,
    body: impl FnOnce(&mut Instance) -> fmi3Status,
) -> fmi3Status {
    unsafe { guard::guarded(&API, instance, function, body) }
}

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// The shared part of both instantiation functions: checks the name and token, finds the model.
#[allow(clippy::too_many_arguments)] // the FMI arguments both functions share, passed through
fn instantiate(
    function: &str,
    instance_name: Option<String>,
    token: Option<String>,
    model_exchange: bool,
    logging_on: bool,
    environment: *mut c_void,
    log: Option<Fmi3LogMessageCallback>,
    (event_mode_used, early_return_allowed): (bool, bool),
) -> Option<fmi3Instance> {
    let name = instance_name.unwrap_or_default();
    let mut logger = logger::logger(log, environment, if name.is_empty() { "?" } else { &name });
    let refuse = |logger: &Logger, why: String| {
        logger.log(Status::Error, &format!("{function}: {why}"));
        None
    };
    if name.is_empty() {
        return refuse(&logger, "instanceName must be a non-empty string".into());
    }
    let Some(token) = token else {
        return refuse(&logger, "instantiationToken must not be NULL".into());
    };
    let Some(factory) = REGISTRY.iter().find(|f| f.info().guid == token) else {
        let known: Vec<String> = REGISTRY
            .iter()
            .map(|f| format!("{} {}", f.info().name, f.info().guid))
            .collect();
        return refuse(
            &logger,
            format!(
                "wrong instantiationToken {token}: the model description and the binary do not match (this binary implements {})",
                known.join(", ")
            ),
        );
    };
    if model_exchange && !factory.model_exchange() {
        return refuse(
            &logger,
            format!("{} is Co-Simulation only", factory.info().name),
        );
    }
    logger.debug = logging_on;
    let mut instance = Box::new(Instance::new(*factory, &API, logger));
    instance.model_exchange = model_exchange;
    instance.event_mode_used = event_mode_used;
    instance.early_return_allowed = early_return_allowed;
    let handle = handles::register(instance);
    if handle.is_none() {
        logger::logger(log, environment, &name).log(
            Status::Error,
            &format!(
                "{function}: {} instances are alive in this process, the most it holds",
                handles::SLOTS
            ),
        );
    }
    handle
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: fmi3String,
    instantiation_token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    event_mode_used: fmi3Boolean,
    early_return_allowed: fmi3Boolean,
    _required_intermediate_variables: *const fmi3ValueReference,
    _n_required_intermediate_variables: usize,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessageCallback>,
    _intermediate_update: *const c_void,
) -> fmi3Instance {
    let result = catch_unwind(|| {
        // SAFETY: NULL or NUL-terminated strings (FMI 3.0 section 2.2.3).
        let (name, token) = unsafe { (text(instance_name), text(instantiation_token)) };
        instantiate(
            "fmi3InstantiateCoSimulation",
            name,
            token,
            false,
            logging_on != 0,
            instance_environment,
            log_message,
            (event_mode_used != 0, early_return_allowed != 0),
        )
    });
    result.ok().flatten().unwrap_or(std::ptr::null_mut())
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instance_name: fmi3String,
    instantiation_token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessageCallback>,
) -> fmi3Instance {
    let result = catch_unwind(|| {
        // SAFETY: NULL or NUL-terminated strings.
        let (name, token) = unsafe { (text(instance_name), text(instantiation_token)) };
        instantiate(
            "fmi3InstantiateModelExchange",
            name,
            token,
            true,
            logging_on != 0,
            instance_environment,
            log_message,
            (false, false),
        )
    });
    result.ok().flatten().unwrap_or(std::ptr::null_mut())
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instance_name: fmi3String,
    _instantiation_token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    _logging_on: fmi3Boolean,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessageCallback>,
    _clock_update: *const c_void,
    _lock_preemption: *const c_void,
    _unlock_preemption: *const c_void,
) -> fmi3Instance {
    let _ = catch_unwind(|| {
        // SAFETY: NULL or a NUL-terminated string.
        let name = unsafe { text(instance_name) }.unwrap_or_else(|| "?".into());
        logger::logger(log_message, instance_environment, &name).log(
            Status::Error,
            "fmi3InstantiateScheduledExecution: Scheduled Execution is not supported: the models have no clocks or model partitions (the description declares Co-Simulation and Model Exchange only)",
        );
    });
    std::ptr::null_mut()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    let Some(inst) = handles::release(instance) else {
        return;
    };
    if !std::ptr::eq(inst.api, &API) {
        // An FMI 2.0 instance freed through FMI 3.0: freed all the same (nothing else can).
        inst.logger.log(
            Status::Warning,
            "fmi3FreeInstance: the instance was instantiated through FMI 2.0",
        );
    }
    let _ = catch_unwind(AssertUnwindSafe(|| drop(inst)));
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    logging_on: fmi3Boolean,
    n_categories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    const F: &str = "fmi3SetDebugLogging";
    unsafe {
        guarded(instance, F, |inst| {
            let Some(list) = slice(categories, n_categories) else {
                return null_argument(inst, F, "categories");
            };
            let names: Option<Vec<String>> = list.iter().map(|&s| text(s)).collect();
            let Some(names) = names else {
                return null_argument(inst, F, "a category name");
            };
            let refs: Vec<&str> = names.iter().map(String::as_str).collect();
            inst.set_debug_logging(F, logging_on != 0, &refs)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    tolerance_defined: fmi3Boolean,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: fmi3Boolean,
    stop_time: f64,
) -> fmi3Status {
    const F: &str = "fmi3EnterInitializationMode";
    unsafe {
        guarded(instance, F, |inst| {
            let tolerance = (tolerance_defined != 0).then_some(tolerance);
            let stop = (stop_time_defined != 0).then_some(stop_time);
            // FMI 2.0's fmi2SetupExperiment and fmi2EnterInitializationMode in one call.
            let status = inst.setup_experiment(F, tolerance, start_time, stop);
            if status >= Status::Error {
                return status;
            }
            status.max(inst.enter_initialization_mode(F))
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    const F: &str = "fmi3ExitInitializationMode";
    unsafe { guarded(instance, F, |inst| inst.exit_initialization_mode(F)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    const F: &str = "fmi3Terminate";
    unsafe { guarded(instance, F, |inst| inst.terminate(F)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    const F: &str = "fmi3Reset";
    unsafe { guarded(instance, F, |inst| inst.reset(F)) }
}

#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: fmi3Boolean,
    event_handling_needed: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    early_return: *mut fmi3Boolean,
    last_successful_time: *mut f64,
) -> fmi3Status {
    const F: &str = "fmi3DoStep";
    unsafe {
        guarded(instance, F, |inst| {
            let (Some(event), Some(terminate), Some(early), Some(last)) = (
                event_handling_needed.as_mut(),
                terminate_simulation.as_mut(),
                early_return.as_mut(),
                last_successful_time.as_mut(),
            ) else {
                return null_argument(
                    inst,
                    F,
                    "eventHandlingNeeded, terminateSimulation, earlyReturn or lastSuccessfulTime",
                );
            };
            let (status, end) =
                inst.do_step_with_events(F, current_communication_point, communication_step_size);
            *event = u8::from(end.event_handling_needed);
            *terminate = 0;
            *early = u8::from(end.early_return);
            *last = end.last_successful_time;
            status
        })
    }
}

/// Co-Simulation with `eventModeUsed`: from Event Mode to Step Mode.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    const F: &str = "fmi3EnterStepMode";
    unsafe { guarded(instance, F, |inst| inst.enter_step_mode(F)) }
}
