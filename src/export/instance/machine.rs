//! The call-sequence state machine of FMI 2.0.4 section 4.2.4 (FMI 3.0 section 4.2.1 has the same
//! states for these FMUs): which function may be called in
//! which state, and the functions that move between states (initialization, stepping, reset).

use super::Instance;
use crate::export::Status;
use crate::models::Report;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum MachineState {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
    Fatal,
    /// Model Exchange (`model_exchange.rs`); after the others so that saved states keep
    /// their encoding.
    EventMode,
    ContinuousTimeMode,
}

impl MachineState {
    /// The state's name in messages (as FMI 2.0 names it; see [`Instance::state_name`]).
    pub const fn name(self) -> &'static str {
        match self {
            MachineState::Instantiated => "Instantiated",
            MachineState::InitializationMode => "InitializationMode",
            MachineState::StepComplete => "StepComplete",
            MachineState::StepFailed => "StepFailed",
            MachineState::Terminated => "Terminated",
            MachineState::Error => "Error",
            MachineState::Fatal => "Fatal",
            MachineState::EventMode => "EventMode",
            MachineState::ContinuousTimeMode => "ContinuousTimeMode",
        }
    }

    pub(super) const fn bit(self) -> u32 {
        1 << self as u32
    }

    /// Every state, for tables indexed by state.
    pub(super) const ALL: [MachineState; 9] = [
        MachineState::Instantiated,
        MachineState::InitializationMode,
        MachineState::StepComplete,
        MachineState::StepFailed,
        MachineState::Terminated,
        MachineState::Error,
        MachineState::Fatal,
        MachineState::EventMode,
        MachineState::ContinuousTimeMode,
    ];
}

/// Which states each function may be called in (FMI 2.0.4 section 4.2.4; asynchronous states
/// never occur because `canRunAsynchronuously` is false).
pub mod allowed {
    use super::MachineState::*;
    const fn mask(states: &[super::MachineState]) -> u32 {
        let mut m = 0;
        let mut i = 0;
        while i < states.len() {
            m |= states[i].bit();
            i += 1;
        }
        m
    }
    pub const ALL_BUT_FATAL: u32 = mask(&[
        Instantiated,
        InitializationMode,
        StepComplete,
        StepFailed,
        Terminated,
        Error,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const SETUP_EXPERIMENT: u32 = mask(&[Instantiated]);
    pub const ENTER_INITIALIZATION: u32 = mask(&[Instantiated]);
    pub const EXIT_INITIALIZATION: u32 = mask(&[InitializationMode]);
    pub const TERMINATE: u32 = mask(&[StepComplete, StepFailed, EventMode, ContinuousTimeMode]);
    pub const GET: u32 = mask(&[
        InitializationMode,
        StepComplete,
        StepFailed,
        Terminated,
        Error,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const SET: u32 = mask(&[
        Instantiated,
        InitializationMode,
        StepComplete,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const EVENT_MODE: u32 = mask(&[EventMode]);
    pub const CONTINUOUS_TIME_MODE: u32 = mask(&[ContinuousTimeMode]);
    pub const EVENT_OR_CONTINUOUS_TIME_MODE: u32 = mask(&[EventMode, ContinuousTimeMode]);
    /// The continuous-state getters (FMI 2.0.4 section 3.2.3).
    pub const GET_STATES: u32 = mask(&[
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        Terminated,
        Error,
    ]);
    pub const DO_STEP: u32 = mask(&[StepComplete]);
    pub const STATUS: u32 = mask(&[StepComplete, StepFailed, Terminated]);
}

impl Instance {
    pub fn set_debug_logging(&mut self, function: &str, on: bool, categories: &[&str]) -> Status {
        if !self.allowed(function, allowed::ALL_BUT_FATAL) {
            return Status::Error;
        }
        if let Some(unknown) = categories
            .iter()
            .find(|c| !self.info.log_categories.contains(c))
        {
            return self.error(&format!(
                "{function}: unknown log category '{unknown}' (known: {})",
                self.info.log_categories.join(", ")
            ));
        }
        // Warnings and errors are always logged; the switch is about call tracing.
        let calls = on && (categories.is_empty() || categories.contains(&"logCalls"));
        self.logger.debug = calls;
        Status::OK
    }

    pub fn setup_experiment(
        &mut self,
        function: &str,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> Status {
        if !self.allowed(function, allowed::SETUP_EXPERIMENT) {
            return Status::Error;
        }
        if !start.is_finite()
            || stop.is_some_and(|s| !s.is_finite())
            || tolerance.is_some_and(|t| !(t.is_finite() && t > 0.0))
        {
            return self.error(&format!(
                "{function}: startTime {start}, stopTime {stop:?} and tolerance {tolerance:?} must be finite (tolerance positive)"
            ));
        }
        if let Some(stop) = stop.filter(|&s| s < start) {
            return self.error(&format!(
                "{function}: stopTime {stop} is before startTime {start}"
            ));
        }
        self.start_time = start;
        self.time = start;
        self.set_stop_time(stop);
        Status::OK
    }

    pub fn enter_initialization_mode(&mut self, function: &str) -> Status {
        if !self.allowed(function, allowed::ENTER_INITIALIZATION) {
            return Status::Error;
        }
        self.set_state(MachineState::InitializationMode);
        Status::OK
    }

    pub fn exit_initialization_mode(&mut self, function: &str) -> Status {
        if !self.allowed(function, allowed::EXIT_INITIALIZATION) {
            return Status::Error;
        }
        let status = self.refresh_outputs(function);
        if status >= Status::Discard {
            // Bad parameters, or start values the model cannot evaluate (a Discard, which has no
            // smaller step to retry here): the instance can be reset (or freed).
            self.set_state(MachineState::Error);
            return status.max(Status::Error);
        }
        // FMI 3.0 section 4.2.1: Co-Simulation with eventModeUsed starts in Event Mode too.
        self.set_state(if self.model_exchange || self.event_mode_used {
            MachineState::EventMode
        } else {
            MachineState::StepComplete
        });
        status
    }

    pub fn terminate(&mut self, function: &str) -> Status {
        if !self.allowed(function, allowed::TERMINATE) {
            return Status::Error;
        }
        self.set_state(MachineState::Terminated);
        Status::OK
    }

    /// Back to the state after instantiation: start values, no model, time zero.
    pub fn reset(&mut self, function: &str) -> Status {
        if !self.allowed(function, allowed::ALL_BUT_FATAL) {
            return Status::Error;
        }
        self.runtime.reset();
        self.set_state(MachineState::Instantiated);
        self.time = 0.0;
        self.start_time = 0.0;
        self.set_stop_time(None);
        Status::OK
    }

    /// `fmi2DoStep`, `fmi3DoStep`: checks the state and the step, steps the model and forwards
    /// its report.
    #[inline(always)]
    pub fn do_step(&mut self, function: &str, time: f64, step: f64) -> Status {
        if !self.allowed(function, allowed::DO_STEP) {
            return Status::Error;
        }
        if let Some(refused) = self.step_refused(function, time, step) {
            return refused;
        }
        let mut report = Report::default();
        // The runtime writes the `input_clamped` output itself: a quiet report needs nothing more.
        self.runtime.step(time, step, &mut report);
        let status = if report.is_quiet() {
            Status::OK
        } else {
            self.forward_messages(function, report, true)
        };
        match status {
            Status::OK | Status::Warning => self.time = time + step,
            Status::Discard => self.set_state(MachineState::StepFailed),
            _ => self.set_state(MachineState::Error),
        }
        status
    }

    pub(super) fn set_stop_time(&mut self, stop: Option<f64>) {
        self.stop_time = stop;
    }

    /// The refusal of a step of `step` from `time`, if any (the caller checked the state).
    #[inline(always)]
    fn step_refused(&self, function: &str, time: f64, step: f64) -> Option<Status> {
        // Positive and finite (NaN fails both comparisons).
        if !(0.0 < step && step <= f64::MAX) {
            return Some(self.refuse_step(function, step));
        }
        // The importer's clock and ours may differ by rounding only; adopt the importer's. The
        // allowance scales with the clocks, not the step: a long step must not excuse a wrong
        // communication point. Most masters pass our own time back: then no allowance is needed.
        // Our time is finite: equal to it, `time` is too.
        if !(time == self.time || (time.is_finite() && self.within_rounding(time))) {
            return Some(self.refuse_communication_point(function, time));
        }
        // Both finite, their sum may not be: the clock would become +inf.
        if !(time + step).is_finite() {
            return Some(self.refuse_step_end(function, time, step));
        }
        if let Some(stop) = self.stop_time.filter(|&stop| time + step > stop) {
            // A step computed as stop - time may overshoot by rounding of either.
            let tolerance = 1e3 * f64::EPSILON * time.abs().max(stop.abs()).max(step);
            if time + step > stop + tolerance {
                return Some(self.refuse_past_stop(function, time + step, stop));
            }
        }
        None
    }

    /// Whether `time` differs from the instance's time by rounding only.
    fn within_rounding(&self, time: f64) -> bool {
        let tolerance = 1e3 * f64::EPSILON * time.abs().max(self.time.abs());
        (time - self.time).abs() <= tolerance
    }

    #[cold]
    #[inline(never)]
    fn refuse_step(&self, function: &str, step: f64) -> Status {
        self.error(&format!(
            "{function}: communicationStepSize = {step} must be positive and finite"
        ))
    }

    #[cold]
    #[inline(never)]
    fn refuse_step_end(&self, function: &str, time: f64, step: f64) -> Status {
        self.error(&format!(
            "{function}: the step's end currentCommunicationPoint + communicationStepSize = \
             {time:e} + {step:e} overflows to {}: it must be finite",
            time + step
        ))
    }

    #[cold]
    #[inline(never)]
    fn refuse_communication_point(&self, function: &str, time: f64) -> Status {
        self.error(&format!(
            "{function}: expected currentCommunicationPoint = {:.16e} but was {time:.16e}",
            self.time
        ))
    }

    #[cold]
    #[inline(never)]
    fn refuse_past_stop(&self, function: &str, end: f64, stop: f64) -> Status {
        self.error(&format!(
            "{function}: a step to {end:.16e} would pass the stop time {stop:.16e}"
        ))
    }

    pub fn last_successful_time(&self, function: &str) -> Result<f64, Status> {
        if !self.allowed(function, allowed::STATUS) {
            return Err(Status::Error);
        }
        Ok(self.time)
    }

    pub fn status_check(&self, function: &str) -> bool {
        self.allowed(function, allowed::STATUS)
    }

    pub fn unsupported(&self, function: &str, why: &str) -> Status {
        self.error(&format!("{function}: not supported: {why}"))
    }
}
