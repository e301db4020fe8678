//! One FMU instance: the FMI 2.0.4 Co-Simulation call-sequence state machine (section 4.2.4), the
//! rules for which variables may be set when (section 2.2.7), stepping, and FMU states. Safe code
//! over slices; `exports.rs` turns C pointers into those slices.

use super::logger::{c_string, Logger};
use super::runtime::{Factory, Runtime};
use super::types::fmi2Status;
use crate::models::{Report, Status};
use crate::variables::{Causality, Initial, ModelInfo, VarType, Variability, Variable};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::ffi::CString;

/// Marks a live instance, so that a stale or foreign pointer is refused rather than used.
pub const MAGIC: u64 = 0x6163_7475_6174_6f72;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum MachineState {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
    Fatal,
}

impl MachineState {
    const fn bit(self) -> u32 {
        1 << self as u32
    }
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
    ]);
    pub const SETUP_EXPERIMENT: u32 = mask(&[Instantiated]);
    pub const ENTER_INITIALIZATION: u32 = mask(&[Instantiated]);
    pub const EXIT_INITIALIZATION: u32 = mask(&[InitializationMode]);
    pub const TERMINATE: u32 = mask(&[StepComplete, StepFailed]);
    pub const GET: u32 = mask(&[
        InitializationMode,
        StepComplete,
        StepFailed,
        Terminated,
        Error,
    ]);
    pub const SET: u32 = mask(&[Instantiated, InitializationMode, StepComplete]);
    pub const DO_STEP: u32 = mask(&[StepComplete]);
    pub const STATUS: u32 = mask(&[StepComplete, StepFailed, Terminated]);
}

/// A saved FMU state (`fmi2GetFMUstate`): everything needed to continue from it.
pub struct FmuState {
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    machine: MachineState,
    runtime: Box<dyn Runtime>,
}

/// Versioned byte format of a serialized FMU state: magic, format version, postcard, then a
/// 64-bit FNV-1a checksum of everything before it (format 3: the models hold their typed ranges
/// and, for PulleyJoint, its time; format 2 had the same envelope; format 1 had no checksum).
const STATE_MAGIC: &[u8; 8] = b"AFMUSTAT";
const STATE_FORMAT: u16 = 3;

/// FNV-1a, 64 bit: catches accidental corruption of a stored state (a flipped byte in the model's
/// history would otherwise reach the physics as garbage), not tampering.
fn checksum(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

#[derive(Serialize, Deserialize)]
struct SerializedState {
    guid: String,
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    machine: MachineState,
    runtime: Vec<u8>,
}

pub struct Instance {
    pub magic: u64,
    pub logger: Logger,
    info: &'static ModelInfo,
    /// Variables by type and value reference (value references are dense per type).
    by_type: [Vec<&'static Variable>; 4],
    pub state: MachineState,
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    runtime: Box<dyn Runtime>,
    /// Keeps the strings handed out by `fmi2GetString` alive until the next call.
    string_values: Vec<CString>,
    /// The FMU states this instance handed out and has not freed; others are refused.
    fmu_states: HashSet<usize>,
}

fn type_index(kind: VarType) -> usize {
    match kind {
        VarType::Real => 0,
        VarType::Integer => 1,
        VarType::Boolean => 2,
        VarType::String => 3,
    }
}

/// A value that fmi2SetXXX can write into [`super::runtime::Vars`].
pub trait Value {
    const KIND: VarType;
    /// A reason to refuse the value for this variable, if any.
    fn invalid_for(&self, var: &Variable) -> Option<String>;
    fn store(&self, vars: &mut super::runtime::Vars, index: usize);
}

impl Value for f64 {
    const KIND: VarType = VarType::Real;
    fn invalid_for(&self, var: &Variable) -> Option<String> {
        if !self.is_finite() {
            return Some(format!("{} = {self} is not finite", var.name));
        }
        range_check(*self, var)
    }
    fn store(&self, vars: &mut super::runtime::Vars, index: usize) {
        vars.real[index] = *self;
    }
}

impl Value for i32 {
    const KIND: VarType = VarType::Integer;
    fn invalid_for(&self, var: &Variable) -> Option<String> {
        range_check(*self as f64, var)
    }
    fn store(&self, vars: &mut super::runtime::Vars, index: usize) {
        vars.integer[index] = *self;
    }
}

/// An `fmi2Boolean` as the importer passed it: any non-zero int is true.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub struct CBoolean(pub std::ffi::c_int);

impl Value for CBoolean {
    const KIND: VarType = VarType::Boolean;
    fn invalid_for(&self, _: &Variable) -> Option<String> {
        None
    }
    fn store(&self, vars: &mut super::runtime::Vars, index: usize) {
        vars.boolean[index] = self.0 != 0;
    }
}

impl Value for String {
    const KIND: VarType = VarType::String;
    fn invalid_for(&self, _: &Variable) -> Option<String> {
        None
    }
    fn store(&self, vars: &mut super::runtime::Vars, index: usize) {
        vars.string[index].clone_from(self);
    }
}

fn range_check(x: f64, var: &Variable) -> Option<String> {
    let below = var
        .min
        .filter(|&min| x < min)
        .map(|min| ("below its minimum", min));
    let (what, bound) = below.or_else(|| {
        var.max
            .filter(|&max| x > max)
            .map(|max| ("above its maximum", max))
    })?;
    // Formatting only on refusal: this runs for every value an importer sets.
    let unit = if var.unit.is_empty() || var.unit == "1" {
        String::new()
    } else {
        format!(" {}", var.unit)
    };
    Some(format!("{} = {x}{unit} is {what} {bound}{unit}", var.name))
}

fn to_fmi(status: Status) -> fmi2Status {
    match status {
        Status::Ok => fmi2Status::OK,
        Status::Warning => fmi2Status::Warning,
        Status::Discard => fmi2Status::Discard,
        Status::Error => fmi2Status::Error,
    }
}

impl Instance {
    pub fn new(factory: &'static dyn Factory, logger: Logger) -> Self {
        let info = factory.info();
        let by_type = std::array::from_fn(|t| {
            (0..info.counts[t])
                .filter_map(|vr| {
                    info.variables
                        .iter()
                        .find(|v| type_index(v.kind) == t && v.vr as usize == vr)
                })
                .collect()
        });
        Self {
            magic: MAGIC,
            logger,
            info,
            by_type,
            state: MachineState::Instantiated,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            runtime: factory.create(),
            string_values: Vec::new(),
            fmu_states: HashSet::new(),
        }
    }

    pub fn error(&self, message: &str) -> fmi2Status {
        self.logger.log(fmi2Status::Error, message);
        fmi2Status::Error
    }

    /// Logs and refuses a call that the current state does not allow.
    pub fn allowed(&self, function: &str, mask: u32) -> bool {
        if mask & self.state.bit() == 0 {
            self.error(&format!(
                "{function}: illegal call in state {:?}",
                self.state
            ));
            return false;
        }
        if self.logger.debug {
            self.logger.log(
                fmi2Status::OK,
                &format!("{function} in state {:?}", self.state),
            );
        }
        true
    }

    /// Passes a model's messages to the logger and turns its status into an FMI status.
    fn forward(&self, function: &str, report: Report) -> fmi2Status {
        for (status, message) in &report.messages {
            self.logger
                .log(to_fmi(*status), &format!("{function}: {message}"));
        }
        to_fmi(report.status)
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> fmi2Status {
        if !self.allowed("fmi2SetDebugLogging", allowed::ALL_BUT_FATAL) {
            return fmi2Status::Error;
        }
        if let Some(unknown) = categories
            .iter()
            .find(|c| !self.info.log_categories.contains(c))
        {
            return self.error(&format!(
                "fmi2SetDebugLogging: unknown log category '{unknown}' (known: {})",
                self.info.log_categories.join(", ")
            ));
        }
        // Warnings and errors are always logged; the switch is about call tracing.
        self.logger.debug = on && (categories.is_empty() || categories.contains(&"logCalls"));
        fmi2Status::OK
    }

    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> fmi2Status {
        if !self.allowed("fmi2SetupExperiment", allowed::SETUP_EXPERIMENT) {
            return fmi2Status::Error;
        }
        if !start.is_finite()
            || stop.is_some_and(|s| !s.is_finite())
            || tolerance.is_some_and(|t| t.is_nan() || t <= 0.0)
        {
            return self.error(&format!(
                "fmi2SetupExperiment: startTime {start}, stopTime {stop:?} and tolerance {tolerance:?} must be finite (tolerance positive)"
            ));
        }
        if let Some(stop) = stop.filter(|&s| s < start) {
            return self.error(&format!(
                "fmi2SetupExperiment: stopTime {stop} is before startTime {start}"
            ));
        }
        self.start_time = start;
        self.time = start;
        self.stop_time = stop;
        fmi2Status::OK
    }

    pub fn enter_initialization_mode(&mut self) -> fmi2Status {
        if !self.allowed("fmi2EnterInitializationMode", allowed::ENTER_INITIALIZATION) {
            return fmi2Status::Error;
        }
        self.state = MachineState::InitializationMode;
        fmi2Status::OK
    }

    pub fn exit_initialization_mode(&mut self) -> fmi2Status {
        if !self.allowed("fmi2ExitInitializationMode", allowed::EXIT_INITIALIZATION) {
            return fmi2Status::Error;
        }
        let status = self.refresh_outputs("fmi2ExitInitializationMode");
        if status >= fmi2Status::Error {
            // Bad parameters: the instance can be reset (or freed).
            self.state = MachineState::Error;
            return status;
        }
        self.state = MachineState::StepComplete;
        status
    }

    pub fn terminate(&mut self) -> fmi2Status {
        if !self.allowed("fmi2Terminate", allowed::TERMINATE) {
            return fmi2Status::Error;
        }
        self.state = MachineState::Terminated;
        fmi2Status::OK
    }

    /// Back to the state after instantiation: start values, no model, time zero.
    pub fn reset(&mut self) -> fmi2Status {
        if !self.allowed("fmi2Reset", allowed::ALL_BUT_FATAL) {
            return fmi2Status::Error;
        }
        self.runtime.reset();
        self.state = MachineState::Instantiated;
        self.time = 0.0;
        self.start_time = 0.0;
        self.stop_time = None;
        fmi2Status::OK
    }

    /// Builds the model if initialization needs it and recomputes outputs that inputs made stale.
    fn refresh_outputs(&mut self, function: &str) -> fmi2Status {
        if !self.runtime.is_built() {
            if self.state != MachineState::InitializationMode {
                return fmi2Status::OK;
            }
            if let Err(reason) = self.runtime.build() {
                return self.error(&format!("{function}: parameters rejected: {reason}"));
            }
        }
        let mut report = Report::default();
        self.runtime.refresh_outputs(&mut report);
        self.forward(function, report)
    }

    fn lookup(
        &self,
        function: &str,
        kind: VarType,
        vr: u32,
    ) -> Result<&'static Variable, fmi2Status> {
        self.by_type[type_index(kind)]
            .get(vr as usize)
            .copied()
            .ok_or_else(|| {
                self.error(&format!(
                    "{function}: {vr} is not the value reference of a {kind:?} variable of {}",
                    self.info.name
                ))
            })
    }

    /// FMI 2.0.4 section 2.2.7: what may be set in which state.
    fn settable(&self, var: &Variable) -> bool {
        if var.variability == Variability::Constant {
            return false;
        }
        let input = var.causality == Causality::Input;
        match self.state {
            MachineState::Instantiated => {
                input || matches!(var.initial, Initial::Exact | Initial::Approx)
            }
            MachineState::InitializationMode => input || var.initial == Initial::Exact,
            MachineState::StepComplete => {
                input
                    || (var.causality == Causality::Parameter
                        && var.variability == Variability::Tunable)
            }
            _ => false,
        }
    }

    /// Sets all values or, if any is refused, none (the old values are kept).
    pub fn set<T: Value>(&mut self, function: &str, vrs: &[u32], values: &[T]) -> fmi2Status {
        if !self.allowed(function, allowed::SET) {
            return fmi2Status::Error;
        }
        let mut parameters_changed = false;
        for (&vr, value) in vrs.iter().zip(values) {
            let var = match self.lookup(function, T::KIND, vr) {
                Ok(v) => v,
                Err(status) => return status,
            };
            if !self.settable(var) {
                return self.error(&format!(
                    "{function}: {} ({:?}, {:?}) cannot be set in state {:?}",
                    var.name, var.causality, var.variability, self.state
                ));
            }
            if let Some(reason) = value.invalid_for(var) {
                return self.error(&format!("{function}: {reason}; the value is kept"));
            }
            parameters_changed |= var.causality == Causality::Parameter;
        }
        let before = self.before_retune(parameters_changed);
        let vars = self.runtime.vars_mut();
        for (&vr, value) in vrs.iter().zip(values) {
            value.store(vars, vr as usize);
        }
        self.runtime.changed(parameters_changed);
        self.rebuild_or_undo(function, before)
    }

    /// A snapshot to undo a tunable parameter change with, if this set changes one between steps.
    fn before_retune(&self, parameters_changed: bool) -> Option<Box<dyn Runtime>> {
        (parameters_changed && self.state == MachineState::StepComplete)
            .then(|| self.runtime.snapshot())
    }

    /// After a tunable parameter changed between steps: [`Model`](crate::models::Model) has no
    /// update hook, so the model is rebuilt from its parameters at once (its history restarts).
    /// Parameters it cannot be built from are refused and every value set by the call is undone.
    fn rebuild_or_undo(&mut self, function: &str, before: Option<Box<dyn Runtime>>) -> fmi2Status {
        let Some(before) = before else {
            return fmi2Status::OK;
        };
        match self.runtime.build() {
            Ok(()) => fmi2Status::OK,
            Err(reason) => {
                let undone = self.runtime.restore(before.as_ref());
                self.error(&format!(
                    "{function}: parameters rejected: {reason}; {}",
                    match undone {
                        Ok(()) => "the old values are kept".to_string(),
                        Err(e) => format!("the old values could not be restored: {e}"),
                    }
                ))
            }
        }
    }

    /// Refreshes stale outputs, then copies `pick(vars, vr)` for each value reference.
    pub fn get<T: Copy>(
        &mut self,
        function: &str,
        kind: VarType,
        vrs: &[u32],
        out: &mut [T],
        pick: impl Fn(&super::runtime::Vars, usize) -> T,
    ) -> fmi2Status {
        if !self.allowed(function, allowed::GET) {
            return fmi2Status::Error;
        }
        let mut status = fmi2Status::OK;
        if matches!(
            self.state,
            MachineState::InitializationMode | MachineState::StepComplete
        ) {
            status = self.refresh_outputs(function);
            if status >= fmi2Status::Error {
                return status;
            }
        }
        for (&vr, slot) in vrs.iter().zip(out.iter_mut()) {
            if let Err(s) = self.lookup(function, kind, vr) {
                return s;
            }
            *slot = pick(self.runtime.vars(), vr as usize);
        }
        status
    }

    /// `fmi2GetString`: the returned strings live until the next call on this instance.
    pub fn get_strings(&mut self, vrs: &[u32]) -> Result<Vec<*const std::ffi::c_char>, fmi2Status> {
        let mut refs = vec![0u32; vrs.len()];
        let status = self.get("fmi2GetString", VarType::String, vrs, &mut refs, |_, vr| {
            vr as u32
        });
        if status >= fmi2Status::Error {
            return Err(status);
        }
        let vars = self.runtime.vars();
        self.string_values = refs
            .iter()
            .map(|&vr| c_string(&vars.string[vr as usize]))
            .collect();
        Ok(self.string_values.iter().map(|s| s.as_ptr()).collect())
    }

    pub fn do_step(&mut self, time: f64, step: f64) -> fmi2Status {
        const F: &str = "fmi2DoStep";
        if !self.allowed(F, allowed::DO_STEP) {
            return fmi2Status::Error;
        }
        if !(step > 0.0 && step.is_finite()) {
            return self.error(&format!(
                "{F}: communicationStepSize = {step} must be positive and finite"
            ));
        }
        // The importer's clock and ours may differ by rounding only; adopt the importer's. The
        // allowance scales with the clocks, not the step: a long step must not excuse a wrong
        // communication point.
        let tolerance = 1e3 * f64::EPSILON * time.abs().max(self.time.abs());
        if !time.is_finite() || (time - self.time).abs() > tolerance {
            return self.error(&format!(
                "{F}: expected currentCommunicationPoint = {:.16e} but was {time:.16e}",
                self.time
            ));
        }
        if let Some(stop) = self.stop_time {
            // A step computed as stop - time may overshoot by rounding of either.
            let tolerance = 1e3 * f64::EPSILON * time.abs().max(stop.abs()).max(step);
            if time + step > stop + tolerance {
                return self.error(&format!(
                    "{F}: a step to {:.16e} would pass the stop time {stop:.16e}",
                    time + step
                ));
            }
        }
        let mut report = Report::default();
        self.runtime.step(time, step, &mut report);
        let status = self.forward(F, report);
        match status {
            fmi2Status::OK | fmi2Status::Warning => self.time = time + step,
            fmi2Status::Discard => self.state = MachineState::StepFailed,
            _ => self.state = MachineState::Error,
        }
        status
    }

    pub fn last_successful_time(&self) -> Result<f64, fmi2Status> {
        if !self.allowed("fmi2GetRealStatus", allowed::STATUS) {
            return Err(fmi2Status::Error);
        }
        Ok(self.time)
    }

    pub fn status_check(&self, function: &str) -> bool {
        self.allowed(function, allowed::STATUS)
    }

    pub fn unsupported(&self, function: &str, why: &str) -> fmi2Status {
        self.error(&format!("{function}: not supported: {why}"))
    }

    // ---- FMU states ----

    fn capture(&self) -> FmuState {
        FmuState {
            time: self.time,
            start_time: self.start_time,
            stop_time: self.stop_time,
            machine: self.state,
            runtime: self.runtime.snapshot(),
        }
    }

    /// Whether `state` is one this instance handed out and has not freed.
    pub fn owns_state(&self, state: *mut FmuState) -> bool {
        self.fmu_states.contains(&(state as usize))
    }

    fn refuse_foreign(&self, function: &str, state: *mut FmuState) -> Option<fmi2Status> {
        (!self.owns_state(state))
            .then(|| self.error(&format!("{function}: unknown FMU state {state:p}")))
    }

    /// `fmi2GetFMUstate`: a new state, or `existing` overwritten.
    pub fn get_fmu_state(&mut self, existing: *mut FmuState) -> Result<*mut FmuState, fmi2Status> {
        const F: &str = "fmi2GetFMUstate";
        if !self.allowed(F, allowed::ALL_BUT_FATAL) {
            return Err(fmi2Status::Error);
        }
        if existing.is_null() {
            let ptr = Box::into_raw(Box::new(self.capture()));
            self.fmu_states.insert(ptr as usize);
            return Ok(ptr);
        }
        if let Some(s) = self.refuse_foreign(F, existing) {
            return Err(s);
        }
        // SAFETY: `existing` is in `fmu_states`, so it came from Box::into_raw and is not freed.
        unsafe { *existing = self.capture() };
        Ok(existing)
    }

    pub fn set_fmu_state(&mut self, state: *mut FmuState) -> fmi2Status {
        const F: &str = "fmi2SetFMUstate";
        if !self.allowed(F, allowed::ALL_BUT_FATAL) {
            return fmi2Status::Error;
        }
        if let Some(s) = self.refuse_foreign(F, state) {
            return s;
        }
        // SAFETY: owned, live (see get_fmu_state).
        let saved = unsafe { &*state };
        self.restore(F, saved)
    }

    fn restore(&mut self, function: &str, saved: &FmuState) -> fmi2Status {
        if let Err(reason) = self.runtime.restore(saved.runtime.as_ref()) {
            return self.error(&format!("{function}: {reason}"));
        }
        self.time = saved.time;
        self.start_time = saved.start_time;
        self.stop_time = saved.stop_time;
        self.state = saved.machine;
        fmi2Status::OK
    }

    pub fn free_fmu_state(&mut self, state: *mut FmuState) -> fmi2Status {
        const F: &str = "fmi2FreeFMUstate";
        if state.is_null() {
            return fmi2Status::OK;
        }
        if let Some(s) = self.refuse_foreign(F, state) {
            return s;
        }
        self.fmu_states.remove(&(state as usize));
        // SAFETY: owned and live until this line, removed from the set so never freed twice.
        drop(unsafe { Box::from_raw(state) });
        fmi2Status::OK
    }

    pub fn serialize_fmu_state(
        &self,
        function: &str,
        state: *mut FmuState,
    ) -> Result<Vec<u8>, fmi2Status> {
        if !self.allowed(function, allowed::ALL_BUT_FATAL) {
            return Err(fmi2Status::Error);
        }
        if let Some(s) = self.refuse_foreign(function, state) {
            return Err(s);
        }
        // SAFETY: owned, live.
        let saved = unsafe { &*state };
        let runtime = saved
            .runtime
            .to_bytes()
            .map_err(|e| self.error(&format!("{function}: {e}")))?;
        let body = SerializedState {
            guid: self.info.guid.to_string(),
            time: saved.time,
            start_time: saved.start_time,
            stop_time: saved.stop_time,
            machine: saved.machine,
            runtime,
        };
        let mut bytes = STATE_MAGIC.to_vec();
        bytes.extend_from_slice(&STATE_FORMAT.to_le_bytes());
        let payload =
            postcard::to_stdvec(&body).map_err(|e| self.error(&format!("{function}: {e}")))?;
        bytes.extend_from_slice(&payload);
        let sum = checksum(&bytes);
        bytes.extend_from_slice(&sum.to_le_bytes());
        Ok(bytes)
    }

    /// A value in `vars` that no legal call sequence produces: a non-finite Real (the FMU never
    /// accepts or outputs one), or an input or parameter outside its declared range.
    fn invalid_values(&self, vars: &super::runtime::Vars) -> Option<String> {
        self.info.variables.iter().find_map(|var| {
            let i = var.vr as usize;
            let x = match var.kind {
                VarType::Real => *vars.real.get(i)?,
                VarType::Integer => f64::from(*vars.integer.get(i)?),
                _ => return None,
            };
            if !x.is_finite() {
                return Some(format!("{} = {x}", var.name));
            }
            let settable = matches!(var.causality, Causality::Input | Causality::Parameter);
            settable.then(|| range_check(x, var)).flatten()
        })
    }

    pub fn deserialize_fmu_state(
        &mut self,
        bytes: &[u8],
        existing: *mut FmuState,
    ) -> Result<*mut FmuState, fmi2Status> {
        const F: &str = "fmi2DeSerializeFMUstate";
        if !self.allowed(F, allowed::ALL_BUT_FATAL) {
            return Err(fmi2Status::Error);
        }
        let refuse = |why: String| self.error(&format!("{F}: {why}"));
        if bytes.len() < 10 || &bytes[..8] != STATE_MAGIC {
            return Err(refuse("not a serialized FMU state of this FMU".into()));
        }
        let format = u16::from_le_bytes([bytes[8], bytes[9]]);
        if format != STATE_FORMAT {
            return Err(refuse(format!(
                "state format {format} is not supported (this binary reads {STATE_FORMAT})"
            )));
        }
        let Some((sealed, sum)) = bytes.split_last_chunk::<8>().filter(|(s, _)| s.len() >= 10)
        else {
            return Err(refuse("corrupt state: too short".into()));
        };
        if checksum(sealed) != u64::from_le_bytes(*sum) {
            return Err(refuse(
                "corrupt state: checksum mismatch (the bytes changed since fmi2SerializeFMUstate)"
                    .into(),
            ));
        }
        let body: SerializedState = postcard::from_bytes(&sealed[10..])
            .map_err(|e| refuse(format!("corrupt state: {e}")))?;
        if body.guid != self.info.guid {
            return Err(refuse(format!(
                "the state is of GUID {}, this instance is {}",
                body.guid, self.info.guid
            )));
        }
        // The clocks decide which steps are legal: non-finite ones would disable those checks.
        let stop_ok = body
            .stop_time
            .is_none_or(|stop| stop.is_finite() && stop >= body.start_time);
        if !body.time.is_finite() || !body.start_time.is_finite() || !stop_ok {
            return Err(refuse(format!(
                "corrupt state: time {}, startTime {} and stopTime {:?} must be finite, stopTime not before startTime",
                body.time, body.start_time, body.stop_time
            )));
        }
        let runtime = self
            .runtime
            .snapshot_from_bytes(&body.runtime)
            .map_err(&refuse)?;
        if let Some(why) = self.invalid_values(runtime.vars()) {
            return Err(refuse(format!("corrupt state: {why}")));
        }
        let state = FmuState {
            time: body.time,
            start_time: body.start_time,
            stop_time: body.stop_time,
            machine: body.machine,
            runtime,
        };
        if existing.is_null() {
            let ptr = Box::into_raw(Box::new(state));
            self.fmu_states.insert(ptr as usize);
            return Ok(ptr);
        }
        if let Some(s) = self.refuse_foreign(F, existing) {
            return Err(s);
        }
        // SAFETY: owned, live.
        unsafe { *existing = state };
        Ok(existing)
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

#[cfg(test)]
mod tests {
    //! The state machine with a minimal model that has what no shipped model has yet: a tunable
    //! parameter (FMI 2.0.4 section 2.2.7 lets it change between steps).
    use super::*;
    use crate::fmi2::registry::Bindings;
    use crate::fmi2::runtime::{ModelFactory, Vars};
    use crate::models::{Model, Refusal};
    use crate::variables::{Interface, Start};

    /// y = gain * u, with a tunable gain.
    #[derive(Clone, Serialize, Deserialize)]
    struct Gain {
        gain: f64,
    }

    const fn var(
        name: &'static str,
        vr: u32,
        causality: Causality,
        variability: Variability,
        initial: Initial,
        start: Start,
    ) -> Variable {
        Variable {
            name,
            kind: VarType::Real,
            vr,
            causality,
            variability,
            initial,
            start,
            min: None,
            max: None,
            unit: "",
            description: "",
        }
    }

    static VARIABLES: [Variable; 3] = [
        var(
            "gain",
            0,
            Causality::Parameter,
            Variability::Tunable,
            Initial::Exact,
            Start::Real(1.0),
        ),
        var(
            "u",
            1,
            Causality::Input,
            Variability::Continuous,
            Initial::None,
            Start::Real(0.0),
        ),
        var(
            "y",
            2,
            Causality::Output,
            Variability::Continuous,
            Initial::Calculated,
            Start::None,
        ),
    ];

    static INFO: ModelInfo = ModelInfo {
        name: "Gain",
        guid: "{gain}",
        description: "",
        model_description_xml: "",
        variables: &VARIABLES,
        counts: [3, 0, 0, 0],
        log_categories: &[],
    };

    /// What build.rs would generate for the three variables above.
    struct GainVariables;
    impl Interface for GainVariables {
        type Parameters = f64;
        type Inputs = f64;
        type Outputs = f64;
        type CalculatedParameters = ();
        const INFO: &'static ModelInfo = &INFO;
    }
    impl Bindings for GainVariables {
        fn parameters(vars: &Vars) -> f64 {
            vars.real[0]
        }
        fn write_parameters(values: &f64, vars: &mut Vars) {
            vars.real[0] = *values;
        }
        fn inputs(vars: &Vars) -> f64 {
            vars.real[1]
        }
        fn write_inputs(values: &f64, vars: &mut Vars) {
            vars.real[1] = *values;
        }
        fn outputs(vars: &Vars) -> f64 {
            vars.real[2]
        }
        fn write_outputs(values: &f64, vars: &mut Vars) {
            vars.real[2] = *values;
        }
        fn calculated_parameters(_: &Vars) {}
        fn write_calculated_parameters(_: &(), _: &mut Vars) {}
    }

    impl Model for Gain {
        type Variables = GainVariables;
        const DOCUMENTATION: &'static str = "";
        fn new(gain: &f64, _: &f64) -> Result<Self, Refusal> {
            match *gain {
                0.0 => Err("gain must not be zero".into()),
                gain => Ok(Self { gain }),
            }
        }
        fn evaluate(&mut self, u: &f64, y: &mut f64, _: &mut Report) {
            *y = self.gain * u;
        }
        fn step(&mut self, u: &f64, y: &mut f64, _: f64, _: f64, report: &mut Report) {
            self.evaluate(u, y, report);
        }
    }

    static FACTORY: ModelFactory<Gain> = ModelFactory::NEW;

    fn y(inst: &mut Instance) -> (fmi2Status, f64) {
        let mut out = [f64::NAN];
        let s = inst.get("fmi2GetReal", VarType::Real, &[2], &mut out, |v, i| {
            v.real[i]
        });
        (s, out[0])
    }

    #[test]
    fn a_tunable_parameter_set_between_steps_takes_effect() {
        let mut inst = Instance::new(&FACTORY, Logger::new(None, std::ptr::null_mut(), "t"));
        assert_eq!(inst.setup_experiment(None, 0.0, None), fmi2Status::OK);
        assert_eq!(inst.enter_initialization_mode(), fmi2Status::OK);
        assert_eq!(inst.exit_initialization_mode(), fmi2Status::OK);
        assert_eq!(inst.set("fmi2SetReal", &[1], &[2.0]), fmi2Status::OK);
        assert_eq!(y(&mut inst), (fmi2Status::OK, 2.0));
        assert_eq!(inst.set("fmi2SetReal", &[0], &[3.0]), fmi2Status::OK);
        assert_eq!(
            y(&mut inst),
            (fmi2Status::OK, 6.0),
            "outputs follow the new gain"
        );
        assert_eq!(inst.do_step(0.0, 0.1), fmi2Status::OK);
        assert_eq!(y(&mut inst), (fmi2Status::OK, 6.0), "and so does the step");
        assert_eq!(inst.set("fmi2SetReal", &[0], &[-1.0]), fmi2Status::OK);
        assert_eq!(inst.do_step(0.1, 0.1), fmi2Status::OK);
        assert_eq!(y(&mut inst), (fmi2Status::OK, -2.0));
        // A gain the model refuses: the whole call is undone, the model keeps running.
        assert_eq!(
            inst.set("fmi2SetReal", &[1, 0], &[5.0, 0.0]),
            fmi2Status::Error
        );
        assert_eq!(y(&mut inst), (fmi2Status::OK, -2.0));
        assert_eq!(inst.runtime.vars().real[..2], [-1.0, 2.0]);
        assert_eq!(inst.do_step(0.2, 0.1), fmi2Status::OK);
        assert_eq!(y(&mut inst), (fmi2Status::OK, -2.0));
    }
}
