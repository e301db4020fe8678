//! The FMI 3.0 Model Exchange functions (FMI 3.0 section 3.2) over the shared instance's event
//! and continuous-time modes. `fmi3EnterEventMode` and `fmi3UpdateDiscreteStates` also serve
//! Co-Simulation with event mode.

use super::exports::{guarded, Status};
use super::{fmi3Boolean, fmi3Instance, fmi3Status};
use crate::export::guard::{null_argument, slice, slice_mut};
use crate::export::instance::{allowed, Vector};

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    const F: &str = "fmi3EnterEventMode";
    unsafe { guarded(instance, F, |inst| inst.enter_event_mode(F)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    instance: fmi3Instance,
    discrete_states_need_update: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    nominals_changed: *mut fmi3Boolean,
    values_changed: *mut fmi3Boolean,
    next_event_time_defined: *mut fmi3Boolean,
    next_event_time: *mut f64,
) -> fmi3Status {
    const F: &str = "fmi3UpdateDiscreteStates";
    unsafe {
        guarded(instance, F, |inst| {
            let (
                Some(update),
                Some(terminate),
                Some(nominals),
                Some(values),
                Some(defined),
                Some(next),
            ) = (
                discrete_states_need_update.as_mut(),
                terminate_simulation.as_mut(),
                nominals_changed.as_mut(),
                values_changed.as_mut(),
                next_event_time_defined.as_mut(),
                next_event_time.as_mut(),
            )
            else {
                return null_argument(inst, F, "an output argument");
            };
            let (status, iteration) = inst.new_discrete_states(F);
            *update = u8::from(iteration.update.iterate);
            *terminate = u8::from(iteration.update.terminate);
            *nominals = 0;
            *values = u8::from(iteration.update.states_changed);
            *defined = u8::from(iteration.next_event_time.is_some());
            *next = iteration.next_event_time.unwrap_or(0.0);
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status {
    const F: &str = "fmi3EnterContinuousTimeMode";
    unsafe { guarded(instance, F, |inst| inst.enter_continuous_time_mode(F)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    instance: fmi3Instance,
    _no_set_fmu_state_prior_to_current_point: fmi3Boolean,
    enter_event_mode: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
) -> fmi3Status {
    const F: &str = "fmi3CompletedIntegratorStep";
    unsafe {
        guarded(instance, F, |inst| {
            let (Some(enter), Some(terminate)) =
                (enter_event_mode.as_mut(), terminate_simulation.as_mut())
            else {
                return null_argument(inst, F, "enterEventMode or terminateSimulation");
            };
            let (status, event) = inst.completed_integrator_step(F);
            *enter = u8::from(event);
            *terminate = 0;
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetTime(instance: fmi3Instance, time: f64) -> fmi3Status {
    const F: &str = "fmi3SetTime";
    unsafe { guarded(instance, F, |inst| inst.set_time(F, time)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetContinuousStates(
    instance: fmi3Instance,
    x: *const f64,
    nx: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetContinuousStates";
    unsafe {
        guarded(instance, F, |inst| match slice(x, nx) {
            Some(x) => inst.set_continuous_states(F, x),
            None => null_argument(inst, F, "continuousStates"),
        })
    }
}

unsafe fn get_vector(
    instance: fmi3Instance,
    function: &'static str,
    what: Vector,
    values: *mut f64,
    n: usize,
) -> fmi3Status {
    unsafe {
        guarded(instance, function, |inst| match slice_mut(values, n) {
            Some(out) => inst.get_vector(function, what, out),
            None => null_argument(inst, function, what.name()),
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
    instance: fmi3Instance,
    derivatives: *mut f64,
    nx: usize,
) -> fmi3Status {
    unsafe {
        get_vector(
            instance,
            "fmi3GetContinuousStateDerivatives",
            Vector::Derivatives,
            derivatives,
            nx,
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetEventIndicators(
    instance: fmi3Instance,
    indicators: *mut f64,
    ni: usize,
) -> fmi3Status {
    unsafe {
        get_vector(
            instance,
            "fmi3GetEventIndicators",
            Vector::EventIndicators,
            indicators,
            ni,
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStates(
    instance: fmi3Instance,
    x: *mut f64,
    nx: usize,
) -> fmi3Status {
    unsafe { get_vector(instance, "fmi3GetContinuousStates", Vector::States, x, nx) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
    instance: fmi3Instance,
    nominals: *mut f64,
    nx: usize,
) -> fmi3Status {
    unsafe {
        get_vector(
            instance,
            "fmi3GetNominalsOfContinuousStates",
            Vector::Nominals,
            nominals,
            nx,
        )
    }
}

/// `fmi3GetNumberOfContinuousStates` and `fmi3GetNumberOfEventIndicators`: the model's counts,
/// available in every state but Fatal.
unsafe fn count(
    instance: fmi3Instance,
    function: &'static str,
    n: *mut usize,
    states: bool,
) -> fmi3Status {
    unsafe {
        guarded(instance, function, |inst| {
            let Some(n) = n.as_mut() else {
                return null_argument(inst, function, "the count");
            };
            if !inst.allowed(function, allowed::ALL_BUT_FATAL) {
                return Status::Error;
            }
            *n = if states {
                inst.runtime.state_count()
            } else {
                inst.runtime.event_indicator_count()
            };
            Status::OK
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
    instance: fmi3Instance,
    n: *mut usize,
) -> fmi3Status {
    unsafe { count(instance, "fmi3GetNumberOfContinuousStates", n, true) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
    instance: fmi3Instance,
    n: *mut usize,
) -> fmi3Status {
    unsafe { count(instance, "fmi3GetNumberOfEventIndicators", n, false) }
}
