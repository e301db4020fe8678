//! Every other function of the FMI 3.0 API. The models have no variables of these types, no
//! clocks and no configuration mode: each call is refused with a logged reason (a getter or setter of no variable at all does nothing and succeeds).

use super::exports::{guarded, Status};
use super::{fmi3Boolean, fmi3Instance, fmi3Status, fmi3String, fmi3ValueReference};
use std::ffi::c_int;

/// Refuses `function` on a live instance, saying why.
///
/// # Safety
/// As `guarded`.
unsafe fn refuse(instance: fmi3Instance, function: &str, why: &str) -> fmi3Status {
    unsafe {
        guarded(instance, function, |inst| {
            inst.error(&format!("{function}: not supported: {why}"))
        })
    }
}

/// A getter or setter of a type no model has: nothing to do for no value references.
///
/// # Safety
/// As `guarded`.
unsafe fn no_such_type(instance: fmi3Instance, function: &str, nvr: usize) -> fmi3Status {
    if nvr == 0 {
        return unsafe { guarded(instance, function, |_| Status::OK) };
    }
    unsafe {
        refuse(
            instance,
            function,
            "the model has no variables of this type (Float64, Int32, Int64 for Enumerations and Boolean only)",
        )
    }
}

macro_rules! typed {
    ($($name:ident($values:ty);)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            instance: fmi3Instance,
            _vr: *const fmi3ValueReference,
            nvr: usize,
            _values: $values,
            _n_values: usize,
        ) -> fmi3Status {
            unsafe { no_such_type(instance, stringify!($name), nvr) }
        }
    )*};
}

typed! {
    fmi3GetFloat32(*mut f32);
    fmi3GetInt8(*mut i8);
    fmi3GetUInt8(*mut u8);
    fmi3GetInt16(*mut i16);
    fmi3GetUInt16(*mut u16);
    fmi3GetUInt32(*mut u32);
    fmi3GetUInt64(*mut u64);
    fmi3GetString(*mut fmi3String);
    fmi3SetFloat32(*const f32);
    fmi3SetInt8(*const i8);
    fmi3SetUInt8(*const u8);
    fmi3SetInt16(*const i16);
    fmi3SetUInt16(*const u16);
    fmi3SetUInt32(*const u32);
    fmi3SetUInt64(*const u64);
    fmi3SetString(*const fmi3String);
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    nvr: usize,
    _value_sizes: *mut usize,
    _values: *mut *const u8,
    _n_values: usize,
) -> fmi3Status {
    unsafe { no_such_type(instance, "fmi3GetBinary", nvr) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    nvr: usize,
    _value_sizes: *const usize,
    _values: *const *const u8,
    _n_values: usize,
) -> fmi3Status {
    unsafe { no_such_type(instance, "fmi3SetBinary", nvr) }
}

const NO_CLOCKS: &str = "the models have no clocks";

#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _values: *mut fmi3Boolean,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3GetClock", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _values: *const fmi3Boolean,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3SetClock", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalDecimal(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _intervals: *mut f64,
    _qualifiers: *mut c_int,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3GetIntervalDecimal", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalFraction(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _counters: *mut u64,
    _resolutions: *mut u64,
    _qualifiers: *mut c_int,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3GetIntervalFraction", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftDecimal(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _shifts: *mut f64,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3GetShiftDecimal", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftFraction(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _counters: *mut u64,
    _resolutions: *mut u64,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3GetShiftFraction", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalDecimal(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _intervals: *const f64,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3SetIntervalDecimal", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalFraction(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _counters: *const u64,
    _resolutions: *const u64,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3SetIntervalFraction", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftDecimal(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _shifts: *const f64,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3SetShiftDecimal", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftFraction(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _counters: *const u64,
    _resolutions: *const u64,
) -> fmi3Status {
    unsafe { refuse(instance, "fmi3SetShiftFraction", NO_CLOCKS) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ActivateModelPartition(
    instance: fmi3Instance,
    _clock_reference: fmi3ValueReference,
    _activation_time: f64,
) -> fmi3Status {
    unsafe {
        refuse(
            instance,
            "fmi3ActivateModelPartition",
            "Scheduled Execution is not supported",
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    unsafe {
        refuse(
            instance,
            "fmi3EnterConfigurationMode",
            "the models have no structural parameters",
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    unsafe {
        refuse(
            instance,
            "fmi3ExitConfigurationMode",
            "the models have no structural parameters",
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(instance: fmi3Instance) -> fmi3Status {
    unsafe {
        refuse(
            instance,
            "fmi3EvaluateDiscreteStates",
            "providesEvaluateDiscreteStates is false",
        )
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    _vr: *const fmi3ValueReference,
    _nvr: usize,
    _orders: *const i32,
    _values: *mut f64,
    _n_values: usize,
) -> fmi3Status {
    unsafe {
        refuse(
            instance,
            "fmi3GetOutputDerivatives",
            "maxOutputDerivativeOrder is 0",
        )
    }
}
