use super::*;
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
    let instance = Instance::new(REGISTRY[0], Logger::new(Some(callback), env, "t"));
    let c = Box::into_raw(Box::new(instance)) as fmi2Component;
    assert_eq!(
        // SAFETY: `c` is a live instance from Box::into_raw.
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
