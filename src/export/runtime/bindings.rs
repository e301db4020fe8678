//! Access by value reference to a model's typed values: the trait the generated bindings
//! (`export/registry.rs`) implement for every model.

use super::Values;
use crate::variables::Interface;

/// Access by value reference to one model's typed values; generated for every
/// `crate::variables::<model>::Variables` as one `match` per type. A value reference that is not
/// the model's reads a default and writes nothing (the export layer refuses those before).
pub trait Bindings: Interface + Sized {
    /// The Real at `vr`; NaN for a value reference that is not the model's, so that the per-step
    /// `fmi2GetReal`, which hands out only finite values, needs no separate test of the reference.
    fn real(values: &Values<Self>, vr: usize) -> f64;
    fn set_real(values: &mut Values<Self>, vr: usize, value: f64);
    fn integer(values: &Values<Self>, vr: usize) -> i32;
    fn set_integer(values: &mut Values<Self>, vr: usize, value: i32);
    fn boolean(values: &Values<Self>, vr: usize) -> bool;
    fn set_boolean(values: &mut Values<Self>, vr: usize, value: bool);
    fn string(values: &Values<Self>, vr: usize) -> &str;
    fn set_string(values: &mut Values<Self>, vr: usize, value: &str);
    /// Writes the `input_clamped` output, if the model has one (else nothing).
    fn set_input_clamped(values: &mut Values<Self>, value: bool);
}
