//! Loads a packaged FMU's binary through its C ABI (libloading), the way an importer does, with a
//! logger that records every message.
#![allow(dead_code, non_snake_case)]

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

pub type Component = *mut c_void;
pub const OK: c_int = 0;
pub const WARNING: c_int = 1;
pub const DISCARD: c_int = 2;
pub const ERROR: c_int = 3;
pub const FATAL: c_int = 4;

/// The importer's view of the logger: the FMU calls it as C-variadic with no variadic argument,
/// which the x86-64 and AArch64 Linux ABIs pass like this fixed signature.
type Logger = unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char);

#[repr(C)]
pub struct Callbacks {
    logger: Option<Logger>,
    allocate: *const c_void,
    free: *const c_void,
    step_finished: *const c_void,
    environment: *mut c_void,
}

/// Log lines as "status category: message", in order.
#[derive(Default)]
pub struct Log(pub Mutex<Vec<String>>);

impl Log {
    pub fn lines(&self) -> Vec<String> {
        self.0.lock().unwrap().clone()
    }
    pub fn contains(&self, needle: &str) -> bool {
        self.lines().iter().any(|l| l.contains(needle))
    }
    pub fn clear(&self) {
        self.0.lock().unwrap().clear()
    }
}

unsafe extern "C" fn record(
    env: *mut c_void,
    _name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    let log = &*(env as *const Log);
    let text = |p: *const c_char| {
        if p.is_null() {
            "<null>".to_string()
        } else {
            CStr::from_ptr(p).to_string_lossy().into_owned()
        }
    };
    log.0
        .lock()
        .unwrap()
        .push(format!("{status} {}: {}", text(category), text(message)));
}

/// Path of a packaged FMU; `make fmus` writes them.
pub fn fmu_path(model: &str) -> PathBuf {
    // The repository root, also when this module is built into tools/ (memcheck_native).
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = manifest
        .ancestors()
        .find(|d| d.join("modelDescription").is_dir())
        .unwrap_or(manifest);
    let p = root.join("target/fmu").join(format!("{model}.fmu"));
    assert!(
        p.exists(),
        "{} is missing: run `make fmus` first",
        p.display()
    );
    p
}

/// The GUID in a packaged FMU's modelDescription.xml.
pub fn guid_of(model: &str) -> String {
    let xml = read_entry(&fmu_path(model), "modelDescription.xml");
    let xml = String::from_utf8(xml).unwrap();
    let start = xml.find("guid=\"").unwrap() + 6;
    xml[start..start + xml[start..].find('"').unwrap()].to_string()
}

pub fn read_entry(fmu: &Path, name: &str) -> Vec<u8> {
    use std::io::Read;
    let mut zip = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
    let mut entry = zip.by_name(name).unwrap();
    let mut data = Vec::new();
    entry.read_to_end(&mut data).unwrap();
    data
}

/// Extracts the binary of `model` into a fresh directory and returns its path.
///
/// The directory is claimed with `create_dir`, which fails if it exists: `tests/all` holds several
/// copies of this module, each with its own counter, and rewriting a library another test has
/// loaded from the same path would pull its code from under it (SIGSEGV).
pub fn extract_binary(model: &str) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = loop {
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let dir =
            std::env::temp_dir().join(format!("actuator-fmus-test-{}-{n}", std::process::id()));
        match std::fs::create_dir(&dir) {
            Ok(()) => break dir,
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => panic!("{}: {e}", dir.display()),
        }
    };
    let so = dir.join(format!("{model}.so"));
    std::fs::write(
        &so,
        read_entry(&fmu_path(model), &format!("binaries/linux64/{model}.so")),
    )
    .unwrap();
    so
}

macro_rules! api {
    ($($name:ident: fn($($arg:ty),*) $(-> $ret:ty)?;)*) => {
        /// The FMI 2.0 functions of one loaded binary (or of the crate linked into the test).
        pub struct Api {
            _lib: Option<libloading::Library>,
            $(pub $name: unsafe extern "C" fn($($arg),*) $(-> $ret)?,)*
        }
        impl Api {
            pub fn load(path: &Path) -> Api {
                unsafe {
                    let lib = libloading::Library::new(path).unwrap();
                    $(let $name = *lib.get::<unsafe extern "C" fn($($arg),*) $(-> $ret)?>(concat!(stringify!($name), "\0").as_bytes())
                        .unwrap_or_else(|e| panic!("missing symbol {}: {e}", stringify!($name)));)*
                    Api { _lib: Some(lib), $($name,)* }
                }
            }
            /// The functions of the crate linked into this test binary (all models in one):
            /// its allocations go through the test's global allocator, which can count them.
            pub fn linked() -> Api {
                extern "C" {
                    $(fn $name($(_: $arg),*) $(-> $ret)?;)*
                }
                Api { _lib: None, $($name,)* }
            }
        }
    };
}

api! {
    fmi2GetTypesPlatform: fn() -> *const c_char;
    fmi2GetVersion: fn() -> *const c_char;
    fmi2SetDebugLogging: fn(Component, c_int, usize, *const *const c_char) -> c_int;
    fmi2Instantiate: fn(*const c_char, c_int, *const c_char, *const c_char, *const Callbacks, c_int, c_int) -> Component;
    fmi2FreeInstance: fn(Component);
    fmi2SetupExperiment: fn(Component, c_int, f64, f64, c_int, f64) -> c_int;
    fmi2EnterInitializationMode: fn(Component) -> c_int;
    fmi2ExitInitializationMode: fn(Component) -> c_int;
    fmi2Terminate: fn(Component) -> c_int;
    fmi2Reset: fn(Component) -> c_int;
    fmi2GetReal: fn(Component, *const u32, usize, *mut f64) -> c_int;
    fmi2GetInteger: fn(Component, *const u32, usize, *mut c_int) -> c_int;
    fmi2GetBoolean: fn(Component, *const u32, usize, *mut c_int) -> c_int;
    fmi2GetString: fn(Component, *const u32, usize, *mut *const c_char) -> c_int;
    fmi2SetReal: fn(Component, *const u32, usize, *const f64) -> c_int;
    fmi2SetInteger: fn(Component, *const u32, usize, *const c_int) -> c_int;
    fmi2SetBoolean: fn(Component, *const u32, usize, *const c_int) -> c_int;
    fmi2SetString: fn(Component, *const u32, usize, *const *const c_char) -> c_int;
    fmi2GetFMUstate: fn(Component, *mut *mut c_void) -> c_int;
    fmi2SetFMUstate: fn(Component, *mut c_void) -> c_int;
    fmi2FreeFMUstate: fn(Component, *mut *mut c_void) -> c_int;
    fmi2SerializedFMUstateSize: fn(Component, *mut c_void, *mut usize) -> c_int;
    fmi2SerializeFMUstate: fn(Component, *mut c_void, *mut c_char, usize) -> c_int;
    fmi2DeSerializeFMUstate: fn(Component, *const c_char, usize, *mut *mut c_void) -> c_int;
    fmi2GetDirectionalDerivative: fn(Component, *const u32, usize, *const u32, usize, *const f64, *mut f64) -> c_int;
    fmi2SetRealInputDerivatives: fn(Component, *const u32, usize, *const c_int, *const f64) -> c_int;
    fmi2GetRealOutputDerivatives: fn(Component, *const u32, usize, *const c_int, *mut f64) -> c_int;
    fmi2DoStep: fn(Component, f64, f64, c_int) -> c_int;
    fmi2CancelStep: fn(Component) -> c_int;
    fmi2GetStatus: fn(Component, c_int, *mut c_int) -> c_int;
    fmi2GetRealStatus: fn(Component, c_int, *mut f64) -> c_int;
    fmi2GetIntegerStatus: fn(Component, c_int, *mut c_int) -> c_int;
    fmi2GetBooleanStatus: fn(Component, c_int, *mut c_int) -> c_int;
    fmi2GetStringStatus: fn(Component, c_int, *mut *const c_char) -> c_int;
}

/// One instance with its own log; freed on drop.
pub struct Instance<'a> {
    pub api: &'a Api,
    pub c: Component,
    pub log: Box<Log>,
    _callbacks: Box<Callbacks>,
}

impl Api {
    /// Instantiates with the given GUID; if the FMU refuses, the log of why.
    pub fn instantiate(&self, name: &str, guid: &str) -> Result<Instance<'_>, Box<Log>> {
        self.instantiate_as(name, guid, 1)
    }

    /// As [`Api::instantiate`], with the given `fmi2Type` (0 Model Exchange, 1 Co-Simulation).
    pub fn instantiate_as(
        &self,
        name: &str,
        guid: &str,
        fmu_type: c_int,
    ) -> Result<Instance<'_>, Box<Log>> {
        let log = Box::new(Log::default());
        let callbacks = Box::new(Callbacks {
            logger: Some(record),
            allocate: std::ptr::null(),
            free: std::ptr::null(),
            step_finished: std::ptr::null(),
            environment: &*log as *const Log as *mut c_void,
        });
        let name = CString::new(name).unwrap();
        let guid = CString::new(guid).unwrap();
        let c = unsafe {
            (self.fmi2Instantiate)(
                name.as_ptr(),
                fmu_type,
                guid.as_ptr(),
                std::ptr::null(),
                &*callbacks,
                0,
                0,
            )
        };
        if c.is_null() {
            return Err(log);
        }
        // The FMU keeps the environment pointer: the boxed log lives as long as the instance.
        Ok(Instance {
            api: self,
            c,
            log,
            _callbacks: callbacks,
        })
    }
}

impl Instance<'_> {
    pub fn setup(&self) -> c_int {
        unsafe { (self.api.fmi2SetupExperiment)(self.c, 0, 0.0, 0.0, 0, 0.0) }
    }
    pub fn enter(&self) -> c_int {
        unsafe { (self.api.fmi2EnterInitializationMode)(self.c) }
    }
    pub fn exit(&self) -> c_int {
        unsafe { (self.api.fmi2ExitInitializationMode)(self.c) }
    }
    /// SetupExperiment, Enter and ExitInitializationMode, all expected OK.
    pub fn initialize(&self) {
        assert_eq!(self.setup(), OK);
        assert_eq!(self.enter(), OK);
        assert_eq!(self.exit(), OK, "{:?}", self.log.lines());
    }
    pub fn set_real(&self, vrs: &[u32], values: &[f64]) -> c_int {
        assert_eq!(vrs.len(), values.len());
        unsafe { (self.api.fmi2SetReal)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn get_real(&self, vrs: &[u32]) -> (c_int, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        let s =
            unsafe { (self.api.fmi2GetReal)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out)
    }
    pub fn real(&self, vr: u32) -> f64 {
        let (s, v) = self.get_real(&[vr]);
        assert!(
            s <= WARNING,
            "fmi2GetReal({vr}) returned {s}: {:?}",
            self.log.lines()
        );
        v[0]
    }
    pub fn do_step(&self, t: f64, h: f64) -> c_int {
        unsafe { (self.api.fmi2DoStep)(self.c, t, h, 1) }
    }
    pub fn set_integer(&self, vrs: &[u32], values: &[c_int]) -> c_int {
        assert_eq!(vrs.len(), values.len());
        unsafe { (self.api.fmi2SetInteger)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn boolean(&self, vr: u32) -> bool {
        let mut out: c_int = -1;
        let s = unsafe { (self.api.fmi2GetBoolean)(self.c, &vr, 1, &mut out) };
        assert!(s <= WARNING, "fmi2GetBoolean({vr}) returned {s}");
        out != 0
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        unsafe { (self.api.fmi2FreeInstance)(self.c) }
    }
}

/// Value references of McKibbenMuscle, from the crate's generated tables.
pub mod mckibben {
    use actuator_fmus::variables::mckibben_muscle::real;
    pub const PRESSURE: u32 = real::PRESSURE as u32;
    pub const LENGTH: u32 = real::LENGTH as u32;
    pub const FORCE: u32 = real::FORCE as u32;
    pub const VOLUME: u32 = real::VOLUME as u32;
    pub const STRAND_LENGTH: u32 = real::STRAND_LENGTH as u32;
    pub const TURNS: u32 = real::TURNS as u32;
    pub const MAX_LENGTH: u32 = real::MAX_LENGTH as u32;
    pub const STIFFNESS: u32 = real::STIFFNESS as u32;
    pub const INPUT_CLAMPED: u32 =
        actuator_fmus::variables::mckibben_muscle::boolean::INPUT_CLAMPED as u32;
    pub const OUT_OF_RANGE_POLICY: u32 =
        actuator_fmus::variables::mckibben_muscle::integer::OUT_OF_RANGE_POLICY as u32;
}

/// Eq. 2.3, written out independently of the crate.
pub fn gaylord_force(p: f64, l: f64, b: f64, n: f64) -> f64 {
    p * (3.0 * l * l - b * b) / (4.0 * std::f64::consts::PI * n * n)
}
