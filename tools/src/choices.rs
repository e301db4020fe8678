//! The named choices of an FMU page: the Enumeration types of a shipped model description, and
//! the values each preset gives, read from the model itself.

use actuator_fmus::export::runtime::Factory;
use actuator_fmus::variables::{Causality, ModelInfo, VarType};

/// One Enumeration type: its name and (value, item name, description) per item.
pub struct Enumeration {
    pub name: String,
    pub items: Vec<(i32, String, String)>,
}

/// The value of attribute `key` in the start tag `tag` (our own XML: double quotes, escaped).
fn attribute(tag: &str, key: &str) -> Option<String> {
    let start = tag.find(&format!(" {key}=\""))? + key.len() + 3;
    let end = tag[start..].find('"')? + start;
    Some(tag[start..end].to_string())
}

/// Start tags `<element ...>` in `text`, in order.
fn tags<'a>(text: &'a str, element: &str) -> std::vec::IntoIter<&'a str> {
    let open = format!("<{element} ");
    text.match_indices(&open)
        .filter_map(|(at, _)| text[at..].find('>').map(|end| &text[at..at + end]))
        .collect::<Vec<_>>()
        .into_iter()
}

/// The Enumeration types of a model description, in order.
pub fn enumerations(xml: &str) -> Vec<Enumeration> {
    let mut out = Vec::new();
    for (at, _) in xml.match_indices("<SimpleType ") {
        let end = xml[at..]
            .find("</SimpleType>")
            .map_or(xml.len(), |e| at + e);
        let block = &xml[at..end];
        let Some(name) = tags(block, "SimpleType")
            .next()
            .and_then(|t| attribute(t, "name"))
        else {
            continue;
        };
        let items = tags(block, "Item")
            .filter_map(|t| {
                let value = attribute(t, "value")?.parse().ok()?;
                Some((
                    value,
                    attribute(t, "name")?,
                    attribute(t, "description").unwrap_or_default(),
                ))
            })
            .collect();
        out.push(Enumeration { name, items });
    }
    out
}

/// (variable name, Enumeration type name) of every Enumeration variable.
pub fn enumeration_variables(xml: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (at, _) in xml.match_indices("<ScalarVariable ") {
        let end = xml[at..]
            .find("</ScalarVariable>")
            .map_or(xml.len(), |e| at + e);
        let block = &xml[at..end];
        let name = tags(block, "ScalarVariable")
            .next()
            .and_then(|t| attribute(t, "name"));
        let declared = tags(block, "Enumeration")
            .next()
            .and_then(|t| attribute(t, "declaredType"));
        if let (Some(name), Some(declared)) = (name, declared) {
            out.push((name, declared));
        }
    }
    out
}

/// For a model with a `preset` Enumeration: each preset's item name and the model's calculated
/// parameters after building with that preset and every other parameter at its start value,
/// as (calculated parameter names and units, rows of (preset, values)).
#[allow(clippy::type_complexity)]
pub fn preset_values(
    factory: &dyn Factory,
    info: &ModelInfo,
) -> Option<(
    Vec<(&'static str, &'static str)>,
    Vec<(String, Vec<String>)>,
)> {
    let preset = info.variables.iter().find(|v| v.name == "preset")?;
    let xml = info.model_description_xml;
    let type_name = enumeration_variables(xml)
        .into_iter()
        .find(|(name, _)| name == "preset")?
        .1;
    let presets = enumerations(xml)
        .into_iter()
        .find(|e| e.name == type_name)?;
    let calculated: Vec<_> = info
        .variables
        .iter()
        .filter(|v| v.causality == Causality::CalculatedParameter)
        .collect();
    let columns = calculated.iter().map(|v| (v.name, v.unit)).collect();
    let mut rows = Vec::new();
    for (value, name, _) in &presets.items {
        let mut runtime = factory.create();
        runtime.set_integer(preset.vr as usize, *value);
        runtime.changed(true);
        let values = match runtime.build() {
            Ok(()) => calculated
                .iter()
                .map(|v| match v.kind {
                    VarType::Real => {
                        crate::package::number(significant(runtime.real(v.vr as usize), 5))
                    }
                    VarType::Integer => {
                        let x = runtime.integer(v.vr as usize);
                        enumeration_variables(xml)
                            .into_iter()
                            .find(|(n, _)| n == v.name)
                            .and_then(|(_, t)| enumerations(xml).into_iter().find(|e| e.name == t))
                            .and_then(|e| e.items.into_iter().find(|i| i.0 == x).map(|i| i.1))
                            .unwrap_or_else(|| x.to_string())
                    }
                    VarType::Boolean => runtime.boolean(v.vr as usize).to_string(),
                    VarType::String => runtime.string(v.vr as usize).to_string(),
                })
                .collect(),
            Err(e) => vec![format!("refused with the start values: {e}")],
        };
        rows.push((name.clone(), values));
    }
    Some((columns, rows))
}

/// `x` rounded to `digits` significant digits: a table read at a glance (the model description
/// and the FMU keep full precision).
fn significant(x: f64, digits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}
