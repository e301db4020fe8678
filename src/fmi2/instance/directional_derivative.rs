//! `fmi2GetDirectionalDerivative` on the instance: the call's state and build checks; the product
//! itself is the runtime's (`runtime/directional_derivative.rs`).

use super::{allowed, Instance};
use crate::fmi2::types::fmi2Status;

impl Instance {
    pub fn get_directional_derivative(
        &mut self,
        unknown: &[u32],
        known: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> fmi2Status {
        const F: &str = "fmi2GetDirectionalDerivative";
        if !self.allowed(F, allowed::GET) {
            return fmi2Status::Error;
        }
        // Builds the model in initialization mode (as fmi2GetReal does); the partials need no
        // fresh outputs, so a built model skips that evaluation.
        let status = if self.runtime.is_built() {
            fmi2Status::OK
        } else {
            self.refresh_outputs(F)
        };
        if status >= fmi2Status::Error {
            return status;
        }
        match self
            .runtime
            .directional_derivative(unknown, known, dv_known, dv_unknown)
        {
            Ok(()) => status,
            Err(why) => self.error(&format!("{F}: {why}")),
        }
    }
}
