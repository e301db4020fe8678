//! Every export's one path, in both FMI versions: find the instance behind the importer's handle,
//! refuse it if it belongs to the other version's API, run the call's body under `catch_unwind`
//! (a panic is logged and becomes `Fatal`, it never unwinds into the importer). Beside it, the
//! checks that turn the importer's pointers into slices and strings.
//!
//! Every `unsafe` function here relies on the importer keeping its FMI version's calling
//! convention: a handle from its instantiation function (or any value, refused by
//! [`handles`](super::handles)), arrays of the length it passes (or NULL) and NUL-terminated
//! strings.

use super::handles::{self, Handle};
use super::instance::{Api, Instance, MachineState};
use super::Status;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The instance behind `c`, if `c` is the handle of a live instance of ours ([`handles`]).
///
/// # Safety
/// No other reference to the instance may be alive (FMI: one call at a time per instance).
unsafe fn instance<'a>(c: Handle) -> Option<&'a mut Instance> {
    // SAFETY: a live instance of ours, owned by the handle table until it is freed.
    handles::resolve(c).map(|ptr| unsafe { &mut *ptr })
}

fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Checks the instance handle `c` of a call to `function` of `api`, then runs `body` on the
/// instance; a panic is logged and the instance becomes fatal, it never unwinds into the importer.
///
/// # Safety
/// As [`instance`].
pub(crate) unsafe fn guarded(
    api: &'static Api,
    c: Handle,
    function: &str,
    body: impl FnOnce(&mut Instance) -> Status,
) -> Status {
    // SAFETY: see `instance`.
    let Some(inst) = (unsafe { instance(c) }) else {
        return Status::Error;
    };
    // One handle table serves both FMI versions: an instance answers only the calls of the `Api`
    // (a static of its version layer) it was instantiated through.
    if !std::ptr::eq(inst.api, api) {
        return wrong_version(inst, function);
    }
    let ptr: *mut Instance = inst;
    // SAFETY: `ptr` is live for the whole call; the closure's borrow ends before the panic arm.
    match catch_unwind(AssertUnwindSafe(|| body(unsafe { &mut *ptr }))) {
        Ok(status) => status,
        // SAFETY: as above; nothing else borrows the instance now.
        Err(payload) => internal_error(unsafe { &mut *ptr }, function, &*payload),
    }
}

#[cold]
#[inline(never)]
fn wrong_version(inst: &Instance, function: &str) -> Status {
    inst.error(&format!(
        "{function}: the instance was instantiated through the {} API",
        inst.api.version
    ))
}

/// A panic caught at the C boundary: logged, and the instance becomes fatal.
#[cold]
#[inline(never)]
fn internal_error(
    inst: &mut Instance,
    function: &str,
    payload: &(dyn std::any::Any + Send),
) -> Status {
    inst.set_state(MachineState::Fatal);
    inst.logger.log(
        Status::Fatal,
        &format!("{function}: internal error: {}", panic_text(payload)),
    );
    Status::Fatal
}

/// A slice from a C array; NULL is accepted only for an empty array.
///
/// # Safety
/// A non-null `ptr` must point to `n` readable elements.
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, n: usize) -> Option<&'a [T]> {
    match (ptr.is_null(), n) {
        (_, 0) => Some(&[]),
        (true, _) => None,
        // SAFETY: the caller promises `n` readable elements at a non-null `ptr`.
        (false, _) => Some(unsafe { std::slice::from_raw_parts(ptr, n) }),
    }
}

/// # Safety
/// As [`slice`], for `n` writable elements.
pub(crate) unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize) -> Option<&'a mut [T]> {
    match (ptr.is_null(), n) {
        (_, 0) => Some(&mut []),
        (true, _) => None,
        // SAFETY: the caller promises `n` writable elements at a non-null `ptr`.
        (false, _) => Some(unsafe { std::slice::from_raw_parts_mut(ptr, n) }),
    }
}

/// # Safety
/// A non-null `s` must be NUL-terminated.
pub(crate) unsafe fn text(s: *const c_char) -> Option<String> {
    // SAFETY: non-null, and the caller promises NUL termination.
    (!s.is_null()).then(|| unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
}

#[cold]
#[inline(never)]
pub(crate) fn null_argument(inst: &Instance, function: &str, argument: &str) -> Status {
    inst.error(&format!("{function}: {argument} must not be NULL"))
}
