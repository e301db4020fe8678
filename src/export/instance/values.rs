//! Getting and setting variables (FMI 2.0.4 section 2.2.7: what may be set in which state),
//! with range checks and the rebuild after a tunable parameter changed.

use super::{allowed, type_index, Instance, MachineState};
use crate::export::logger::c_string;
use crate::export::runtime::Runtime;
use crate::export::Status;
use crate::variables::{Causality, Initial, VarType, Variability, Variable};

/// A value that fmi2SetXXX can write into a [`Runtime`].
pub trait Value {
    const KIND: VarType;
    /// A reason to refuse the value for this variable, if any.
    fn invalid_for(&self, var: &Variable) -> Option<String>;
    /// Whether the value passes [`Value::invalid_for`], by the bounds of a [`SetRule`].
    #[inline]
    fn within(&self, _min: f64, _max: f64) -> bool {
        true
    }
    fn store(&self, runtime: &mut dyn Runtime, vr: usize);
    /// Stores every value, then tells the runtime what changed.
    fn store_all(runtime: &mut dyn Runtime, vrs: &[u32], values: &[Self], parameters: bool)
    where
        Self: Sized,
    {
        for (&vr, value) in vrs.iter().zip(values) {
            value.store(runtime, vr as usize);
        }
        runtime.changed(parameters);
    }
}

impl Value for f64 {
    const KIND: VarType = VarType::Real;
    /// The bounds are finite: NaN and the infinities fail one of the comparisons.
    #[inline]
    fn within(&self, min: f64, max: f64) -> bool {
        *self >= min && *self <= max
    }
    #[inline]
    fn invalid_for(&self, var: &Variable) -> Option<String> {
        if !self.is_finite() {
            return Some(not_finite(*self, var));
        }
        range_check(*self, var)
    }
    #[inline]
    fn store(&self, runtime: &mut dyn Runtime, vr: usize) {
        runtime.set_real(vr, *self);
    }
    /// One dynamic call for the whole array (fmi2SetReal is on every step's path).
    #[inline]
    fn store_all(runtime: &mut dyn Runtime, vrs: &[u32], values: &[Self], parameters: bool) {
        runtime.set_reals(vrs, values, parameters);
    }
}

impl Value for i32 {
    const KIND: VarType = VarType::Integer;
    #[inline]
    fn within(&self, min: f64, max: f64) -> bool {
        let x = *self as f64;
        x >= min && x <= max
    }
    fn invalid_for(&self, var: &Variable) -> Option<String> {
        range_check(*self as f64, var)
    }
    fn store(&self, runtime: &mut dyn Runtime, vr: usize) {
        runtime.set_integer(vr, *self);
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
    fn store(&self, runtime: &mut dyn Runtime, vr: usize) {
        runtime.set_boolean(vr, self.0 != 0);
    }
}

impl Value for String {
    const KIND: VarType = VarType::String;
    fn invalid_for(&self, _: &Variable) -> Option<String> {
        None
    }
    fn store(&self, runtime: &mut dyn Runtime, vr: usize) {
        runtime.set_string(vr, self);
    }
}

#[cold]
#[inline(never)]
fn not_finite(x: f64, var: &Variable) -> String {
    format!("{} = {x} is not finite", var.name)
}

/// A reason to refuse `x` for `var`'s declared range, if any. Inlined: two comparisons per value
/// set; the message is built out of line, only on refusal.
#[inline]
pub(super) fn range_check(x: f64, var: &Variable) -> Option<String> {
    let below = var.min.is_some_and(|min| x < min);
    if below || var.max.is_some_and(|max| x > max) {
        return Some(range_message(x, var, below));
    }
    None
}

#[cold]
#[inline(never)]
fn range_message(x: f64, var: &Variable, below: bool) -> String {
    let (what, bound) = match (below, var.min, var.max) {
        (true, Some(min), _) => ("below its minimum", min),
        (_, _, Some(max)) => ("above its maximum", max),
        _ => unreachable!("range_message is only called for a value out of a declared bound"),
    };
    let unit = if var.unit.is_empty() || var.unit == "1" {
        String::new()
    } else {
        format!(" {}", var.unit)
    };
    format!("{} = {x}{unit} is {what} {bound}{unit}", var.name)
}

/// FMI 2.0.4 section 2.2.7: whether `var` may be set in `state`.
fn settable_in(var: &Variable, state: MachineState) -> bool {
    if var.variability == Variability::Constant {
        return false;
    }
    let input = var.causality == Causality::Input;
    match state {
        MachineState::Instantiated => {
            input || matches!(var.initial, Initial::Exact | Initial::Approx)
        }
        MachineState::InitializationMode => input || var.initial == Initial::Exact,
        MachineState::StepComplete | MachineState::EventMode => {
            input
                || (var.causality == Causality::Parameter
                    && var.variability == Variability::Tunable)
        }
        MachineState::ContinuousTimeMode => input,
        _ => false,
    }
}

/// One variable's checks for fmi2SetXXX, computed once per instance: the states it may be set in
/// (a mask of [`MachineState::bit`]) and its bounds: the declared ones, else the largest finite
/// doubles, so that the two comparisons of [`Value::within`] also refuse NaN and the infinities.
pub struct SetRule {
    var: &'static Variable,
    states: u32,
    min: f64,
    max: f64,
    parameter: bool,
}

impl SetRule {
    pub fn new(var: &'static Variable) -> Self {
        let states = MachineState::ALL
            .iter()
            .filter(|&&s| settable_in(var, s))
            .fold(0, |mask, s| mask | s.bit());
        let min = var.min.unwrap_or(f64::MIN);
        let max = var.max.unwrap_or(f64::MAX);
        let parameter = var.causality == Causality::Parameter;
        Self {
            var,
            states,
            min,
            max,
            parameter,
        }
    }
}

impl Instance {
    #[inline]
    fn lookup(&self, function: &str, kind: VarType, vr: u32) -> Result<&'static Variable, Status> {
        match self.by_type[type_index(kind)].get(vr as usize) {
            Some(var) => Ok(var),
            None => Err(self.unknown_reference(function, kind, vr)),
        }
    }

    #[cold]
    #[inline(never)]
    fn unknown_reference(&self, function: &str, kind: VarType, vr: u32) -> Status {
        self.error(&format!(
            "{function}: {vr} is not the value reference of a {kind:?} variable of {}",
            self.info.name
        ))
    }

    /// Sets all values or, if any is refused, none (the old values are kept).
    #[inline(always)]
    pub fn set<T: Value>(&mut self, function: &str, vrs: &[u32], values: &[T]) -> Status {
        if !self.allowed(function, allowed::SET) {
            return Status::Error;
        }
        let rules = &self.set_rules[type_index(T::KIND)];
        let state = self.state().bit();
        let mut parameters_changed = false;
        for (&vr, value) in vrs.iter().zip(values) {
            let Some(rule) = rules.get(vr as usize) else {
                return self.unknown_reference(function, T::KIND, vr);
            };
            if rule.states & state == 0 {
                return self.not_settable(function, rule.var);
            }
            if !value.within(rule.min, rule.max) {
                return self.refuse_value(function, value, rule.var);
            }
            parameters_changed |= rule.parameter;
        }
        let before = self.before_retune(parameters_changed);
        T::store_all(self.runtime.as_mut(), vrs, values, parameters_changed);
        self.rebuild_or_undo(function, before)
    }

    #[cold]
    #[inline(never)]
    fn not_settable(&self, function: &str, var: &Variable) -> Status {
        self.error(&format!(
            "{function}: {} ({:?}, {:?}) cannot be set in state {}",
            var.name,
            var.causality,
            var.variability,
            self.state_name(self.state())
        ))
    }

    #[cold]
    #[inline(never)]
    fn refuse_value<T: Value>(&self, function: &str, value: &T, var: &Variable) -> Status {
        let reason = value
            .invalid_for(var)
            .unwrap_or_else(|| format!("{} is out of its declared range", var.name));
        self.error(&format!("{function}: {reason}; the value is kept"))
    }

    /// A snapshot to undo a tunable parameter change with, if this set changes one between steps.
    #[inline]
    fn before_retune(&self, parameters_changed: bool) -> Option<Box<dyn Runtime>> {
        (parameters_changed
            && matches!(
                self.state(),
                MachineState::StepComplete | MachineState::EventMode
            ))
        .then(|| self.runtime.snapshot())
    }

    /// After a tunable parameter changed between steps: [`Model`](crate::models::Model) has no
    /// update hook, so the model is rebuilt from its parameters at once (its history restarts).
    /// Parameters it cannot be built from are refused and every value set by the call is undone.
    #[inline]
    fn rebuild_or_undo(&mut self, function: &str, before: Option<Box<dyn Runtime>>) -> Status {
        match before {
            None => Status::OK,
            Some(before) => self.rebuild(function, before),
        }
    }

    #[inline(never)]
    fn rebuild(&mut self, function: &str, before: Box<dyn Runtime>) -> Status {
        match self.runtime.build() {
            Ok(()) => Status::OK,
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

    /// Before a get reads values: outputs that inputs made stale are brought up to date (the
    /// model built in initialization mode) where the state lets inputs change them; the status
    /// of that.
    #[inline]
    fn outputs_for_get(&mut self, function: &str) -> Status {
        if self.runtime.outputs_current() {
            return Status::OK;
        }
        match self.state() {
            MachineState::InitializationMode
            | MachineState::StepComplete
            | MachineState::EventMode
            | MachineState::ContinuousTimeMode => self.recompute_outputs(function),
            _ => Status::OK,
        }
    }

    /// Copies `pick(vars, vr)` for each value reference, outputs brought up to date first.
    pub fn get<T: Copy>(
        &mut self,
        function: &str,
        kind: VarType,
        vrs: &[u32],
        out: &mut [T],
        pick: impl Fn(&dyn Runtime, usize) -> T,
    ) -> Status {
        if !self.allowed(function, allowed::GET) {
            return Status::Error;
        }
        let status = self.outputs_for_get(function);
        if status >= Status::Error {
            return status;
        }
        for (&vr, slot) in vrs.iter().zip(out.iter_mut()) {
            if let Err(s) = self.lookup(function, kind, vr) {
                return s;
            }
            // The last guard of "no output is ever NaN": the models check their own results,
            // and a value that still is not finite is refused here, never handed out.
            if kind == VarType::Real && !self.runtime.real(vr as usize).is_finite() {
                return self.non_finite(function, vr);
            }
            *slot = pick(self.runtime.as_ref(), vr as usize);
        }
        status
    }

    /// An FMI 3.0 array output (`Runtime::array`): the model's values once it is built (zeros
    /// before, as the outputs' start values), every element finite. Where the model has no
    /// value the elements are 0 and a warning says why.
    pub fn get_array(
        &mut self,
        function: &str,
        (index, name): (usize, &str),
        out: &mut [f64],
    ) -> Status {
        if !self.allowed(function, allowed::GET) {
            return Status::Error;
        }
        out.fill(0.0);
        let status = self.outputs_for_get(function);
        if status >= Status::Error || !self.runtime.is_built() {
            return status;
        }
        let why = match self.runtime.array(index, out) {
            Ok(()) if out.iter().all(|x| x.is_finite()) => return status,
            Ok(()) => "a value is not finite".to_string(),
            Err(why) => why,
        };
        out.fill(0.0);
        self.logger.log(
            Status::Warning,
            &format!("{function}: {name} is 0 here: {why}"),
        );
        status.max(Status::Warning)
    }

    /// `fmi2GetReal`, `fmi3GetFloat64`: as [`Instance::get`], in one call into the runtime for
    /// all values. A value reference that is not the model's reads NaN ([`Bindings::real`]), so
    /// that one test refuses both it and a non-finite output.
    ///
    /// [`Bindings::real`]: crate::export::runtime::Bindings::real
    #[inline(always)]
    pub fn get_reals(&mut self, function: &str, vrs: &[u32], out: &mut [f64]) -> Status {
        if !self.allowed(function, allowed::GET) {
            return Status::Error;
        }
        let status = self.outputs_for_get(function);
        if status >= Status::Error {
            return status;
        }
        self.runtime.reals(vrs, out);
        // The last guard of "no output is ever NaN": the models check their own results, and a
        // value that still is not finite is refused here, never handed out.
        match out.iter().position(|x| !x.is_finite()) {
            None => status,
            Some(k) => self.refuse_real(function, vrs[k]),
        }
    }

    /// The refusal of fmi2GetReal's non-finite value at `vr`: an unknown value reference (the
    /// importer's error) or a non-finite output (the model's).
    #[cold]
    #[inline(never)]
    fn refuse_real(&self, function: &str, vr: u32) -> Status {
        match self.by_type[type_index(VarType::Real)].get(vr as usize) {
            None => self.unknown_reference(function, VarType::Real, vr),
            Some(_) => self.non_finite(function, vr),
        }
    }

    /// Refuses to hand out a non-finite Real, naming it: a model error, not the importer's.
    #[cold]
    fn non_finite(&self, function: &str, vr: u32) -> Status {
        let x = self.runtime.real(vr as usize);
        let name = self.by_type[0].get(vr as usize).map_or("?", |v| v.name);
        self.error(&format!(
            "{function}: {name} (value reference {vr}) is {x}: the model produced a non-finite \
             value from the current parameters and inputs; it is not handed out"
        ))
    }

    /// `fmi2GetString`: the returned strings live until the next call on this instance.
    pub fn get_strings(
        &mut self,
        function: &str,
        vrs: &[u32],
    ) -> Result<Vec<*const std::ffi::c_char>, Status> {
        let mut refs = vec![0u32; vrs.len()];
        let status = self.get(function, VarType::String, vrs, &mut refs, |_, vr| vr as u32);
        if status >= Status::Error {
            return Err(status);
        }
        let runtime = self.runtime.as_ref();
        self.string_values = refs
            .iter()
            .map(|&vr| c_string(runtime.string(vr as usize)))
            .collect();
        Ok(self.string_values.iter().map(|s| s.as_ptr()).collect())
    }
}
