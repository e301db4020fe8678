//! The bridge between the C ABI and any [`Model`]: one instance's typed variable values and
//! model, behind a trait object so that the exported functions are written once for every model.

use super::registry::Bindings;
use crate::models::{Model, Report};
use crate::variables::{Interface, ModelInfo};
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::marker::PhantomData;

/// One instance's variable values, typed: the model's generated groups themselves. The model
/// reads and writes these fields directly; `fmi2GetXXX`/`fmi2SetXXX` reach them by value reference
/// through the generated [`Bindings`] (one `match` per call, no copies around a step).
#[derive(Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Values<V: Interface> {
    pub parameters: V::Parameters,
    pub inputs: V::Inputs,
    pub outputs: V::Outputs,
    pub calculated: V::CalculatedParameters,
}

// By hand: a derive would ask `V: Clone` of the marker type.
impl<V: Interface> Clone for Values<V> {
    fn clone(&self) -> Self {
        Self {
            parameters: self.parameters.clone(),
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
            calculated: self.calculated.clone(),
        }
    }
}

impl<V: Interface> Default for Values<V> {
    /// The start values of the model description.
    fn default() -> Self {
        Self {
            parameters: Default::default(),
            inputs: Default::default(),
            outputs: Default::default(),
            calculated: Default::default(),
        }
    }
}

/// Creates instances of one model; the generated `REGISTRY` holds one per model description.
pub trait Factory: Sync {
    fn info(&self) -> &'static ModelInfo;
    /// HTML fragment describing the model's equations.
    fn documentation(&self) -> &'static str;
    fn create(&self) -> Box<dyn Runtime>;
    /// Whether the model serves Model Exchange ([`Model::ALGEBRAIC_MODEL_EXCHANGE`]).
    fn model_exchange(&self) -> bool;
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
    fn model_exchange(&self) -> bool {
        M::ALGEBRAIC_MODEL_EXCHANGE
    }
    fn create(&self) -> Box<dyn Runtime> {
        Box::new(RuntimeOf::<M> {
            values: Values::default(),
            model: None,
            outputs_stale: true,
        })
    }
}

/// One instance's variables and model, independent of the model's type. Values are read and
/// written by value reference (the caller checks that `vr` is one of the model's); writes are
/// followed by [`Runtime::changed`] so that outputs and the model follow them.
pub trait Runtime: Send {
    fn real(&self, vr: usize) -> f64;
    fn set_real(&mut self, vr: usize, value: f64);
    fn integer(&self, vr: usize) -> i32;
    fn set_integer(&mut self, vr: usize, value: i32);
    fn boolean(&self, vr: usize) -> bool;
    fn set_boolean(&mut self, vr: usize, value: bool);
    fn string(&self, vr: usize) -> &str;
    /// `out[i] = real(vrs[i])`: fmi2GetReal in one dynamic call.
    fn reals(&self, vrs: &[u32], out: &mut [f64]);
    /// [`Runtime::reals`] if [`Runtime::outputs_current`], else nothing: whether it read them.
    fn current_reals(&self, vrs: &[u32], out: &mut [f64]) -> bool;
    /// `set_real(vrs[i], values[i])`, then [`Runtime::changed`]: fmi2SetReal in one dynamic call.
    fn set_reals(&mut self, vrs: &[u32], values: &[f64], parameters: bool);
    fn set_string(&mut self, vr: usize, value: &str);
    /// Tells that inputs changed (outputs are stale) or that parameters did (the model is too).
    fn changed(&mut self, parameters: bool);
    fn is_built(&self) -> bool;
    /// Built, and no input or parameter changed since the outputs were last written.
    fn outputs_current(&self) -> bool;
    /// Builds the model from the current parameters, with only the effects they switch on.
    fn build(&mut self) -> Result<(), String>;
    /// Recomputes the outputs if an input changed since they were last written.
    fn refresh_outputs(&mut self, report: &mut Report);
    /// Steps the model; with `clamp_flag` (the `input_clamped` output's value reference) also
    /// writes that flag from the report, as [`super::out_of_range::OutOfRange::apply`] would,
    /// within this one dynamic call.
    fn step(&mut self, time: f64, step: f64, report: &mut Report, clamp_flag: Option<usize>);
    /// Model Exchange: commits the history at the current inputs (completed integrator step or
    /// event) and writes the outputs.
    fn update_discrete_states(&mut self, time: f64, report: &mut Report);
    /// `dv_unknown = d(unknown)/d(known) * dv_known` over Real value references
    /// ([`super::derivatives`]).
    fn directional_derivative(
        &mut self,
        unknown: &[u32],
        known: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String>;
    /// Start values, no model.
    fn reset(&mut self);
    fn snapshot(&self) -> Box<dyn Runtime>;
    /// Copies `other` (a snapshot of the same model) into `self`.
    fn restore(&mut self, other: &dyn Runtime) -> Result<(), String>;
    fn to_bytes(&self) -> Result<Vec<u8>, String>;
    fn snapshot_from_bytes(&self, bytes: &[u8]) -> Result<Box<dyn Runtime>, String>;
    /// For a snapshot from bytes whose values passed the declared checks: the model rebuilt from
    /// its parameters, with only its checked history taken from the bytes ([`rebuilt`]).
    fn rebuild_model(&mut self) -> Result<(), String>;
    fn as_any(&self) -> &dyn Any;
}

#[derive(Serialize, Deserialize)]
#[serde(bound = "M: Model")]
struct RuntimeOf<M: Model> {
    values: Values<M::Variables>,
    model: Option<M>,
    outputs_stale: bool,
}

impl<M: Model> Clone for RuntimeOf<M> {
    fn clone(&self) -> Self {
        Self {
            values: self.values.clone(),
            model: self.model.clone(),
            outputs_stale: self.outputs_stale,
        }
    }
}

impl<M: Model> Runtime for RuntimeOf<M>
where
    M::Variables: Bindings,
{
    fn real(&self, vr: usize) -> f64 {
        M::Variables::real(&self.values, vr)
    }
    fn set_real(&mut self, vr: usize, value: f64) {
        M::Variables::set_real(&mut self.values, vr, value)
    }
    fn integer(&self, vr: usize) -> i32 {
        M::Variables::integer(&self.values, vr)
    }
    fn set_integer(&mut self, vr: usize, value: i32) {
        M::Variables::set_integer(&mut self.values, vr, value)
    }
    fn boolean(&self, vr: usize) -> bool {
        M::Variables::boolean(&self.values, vr)
    }
    fn set_boolean(&mut self, vr: usize, value: bool) {
        M::Variables::set_boolean(&mut self.values, vr, value)
    }
    fn string(&self, vr: usize) -> &str {
        M::Variables::string(&self.values, vr)
    }
    fn reals(&self, vrs: &[u32], out: &mut [f64]) {
        for (&vr, slot) in vrs.iter().zip(out) {
            *slot = M::Variables::real(&self.values, vr as usize);
        }
    }
    fn current_reals(&self, vrs: &[u32], out: &mut [f64]) -> bool {
        if !self.outputs_current() {
            return false;
        }
        self.reals(vrs, out);
        true
    }
    fn set_reals(&mut self, vrs: &[u32], values: &[f64], parameters: bool) {
        for (&vr, &value) in vrs.iter().zip(values) {
            M::Variables::set_real(&mut self.values, vr as usize, value);
        }
        self.changed(parameters);
    }
    fn set_string(&mut self, vr: usize, value: &str) {
        M::Variables::set_string(&mut self.values, vr, value)
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
    fn outputs_current(&self) -> bool {
        !self.outputs_stale && self.model.is_some()
    }
    fn build(&mut self) -> Result<(), String> {
        let v = &mut self.values;
        let model = M::new(&v.parameters, &v.inputs).map_err(|r| r.0)?;
        v.calculated = model.calculated_parameters();
        self.model = Some(model);
        self.outputs_stale = true;
        Ok(())
    }
    fn refresh_outputs(&mut self, report: &mut Report) {
        if let (true, Some(model)) = (self.outputs_stale, self.model.as_mut()) {
            let v = &mut self.values;
            model.evaluate(&v.inputs, &mut v.outputs, report);
            report.evaluated = true;
            self.outputs_stale = false;
        }
    }
    fn step(&mut self, time: f64, step: f64, report: &mut Report, clamp_flag: Option<usize>) {
        if let Some(model) = self.model.as_mut() {
            let v = &mut self.values;
            model.step(&v.inputs, &mut v.outputs, time, step, report);
            report.evaluated = true;
            self.outputs_stale = false;
            if let Some(flag) = clamp_flag {
                M::Variables::set_boolean(v, flag, report.clamped);
            }
        }
    }
    fn update_discrete_states(&mut self, time: f64, report: &mut Report) {
        if let Some(model) = self.model.as_mut() {
            let v = &mut self.values;
            model.update_discrete_states(&v.inputs, &mut v.outputs, time, report);
            self.outputs_stale = false;
        }
    }
    fn directional_derivative(
        &mut self,
        unknown: &[u32],
        known: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        super::derivatives::directional_derivative(
            self.model.as_mut(),
            &self.values.inputs,
            unknown,
            known,
            dv_known,
            dv_unknown,
        )
    }
    fn reset(&mut self) {
        self.values = Values::default();
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
    fn rebuild_model(&mut self) -> Result<(), String> {
        if let Some(saved) = self.model.take() {
            self.model = Some(rebuilt(&self.values, &saved)?);
        }
        Ok(())
    }
    fn snapshot_from_bytes(&self, bytes: &[u8]) -> Result<Box<dyn Runtime>, String> {
        let r: Self =
            postcard::from_bytes(bytes).map_err(|e| format!("corrupt model state: {e}"))?;
        Ok(Box::new(r))
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// The model that `saved` (deserialized from an importer's bytes) stands for, rebuilt from the
/// parameters in `values` so that its derived data (limits, geometry, caches) never comes from the
/// bytes, with `saved`'s history once the model has checked it ([`Model::adopt_history`]). The
/// checksum of a serialized state only catches accidents: bytes changed and resealed deliberately
/// reach this point.
fn rebuilt<M: Model>(values: &Values<M::Variables>, saved: &M) -> Result<M, String>
where
    M::Variables: Bindings,
{
    let mut model = M::new(&values.parameters, &values.inputs).map_err(|r| {
        format!(
            "corrupt model state: its parameters do not build the model: {}",
            r.0
        )
    })?;
    // The restored variables keep their own values, which must agree with what the parameters give.
    if model.calculated_parameters() != values.calculated {
        return Err(format!(
            "corrupt model state: its calculated parameters {:?} are not those its parameters give, {:?}",
            values.calculated,
            model.calculated_parameters()
        ));
    }
    model
        .adopt_history(saved)
        .map_err(|e| format!("corrupt model state: {e}"))?;
    Ok(model)
}
