//! The FMI 3.0 model description of a model, written from the same checked source as the FMI 2.0
//! one (`model_description::check`), and the tables `src/fmi3` needs to serve it
//! (`$OUT_DIR/fmi3_tables.rs`).
//!
//! FMI 3.0 gives every variable one value reference, unique over all types (FMI 3.0 section
//! 2.4.7), and asks for an independent variable and for event indicators that are variables. The
//! value references are therefore laid out as:
//! - the Float64 variables keep their FMI 2.0 Real value references `0..nReal`;
//! - `time`, the independent variable, is `nReal`;
//! - the event indicators (local Float64) follow: `nReal + 1 + k`;
//! - then the Int32 and Enumeration variables (FMI 2.0 Integer `i`): `nReal + 1 + nEvent + i`;
//! - then the Booleans (FMI 2.0 Boolean `b`): after the integers;
//! - then the array outputs, FMI 3.0's own (FMI 2.0 has no arrays).
//!
//! An array output is declared in the source's VendorAnnotations, which the FMI 2.0 description
//! ships without (`shipped_xml.rs`):
//!
//! ```xml
//! <Arrays><Array name="wall_radius" size="9" unit="m" dependenciesOf="stress_hoop"/></Arrays>
//! ```
//!
//! It is a continuous `Float64` output with a fixed `<Dimension start="size"/>`: a Dimension that
//! names a variable must name a UInt64 structural parameter, which an importer may change only in
//! Configuration Mode (FMI 3.0 section 2.3), so no parameter an FMI 2.0 importer sets can size it.
//! Its dependencies, as an output and as an initial unknown, are those of the scalar output it
//! names in `dependenciesOf`.

#[path = "fmi3_arrays.rs"]
mod arrays;

use super::model_description::{Model, ResolvedUnknown, Variable};
use arrays::array_outputs;
use std::fmt::Write as _;

/// The FMI 3.0 value reference of each variable of `model` (same order as `model.variables`),
/// and the first value references of the event indicators and of the integers.
pub struct Layout {
    pub vr: Vec<u32>,
    pub time: u32,
    pub event_indicators: u32,
    pub integers: u32,
    pub booleans: u32,
    /// The first array output's value reference.
    pub arrays: u32,
}

pub fn layout(model: &Model) -> Layout {
    let [reals, integers, booleans, _] = model.counts.map(|c| c as u32);
    let time = reals;
    let event_indicators = time + 1;
    let first_integer = event_indicators + model.event_indicators as u32;
    let first_boolean = first_integer + integers;
    let vr = model
        .variables
        .iter()
        .map(|v| match v.type_index {
            0 => v.value_reference,
            1 => first_integer + v.value_reference,
            _ => first_boolean + v.value_reference,
        })
        .collect();
    Layout {
        vr,
        time,
        event_indicators,
        integers: first_integer,
        booleans: first_boolean,
        arrays: first_boolean + booleans,
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The `<UnitDefinitions>` element of the source, verbatim (FMI 3.0 keeps FMI 2.0's `Unit` and
/// `BaseUnit`), with `s` added for `time` when the model does not define it.
fn unit_definitions(text: &str) -> String {
    let start = text.find("<UnitDefinitions>");
    let end = text.find("</UnitDefinitions>");
    let (mut inner, has_s) = match (start, end) {
        (Some(s), Some(e)) => {
            let inner = text[s + "<UnitDefinitions>".len()..e]
                .trim_end()
                .to_string();
            let has_s = inner.contains("<Unit name=\"s\"");
            (inner, has_s)
        }
        _ => (String::new(), false),
    };
    if !has_s {
        inner.push_str("\n    <Unit name=\"s\"><BaseUnit s=\"1\"/></Unit>");
    }
    format!("  <UnitDefinitions>{inner}\n  </UnitDefinitions>\n")
}

/// What `src/fmi3` implements, the same for every model.
const CO_SIMULATION_CAPABILITIES_3: &str = r#"needsExecutionTool="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canGetAndSetFMUState="true"
    canSerializeFMUState="true"
    providesDirectionalDerivatives="true"
    providesAdjointDerivatives="true"
    canHandleVariableCommunicationStepSize="true"
    maxOutputDerivativeOrder="0"
    providesIntermediateUpdate="false"
    mightReturnEarlyFromDoStep="true"
    hasEventMode="true""#;

/// The friction history is committed at completed integrator steps: the importer must call them.
const MODEL_EXCHANGE_CAPABILITIES_3: &str = r#"needsExecutionTool="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canGetAndSetFMUState="true"
    canSerializeFMUState="true"
    providesDirectionalDerivatives="true"
    providesAdjointDerivatives="true"
    needsCompletedIntegratorStep="true""#;

/// The `declaredType` of each variable of the source that is an Enumeration.
fn declared_types(model: &Model) -> Vec<Option<&str>> {
    model
        .source
        .model_variables
        .variables
        .iter()
        .map(|v| {
            v.enumeration
                .as_ref()
                .and_then(|e| e.declared_type.as_deref())
        })
        .collect()
}

/// The FMI 3.0 modelDescription.xml of `model` (checked) from its source `text` (read once, into
/// `model.source`; its `<UnitDefinitions>` are copied as written).
pub fn xml(text: &str, model: &Model) -> Result<String, String> {
    let source = &model.source;
    if model.counts[3] != 0 {
        return Err("FMI 3.0 description: String variables are not exported".into());
    }
    let layout = layout(model);
    let stem = &model.name;
    let mut x = String::new();
    let _ = write!(
        x,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Generated by build.rs from modelDescription/{stem}.xml, the same source as the FMI 2.0 description. Float64 value references equal the FMI 2.0 Real ones; time, the event indicators, Int32/Enumeration and Boolean variables follow. -->\n<fmiModelDescription\n  fmiVersion=\"3.0\"\n  modelName=\"{stem}\"\n  instantiationToken=\"{}\"\n  description=\"{}\"\n  generationTool=\"actuator-fmus\"\n  variableNamingConvention=\"{}\">\n\n",
        model.guid,
        escape(&model.description),
        source.variable_naming_convention.as_deref().unwrap_or("flat"),
    );
    let _ = write!(
        x,
        "  <ModelExchange\n    modelIdentifier=\"{stem}\"\n    {MODEL_EXCHANGE_CAPABILITIES_3}/>\n  <CoSimulation\n    modelIdentifier=\"{stem}\"\n    {CO_SIMULATION_CAPABILITIES_3}/>\n\n"
    );
    x.push_str(&unit_definitions(text));
    if !source.type_definitions.types.is_empty() {
        x.push_str("\n  <TypeDefinitions>\n");
        for t in &source.type_definitions.types {
            let items = t
                .enumeration
                .as_ref()
                .ok_or_else(|| format!("type '{}' is not an Enumeration", t.name))?;
            let description = t
                .description
                .as_deref()
                .map(|d| format!(" description=\"{}\"", escape(d)))
                .unwrap_or_default();
            let _ = writeln!(
                x,
                "    <EnumerationType name=\"{}\"{description}>",
                escape(&t.name)
            );
            for item in &items.items {
                let description = item
                    .description
                    .as_deref()
                    .map(|d| format!(" description=\"{}\"", escape(d)))
                    .unwrap_or_default();
                let _ = writeln!(
                    x,
                    "      <Item name=\"{}\" value=\"{}\"{description}/>",
                    escape(&item.name),
                    item.value
                );
            }
            x.push_str("    </EnumerationType>\n");
        }
        x.push_str("  </TypeDefinitions>\n");
    }
    x.push_str("\n  <LogCategories>\n");
    for (name, description) in super::model_description::LOG_CATEGORIES {
        let _ = writeln!(
            x,
            "    <Category name=\"{name}\" description=\"{description}\"/>"
        );
    }
    x.push_str("  </LogCategories>\n");
    if let Some(e) = &source.default_experiment {
        x.push_str("\n  <DefaultExperiment");
        for (name, value) in [
            ("startTime", &e.start_time),
            ("stopTime", &e.stop_time),
            ("tolerance", &e.tolerance),
            ("stepSize", &e.step_size),
        ] {
            if let Some(v) = value {
                let _ = write!(x, " {name}=\"{}\"", escape(v));
            }
        }
        x.push_str("/>\n");
    }
    x.push_str("\n  <ModelVariables>\n");
    let _ = writeln!(
        x,
        "    <Float64 name=\"time\" valueReference=\"{}\" causality=\"independent\" variability=\"continuous\" unit=\"s\" description=\"Simulation time\"/>",
        layout.time
    );
    let declared = declared_types(model);
    if declared.len() != model.variables.len() {
        return Err("FMI 3.0 description: the variables do not match the checked model".into());
    }
    for (i, v) in model.variables.iter().enumerate() {
        x.push_str(&variable(v, layout.vr[i], declared[i], model)?);
    }
    for k in 0..model.event_indicators {
        let _ = writeln!(
            x,
            "    <Float64 name=\"event_indicator[{}]\" valueReference=\"{}\" causality=\"local\" variability=\"continuous\" initial=\"calculated\" description=\"Event indicator {} of the model (zero crossings are events in Model Exchange)\"/>",
            k + 1,
            layout.event_indicators + k as u32,
            k + 1
        );
    }
    let arrays = array_outputs(model, &layout)?;
    for a in &arrays {
        let d = &a.declaration;
        let mut attributes = format!("name=\"{}\" valueReference=\"{}\"", escape(&d.name), a.vr);
        if let Some(description) = &d.description {
            let _ = write!(attributes, " description=\"{}\"", escape(description));
        }
        attributes
            .push_str(" causality=\"output\" variability=\"continuous\" initial=\"calculated\"");
        if let Some(unit) = &d.unit {
            let _ = write!(attributes, " unit=\"{}\"", escape(unit));
        }
        let _ = writeln!(
            x,
            "    <Float64 {attributes}>\n      <Dimension start=\"{}\"/>\n    </Float64>",
            d.size
        );
    }
    x.push_str("  </ModelVariables>\n\n  <ModelStructure>\n");
    let unknown = |x: &mut String, element: &str, u: &ResolvedUnknown, vr: u32, name: &str| {
        let mut attributes = format!("valueReference=\"{vr}\"");
        if let Some(d) = &u.dependencies {
            let pairs = sorted_dependencies(&layout, d, u.kinds.as_deref());
            let d: Vec<String> = pairs.iter().map(|(vr, _)| vr.to_string()).collect();
            let _ = write!(attributes, " dependencies=\"{}\"", d.join(" "));
            if u.kinds.is_some() {
                let k: Vec<&str> = pairs.iter().map(|(_, k)| *k).collect();
                let _ = write!(attributes, " dependenciesKind=\"{}\"", k.join(" "));
            }
        }
        let _ = writeln!(x, "    <{element} {attributes}/> <!-- {name} -->");
    };
    let scalar = |u: &ResolvedUnknown| (layout.vr[u.index - 1], &model.variables[u.index - 1].name);
    for u in &model.outputs {
        let (vr, name) = scalar(u);
        unknown(&mut x, "Output", u, vr, name);
    }
    for a in &arrays {
        unknown(&mut x, "Output", a.output, a.vr, &a.declaration.name);
    }
    for u in &model.derivatives {
        let (vr, name) = scalar(u);
        unknown(&mut x, "ContinuousStateDerivative", u, vr, name);
    }
    for u in &model.initial_unknowns {
        let (vr, name) = scalar(u);
        unknown(&mut x, "InitialUnknown", u, vr, name);
    }
    for a in &arrays {
        if let Some(u) = a.initial {
            unknown(&mut x, "InitialUnknown", u, a.vr, &a.declaration.name);
        }
    }
    for k in 0..model.event_indicators {
        let _ = writeln!(
            x,
            "    <EventIndicator valueReference=\"{}\"/>",
            layout.event_indicators + k as u32
        );
    }
    x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    Ok(x)
}

fn variable(
    v: &Variable,
    vr: u32,
    declared: Option<&str>,
    model: &Model,
) -> Result<String, String> {
    let element = match (v.type_index, declared) {
        (0, _) => "Float64",
        (1, Some(_)) => "Enumeration",
        (1, None) => "Int32",
        (2, _) => "Boolean",
        _ => return Err(format!("variable '{}': no FMI 3.0 type", v.name)),
    };
    let mut a = format!("name=\"{}\" valueReference=\"{vr}\"", escape(&v.name));
    if !v.description.is_empty() {
        let _ = write!(a, " description=\"{}\"", escape(&v.description));
    }
    let _ = write!(
        a,
        " causality=\"{}\" variability=\"{}\"",
        v.causality, v.variability
    );
    if v.initial != "none" && v.causality != "input" {
        // FMI 3.0 keeps FMI 2.0's defaults for `initial` (section 2.4.7.5); written out in full.
        let _ = write!(a, " initial=\"{}\"", v.initial);
    }
    if let Some(t) = declared {
        let _ = write!(a, " declaredType=\"{}\"", escape(t));
    }
    if let Some(u) = &v.unit {
        let _ = write!(a, " unit=\"{}\"", escape(u));
    }
    for (name, value) in [("min", &v.min), ("max", &v.max), ("nominal", &v.nominal)] {
        if let Some(value) = value {
            let _ = write!(a, " {name}=\"{}\"", escape(value));
        }
    }
    if let Some(state) = &v.derivative_of {
        let i = model
            .variables
            .iter()
            .position(|s| &s.name == state)
            .ok_or_else(|| format!("variable '{}': derivative of unknown '{state}'", v.name))?;
        // States are Float64: their value reference is the FMI 2.0 one.
        let _ = write!(a, " derivative=\"{}\"", model.variables[i].value_reference);
    }
    if let Some(s) = &v.start {
        let _ = write!(a, " start=\"{}\"", escape(s.trim()));
    }
    Ok(format!("    <{element} {a}/>\n"))
}

/// Rust source of the tables `src/fmi3` serves one model with (`Fmi3Model`).
pub fn tables(model: &Model, xml_path: &str, out: &mut String) -> Result<(), String> {
    let layout = layout(model);
    let module = super::model_description::field_name(&model.name);
    let declared = declared_types(model);
    // FMI 2.0 Integer value references of the Enumerations (FMI 3.0 reads them as Int64).
    let enum_vrs: Vec<u32> = model
        .variables
        .iter()
        .zip(&declared)
        .filter(|(v, d)| v.type_index == 1 && d.is_some())
        .map(|(v, _)| v.value_reference)
        .collect();
    let arrays = array_outputs(model, &layout)?;
    let mut dependencies = String::new();
    let mut seen = std::collections::BTreeSet::new();
    let scalars = model
        .outputs
        .iter()
        .chain(&model.derivatives)
        .chain(&model.initial_unknowns)
        .map(|u| (layout.vr[u.index - 1], u));
    for (vr, u) in scalars.chain(arrays.iter().map(|a| (a.vr, a.output))) {
        if !seen.insert(vr) {
            continue;
        }
        let list = match &u.dependencies {
            Some(d) => {
                let pairs: Vec<String> = sorted_dependencies(&layout, d, u.kinds.as_deref())
                    .iter()
                    .map(|(vr, kind)| format!("({vr}, {})", dependency_kind(kind)))
                    .collect();
                format!("Some(&[{}])", pairs.join(", "))
            }
            None => "None".into(),
        };
        let _ = writeln!(dependencies, "        ({vr}, {list}),");
    }
    let array_table: String = arrays
        .iter()
        .map(|a| {
            format!(
                "        Fmi3Array {{ name: {:?}, value_reference: {}, size: {} }},\n",
                a.declaration.name, a.vr, a.declaration.size
            )
        })
        .collect();
    let _ = writeln!(
        out,
        "pub static {}: Fmi3Model = Fmi3Model {{\n    name: {:?},\n    model_description_xml: include_str!({xml_path:?}),\n    time: {},\n    event_indicators: {},\n    integers: {},\n    booleans: {},\n    enumerations: &{enum_vrs:?},\n    arrays: &[\n{array_table}    ],\n    dependencies: &[\n{dependencies}    ],\n}};\n",
        module.to_uppercase(),
        model.name,
        layout.time,
        layout.event_indicators,
        layout.integers,
        layout.booleans,
    );
    Ok(())
}

/// (FMI 3.0 value reference, dependenciesKind) of 1-based variable indices `d`, by value reference.
fn sorted_dependencies<'a>(
    layout: &Layout,
    d: &[usize],
    kinds: Option<&'a [String]>,
) -> Vec<(u32, &'a str)> {
    let mut pairs: Vec<(u32, &str)> = d
        .iter()
        .enumerate()
        .map(|(j, i)| {
            let kind = kinds.map_or("dependent", |k| k[j].as_str());
            (layout.vr[i - 1], kind)
        })
        .collect();
    pairs.sort_unstable_by_key(|p| p.0);
    pairs
}

/// `fmi3DependencyKind` (fmi3FunctionTypes.h) of a `dependenciesKind` word.
fn dependency_kind(kind: &str) -> u8 {
    match kind {
        "constant" => 1,
        "fixed" => 2,
        "tunable" => 3,
        "discrete" => 4,
        _ => 5,
    }
}
