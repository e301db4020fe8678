//! `fmi2GetDirectionalDerivative`: the importer's seed `dv_known` over inputs (and continuous
//! states), times the model's exact partials ([`Model::partials`]), gives `dv_unknown` over
//! outputs (and state derivatives): Model Exchange's Jacobian. No finite differences: a model
//! that has no partials says so and the call is refused.

use super::Bindings;
use crate::models::{Inputs, Model};
use crate::variables::{Causality, ContinuousStates, Interface, VarType};

/// `dv_unknown[i] = sum_j d(unknown_i)/d(known_j) dv_known[j]` for model `M` at the current inputs.
pub(super) fn directional_derivative<M: Model>(
    model: Option<&mut M>,
    inputs: &Inputs<M>,
    unknown: &[u32],
    known: &[u32],
    dv_known: &[f64],
    dv_unknown: &mut [f64],
) -> Result<(), String>
where
    M::Variables: Bindings,
{
    let info = M::Variables::INFO;
    type S<M> = <<M as Model>::Variables as Interface>::States;
    // Knowns: inputs and continuous states; unknowns: outputs and state derivatives.
    let name = |vr: u32, causality: Causality, also: &[u32], role: &str| {
        let var = info
            .variable(VarType::Real, vr)
            .ok_or_else(|| format!("{vr} is not the value reference of a Real variable"))?;
        if var.causality == causality || also.contains(&vr) {
            Ok(var.name)
        } else {
            Err(format!(
                "{} (value reference {vr}) is not {role} of {}",
                var.name, info.name
            ))
        }
    };
    let knowns = known
        .iter()
        .map(|&vr| {
            name(
                vr,
                Causality::Input,
                S::<M>::VALUE_REFERENCES,
                if S::<M>::COUNT == 0 {
                    "an input"
                } else {
                    "an input or a continuous state"
                },
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let unknowns = unknown
        .iter()
        .map(|&vr| {
            name(
                vr,
                Causality::Output,
                S::<M>::DERIVATIVE_VALUE_REFERENCES,
                if S::<M>::COUNT == 0 {
                    "an output"
                } else {
                    "an output or a state derivative"
                },
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(bad) = dv_known.iter().find(|v| !v.is_finite()) {
        return Err(format!("dvKnown must be finite, got {bad}"));
    }
    let model = model.ok_or("no model yet: call it in initialization mode or later")?;
    let partials = model.partials_for(inputs, &unknowns)?;
    for (slot, output) in dv_unknown.iter_mut().zip(&unknowns) {
        let row = partials
            .get(output)
            .ok_or_else(|| format!("the partial derivatives of {output} are not provided"))?;
        let value: f64 = knowns
            .iter()
            .zip(dv_known)
            .filter_map(|(input, seed)| {
                row.iter()
                    .find(|(name, _)| name == input)
                    .map(|(_, d)| d * seed)
            })
            .sum();
        if !value.is_finite() {
            return Err(format!("the derivative of {output} overflows"));
        }
        *slot = value;
    }
    Ok(())
}
