//! FMI 2.0 Model Exchange for the models without continuous states
//! ([`Model::ALGEBRAIC_MODEL_EXCHANGE`](crate::models::Model::ALGEBRAIC_MODEL_EXCHANGE)): the
//! event-mode / continuous-time-mode state machine (FMI 2.0.4 section 3.2.3) over the same
//! [`Instance`] and model as Co-Simulation.
//!
//! The outputs are algebraic in the inputs. The friction history is a discrete state: it is
//! committed at every completed integrator step (`fmi2CompletedIntegratorStep`) and at every event
//! (`fmi2NewDiscreteStates`), never during the integrator's trial evaluations. That is where
//! Co-Simulation commits it (each communication point), so a Model Exchange run whose integrator
//! steps fall on the communication points gives the Co-Simulation outputs, and the stop operator
//! needs no event of its own: it is rate-independent and continuous in the length.

use super::exports::{guarded, null_argument, slice, slice_mut};
use super::instance::{allowed, Instance, MachineState};
use super::types::*;
use crate::models::Report;

/// `fmi2EventInfo` (fmi2FunctionTypes.h).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct fmi2EventInfo {
    pub new_discrete_states_needed: fmi2Boolean,
    pub terminate_simulation: fmi2Boolean,
    pub nominals_of_continuous_states_changed: fmi2Boolean,
    pub values_of_continuous_states_changed: fmi2Boolean,
    pub next_event_time_defined: fmi2Boolean,
    pub next_event_time: fmi2Real,
}

impl Instance {
    /// Refuses Model Exchange calls on a Co-Simulation instance and in the wrong state.
    fn me_allowed(&self, function: &str, mask: u32) -> bool {
        if !self.model_exchange {
            self.error(&format!(
                "{function}: a Model Exchange function, but the instance was instantiated for \
                 Co-Simulation"
            ));
            return false;
        }
        self.allowed(function, mask)
    }

    /// Commits the discrete state (friction history) at the current inputs and time.
    fn commit(&mut self, function: &str) -> fmi2Status {
        let status = self.refresh_outputs(function);
        if status >= fmi2Status::Error {
            return status;
        }
        let mut report = Report::default();
        self.runtime.update_discrete_states(self.time, &mut report);
        status.max(self.forward(function, report, false))
    }

    pub fn enter_event_mode(&mut self) -> fmi2Status {
        const F: &str = "fmi2EnterEventMode";
        if !self.me_allowed(F, allowed::EVENT_OR_CONTINUOUS_TIME_MODE) {
            return fmi2Status::Error;
        }
        self.state = MachineState::EventMode;
        fmi2Status::OK
    }

    /// One event iteration: commits the history; no continuous states, no time events.
    pub fn new_discrete_states(&mut self, info: &mut fmi2EventInfo) -> fmi2Status {
        const F: &str = "fmi2NewDiscreteStates";
        if !self.me_allowed(F, allowed::EVENT_MODE) {
            return fmi2Status::Error;
        }
        let status = self.commit(F);
        *info = fmi2EventInfo {
            new_discrete_states_needed: FMI2_FALSE,
            terminate_simulation: FMI2_FALSE,
            nominals_of_continuous_states_changed: FMI2_FALSE,
            values_of_continuous_states_changed: FMI2_FALSE,
            next_event_time_defined: FMI2_FALSE,
            next_event_time: 0.0,
        };
        status
    }

    pub fn enter_continuous_time_mode(&mut self) -> fmi2Status {
        const F: &str = "fmi2EnterContinuousTimeMode";
        if !self.me_allowed(F, allowed::EVENT_MODE) {
            return fmi2Status::Error;
        }
        self.state = MachineState::ContinuousTimeMode;
        fmi2Status::OK
    }

    /// Commits the history at the accepted point; never asks for an event.
    pub fn completed_integrator_step(&mut self) -> (fmi2Status, bool) {
        const F: &str = "fmi2CompletedIntegratorStep";
        if !self.me_allowed(F, allowed::CONTINUOUS_TIME_MODE) {
            return (fmi2Status::Error, false);
        }
        (self.commit(F), false)
    }

    pub fn set_time(&mut self, time: f64) -> fmi2Status {
        const F: &str = "fmi2SetTime";
        if !self.me_allowed(F, allowed::EVENT_OR_CONTINUOUS_TIME_MODE) {
            return fmi2Status::Error;
        }
        if !time.is_finite() {
            return self.error(&format!("{F}: time must be finite, got {time}"));
        }
        self.time = time;
        fmi2Status::OK
    }

    /// The continuous-state vectors: none, so only `n = 0` is accepted.
    pub fn states(&self, function: &str, mask: u32, n: usize, what: &str) -> fmi2Status {
        if !self.me_allowed(function, mask) {
            return fmi2Status::Error;
        }
        if n != 0 {
            return self.error(&format!(
                "{function}: {n} {what} requested, but this model has none \
                 (numberOfContinuousStates and numberOfEventIndicators are 0)"
            ));
        }
        fmi2Status::OK
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    unsafe { guarded(c, "fmi2EnterEventMode", |inst| inst.enter_event_mode()) }
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
            match event_info.as_mut() {
                Some(info) => inst.new_discrete_states(info),
                None => null_argument(inst, F, "fmi2eventInfo"),
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2EnterContinuousTimeMode", |inst| {
            inst.enter_continuous_time_mode()
        })
    }
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
            let (status, event) = inst.completed_integrator_step();
            *enter = if event { FMI2_TRUE } else { FMI2_FALSE };
            *terminate = FMI2_FALSE;
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    unsafe { guarded(c, "fmi2SetTime", |inst| inst.set_time(time)) }
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
            if slice(x, nx).is_none() {
                return null_argument(inst, F, "x");
            }
            inst.states(F, allowed::CONTINUOUS_TIME_MODE, nx, "states")
        })
    }
}

/// The getters of state-sized vectors: none to write.
unsafe fn get_vector(
    c: fmi2Component,
    function: &'static str,
    mask: u32,
    values: *mut fmi2Real,
    n: usize,
    what: &'static str,
) -> fmi2Status {
    unsafe {
        guarded(c, function, |inst| {
            // SAFETY: the importer passes n writable values (or NULL, refused here).
            if slice_mut(values, n).is_none() {
                return null_argument(inst, function, what);
            }
            inst.states(function, mask, n, what)
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
            allowed::GET_STATES,
            derivatives,
            nx,
            "derivatives",
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
            allowed::GET_STATES,
            indicators,
            ni,
            "event indicators",
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetContinuousStates(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    unsafe {
        get_vector(
            c,
            "fmi2GetContinuousStates",
            allowed::GET_STATES,
            x,
            nx,
            "states",
        )
    }
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
            allowed::GET_STATES,
            nominals,
            nx,
            "nominals",
        )
    }
}
