//! The FMI 2.0 Co-Simulation export layer: the only `unsafe` code of the crate.
//!
//! `exports` holds the C functions; `instance` the call-sequence state machine and the variable
//! rules; `runtime` the bridge to any [`crate::models::Model`]. A model needs no code here.

mod exports;
mod instance;
mod logger;
mod out_of_range;
pub mod runtime;
pub mod types;
