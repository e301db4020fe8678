//! `fmi3Get/Set<Type>` by FMI 3.0 value reference: Float64 (the FMI 2.0 Reals, `time`, the event
//! indicators, the array outputs), Int32, Int64 (the Enumerations, FMI 3.0 section 2.4.7.3) and
//! Boolean. Each value reference is translated to FMI 2.0's by the model's [`Fmi3Model`] layout;
//! the shared `Instance` then applies the same state, range and NaN rules as FMI 2.0. An array
//! takes as many of `values` as it has elements (FMI 3.0 section 2.2.6.2: `nValues` counts the
//! elements of every variable, arrays serialized in row-major order).

use super::exports::{guarded, Status};
use super::{fmi3Boolean, fmi3Instance, fmi3Status, fmi3ValueReference, Fmi3Model};
use crate::export::guard::{null_argument, slice, slice_mut};
use crate::export::instance::{allowed, CBoolean, Instance, Vector};
use crate::variables::VarType;

/// What an FMI 3.0 value reference names.
#[derive(Clone, Copy, PartialEq)]
enum Slot {
    Real(u32),
    Time,
    EventIndicator(usize),
    Integer(u32),
    Enumeration(u32),
    Boolean(u32),
    /// The index of an array output in [`Fmi3Model::arrays`].
    Array(usize),
    Unknown,
}

fn classify(model: &Fmi3Model, counts: [usize; 4], vr: u32) -> Slot {
    let [_, integers, booleans, _] = counts.map(|c| c as u32);
    if vr < model.time {
        Slot::Real(vr)
    } else if vr == model.time {
        Slot::Time
    } else if vr < model.integers {
        Slot::EventIndicator((vr - model.event_indicators) as usize)
    } else if vr < model.integers + integers {
        let i = vr - model.integers;
        if model.enumerations.contains(&i) {
            Slot::Enumeration(i)
        } else {
            Slot::Integer(i)
        }
    } else if vr >= model.booleans && vr < model.booleans + booleans {
        Slot::Boolean(vr - model.booleans)
    } else if let Some(k) = model.arrays.iter().position(|a| a.value_reference == vr) {
        Slot::Array(k)
    } else {
        Slot::Unknown
    }
}

fn model_of(inst: &Instance, function: &str) -> Result<&'static Fmi3Model, fmi3Status> {
    super::model(inst.info().name)
        .ok_or_else(|| inst.error(&format!("{function}: no FMI 3.0 description of this model")))
}

/// The FMI 2.0 value references of `vrs`, each of which must be `want` (by kind); the error
/// names the first that is not.
fn translate(
    inst: &Instance,
    function: &str,
    type_name: &str,
    vrs: &[u32],
    want: impl Fn(Slot) -> Option<u32>,
) -> Result<Vec<u32>, fmi3Status> {
    let model = model_of(inst, function)?;
    let counts = inst.info().counts;
    vrs.iter()
        .map(|&vr| {
            want(classify(model, counts, vr)).ok_or_else(|| {
                inst.error(&format!(
                    "{function}: value reference {vr} is not a settable or gettable {type_name} \
                     variable of {}",
                    model.name
                ))
            })
        })
        .collect()
}

/// The shared checks of every getter and setter: the array lengths and pointers.
///
/// # Safety
/// As `slice`.
unsafe fn arrays<'a, T>(
    inst: &Instance,
    function: &str,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const T,
    n_values: usize,
) -> Result<(&'a [u32], &'a [T]), fmi3Status> {
    if nvr != n_values {
        return Err(inst.error(&format!(
            "{function}: nValues ({n_values}) must equal nValueReferences ({nvr}): the \
             variables are scalars"
        )));
    }
    // SAFETY: the importer passes arrays of the stated lengths (or NULL, refused here).
    match unsafe { (slice(vr, nvr), slice(values, n_values)) } {
        (Some(v), Some(x)) => Ok((v, x)),
        _ => Err(null_argument(inst, function, "valueReferences and values")),
    }
}

/// # Safety
/// As `slice_mut`.
unsafe fn arrays_mut<'a, T>(
    inst: &Instance,
    function: &str,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut T,
    n_values: usize,
) -> Result<(&'a [u32], &'a mut [T]), fmi3Status> {
    if nvr != n_values {
        return Err(inst.error(&format!(
            "{function}: nValues ({n_values}) must equal nValueReferences ({nvr}): the \
             variables are scalars"
        )));
    }
    // SAFETY: as in `arrays`.
    match unsafe { (slice(vr, nvr), slice_mut(values, n_values)) } {
        (Some(v), Some(x)) => Ok((v, x)),
        _ => Err(null_argument(inst, function, "valueReferences and values")),
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut f64,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetFloat64";
    unsafe {
        guarded(instance, F, |inst| {
            let reals = inst.info().counts[0] as u32;
            // SAFETY: the importer passes `nvr` value references (or NULL, refused below).
            let Some(vrs) = slice(vr, nvr) else {
                return null_argument(inst, F, "valueReferences and values");
            };
            // The FMI 2.0 Reals in one call: the common case.
            if vrs.iter().all(|&v| v < reals) {
                let (vrs, out) = match arrays_mut(inst, F, vr, nvr, values, n_values) {
                    Ok(a) => a,
                    Err(status) => return status,
                };
                return inst.get_reals(F, vrs, out);
            }
            let Ok(model) = model_of(inst, F) else {
                return Status::Error;
            };
            let counts = inst.info().counts;
            let slots: Vec<Slot> = vrs.iter().map(|&v| classify(model, counts, v)).collect();
            let elements = |s: &Slot| match s {
                Slot::Array(k) => model.arrays[*k].size,
                _ => 1,
            };
            let total: usize = slots.iter().map(elements).sum();
            if total != n_values {
                return inst.error(&format!(
                    "{F}: nValues ({n_values}) must be {total}, the number of elements of the \
                     {nvr} variables asked for (arrays count their elements: {})",
                    array_sizes(model, &slots)
                ));
            }
            // SAFETY: the importer passes `nValues` values (or NULL, refused here).
            let Some(out) = slice_mut(values, n_values) else {
                return null_argument(inst, F, "valueReferences and values");
            };
            let mut status = Status::OK;
            let mut at = 0;
            for (&v, slot) in vrs.iter().zip(&slots) {
                let n = elements(slot);
                let target = &mut out[at..at + n];
                at += n;
                let s = match *slot {
                    Slot::Real(r) => inst.get_reals(F, &[r], target),
                    Slot::Time => {
                        if inst.allowed(F, allowed::GET) {
                            target[0] = inst.time;
                            Status::OK
                        } else {
                            Status::Error
                        }
                    }
                    Slot::EventIndicator(k) => {
                        let mut z = vec![0.0; inst.runtime.event_indicator_count()];
                        let s = inst.get_vector(F, Vector::EventIndicators, &mut z);
                        if s < Status::Error {
                            target[0] = z.get(k).copied().unwrap_or(0.0);
                        }
                        s
                    }
                    Slot::Array(k) => inst.get_array(F, (k, model.arrays[k].name), target),
                    _ => inst.error(&format!(
                        "{F}: value reference {v} is not a Float64 variable of {}",
                        model.name
                    )),
                };
                if s >= Status::Error {
                    return s;
                }
                status = status.max(s);
            }
            status
        })
    }
}

/// "name (size)" of the arrays among `slots`, or "none".
fn array_sizes(model: &Fmi3Model, slots: &[Slot]) -> String {
    let listed: Vec<String> = slots
        .iter()
        .filter_map(|s| match s {
            Slot::Array(k) => Some(format!(
                "{} has {}",
                model.arrays[*k].name, model.arrays[*k].size
            )),
            _ => None,
        })
        .collect();
    if listed.is_empty() {
        "none here".into()
    } else {
        listed.join(", ")
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const f64,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetFloat64";
    unsafe {
        guarded(instance, F, |inst| {
            let (vrs, x) = match arrays(inst, F, vr, nvr, values, n_values) {
                Ok(a) => a,
                Err(status) => return status,
            };
            let reals = inst.info().counts[0] as u32;
            if let Some(&bad) = vrs.iter().find(|&&v| v >= reals) {
                return inst.error(&format!(
                    "{F}: value reference {bad} is not a Float64 variable that can be set (time \
                     and the event indicators are computed)"
                ));
            }
            inst.set(F, vrs, x)
        })
    }
}

/// Int32 (a plain Integer) or Int64 (an Enumeration): their FMI 2.0 Integer value references.
fn integers(
    inst: &Instance,
    function: &str,
    vrs: &[u32],
    enumeration: bool,
) -> Result<Vec<u32>, fmi3Status> {
    let name = if enumeration {
        "Enumeration (Int64)"
    } else {
        "Int32"
    };
    translate(inst, function, name, vrs, |slot| match slot {
        Slot::Integer(i) if !enumeration => Some(i),
        Slot::Enumeration(i) if enumeration => Some(i),
        _ => None,
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut i32,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetInt32";
    unsafe {
        guarded(instance, F, |inst| {
            let (vrs, out) = match arrays_mut(inst, F, vr, nvr, values, n_values) {
                Ok(a) => a,
                Err(status) => return status,
            };
            match integers(inst, F, vrs, false) {
                Ok(vrs) => inst.get(F, VarType::Integer, &vrs, out, |r, i| r.integer(i)),
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const i32,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetInt32";
    unsafe {
        guarded(instance, F, |inst| {
            let (vrs, x) = match arrays(inst, F, vr, nvr, values, n_values) {
                Ok(a) => a,
                Err(status) => return status,
            };
            match integers(inst, F, vrs, false) {
                Ok(vrs) => inst.set(F, &vrs, x),
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt64(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut i64,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetInt64";
    unsafe {
        guarded(instance, F, |inst| {
            let (vrs, out) = match arrays_mut(inst, F, vr, nvr, values, n_values) {
                Ok(a) => a,
                Err(status) => return status,
            };
            let vrs = match integers(inst, F, vrs, true) {
                Ok(vrs) => vrs,
                Err(status) => return status,
            };
            let mut narrow = vec![0i32; vrs.len()];
            let status = inst.get(F, VarType::Integer, &vrs, &mut narrow, |r, i| r.integer(i));
            if status < Status::Error {
                for (o, n) in out.iter_mut().zip(&narrow) {
                    *o = i64::from(*n);
                }
            }
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt64(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const i64,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetInt64";
    unsafe {
        guarded(instance, F, |inst| {
            let (vrs, x) = match arrays(inst, F, vr, nvr, values, n_values) {
                Ok(a) => a,
                Err(status) => return status,
            };
            let vrs = match integers(inst, F, vrs, true) {
                Ok(vrs) => vrs,
                Err(status) => return status,
            };
            // Enumeration items are small: a value outside i32 is no item (the range check
            // then names the items).
            let narrow: Vec<i32> = x
                .iter()
                .map(|&v| i32::try_from(v).unwrap_or(if v < 0 { i32::MIN } else { i32::MAX }))
                .collect();
            inst.set(F, &vrs, &narrow)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetBoolean";
    unsafe {
        guarded(instance, F, |inst| {
            let (vrs, out) = match arrays_mut(inst, F, vr, nvr, values, n_values) {
                Ok(a) => a,
                Err(status) => return status,
            };
            let vrs = match translate(inst, F, "Boolean", vrs, |s| match s {
                Slot::Boolean(b) => Some(b),
                _ => None,
            }) {
                Ok(vrs) => vrs,
                Err(status) => return status,
            };
            inst.get(F, VarType::Boolean, &vrs, out, |r, i| {
                u8::from(r.boolean(i))
            })
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetBoolean";
    unsafe {
        guarded(instance, F, |inst| {
            let (vrs, x) = match arrays(inst, F, vr, nvr, values, n_values) {
                Ok(a) => a,
                Err(status) => return status,
            };
            let vrs = match translate(inst, F, "Boolean", vrs, |s| match s {
                Slot::Boolean(b) => Some(b),
                _ => None,
            }) {
                Ok(vrs) => vrs,
                Err(status) => return status,
            };
            let x: Vec<CBoolean> = x.iter().map(|&b| CBoolean(i32::from(b != 0))).collect();
            inst.set(F, &vrs, &x)
        })
    }
}
