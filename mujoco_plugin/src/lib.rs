//! MuJoCo actuator plugin `actuator_fmus.fmu`: each actuator that names it runs its own instance
//! of an FMI 2.0 Co-Simulation FMU. Loaded with `mujoco.mj_loadPluginLibrary(path)`; configured
//! in MJCF (docs/mujoco.md):
//!
//! ```xml
//! <extension><plugin plugin="actuator_fmus.fmu"/></extension>
//! <actuator>
//!   <plugin name="flexor" plugin="actuator_fmus.fmu" tendon="flexor" ctrllimited="true"
//!           ctrlrange="0 600000">
//!     <config key="fmu" value="target/fmu/McKibbenMuscle.fmu"/>
//!     <config key="parameters" value="preset=DMSP-10 friction=true"/>
//!     <config key="length_input" value="length"/>
//!     <config key="ctrl_input" value="pressure"/>
//!   </plugin>
//! </actuator>
//! ```
//!
//! Per step: `compute` sets the inputs (actuator length, velocity, control) and writes
//! `force_scale * output` to `actuator_force` without changing the FMU's history; `advance`
//! (after MuJoCo integrates) calls fmi2DoStep over `opt.timestep` with the same inputs and saves the
//! FMU state into `plugin_state` (src/actuator.rs). Every failure is a MuJoCo error naming the
//! actuator and the cause; no panic crosses into MuJoCo.

mod actuator;
mod config;
mod fmu;
mod layout;
mod model_description;
mod mujoco;

use actuator::Actuator;
use config::{Config, ATTRIBUTES};
use layout::{MjData, MjModel, MjpPlugin, MUJOCO_VERSION, PLUGIN_ACTUATOR};
use mujoco as mj;
use std::ffi::{c_char, c_void, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The name MJCF uses: `<plugin plugin="actuator_fmus.fmu" .../>`.
pub const PLUGIN_NAME: &str = "actuator_fmus.fmu";

/// Runs `body` for plugin instance `instance`; a returned error or a panic becomes a message for
/// MuJoCo. The result holds nothing to drop, so the caller can raise it from a frame MuJoCo's
/// handler may leave abruptly (hence the fixed-size error). Nothing is allocated unless something
/// failed.
#[allow(clippy::result_large_err)]
fn guarded<T>(
    instance: i32,
    body: impl FnOnce() -> Result<T, String>,
) -> Result<T, [u8; mj::MESSAGE_BYTES]> {
    let outcome = catch_unwind(AssertUnwindSafe(body));
    let text = match outcome {
        Ok(Ok(value)) => return Ok(value),
        Ok(Err(reason)) => format!("{PLUGIN_NAME}: plugin instance {instance}: {reason}"),
        Err(panic) => {
            let detail = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            format!("{PLUGIN_NAME}: plugin instance {instance}: internal error (panic: {detail})")
        }
    };
    Err(mj::message(&text))
}

unsafe fn read_config(m: *const MjModel, instance: i32) -> Result<Config, String> {
    Config::new(|key| {
        let key = CString::new(key).unwrap_or_default();
        // SAFETY: `m` is live for the callback.
        unsafe { mj::config(m, instance, &key) }
    })
}

unsafe fn actuator<'a>(d: *mut MjData, instance: i32) -> Result<&'a mut Actuator, String> {
    let ptr = *mj::plugin_data(d).add(instance as usize) as *mut Actuator;
    ptr.as_mut()
        .ok_or_else(|| "the plugin instance was not initialized".to_string())
}

unsafe extern "C-unwind" fn nstate(m: *const MjModel, instance: i32) -> i32 {
    let words = guarded(instance, || {
        let config = read_config(m, instance)?;
        let words = Actuator::probe_state_words(&config)?;
        i32::try_from(words).map_err(|_| "state too large".to_string())
    });
    match words {
        Ok(words) => words,
        Err(message) => {
            mj::raise(&message);
            0
        }
    }
}

unsafe extern "C-unwind" fn init(m: *const MjModel, d: *mut MjData, instance: i32) -> i32 {
    let made = guarded(instance, || {
        let config = read_config(m, instance)?;
        let actuator = Actuator::new(m, instance, config)?;
        let (adr, words) = mj::state_span(m, instance);
        // A fresh mjData: the FMU starts at rest at the first evaluated inputs.
        std::slice::from_raw_parts_mut(mj::plugin_state(d).add(adr), words).fill(0.0);
        *mj::plugin_data(d).add(instance as usize) = Box::into_raw(Box::new(actuator)) as usize;
        Ok(())
    });
    match made {
        Ok(()) => 0,
        Err(message) => {
            mj::raise(&message);
            -1
        }
    }
}

unsafe extern "C-unwind" fn destroy(d: *mut MjData, instance: i32) {
    // Dropping frees the FMU instance; nothing here can fail, a panic is contained.
    let _ = catch_unwind(|| {
        // SAFETY: plugin_data holds null or a Box this plugin made in `init` or `copy`.
        let slot = unsafe { mj::plugin_data(d).add(instance as usize) };
        let ptr = unsafe { *slot } as *mut Actuator;
        if !ptr.is_null() {
            drop(unsafe { Box::from_raw(ptr) });
        }
        unsafe { *slot = 0 };
    });
}

unsafe extern "C-unwind" fn copy(
    dest: *mut MjData,
    m: *const MjModel,
    src: *const MjData,
    instance: i32,
) {
    let done = guarded(instance, || {
        let slot = mj::plugin_data(dest).add(instance as usize);
        if (*slot as *mut Actuator).is_null() {
            let actuator = Actuator::new(m, instance, read_config(m, instance)?)?;
            *slot = Box::into_raw(Box::new(actuator)) as usize;
        }
        let copy = &mut *(*slot as *mut Actuator);
        // MuJoCo copied plugin_state; the copy continues from it, or from the source's FMU when
        // the history stays in the FMU (history="fmu").
        copy.resync();
        let source = *mj::plugin_data(src).add(instance as usize) as *mut Actuator;
        if let Some(source) = source.as_mut().filter(|s| !std::ptr::eq(*s, copy)) {
            copy.adopt(m, dest, source)?;
        }
        Ok(())
    });
    if let Err(message) = done {
        mj::raise(&message);
    }
}

unsafe extern "C-unwind" fn reset(
    m: *const MjModel,
    plugin_state: *mut f64,
    _plugin_data: *mut c_void,
    instance: i32,
) {
    // `started = 0`: the next evaluation initializes the FMU at rest (src/actuator.rs).
    let _ = catch_unwind(|| {
        // SAFETY: MuJoCo passes this instance's slice of plugin_state.
        let words = unsafe { mj::state_span(m, instance).1 };
        if !plugin_state.is_null() {
            unsafe { std::slice::from_raw_parts_mut(plugin_state, words) }.fill(0.0);
        }
    });
}

/// Which callback failed, for the message.
#[derive(Clone, Copy)]
enum Phase {
    Compute,
    Advance,
}

unsafe fn run(m: *const MjModel, d: *mut MjData, instance: i32, phase: Phase) {
    let done = guarded(instance, || {
        let actuator = actuator(d, instance)?;
        let result = match phase {
            Phase::Compute => actuator.compute(m, d),
            Phase::Advance => actuator.advance(m, d),
        };
        result.map_err(|e| format!("actuator '{}': {e}", actuator.name))
    });
    if let Err(message) = done {
        // Not a silent zero: if the host's error handler returns, the force is NaN, which MuJoCo
        // reports (mjWARN_BADQACC) rather than simulating on.
        if let Ok(a) = actuator(d, instance) {
            mj::set_actuator_force(d, a.id, f64::NAN);
        }
        mj::raise(&message);
    }
}

unsafe extern "C-unwind" fn compute(
    m: *const MjModel,
    d: *mut MjData,
    instance: i32,
    _capability: i32,
) {
    run(m, d, instance, Phase::Compute);
}

unsafe extern "C-unwind" fn advance(m: *const MjModel, d: *mut MjData, instance: i32) {
    run(m, d, instance, Phase::Advance);
}

/// Static C strings for the plugin descriptor (MuJoCo keeps the pointers).
struct Names {
    name: CString,
    attributes: Vec<CString>,
    pointers: Vec<*const c_char>,
}

// SAFETY: written once at registration, then only read.
unsafe impl Sync for Names {}
unsafe impl Send for Names {}

static NAMES: std::sync::OnceLock<Names> = std::sync::OnceLock::new();

fn register() -> Result<(), String> {
    // SAFETY: plain query.
    let version = unsafe { mj::mj_version() };
    if version != MUJOCO_VERSION {
        return Err(format!(
            "built for MuJoCo {MUJOCO_VERSION} but loaded into {version}: rebuild the plugin \
             (make mujoco-plugin) against this MuJoCo"
        ));
    }
    let names = NAMES.get_or_init(|| {
        let attributes: Vec<CString> = ATTRIBUTES
            .iter()
            .map(|a| CString::new(*a).unwrap_or_default())
            .collect();
        let pointers = attributes.iter().map(|a| a.as_ptr()).collect();
        Names {
            name: CString::new(PLUGIN_NAME).unwrap_or_default(),
            attributes,
            pointers,
        }
    });
    debug_assert_eq!(names.attributes.len(), names.pointers.len());
    let mut plugin = std::mem::MaybeUninit::<MjpPlugin>::zeroed();
    // SAFETY: mjp_defaultPlugin fills the whole descriptor; the names live for the process.
    unsafe {
        mj::mjp_defaultPlugin(plugin.as_mut_ptr());
        let mut plugin = plugin.assume_init();
        plugin.name = names.name.as_ptr();
        plugin.nattribute = names.pointers.len() as i32;
        plugin.attributes = names.pointers.as_ptr();
        plugin.capabilityflags |= PLUGIN_ACTUATOR;
        plugin.nstate = Some(nstate);
        plugin.init = Some(init);
        plugin.destroy = Some(destroy);
        plugin.copy = Some(copy);
        plugin.reset = Some(reset);
        plugin.compute = Some(compute);
        plugin.advance = Some(advance);
        mj::mjp_registerPlugin(&plugin);
    }
    Ok(())
}

/// Runs when the library is loaded (mj_loadPluginLibrary): registers the plugin with MuJoCo.
extern "C" fn on_load() {
    let outcome = catch_unwind(register);
    let problem = match outcome {
        Ok(Ok(())) => return,
        Ok(Err(reason)) => reason,
        Err(_) => "internal error while registering".to_string(),
    };
    let text = mj::message(&format!("{PLUGIN_NAME} not registered: {problem}"));
    // SAFETY: a NUL-terminated buffer; mju_warning returns.
    unsafe { mj::actuator_fmus_mujoco_warning(text.as_ptr().cast()) };
}

#[used]
#[cfg_attr(target_os = "linux", link_section = ".init_array")]
#[cfg_attr(target_os = "macos", link_section = "__DATA,__mod_init_func")]
#[cfg_attr(target_os = "windows", link_section = ".CRT$XCU")]
static ON_LOAD: extern "C" fn() = on_load;
