//! The FMI 2.0 export layer (Co-Simulation and Model Exchange): the only `unsafe` code of the
//! crate.
//!
//! Imports point one way, each module only at those after it:
//! - `exports`: the C functions, Co-Simulation and Model Exchange; each checks the pointers and
//!   runs one `Instance` method under the panic guard;
//! - `instance`: the call-sequence state machine, the variable rules, FMU states, the
//!   out-of-range policy;
//! - `registry`: the generated list of models and their [`runtime::Bindings`];
//! - `runtime`: the bridge to any [`crate::models::Model`] behind `dyn Runtime`;
//! - `logger`, `types`: the importer's callbacks and the C types.
//!
//! A model needs no code here.

#![deny(unsafe_op_in_unsafe_fn)]

pub(crate) mod exports;
pub(crate) mod instance;
pub(crate) mod logger;
pub mod registry;
pub mod runtime;
pub mod types;

pub use registry::REGISTRY;
