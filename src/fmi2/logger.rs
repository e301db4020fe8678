//! Messages to the importer's logger callback.

use super::types::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status};
use std::ffi::CString;

/// Where an instance's messages go. Messages at `fmi2Warning` and worse always reach the logger
/// (an error without its reason helps nobody); `logCalls` tracing only while debug logging is on.
pub struct Logger {
    callback: Option<fmi2CallbackLogger>,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
    pub debug: bool,
}

impl Logger {
    pub fn new(
        callback: Option<fmi2CallbackLogger>,
        environment: fmi2ComponentEnvironment,
        instance_name: &str,
    ) -> Self {
        Self {
            callback,
            environment,
            instance_name: c_string(instance_name),
            debug: false,
        }
    }

    pub fn log(&self, status: fmi2Status, message: &str) {
        let category = match status {
            fmi2Status::OK | fmi2Status::Pending => "logCalls",
            fmi2Status::Warning => "logStatusWarning",
            fmi2Status::Discard => "logStatusDiscard",
            fmi2Status::Error => "logStatusError",
            fmi2Status::Fatal => "logStatusFatal",
        };
        if status < fmi2Status::Warning && !self.debug {
            return;
        }
        self.send(status, category, message);
    }

    /// A message the importer should see although the call succeeds (an input evaluated at the
    /// nearest valid point under the default out-of-range policy): fmi2OK, always logged.
    pub fn notice(&self, message: &str) {
        self.send(fmi2Status::OK, "logStatusWarning", message);
    }

    fn send(&self, status: fmi2Status, category: &str, message: &str) {
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

/// A C string of `s`, with any interior NUL replaced so that nothing is cut off silently.
pub fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{fffd}")).unwrap_or_default()
}
