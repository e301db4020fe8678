//! The FMI 2.0 logger callback (C-variadic, with the instance name) as the instance's
//! [`Sink`].

use super::types::{fmi2CallbackLogger, fmi2ComponentEnvironment};
use crate::export::logger::{c_string, Logger, Sink};
use crate::export::Status;
use std::ffi::CString;

struct Fmi2Callback {
    callback: Option<fmi2CallbackLogger>,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
}

/// The logger of an FMI 2.0 instance named `instance_name`.
pub fn logger(
    callback: Option<fmi2CallbackLogger>,
    environment: fmi2ComponentEnvironment,
    instance_name: &str,
) -> Logger {
    Logger::new(Fmi2Callback {
        callback,
        environment,
        instance_name: c_string(instance_name),
    })
}

impl Sink for Fmi2Callback {
    fn send(&self, status: Status, category: &str, message: &str) {
        let Some(callback) = self.callback else {
            return;
        };
        // The message is the logger's format string: double every '%' so that none is a directive.
        let text = c_string(&message.replace('%', "%%"));
        let category = c_string(category);
        // SAFETY: the importer gave this callback and environment for this instance's lifetime;
        // all strings are NUL-terminated and outlive the call.
        unsafe {
            callback(
                self.environment,
                self.instance_name.as_ptr(),
                status as i32,
                category.as_ptr(),
                text.as_ptr(),
            );
        }
    }
}
