//! FMI 3.0 Co-Simulation with event mode (`eventModeUsed`, FMI 3.0 section 4.2.1 and 4.3): the
//! model's time events (the motor's schedule switches) are reported by `fmi3DoStep`, which ends
//! the step at the first of them when the importer allows early return, and the instance has an
//! Event Mode between `fmi3EnterEventMode` and `fmi3EnterStepMode`.
//!
//! Co-Simulation steps integrate through a time event on their own (the schedule is a function of
//! time), so event mode changes no state: `fmi3UpdateDiscreteStates` refreshes the outputs at the
//! event and gives the next event time. A model without time events never raises one.

use super::model_exchange::EventIteration;
use super::{allowed, Instance, MachineState};
use crate::export::Status;

/// How a Co-Simulation step ended (the outputs of `fmi3DoStep`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepEnd {
    /// A time event lies in the step, at `last_successful_time` when the step ended early,
    /// or before or at its end otherwise: the importer should enter Event Mode.
    pub event_handling_needed: bool,
    /// The step ended at an event before the communication point.
    pub early_return: bool,
    /// The time the instance reached (or kept, after a refused step).
    pub last_successful_time: f64,
}

impl Instance {
    /// Whether this is a Co-Simulation instance with event mode.
    pub(super) fn co_simulation_events(&self) -> bool {
        !self.model_exchange && self.event_mode_used
    }

    /// `fmi3DoStep`: a step of `step` from `time`, or with event mode and early return allowed,
    /// to the first time event inside it.
    pub fn do_step_with_events(
        &mut self,
        function: &str,
        time: f64,
        step: f64,
    ) -> (Status, StepEnd) {
        // Rounding of the clocks: an event this close to the step's end is at its end (it is
        // reported, and no sliver of a step follows it).
        let end = time + step;
        let rounding = 1e3 * f64::EPSILON * end.abs().max(step);
        // The next event after the importer's time, if within the step and the instance may step.
        let event = if self.co_simulation_events() && self.state == MachineState::StepComplete {
            self.runtime
                .next_time_event(time)
                .filter(|&t| end.is_finite() && t <= end + rounding)
        } else {
            None
        };
        let early = event.filter(|&t| self.early_return_allowed && end - t > rounding);
        let status = match early {
            Some(t) => self.do_step(function, time, t - time),
            None => self.do_step(function, time, step),
        };
        let stepped = matches!(status, Status::OK | Status::Warning);
        if stepped {
            if let Some(t) = early {
                // The step ends on the event exactly: `time + (t - time)` may round away from it.
                self.time = t;
            }
        }
        let end = StepEnd {
            event_handling_needed: stepped && event.is_some(),
            early_return: stepped && early.is_some(),
            last_successful_time: self.time,
        };
        (status, end)
    }

    /// `fmi3EnterEventMode` in Co-Simulation: from Step Mode.
    pub(super) fn co_simulation_enter_event_mode(&mut self, function: &str) -> Status {
        if !self.allowed(function, allowed::DO_STEP) {
            return Status::Error;
        }
        self.set_state(MachineState::EventMode);
        Status::OK
    }

    /// `fmi3UpdateDiscreteStates` in Co-Simulation: nothing jumps (the step integrated through
    /// the event); the outputs at the event and the next event time.
    pub(super) fn co_simulation_update_discrete_states(
        &mut self,
        function: &str,
    ) -> (Status, EventIteration) {
        if !self.allowed(function, allowed::EVENT_MODE) {
            return (Status::Error, EventIteration::default());
        }
        let status = self.refresh_outputs(function);
        let next_event_time = self.runtime.next_time_event(self.time);
        (
            status,
            EventIteration {
                next_event_time,
                ..EventIteration::default()
            },
        )
    }

    /// `fmi3EnterStepMode`: from Event Mode back to Step Mode, in Co-Simulation with event mode.
    pub fn enter_step_mode(&mut self, function: &str) -> Status {
        if !self.co_simulation_events() {
            return self.unsupported(
                function,
                "the instance has no event mode: it was instantiated for Model Exchange, or \
                 for Co-Simulation with eventModeUsed = false (it is in Step Mode after \
                 initialization)",
            );
        }
        if !self.allowed(function, allowed::EVENT_MODE) {
            return Status::Error;
        }
        self.set_state(MachineState::StepComplete);
        Status::OK
    }
}
