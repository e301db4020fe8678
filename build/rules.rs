//! FMI 2.0 chapter 2 rules that conformance checkers test (the INTO-CPS VDMCheck inventory) and
//! that the structural checker in `model_description.rs` does not cover. They read the XML as
//! events, so they hold whatever shape the generator's own structs take. Each rule has a test in
//! `tests/all/shipped_descriptions.rs` that feeds it a bad description.

// `!(x > y)` is deliberate: it also refuses NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use quick_xml::events::{BytesStart, Event};
use std::collections::{BTreeMap, BTreeSet};

/// The rules, one line each: docs/compatibility.md quotes this list.
#[allow(dead_code)]
pub const RULES: &[&str] = &[
    "unit names in UnitDefinitions are unique (2.2.2)",
    "type names in TypeDefinitions are unique (2.2.3)",
    "log category names are unique (2.2.4)",
    "BaseUnit exponents are integers and factor is not zero (2.2.2)",
    "DefaultExperiment: startTime < stopTime, stepSize > 0, tolerance > 0 (2.2.5)",
    "Real and Integer: min <= max, and min <= start <= max (2.2.7)",
    "Boolean and String variables carry no min, max, unit or nominal (2.2.7)",
    "nominal is positive (2.2.7)",
    "boolean attributes are 'true' or 'false' (2.2.1)",
    "variableNamingConvention 'structured' names follow the structured grammar (2.2.9)",
    "ModelStructure Unknown indices refer to existing variables, at most once per list (2.2.8)",
    "every Outputs and InitialUnknowns entry declares its dependencies",
    "dependencies are ascending unique indices of knowns: inputs, continuous states (Outputs and \
     Derivatives) or the independent variable, dependenciesKind has one valid kind per \
     dependency (2.2.8)",
    "a Real's derivative attribute is the index of a continuous Real output or local, and each \
     Derivatives entry is a variable that has one (2.2.7, 2.2.8)",
];

struct Variable {
    name: String,
    causality: String,
    /// The index its `derivative` attribute gives (shipped description; a source names the state).
    derivative: Option<usize>,
    /// Real with variability continuous.
    continuous_real: bool,
}

fn attributes(e: &BytesStart) -> Result<BTreeMap<String, String>, String> {
    e.attributes()
        .map(|a| {
            let a = a.map_err(|e| format!("bad attribute: {e}"))?;
            let value = a
                .unescape_value()
                .map_err(|e| format!("bad attribute value: {e}"))?;
            Ok((
                String::from_utf8_lossy(a.key.as_ref()).into_owned(),
                value.into_owned(),
            ))
        })
        .collect()
}

fn number(attrs: &BTreeMap<String, String>, key: &str, at: &str) -> Result<Option<f64>, String> {
    attrs
        .get(key)
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .map_err(|_| format!("{at}: {key} = '{v}' is not a number"))
        })
        .transpose()
}

/// Boolean-valued attributes of the elements this project writes.
const BOOLEAN_ATTRIBUTES: &[&str] = &[
    "needsExecutionTool",
    "canHandleVariableCommunicationStepSize",
    "canInterpolateInputs",
    "canRunAsynchronuously",
    "canBeInstantiatedOnlyOncePerProcess",
    "canNotUseMemoryManagementFunctions",
    "canGetAndSetFMUstate",
    "canSerializeFMUstate",
    "providesDirectionalDerivative",
    "canHandleMultipleSetPerTimeInstant",
    "completedIntegratorStepNotNeeded",
    "relativeQuantity",
    "unbounded",
    "reinit",
    "canHandleEvents",
];

/// `name` in the structured convention (FMI 2.0 section 2.2.9): dot-separated identifiers or
/// quoted names, each optionally indexed `[1,2]`, or `der(name)` / `der(name, n)`.
fn structured(name: &str) -> bool {
    if let Some(inner) = name.strip_prefix("der(").and_then(|s| s.strip_suffix(')')) {
        let (base, order) = match inner.rsplit_once(',') {
            Some((b, n)) => (b.trim(), Some(n.trim())),
            None => (inner, None),
        };
        return structured(base)
            && order.is_none_or(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
    }
    !name.is_empty() && name.split('.').all(structured_part)
}

fn structured_part(part: &str) -> bool {
    let (head, index) = match part.find('[') {
        Some(i) => (&part[..i], Some(&part[i..])),
        None => (part, None),
    };
    let identifier = head
        .bytes()
        .next()
        .is_some_and(|b| b.is_ascii_alphabetic() || b == b'_')
        && head.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_');
    let quoted = head.len() >= 3 && head.starts_with('\'') && head.ends_with('\'');
    let index_ok = index.is_none_or(|s| {
        s.ends_with(']')
            && s[1..s.len() - 1]
                .split(',')
                .all(|n| !n.trim().is_empty() && n.trim().bytes().all(|b| b.is_ascii_digit()))
    });
    (identifier || quoted) && index_ok
}

/// Checks every rule of [`RULES`] on a model description; the first violation is the error.
pub fn check(text: &str) -> Result<(), String> {
    let mut reader = quick_xml::Reader::from_str(text);
    let mut units = BTreeSet::new();
    let mut types = BTreeSet::new();
    let mut categories = BTreeSet::new();
    let mut variables: Vec<Variable> = Vec::new();
    let mut structured_names = false;
    // (list, attributes) of every ModelStructure Unknown.
    let mut unknowns: Vec<(String, BTreeMap<String, String>)> = Vec::new();
    let mut path: Vec<String> = Vec::new();
    loop {
        let (e, empty) = match reader
            .read_event()
            .map_err(|e| format!("cannot parse: {e}"))?
        {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                path.pop();
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let tag = String::from_utf8_lossy(e.name().as_ref()).into_owned();
        let attrs = attributes(&e)?;
        let parent = path.last().map(String::as_str).unwrap_or("");
        let name = attrs.get("name").cloned().unwrap_or_default();
        for key in BOOLEAN_ATTRIBUTES {
            if let Some(v) = attrs.get(*key) {
                if v != "true" && v != "false" {
                    return Err(format!("{tag}: {key} = '{v}' must be 'true' or 'false'"));
                }
            }
        }
        match (parent, tag.as_str()) {
            ("", "fmiModelDescription") => {
                structured_names =
                    attrs.get("variableNamingConvention").map(String::as_str) == Some("structured")
            }
            ("UnitDefinitions", "Unit") if !units.insert(name.clone()) => {
                return Err(format!("unit '{name}' is defined twice in UnitDefinitions"));
            }
            ("Unit", "BaseUnit") => {
                for (key, value) in &attrs {
                    if key == "factor" {
                        if number(&attrs, key, "BaseUnit")? == Some(0.0) {
                            return Err("BaseUnit factor must not be zero".into());
                        }
                    } else if key != "offset" && value.trim().parse::<i32>().is_err() {
                        return Err(format!(
                            "BaseUnit exponent {key} = '{value}' must be an integer"
                        ));
                    }
                }
            }
            ("TypeDefinitions", "SimpleType") if !types.insert(name.clone()) => {
                return Err(format!("type '{name}' is defined twice in TypeDefinitions"));
            }
            ("LogCategories", "Category") if !categories.insert(name.clone()) => {
                return Err(format!("log category '{name}' is declared twice"));
            }
            (_, "DefaultExperiment") => {
                let at = "DefaultExperiment";
                let start = number(&attrs, "startTime", at)?.unwrap_or(0.0);
                if let Some(stop) = number(&attrs, "stopTime", at)? {
                    if !(stop > start) {
                        return Err(format!(
                            "DefaultExperiment: stopTime {stop} must be after startTime {start}"
                        ));
                    }
                }
                for key in ["stepSize", "tolerance"] {
                    if let Some(x) = number(&attrs, key, at)? {
                        if !(x > 0.0) {
                            return Err(format!("DefaultExperiment: {key} {x} must be positive"));
                        }
                    }
                }
            }
            ("ModelVariables", "ScalarVariable") => {
                if structured_names && !structured(&name) {
                    return Err(format!(
                        "variable name '{name}' does not follow the structured naming convention"
                    ));
                }
                variables.push(Variable {
                    name,
                    causality: attrs
                        .get("causality")
                        .cloned()
                        .unwrap_or_else(|| "local".into()),
                    derivative: None,
                    continuous_real: attrs.get("variability").is_none_or(|v| v == "continuous"),
                });
            }
            (
                "ScalarVariable",
                kind @ ("Real" | "Integer" | "Boolean" | "String" | "Enumeration"),
            ) => {
                let var = variables.last().map_or("?", |v| v.name.as_str());
                let at = format!("variable '{var}'");
                if kind != "Real" {
                    if let Some(last) = variables.last_mut() {
                        last.continuous_real = false;
                    }
                }
                if let Some(d) = attrs.get("derivative") {
                    if kind != "Real" {
                        return Err(format!("{at}: only a Real has a derivative attribute"));
                    }
                    // A source names the state (build.rs resolves it); a shipped one indexes it.
                    if let (Ok(index), Some(last)) = (d.trim().parse(), variables.last_mut()) {
                        last.derivative = Some(index);
                    }
                }
                if matches!(kind, "Boolean" | "String") {
                    if let Some(key) = ["min", "max", "unit", "nominal", "quantity"]
                        .into_iter()
                        .find(|k| attrs.contains_key(*k))
                    {
                        return Err(format!("{at}: a {kind} has no attribute {key}"));
                    }
                } else {
                    let (min, max) = (number(&attrs, "min", &at)?, number(&attrs, "max", &at)?);
                    if let (Some(lo), Some(hi)) = (min, max) {
                        if !(lo <= hi) {
                            return Err(format!("{at}: min {lo} is above max {hi}"));
                        }
                    }
                    if let Some(start) = number(&attrs, "start", &at)? {
                        if min.is_some_and(|lo| start < lo) || max.is_some_and(|hi| start > hi) {
                            return Err(format!(
                                "{at}: start {start} is outside [{}, {}]",
                                min.unwrap_or(f64::NEG_INFINITY),
                                max.unwrap_or(f64::INFINITY)
                            ));
                        }
                    }
                    if let Some(nominal) = number(&attrs, "nominal", &at)? {
                        if !(nominal > 0.0) {
                            return Err(format!("{at}: nominal {nominal} must be positive"));
                        }
                    }
                }
            }
            (list @ ("Outputs" | "Derivatives" | "InitialUnknowns"), "Unknown") => {
                unknowns.push((list.to_string(), attrs.clone()));
            }
            _ => {}
        }
        if !empty {
            path.push(tag);
        }
    }
    check_derivatives(&variables, &unknowns)?;
    check_unknowns(&variables, &unknowns)
}

/// The continuous states: the variables a `derivative` attribute points to, 1-based.
fn states(variables: &[Variable]) -> Result<BTreeSet<usize>, String> {
    let mut states = BTreeSet::new();
    for v in variables {
        let Some(s) = v.derivative else { continue };
        let state = s.checked_sub(1).and_then(|i| variables.get(i));
        if !state.is_some_and(|x| {
            x.continuous_real && matches!(x.causality.as_str(), "output" | "local")
        }) {
            return Err(format!(
                "variable '{}': derivative=\"{s}\" is not the index of a continuous Real \
                 output or local",
                v.name
            ));
        }
        if !states.insert(s) {
            return Err(format!("variable {s} is the state of two derivatives"));
        }
    }
    Ok(states)
}

fn check_derivatives(
    variables: &[Variable],
    unknowns: &[(String, BTreeMap<String, String>)],
) -> Result<(), String> {
    states(variables)?;
    for (list, attrs) in unknowns {
        let index = attrs.get("index").and_then(|i| i.parse::<usize>().ok());
        if let (Some(i), "Derivatives") = (index, list.as_str()) {
            let v = i.checked_sub(1).and_then(|i| variables.get(i));
            if v.is_none_or(|v| v.derivative.is_none()) {
                return Err(format!(
                    "ModelStructure/Derivatives: Unknown {i} is not a variable with a derivative attribute"
                ));
            }
        }
    }
    Ok(())
}

fn check_unknowns(
    variables: &[Variable],
    unknowns: &[(String, BTreeMap<String, String>)],
) -> Result<(), String> {
    let mut seen: BTreeSet<(&str, usize)> = BTreeSet::new();
    let states = states(variables)?;
    for (list, attrs) in unknowns {
        let at = format!("ModelStructure/{list}");
        if !attrs.contains_key("index") && attrs.contains_key("name") {
            // A source description names its unknowns; build.rs resolves and checks them, and
            // these rules run again on the shipped indices.
            continue;
        }
        let index: usize = attrs
            .get("index")
            .and_then(|i| i.parse().ok())
            .ok_or_else(|| format!("{at}: every Unknown needs a numeric index"))?;
        if !(1..=variables.len()).contains(&index) {
            return Err(format!(
                "{at}: Unknown index {index} is not a variable (1..{})",
                variables.len()
            ));
        }
        if !seen.insert((list.as_str(), index)) {
            return Err(format!("{at}: Unknown index {index} is listed twice"));
        }
        let Some(deps) = attrs.get("dependencies") else {
            if attrs.contains_key("dependenciesKind") {
                return Err(format!(
                    "{at}: Unknown {index} has dependenciesKind without dependencies"
                ));
            }
            // Without a list a master must assume the unknown depends on everything.
            if list != "Derivatives" {
                return Err(format!("{at}: Unknown {index} declares no dependencies"));
            }
            continue;
        };
        let deps: Vec<usize> = deps
            .split_whitespace()
            .map(|d| d.parse::<usize>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("{at}: Unknown {index}: dependencies must be indices"))?;
        if deps.windows(2).any(|w| w[0] >= w[1]) {
            return Err(format!(
                "{at}: Unknown {index}: dependencies {deps:?} must be ascending and unique"
            ));
        }
        for &d in &deps {
            let Some(v) = d.checked_sub(1).and_then(|i| variables.get(i)) else {
                return Err(format!(
                    "{at}: Unknown {index}: dependency {d} is not a variable"
                ));
            };
            // Outputs and derivatives depend on the knowns: inputs, continuous states and time;
            // initial unknowns on the inputs, parameters and start values (FMI 2.0 section 2.2.8).
            let allowed = match list.as_str() {
                "InitialUnknowns" => {
                    matches!(v.causality.as_str(), "input" | "parameter" | "independent")
                        || states.contains(&d)
                }
                _ => matches!(v.causality.as_str(), "input" | "independent") || states.contains(&d),
            };
            if !allowed {
                return Err(format!(
                    "{at}: Unknown {index} may not depend on '{}' (causality {})",
                    v.name, v.causality
                ));
            }
        }
        if let Some(kinds) = attrs.get("dependenciesKind") {
            let kinds: Vec<&str> = kinds.split_whitespace().collect();
            if kinds.len() != deps.len() {
                return Err(format!(
                    "{at}: Unknown {index}: {} dependenciesKind for {} dependencies",
                    kinds.len(),
                    deps.len()
                ));
            }
            let valid: &[&str] = if list == "InitialUnknowns" {
                &["dependent", "constant"]
            } else {
                &["dependent", "constant", "fixed", "tunable", "discrete"]
            };
            if let Some(k) = kinds.iter().find(|k| !valid.contains(k)) {
                return Err(format!(
                    "{at}: Unknown {index}: dependenciesKind '{k}' is not one of {valid:?}"
                ));
            }
        }
    }
    Ok(())
}
