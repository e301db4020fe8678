//! The C entry points of the per-step calls, compiled once per model: `fmi2SetReal`, `fmi2DoStep`
//! and `fmi2GetReal` check the instance pointer and jump (a tail call) to the entry point of the
//! instance's model, which catches panics, checks the arrays and runs the monomorphized body
//! (`instance/hot.rs`). A set or get of one value is first tried on a path that cannot panic,
//! outside the guard: without a landing pad it needs no stack frame.

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

/// Neither pointer is NULL: one test of the smaller address (two tests compiled to four flag
/// operations).
#[inline(always)]
fn non_null<T, U>(a: *const T, b: *const U) -> bool {
    (a as usize).min(b as usize) != 0
}

/// # Safety
/// See [`HotPath`].
unsafe extern "C" fn set_real<R: Runtime + 'static>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    // SAFETY: see HotPath; one readable element at each non-null pointer.
    if nvr == 1
        && non_null(vr, value)
        && unsafe { hot::try_set_real::<R>(&mut *(c as *mut Instance), *vr, *value) }
    {
        return fmi2Status::OK;
    }
    // SAFETY: the caller's promise.
    unsafe { set_real_guarded::<R>(c, vr, nvr, value) }
}

/// `fmi2SetReal` under the panic guard. `extern "C"`, as it cannot unwind: the call to it is then a
/// tail call (a call that may unwind out of an `extern "C"` function needs a landing pad).
///
/// # Safety
/// See [`HotPath`].
#[inline(never)]
unsafe extern "C" fn set_real_guarded<R: Runtime + 'static>(
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
    // SAFETY: see HotPath; one element at each non-null pointer, `value` writable.
    if nvr == 1
        && non_null(vr, value)
        && unsafe { hot::try_get_real::<R>(&mut *(c as *mut Instance), *vr, &mut *value) }
    {
        return fmi2Status::OK;
    }
    // SAFETY: the caller's promise.
    unsafe { get_real_guarded::<R>(c, vr, nvr, value) }
}

/// `fmi2GetReal` under the panic guard, `extern "C"` as [`set_real_guarded`].
///
/// # Safety
/// See [`HotPath`].
#[inline(never)]
unsafe extern "C" fn get_real_guarded<R: Runtime + 'static>(
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
