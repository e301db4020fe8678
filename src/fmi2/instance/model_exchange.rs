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

use super::{allowed, Instance, MachineState};
use crate::fmi2::types::{fmi2EventInfo, fmi2Status, FMI2_FALSE, FMI2_TRUE};
use crate::models::{EventUpdate, Report};

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

    /// Gives the model the current time and builds it in initialization mode (as fmi2GetReal
    /// does); outputs are refreshed if inputs, states or time made them stale.
    fn prepare(&mut self, function: &str) -> fmi2Status {
        self.runtime.set_time(self.time);
        self.refresh_outputs(function)
    }

    /// Commits the discrete state at the current inputs and time: event mode or a completed
    /// integrator step.
    fn commit(&mut self, function: &str, event_mode: bool) -> (fmi2Status, EventUpdate, bool) {
        let status = self.prepare(function);
        if status >= fmi2Status::Error {
            return (status, EventUpdate::default(), false);
        }
        let mut report = Report::default();
        let (update, event) = if event_mode {
            let update = self.runtime.update_discrete_states(self.time, &mut report);
            (update, false)
        } else {
            let event = self
                .runtime
                .completed_integrator_step(self.time, &mut report);
            (EventUpdate::default(), event)
        };
        (
            status.max(self.forward(function, report, false)),
            update,
            event,
        )
    }

    pub fn enter_event_mode(&mut self) -> fmi2Status {
        const F: &str = "fmi2EnterEventMode";
        if !self.me_allowed(F, allowed::EVENT_OR_CONTINUOUS_TIME_MODE) {
            return fmi2Status::Error;
        }
        self.set_state(MachineState::EventMode);
        fmi2Status::OK
    }

    /// One event iteration: commits the history, lets the model update its discrete states (and
    /// reinitialize continuous ones), and gives the next time event.
    pub fn new_discrete_states(&mut self, info: &mut fmi2EventInfo) -> fmi2Status {
        const F: &str = "fmi2NewDiscreteStates";
        if !self.me_allowed(F, allowed::EVENT_MODE) {
            return fmi2Status::Error;
        }
        let (status, update, _) = self.commit(F, true);
        let next = self.runtime.next_time_event(self.time);
        let flag = |b: bool| if b { FMI2_TRUE } else { FMI2_FALSE };
        *info = fmi2EventInfo {
            new_discrete_states_needed: flag(update.iterate),
            terminate_simulation: flag(update.terminate),
            nominals_of_continuous_states_changed: FMI2_FALSE,
            values_of_continuous_states_changed: flag(update.states_changed),
            next_event_time_defined: flag(next.is_some()),
            next_event_time: next.unwrap_or(0.0),
        };
        status
    }

    pub fn enter_continuous_time_mode(&mut self) -> fmi2Status {
        const F: &str = "fmi2EnterContinuousTimeMode";
        if !self.me_allowed(F, allowed::EVENT_MODE) {
            return fmi2Status::Error;
        }
        self.set_state(MachineState::ContinuousTimeMode);
        fmi2Status::OK
    }

    /// Commits the history at the accepted point; the model may ask for an event there.
    pub fn completed_integrator_step(&mut self) -> (fmi2Status, bool) {
        const F: &str = "fmi2CompletedIntegratorStep";
        if !self.me_allowed(F, allowed::CONTINUOUS_TIME_MODE) {
            return (fmi2Status::Error, false);
        }
        let (status, _, event) = self.commit(F, false);
        (status, event)
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
        self.runtime.set_time(time);
        fmi2Status::OK
    }

    /// Checks a state-sized (or event-indicator-sized) vector call: interface, machine state,
    /// length; then builds the model if initialization needs it.
    fn vector_call(&mut self, function: &str, mask: u32, n: usize, what: Vector) -> fmi2Status {
        if !self.me_allowed(function, mask) {
            return fmi2Status::Error;
        }
        let (expected, count) = match what {
            Vector::EventIndicators => (
                self.runtime.event_indicator_count(),
                "numberOfEventIndicators",
            ),
            _ => (self.runtime.state_count(), "numberOfContinuousStates"),
        };
        if n != expected {
            let has = match expected {
                0 => "none".to_string(),
                _ => expected.to_string(),
            };
            return self.error(&format!(
                "{function}: {n} {} requested, but this model has {has} ({count} is {expected})",
                what.name()
            ));
        }
        if n == 0 {
            return fmi2Status::OK;
        }
        // The hot path: only the time goes to the model; the outputs are not recomputed (an
        // unbuilt model is built in initialization mode, as fmi2GetReal does).
        self.runtime.set_time(self.time);
        if self.runtime.is_built() {
            fmi2Status::OK
        } else {
            self.refresh_outputs(function)
        }
    }

    /// `fmi2GetContinuousStates`, `fmi2GetDerivatives`, `fmi2GetEventIndicators`,
    /// `fmi2GetNominalsOfContinuousStates` on a checked buffer.
    pub fn get_vector(&mut self, function: &str, what: Vector, out: &mut [f64]) -> fmi2Status {
        let status = self.vector_call(function, allowed::GET_STATES, out.len(), what);
        if status >= fmi2Status::Error || out.is_empty() {
            return status;
        }
        let result = match what {
            Vector::States => self.runtime.continuous_states(out),
            Vector::Derivatives => self.runtime.derivatives(out),
            Vector::EventIndicators => self.runtime.event_indicators(out),
            Vector::Nominals => {
                self.runtime.nominals(out);
                Ok(())
            }
        };
        match result {
            // The last guard of "no output is ever NaN", as in fmi2GetReal.
            Ok(()) => match out.iter().position(|x| !x.is_finite()) {
                None => status,
                Some(k) => self.error(&format!(
                    "{function}: {} element {k} is {}: the model produced a non-finite value",
                    what.name(),
                    out[k]
                )),
            },
            Err(why) => self.error(&format!("{function}: {why}")),
        }
    }

    /// `fmi2SetContinuousStates`: finite values the model accepts, or an error and the states
    /// kept.
    pub fn set_continuous_states(&mut self, x: &[f64]) -> fmi2Status {
        const F: &str = "fmi2SetContinuousStates";
        let status = self.vector_call(F, allowed::CONTINUOUS_TIME_MODE, x.len(), Vector::States);
        if status >= fmi2Status::Error || x.is_empty() {
            return status;
        }
        match self.runtime.set_continuous_states(x) {
            Ok(()) => status,
            Err(why) => self.error(&format!("{F}: {why}")),
        }
    }
}

/// The state-sized vectors of Model Exchange (and the event indicators).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Vector {
    States,
    Derivatives,
    EventIndicators,
    Nominals,
}

impl Vector {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Vector::States => "states",
            Vector::Derivatives => "derivatives",
            Vector::EventIndicators => "event indicators",
            Vector::Nominals => "nominals",
        }
    }
}
