//! The FMI 2.0 export layer (Co-Simulation and Model Exchange): its C functions and their
//! mapping onto the version-neutral machinery of [`crate::export`].
//!
//! - `exports`: the C functions, Co-Simulation and Model Exchange; each checks the pointers and
//!   runs one `Instance` method under the panic guard ([`crate::export::guard`]);
//! - `logger`: the FMI 2.0 logger callback as a [`crate::export::logger::Sink`];
//! - `types`: the C types of the FMI 2.0 headers.
//!
//! A model needs no code here.

#![deny(unsafe_op_in_unsafe_fn)]

pub(crate) mod exports;
pub(crate) mod logger;
pub mod types;

// The registry and the runtime are version-neutral; tests, benches and tools reach them here too.
pub use crate::export::{registry, runtime, REGISTRY};
