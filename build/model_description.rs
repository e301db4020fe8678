//! Checking of `modelDescription/<Model>.xml` (read once, into the typed `description.rs`), and
//! the shipped model description that build.rs writes from it. Used by build.rs (with
//! `build/codegen.rs`, which writes the Rust code), and by `tests/all/shipped_descriptions.rs` to
//! prove that bad descriptions fail.
//!
//! A source description holds only the model's own: its variables, units, default experiment and
//! output dependencies (by variable name). The export layer's part is written here: the
//! `<CoSimulation>` block, the `<LogCategories>`, the 1-based ModelStructure indices and the GUID.

use sha2::{Digest, Sha256};
use std::collections::BTreeSet;

#[path = "description.rs"]
pub mod description;
#[path = "rules.rs"]
pub mod rules;
#[path = "shipped_xml.rs"]
mod shipped_xml;
#[path = "variable_checks.rs"]
mod variable_checks;

use shipped_xml::shipped;
use variable_checks::{check_enumerations, check_variable, resolve_states, resolve_structure};

const GUID_PLACEHOLDER: &str = "@GUID@";

// The export layer's part of every shipped description: log categories and capabilities.
include!("export_layer.rs");

pub const TYPES: [&str; 4] = ["Real", "Integer", "Boolean", "String"];

/// One checked `ScalarVariable`, owned, for the code generator.
pub struct Variable {
    pub name: String,
    pub description: String,
    /// Index into [`TYPES`].
    pub type_index: usize,
    pub value_reference: u32,
    pub causality: String,
    pub variability: String,
    /// The `initial` in effect ("none" for inputs and the independent variable).
    pub initial: &'static str,
    pub start: Option<String>,
    pub min: Option<String>,
    pub max: Option<String>,
    pub unit: Option<String>,
    /// The state this variable is the derivative of (source: by name).
    pub derivative_of: Option<String>,
    pub nominal: Option<String>,
}

/// One ModelStructure entry with 1-based indices.
#[derive(Debug, PartialEq)]
pub struct ResolvedUnknown {
    pub index: usize,
    /// Ascending indices; `None` when the source declares none (then the attribute is left out).
    pub dependencies: Option<Vec<usize>>,
    pub kinds: Option<Vec<String>>,
}

/// A checked model description: what the code generator and the shipped XML need.
pub struct Model {
    pub name: String,
    pub description: String,
    pub variables: Vec<Variable>,
    /// Number of Real, Integer, Boolean and String variables.
    pub counts: [usize; 4],
    #[allow(dead_code)] // read by tests/all/shipped_descriptions.rs
    pub outputs: Vec<ResolvedUnknown>,
    #[allow(dead_code)]
    pub initial_unknowns: Vec<ResolvedUnknown>,
    #[allow(dead_code)]
    pub derivatives: Vec<ResolvedUnknown>,
    /// The continuous states in state-vector order: (state, derivative) variable indices
    /// (0-based into `variables`), ordered as the derivatives are declared.
    pub states: Vec<(usize, usize)>,
    /// `numberOfEventIndicators`.
    pub event_indicators: usize,
    /// The model description as shipped in the FMU, GUID filled in.
    pub shipped_xml: String,
    pub guid: String,
    /// The source as read, once: the FMI 3.0 description, its array outputs and its terminals are
    /// written from it.
    pub source: description::Description,
}

/// Checks the model description `text` of file `<stem>.xml`; the error says what is wrong.
pub fn check(text: &str, stem: &str) -> Result<Model, String> {
    let md = description::parse(text)?;
    if md.fmi_version != "2.0" {
        return Err(format!("fmiVersion must be 2.0, found {}", md.fmi_version));
    }
    if md.model_name != stem {
        return Err(format!("modelName must equal the file name '{stem}'"));
    }
    if md.guid != GUID_PLACEHOLDER {
        return Err(format!(
            "guid must be the placeholder \"{GUID_PLACEHOLDER}\"; build.rs fills it in"
        ));
    }
    for (present, element) in [
        (md.co_simulation.is_some(), "CoSimulation"),
        (md.model_exchange.is_some(), "ModelExchange"),
        (md.log_categories.is_some(), "LogCategories"),
    ] {
        if present {
            return Err(format!(
                "<{element}> belongs to the export layer: build.rs writes it, remove it from the source"
            ));
        }
    }
    let units: BTreeSet<&str> = md
        .unit_definitions
        .units
        .iter()
        .map(|u| u.name.as_str())
        .collect();
    if units.len() != md.unit_definitions.units.len() {
        return Err("a unit is defined twice in UnitDefinitions".into());
    }

    let enumerations = check_enumerations(&md.type_definitions)?;
    let mut variables = Vec::new();
    let mut names = BTreeSet::new();
    let mut field_names = BTreeSet::new();
    for v in &md.model_variables.variables {
        let c = check_variable(v, &units, &enumerations)
            .map_err(|e| format!("variable '{}': {e}", v.name))?;
        if !names.insert(v.name.as_str()) {
            return Err(format!("variable name '{}' is used twice", v.name));
        }
        if !field_names.insert(field_name(&v.name)) {
            return Err(format!(
                "variable '{}' has the same Rust field name as another, '{}'",
                v.name,
                field_name(&v.name)
            ));
        }
        variables.push(c);
    }
    // Value references are dense per type so that the export layer indexes arrays directly.
    let mut counts = [0usize; 4];
    for (t, count) in counts.iter_mut().enumerate() {
        let mut vrs: Vec<u32> = variables
            .iter()
            .filter(|c| c.type_index == t)
            .map(|c| c.value_reference)
            .collect();
        vrs.sort_unstable();
        *count = vrs.len();
        if vrs.iter().enumerate().any(|(i, &vr)| vr as usize != i) {
            return Err(format!(
                "{} value references must be 0..{} without gaps or repeats, found {vrs:?}",
                TYPES[t],
                vrs.len()
            ));
        }
    }
    let states = resolve_states(&variables)?;
    let event_indicators = match md.number_of_event_indicators.as_deref() {
        None => 0,
        Some(n) => n.trim().parse::<usize>().map_err(|_| {
            format!("numberOfEventIndicators must be a non-negative integer, got '{n}'")
        })?,
    };
    let (outputs, derivatives, initial_unknowns) =
        resolve_structure(&md.model_structure, &variables, &states)?;
    rules::check_description(&md, rules::Form::Source)?;
    let structure = [
        ("Outputs", outputs.as_slice()),
        ("Derivatives", derivatives.as_slice()),
        ("InitialUnknowns", initial_unknowns.as_slice()),
    ];
    let rendered = shipped(text, stem, &variables, &states, &structure)?;
    // The rules again on what ships: the export layer's part and the resolved indices included.
    rules::check(&rendered).map_err(|e| format!("shipped description: {e}"))?;
    let guid = guid_of(&rendered);
    Ok(Model {
        name: stem.to_string(),
        description: md.description.clone(),
        variables,
        counts,
        outputs,
        initial_unknowns,
        derivatives,
        states,
        event_indicators,
        shipped_xml: rendered.replacen(GUID_PLACEHOLDER, &guid, 1),
        guid,
        source: md,
    })
}

/// A GUID derived from the whole shipped description: any change to a variable changes it.
pub fn guid_of(text: &str) -> String {
    let normalized = text.replace("\r\n", "\n");
    let h = Sha256::digest(normalized.as_bytes());
    let hex: String = h.iter().take(16).map(|b| format!("{b:02x}")).collect();
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    )
}

/// The Rust field name of a variable: `jointPosition` -> `joint_position`, `a.b` -> `a_b`.
pub fn field_name(name: &str) -> String {
    let mut out = String::new();
    let mut prev_lower = false;
    for ch in name.chars() {
        if !ch.is_ascii_alphanumeric() {
            if !out.is_empty() && !out.ends_with('_') {
                out.push('_');
            }
            prev_lower = false;
            continue;
        }
        if ch.is_ascii_uppercase() && prev_lower {
            out.push('_');
        }
        out.push(ch.to_ascii_lowercase());
        prev_lower = ch.is_ascii_lowercase() || ch.is_ascii_digit();
    }
    let out = out.trim_end_matches('_').to_string();
    match out.chars().next() {
        Some(c) if c.is_ascii_digit() => format!("v_{out}"),
        _ => out,
    }
}
