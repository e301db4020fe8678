//! Directional derivatives (`fmi2GetDirectionalDerivative`, `fmi3GetDirectionalDerivative`) on the
//! instance: the call's state and build checks; the product
//! itself is the runtime's (`runtime/directional_derivative.rs`), but for the parameters and
//! the non-output initial unknowns of Initialization Mode (central differences of the rebuilt
//! model, here).

use super::{allowed, Instance, MachineState};
use crate::export::runtime::Runtime;
use crate::export::Status;
use crate::variables::{Causality, VarType, Variable};

impl Instance {
    pub fn get_directional_derivative(
        &mut self,
        function: &str,
        unknown: &[u32],
        known: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Status {
        if !self.allowed(function, allowed::GET) {
            return Status::Error;
        }
        // Builds the model in initialization mode (as fmi2GetReal does); the partials need no
        // fresh outputs, so a built model skips that evaluation.
        let status = if self.runtime.is_built() {
            Status::OK
        } else {
            self.refresh_outputs(function)
        };
        if status >= Status::Error {
            return status;
        }
        if self.state() == MachineState::InitializationMode
            && self.initialization_partials_needed(unknown, known)
        {
            return match self.initialization_derivative(unknown, known, dv_known, dv_unknown) {
                Ok(()) => status,
                Err(why) => self.error(&format!("{function}: {why}")),
            };
        }
        match self
            .runtime
            .directional_derivative(unknown, known, dv_known, dv_unknown)
        {
            Ok(()) => status,
            Err(why) => self.error(&format!("{function}: {why}")),
        }
    }
}

/// The relative step of the central differences in Initialization Mode: the cube root of the
/// machine epsilon balances truncation (h^2) against rounding (eps / h).
const CENTRAL_STEP: f64 = 6.055_454_452_393_343e-6;

impl Instance {
    /// Whether a call in Initialization Mode involves a parameter (a known) or an initial unknown
    /// that is not an output (a calculated parameter, a state, a derivative): dependencies FMI
    /// 2.0 lets a master ask for there, which the models' exact partials (outputs by inputs and
    /// states) do not cover.
    fn initialization_partials_needed(&self, unknown: &[u32], known: &[u32]) -> bool {
        let info = self.info();
        let is = |vr: u32, causality: Causality| {
            info.variable(VarType::Real, vr)
                .is_some_and(|v| v.causality == causality)
        };
        // Exact partials cover outputs by inputs; states and derivatives among the initial
        // unknowns depend on the start values the model is built from.
        known.iter().any(|&vr| is(vr, Causality::Parameter))
            || unknown.iter().any(|&vr| !is(vr, Causality::Output))
    }

    /// Initialization Mode with parameters among the knowns: the parameters shape the model
    /// itself (geometry, tables, presets), so the derivative along `dv_known` is the central
    /// difference of the initial unknowns of the model rebuilt at the knowns moved by `+-h dv_known`,
    /// with `h` relative to the knowns' magnitudes ([`CENTRAL_STEP`]); one-sided where a central
    /// point would leave a declared range. The instance's own values are not touched.
    fn initialization_derivative(
        &mut self,
        unknown: &[u32],
        known: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        let info = self.info();
        let real = |vr: u32| {
            info.variable(VarType::Real, vr)
                .ok_or_else(|| format!("{vr} is not the value reference of a Real variable"))
        };
        let mut knowns = Vec::with_capacity(known.len());
        for &vr in known {
            let var = real(vr)?;
            if !matches!(var.causality, Causality::Parameter | Causality::Input) {
                return Err(format!(
                    "{} (value reference {vr}) is not a parameter or an input of {}: in \
                     Initialization Mode the knowns are those the initial unknowns depend on",
                    var.name, info.name
                ));
            }
            knowns.push(var);
        }
        for &vr in unknown {
            let var = real(vr)?;
            // Outputs, calculated parameters, continuous states and their derivatives.
            if matches!(var.causality, Causality::Parameter | Causality::Input) {
                return Err(format!(
                    "{} (value reference {vr}) is a {} of {}: in Initialization Mode the \
                     unknowns are the initial unknowns (outputs, calculated parameters, states \
                     and their derivatives)",
                    var.name,
                    if var.causality == Causality::Input {
                        "input"
                    } else {
                        "parameter"
                    },
                    info.name
                ));
            }
        }
        if let Some(bad) = dv_known.iter().find(|v| !v.is_finite()) {
            return Err(format!("dvKnown must be finite, got {bad}"));
        }
        let x: Vec<f64> = known
            .iter()
            .map(|&vr| self.runtime.real(vr as usize))
            .collect();
        // The largest step that moves no known by more than CENTRAL_STEP of its magnitude (at
        // zero, of half its declared range, at most 1 in its unit).
        let scale = |var: &Variable, x: f64| match (x, var.min, var.max) {
            (0.0, Some(lo), Some(hi)) => (0.5 * (hi - lo)).min(1.0),
            (0.0, _, _) => 1.0,
            _ => x.abs(),
        };
        let Some(h) = knowns
            .iter()
            .zip(&x)
            .zip(dv_known)
            .filter(|(_, d)| **d != 0.0)
            .map(|((var, x), d)| CENTRAL_STEP * scale(var, *x) / d.abs())
            .reduce(f64::min)
        else {
            dv_unknown.fill(0.0);
            return Ok(());
        };
        let inside = |s: f64| {
            knowns.iter().zip(&x).zip(dv_known).all(|((v, x), d)| {
                let y = x + s * d;
                v.min.is_none_or(|m| y >= m) && v.max.is_none_or(|m| y <= m)
            })
        };
        let (plus, minus) = match (inside(h), inside(-h)) {
            (true, true) => (h, -h),
            (true, false) => (h, 0.0),
            (false, true) => (0.0, -h),
            (false, false) => {
                return Err(format!(
                    "the knowns cannot move by {h:e} times dvKnown within their declared ranges"
                ))
            }
        };
        let at = |runtime: &dyn Runtime, s: f64| -> Result<Vec<f64>, String> {
            let mut probe = runtime.snapshot();
            let moved: Vec<f64> = x.iter().zip(dv_known).map(|(x, d)| x + s * d).collect();
            probe.set_reals(known, &moved, true);
            probe
                .build()
                .map_err(|why| format!("the model moved by {s:e} dvKnown is refused: {why}"))?;
            let mut report = crate::models::Report::default();
            probe.refresh_outputs(&mut report);
            let mut out = vec![0.0; unknown.len()];
            probe.reals(unknown, &mut out);
            Ok(out)
        };
        let (high, low) = (at(&*self.runtime, plus)?, at(&*self.runtime, minus)?);
        for (k, slot) in dv_unknown.iter_mut().enumerate() {
            let value = (high[k] - low[k]) / (plus - minus);
            if !value.is_finite() {
                return Err(format!(
                    "the derivative of {} is not finite",
                    real(unknown[k]).map_or("?", |v| v.name)
                ));
            }
            *slot = value;
        }
        Ok(())
    }
}
