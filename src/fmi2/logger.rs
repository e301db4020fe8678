//! Messages to the importer's logger callback, FMI 2.0's (C-variadic, with the instance name) or
//! FMI 3.0's (`fmi3LogMessageCallback`): the instance code is the same for both versions.

use super::types::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status};
use std::ffi::{c_char, c_int, c_void, CString};

/// `fmi3LogMessageCallback` (fmi3FunctionTypes.h); the status is a C enum, received as an int.
pub type Fmi3LogMessageCallback =
    unsafe extern "C" fn(*mut c_void, c_int, *const c_char, *const c_char);

#[derive(Clone, Copy)]
enum Callback {
    Fmi2(Option<fmi2CallbackLogger>),
    Fmi3(Option<Fmi3LogMessageCallback>),
}

/// Where an instance's messages go. Messages at `fmi2Warning` and worse always reach the logger
/// (an error without its reason helps nobody); `logCalls` tracing only while debug logging is on.
pub struct Logger {
    callback: Callback,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
    pub debug: bool,
}

/// The instance's code names FMI 2.0 functions in its messages; an FMI 3.0 instance's messages
/// name the FMI 3.0 function the importer called instead.
const FMI3_NAMES: [(&str, &str); 13] = [
    ("state StepComplete", "state StepMode"),
    ("fmi2GetReal", "fmi3GetFloat64"),
    ("fmi2SetReal", "fmi3SetFloat64"),
    ("fmi2GetInteger", "fmi3GetInt32"),
    ("fmi2SetInteger", "fmi3SetInt32"),
    ("fmi2SetupExperiment", "fmi3EnterInitializationMode"),
    ("fmi2NewDiscreteStates", "fmi3UpdateDiscreteStates"),
    ("fmi2GetDerivatives", "fmi3GetContinuousStateDerivatives"),
    ("fmi2GetFMUstate", "fmi3GetFMUState"),
    ("fmi2SetFMUstate", "fmi3SetFMUState"),
    ("fmi2FreeFMUstate", "fmi3FreeFMUState"),
    ("fmi2SerializeFMUstate", "fmi3SerializeFMUState"),
    ("fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState"),
];

impl Logger {
    pub fn new(
        callback: Option<fmi2CallbackLogger>,
        environment: fmi2ComponentEnvironment,
        instance_name: &str,
    ) -> Self {
        Self {
            callback: Callback::Fmi2(callback),
            environment,
            instance_name: c_string(instance_name),
            debug: false,
        }
    }

    /// The logger of an FMI 3.0 instance.
    pub fn new_fmi3(
        callback: Option<Fmi3LogMessageCallback>,
        environment: *mut c_void,
        instance_name: &str,
    ) -> Self {
        Self {
            callback: Callback::Fmi3(callback),
            environment,
            instance_name: c_string(instance_name),
            debug: false,
        }
    }

    /// Whether the importer instantiated through the FMI 3.0 API.
    pub fn is_fmi3(&self) -> bool {
        matches!(self.callback, Callback::Fmi3(_))
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
        let callback = match self.callback {
            Callback::Fmi2(Some(callback)) => callback,
            Callback::Fmi3(Some(callback)) => {
                return self.send_fmi3(callback, status, category, message)
            }
            _ => return,
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

impl Logger {
    #[cold]
    fn send_fmi3(
        &self,
        callback: Fmi3LogMessageCallback,
        status: fmi2Status,
        category: &str,
        message: &str,
    ) {
        let mut message = message.to_string();
        for (fmi2, fmi3) in FMI3_NAMES {
            message = message.replace(fmi2, fmi3);
        }
        // FMI 3.0's callback has no instance name: the message starts with it.
        let text = c_string(&format!(
            "{}: {}",
            self.instance_name.to_string_lossy(),
            message.replace("fmi2", "fmi3")
        ));
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

/// A C string of `s`, with any interior NUL replaced so that nothing is cut off silently.
pub fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{fffd}")).unwrap_or_default()
}
