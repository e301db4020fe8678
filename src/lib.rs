//! FMI 2.0 Co-Simulation FMUs of novel actuators: McKibben and knitted-sleeve pneumatic muscles and
//! a multiferroic nano-motor, after E. Ball, *Novel Methods in Meso-Scale and Nano-Scale Actuation*,
//! M.S. thesis, Cornell University, 2014 ("the dissertation"; Cornell's eCommons repository).
//!
//! Data flows one way: `modelDescription/*.xml` (variables) -> [`variables`] (generated tables) ->
//! [`models`] (variables to physics, effect switches) -> [`physics`] (pure equations).
//! [`fmi2`] is the C ABI around any [`models::Model`], and the only module that handles raw pointers.

pub mod fmi2;
pub mod models;
pub mod package;
pub mod physics;
pub mod scene;
pub mod variables;
