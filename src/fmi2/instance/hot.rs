//! The per-step calls (`fmi2SetReal`, `fmi2DoStep`, `fmi2GetReal`), compiled once per model.
//!
//! One binary serves every model, so the instance reaches its model through `dyn Runtime`. On the
//! per-step path that costs a dynamic call per FMI call and, worse, hides the model from the
//! optimizer: the step could not inline the model's `step`, so it built, passed and inspected a
//! `Report` even for models that never write one. Here each function is generic over the concrete
//! runtime, and the instance holds the three instantiations of its own model (their C entry points
//! are [`HotPath`]'s): one indirect call, a tail call from the exported function, reaches code in
//! which the bindings' `match`, the model's step and the report's bookkeeping are all inlined.
//!
//! Each function takes the fast path only for a call the FMI standard accepts without a word: state
//! allowed, debug logging off, known value references, values within their declared range, no
//! parameter among them. Anything else goes to the general code in `values.rs` and `machine.rs`,
//! which checks again and refuses, logs or rebuilds exactly as before.

use super::{allowed, Instance, MachineState};
pub use crate::fmi2::exports::HotPath;
use crate::fmi2::runtime::Runtime;
use crate::fmi2::types::fmi2Status;
use crate::models::Report;

impl Instance {
    /// The per-step entry points of this instance's model.
    #[inline(always)]
    pub(in crate::fmi2) fn hot_path(&self) -> &HotPath {
        &self.hot
    }

    /// The runtime as its concrete type.
    ///
    /// # Safety
    /// `R` must be the type of `self.runtime`: [`Instance::new`] takes the runtime and the
    /// [`HotPath`] (whose functions call this) from the same factory, and nothing replaces the
    /// runtime.
    #[inline(always)]
    unsafe fn runtime_as<R: Runtime + 'static>(&mut self) -> &mut R {
        debug_assert!(self.runtime.as_any().is::<R>());
        // SAFETY: the caller promises that the box holds an `R`; the cast drops the vtable only.
        unsafe { &mut *(self.runtime.as_mut() as *mut dyn Runtime as *mut R) }
    }

    /// Whether a call allowed in `mask` takes the fast path: allowed now, and no call tracing.
    #[inline(always)]
    fn quietly_allowed(&self, mask: u32) -> bool {
        mask & self.gate.quiet() != 0
    }
}

/// `fmi2SetReal` of one value on the per-step path: stores an input (or tunable local) within its
/// range, and says whether it did. Anything else is left to [`set_reals`].
///
/// Called outside the panic guard (`exports/hot.rs`): it must not panic, and cannot (compares,
/// loads and two stores; `get` rather than indexing).
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
#[inline(always)]
pub(in crate::fmi2) unsafe fn try_set_real<R: Runtime + 'static>(
    inst: &mut Instance,
    vr: u32,
    value: f64,
) -> bool {
    if !accepts(inst, vr, value) {
        return false;
    }
    // SAFETY: the caller promises that R is the runtime's type.
    let runtime = unsafe { inst.runtime_as::<R>() };
    runtime.set_real(vr as usize, value);
    runtime.changed(false);
    true
}

/// `fmi2SetReal` of what the entry point's one-value path ([`try_set_real`]) did not take: many
/// values through the per-step loop, one value through the general path (which is right for any
/// call, so nothing depends on the first try).
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
pub(in crate::fmi2) unsafe fn set_reals<R: Runtime + 'static>(
    inst: &mut Instance,
    vrs: &[u32],
    values: &[f64],
) -> fmi2Status {
    if vrs.len() == 1 {
        return set_general_path(inst, vrs, values);
    }
    // SAFETY: the caller's promise.
    unsafe { set_many_reals::<R>(inst, vrs, values) }
}

/// Whether the per-step path may store `value` at `vr` now: a rule's fast states are a subset of
/// those that allow a set, so no separate state check; none while calls are logged.
#[inline(always)]
fn accepts(inst: &Instance, vr: u32, value: f64) -> bool {
    let quiet = inst.gate.quiet();
    inst.set_rules[0]
        .get(vr as usize)
        .is_some_and(|rule| rule.fast_states & quiet != 0 && rule.accepts(value))
}

/// The general `fmi2SetReal` (it refuses, logs or stores as before), out of line and cold.
#[cold]
#[inline(never)]
fn set_general_path(inst: &mut Instance, vrs: &[u32], values: &[f64]) -> fmi2Status {
    inst.set_general("fmi2SetReal", vrs, values)
}

/// [`set_reals`] of any number of values.
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
#[inline(never)]
unsafe fn set_many_reals<R: Runtime + 'static>(
    inst: &mut Instance,
    vrs: &[u32],
    values: &[f64],
) -> fmi2Status {
    let fast = vrs
        .iter()
        .zip(values)
        .all(|(&vr, &value)| accepts(inst, vr, value));
    if !fast {
        return set_general_path(inst, vrs, values);
    }
    // SAFETY: the caller promises that R is the runtime's type.
    unsafe { inst.runtime_as::<R>() }.set_reals(vrs, values, false);
    fmi2Status::OK
}

/// `fmi2DoStep`, all of it: the checks refuse out of line.
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
pub(in crate::fmi2) unsafe fn do_step<R: Runtime + 'static>(
    inst: &mut Instance,
    time: f64,
    step: f64,
) -> fmi2Status {
    // The checks of a step that the standard accepts without a word, none of which calls out:
    // anything else takes the general checks, out of line, which refuse or log as before.
    if !(inst.quietly_allowed(allowed::DO_STEP) && inst.step_accepted(time, step)) {
        // SAFETY: the caller's promise.
        return unsafe { step_checked::<R>(inst, time, step) };
    }
    // SAFETY: the caller's promise.
    unsafe { step_unchecked::<R>(inst, time, step) }
}

/// `fmi2DoStep` after a state or step check that did not pass at once: refused with the reason,
/// or (a logged call, a communication point off by rounding) stepped after all.
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
#[cold]
#[inline(never)]
unsafe fn step_checked<R: Runtime + 'static>(
    inst: &mut Instance,
    time: f64,
    step: f64,
) -> fmi2Status {
    if !inst.quietly_allowed(allowed::DO_STEP) && !inst.allowed("fmi2DoStep", allowed::DO_STEP) {
        return fmi2Status::Error;
    }
    if let Some(refused) = inst.step_refused(time, step) {
        return refused;
    }
    // SAFETY: the caller's promise.
    unsafe { step_unchecked::<R>(inst, time, step) }
}

/// The step itself, its checks passed.
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
#[inline(always)]
unsafe fn step_unchecked<R: Runtime + 'static>(
    inst: &mut Instance,
    time: f64,
    step: f64,
) -> fmi2Status {
    const F: &str = "fmi2DoStep";
    let mut report = Report::default();
    // SAFETY: the caller promises that R is the runtime's type.
    unsafe { inst.runtime_as::<R>() }.step(time, step, &mut report);
    // The flag is written: only a report with something to say needs more. A quiet report has
    // nothing to log and nothing to free: its drop is skipped and the step returns at once,
    // without a dispatch on the status.
    if report.is_quiet() {
        std::mem::forget(report);
        inst.time = time + step;
        return fmi2Status::OK;
    }
    let status = inst.forward_messages(F, report, true);
    // Compares, not a `match`: that compiled to a jump table.
    if status <= fmi2Status::Warning {
        inst.time = time + step;
    } else if status == fmi2Status::Discard {
        inst.set_state(MachineState::StepFailed);
    } else {
        inst.set_state(MachineState::Error);
    }
    status
}

/// `fmi2GetReal` of one value on the per-step path: reads an output that is current (after a
/// step, or a get with no set since) and finite into `slot`, and says whether it did. Anything
/// else is left to [`get_reals`].
///
/// Called outside the panic guard (`exports/hot.rs`): it must not panic, and cannot (compares,
/// loads and a store; `get` rather than indexing).
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
#[inline(always)]
pub(in crate::fmi2) unsafe fn try_get_real<R: Runtime + 'static>(
    inst: &mut Instance,
    vr: u32,
    slot: &mut f64,
) -> bool {
    // Current outputs are what the general path hands out in every state that allows a get:
    // it refreshes only stale ones. An unknown value reference reads as NaN, so the finiteness
    // test sends it to the general path too, which refuses it.
    if !inst.quietly_allowed(allowed::GET) {
        return false;
    }
    // SAFETY: the caller promises that R is the runtime's type.
    let runtime = unsafe { inst.runtime_as::<R>() };
    if !runtime.outputs_current() {
        return false;
    }
    let x = runtime.real(vr as usize);
    if !x.is_finite() {
        return false;
    }
    *slot = x;
    true
}

/// `fmi2GetReal` of what the entry point's one-value path ([`try_get_real`]) did not take, as
/// [`set_reals`].
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
pub(in crate::fmi2) unsafe fn get_reals<R: Runtime + 'static>(
    inst: &mut Instance,
    vrs: &[u32],
    out: &mut [f64],
) -> fmi2Status {
    if vrs.len() == 1 {
        return get_general_path(inst, vrs, out);
    }
    // SAFETY: the caller's promise.
    unsafe { get_many_reals::<R>(inst, vrs, out) }
}

/// The general `fmi2GetReal` (it refreshes stale outputs and refuses as before), out of line and
/// cold.
#[cold]
#[inline(never)]
fn get_general_path(inst: &mut Instance, vrs: &[u32], out: &mut [f64]) -> fmi2Status {
    inst.get_reals_general(vrs, out)
}

/// [`get_reals`] of any number of values.
///
/// # Safety
/// `R` is the runtime's type ([`Instance::runtime_as`]).
#[inline(never)]
unsafe fn get_many_reals<R: Runtime + 'static>(
    inst: &mut Instance,
    vrs: &[u32],
    out: &mut [f64],
) -> fmi2Status {
    if inst.quietly_allowed(allowed::GET) {
        // SAFETY: the caller promises that R is the runtime's type.
        let runtime = unsafe { inst.runtime_as::<R>() };
        // Checked before anything is written: NaN (an unknown value reference reads as NaN) never
        // reaches the importer's array.
        let fast = runtime.outputs_current()
            && vrs.iter().all(|&vr| runtime.real(vr as usize).is_finite());
        if fast {
            runtime.reals(vrs, out);
            return fmi2Status::OK;
        }
    }
    get_general_path(inst, vrs, out)
}
