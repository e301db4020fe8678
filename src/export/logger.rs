//! Where an instance's messages go: the status decides the log category and whether the message
//! is sent at all; the version layer's [`Sink`] calls the importer's callback.

use super::Status;
use std::ffi::CString;

/// The importer's logger callback, as one FMI version calls it.
pub trait Sink {
    fn send(&self, status: Status, category: &str, message: &str);
}

/// An instance's logger. Messages at `Warning` and worse always reach the importer (an error
/// without its reason helps nobody); `logCalls` tracing only while debug logging is on.
pub struct Logger {
    sink: Box<dyn Sink>,
    pub debug: bool,
}

impl Logger {
    pub fn new(sink: impl Sink + 'static) -> Self {
        Self {
            sink: Box::new(sink),
            debug: false,
        }
    }

    pub fn log(&self, status: Status, message: &str) {
        let category = match status {
            Status::OK => "logCalls",
            Status::Warning => "logStatusWarning",
            Status::Discard => "logStatusDiscard",
            Status::Error => "logStatusError",
            Status::Fatal => "logStatusFatal",
        };
        if status < Status::Warning && !self.debug {
            return;
        }
        self.sink.send(status, category, message);
    }

    /// A message the importer should see although the call succeeds (an input evaluated at the
    /// nearest valid point under the default out-of-range policy): OK, always logged.
    pub fn notice(&self, message: &str) {
        self.sink.send(Status::OK, "logStatusWarning", message);
    }
}

/// A C string of `s`, with any interior NUL replaced so that nothing is cut off silently.
pub fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{fffd}")).unwrap_or_default()
}
