//! The Model Exchange functions of FMI 2.0 (section 3.2), for every model that serves Model
//! Exchange; the state machine behind them is `src/export/instance/model_exchange.rs`.

use super::guarded;
use crate::export::guard::{null_argument, slice, slice_mut};
use crate::export::instance::Vector;
use crate::fmi2::types::*;

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    const F: &str = "fmi2EnterEventMode";
    unsafe { guarded(c, F, |inst| inst.enter_event_mode(F)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2NewDiscreteStates(
    c: fmi2Component,
    event_info: *mut fmi2EventInfo,
) -> fmi2Status {
    const F: &str = "fmi2NewDiscreteStates";
    unsafe {
        guarded(c, F, |inst| {
            // SAFETY: a non-null pointer from the importer points to an fmi2EventInfo.
            let Some(info) = event_info.as_mut() else {
                return null_argument(inst, F, "fmi2eventInfo");
            };
            let (status, iteration) = inst.new_discrete_states(F);
            let flag = |b: bool| if b { FMI2_TRUE } else { FMI2_FALSE };
            *info = fmi2EventInfo {
                new_discrete_states_needed: flag(iteration.update.iterate),
                terminate_simulation: flag(iteration.update.terminate),
                nominals_of_continuous_states_changed: FMI2_FALSE,
                values_of_continuous_states_changed: flag(iteration.update.states_changed),
                next_event_time_defined: flag(iteration.next_event_time.is_some()),
                next_event_time: iteration.next_event_time.unwrap_or(0.0),
            };
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    const F: &str = "fmi2EnterContinuousTimeMode";
    unsafe { guarded(c, F, |inst| inst.enter_continuous_time_mode(F)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: fmi2Component,
    _no_set_fmu_state_prior_to_current_point: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate_simulation: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2CompletedIntegratorStep";
    unsafe {
        guarded(c, F, |inst| {
            // SAFETY: non-null pointers from the importer point to fmi2Booleans.
            let (Some(enter), Some(terminate)) =
                (enter_event_mode.as_mut(), terminate_simulation.as_mut())
            else {
                return null_argument(inst, F, "enterEventMode or terminateSimulation");
            };
            let (status, event) = inst.completed_integrator_step(F);
            *enter = if event { FMI2_TRUE } else { FMI2_FALSE };
            *terminate = FMI2_FALSE;
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    const F: &str = "fmi2SetTime";
    unsafe { guarded(c, F, |inst| inst.set_time(F, time)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetContinuousStates(
    c: fmi2Component,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    const F: &str = "fmi2SetContinuousStates";
    unsafe {
        guarded(c, F, |inst| {
            // SAFETY: the importer passes nx readable values (or NULL, refused here).
            match slice(x, nx) {
                Some(x) => inst.set_continuous_states(F, x),
                None => null_argument(inst, F, "x"),
            }
        })
    }
}

/// The getters of state-sized vectors, on the importer's buffer of n values.
unsafe fn get_vector(
    c: fmi2Component,
    function: &'static str,
    what: Vector,
    values: *mut fmi2Real,
    n: usize,
) -> fmi2Status {
    unsafe {
        guarded(c, function, |inst| {
            // SAFETY: the importer passes n writable values (or NULL, refused here).
            match slice_mut(values, n) {
                Some(out) => inst.get_vector(function, what, out),
                None => null_argument(inst, function, what.name()),
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDerivatives(
    c: fmi2Component,
    derivatives: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    unsafe {
        get_vector(
            c,
            "fmi2GetDerivatives",
            Vector::Derivatives,
            derivatives,
            nx,
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetEventIndicators(
    c: fmi2Component,
    indicators: *mut fmi2Real,
    ni: usize,
) -> fmi2Status {
    unsafe {
        get_vector(
            c,
            "fmi2GetEventIndicators",
            Vector::EventIndicators,
            indicators,
            ni,
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetContinuousStates(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    unsafe { get_vector(c, "fmi2GetContinuousStates", Vector::States, x, nx) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
    c: fmi2Component,
    nominals: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    unsafe {
        get_vector(
            c,
            "fmi2GetNominalsOfContinuousStates",
            Vector::Nominals,
            nominals,
            nx,
        )
    }
}
