//! The C entry points of the per-step calls, compiled once per model: `fmi2SetReal`, `fmi2DoStep`
//! and `fmi2GetReal` check the instance pointer and jump (a tail call) to the entry point of the
//! instance's model, which catches panics, checks the arrays and runs the monomorphized body
//! (`instance/hot.rs`).

use super::{null_argument, run_guarded, slice, slice_mut};
use crate::fmi2::instance::{hot, Instance};
use crate::fmi2::runtime::Runtime;
use crate::fmi2::types::*;

/// The per-step entry points of one model, for the runtime type its factory creates. Each has the
/// signature of the FMI function it serves, so that the exported function can jump to it.
///
/// # Safety
/// Each function may only be called with a live instance (the caller checked its magic number)
/// whose runtime is that type: [`Instance::new`] takes the runtime and this table from the same
/// factory, and nothing replaces the runtime.
#[derive(Clone, Copy)]
pub struct HotPath {
    pub(in crate::fmi2) set_real: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *const fmi2Real,
    ) -> fmi2Status,
    pub(in crate::fmi2) do_step:
        unsafe extern "C" fn(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean) -> fmi2Status,
    pub(in crate::fmi2) get_real: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *mut fmi2Real,
    ) -> fmi2Status,
}

impl HotPath {
    /// The entry points for runtimes of type `R`.
    pub fn of<R: Runtime + 'static>() -> Self {
        Self {
            set_real: set_real::<R>,
            do_step: do_step::<R>,
            get_real: get_real::<R>,
        }
    }
}

/// # Safety
/// See [`HotPath`].
unsafe extern "C" fn set_real<R: Runtime + 'static>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetReal";
    // SAFETY: see HotPath; the importer passes arrays of `nvr` elements (or NULL, refused).
    unsafe {
        run_guarded(c as *mut Instance, F, |inst| {
            let (Some(vrs), Some(values)) = (slice(vr, nvr), slice(value, nvr)) else {
                return null_argument(inst, F, "vr and value");
            };
            hot::set_reals::<R>(inst, vrs, values)
        })
    }
}

/// # Safety
/// See [`HotPath`].
unsafe extern "C" fn do_step<R: Runtime + 'static>(
    c: fmi2Component,
    current_communication_point: fmi2Real,
    communication_step_size: fmi2Real,
    _no_set_fmu_state_prior_to_current_point: fmi2Boolean,
) -> fmi2Status {
    // SAFETY: see HotPath.
    unsafe {
        run_guarded(c as *mut Instance, "fmi2DoStep", |inst| {
            hot::do_step::<R>(inst, current_communication_point, communication_step_size)
        })
    }
}

/// # Safety
/// See [`HotPath`].
unsafe extern "C" fn get_real<R: Runtime + 'static>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetReal";
    // SAFETY: see HotPath; the importer passes arrays of `nvr` elements (or NULL, refused).
    unsafe {
        run_guarded(c as *mut Instance, F, |inst| {
            let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
                return null_argument(inst, F, "vr and value");
            };
            hot::get_reals::<R>(inst, vrs, out)
        })
    }
}
