//! Directional and adjoint derivatives, and the declared variable dependencies.

use super::exports::{guarded, Status};
use super::{fmi3Instance, fmi3Status, fmi3ValueReference};
use crate::export::guard::{null_argument, slice, slice_mut};
use crate::export::instance::{allowed, Instance};
use std::ffi::c_int;

/// Partials are served for Float64 variables (the FMI 2.0 Reals, same value references); `time`
/// and the event indicators have none.
fn check_float64(inst: &Instance, function: &str, vrs: &[u32]) -> Option<fmi3Status> {
    let reals = inst.info().counts[0] as u32;
    vrs.iter().find(|&&vr| vr >= reals).map(|vr| {
        inst.error(&format!(
            "{function}: value reference {vr} is not a Float64 variable with partial derivatives \
             (those are 0..{reals})"
        ))
    })
}

/// Which side of the Jacobian `J` a derivative call's seed is on.
#[derive(Clone, Copy)]
enum Seed {
    /// `sensitivity = J seed` (`fmi3GetDirectionalDerivative`): a seed value per known.
    Knowns,
    /// `sensitivity = seed^T J` (`fmi3GetAdjointDerivative`): a seed value per unknown.
    Unknowns,
}

/// A raw array argument and its length.
type Raw<T> = (T, usize);

/// The arguments both derivative calls share, as slices of Float64 value references and values.
type Checked<'a> = (&'a [u32], &'a [u32], &'a [f64], &'a mut [f64]);

/// The arguments of a derivative call, checked: the seed and the sensitivity as long as the side
/// `seed_on` says (the variables are scalars), no NULL array of non-zero length, and every value
/// reference a Float64 variable.
///
/// # Safety
/// Each non-NULL pointer points to as many values as its length says.
unsafe fn checked<'a>(
    inst: &Instance,
    function: &str,
    seed_on: Seed,
    unknowns: Raw<*const fmi3ValueReference>,
    knowns: Raw<*const fmi3ValueReference>,
    seed: Raw<*const f64>,
    sensitivity: Raw<*mut f64>,
) -> Result<Checked<'a>, fmi3Status> {
    let ((seeded, n_seeded), (sensed, n_sensed)) = match seed_on {
        Seed::Knowns => (("nKnowns", knowns.1), ("nUnknowns", unknowns.1)),
        Seed::Unknowns => (("nUnknowns", unknowns.1), ("nKnowns", knowns.1)),
    };
    if seed.1 != n_seeded || sensitivity.1 != n_sensed {
        return Err(inst.error(&format!(
            "{function}: nSeed ({}) must equal {seeded} ({n_seeded}) and nSensitivity ({}) \
             {sensed} ({n_sensed}): the variables are scalars",
            seed.1, sensitivity.1
        )));
    }
    // SAFETY: the caller's contract.
    let arrays = unsafe {
        (
            slice(unknowns.0, unknowns.1),
            slice(knowns.0, knowns.1),
            slice(seed.0, seed.1),
            slice_mut(sensitivity.0, sensitivity.1),
        )
    };
    let (Some(unknowns), Some(knowns), Some(seed), Some(sensitivity)) = arrays else {
        return Err(null_argument(
            inst,
            function,
            "unknowns, knowns, seed or sensitivity",
        ));
    };
    match check_float64(inst, function, unknowns).or_else(|| check_float64(inst, function, knowns))
    {
        Some(refused) => Err(refused),
        None => Ok((unknowns, knowns, seed, sensitivity)),
    }
}

#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    n_unknowns: usize,
    knowns: *const fmi3ValueReference,
    n_knowns: usize,
    seed: *const f64,
    n_seed: usize,
    sensitivity: *mut f64,
    n_sensitivity: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetDirectionalDerivative";
    unsafe {
        guarded(instance, F, |inst| {
            let arguments = checked(
                inst,
                F,
                Seed::Knowns,
                (unknowns, n_unknowns),
                (knowns, n_knowns),
                (seed, n_seed),
                (sensitivity, n_sensitivity),
            );
            let (unknowns, knowns, seed, sensitivity) = match arguments {
                Ok(a) => a,
                Err(refused) => return refused,
            };
            inst.get_directional_derivative(F, unknowns, knowns, seed, sensitivity)
        })
    }
}

/// `sensitivity = seed^T J`: one directional derivative per known (a column of the Jacobian).
/// Cheap here: a model has a handful of knowns, and each column is one exact partial.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    n_unknowns: usize,
    knowns: *const fmi3ValueReference,
    n_knowns: usize,
    seed: *const f64,
    n_seed: usize,
    sensitivity: *mut f64,
    n_sensitivity: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetAdjointDerivative";
    unsafe {
        guarded(instance, F, |inst| {
            let arguments = checked(
                inst,
                F,
                Seed::Unknowns,
                (unknowns, n_unknowns),
                (knowns, n_knowns),
                (seed, n_seed),
                (sensitivity, n_sensitivity),
            );
            let (unknowns, knowns, seed, sensitivity) = match arguments {
                Ok(a) => a,
                Err(refused) => return refused,
            };
            let mut column = vec![0.0; unknowns.len()];
            let mut status = Status::OK;
            for (k, &known) in knowns.iter().enumerate() {
                let s = inst.get_directional_derivative(F, unknowns, &[known], &[1.0], &mut column);
                if s >= Status::Discard {
                    return s;
                }
                status = status.max(s);
                sensitivity[k] = seed.iter().zip(&column).map(|(a, b)| a * b).sum();
            }
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
    instance: fmi3Instance,
    value_reference: fmi3ValueReference,
    n_dependencies: *mut usize,
) -> fmi3Status {
    const F: &str = "fmi3GetNumberOfVariableDependencies";
    unsafe {
        guarded(instance, F, |inst| {
            let Some(n) = n_dependencies.as_mut() else {
                return null_argument(inst, F, "nDependencies");
            };
            match dependencies(inst, F, value_reference) {
                Ok(list) => {
                    *n = list.len();
                    Status::OK
                }
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    instance: fmi3Instance,
    dependent: fmi3ValueReference,
    element_indices_of_dependent: *mut usize,
    independents: *mut fmi3ValueReference,
    element_indices_of_independents: *mut usize,
    dependency_kinds: *mut c_int,
    n_dependencies: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetVariableDependencies";
    unsafe {
        guarded(instance, F, |inst| {
            let list = match dependencies(inst, F, dependent) {
                Ok(list) => list,
                Err(status) => return status,
            };
            if n_dependencies != list.len() {
                return inst.error(&format!(
                    "{F}: nDependencies is {n_dependencies}, but value reference {dependent} has {} \
                     (fmi3GetNumberOfVariableDependencies)",
                    list.len()
                ));
            }
            let n = list.len();
            let (Some(dep_elements), Some(independents), Some(elements), Some(kinds)) = (
                slice_mut(element_indices_of_dependent, n),
                slice_mut(independents, n),
                slice_mut(element_indices_of_independents, n),
                slice_mut(dependency_kinds, n),
            ) else {
                return null_argument(inst, F, "an output array");
            };
            // Scalars: every element index is 0.
            for (k, &(vr, kind)) in list.iter().enumerate() {
                dep_elements[k] = 0;
                independents[k] = vr;
                elements[k] = 0;
                kinds[k] = c_int::from(kind);
            }
            Status::OK
        })
    }
}

/// The declared dependencies of the ModelStructure unknown `vr`.
fn dependencies(
    inst: &Instance,
    function: &str,
    vr: u32,
) -> Result<&'static [(u32, u8)], fmi3Status> {
    if !inst.allowed(function, allowed::ALL_BUT_FATAL) {
        return Err(Status::Error);
    }
    let Some(model) = super::model(inst.info().name) else {
        return Err(inst.error(&format!("{function}: no FMI 3.0 description of this model")));
    };
    match model.dependencies.iter().find(|(v, _)| *v == vr) {
        Some((_, Some(list))) => Ok(list),
        Some((_, None)) => Err(inst.error(&format!(
            "{function}: value reference {vr} declares no dependencies"
        ))),
        None => Err(inst.error(&format!(
            "{function}: value reference {vr} is not an output, state derivative or initial \
             unknown of the ModelStructure"
        ))),
    }
}
