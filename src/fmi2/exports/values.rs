//! fmi2SetXXX and fmi2GetXXX: the importer's arrays as slices, handed to the instance.

use super::guarded;
use crate::export::guard::{null_argument, slice, slice_mut, text};
use crate::export::instance::{CBoolean, Value};
use crate::export::runtime::Runtime;
use crate::fmi2::types::*;
use crate::variables::VarType;

/// The shared body of fmi2SetReal/Integer/Boolean: checks the arrays and sets, without copying.
unsafe fn set_values<T: Value>(
    c: fmi2Component,
    function: &'static str,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const T,
) -> fmi2Status {
    unsafe {
        guarded(c, function, |inst| {
            let (Some(vrs), Some(values)) = (slice(vr, nvr), slice(value, nvr)) else {
                return null_argument(inst, function, "vr and value");
            };
            inst.set(function, vrs, values)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    unsafe { set_values(c, "fmi2SetReal", vr, nvr, value) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    unsafe { set_values(c, "fmi2SetInteger", vr, nvr, value) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    // CBoolean is a transparent wrapper of the C int.
    unsafe { set_values(c, "fmi2SetBoolean", vr, nvr, value as *const CBoolean) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    unsafe {
        guarded(c, "fmi2SetString", |inst| {
            let (Some(vrs), Some(values)) = (slice(vr, nvr), slice(value, nvr)) else {
                return null_argument(inst, "fmi2SetString", "vr and value");
            };
            let Some(strings) = values
                .iter()
                .map(|&s| text(s))
                .collect::<Option<Vec<String>>>()
            else {
                return null_argument(inst, "fmi2SetString", "a string value");
            };
            inst.set("fmi2SetString", vrs, &strings)
        })
    }
}

unsafe fn get_values<C: Copy + Default>(
    c: fmi2Component,
    function: &'static str,
    kind: VarType,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut C,
    pick: impl Fn(&dyn Runtime, usize) -> C,
) -> fmi2Status {
    unsafe {
        guarded(c, function, |inst| {
            let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
                return null_argument(inst, function, "vr and value");
            };
            inst.get(function, kind, vrs, out, pick)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetReal";
    unsafe {
        guarded(c, F, |inst| {
            let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
                return null_argument(inst, F, "vr and value");
            };
            inst.get_reals(F, vrs, out)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unsafe {
        get_values(
            c,
            "fmi2GetInteger",
            VarType::Integer,
            vr,
            nvr,
            value,
            |v, i| v.integer(i),
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        get_values(
            c,
            "fmi2GetBoolean",
            VarType::Boolean,
            vr,
            nvr,
            value,
            |v, i| v.boolean(i) as fmi2Boolean,
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2GetString";
    unsafe {
        guarded(c, F, |inst| {
            let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
                return null_argument(inst, F, "vr and value");
            };
            match inst.get_strings(F, vrs) {
                Ok(ptrs) => {
                    out.copy_from_slice(&ptrs);
                    fmi2Status::OK
                }
                Err(status) => status,
            }
        })
    }
}
