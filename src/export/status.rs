//! The status every call returns: `fmi2Status` and `fmi3Status` have the same values.

/// `fmi2Status` (without `fmi2Pending`, which only asynchronous steps return, and
/// `canRunAsynchronuously` is false) and `fmi3Status`: a C enum with these values.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    OK = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
}
