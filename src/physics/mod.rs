//! Pure physics: functions and small structs, SI units throughout. No FMI, no I/O, no pointers.

#![forbid(unsafe_code)]

pub mod bladder;
pub mod festo;
pub mod free_bladder;
pub mod friction;
pub mod gaylord;
pub mod inverse;
pub mod knitted;
pub mod knitted_bag;
pub mod knitted_cylinder;
pub mod knitted_muscle;
pub mod knitted_partials;
pub mod knitted_shape;
pub mod knitted_yarn;
pub mod mckibben;
pub mod multiferroic;
pub mod muscle_params;
pub mod numerics;
