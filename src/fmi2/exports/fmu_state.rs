//! The FMU-state functions: get, set, free, serialize and deserialize.

use super::guarded;
use crate::export::guard::{null_argument, slice, slice_mut};
use crate::export::instance::FmuState;
use crate::fmi2::types::*;

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    const F: &str = "fmi2GetFMUstate";
    unsafe {
        guarded(c, F, |inst| {
            let Some(slot) = state.as_mut() else {
                return null_argument(inst, F, "FMUstate");
            };
            match inst.get_fmu_state(F, *slot as *mut FmuState) {
                Ok(ptr) => {
                    *slot = ptr as fmi2FMUstate;
                    fmi2Status::OK
                }
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    const F: &str = "fmi2SetFMUstate";
    unsafe { guarded(c, F, |inst| inst.set_fmu_state(F, state as *mut FmuState)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2FreeFMUstate";
    unsafe {
        guarded(c, F, |inst| {
            let Some(slot) = state.as_mut() else {
                return null_argument(inst, F, "FMUstate");
            };
            let status = inst.free_fmu_state(F, *slot as *mut FmuState);
            if status == fmi2Status::OK {
                *slot = std::ptr::null_mut();
            }
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializedFMUstateSize";
    unsafe {
        guarded(c, F, |inst| {
            let Some(size) = size.as_mut() else {
                return null_argument(inst, F, "size");
            };
            match inst.serialize_fmu_state(F, state as *mut FmuState) {
                Ok(bytes) => {
                    *size = bytes.len();
                    fmi2Status::OK
                }
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializeFMUstate";
    unsafe {
        guarded(c, F, |inst| {
            let Some(out) = slice_mut(bytes as *mut u8, size) else {
                return null_argument(inst, F, "serializedState");
            };
            match inst.serialize_fmu_state(F, state as *mut FmuState) {
                Ok(data) if data.len() <= out.len() => {
                    out[..data.len()].copy_from_slice(&data);
                    fmi2Status::OK
                }
                Ok(data) => inst.error(&format!(
                    "{F}: size {size} is too small, the state needs {} bytes",
                    data.len()
                )),
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2DeSerializeFMUstate";
    unsafe {
        guarded(c, F, |inst| {
            let (Some(data), Some(slot)) = (slice(bytes as *const u8, size), state.as_mut()) else {
                return null_argument(inst, F, "serializedState and FMUstate");
            };
            match inst.deserialize_fmu_state(F, data, *slot as *mut FmuState) {
                Ok(ptr) => {
                    *slot = ptr as fmi2FMUstate;
                    fmi2Status::OK
                }
                Err(status) => status,
            }
        })
    }
}
