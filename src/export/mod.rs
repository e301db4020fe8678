//! The machinery both export layers share, whatever the FMI version: the FMI 2.0 layer
//! (`src/fmi2`) and the FMI 3.0 layer (`src/fmi3`) hold only their C ABI and its mapping onto
//! this, and depend on it, never on each other.
//!
//! Imports point one way, each module only at those after it:
//! - `guard`: every export's one path: the instance behind a handle, refused if it belongs to
//!   the other version's API, the call's body under the panic guard; pointer and string checks;
//! - `handles`: the table of live instances behind the handles importers hold;
//! - `instance`: the call-sequence state machine, the variable rules, FMU states and their
//!   serialization, Model Exchange's modes, directional derivatives, the out-of-range policy;
//!   every method is told the name of the function the importer called, for its messages;
//! - `registry`: the generated list of models and their [`runtime::Bindings`];
//! - `runtime`: the bridge to any [`crate::models::Model`] behind `dyn Runtime`;
//! - `logger`, `status`: where messages go (each version supplies a [`logger::Sink`] for its
//!   callback) and the status every call returns.
//!
//! A model needs no code here.

#![deny(unsafe_op_in_unsafe_fn)]

pub(crate) mod guard;
pub(crate) mod handles;
pub(crate) mod instance;
pub(crate) mod logger;
pub mod registry;
pub mod runtime;
mod status;

pub use registry::REGISTRY;
pub use status::Status;
