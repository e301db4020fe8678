//! Getting and setting variables (FMI 2.0.4 section 2.2.7: what may be set in which state),
//! with range checks and the rebuild after a tunable parameter changed.

use super::{allowed, type_index, Instance, MachineState};
use crate::fmi2::logger::c_string;
use crate::fmi2::runtime::Runtime;
use crate::fmi2::types::fmi2Status;
use crate::variables::{Causality, Initial, VarType, Variability, Variable};

/// A value that fmi2SetXXX can write into a [`Runtime`].
pub trait Value {
    const KIND: VarType;
    /// A reason to refuse the value for this variable, if any.
    fn invalid_for(&self, var: &Variable) -> Option<String>;
    fn store(&self, runtime: &mut dyn Runtime, vr: usize);
}

impl Value for f64 {
    const KIND: VarType = VarType::Real;
    fn invalid_for(&self, var: &Variable) -> Option<String> {
        if !self.is_finite() {
            return Some(format!("{} = {self} is not finite", var.name));
        }
        range_check(*self, var)
    }
    fn store(&self, runtime: &mut dyn Runtime, vr: usize) {
        runtime.set_real(vr, *self);
    }
}

impl Value for i32 {
    const KIND: VarType = VarType::Integer;
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

pub(super) fn range_check(x: f64, var: &Variable) -> Option<String> {
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

impl Instance {
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
            MachineState::StepComplete | MachineState::EventMode => {
                input
                    || (var.causality == Causality::Parameter
                        && var.variability == Variability::Tunable)
            }
            MachineState::ContinuousTimeMode => input,
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
        for (&vr, value) in vrs.iter().zip(values) {
            value.store(self.runtime.as_mut(), vr as usize);
        }
        self.runtime.changed(parameters_changed);
        self.rebuild_or_undo(function, before)
    }

    /// A snapshot to undo a tunable parameter change with, if this set changes one between steps.
    fn before_retune(&self, parameters_changed: bool) -> Option<Box<dyn Runtime>> {
        (parameters_changed
            && matches!(
                self.state,
                MachineState::StepComplete | MachineState::EventMode
            ))
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
        pick: impl Fn(&dyn Runtime, usize) -> T,
    ) -> fmi2Status {
        if !self.allowed(function, allowed::GET) {
            return fmi2Status::Error;
        }
        let mut status = fmi2Status::OK;
        if matches!(
            self.state,
            MachineState::InitializationMode
                | MachineState::StepComplete
                | MachineState::EventMode
                | MachineState::ContinuousTimeMode
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
            // The last guard of "no output is ever NaN": the models check their own results,
            // and a value that still is not finite is refused here, never handed out.
            if kind == VarType::Real && !self.runtime.real(vr as usize).is_finite() {
                return self.non_finite(function, vr);
            }
            *slot = pick(self.runtime.as_ref(), vr as usize);
        }
        status
    }

    /// Refuses to hand out a non-finite Real, naming it: a model error, not the importer's.
    #[cold]
    fn non_finite(&self, function: &str, vr: u32) -> fmi2Status {
        let x = self.runtime.real(vr as usize);
        let name = self.by_type[0].get(vr as usize).map_or("?", |v| v.name);
        self.error(&format!(
            "{function}: {name} (value reference {vr}) is {x}: the model produced a non-finite \
             value from the current parameters and inputs; it is not handed out"
        ))
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
        let runtime = self.runtime.as_ref();
        self.string_values = refs
            .iter()
            .map(|&vr| c_string(runtime.string(vr as usize)))
            .collect();
        Ok(self.string_values.iter().map(|s| s.as_ptr()).collect())
    }
}
