//! Generic numerics the physics is written with, each hand-written for the per-step cost or for its
//! failure mode (no panic, no NaN, a bounded loop): a safeguarded Newton-bisection root finder,
//! limiting to computed bounds, forward-mode dual numbers of two variables, the matrix exponential
//! of a small matrix (and of a 2x2 one in closed form), one Dormand-Prince 5(4) step and one
//! classical RK4 step. Nothing here knows an actuator; the domain code beside it does.

pub mod bounds;
pub mod dormand_prince;
pub mod dual;
pub mod expm;
pub mod expm2;
pub mod hyper_dual;
pub mod rk4;
pub mod root;
