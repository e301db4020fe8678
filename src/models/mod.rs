//! One file per FMU: maps the generated variables to physics and holds the effect switches.
//!
//! A model is built from its parameters when initialization ends (only the effects switched on),
//! then evaluated and stepped by the export layer through [`Model`]. Models know nothing of FMI
//! calls, states or pointers.

use crate::variables::{ModelInfo, Start, VarType};
use serde::{de::DeserializeOwned, Deserialize, Serialize};

pub mod knitted_muscle;
pub mod mckibben_joint;
pub mod mckibben_muscle;
pub mod multiferroic_motor;
pub mod pass_through;
pub mod pulley_joint;

/// Outcome of a model call, in FMI's order of severity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    #[default]
    Ok,
    /// The result is usable but something was clamped or approximated; said in the log.
    Warning,
    /// The step could not be completed; the importer may retry from an earlier state.
    Discard,
    Error,
}

/// What a model call has to say: the worst status and the messages that explain it.
#[derive(Debug, Default)]
pub struct Report {
    pub status: Status,
    pub messages: Vec<(Status, String)>,
}

impl Report {
    pub fn add(&mut self, status: Status, message: impl Into<String>) {
        self.status = self.status.max(status);
        self.messages.push((status, message.into()));
    }
    pub fn warn(&mut self, message: impl Into<String>) {
        self.add(Status::Warning, message)
    }
}

/// Current values of all variables, indexed by value reference within each type.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Vars {
    pub real: Vec<f64>,
    pub integer: Vec<i32>,
    pub boolean: Vec<bool>,
    pub string: Vec<String>,
}

impl Vars {
    /// Start values from the model description; variables without one start at zero.
    pub fn from_start(info: &ModelInfo) -> Self {
        let [nr, ni, nb, ns] = info.counts;
        let mut v = Vars {
            real: vec![0.0; nr],
            integer: vec![0; ni],
            boolean: vec![false; nb],
            string: vec![String::new(); ns],
        };
        for var in info.variables {
            let i = var.vr as usize;
            match (var.kind, var.start) {
                (VarType::Real, Start::Real(x)) => v.real[i] = x,
                (VarType::Integer, Start::Integer(x)) => v.integer[i] = x,
                (VarType::Boolean, Start::Boolean(x)) => v.boolean[i] = x,
                (VarType::String, Start::String(x)) => v.string[i] = x.to_string(),
                _ => {}
            }
        }
        v
    }
}

/// A co-simulation model. The export layer owns the [`Vars`]; the model owns its physics and its
/// history (friction state, onion state, rotor state), which is part of the FMU state.
pub trait Model: Clone + Send + Serialize + DeserializeOwned + 'static {
    /// The generated tables of this model's variables.
    const INFO: &'static ModelInfo;
    /// HTML fragment for the FMU's `documentation/index.html`: the equations it implements.
    const DOCUMENTATION: &'static str;

    /// Builds the model from its parameters, with only the effects they switch on, and writes the
    /// calculated parameters. An unusable parameter set is an `Err` that says which and why.
    fn new(vars: &mut Vars) -> Result<Self, String>;

    /// Writes the outputs for the current inputs and history, without advancing the history.
    fn evaluate(&mut self, vars: &mut Vars, report: &mut Report);

    /// Advances from `time` to `time + step` with the inputs held, commits the history and writes
    /// the outputs at the end of the step.
    fn step(&mut self, vars: &mut Vars, time: f64, step: f64, report: &mut Report);

    /// Takes over the history of `saved`, a model deserialized from an importer's bytes, after
    /// checking it against the model's invariants. `self` was rebuilt by [`Model::new`] from the
    /// parameters that came with `saved`, so nothing derived from parameters (limits, geometry,
    /// caches) is taken from the bytes. A history no legal call sequence produces is an `Err`
    /// saying which. The default, for models without history, takes nothing.
    fn adopt_history(&mut self, _saved: &Self) -> Result<(), String> {
        Ok(())
    }
}
