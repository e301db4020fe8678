//! FMU states (`fmi2GetFMUstate`, `fmi3GetFMUState` and friends) and their versioned,
//! checksummed serialization.

use super::{allowed, values::range_check, Instance, MachineState};
use crate::export::runtime::Runtime;
use crate::export::Status;
use crate::variables::{Causality, VarType};
use serde::{Deserialize, Serialize};

/// A saved FMU state (`fmi2GetFMUstate`): everything needed to continue from it.
pub struct FmuState {
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    machine: MachineState,
    runtime: Box<dyn Runtime>,
}

/// Versioned byte format of a serialized FMU state: magic, format version, postcard, then a
/// 64-bit FNV-1a checksum of everything before it (format 3: the variables are the models' typed
/// structs; format 2 held them as arrays by value reference; format 1 had no checksum).
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

/// Why the clocks of a state are not those a run produces, if they are not: all finite, and
/// startTime <= time <= stopTime (a step may end past the stop time by the rounding that
/// `fmi2DoStep` allows). The clocks decide which steps are legal.
fn clock_disorder(time: f64, start: f64, stop: Option<f64>) -> Option<String> {
    let finite = time.is_finite() && start.is_finite() && stop.is_none_or(f64::is_finite);
    let rounding = |t: f64| 1e3 * f64::EPSILON * t.abs().max(start.abs());
    let ordered =
        start <= time && stop.is_none_or(|stop| start <= stop && time <= stop + rounding(stop));
    (!(finite && ordered)).then(|| {
        format!(
            "its clocks must be finite with startTime <= time <= stopTime, but startTime = {start:e}, time = {time:e}, stopTime = {}",
            stop.map_or("undefined".into(), |s| format!("{s:e}"))
        )
    })
}

impl Instance {
    fn capture(&self) -> FmuState {
        FmuState {
            time: self.time,
            start_time: self.start_time,
            stop_time: self.stop_time,
            machine: self.state(),
            runtime: self.runtime.snapshot(),
        }
    }

    /// Whether `state` is one this instance handed out and has not freed.
    pub fn owns_state(&self, state: *mut FmuState) -> bool {
        self.fmu_states.contains(&(state as usize))
    }

    fn refuse_foreign(&self, function: &str, state: *mut FmuState) -> Option<Status> {
        (!self.owns_state(state))
            .then(|| self.error(&format!("{function}: unknown FMU state {state:p}")))
    }

    /// `fmi2GetFMUstate`: a new state, or `existing` overwritten.
    pub fn get_fmu_state(
        &mut self,
        function: &str,
        existing: *mut FmuState,
    ) -> Result<*mut FmuState, Status> {
        if !self.allowed(function, allowed::ALL_BUT_FATAL) {
            return Err(Status::Error);
        }
        if existing.is_null() {
            let ptr = Box::into_raw(Box::new(self.capture()));
            self.fmu_states.insert(ptr as usize);
            return Ok(ptr);
        }
        if let Some(s) = self.refuse_foreign(function, existing) {
            return Err(s);
        }
        // SAFETY: `existing` is in `fmu_states`, so it came from Box::into_raw and is not freed.
        unsafe { *existing = self.capture() };
        Ok(existing)
    }

    pub fn set_fmu_state(&mut self, function: &str, state: *mut FmuState) -> Status {
        if !self.allowed(function, allowed::ALL_BUT_FATAL) {
            return Status::Error;
        }
        if let Some(s) = self.refuse_foreign(function, state) {
            return s;
        }
        // SAFETY: owned, live (see get_fmu_state).
        let saved = unsafe { &*state };
        self.restore(function, saved)
    }

    fn restore(&mut self, function: &str, saved: &FmuState) -> Status {
        use MachineState::*;
        // A state saved mid-run by one interface cannot continue in the other's state machine.
        let interface_of = |m| match m {
            StepComplete | StepFailed => Some(false),
            EventMode | ContinuousTimeMode => Some(true),
            _ => None,
        };
        // FMI 3.0 Co-Simulation with event mode has an Event Mode too.
        let cs_event_mode = saved.machine == EventMode && self.co_simulation_events();
        if !cs_event_mode && interface_of(saved.machine).is_some_and(|me| me != self.model_exchange)
        {
            return self.error(&format!(
                "{function}: the FMU state was saved in state {}, which this {} instance has not",
                self.state_name(saved.machine),
                if self.model_exchange {
                    "Model Exchange"
                } else {
                    "Co-Simulation"
                }
            ));
        }
        if let Err(reason) = self.runtime.restore(saved.runtime.as_ref()) {
            return self.error(&format!("{function}: {reason}"));
        }
        self.time = saved.time;
        self.start_time = saved.start_time;
        self.set_stop_time(saved.stop_time);
        self.set_state(saved.machine);
        Status::OK
    }

    pub fn free_fmu_state(&mut self, function: &str, state: *mut FmuState) -> Status {
        if state.is_null() {
            return Status::OK;
        }
        if let Some(s) = self.refuse_foreign(function, state) {
            return s;
        }
        self.fmu_states.remove(&(state as usize));
        // SAFETY: owned and live until this line, removed from the set so never freed twice.
        drop(unsafe { Box::from_raw(state) });
        Status::OK
    }

    pub fn serialize_fmu_state(
        &self,
        function: &str,
        state: *mut FmuState,
    ) -> Result<Vec<u8>, Status> {
        if !self.allowed(function, allowed::ALL_BUT_FATAL) {
            return Err(Status::Error);
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

    /// A value in `runtime` that no legal call sequence produces: a non-finite Real (the FMU never
    /// accepts or outputs one), or an input or parameter outside its declared range.
    fn invalid_values(&self, runtime: &dyn Runtime) -> Option<String> {
        self.info.variables.iter().find_map(|var| {
            let i = var.vr as usize;
            let x = match var.kind {
                VarType::Real => runtime.real(i),
                VarType::Integer => f64::from(runtime.integer(i)),
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
        function: &str,
        bytes: &[u8],
        existing: *mut FmuState,
    ) -> Result<*mut FmuState, Status> {
        if !self.allowed(function, allowed::ALL_BUT_FATAL) {
            return Err(Status::Error);
        }
        let refuse = |why: String| self.error(&format!("{function}: {why}"));
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
            return Err(refuse(format!(
                "corrupt state: checksum mismatch (the bytes changed since {})",
                self.api.serialize_fmu_state
            )));
        }
        let body: SerializedState = postcard::from_bytes(&sealed[10..])
            .map_err(|e| refuse(format!("corrupt state: {e}")))?;
        if body.guid != self.info.guid {
            return Err(refuse(format!(
                "the state is of GUID {}, this instance is {}",
                body.guid, self.info.guid
            )));
        }
        // Saving captures every state but Fatal, which no restore may set: after it even a reset
        // is refused.
        if body.machine == MachineState::Fatal {
            return Err(refuse(format!(
                "corrupt state: machine state Fatal is not one {} saves",
                self.api.get_fmu_state
            )));
        }
        if let Some(why) = clock_disorder(body.time, body.start_time, body.stop_time) {
            return Err(refuse(format!("corrupt state: {why}")));
        }
        let mut runtime = self
            .runtime
            .snapshot_from_bytes(&body.runtime)
            .map_err(&refuse)?;
        if let Some(why) = self.invalid_values(runtime.as_ref()) {
            return Err(refuse(format!("corrupt state: {why}")));
        }
        // Derived data is rebuilt from the parameters, never trusted from the bytes.
        runtime.rebuild_model().map_err(&refuse)?;
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
        if let Some(s) = self.refuse_foreign(function, existing) {
            return Err(s);
        }
        // SAFETY: owned, live.
        unsafe { *existing = state };
        Ok(existing)
    }
}
