//! FMI 2.0 and FMI 3.0 Co-Simulation and Model Exchange FMUs of novel actuators: McKibben and
//! knitted-sleeve pneumatic muscles and a multiferroic nano-motor, after the dissertation (E.
//! Ball, *Novel Methods in Meso-Scale and Nano-Scale Actuation*, M.S. thesis, Cornell University,
//! 2014; Cornell's eCommons repository).
//!
//! Data flows one way, every arrow pointing down:
//! [`fmi2`], [`fmi3`] (each FMI version's C ABI and its mapping) -> [`export`] (the
//! version-neutral machinery: instance handles, panic guard, call-sequence state machine,
//! variable rules, FMU states, logging, registry) -> [`models`] (typed variables to physics,
//! effect switches) -> [`physics`] (pure equations). Beside them, [`variables`] holds what
//! build.rs generates from `modelDescription/*.xml`: value references, metadata and each model's
//! typed `Parameters`, `Inputs`, `Outputs` and `CalculatedParameters`; it names nothing above it.
//! [`terminals`] holds the FMI 3.0 terminals the packager adds to its FMUs.
//! [`fmi2`] and [`fmi3`] never use each other. [`export`], [`fmi2`] and [`fmi3`] are the only
//! modules that allow `unsafe_code`; `physics` and `models` forbid it.

pub mod export;
pub mod fmi2;
pub mod fmi3;
pub mod models;
pub mod physics;
pub mod terminals;
pub mod variables;
