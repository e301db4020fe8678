//! Parsing and checking of `modelDescription/<Model>.xml`, and the shipped model description that
//! build.rs writes from it. Used by build.rs (with `build/codegen.rs`, which writes the Rust
//! code), and by `tests/all/shipped_descriptions.rs` to prove that bad descriptions fail.
//!
//! A source description holds only the model's own: its variables, units, default experiment and
//! output dependencies (by variable name). The export layer's part is written here: the
//! `<CoSimulation>` block, the `<LogCategories>`, the 1-based ModelStructure indices and the GUID.

use serde::de::IgnoredAny;
use serde::Deserialize;
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

#[path = "rules.rs"]
pub mod rules;

const GUID_PLACEHOLDER: &str = "@GUID@";

// The export layer's part of every shipped description: log categories and capabilities.
include!("export_layer.rs");

#[derive(Deserialize)]
struct ModelDescription {
    #[serde(rename = "@fmiVersion")]
    fmi_version: String,
    #[serde(rename = "@modelName")]
    model_name: String,
    #[serde(rename = "@guid")]
    guid: String,
    #[serde(rename = "@description", default)]
    description: String,
    #[serde(rename = "@numberOfEventIndicators")]
    number_of_event_indicators: Option<String>,
    #[serde(rename = "CoSimulation")]
    co_simulation: Option<IgnoredAny>,
    #[serde(rename = "ModelExchange")]
    model_exchange: Option<IgnoredAny>,
    #[serde(rename = "LogCategories")]
    log_categories: Option<IgnoredAny>,
    #[serde(rename = "UnitDefinitions", default)]
    unit_definitions: UnitDefinitions,
    #[serde(rename = "TypeDefinitions", default)]
    type_definitions: TypeDefinitions,
    #[serde(rename = "ModelVariables")]
    model_variables: ModelVariables,
    #[serde(rename = "ModelStructure", default)]
    model_structure: ModelStructure,
}

#[derive(Deserialize, Default)]
struct UnitDefinitions {
    #[serde(rename = "Unit", default)]
    units: Vec<Named>,
}

/// Only Enumeration types: a variable's unit is given directly (see `check_variable`).
#[derive(Deserialize, Default)]
struct TypeDefinitions {
    #[serde(rename = "SimpleType", default)]
    types: Vec<SimpleType>,
}

#[derive(Deserialize)]
struct SimpleType {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "Enumeration")]
    enumeration: Option<EnumerationType>,
}

#[derive(Deserialize)]
struct EnumerationType {
    #[serde(rename = "Item", default)]
    items: Vec<Item>,
}

#[derive(Deserialize)]
struct Item {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@value")]
    value: i32,
}

#[derive(Deserialize)]
struct Named {
    #[serde(rename = "@name")]
    name: String,
}

#[derive(Deserialize)]
struct ModelVariables {
    #[serde(rename = "ScalarVariable", default)]
    variables: Vec<ScalarVariable>,
}

#[derive(Deserialize)]
struct ScalarVariable {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@valueReference")]
    value_reference: u32,
    #[serde(rename = "@description", default)]
    description: String,
    #[serde(rename = "@causality", default = "default_causality")]
    causality: String,
    #[serde(rename = "@variability", default = "default_variability")]
    variability: String,
    #[serde(rename = "@initial")]
    initial: Option<String>,
    #[serde(rename = "Real")]
    real: Option<TypeAttributes>,
    #[serde(rename = "Integer")]
    integer: Option<TypeAttributes>,
    #[serde(rename = "Boolean")]
    boolean: Option<TypeAttributes>,
    #[serde(rename = "String")]
    string: Option<TypeAttributes>,
    /// Travels as an Integer through fmi2Set/GetInteger (FMI 2.0 section 2.2.7).
    #[serde(rename = "Enumeration")]
    enumeration: Option<TypeAttributes>,
}

fn default_causality() -> String {
    "local".into()
}
fn default_variability() -> String {
    "continuous".into()
}

#[derive(Deserialize)]
struct TypeAttributes {
    #[serde(rename = "@start")]
    start: Option<String>,
    #[serde(rename = "@min")]
    min: Option<String>,
    #[serde(rename = "@max")]
    max: Option<String>,
    #[serde(rename = "@unit")]
    unit: Option<String>,
    #[serde(rename = "@declaredType")]
    declared_type: Option<String>,
    /// In the source, the NAME of the state this variable is the derivative of; the shipped
    /// description gets its index.
    #[serde(rename = "@derivative")]
    derivative: Option<String>,
    #[serde(rename = "@nominal")]
    nominal: Option<String>,
}

#[derive(Deserialize, Default)]
struct ModelStructure {
    #[serde(rename = "Outputs", default)]
    outputs: Unknowns,
    #[serde(rename = "Derivatives", default)]
    derivatives: Unknowns,
    #[serde(rename = "InitialUnknowns", default)]
    initial_unknowns: Unknowns,
}

#[derive(Deserialize, Default)]
struct Unknowns {
    #[serde(rename = "Unknown", default)]
    unknowns: Vec<Unknown>,
}

/// `<Unknown name="force" dependencies="pressure length" dependenciesKind="dependent dependent"/>`
#[derive(Deserialize)]
struct Unknown {
    #[serde(rename = "@name")]
    name: Option<String>,
    #[serde(rename = "@index")]
    index: Option<IgnoredAny>,
    #[serde(rename = "@dependencies")]
    dependencies: Option<String>,
    #[serde(rename = "@dependenciesKind")]
    dependencies_kind: Option<String>,
}

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
}

/// Checks the model description `text` of file `<stem>.xml`; the error says what is wrong.
pub fn check(text: &str, stem: &str) -> Result<Model, String> {
    let md: ModelDescription =
        quick_xml::de::from_str(text).map_err(|e| format!("cannot parse: {e}"))?;
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
    rules::check(text)?;
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
        description: md.description,
        variables,
        counts,
        outputs,
        initial_unknowns,
        derivatives,
        states,
        event_indicators,
        shipped_xml: rendered.replacen(GUID_PLACEHOLDER, &guid, 1),
        guid,
    })
}

/// The (lowest, highest) item value of each Enumeration type by name. The items must be the
/// consecutive integers from the lowest: the export layer checks an Integer against its min and
/// max, which then admit exactly the items.
fn check_enumerations(types: &TypeDefinitions) -> Result<BTreeMap<String, (i32, i32)>, String> {
    let mut out = BTreeMap::new();
    for t in &types.types {
        let Some(e) = &t.enumeration else {
            return Err(format!(
                "type '{}': only Enumeration types are supported; give a Real's unit directly",
                t.name
            ));
        };
        let first = e.items.first().map(|i| i.value).ok_or(format!(
            "type '{}': an Enumeration needs at least one Item",
            t.name
        ))?;
        let mut item_names = BTreeSet::new();
        for (k, item) in e.items.iter().enumerate() {
            if item.value != first + k as i32 {
                return Err(format!(
                    "type '{}': item '{}' has value {}, expected {} (consecutive values in order)",
                    t.name,
                    item.name,
                    item.value,
                    first + k as i32
                ));
            }
            if !item_names.insert(item.name.as_str()) {
                return Err(format!(
                    "type '{}': item '{}' appears twice",
                    t.name, item.name
                ));
            }
        }
        let last = first + e.items.len() as i32 - 1;
        if out.insert(t.name.clone(), (first, last)).is_some() {
            return Err(format!("type '{}' is defined twice", t.name));
        }
    }
    Ok(out)
}

/// FMI 2.0 section 2.2.7: which causality/variability pairs exist and which `initial` each allows.
/// An Enumeration variable becomes an Integer (type index 1) whose min and max default to its
/// type's items.
fn check_variable(
    v: &ScalarVariable,
    units: &BTreeSet<&str>,
    enumerations: &BTreeMap<String, (i32, i32)>,
) -> Result<Variable, String> {
    let typed = [&v.real, &v.integer, &v.boolean, &v.string, &v.enumeration];
    let present: Vec<usize> = (0..5).filter(|&t| typed[t].is_some()).collect();
    let [present_index] = present[..] else {
        return Err("needs exactly one of Real, Integer, Boolean, String, Enumeration".into());
    };
    let attrs = typed[present_index].as_ref().expect("checked present");
    let mut enumeration_range = None;
    if present_index == 4 {
        let declared = attrs
            .declared_type
            .as_deref()
            .ok_or("an Enumeration needs a declaredType")?;
        let range = enumerations.get(declared).ok_or(format!(
            "declaredType '{declared}' is not an Enumeration in TypeDefinitions"
        ))?;
        enumeration_range = Some(*range);
    } else if attrs.declared_type.is_some() {
        return Err(
            "declaredType is supported for Enumerations only; give the unit directly".into(),
        );
    }
    let type_index = if present_index == 4 { 1 } else { present_index };
    let (causality, variability) = (v.causality.as_str(), v.variability.as_str());
    // Case letters of the spec's table: which initial values are legal, the first being the default.
    // Tunable parameters are accepted: the export layer rebuilds the model when one changes
    // between steps (src/export/instance/values.rs).
    let allowed: &[&'static str] = match (variability, causality) {
        ("constant", "output" | "local") => &["exact"],
        ("fixed" | "tunable", "parameter") => &["exact"],
        ("fixed" | "tunable", "calculatedParameter" | "local") => &["calculated", "approx"],
        ("discrete" | "continuous", "input") => &[],
        ("discrete" | "continuous", "output" | "local") => &["calculated", "exact", "approx"],
        ("continuous", "independent") => &[],
        _ => {
            return Err(format!(
                "causality '{causality}' with variability '{variability}' is not allowed"
            ))
        }
    };
    if variability == "continuous" && type_index != 0 {
        return Err("only Real variables can be continuous".into());
    }
    let initial: &'static str = match &v.initial {
        None => allowed.first().copied().unwrap_or("none"),
        Some(i) => allowed.iter().copied().find(|a| *a == i).ok_or_else(|| {
            format!(
                "initial '{i}' is not allowed for {causality}/{variability} (allowed: {allowed:?})"
            )
        })?,
    };
    let needs_start = matches!(initial, "exact" | "approx") || causality == "input";
    match (needs_start, &attrs.start) {
        (true, None) => return Err("needs a start value".into()),
        (false, Some(_)) => {
            return Err(format!("must not have a start value (initial '{initial}')"))
        }
        _ => {}
    }
    let (mut min, mut max) = (attrs.min.clone(), attrs.max.clone());
    if let Some((first, last)) = enumeration_range {
        for (bound, value) in [("min", &min), ("max", &max), ("start", &attrs.start)] {
            if let Some(text) = value {
                match text.trim().parse::<i32>() {
                    Ok(x) if (first..=last).contains(&x) => {}
                    _ => {
                        return Err(format!(
                            "{bound} '{text}' is not an item value ({first} .. {last})"
                        ))
                    }
                }
            }
        }
        min.get_or_insert(first.to_string());
        max.get_or_insert(last.to_string());
    }
    if type_index == 0 {
        let unit = attrs
            .unit
            .as_deref()
            .ok_or("every Real needs a unit (use \"1\" for numbers)")?;
        if !units.contains(unit) {
            return Err(format!("unit '{unit}' is not defined in UnitDefinitions"));
        }
    }
    if field_name(&v.name).is_empty() {
        return Err("the name has no letter or digit for a Rust field".into());
    }
    Ok(Variable {
        name: v.name.clone(),
        description: v.description.clone(),
        type_index,
        value_reference: v.value_reference,
        causality: v.causality.clone(),
        variability: v.variability.clone(),
        initial,
        start: attrs.start.clone(),
        min,
        max,
        unit: attrs.unit.clone(),
        derivative_of: attrs.derivative.clone(),
        nominal: attrs.nominal.clone(),
    })
}

/// FMI 2.0 sections 2.2.7 and 3.1: the continuous states are the variables that a derivative
/// variable names in its `derivative` attribute (here by name). Returns (state, derivative) pairs
/// in the order the derivatives are declared, which is the state-vector order.
fn resolve_states(variables: &[Variable]) -> Result<Vec<(usize, usize)>, String> {
    let mut states: Vec<(usize, usize)> = Vec::new();
    for (d, v) in variables.iter().enumerate() {
        let Some(name) = v.derivative_of.as_deref() else {
            continue;
        };
        let at = |e: String| format!("variable '{}': {e}", v.name);
        if name.trim().parse::<usize>().is_ok() {
            return Err(at(format!(
                "derivative=\"{name}\": name the state; build.rs writes its index"
            )));
        }
        let s = variables
            .iter()
            .position(|x| x.name == name)
            .ok_or_else(|| at(format!("derivative=\"{name}\" is not a variable")))?;
        let state = &variables[s];
        if v.type_index != 0 || v.variability != "continuous" {
            return Err(at("a derivative must be a continuous Real".into()));
        }
        if v.causality != "local" || v.initial != "calculated" {
            return Err(at(
                "a derivative must be a local with initial 'calculated' (the model computes it)"
                    .into(),
            ));
        }
        if s == d {
            return Err(at("a variable cannot be its own derivative".into()));
        }
        if state.type_index != 0
            || state.variability != "continuous"
            || !matches!(state.causality.as_str(), "output" | "local")
        {
            return Err(at(format!(
                "the state '{name}' must be a continuous Real output or local"
            )));
        }
        if state.initial != "calculated" {
            return Err(at(format!(
                "the state '{name}' must have initial 'calculated': the model computes the start \
                 state in Model::new (give a start value as a parameter)"
            )));
        }
        if state.derivative_of.is_some() {
            return Err(at(format!(
                "the state '{name}' is itself a derivative; declare its own state variable"
            )));
        }
        if let Some(&(_, other)) = states.iter().find(|(x, _)| *x == s) {
            return Err(at(format!(
                "the state '{name}' already has the derivative '{}'",
                variables[other].name
            )));
        }
        states.push((s, d));
    }
    for (i, v) in variables.iter().enumerate() {
        if v.causality == "local" && !states.iter().any(|&(s, d)| s == i || d == i) {
            return Err(format!(
                "variable '{}': a local must be a continuous state or a state derivative \
                 (other locals have no typed group)",
                v.name
            ));
        }
    }
    Ok(states)
}

const DEPENDENCY_KINDS: [&str; 5] = ["dependent", "constant", "fixed", "tunable", "discrete"];

type Structure = (
    Vec<ResolvedUnknown>,
    Vec<ResolvedUnknown>,
    Vec<ResolvedUnknown>,
);

/// FMI 2.0 section 2.2.8. Outputs: every output, in order. Derivatives: every state derivative,
/// in state order. InitialUnknowns: outputs and locals (states, derivatives) with initial
/// calculated or approx and every calculated parameter, ascending. The source lists each by name
/// with its dependencies, and must: an unknown without a declared list is refused. Outputs and
/// derivatives depend on the knowns: inputs and continuous states.
fn resolve_structure(
    md: &ModelStructure,
    variables: &[Variable],
    states: &[(usize, usize)],
) -> Result<Structure, String> {
    let expected_outputs: Vec<usize> = (0..variables.len())
        .filter(|&i| variables[i].causality == "output")
        .collect();
    let expected_derivatives: Vec<usize> = states.iter().map(|&(_, d)| d).collect();
    let expected_initial: Vec<usize> = (0..variables.len())
        .filter(|&i| {
            let v = &variables[i];
            (matches!(v.causality.as_str(), "output" | "local")
                && matches!(v.initial, "calculated" | "approx"))
                || v.causality == "calculatedParameter"
        })
        .collect();
    let state_names: Vec<&str> = states
        .iter()
        .map(|&(s, _)| variables[s].name.as_str())
        .collect();
    let known = |v: &Variable| v.causality == "input" || state_names.contains(&v.name.as_str());
    let outputs = resolve_list(
        "Outputs",
        &md.outputs,
        &expected_outputs,
        variables,
        known,
        "an input or a continuous state",
    )?;
    let derivatives = resolve_list(
        "Derivatives",
        &md.derivatives,
        &expected_derivatives,
        variables,
        known,
        "an input or a continuous state",
    )?;
    let initial = resolve_list(
        "InitialUnknowns",
        &md.initial_unknowns,
        &expected_initial,
        variables,
        |v| v.causality == "input" || v.initial == "exact",
        "an input or a variable with initial 'exact'",
    )?;
    Ok((outputs, derivatives, initial))
}

fn resolve_list(
    list: &str,
    source: &Unknowns,
    expected: &[usize],
    variables: &[Variable],
    may_depend_on: impl Fn(&Variable) -> bool,
    allowed: &str,
) -> Result<Vec<ResolvedUnknown>, String> {
    let index_of: BTreeMap<&str, usize> = variables
        .iter()
        .enumerate()
        .map(|(i, v)| (v.name.as_str(), i))
        .collect();
    let mut given: BTreeMap<usize, ResolvedUnknown> = BTreeMap::new();
    for u in &source.unknowns {
        let context = |e: String| format!("ModelStructure/{list}: {e}");
        if u.index.is_some() {
            return Err(context(
                "give the unknown by name=\"...\"; build.rs writes the index".into(),
            ));
        }
        let name = u
            .name
            .as_deref()
            .ok_or_else(|| context("an Unknown needs a name".into()))?;
        let &i = index_of
            .get(name)
            .ok_or_else(|| context(format!("'{name}' is not a variable")))?;
        if !expected.contains(&i) {
            return Err(context(format!(
                "'{name}' does not belong in this list (FMI 2.0 section 2.2.8)"
            )));
        }
        let names: Option<Vec<&str>> = u
            .dependencies
            .as_deref()
            .map(|d| d.split_whitespace().collect());
        let kinds: Option<Vec<&str>> = u
            .dependencies_kind
            .as_deref()
            .map(|d| d.split_whitespace().collect());
        let mut pairs: Vec<(usize, Option<&str>)> = Vec::new();
        match (&names, &kinds) {
            (None, Some(_)) => {
                return Err(context(format!(
                    "'{name}' has dependenciesKind without dependencies"
                )))
            }
            (Some(n), Some(k)) if n.len() != k.len() => {
                return Err(context(format!(
                    "'{name}' has {} dependencies but {} dependenciesKind",
                    n.len(),
                    k.len()
                )))
            }
            _ => {}
        }
        for (j, dep) in names.iter().flatten().enumerate() {
            let &d = index_of
                .get(dep)
                .ok_or_else(|| context(format!("'{name}' depends on '{dep}', not a variable")))?;
            if !may_depend_on(&variables[d]) {
                return Err(context(format!(
                    "'{name}' may depend only on {allowed}, not on '{dep}'"
                )));
            }
            let kind = kinds.as_ref().map(|k| k[j]);
            if let Some(k) = kind.filter(|k| !DEPENDENCY_KINDS.contains(k)) {
                return Err(context(format!(
                    "dependenciesKind '{k}' of '{name}' is not one of {DEPENDENCY_KINDS:?}"
                )));
            }
            if pairs.iter().any(|(p, _)| *p == d + 1) {
                return Err(context(format!("'{name}' lists '{dep}' twice")));
            }
            pairs.push((d + 1, kind));
        }
        // The spec orders the dependency indices by magnitude.
        pairs.sort_unstable_by_key(|(d, _)| *d);
        let resolved = ResolvedUnknown {
            index: i + 1,
            dependencies: names.as_ref().map(|_| pairs.iter().map(|p| p.0).collect()),
            kinds: kinds.as_ref().map(|_| {
                pairs
                    .iter()
                    .map(|p| p.1.unwrap_or_default().to_string())
                    .collect()
            }),
        };
        if given.insert(i, resolved).is_some() {
            return Err(context(format!("'{name}' is listed twice")));
        }
    }
    // Every output and initial unknown declares its dependencies (an empty list where
    // it depends on none), so masters need not assume that everything depends on everything.
    expected
        .iter()
        .map(|&i| match given.remove(&i) {
            Some(u) if u.dependencies.is_some() => Ok(u),
            _ => Err(format!(
                "ModelStructure/{list}: '{}' declares no dependencies; list it as <Unknown \
                 name=\"{}\" dependencies=\"...\" dependenciesKind=\"...\"/> \
                 (dependencies=\"\" where it depends on none)",
                variables[i].name, variables[i].name
            )),
        })
        .collect()
}

/// Byte offsets in the source where the export layer's parts go.
#[derive(Default)]
struct Splices {
    /// Right after the `<fmiModelDescription ...>` start tag.
    after_root: usize,
    /// Before the first of DefaultExperiment, VendorAnnotations, ModelVariables.
    log_categories: Option<usize>,
    /// Before each ScalarVariable.
    variables: Vec<usize>,
    /// The source's ModelStructure element, start and end.
    model_structure: Option<(usize, usize)>,
    /// The source's `<Tool><Terminals>` element (the FMI 3.0 flanges, `build/terminals.rs`),
    /// from the start of its line: FMI 2.0's schema allows a Tool one element, its `<Tests>`.
    terminals: Option<(usize, usize)>,
}

fn find_splices(text: &str) -> Result<Splices, String> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    let mut splices = Splices::default();
    let mut depth = 0usize;
    let mut structure_start = None;
    let mut terminals_start = None;
    loop {
        let before = reader.buffer_position() as usize;
        let event = reader
            .read_event()
            .map_err(|e| format!("cannot parse: {e}"))?;
        let after = reader.buffer_position() as usize;
        let (name, empty) = match &event {
            Event::Start(e) => (e.local_name().as_ref().to_vec(), false),
            Event::Empty(e) => (e.local_name().as_ref().to_vec(), true),
            Event::End(_) => {
                depth -= 1;
                if depth == 1 {
                    if let Some(start) = structure_start.take() {
                        splices.model_structure = Some((start, after));
                    }
                }
                if depth == 3 {
                    if let Some(start) = terminals_start.take() {
                        splices.terminals = Some((start, after));
                    }
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        match (depth, name.as_slice()) {
            (0, b"fmiModelDescription") => splices.after_root = after,
            (1, b"DefaultExperiment" | b"VendorAnnotations" | b"ModelVariables") => {
                splices.log_categories.get_or_insert(before);
            }
            (1, b"ModelStructure") if empty => splices.model_structure = Some((before, after)),
            (1, b"ModelStructure") => structure_start = Some(before),
            (3, b"Terminals") => {
                let line = text[..before].rfind('\n').unwrap_or(before);
                if empty {
                    splices.terminals = Some((line, after));
                } else {
                    terminals_start = Some(line);
                }
            }
            (2, b"ScalarVariable") => splices.variables.push(before),
            _ => {}
        }
        if !empty {
            depth += 1;
        }
    }
    Ok(splices)
}

/// The model description as shipped (GUID still the placeholder): the source with the export
/// layer's `<CoSimulation>` and `<LogCategories>`, an index comment before each variable, and the
/// ModelStructure with 1-based indices.
fn shipped(
    text: &str,
    stem: &str,
    variables: &[Variable],
    states: &[(usize, usize)],
    lists: &[(&str, &[ResolvedUnknown])],
) -> Result<String, String> {
    let s = find_splices(text)?;
    // Every model serves both interfaces and its exact partials: the registry's test
    // (`src/export/registry.rs`) checks each model against this, so that no list names them.
    let mut inserts: Vec<(usize, usize, String)> = Vec::new();
    inserts.push((
        s.after_root,
        s.after_root,
        format!(
            "\n\n  <!-- Written by build.rs: the export layer's capabilities. -->\n  <ModelExchange\n    modelIdentifier=\"{stem}\"\n    {MODEL_EXCHANGE_CAPABILITIES}\n    providesDirectionalDerivative=\"true\"/>\n  <CoSimulation\n    modelIdentifier=\"{stem}\"\n    {CO_SIMULATION_CAPABILITIES}\n    providesDirectionalDerivative=\"true\"/>"
        ),
    ));
    let mut log = String::from("<LogCategories>\n");
    for (name, description) in LOG_CATEGORIES {
        let _ = writeln!(
            log,
            "    <Category name=\"{name}\" description=\"{description}\"/>"
        );
    }
    log.push_str("  </LogCategories>\n\n  ");
    let at = s.log_categories.ok_or("no ModelVariables element found")?;
    inserts.push((at, at, log));
    if let Some((start, end)) = s.terminals {
        inserts.push((start, end, String::new()));
    }
    for (i, &at) in s.variables.iter().enumerate() {
        inserts.push((at, at, format!("<!-- {} -->", i + 1)));
    }
    let mut structure = String::from("<ModelStructure>\n");
    for &(list, unknowns) in lists {
        if unknowns.is_empty() {
            continue;
        }
        let _ = writeln!(structure, "    <{list}>");
        for u in unknowns {
            let mut attributes = format!("index=\"{}\"", u.index);
            if let Some(d) = &u.dependencies {
                let d: Vec<String> = d.iter().map(|i| i.to_string()).collect();
                let _ = write!(attributes, " dependencies=\"{}\"", d.join(" "));
            }
            if let Some(k) = &u.kinds {
                let _ = write!(attributes, " dependenciesKind=\"{}\"", k.join(" "));
            }
            let _ = writeln!(
                structure,
                "      <Unknown {attributes}/> <!-- {} -->",
                variables[u.index - 1].name
            );
        }
        let _ = writeln!(structure, "    </{list}>");
    }
    structure.push_str("  </ModelStructure>");
    match s.model_structure {
        Some((start, end)) => inserts.push((start, end, structure)),
        None => {
            // No ModelStructure in the source: it goes before the closing root tag.
            let end = text
                .rfind("</fmiModelDescription>")
                .ok_or("no closing </fmiModelDescription>")?;
            inserts.push((end, end, format!("\n  {structure}\n")));
        }
    }
    inserts.sort_by_key(|(start, _, _)| *start);
    let mut out = String::with_capacity(text.len() + 4096);
    let mut cursor = 0;
    for (start, end, insert) in inserts {
        out.push_str(&text[cursor..start]);
        out.push_str(&insert);
        cursor = end;
    }
    out.push_str(&text[cursor..]);
    // Each derivative names its state in the source; the shipped description gives the index.
    for &(state, derivative) in states {
        let named = format!("derivative=\"{}\"", variables[state].name);
        if out.matches(&named).count() != 1 {
            return Err(format!(
                "variable '{}': {named} must appear exactly once in the description",
                variables[derivative].name
            ));
        }
        out = out.replacen(&named, &format!("derivative=\"{}\"", state + 1), 1);
    }
    Ok(out)
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
