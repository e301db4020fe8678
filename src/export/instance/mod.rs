//! One FMU instance, whichever FMI version's API created it: its core (this file), the
//! call-sequence state machine (FMI 2.0.4 section 4.2.4, FMI 3.0 section 4.2.1; `machine`), the
//! rules for which variables may be set when (FMI 2.0.4 section 2.2.7, `values`), FMU states
//! (`fmu_state`), Model Exchange's modes (`model_exchange`), FMI 3.0 Co-Simulation's event mode
//! (`co_simulation_events`), the out-of-range policy
//! (`out_of_range`) and directional derivatives. The code here works on Rust slices and
//! references and is told the name of the function the importer called; the version layers
//! (`src/fmi2`, `src/fmi3`) turn the importer's C pointers into them. The only `unsafe` here is
//! in `fmu_state`, on the state pointers this instance handed out itself.
//!
//! The three calls of every communication step (`set`, `do_step`, `get_reals`) are
//! `#[inline(always)]`: each version's export runs its one path as one function, as if it had
//! been written there.

mod co_simulation_events;
mod directional_derivative;
mod fmu_state;
mod machine;
mod model_exchange;
mod out_of_range;
#[cfg(test)]
mod tests;
mod values;

pub use fmu_state::FmuState;
pub use machine::{allowed, MachineState};
pub use model_exchange::Vector;
pub use values::{CBoolean, Value};

use super::logger::Logger;
use super::runtime::{Factory, Runtime};
use crate::export::Status;
use crate::models::{Report, Status as ModelStatus};
use crate::variables::{ModelInfo, VarType, Variable};
use out_of_range::OutOfRange;
use std::collections::HashSet;
use std::ffi::CString;

/// Marks a live instance, so that a stale or foreign pointer is refused rather than used.
pub const MAGIC: u64 = 0x6163_7475_6174_6f72;

/// What an instance needs to know of the FMI version it was instantiated through: which calls are
/// its own, and the names its messages use. Each version layer defines one.
pub struct Api {
    /// "FMI 2.0" or "FMI 3.0", for messages. An instance answers only the calls of the `Api` it
    /// was instantiated through (each version layer has one, a static).
    pub version: &'static str,
    /// The name of [`MachineState::StepComplete`] (FMI 3.0 calls it Step Mode).
    pub step_state: &'static str,
    /// The function that saves an FMU state, named where a restored state is refused.
    pub get_fmu_state: &'static str,
    /// The function that serializes an FMU state, named where a corrupt one is refused.
    pub serialize_fmu_state: &'static str,
}

pub struct Instance {
    pub magic: u64,
    pub logger: Logger,
    /// The FMI version the instance was instantiated through.
    pub api: &'static Api,
    info: &'static ModelInfo,
    /// Variables by type and value reference (value references are dense per type).
    by_type: [Vec<&'static Variable>; 4],
    /// What fmi2SetXXX checks, by type and value reference.
    set_rules: [Vec<values::SetRule>; 4],
    /// Where the instance is in FMI's call sequence.
    state: MachineState,
    /// Instantiated for Model Exchange (fmuType 0) rather than Co-Simulation.
    pub(crate) model_exchange: bool,
    /// FMI 3.0 Co-Simulation with event mode (`eventModeUsed`): `fmi3DoStep` reports the
    /// model's time events and the instance has an event mode (`co_simulation_events`).
    pub(crate) event_mode_used: bool,
    /// The importer accepts a step that ends early, at an event (`earlyReturnAllowed`).
    pub(crate) early_return_allowed: bool,
    pub(crate) time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    pub(crate) runtime: Box<dyn Runtime>,
    /// Keeps the strings handed out by `fmi2GetString` alive until the next call.
    string_values: Vec<CString>,
    /// The FMU states this instance handed out and has not freed; others are refused.
    fmu_states: HashSet<usize>,
    pub(super) out_of_range: OutOfRange,
}

fn type_index(kind: VarType) -> usize {
    match kind {
        VarType::Real => 0,
        VarType::Integer => 1,
        VarType::Boolean => 2,
        VarType::String => 3,
    }
}

/// A report with nothing to log and no clamp to apply the out-of-range policy to.
#[inline]
fn quiet(report: &Report) -> bool {
    !report.clamped() && report.messages().is_empty()
}

fn to_fmi(status: ModelStatus) -> Status {
    match status {
        ModelStatus::Ok => Status::OK,
        ModelStatus::Warning => Status::Warning,
        ModelStatus::Discard => Status::Discard,
        ModelStatus::Error => Status::Error,
    }
}

impl Instance {
    pub fn new(factory: &'static dyn Factory, api: &'static Api, logger: Logger) -> Self {
        let info = factory.info();
        let by_type: [Vec<&'static Variable>; 4] = std::array::from_fn(|t| {
            (0..info.counts[t])
                .filter_map(|vr| {
                    info.variables
                        .iter()
                        .find(|v| type_index(v.kind) == t && v.vr as usize == vr)
                })
                .collect()
        });
        let set_rules = std::array::from_fn(|t| {
            by_type[t]
                .iter()
                .map(|var: &&'static Variable| values::SetRule::new(var))
                .collect()
        });
        Self {
            magic: MAGIC,
            logger,
            api,
            info,
            by_type,
            set_rules,
            state: MachineState::Instantiated,
            model_exchange: false,
            event_mode_used: false,
            early_return_allowed: false,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            runtime: factory.create(),
            string_values: Vec::new(),
            fmu_states: HashSet::new(),
            out_of_range: OutOfRange::new(info),
        }
    }

    pub fn error(&self, message: &str) -> Status {
        self.logger.log(Status::Error, message);
        Status::Error
    }

    /// The model's variables.
    pub(crate) fn info(&self) -> &'static ModelInfo {
        self.info
    }

    /// The state of FMI's call sequence.
    pub fn state(&self) -> MachineState {
        self.state
    }

    pub fn set_state(&mut self, state: MachineState) {
        self.state = state;
    }

    /// The name of `state` in this instance's FMI version.
    pub fn state_name(&self, state: MachineState) -> &'static str {
        match state {
            MachineState::StepComplete => self.api.step_state,
            _ => state.name(),
        }
    }

    /// Logs and refuses a call that the current state does not allow.
    pub fn allowed(&self, function: &str, mask: u32) -> bool {
        if mask & self.state().bit() == 0 {
            self.illegal_call(function);
            return false;
        }
        if self.logger.debug {
            self.trace_call(function);
        }
        true
    }

    #[cold]
    #[inline(never)]
    fn illegal_call(&self, function: &str) {
        self.error(&format!(
            "{function}: illegal call in state {}",
            self.state_name(self.state())
        ));
    }

    #[cold]
    #[inline(never)]
    fn trace_call(&self, function: &str) {
        self.logger.log(
            Status::OK,
            &format!("{function} in state {}", self.state_name(self.state())),
        );
    }

    /// Applies the out-of-range policy, passes a model's messages to the logger and turns its
    /// status into an FMI status; `in_step` for fmi2DoStep.
    pub(super) fn forward(&mut self, function: &str, mut report: Report, in_step: bool) -> Status {
        self.settle(function, &mut report, in_step)
    }

    /// [`Instance::forward`] on a report in place. A report with nothing to log needs only the
    /// `input_clamped` flag cleared.
    pub(super) fn settle(&mut self, function: &str, report: &mut Report, in_step: bool) -> Status {
        if quiet(report) {
            if report.evaluated {
                self.out_of_range.clear_flag(self.runtime.as_mut());
            }
            return to_fmi(report.status());
        }
        self.forward_messages(function, std::mem::take(report), in_step)
    }

    #[cold]
    #[inline(never)]
    pub(super) fn forward_messages(
        &mut self,
        function: &str,
        mut report: Report,
        in_step: bool,
    ) -> Status {
        let notes = self
            .out_of_range
            .apply(self.runtime.as_mut(), &mut report, in_step);
        for note in notes {
            self.logger.notice(&format!("{function}: {note}"));
        }
        for (status, message) in report.messages() {
            let message = format!("{function}: {message}");
            match status {
                // A notice the user should read although nothing failed: always logged, at fmi2OK.
                ModelStatus::Ok => self.logger.notice(&message),
                _ => self.logger.log(to_fmi(*status), &message),
            }
        }
        to_fmi(report.status())
    }

    /// Builds the model if initialization needs it and recomputes outputs that inputs made stale.
    #[inline]
    pub(super) fn refresh_outputs(&mut self, function: &str) -> Status {
        // After a step, or a get with no set since: nothing to recompute, nothing to report.
        if self.runtime.outputs_current() {
            return Status::OK;
        }
        self.recompute_outputs(function)
    }

    #[inline(never)]
    pub(super) fn recompute_outputs(&mut self, function: &str) -> Status {
        if !self.runtime.is_built() {
            if self.state() != MachineState::InitializationMode {
                return Status::OK;
            }
            if let Err(reason) = self.runtime.build() {
                return self.error(&format!("{function}: parameters rejected: {reason}"));
            }
        }
        let mut report = Report::default();
        self.runtime.refresh_outputs(&mut report);
        self.forward(function, report, false)
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        self.magic = 0;
        for ptr in self.fmu_states.drain() {
            // SAFETY: every pointer in the set came from Box::into_raw and was not freed.
            drop(unsafe { Box::from_raw(ptr as *mut FmuState) });
        }
    }
}
