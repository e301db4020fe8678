//! The bridge between the C ABI and any [`Model`]: one instance's typed variable values and
//! model, behind a trait object so that the exported functions are written once for every model.

mod bindings;
mod directional_derivative;

use crate::models::{ArrayOutput, EventUpdate, Model, Report};
use crate::variables::{ArrayIdentifier, ContinuousStates, Interface, ModelInfo};
pub use bindings::Bindings;
use directional_derivative::PartialsCache;
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
    /// Model Exchange: the model's states (read by `fmi2GetReal` for the local ones) and their
    /// derivatives (`der(x)`) as last computed. Copies of what the model owns, so not saved.
    #[serde(skip)]
    pub states: V::States,
    #[serde(skip)]
    pub derivatives: V::States,
}

// By hand: a derive would ask `V: Clone` of the marker type.
impl<V: Interface> Clone for Values<V> {
    fn clone(&self) -> Self {
        Self {
            parameters: self.parameters.clone(),
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
            calculated: self.calculated.clone(),
            states: self.states,
            derivatives: self.derivatives,
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
            states: Default::default(),
            derivatives: Default::default(),
        }
    }
}

/// Creates instances of one model; the generated `REGISTRY` holds one per model description.
pub trait Factory: Sync {
    fn info(&self) -> &'static ModelInfo;
    /// HTML fragment describing the model's equations.
    fn documentation(&self) -> &'static str;
    fn create(&self) -> Box<dyn Runtime>;
    /// Whether the model serves Model Exchange ([`Model::MODEL_EXCHANGE`]).
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
        M::MODEL_EXCHANGE
    }
    fn create(&self) -> Box<dyn Runtime> {
        Box::new(RuntimeOf::<M> {
            values: Values::default(),
            model: None,
            outputs_stale: true,
            time: None,
            rejected: None,
            partials: PartialsCache::default(),
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
    /// Steps the model and writes its `input_clamped` output (if it has one) from the report, as
    /// the instance's out-of-range policy would, within this one dynamic call.
    fn step(&mut self, time: f64, step: f64, report: &mut Report);
    /// Model Exchange, event mode: commits the history at the current inputs and writes the
    /// outputs ([`Model::update_discrete_states`]).
    fn update_discrete_states(&mut self, time: f64, report: &mut Report) -> EventUpdate;
    /// Model Exchange: the integrator accepted a step; whether the model asks for an event.
    fn completed_integrator_step(&mut self, time: f64, report: &mut Report) -> bool;
    /// `numberOfContinuousStates` and `numberOfEventIndicators`.
    fn state_count(&self) -> usize;
    fn event_indicator_count(&self) -> usize;
    /// Model Exchange: the independent variable (passed on to the model once it is built).
    fn set_time(&mut self, time: f64);
    /// The built model's states into `x` (`state_count` values).
    fn continuous_states(&self, x: &mut [f64]) -> Result<(), String>;
    /// Gives the built model the states `x` (`state_count` finite values).
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String>;
    /// The state derivatives into `dx` (`state_count` values), finite or an `Err`.
    fn derivatives(&mut self, dx: &mut [f64]) -> Result<(), String>;
    /// The event indicators into `z` (`event_indicator_count` values), finite or an `Err`.
    fn event_indicators(&mut self, z: &mut [f64]) -> Result<(), String>;
    /// The states' nominal values into `x` (`state_count` values).
    fn nominals(&self, x: &mut [f64]);
    /// The next time event after `time`, if any.
    fn next_time_event(&self, time: f64) -> Option<f64>;
    /// `dv_unknown = d(unknown)/d(known) * dv_known` over Real value references
    /// ([`directional_derivative`]).
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
    /// The built model's FMI 3.0 array output number `index` (declaration order, that of the
    /// generated `ArrayOutput::ALL` and of the FMI 3.0 value references) at the current inputs
    /// ([`Model::array`]).
    fn array(&self, index: usize, out: &mut [f64]) -> Result<(), String>;
}

#[derive(Serialize, Deserialize)]
#[serde(bound = "M: Model")]
struct RuntimeOf<M: Model> {
    values: Values<M::Variables>,
    model: Option<M>,
    /// The outputs are not those the built model wrote for the current values. True whenever
    /// `model` is `None` (every change of `model` sets it; bytes from an importer are made to
    /// agree), so that [`Runtime::outputs_current`] is one test.
    outputs_stale: bool,
    /// Model Exchange's time, given to the model when it is built (`None` for Co-Simulation).
    /// Not saved: the model keeps its own time, and the instance its.
    #[serde(skip)]
    time: Option<f64>,
    /// Why the last build failed, with the values it failed on: a rejected KnittedMuscle builds
    /// its whole shape table before a later check refuses it, and initialization mode retries
    /// the build at every get. Compared when building, so that a set clears nothing.
    #[serde(skip)]
    rejected: Option<Rejected<M::Variables>>,
    /// The model's last partials, for the further seeds of a Jacobian. Not saved; forgotten
    /// whenever the model is replaced.
    #[serde(skip)]
    partials: PartialsCache<M::Variables>,
}

/// A failed build: the parameters and start inputs [`Model::new`] refused, and why.
struct Rejected<V: Interface> {
    parameters: V::Parameters,
    inputs: V::Inputs,
    why: String,
}

impl<V: Interface> Clone for Rejected<V> {
    fn clone(&self) -> Self {
        Self {
            parameters: self.parameters.clone(),
            inputs: self.inputs.clone(),
            why: self.why.clone(),
        }
    }
}

impl<V: Interface> Rejected<V> {
    /// Why, if `values` are those that were refused.
    fn of(&self, values: &Values<V>) -> Option<&str> {
        (self.parameters == values.parameters && self.inputs == values.inputs)
            .then_some(self.why.as_str())
    }
}

impl<M: Model> RuntimeOf<M>
where
    M::Variables: Bindings,
{
    /// Copies the model's states and derivatives into the values `fmi2GetReal` reads (models with
    /// continuous states only; a derivative the model cannot give keeps its last value).
    fn mirror_states(&mut self) {
        if States::<M>::COUNT == 0 {
            return;
        }
        if let Some(model) = self.model.as_mut() {
            let v = &mut self.values;
            v.states = model.states();
            if let Ok(dx) = model.derivatives(&v.inputs) {
                v.derivatives = dx;
            }
        }
    }

    fn built(&mut self) -> Result<&mut M, String> {
        self.model
            .as_mut()
            .ok_or_else(|| "no model yet: call it in initialization mode or later".to_string())
    }
}

type States<M> = <<M as Model>::Variables as Interface>::States;

/// `Err` naming the first non-finite value of `values`.
fn finite(what: &str, names: &[&str], values: &[f64]) -> Result<(), String> {
    match values.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(format!(
            "{what} {} is {}",
            names.get(i).copied().unwrap_or("?"),
            values[i]
        )),
    }
}

impl<M: Model> Clone for RuntimeOf<M> {
    fn clone(&self) -> Self {
        Self {
            values: self.values.clone(),
            model: self.model.clone(),
            outputs_stale: self.outputs_stale,
            time: self.time,
            rejected: self.rejected.clone(),
            partials: PartialsCache::default(),
        }
    }
}

impl<M: Model> Runtime for RuntimeOf<M>
where
    M::Variables: Bindings,
{
    #[inline]
    fn real(&self, vr: usize) -> f64 {
        M::Variables::real(&self.values, vr)
    }
    #[inline]
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
    #[inline]
    fn reals(&self, vrs: &[u32], out: &mut [f64]) {
        for (&vr, slot) in vrs.iter().zip(out) {
            *slot = M::Variables::real(&self.values, vr as usize);
        }
    }
    #[inline]
    fn set_reals(&mut self, vrs: &[u32], values: &[f64], parameters: bool) {
        for (&vr, &value) in vrs.iter().zip(values) {
            M::Variables::set_real(&mut self.values, vr as usize, value);
        }
        self.changed(parameters);
    }
    fn set_string(&mut self, vr: usize, value: &str) {
        M::Variables::set_string(&mut self.values, vr, value)
    }
    #[inline]
    fn changed(&mut self, parameters: bool) {
        self.outputs_stale = true;
        if parameters {
            self.model = None;
        }
    }
    fn is_built(&self) -> bool {
        self.model.is_some()
    }
    #[inline]
    fn outputs_current(&self) -> bool {
        debug_assert!(self.outputs_stale || self.model.is_some());
        !self.outputs_stale
    }
    fn build(&mut self) -> Result<(), String> {
        if let Some(why) = self.rejected.as_ref().and_then(|r| r.of(&self.values)) {
            return Err(why.to_string());
        }
        let v = &mut self.values;
        let mut model = match M::new(&v.parameters, &v.inputs) {
            Ok(model) => model,
            Err(why) => {
                let rejected = Rejected {
                    parameters: v.parameters.clone(),
                    inputs: v.inputs.clone(),
                    why: why.0,
                };
                return Err(self.rejected.insert(rejected).why.clone());
            }
        };
        v.calculated = model.calculated_parameters();
        if let Some(time) = self.time {
            model.set_time(time);
        }
        self.model = Some(model);
        self.partials.forget();
        self.outputs_stale = true;
        Ok(())
    }
    fn refresh_outputs(&mut self, report: &mut Report) {
        if let (true, Some(model)) = (self.outputs_stale, self.model.as_mut()) {
            let v = &mut self.values;
            model.evaluate(&v.inputs, &mut v.outputs, report);
            report.evaluated = true;
            self.outputs_stale = false;
            self.mirror_states();
        }
    }
    fn step(&mut self, time: f64, step: f64, report: &mut Report) {
        // Always built: the state machine lets no step through before initialization.
        let Some(model) = self.model.as_mut() else {
            return;
        };
        report.evaluated = true;
        let v = &mut self.values;
        model.step(&v.inputs, &mut v.outputs, time, step, report);
        self.outputs_stale = false;
        M::Variables::set_input_clamped(v, report.clamped());
    }
    fn update_discrete_states(&mut self, time: f64, report: &mut Report) -> EventUpdate {
        let Some(model) = self.model.as_mut() else {
            return EventUpdate::default();
        };
        let v = &mut self.values;
        let update = model.update_discrete_states(&v.inputs, &mut v.outputs, time, report);
        self.outputs_stale = false;
        self.mirror_states();
        update
    }
    fn completed_integrator_step(&mut self, time: f64, report: &mut Report) -> bool {
        let Some(model) = self.model.as_mut() else {
            return false;
        };
        let v = &mut self.values;
        let event = model.completed_integrator_step(&v.inputs, &mut v.outputs, time, report);
        self.outputs_stale = false;
        self.mirror_states();
        event
    }
    fn state_count(&self) -> usize {
        States::<M>::COUNT
    }
    fn event_indicator_count(&self) -> usize {
        M::Variables::EVENT_INDICATORS
    }
    fn set_time(&mut self, time: f64) {
        if self.time == Some(time) {
            return;
        }
        self.time = Some(time);
        if let Some(model) = self.model.as_mut() {
            model.set_time(time);
            // Outputs depend on time only through states or schedules.
            if States::<M>::COUNT > 0 {
                self.outputs_stale = true;
            }
        }
    }
    fn continuous_states(&self, x: &mut [f64]) -> Result<(), String> {
        let model = self
            .model
            .as_ref()
            .ok_or("no model yet: call it in initialization mode or later")?;
        model.states().write_to(x);
        Ok(())
    }
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        finite("state", States::<M>::NAMES, x)?;
        let states = States::<M>::from_slice(x);
        self.built()?.set_states(&states)?;
        self.values.states = states;
        self.outputs_stale = true;
        Ok(())
    }
    fn derivatives(&mut self, dx: &mut [f64]) -> Result<(), String> {
        let model = self
            .model
            .as_mut()
            .ok_or("no model yet: call it in initialization mode or later")?;
        let derivatives = model.derivatives(&self.values.inputs)?;
        derivatives.write_to(dx);
        finite("derivative", States::<M>::DERIVATIVE_NAMES, dx)?;
        self.values.derivatives = derivatives;
        Ok(())
    }
    fn event_indicators(&mut self, z: &mut [f64]) -> Result<(), String> {
        let model = self
            .model
            .as_mut()
            .ok_or("no model yet: call it in initialization mode or later")?;
        model.event_indicators(&self.values.inputs, z)?;
        finite("event indicator", &[], z)
    }
    fn nominals(&self, x: &mut [f64]) {
        x.copy_from_slice(States::<M>::NOMINALS);
    }
    fn next_time_event(&self, time: f64) -> Option<f64> {
        self.model
            .as_ref()
            .and_then(|m| m.next_time_event(time))
            .filter(|t| t.is_finite() && *t > time)
    }
    fn directional_derivative(
        &mut self,
        unknown: &[u32],
        known: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        directional_derivative::directional_derivative(
            self.model.as_mut(),
            &mut self.partials,
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
        self.partials.forget();
        self.outputs_stale = true;
        self.time = None;
        self.rejected = None;
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
        // The outputs are recomputed from the inputs and the model's history, never taken from
        // the bytes: start values until a model is built, then what it evaluates.
        self.values.outputs = Default::default();
        self.outputs_stale = true;
        if let Some(saved) = self.model.take() {
            self.model = Some(rebuilt(&self.values, &saved)?);
            self.partials.forget();
            let mut report = Report::default();
            self.refresh_outputs(&mut report);
            M::Variables::set_input_clamped(&mut self.values, report.clamped());
        }
        self.mirror_states();
        Ok(())
    }
    fn snapshot_from_bytes(&self, bytes: &[u8]) -> Result<Box<dyn Runtime>, String> {
        let mut r: Self =
            postcard::from_bytes(bytes).map_err(|e| format!("corrupt model state: {e}"))?;
        // No model, no current outputs, whatever the bytes say.
        r.outputs_stale |= r.model.is_none();
        Ok(Box::new(r))
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn array(&self, index: usize, out: &mut [f64]) -> Result<(), String> {
        let array = *ArrayOutput::<M>::ALL
            .get(index)
            .ok_or_else(|| format!("no array output number {index}"))?;
        match &self.model {
            Some(model) => model.array(&self.values.inputs, array, out),
            None => Err("no model yet: call it in initialization mode or later".into()),
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::mckibben_muscle::McKibbenMuscle;

    /// A copy of `runtime` as its concrete type, to edit before serializing.
    fn copy_of(runtime: &dyn Runtime) -> Result<RuntimeOf<McKibbenMuscle>, String> {
        runtime
            .as_any()
            .downcast_ref::<RuntimeOf<McKibbenMuscle>>()
            .cloned()
            .ok_or_else(|| "not a McKibbenMuscle runtime".to_string())
    }

    /// "Outputs current" is one flag, which holds only with a built model:
    /// bytes that claim current outputs without a model, or whose model fails to rebuild, are
    /// made to agree.
    #[test]
    fn no_model_means_stale_outputs_whatever_the_bytes_say() -> Result<(), String> {
        let mut runtime = ModelFactory::<McKibbenMuscle>::NEW.create();
        let mut crafted = copy_of(&*runtime)?;
        crafted.outputs_stale = false;
        let restored = runtime.snapshot_from_bytes(&crafted.to_bytes()?)?;
        assert!(!restored.is_built());
        assert!(!restored.outputs_current());

        runtime.build()?;
        let mut report = Report::default();
        runtime.step(0.0, 1e-3, &mut report);
        assert!(runtime.outputs_current());
        // A model whose parameters no longer build it: no model, stale outputs.
        let mut r = copy_of(&*runtime)?;
        r.values.parameters.turns = -1.0;
        let mut broken = runtime.snapshot_from_bytes(&r.to_bytes()?)?;
        assert!(broken.outputs_current());
        assert!(broken.rebuild_model().is_err());
        assert!(!broken.is_built());
        assert!(!broken.outputs_current());
        Ok(())
    }
}
