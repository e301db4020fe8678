//! The array outputs of the FMI 3.0 description (see `fmi3_description.rs`): declared in the
//! source's VendorAnnotations, `<Tool name="actuator-fmus"><Arrays><Array .../></Arrays>` (read by
//! `description.rs`), and checked against the model.

use super::super::model_description::description::ArrayDeclaration;
use super::super::model_description::{Model, ResolvedUnknown};
use super::Layout;

/// A checked array output: its declaration, value reference and the scalar output whose
/// dependencies it has (as an output, and as an initial unknown if that one is).
pub(super) struct ArrayOutput<'a> {
    pub(super) declaration: &'a ArrayDeclaration,
    pub(super) vr: u32,
    pub(super) output: &'a ResolvedUnknown,
    pub(super) initial: Option<&'a ResolvedUnknown>,
}

/// The array outputs the source of `model` declares, checked against it.
pub(super) fn array_outputs<'a>(
    model: &'a Model,
    layout: &Layout,
) -> Result<Vec<ArrayOutput<'a>>, String> {
    let mut names = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for (i, declaration) in model.source.arrays().enumerate() {
        let context = |e: &str| format!("Arrays: array '{}': {e}", declaration.name);
        if declaration.name.trim().is_empty()
            || !names.insert(declaration.name.as_str())
            || model.variables.iter().any(|v| v.name == declaration.name)
        {
            return Err(context(
                "the name must be non-empty and unique among the variables",
            ));
        }
        if declaration.size == 0 {
            return Err(context("size must be at least 1"));
        }
        let named =
            |u: &&ResolvedUnknown| model.variables[u.index - 1].name == declaration.dependencies_of;
        let output = model.outputs.iter().find(named).ok_or_else(|| {
            context(&format!(
                "dependenciesOf '{}' is not an output",
                declaration.dependencies_of
            ))
        })?;
        let initial = model.initial_unknowns.iter().find(named);
        out.push(ArrayOutput {
            declaration,
            vr: layout.arrays + i as u32,
            output,
            initial,
        });
    }
    Ok(out)
}
