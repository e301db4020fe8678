//! The FMI 2.0 export layer (Co-Simulation, and Model Exchange in `model_exchange`): the only
//! `unsafe` code of the crate.
//!
//! `exports` holds the C functions; `instance` the call-sequence state machine and the variable
//! rules; `runtime` the bridge to any [`crate::models::Model`]; `registry` the generated list of
//! models and the bindings between value references and each model's typed variables. A model
//! needs no code here.

#![deny(unsafe_op_in_unsafe_fn)]

mod derivatives;
mod exports;
mod instance;
mod logger;
mod model_exchange;
mod out_of_range;
pub mod registry;
pub mod runtime;
pub mod types;

pub use registry::REGISTRY;
