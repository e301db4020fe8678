//! Model Exchange (FMI 2.0 and FMI 3.0) for the models without continuous states
//! ([`Model::ALGEBRAIC_MODEL_EXCHANGE`](crate::models::Model::ALGEBRAIC_MODEL_EXCHANGE)): the
//! event-mode / continuous-time-mode state machine (FMI 2.0.4 section 3.2.3, FMI 3.0 section 3.2) over the same
//! [`Instance`] and model as Co-Simulation.
//!
//! The outputs are algebraic in the inputs. The friction history is a discrete state: it is
//! committed at every completed integrator step (`fmi2CompletedIntegratorStep`) and at every event
//! (`fmi2NewDiscreteStates`), never during the integrator's trial evaluations. That is where
//! Co-Simulation commits it (each communication point), so a Model Exchange run whose integrator
//! steps fall on the communication points gives the Co-Simulation outputs, and the stop operator
//! needs no event of its own: it is rate-independent and continuous in the length.

use super::{allowed, Instance, MachineState};
use crate::export::Status;
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
    fn prepare(&mut self, function: &str) -> Status {
        self.runtime.set_time(self.time);
        self.refresh_outputs(function)
    }

    /// Commits the discrete state at the current inputs and time: event mode or a completed
    /// integrator step.
    fn commit(&mut self, function: &str, event_mode: bool) -> (Status, EventUpdate, bool) {
        let status = self.prepare(function);
        if status >= Status::Error {
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

    pub fn enter_event_mode(&mut self, function: &str) -> Status {
        if self.co_simulation_events() {
            return self.co_simulation_enter_event_mode(function);
        }
        if !self.me_allowed(function, allowed::EVENT_OR_CONTINUOUS_TIME_MODE) {
            return Status::Error;
        }
        self.set_state(MachineState::EventMode);
        Status::OK
    }

    /// One event iteration: commits the history, lets the model update its discrete states (and
    /// reinitialize continuous ones), and gives the next time event.
    pub fn new_discrete_states(&mut self, function: &str) -> (Status, EventIteration) {
        if self.co_simulation_events() {
            return self.co_simulation_update_discrete_states(function);
        }
        if !self.me_allowed(function, allowed::EVENT_MODE) {
            return (Status::Error, EventIteration::default());
        }
        let (status, update, _) = self.commit(function, true);
        let next_event_time = self.runtime.next_time_event(self.time);
        (
            status,
            EventIteration {
                update,
                next_event_time,
            },
        )
    }

    pub fn enter_continuous_time_mode(&mut self, function: &str) -> Status {
        if !self.me_allowed(function, allowed::EVENT_MODE) {
            return Status::Error;
        }
        self.set_state(MachineState::ContinuousTimeMode);
        Status::OK
    }

    /// Commits the history at the accepted point; the model may ask for an event there.
    pub fn completed_integrator_step(&mut self, function: &str) -> (Status, bool) {
        if !self.me_allowed(function, allowed::CONTINUOUS_TIME_MODE) {
            return (Status::Error, false);
        }
        let (status, _, event) = self.commit(function, false);
        (status, event)
    }

    pub fn set_time(&mut self, function: &str, time: f64) -> Status {
        if !self.me_allowed(function, allowed::EVENT_OR_CONTINUOUS_TIME_MODE) {
            return Status::Error;
        }
        if !time.is_finite() {
            return self.error(&format!("{function}: time must be finite, got {time}"));
        }
        self.time = time;
        self.runtime.set_time(time);
        Status::OK
    }

    /// Checks a state-sized (or event-indicator-sized) vector call: interface, machine state,
    /// length; then builds the model if initialization needs it.
    fn vector_call(&mut self, function: &str, mask: u32, n: usize, what: Vector) -> Status {
        if !self.me_allowed(function, mask) {
            return Status::Error;
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
            return Status::OK;
        }
        // The hot path: only the time goes to the model; the outputs are not recomputed (an
        // unbuilt model is built in initialization mode, as fmi2GetReal does).
        self.runtime.set_time(self.time);
        if self.runtime.is_built() {
            Status::OK
        } else {
            self.refresh_outputs(function)
        }
    }

    /// `fmi2GetContinuousStates`, `fmi2GetDerivatives`, `fmi2GetEventIndicators`,
    /// `fmi2GetNominalsOfContinuousStates` on a checked buffer.
    pub fn get_vector(&mut self, function: &str, what: Vector, out: &mut [f64]) -> Status {
        let status = self.vector_call(function, allowed::GET_STATES, out.len(), what);
        if status >= Status::Error || out.is_empty() {
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
    pub fn set_continuous_states(&mut self, function: &str, x: &[f64]) -> Status {
        let status = self.vector_call(
            function,
            allowed::CONTINUOUS_TIME_MODE,
            x.len(),
            Vector::States,
        );
        if status >= Status::Error || x.is_empty() {
            return status;
        }
        match self.runtime.set_continuous_states(x) {
            Ok(()) => status,
            Err(why) => self.error(&format!("{function}: {why}")),
        }
    }
}

/// What an event iteration tells the importer (FMI 2.0's `fmi2EventInfo`, the outputs of FMI
/// 3.0's `fmi3UpdateDiscreteStates`); the nominals of the continuous states never change.
#[derive(Clone, Copy, Debug, Default)]
pub struct EventIteration {
    pub update: EventUpdate,
    pub next_event_time: Option<f64>,
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
