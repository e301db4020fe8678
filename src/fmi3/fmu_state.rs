//! FMU states through FMI 3.0: the shared instance's states and their checked serialization.

use super::exports::Status;
use super::{fmi3FMUState, fmi3Instance, fmi3Status};
use crate::fmi2::exports::{guarded, null_argument, slice, slice_mut};
use crate::fmi2::instance::FmuState;

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    state: *mut fmi3FMUState,
) -> fmi3Status {
    const F: &str = "fmi3GetFMUState";
    unsafe {
        guarded(instance, F, |inst| {
            let Some(slot) = state.as_mut() else {
                return null_argument(inst, F, "FMUState");
            };
            match inst.get_fmu_state(*slot as *mut FmuState) {
                Ok(ptr) => {
                    *slot = ptr as fmi3FMUState;
                    Status::OK
                }
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    state: fmi3FMUState,
) -> fmi3Status {
    unsafe {
        guarded(instance, "fmi3SetFMUState", |inst| {
            inst.set_fmu_state(state as *mut FmuState)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    state: *mut fmi3FMUState,
) -> fmi3Status {
    const F: &str = "fmi3FreeFMUState";
    unsafe {
        guarded(instance, F, |inst| {
            let Some(slot) = state.as_mut() else {
                return null_argument(inst, F, "FMUState");
            };
            let status = inst.free_fmu_state(*slot as *mut FmuState);
            if status == Status::OK {
                *slot = std::ptr::null_mut();
            }
            status
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    state: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    const F: &str = "fmi3SerializedFMUStateSize";
    unsafe {
        guarded(instance, F, |inst| {
            let Some(size) = size.as_mut() else {
                return null_argument(inst, F, "size");
            };
            match inst.serialize_fmu_state(F, state as *mut FmuState) {
                Ok(bytes) => {
                    *size = bytes.len();
                    Status::OK
                }
                Err(status) => status,
            }
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    state: fmi3FMUState,
    bytes: *mut u8,
    size: usize,
) -> fmi3Status {
    const F: &str = "fmi3SerializeFMUState";
    unsafe {
        guarded(instance, F, |inst| {
            let Some(out) = slice_mut(bytes, size) else {
                return null_argument(inst, F, "serializedState");
            };
            match inst.serialize_fmu_state(F, state as *mut FmuState) {
                Ok(data) if data.len() <= out.len() => {
                    out[..data.len()].copy_from_slice(&data);
                    Status::OK
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
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    bytes: *const u8,
    size: usize,
    state: *mut fmi3FMUState,
) -> fmi3Status {
    const F: &str = "fmi3DeserializeFMUState";
    unsafe {
        guarded(instance, F, |inst| {
            let (Some(data), Some(slot)) = (slice(bytes, size), state.as_mut()) else {
                return null_argument(inst, F, "serializedState and FMUState");
            };
            match inst.deserialize_fmu_state(data, *slot as *mut FmuState) {
                Ok(ptr) => {
                    *slot = ptr as fmi3FMUState;
                    Status::OK
                }
                Err(status) => status,
            }
        })
    }
}
