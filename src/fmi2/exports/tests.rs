use super::values::{fmi2GetReal, fmi2SetReal};
use super::*;
use crate::fmi2::logger::logger;
use std::ffi::CStr;
use std::sync::Mutex;

type Log = Mutex<Vec<(c_int, String)>>;

unsafe extern "C" fn record(
    env: *mut std::ffi::c_void,
    _: fmi2String,
    status: c_int,
    _: fmi2String,
    msg: fmi2String,
) {
    // SAFETY: `env` is the test's Log and `msg` a NUL-terminated message from the logger.
    let log = unsafe { &*(env as *const Log) };
    if let Ok(mut lines) = log.lock() {
        let msg = unsafe { CStr::from_ptr(msg) };
        lines.push((status, msg.to_string_lossy().into_owned()));
    }
}

fn line(log: &Log, i: usize) -> (c_int, String) {
    log.lock().map(|lines| lines[i].clone()).unwrap_or_default()
}

#[test]
fn a_panic_is_logged_and_becomes_fatal() {
    let log: Log = Mutex::new(Vec::new());
    // SAFETY (test only): the FMU calls the logger with exactly these five arguments.
    let callback = unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(*mut std::ffi::c_void, fmi2String, c_int, fmi2String, fmi2String),
            fmi2CallbackLogger,
        >(record)
    };
    let env = &log as *const _ as *mut std::ffi::c_void;
    let instance = Instance::new(REGISTRY[0], &API, logger(Some(callback), env, "t"));
    let c = handles::register(Box::new(instance)).unwrap();
    assert_eq!(
        // SAFETY: `c` is a live instance's handle.
        unsafe { guarded(c, "fmi2Test", |_| panic!("boom")) },
        fmi2Status::Fatal
    );
    assert_eq!(
        line(&log, 0),
        (4, "fmi2Test: internal error: boom".to_string())
    );
    // Only freeing is left to do, and it works.
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::Error);
        assert!(line(&log, 1).1.contains("illegal call in state Fatal"));
        fmi2FreeInstance(c);
    }
}

/// Handles of freed instances, handles a few bytes off a live one, and made-up values are refused
/// without being read; a second free never reaches the instance that took the first one's place.
#[test]
fn stale_and_made_up_handles_are_refused() {
    let make = || {
        let instance = Instance::new(REGISTRY[0], &API, logger(None, std::ptr::null_mut(), "t"));
        handles::register(Box::new(instance)).unwrap()
    };
    let vr = 0u32;
    let refused = |c: fmi2Component| unsafe {
        // SAFETY: the calls must refuse `c` before anything is read through it.
        let mut value = 0.0;
        fmi2SetReal(c, &vr, 1, &value) == fmi2Status::Error
            && fmi2DoStep(c, 0.0, 1e-3, 0) == fmi2Status::Error
            && fmi2GetReal(c, &vr, 1, &mut value) == fmi2Status::Error
            && fmi2Reset(c) == fmi2Status::Error
    };
    let first = make();
    for off in (1..8isize).flat_map(|k| [k, -k]) {
        assert!(refused(first.wrapping_byte_offset(off)), "{off}");
    }
    for made_up in [1usize, 0xdead_beef, usize::MAX] {
        assert!(
            refused(std::ptr::without_provenance_mut(made_up)),
            "{made_up:#x}"
        );
    }
    // SAFETY: a live handle, freed once; then a stale one.
    unsafe { fmi2FreeInstance(first) };
    assert!(refused(first));
    // Another instance takes the freed slot: the stale handle still names nothing.
    let second = make();
    unsafe {
        fmi2FreeInstance(first);
        assert_eq!(
            fmi2Reset(second),
            fmi2Status::OK,
            "the double free reached the live instance"
        );
        fmi2FreeInstance(second);
    }
    assert!(refused(second));
}

#[test]
fn resource_locations() {
    let path = |s: &str| Some(PathBuf::from(s));
    assert_eq!(
        resource_path("file:///tmp/a%20b/resources").ok(),
        path("/tmp/a b/resources")
    );
    assert_eq!(resource_path("file:/tmp/x").ok(), path("/tmp/x"));
    assert_eq!(resource_path("file://localhost/tmp/x").ok(), path("/tmp/x"));
    assert!(resource_path("http://example.org/x").is_err());
    assert!(resource_path("file:///bad%zz").is_err());
}

/// A rejected parameter set is remembered rather than rebuilt at every get in initialization mode (a KnittedMuscle
/// builds its whole shape table before a later check refuses it), but a changed value is tried
/// again at once.
#[test]
fn a_rejected_build_is_tried_again_after_a_change() {
    let log: Log = Mutex::new(Vec::new());
    // SAFETY (test only): the FMU calls the logger with exactly these five arguments.
    let logger = unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(*mut std::ffi::c_void, fmi2String, c_int, fmi2String, fmi2String),
            fmi2CallbackLogger,
        >(record)
    };
    let functions = fmi2CallbackFunctions {
        logger: Some(logger),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: &log as *const _ as *mut std::ffi::c_void,
    };
    let info = REGISTRY
        .iter()
        .find(|f| f.info().name == "MultiferroicMotor")
        .unwrap()
        .info();
    let bar = info.by_name("bar_length").unwrap().vr;
    let guid = std::ffi::CString::new(info.guid).unwrap();
    // SAFETY: valid strings and callbacks that outlive the instance, which is freed at the end.
    unsafe {
        let c = fmi2Instantiate(
            c"t".as_ptr(),
            1,
            guid.as_ptr(),
            std::ptr::null(),
            &functions,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::OK);
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::OK);
        let mut length = 0.0;
        assert_eq!(values::fmi2GetReal(c, &bar, 1, &mut length), fmi2Status::OK);
        // Longer than the ring's hole is wide: the motor cannot be built.
        assert_eq!(values::fmi2SetReal(c, &bar, 1, &600e-9), fmi2Status::OK);
        let mut x = 0.0;
        for _ in 0..2 {
            assert_eq!(values::fmi2GetReal(c, &bar, 1, &mut x), fmi2Status::Error);
        }
        let lines = log.lock().unwrap().clone();
        let last = &lines[lines.len() - 1].1;
        assert!(last.contains("parameters rejected"), "{lines:?}");
        assert_eq!(&lines[lines.len() - 2].1, last);
        // Changed back: built at once.
        assert_eq!(values::fmi2SetReal(c, &bar, 1, &length), fmi2Status::OK);
        assert_eq!(values::fmi2GetReal(c, &bar, 1, &mut x), fmi2Status::OK);
        assert_eq!(x, length);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status::OK);
        fmi2FreeInstance(c);
    }
}
