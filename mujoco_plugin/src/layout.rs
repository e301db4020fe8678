// Byte offsets of the few mjModel and mjData fields the plugin touches, and the plugin
// descriptor, for MuJoCo 4.0.0 (`mjVERSION_HEADER` 4000000). build.rs includes this file and
// compiles every number as a C `_Static_assert` against the wheel's headers: a MuJoCo whose layout
// differs fails the build instead of corrupting memory.

/// `mjVERSION_HEADER` these offsets were read from; `mj_version()` must return it.
pub const MUJOCO_VERSION: i32 = 4_000_000;

/// Offsets in `mjModel`.
pub mod model {
    pub const NU: usize = 16;
    pub const OPT_TIMESTEP: usize = 792;
    pub const ACTUATOR_PLUGIN: usize = 4984;
    pub const ACTUATOR_CTRLLIMITED: usize = 5008;
    pub const ACTUATOR_CTRLRANGE: usize = 5016;
    pub const PLUGIN_STATEADR: usize = 5208;
    pub const PLUGIN_STATENUM: usize = 5216;
}

/// Offsets in `mjData`.
pub mod data {
    pub const PLUGIN_STATE: usize = 160_736;
    pub const CTRL: usize = 160_744;
    pub const PLUGIN_DATA: usize = 160_840;
    pub const ACTUATOR_LENGTH: usize = 161_152;
    pub const ACTUATOR_VELOCITY: usize = 161_288;
    pub const ACTUATOR_FORCE: usize = 161_416;
}

/// `(struct, field, offset)` for each constant above, as build.rs checks them.
#[allow(dead_code)] // read by build.rs
pub const CHECKED_OFFSETS: &[(&str, &str, usize)] = &[
    ("mjModel", "nu", model::NU),
    ("mjModel", "opt.timestep", model::OPT_TIMESTEP),
    ("mjModel", "actuator_plugin", model::ACTUATOR_PLUGIN),
    (
        "mjModel",
        "actuator_ctrllimited",
        model::ACTUATOR_CTRLLIMITED,
    ),
    ("mjModel", "actuator_ctrlrange", model::ACTUATOR_CTRLRANGE),
    ("mjModel", "plugin_stateadr", model::PLUGIN_STATEADR),
    ("mjModel", "plugin_statenum", model::PLUGIN_STATENUM),
    ("mjData", "plugin_state", data::PLUGIN_STATE),
    ("mjData", "ctrl", data::CTRL),
    ("mjData", "plugin_data", data::PLUGIN_DATA),
    ("mjData", "actuator_length", data::ACTUATOR_LENGTH),
    ("mjData", "actuator_velocity", data::ACTUATOR_VELOCITY),
    ("mjData", "actuator_force", data::ACTUATOR_FORCE),
];

/// `mjPLUGIN_ACTUATOR`.
pub const PLUGIN_ACTUATOR: i32 = 1;
/// `mjOBJ_ACTUATOR`.
pub const OBJ_ACTUATOR: i32 = 19;

/// `mjpPlugin`, field for field (mjplugin.h). Callbacks we do not provide stay `None`.
#[repr(C)]
pub struct MjpPlugin {
    pub name: *const core::ffi::c_char,
    pub nattribute: i32,
    pub attributes: *const *const core::ffi::c_char,
    pub capabilityflags: i32,
    pub needstage: i32,
    pub nstate: Option<unsafe extern "C-unwind" fn(*const MjModel, i32) -> i32>,
    pub nsensordata: Option<unsafe extern "C-unwind" fn(*const MjModel, i32, i32) -> i32>,
    pub init: Option<unsafe extern "C-unwind" fn(*const MjModel, *mut MjData, i32) -> i32>,
    pub destroy: Option<unsafe extern "C-unwind" fn(*mut MjData, i32)>,
    pub copy: Option<unsafe extern "C-unwind" fn(*mut MjData, *const MjModel, *const MjData, i32)>,
    pub reset:
        Option<unsafe extern "C-unwind" fn(*const MjModel, *mut f64, *mut core::ffi::c_void, i32)>,
    pub compute: Option<unsafe extern "C-unwind" fn(*const MjModel, *mut MjData, i32, i32)>,
    pub advance: Option<unsafe extern "C-unwind" fn(*const MjModel, *mut MjData, i32)>,
    pub visualize: Option<unsafe extern "C" fn()>,
    pub actuator_act_dot: Option<unsafe extern "C" fn()>,
    pub sdf_distance: Option<unsafe extern "C" fn()>,
    pub sdf_gradient: Option<unsafe extern "C" fn()>,
    pub sdf_staticdistance: Option<unsafe extern "C" fn()>,
    pub sdf_attribute: Option<unsafe extern "C" fn()>,
    pub sdf_aabb: Option<unsafe extern "C" fn()>,
}

/// `(field, offset)` of MjpPlugin checked against `offsetof(mjpPlugin, field)`.
#[allow(dead_code)] // read by build.rs
pub fn plugin_offsets() -> [(&'static str, usize); 6] {
    [
        ("nstate", core::mem::offset_of!(MjpPlugin, nstate)),
        ("init", core::mem::offset_of!(MjpPlugin, init)),
        ("reset", core::mem::offset_of!(MjpPlugin, reset)),
        ("compute", core::mem::offset_of!(MjpPlugin, compute)),
        ("advance", core::mem::offset_of!(MjpPlugin, advance)),
        ("sdf_aabb", core::mem::offset_of!(MjpPlugin, sdf_aabb)),
    ]
}

/// Opaque `mjModel`: read only through the offsets above.
#[repr(C)]
pub struct MjModel {
    _opaque: [u8; 0],
}

/// Opaque `mjData`: read and written only through the offsets above.
#[repr(C)]
pub struct MjData {
    _opaque: [u8; 0],
}
