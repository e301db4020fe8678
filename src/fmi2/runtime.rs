//! The bridge between the C ABI and any [`Model`]: one instance's variable values and model,
//! behind a trait object so that the exported functions are written once for every model.

use super::registry::Bindings;
use crate::models::{Model, Report};
use crate::variables::{Interface, ModelInfo, Start, VarType};
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::marker::PhantomData;

/// Current values of all variables, indexed by value reference within each type: what
/// `fmi2GetXXX`/`fmi2SetXXX` read and write. Models never see it; [`Bindings`] copy between it
/// and their typed groups.
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

/// Creates instances of one model; the generated `REGISTRY` holds one per model description.
pub trait Factory: Sync {
    fn info(&self) -> &'static ModelInfo;
    /// HTML fragment describing the model's equations.
    fn documentation(&self) -> &'static str;
    fn create(&self) -> Box<dyn Runtime>;
}

pub struct ModelFactory<M>(PhantomData<fn() -> M>);

impl<M> ModelFactory<M> {
    pub const NEW: Self = Self(PhantomData);
}

impl<M: Model> Factory for ModelFactory<M>
where
    M::Variables: Bindings,
{
    fn info(&self) -> &'static ModelInfo {
        M::Variables::INFO
    }
    fn documentation(&self) -> &'static str {
        M::DOCUMENTATION
    }
    fn create(&self) -> Box<dyn Runtime> {
        Box::new(RuntimeOf::<M> {
            vars: Vars::from_start(M::Variables::INFO),
            model: None,
            outputs_stale: true,
        })
    }
}

/// One instance's variables and model, independent of the model's type.
pub trait Runtime: Send {
    fn vars(&self) -> &Vars;
    /// Writes go through [`Runtime::changed`] so that outputs and the model follow them.
    fn vars_mut(&mut self) -> &mut Vars;
    /// Tells that inputs changed (outputs are stale) or that parameters did (the model is too).
    fn changed(&mut self, parameters: bool);
    fn is_built(&self) -> bool;
    /// Builds the model from the current parameters, with only the effects they switch on.
    fn build(&mut self) -> Result<(), String>;
    /// Recomputes the outputs if an input changed since they were last written.
    fn refresh_outputs(&mut self, report: &mut Report);
    fn step(&mut self, time: f64, step: f64, report: &mut Report);
    /// Start values, no model.
    fn reset(&mut self);
    fn snapshot(&self) -> Box<dyn Runtime>;
    /// Copies `other` (a snapshot of the same model) into `self`.
    fn restore(&mut self, other: &dyn Runtime) -> Result<(), String>;
    fn to_bytes(&self) -> Result<Vec<u8>, String>;
    fn snapshot_from_bytes(&self, bytes: &[u8]) -> Result<Box<dyn Runtime>, String>;
    fn as_any(&self) -> &dyn Any;
}

#[derive(Clone, Serialize, Deserialize)]
#[serde(bound = "M: Model")]
struct RuntimeOf<M: Model> {
    vars: Vars,
    model: Option<M>,
    outputs_stale: bool,
}

impl<M: Model> Runtime for RuntimeOf<M>
where
    M::Variables: Bindings,
{
    fn vars(&self) -> &Vars {
        &self.vars
    }
    fn vars_mut(&mut self) -> &mut Vars {
        &mut self.vars
    }
    fn changed(&mut self, parameters: bool) {
        self.outputs_stale = true;
        if parameters {
            self.model = None;
        }
    }
    fn is_built(&self) -> bool {
        self.model.is_some()
    }
    fn build(&mut self) -> Result<(), String> {
        let parameters = M::Variables::parameters(&self.vars);
        let start = M::Variables::inputs(&self.vars);
        let model = M::new(&parameters, &start).map_err(|r| r.0)?;
        M::Variables::write_calculated_parameters(&model.calculated_parameters(), &mut self.vars);
        self.model = Some(model);
        self.outputs_stale = true;
        Ok(())
    }
    fn refresh_outputs(&mut self, report: &mut Report) {
        if let (true, Some(model)) = (self.outputs_stale, self.model.as_mut()) {
            let inputs = M::Variables::inputs(&self.vars);
            let mut outputs = M::Variables::outputs(&self.vars);
            model.evaluate(&inputs, &mut outputs, report);
            M::Variables::write_outputs(&outputs, &mut self.vars);
            self.outputs_stale = false;
        }
    }
    fn step(&mut self, time: f64, step: f64, report: &mut Report) {
        if let Some(model) = self.model.as_mut() {
            let inputs = M::Variables::inputs(&self.vars);
            let mut outputs = M::Variables::outputs(&self.vars);
            model.step(&inputs, &mut outputs, time, step, report);
            M::Variables::write_outputs(&outputs, &mut self.vars);
            self.outputs_stale = false;
        }
    }
    fn reset(&mut self) {
        self.vars = Vars::from_start(M::Variables::INFO);
        self.model = None;
        self.outputs_stale = true;
    }
    fn snapshot(&self) -> Box<dyn Runtime> {
        Box::new(self.clone())
    }
    fn restore(&mut self, other: &dyn Runtime) -> Result<(), String> {
        let other = other
            .as_any()
            .downcast_ref::<Self>()
            .ok_or("the FMU state belongs to another model")?;
        self.clone_from(other);
        Ok(())
    }
    fn to_bytes(&self) -> Result<Vec<u8>, String> {
        postcard::to_stdvec(self).map_err(|e| e.to_string())
    }
    fn snapshot_from_bytes(&self, bytes: &[u8]) -> Result<Box<dyn Runtime>, String> {
        let r: Self =
            postcard::from_bytes(bytes).map_err(|e| format!("corrupt model state: {e}"))?;
        let [nr, ni, nb, ns] = M::Variables::INFO.counts;
        let v = &r.vars;
        if (
            v.real.len(),
            v.integer.len(),
            v.boolean.len(),
            v.string.len(),
        ) != (nr, ni, nb, ns)
        {
            return Err("the variable counts do not match this model".into());
        }
        Ok(Box::new(r))
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}
