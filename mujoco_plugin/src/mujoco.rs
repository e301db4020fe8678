//! The MuJoCo C API the plugin uses: a few functions, and the mjModel/mjData fields at the
//! offsets of [`crate::layout`] (checked against the headers at build time).

use crate::layout::{data, model, MjData, MjModel, MjpPlugin};
use std::ffi::{c_char, CStr};

extern "C" {
    pub fn mj_version() -> i32;
    pub fn mjp_defaultPlugin(plugin: *mut MjpPlugin);
    pub fn mjp_registerPlugin(plugin: *const MjpPlugin) -> i32;
    pub fn mj_getPluginConfig(
        m: *const MjModel,
        plugin_id: i32,
        attrib: *const c_char,
    ) -> *const c_char;
    pub fn mj_id2name(m: *const MjModel, kind: i32, id: i32) -> *const c_char;
}

extern "C-unwind" {
    /// src/shim.c: `mju_error("%s", message)`. MuJoCo's handler may unwind or longjmp.
    fn actuator_fmus_mujoco_error(message: *const c_char);
    /// src/shim.c: `mju_warning("%s", message)`.
    pub fn actuator_fmus_mujoco_warning(message: *const c_char);
}

/// Raises a MuJoCo error with the NUL-terminated `message`.
///
/// # Safety
/// The caller's frame must own nothing that needs dropping: MuJoCo's error handler may leave it
/// by unwinding (Python's bindings throw) or by longjmp.
pub unsafe fn raise(message: &[u8; MESSAGE_BYTES]) {
    actuator_fmus_mujoco_error(message.as_ptr().cast());
}

/// Longest error message, NUL included.
pub const MESSAGE_BYTES: usize = 2048;

/// `text` as a NUL-terminated fixed buffer (nothing to drop), cut at a character boundary.
pub fn message(text: &str) -> [u8; MESSAGE_BYTES] {
    let mut out = [0u8; MESSAGE_BYTES];
    let mut end = text.len().min(MESSAGE_BYTES - 1);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    out[..end].copy_from_slice(&text.as_bytes()[..end]);
    for b in &mut out[..end] {
        if *b == 0 {
            *b = b' ';
        }
    }
    out
}

unsafe fn at<T: Copy>(base: *const u8, offset: usize) -> T {
    base.add(offset).cast::<T>().read()
}

/// The configuration attribute `key` of plugin instance `instance` ("" when absent).
///
/// # Safety
/// `m` is a live model.
pub unsafe fn config(m: *const MjModel, instance: i32, key: &CStr) -> String {
    let value = mj_getPluginConfig(m, instance, key.as_ptr());
    if value.is_null() {
        String::new()
    } else {
        CStr::from_ptr(value).to_string_lossy().into_owned()
    }
}

/// The accessors below read or point into live MuJoCo structures.
///
/// # Safety (all)
/// `m` and `d` are a live model and a data made for it; indices are in range.
pub unsafe fn nu(m: *const MjModel) -> usize {
    at::<i32>(m.cast(), model::NU).max(0) as usize
}

pub unsafe fn timestep(m: *const MjModel) -> f64 {
    at(m.cast(), model::OPT_TIMESTEP)
}

pub unsafe fn actuator_plugin(m: *const MjModel, actuator: usize) -> i32 {
    *at::<*const i32>(m.cast(), model::ACTUATOR_PLUGIN).add(actuator)
}

/// `Some((lo, hi))` when the actuator's control is limited.
pub unsafe fn ctrl_range(m: *const MjModel, actuator: usize) -> Option<(f64, f64)> {
    let limited = *at::<*const u8>(m.cast(), model::ACTUATOR_CTRLLIMITED).add(actuator);
    let range = at::<*const f64>(m.cast(), model::ACTUATOR_CTRLRANGE).add(2 * actuator);
    (limited != 0).then(|| (*range, *range.add(1)))
}

/// `(plugin_stateadr, plugin_statenum)` of an instance.
pub unsafe fn state_span(m: *const MjModel, instance: i32) -> (usize, usize) {
    let i = instance as usize;
    let adr = *at::<*const i32>(m.cast(), model::PLUGIN_STATEADR).add(i);
    let num = *at::<*const i32>(m.cast(), model::PLUGIN_STATENUM).add(i);
    (adr.max(0) as usize, num.max(0) as usize)
}

pub unsafe fn plugin_state(d: *mut MjData) -> *mut f64 {
    at(d.cast_const().cast(), data::PLUGIN_STATE)
}

pub unsafe fn plugin_data(d: *const MjData) -> *mut usize {
    at(d.cast(), data::PLUGIN_DATA)
}

pub unsafe fn ctrl(d: *const MjData, actuator: usize) -> f64 {
    *at::<*const f64>(d.cast(), data::CTRL).add(actuator)
}

pub unsafe fn actuator_length(d: *const MjData, actuator: usize) -> f64 {
    *at::<*const f64>(d.cast(), data::ACTUATOR_LENGTH).add(actuator)
}

pub unsafe fn actuator_velocity(d: *const MjData, actuator: usize) -> f64 {
    *at::<*const f64>(d.cast(), data::ACTUATOR_VELOCITY).add(actuator)
}

pub unsafe fn set_actuator_force(d: *mut MjData, actuator: usize, force: f64) {
    *at::<*mut f64>(d.cast_const().cast(), data::ACTUATOR_FORCE).add(actuator) = force;
}
