//! The FMI 3.0 logger callback (`fmi3LogMessageCallback`) as the instance's [`Sink`].

use crate::export::logger::{c_string, Logger, Sink};
use crate::export::Status;
use std::ffi::{c_char, c_int, c_void};

/// `fmi3LogMessageCallback` (fmi3FunctionTypes.h); the status is a C enum, received as an int.
pub type Fmi3LogMessageCallback =
    unsafe extern "C" fn(*mut c_void, c_int, *const c_char, *const c_char);

struct Fmi3Callback {
    callback: Option<Fmi3LogMessageCallback>,
    environment: *mut c_void,
    instance_name: String,
}

/// The logger of an FMI 3.0 instance named `instance_name`.
pub fn logger(
    callback: Option<Fmi3LogMessageCallback>,
    environment: *mut c_void,
    instance_name: &str,
) -> Logger {
    Logger::new(Fmi3Callback {
        callback,
        environment,
        instance_name: instance_name.to_string(),
    })
}

impl Sink for Fmi3Callback {
    fn send(&self, status: Status, category: &str, message: &str) {
        let Some(callback) = self.callback else {
            return;
        };
        // FMI 3.0's callback has no instance name: the message starts with it.
        let text = c_string(&format!("{}: {message}", self.instance_name));
        let category = c_string(category);
        // SAFETY: the importer gave this callback and environment for this instance's lifetime;
        // both strings are NUL-terminated and outlive the call (not a format string in FMI 3.0).
        unsafe {
            callback(
                self.environment,
                status as c_int,
                category.as_ptr(),
                text.as_ptr(),
            )
        };
    }
}
