//! An FMI 2.0 Co-Simulation FMU loaded through its C ABI: the archive unpacked once per content
//! into a cache directory, `modelDescription.xml` read, the binary opened and its functions
//! resolved, and one [`Instance`] per actuator.

pub use crate::model_description::{Kind, ModelDescription, Variable};
use std::collections::HashMap;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// fmi2Status values.
const OK: c_int = 0;
const WARNING: c_int = 1;
const STATUS_NAMES: [&str; 6] = [
    "fmi2OK",
    "fmi2Warning",
    "fmi2Discard",
    "fmi2Error",
    "fmi2Fatal",
    "fmi2Pending",
];

fn status_name(status: c_int) -> &'static str {
    usize::try_from(status)
        .ok()
        .and_then(|i| STATUS_NAMES.get(i))
        .copied()
        .unwrap_or("an unknown fmi2Status")
}

/// fmi2CallbackFunctions.
#[repr(C)]
struct CallbackFunctions {
    logger: unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char),
    allocate_memory: unsafe extern "C" fn(usize, usize) -> *mut c_void,
    free_memory: unsafe extern "C" fn(*mut c_void),
    step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    component_environment: *mut c_void,
}

extern "C" {
    fn calloc(count: usize, size: usize) -> *mut c_void;
    fn free(ptr: *mut c_void);
    /// src/shim.c: formats the message and calls [`actuator_fmus_mujoco_log`].
    fn actuator_fmus_mujoco_fmi2_logger(
        environment: *mut c_void,
        instance_name: *const c_char,
        status: c_int,
        category: *const c_char,
        message: *const c_char,
    );
}

/// The FMU's messages of one instance, kept for the error that names the cause.
#[derive(Default)]
pub struct Log {
    messages: Mutex<Vec<String>>,
}

impl Log {
    fn take(&self) -> String {
        let mut messages = self.messages.lock().unwrap_or_else(|e| e.into_inner());
        // The newest message (the failing call's) first, then the earlier ones from the oldest,
        // which tends to explain the cause (an excursion is explained once, when it begins).
        let mut parts: Vec<String> = messages.last().cloned().into_iter().collect();
        for earlier in messages.iter().take(messages.len().saturating_sub(1)) {
            let cut = earlier
                .char_indices()
                .nth(400)
                .map_or(earlier.as_str(), |(i, _)| &earlier[..i]);
            parts.push(cut.to_string());
        }
        let text = parts.join("; earlier: ");
        messages.clear();
        text
    }
}

/// Called by the C shim with a formatted message; `environment` is the instance's [`Log`].
///
/// # Safety
/// `environment` is null or a live `Log`; `category` and `message` are NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn actuator_fmus_mujoco_log(
    environment: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    let _ = std::panic::catch_unwind(|| {
        if environment.is_null() || message.is_null() {
            return;
        }
        // SAFETY: see the function's contract.
        let log = unsafe { &*(environment as *const Log) };
        let text = unsafe { CStr::from_ptr(message) }.to_string_lossy();
        let category = if category.is_null() {
            String::new()
        } else {
            unsafe { CStr::from_ptr(category) }
                .to_string_lossy()
                .into_owned()
        };
        let mut messages = log.messages.lock().unwrap_or_else(|e| e.into_inner());
        // Bounded: only the latest messages matter for an error.
        if messages.len() >= 8 {
            messages.remove(0);
        }
        messages.push(format!("[{} {category}] {text}", status_name(status)));
    });
}

type Component = *mut c_void;
type State = *mut c_void;

/// The fmi2 functions the plugin calls, resolved once per binary.
struct Functions {
    instantiate: unsafe extern "C" fn(
        *const c_char,
        c_int,
        *const c_char,
        *const c_char,
        *const CallbackFunctions,
        c_int,
        c_int,
    ) -> Component,
    free_instance: unsafe extern "C" fn(Component),
    reset: unsafe extern "C" fn(Component) -> c_int,
    setup_experiment: unsafe extern "C" fn(Component, c_int, f64, f64, c_int, f64) -> c_int,
    enter_initialization_mode: unsafe extern "C" fn(Component) -> c_int,
    exit_initialization_mode: unsafe extern "C" fn(Component) -> c_int,
    set_real: unsafe extern "C" fn(Component, *const u32, usize, *const f64) -> c_int,
    set_integer: unsafe extern "C" fn(Component, *const u32, usize, *const c_int) -> c_int,
    set_boolean: unsafe extern "C" fn(Component, *const u32, usize, *const c_int) -> c_int,
    set_string: unsafe extern "C" fn(Component, *const u32, usize, *const *const c_char) -> c_int,
    get_real: unsafe extern "C" fn(Component, *const u32, usize, *mut f64) -> c_int,
    do_step: unsafe extern "C" fn(Component, f64, f64, c_int) -> c_int,
    get_fmu_state: unsafe extern "C" fn(Component, *mut State) -> c_int,
    set_fmu_state: unsafe extern "C" fn(Component, State) -> c_int,
    free_fmu_state: unsafe extern "C" fn(Component, *mut State) -> c_int,
    serialized_size: unsafe extern "C" fn(Component, State, *mut usize) -> c_int,
    serialize: unsafe extern "C" fn(Component, State, *mut u8, usize) -> c_int,
    deserialize: unsafe extern "C" fn(Component, *const u8, usize, *mut State) -> c_int,
}

/// One FMU file, unpacked and its binary loaded (never unloaded: the binary may register
/// thread-local destructors, rust-lang/rust#91979).
pub struct Fmu {
    pub md: ModelDescription,
    resource_uri: CString,
    guid: CString,
    functions: Functions,
    _library: libloading::Library,
}

#[cfg(all(target_os = "linux", target_arch = "x86_64"))]
const PLATFORM: (&str, &str) = ("linux64", "so");
#[cfg(all(target_os = "linux", target_arch = "aarch64"))]
const PLATFORM: (&str, &str) = ("aarch64-linux", "so");
#[cfg(target_os = "windows")]
const PLATFORM: (&str, &str) = ("win64", "dll");
#[cfg(target_os = "macos")]
const PLATFORM: (&str, &str) = ("darwin64", "dylib");

/// FNV-1a over the archive: names its cache directory, so that a rebuilt FMU is unpacked anew.
fn fingerprint(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Unpacks `archive` into `<temp>/actuator-fmus-mujoco/<fingerprint>/` unless already there. A
/// directory appears only complete (unpacked beside it, then renamed), so processes can share it.
fn unpack(path: &Path, bytes: &[u8]) -> Result<PathBuf, String> {
    let root = std::env::temp_dir().join("actuator-fmus-mujoco");
    let dir = root.join(format!("{:016x}", fingerprint(bytes)));
    if dir.join("modelDescription.xml").exists() {
        return Ok(dir);
    }
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let scratch = root.join(format!(".unpack-{}-{nanos}", std::process::id()));
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| format!("{} is not an FMU (zip archive): {e}", path.display()))?;
    zip.extract(&scratch).map_err(|e| {
        format!(
            "cannot unpack {} into {}: {e}",
            path.display(),
            scratch.display()
        )
    })?;
    if std::fs::rename(&scratch, &dir).is_err() {
        // Another process won the race; its copy is identical.
        let _ = std::fs::remove_dir_all(&scratch);
        if !dir.join("modelDescription.xml").exists() {
            return Err(format!(
                "cannot unpack {} into {}",
                path.display(),
                dir.display()
            ));
        }
    }
    Ok(dir)
}

/// Loads `path` (cached per process and content: every actuator on the same FMU shares one).
pub fn load(path: &str) -> Result<Arc<Fmu>, String> {
    static CACHE: OnceLock<Mutex<HashMap<u64, Arc<Fmu>>>> = OnceLock::new();
    if path.is_empty() {
        return Err("no FMU given (attribute 'fmu')".into());
    }
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read FMU '{path}': {e}"))?;
    let key = fingerprint(&bytes);
    let cache = CACHE.get_or_init(Default::default);
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(fmu) = cache.get(&key) {
        return Ok(fmu.clone());
    }
    let fmu = Arc::new(open(Path::new(path), &bytes)?);
    cache.insert(key, fmu.clone());
    Ok(fmu)
}

fn open(path: &Path, bytes: &[u8]) -> Result<Fmu, String> {
    let dir = unpack(path, bytes)?;
    let xml = std::fs::read_to_string(dir.join("modelDescription.xml"))
        .map_err(|e| format!("{}: no modelDescription.xml ({e})", path.display()))?;
    let md = ModelDescription::parse(&xml).map_err(|e| format!("{}: {e}", path.display()))?;
    let (platform, extension) = PLATFORM;
    let binary = dir
        .join("binaries")
        .join(platform)
        .join(format!("{}.{extension}", md.model_identifier));
    // SAFETY: loading a library runs its initialisers; an FMU binary is code the user chose to run.
    let library = unsafe { libloading::Library::new(&binary) }
        .map_err(|e| format!("cannot load the FMU's binary {}: {e}", binary.display()))?;
    macro_rules! resolve {
        ($name:literal) => {
            // SAFETY: the fmi2 function types are fixed by the FMI 2.0 standard (fmi2Functions.h).
            *unsafe { library.get(concat!($name, "\0").as_bytes()) }
                .map_err(|e| format!("{}: the binary lacks {} ({e})", path.display(), $name))?
        };
    }
    let functions = Functions {
        instantiate: resolve!("fmi2Instantiate"),
        free_instance: resolve!("fmi2FreeInstance"),
        reset: resolve!("fmi2Reset"),
        setup_experiment: resolve!("fmi2SetupExperiment"),
        enter_initialization_mode: resolve!("fmi2EnterInitializationMode"),
        exit_initialization_mode: resolve!("fmi2ExitInitializationMode"),
        set_real: resolve!("fmi2SetReal"),
        set_integer: resolve!("fmi2SetInteger"),
        set_boolean: resolve!("fmi2SetBoolean"),
        set_string: resolve!("fmi2SetString"),
        get_real: resolve!("fmi2GetReal"),
        do_step: resolve!("fmi2DoStep"),
        get_fmu_state: resolve!("fmi2GetFMUstate"),
        set_fmu_state: resolve!("fmi2SetFMUstate"),
        free_fmu_state: resolve!("fmi2FreeFMUstate"),
        serialized_size: resolve!("fmi2SerializedFMUstateSize"),
        serialize: resolve!("fmi2SerializeFMUstate"),
        deserialize: resolve!("fmi2DeSerializeFMUstate"),
    };
    let resource_uri = format!("file://{}/resources", dir.display());
    Ok(Fmu {
        guid: CString::new(md.guid.clone()).map_err(|_| "GUID contains NUL".to_string())?,
        resource_uri: CString::new(resource_uri).map_err(|_| "path contains NUL".to_string())?,
        md,
        functions,
        _library: library,
    })
}

/// A start value for a parameter, typed as the FMU declares it.
#[derive(Clone, Debug)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(CString),
}

/// One FMU instance with its logger environment and a reusable FMU state.
pub struct Instance {
    fmu: Arc<Fmu>,
    component: Component,
    state: State,
    log: Box<Log>,
    _callbacks: Box<CallbackFunctions>,
    _name: CString,
}

// SAFETY: an FMI 2.0 instance may be called from any thread as long as calls do not overlap;
// MuJoCo calls one mjData's plugin callbacks from one thread at a time.
unsafe impl Send for Instance {}

impl Instance {
    pub fn new(fmu: Arc<Fmu>, name: &str) -> Result<Self, String> {
        let log = Box::<Log>::default();
        let callbacks = Box::new(CallbackFunctions {
            logger: actuator_fmus_mujoco_fmi2_logger,
            allocate_memory: calloc,
            free_memory: free,
            step_finished: None,
            component_environment: &*log as *const Log as *mut c_void,
        });
        let name = CString::new(name.replace('\0', " ")).unwrap_or_default();
        // SAFETY: every pointer is a live NUL-terminated string or the boxed callbacks, which the
        // instance owns until fmi2FreeInstance; 1 = fmi2CoSimulation.
        let component = unsafe {
            (fmu.functions.instantiate)(
                name.as_ptr(),
                1,
                fmu.guid.as_ptr(),
                fmu.resource_uri.as_ptr(),
                &*callbacks,
                0,
                0,
            )
        };
        if component.is_null() {
            return Err(format!("fmi2Instantiate failed: {}", log.take()));
        }
        Ok(Self {
            fmu,
            component,
            state: std::ptr::null_mut(),
            log,
            _callbacks: callbacks,
            _name: name,
        })
    }

    /// fmi2OK and fmi2Warning pass; anything else is an error naming the call and the FMU's
    /// log ([`Log::take`]).
    fn check(&self, call: &str, status: c_int) -> Result<(), String> {
        if status == OK || status == WARNING {
            return Ok(());
        }
        let log = self.log.take();
        Err(if log.is_empty() {
            format!("{call} returned {}", status_name(status))
        } else {
            format!("{call} returned {}: {log}", status_name(status))
        })
    }

    /// fmi2Reset, then setup at time 0 and initialization with `values` (parameters first, then
    /// inputs): the instance starts from rest at these inputs.
    pub fn initialize(&mut self, values: &[(&Variable, Value)], reset: bool) -> Result<(), String> {
        let f = &self.fmu.functions;
        // SAFETY: `component` is live until Drop.
        unsafe {
            if reset {
                self.check("fmi2Reset", (f.reset)(self.component))?;
            }
            self.check(
                "fmi2SetupExperiment",
                (f.setup_experiment)(self.component, 0, 0.0, 0.0, 0, 0.0),
            )?;
        }
        for (variable, value) in values {
            self.set(variable, value)
                .map_err(|e| format!("{} refused: {e}", variable.name))?;
        }
        // SAFETY: as above.
        unsafe {
            self.check(
                "fmi2EnterInitializationMode",
                (f.enter_initialization_mode)(self.component),
            )?;
            self.check(
                "fmi2ExitInitializationMode",
                (f.exit_initialization_mode)(self.component),
            )
        }
    }

    fn set(&self, variable: &Variable, value: &Value) -> Result<(), String> {
        let f = &self.fmu.functions;
        let vr = [variable.vr];
        // SAFETY: one value reference and one value, both on the stack.
        let status = unsafe {
            match value {
                Value::Real(x) => (f.set_real)(self.component, vr.as_ptr(), 1, x),
                Value::Integer(i) => (f.set_integer)(self.component, vr.as_ptr(), 1, i),
                Value::Boolean(b) => {
                    (f.set_boolean)(self.component, vr.as_ptr(), 1, &c_int::from(*b))
                }
                Value::String(s) => (f.set_string)(self.component, vr.as_ptr(), 1, &s.as_ptr()),
            }
        };
        self.check("fmi2Set", status)
    }

    pub fn set_reals(&self, vrs: &[u32], values: &[f64]) -> Result<(), String> {
        debug_assert_eq!(vrs.len(), values.len());
        // SAFETY: equal lengths.
        let status = unsafe {
            (self.fmu.functions.set_real)(self.component, vrs.as_ptr(), vrs.len(), values.as_ptr())
        };
        self.check("fmi2SetReal", status)
    }

    pub fn get_real(&self, vr: u32) -> Result<f64, String> {
        let mut value = f64::NAN;
        // SAFETY: one value reference, one output slot.
        let status = unsafe { (self.fmu.functions.get_real)(self.component, &vr, 1, &mut value) };
        self.check("fmi2GetReal", status)?;
        Ok(value)
    }

    pub fn do_step(&self, time: f64, step: f64) -> Result<(), String> {
        // SAFETY: live component.
        let status = unsafe { (self.fmu.functions.do_step)(self.component, time, step, 1) };
        self.check("fmi2DoStep", status)
    }

    /// The instance's state serialized into `out` (its length is the capacity); the byte count.
    pub fn save(&mut self, out: &mut [u8]) -> Result<usize, String> {
        let f = &self.fmu.functions;
        let mut size = 0usize;
        // SAFETY: `state` is null or a state this instance handed out (overwritten in place).
        unsafe {
            let status = (f.get_fmu_state)(self.component, &mut self.state);
            self.check("fmi2GetFMUstate", status)?;
            self.check(
                "fmi2SerializedFMUstateSize",
                (f.serialized_size)(self.component, self.state, &mut size),
            )?;
        }
        if size > out.len() {
            return Err(format!(
                "the FMU state needs {size} bytes, more than the {} reserved in plugin_state \
                 (raise the attribute 'state_bytes')",
                out.len()
            ));
        }
        // SAFETY: `out` holds at least `size` bytes.
        unsafe {
            self.check(
                "fmi2SerializeFMUstate",
                (f.serialize)(self.component, self.state, out.as_mut_ptr(), size),
            )?;
        }
        Ok(size)
    }

    /// The instance's state serialized into a new buffer of exactly its size (not per step).
    pub fn save_to_vec(&mut self) -> Result<Vec<u8>, String> {
        let f = &self.fmu.functions;
        let mut size = 0usize;
        // SAFETY: as in `save`.
        unsafe {
            let status = (f.get_fmu_state)(self.component, &mut self.state);
            self.check("fmi2GetFMUstate", status)?;
            self.check(
                "fmi2SerializedFMUstateSize",
                (f.serialized_size)(self.component, self.state, &mut size),
            )?;
        }
        let mut bytes = vec![0u8; size];
        let count = self.save(&mut bytes)?;
        bytes.truncate(count);
        Ok(bytes)
    }

    /// Continues from serialized `bytes` (fmi2DeSerializeFMUstate, then fmi2SetFMUstate).
    pub fn restore(&mut self, bytes: &[u8]) -> Result<(), String> {
        let f = &self.fmu.functions;
        // SAFETY: `bytes` is a live slice; `state` as in `save`.
        unsafe {
            let status =
                (f.deserialize)(self.component, bytes.as_ptr(), bytes.len(), &mut self.state);
            self.check("fmi2DeSerializeFMUstate", status)?;
            self.check(
                "fmi2SetFMUstate",
                (f.set_fmu_state)(self.component, self.state),
            )
        }
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        let f = &self.fmu.functions;
        // SAFETY: both belong to this instance; the component is freed last, once.
        unsafe {
            if !self.state.is_null() {
                (f.free_fmu_state)(self.component, &mut self.state);
            }
            (f.free_instance)(self.component);
        }
    }
}
