//! Parsing and checking of `modelDescription/<Model>.xml`, and generation of the Rust tables.
//! Used by build.rs, and by `tests/model_description.rs` to prove that bad descriptions fail.

use serde::Deserialize;
use sha2::{Digest, Sha256};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

#[path = "rules.rs"]
pub mod rules;

const GUID_PLACEHOLDER: &str = "@GUID@";

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
    #[serde(rename = "CoSimulation")]
    co_simulation: CoSimulation,
    #[serde(rename = "UnitDefinitions", default)]
    unit_definitions: UnitDefinitions,
    #[serde(rename = "LogCategories", default)]
    log_categories: LogCategories,
    #[serde(rename = "ModelVariables")]
    model_variables: ModelVariables,
    #[serde(rename = "ModelStructure")]
    model_structure: ModelStructure,
}

#[derive(Deserialize)]
struct CoSimulation {
    #[serde(rename = "@modelIdentifier")]
    model_identifier: String,
}

#[derive(Deserialize, Default)]
struct UnitDefinitions {
    #[serde(rename = "Unit", default)]
    units: Vec<Named>,
}

#[derive(Deserialize, Default)]
struct LogCategories {
    #[serde(rename = "Category", default)]
    categories: Vec<Named>,
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
}

#[derive(Deserialize)]
struct ModelStructure {
    #[serde(rename = "Outputs", default)]
    outputs: Unknowns,
    #[serde(rename = "InitialUnknowns", default)]
    initial_unknowns: Unknowns,
}

#[derive(Deserialize, Default)]
struct Unknowns {
    #[serde(rename = "Unknown", default)]
    unknowns: Vec<Unknown>,
}

#[derive(Deserialize)]
struct Unknown {
    #[serde(rename = "@index")]
    index: usize,
}

const TYPES: [&str; 4] = ["Real", "Integer", "Boolean", "String"];

struct Checked<'a> {
    var: &'a ScalarVariable,
    type_index: usize,
    attrs: &'a TypeAttributes,
    initial: &'static str,
}

/// Checks the model description `text` of file `<stem>.xml`; the error says what is wrong.
#[allow(dead_code)]
pub fn check(text: &str, stem: &str) -> Result<(), String> {
    with_checked(text, stem, |_, _, _| Ok(()))
}

/// Parses and checks `text`, then hands the checked variables and per-type counts to `then`.
fn with_checked<R>(
    text: &str,
    stem: &str,
    then: impl FnOnce(&ModelDescription, &[Checked], [usize; 4]) -> Result<R, String>,
) -> Result<R, String> {
    rules::check(text)?;
    let md: ModelDescription =
        quick_xml::de::from_str(text).map_err(|e| format!("cannot parse: {e}"))?;
    if md.fmi_version != "2.0" {
        return Err(format!("fmiVersion must be 2.0, found {}", md.fmi_version));
    }
    if md.model_name != stem || md.co_simulation.model_identifier != stem {
        return Err(format!(
            "modelName and modelIdentifier must both equal the file name '{stem}'"
        ));
    }
    if md.guid != GUID_PLACEHOLDER {
        return Err(format!(
            "guid must be the placeholder \"{GUID_PLACEHOLDER}\"; build.rs fills it in"
        ));
    }
    let units: BTreeSet<&str> = md
        .unit_definitions
        .units
        .iter()
        .map(|u| u.name.as_str())
        .collect();

    let mut checked = Vec::new();
    let mut names = BTreeSet::new();
    for v in &md.model_variables.variables {
        let c = check_variable(v, &units).map_err(|e| format!("variable '{}': {e}", v.name))?;
        if !names.insert(v.name.as_str()) {
            return Err(format!("variable name '{}' is used twice", v.name));
        }
        checked.push(c);
    }
    // Value references are dense per type so that the export layer indexes arrays directly.
    let mut counts = [0usize; 4];
    for t in 0..4 {
        let mut vrs: Vec<u32> = checked
            .iter()
            .filter(|c| c.type_index == t)
            .map(|c| c.var.value_reference)
            .collect();
        vrs.sort_unstable();
        counts[t] = vrs.len();
        if vrs.iter().enumerate().any(|(i, &vr)| vr as usize != i) {
            return Err(format!(
                "{} value references must be 0..{} without gaps or repeats, found {vrs:?}",
                TYPES[t],
                vrs.len()
            ));
        }
    }
    check_model_structure(&md, &checked)?;
    then(&md, &checked, counts)
}

/// Validates one model description and appends its tables; returns (module, type name).
pub fn generate(path: &Path, out_dir: &str, code: &mut String) -> Result<(String, String), String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or_default();
    with_checked(&text, stem, |md, checked, counts| {
        emit(md, checked, counts, &text, stem, out_dir, code)
    })
}

fn emit(
    md: &ModelDescription,
    checked: &[Checked],
    counts: [usize; 4],
    text: &str,
    stem: &str,
    out_dir: &str,
    code: &mut String,
) -> Result<(String, String), String> {
    let guid = guid_of(text);
    let shipped = text.replacen(GUID_PLACEHOLDER, &guid, 1);
    let xml_path = Path::new(out_dir).join(format!("{stem}.xml"));
    std::fs::write(&xml_path, shipped).map_err(|e| e.to_string())?;

    let module = snake_case(stem);
    let _ = writeln!(
        code,
        "/// Tables of `{stem}`, from modelDescription/{stem}.xml."
    );
    let _ = writeln!(code, "pub mod {module} {{");
    let _ = writeln!(code, "    use crate::variables::*;");
    for (t, type_name) in TYPES.iter().enumerate() {
        let _ = writeln!(
            code,
            "    /// Value references (array indices) of the {type_name} variables."
        );
        let _ = writeln!(code, "    #[allow(dead_code)]");
        let _ = writeln!(code, "    pub mod {} {{", type_name.to_lowercase());
        for c in checked.iter().filter(|c| c.type_index == t) {
            let _ = writeln!(code, "        /// {}", c.var.description);
            let _ = writeln!(
                code,
                "        pub const {}: usize = {};",
                c.var.name.to_uppercase().replace('.', "_"),
                c.var.value_reference
            );
        }
        let _ = writeln!(code, "    }}");
    }
    let _ = writeln!(code, "    pub static VARIABLES: &[Variable] = &[");
    for c in checked {
        let a = c.attrs;
        let start = match (c.type_index, &a.start) {
            (_, None) => "Start::None".to_string(),
            (0, Some(s)) => format!("Start::Real({})", real_literal(s)?),
            (1, Some(s)) => format!(
                "Start::Integer({})",
                s.trim()
                    .parse::<i32>()
                    .map_err(|e| format!("bad start '{s}': {e}"))?
            ),
            (2, Some(s)) => format!("Start::Boolean({})", parse_bool(s)?),
            (_, Some(s)) => format!("Start::String({s:?})"),
        };
        let bound = |b: &Option<String>| -> Result<String, String> {
            Ok(match b {
                None => "None".into(),
                Some(s) if c.type_index == 0 => format!("Some({})", real_literal(s)?),
                Some(s) => format!(
                    "Some({}.0)",
                    s.trim()
                        .parse::<i64>()
                        .map_err(|e| format!("bad bound '{s}': {e}"))?
                ),
            })
        };
        let _ = writeln!(
            code,
            "        Variable {{ name: {:?}, kind: VarType::{}, vr: {}, causality: Causality::{}, variability: Variability::{}, initial: Initial::{}, start: {start}, min: {}, max: {}, unit: {:?}, description: {:?} }},",
            c.var.name,
            TYPES[c.type_index],
            c.var.value_reference,
            capitalize(&c.var.causality),
            capitalize(&c.var.variability),
            capitalize(c.initial),
            bound(&a.min)?,
            bound(&a.max)?,
            a.unit.clone().unwrap_or_default(),
            c.var.description,
        );
    }
    let _ = writeln!(code, "    ];");
    let categories: Vec<String> = md
        .log_categories
        .categories
        .iter()
        .map(|c| format!("{:?}", c.name))
        .collect();
    let _ = writeln!(code, "    pub static INFO: ModelInfo = ModelInfo {{");
    let _ = writeln!(code, "        name: {stem:?},");
    let _ = writeln!(code, "        guid: {guid:?},");
    let _ = writeln!(code, "        description: {:?},", md.description);
    let _ = writeln!(
        code,
        "        model_description_xml: include_str!({:?}),",
        xml_path.display().to_string()
    );
    let _ = writeln!(code, "        variables: VARIABLES,");
    let _ = writeln!(code, "        counts: {counts:?},");
    let _ = writeln!(
        code,
        "        log_categories: &[{}],",
        categories.join(", ")
    );
    let _ = writeln!(code, "    }};");
    let _ = writeln!(code, "}}\n");
    Ok((module, stem.to_string()))
}

/// FMI 2.0 section 2.2.7: which causality/variability pairs exist and which `initial` each allows.
fn check_variable<'a>(
    v: &'a ScalarVariable,
    units: &BTreeSet<&str>,
) -> Result<Checked<'a>, String> {
    let typed = [&v.real, &v.integer, &v.boolean, &v.string];
    let present: Vec<usize> = (0..4).filter(|&t| typed[t].is_some()).collect();
    let [type_index] = present[..] else {
        return Err("needs exactly one of Real, Integer, Boolean, String".into());
    };
    let attrs = typed[type_index].as_ref().expect("checked present");
    let (causality, variability) = (v.causality.as_str(), v.variability.as_str());
    // Case letters of the spec's table: which initial values are legal, the first being the default.
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
    if variability == "tunable" && causality == "parameter" {
        // Changing one mid-run would rebuild the model and lose its history; not supported yet.
        return Err(
            "tunable parameters are not supported by the export layer yet; use fixed".into(),
        );
    }
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
    if attrs.declared_type.is_some() {
        return Err(
            "declaredType is not supported by the generator; give the unit directly".into(),
        );
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
    Ok(Checked {
        var: v,
        type_index,
        attrs,
        initial,
    })
}

/// Outputs: every output in order. InitialUnknowns: outputs with initial calculated or approx and
/// every calculated parameter, ascending (FMI 2.0 section 2.2.8).
fn check_model_structure(md: &ModelDescription, checked: &[Checked]) -> Result<(), String> {
    let expected_outputs: Vec<usize> = (0..checked.len())
        .filter(|&i| checked[i].var.causality == "output")
        .map(|i| i + 1)
        .collect();
    let expected_initial: Vec<usize> = (0..checked.len())
        .filter(|&i| {
            let c = &checked[i];
            (c.var.causality == "output" && matches!(c.initial, "calculated" | "approx"))
                || c.var.causality == "calculatedParameter"
        })
        .map(|i| i + 1)
        .collect();
    let outputs: Vec<usize> = md
        .model_structure
        .outputs
        .unknowns
        .iter()
        .map(|u| u.index)
        .collect();
    let initial: Vec<usize> = md
        .model_structure
        .initial_unknowns
        .unknowns
        .iter()
        .map(|u| u.index)
        .collect();
    if outputs != expected_outputs {
        return Err(format!(
            "ModelStructure/Outputs must list indices {expected_outputs:?}, found {outputs:?}"
        ));
    }
    if initial != expected_initial {
        return Err(format!("ModelStructure/InitialUnknowns must list indices {expected_initial:?}, found {initial:?}"));
    }
    Ok(())
}

/// A GUID derived from the whole source file: any change to a variable changes it.
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

fn real_literal(s: &str) -> Result<String, String> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|e| format!("bad number '{s}': {e}"))?;
    if !x.is_finite() {
        return Err(format!("'{s}' is not finite"));
    }
    Ok(format!("{x:?}"))
}

fn parse_bool(s: &str) -> Result<bool, String> {
    match s.trim() {
        "true" | "1" => Ok(true),
        "false" | "0" => Ok(false),
        _ => Err(format!("bad Boolean '{s}'")),
    }
}

fn capitalize(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().collect::<String>() + c.as_str())
        .unwrap_or_default()
}

/// `McKibbenMuscle` -> `mckibben_muscle`: a word break comes before a capital that follows a
/// lower-case letter, unless the word so far is a two-letter prefix such as "Mc".
fn snake_case(s: &str) -> String {
    let mut out = String::new();
    let mut word_len = 0;
    let mut prev_lower = false;
    for ch in s.chars() {
        if ch.is_uppercase() && prev_lower && word_len > 2 {
            out.push('_');
            word_len = 0;
        }
        out.extend(ch.to_lowercase());
        word_len += 1;
        prev_lower = ch.is_lowercase();
    }
    out
}
