//! The bridge between the C ABI and any [`Model`]: one instance's variables and model, behind a
//! trait object so that the exported functions are written once for every model.

use crate::models::{Model, Report, Vars};
use crate::variables::{Causality, ModelInfo, VarType};
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::marker::PhantomData;

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

impl<M: Model> Factory for ModelFactory<M> {
    fn info(&self) -> &'static ModelInfo {
        M::INFO
    }
    fn documentation(&self) -> &'static str {
        M::DOCUMENTATION
    }
    fn create(&self) -> Box<dyn Runtime> {
        Box::new(RuntimeOf::<M> {
            vars: Vars::from_start(M::INFO),
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

impl<M: Model> Runtime for RuntimeOf<M> {
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
        self.model = Some(M::new(&mut self.vars)?);
        self.outputs_stale = true;
        Ok(())
    }
    fn refresh_outputs(&mut self, report: &mut Report) {
        if let (true, Some(model)) = (self.outputs_stale, self.model.as_mut()) {
            model.evaluate(&mut self.vars, report);
            self.outputs_stale = false;
        }
    }
    fn step(&mut self, time: f64, step: f64, report: &mut Report) {
        if let Some(model) = self.model.as_mut() {
            model.step(&mut self.vars, time, step, report);
            self.outputs_stale = false;
        }
    }
    fn reset(&mut self) {
        self.vars = Vars::from_start(M::INFO);
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
        let mut r: Self =
            postcard::from_bytes(bytes).map_err(|e| format!("corrupt model state: {e}"))?;
        let [nr, ni, nb, ns] = M::INFO.counts;
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
        if let Some(saved) = r.model.take() {
            r.model = Some(rebuilt(&r.vars, &saved)?);
        }
        Ok(Box::new(r))
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// The model that `saved` (deserialized from an importer's bytes) stands for, rebuilt from the
/// parameters in `vars` so that its derived data (limits, geometry, caches) never comes from the
/// bytes, with `saved`'s history once the model has checked it. The checksum of a serialized state
/// only catches accidents: bytes changed and resealed deliberately reach this point.
fn rebuilt<M: Model>(vars: &Vars, saved: &M) -> Result<M, String> {
    // `new` also writes the calculated parameters (and some models their initial outputs) into
    // its copy: the restored variables keep their own values, which must agree on the former.
    let mut fresh_vars = vars.clone();
    let mut model = M::new(&mut fresh_vars)
        .map_err(|e| format!("corrupt model state: its parameters do not build the model: {e}"))?;
    for var in M::INFO.variables {
        let i = var.vr as usize;
        if var.causality == Causality::CalculatedParameter
            && var.kind == VarType::Real
            && vars.real[i].to_bits() != fresh_vars.real[i].to_bits()
        {
            return Err(format!(
                "corrupt model state: calculated parameter {} = {} but its parameters give {}",
                var.name, vars.real[i], fresh_vars.real[i]
            ));
        }
    }
    model
        .adopt_history(saved)
        .map_err(|e| format!("corrupt model state: {e}"))?;
    Ok(model)
}
