//! The array outputs of the FMI 3.0 description (see `fmi3_description.rs`): declared in the
//! source's VendorAnnotations, `<Tool name="actuator-fmus"><Arrays><Array .../></Arrays>`, and
//! checked against the model.

use super::super::model_description::{Model, ResolvedUnknown};
use super::Layout;
use serde::Deserialize;

#[derive(Deserialize)]
pub(super) struct VendorAnnotations {
    #[serde(rename = "Tool", default)]
    tools: Vec<Tool>,
}

#[derive(Deserialize)]
struct Tool {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "Arrays")]
    arrays: Option<Arrays>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Arrays {
    #[serde(rename = "Array", default)]
    arrays: Vec<ArrayDeclaration>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ArrayDeclaration {
    #[serde(rename = "@name")]
    pub(super) name: String,
    #[serde(rename = "@size")]
    pub(super) size: u64,
    #[serde(rename = "@unit")]
    pub(super) unit: Option<String>,
    #[serde(rename = "@description")]
    pub(super) description: Option<String>,
    #[serde(rename = "@dependenciesOf")]
    dependencies_of: String,
}

/// A checked array output: its declaration, value reference and the scalar output whose
/// dependencies it has (as an output, and as an initial unknown if that one is).
pub(super) struct ArrayOutput<'a> {
    pub(super) declaration: ArrayDeclaration,
    pub(super) vr: u32,
    pub(super) output: &'a ResolvedUnknown,
    pub(super) initial: Option<&'a ResolvedUnknown>,
}

/// The array outputs the source declares, checked against `model`.
pub(super) fn array_outputs<'a>(
    source: Option<VendorAnnotations>,
    model: &'a Model,
    layout: &Layout,
) -> Result<Vec<ArrayOutput<'a>>, String> {
    let declarations = source
        .into_iter()
        .flat_map(|a| a.tools)
        .filter(|t| t.name == "actuator-fmus")
        .filter_map(|t| t.arrays)
        .flat_map(|a| a.arrays);
    let mut names = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for (i, declaration) in declarations.enumerate() {
        let context = |e: &str| format!("Arrays: array '{}': {e}", declaration.name);
        if declaration.name.trim().is_empty()
            || !names.insert(declaration.name.clone())
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
