//! FMI 2.0 chapter 2 rules that conformance checkers test (the INTO-CPS VDMCheck inventory) and
//! that the structural checks in `variable_checks.rs` do not cover, as checks over the typed
//! description of `description.rs`. build.rs runs them on the source and again on the shipped
//! description. Each rule has a test in `tests/all/shipped_descriptions.rs` that feeds it a bad
//! description.

// `!(x > y)` is deliberate: it also refuses NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::description::{self, Description, ToolElement, Unknowns};
use std::collections::BTreeSet;

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
    "a VendorAnnotations Tool holds at most one element (2.2.6, the schema's fmi2Annotation)",
];

/// Which form of a description the rules judge. A source names its unknowns, dependencies and
/// states (build.rs resolves them to indices) and may declare `<Terminals>` and `<Arrays>` in its
/// Tool, which build.rs moves to the FMI 3.0 FMU; what ships must hold every rule as written.
#[derive(Clone, Copy, PartialEq)]
pub enum Form {
    Source,
    Shipped,
}

/// Checks every rule of [`RULES`] on a shipped model description's text.
pub fn check(text: &str) -> Result<(), String> {
    check_description(&description::parse(text)?, Form::Shipped)
}

/// Checks every rule of [`RULES`] on a description read by `description::parse`; the first
/// violation found is the error.
pub fn check_description(md: &Description, form: Form) -> Result<(), String> {
    check_flags(md)?;
    check_definitions(md)?;
    check_experiment(md)?;
    check_vendor_annotations(md, form)?;
    let variables = check_variables(md)?;
    check_derivatives(&variables, &md.model_structure.derivatives)?;
    check_unknowns(&variables, md)
}

/// What the ModelStructure rules need of a variable.
struct Variable {
    name: String,
    causality: String,
    /// The index its `derivative` attribute gives (shipped description; a source names the state).
    derivative: Option<usize>,
    /// Real with variability continuous.
    continuous_real: bool,
}

fn number(value: Option<&str>, key: &str, at: &str) -> Result<Option<f64>, String> {
    value
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .map_err(|_| format!("{at}: {key} = '{v}' is not a number"))
        })
        .transpose()
}

/// Boolean-valued attributes hold 'true' or 'false'.
fn check_flags(md: &Description) -> Result<(), String> {
    let mut flags: Vec<(&str, &str, &str)> = Vec::new();
    for (tag, capabilities) in [
        ("ModelExchange", &md.model_exchange),
        ("CoSimulation", &md.co_simulation),
    ] {
        for (key, value) in capabilities.iter().flat_map(|c| c.flags()) {
            flags.push((tag, key, value));
        }
    }
    for t in &md.type_definitions.types {
        for (key, value) in t.real.iter().flat_map(|r| r.flags()) {
            flags.push(("Real", key, value));
        }
    }
    for v in &md.model_variables.variables {
        if let Some(value) = &v.can_handle_multiple_set_per_time_instant {
            flags.push((
                "ScalarVariable",
                "canHandleMultipleSetPerTimeInstant",
                value,
            ));
        }
        for (kind, attrs) in v.types() {
            for (key, value) in attrs.flags() {
                flags.push((kind, key, value));
            }
        }
    }
    match flags.iter().find(|(_, _, v)| *v != "true" && *v != "false") {
        Some((tag, key, v)) => Err(format!("{tag}: {key} = '{v}' must be 'true' or 'false'")),
        None => Ok(()),
    }
}

/// Unique unit, type and log category names; integer BaseUnit exponents and a non-zero factor.
fn check_definitions(md: &Description) -> Result<(), String> {
    let mut units = BTreeSet::new();
    for unit in &md.unit_definitions.units {
        if !units.insert(unit.name.as_str()) {
            return Err(format!(
                "unit '{}' is defined twice in UnitDefinitions",
                unit.name
            ));
        }
        let Some(base) = &unit.base_unit else {
            continue;
        };
        if number(base.factor.as_deref(), "factor", "BaseUnit")? == Some(0.0) {
            return Err("BaseUnit factor must not be zero".into());
        }
        number(base.offset.as_deref(), "offset", "BaseUnit")?;
        for (key, value) in base.exponents() {
            if value.trim().parse::<i32>().is_err() {
                return Err(format!(
                    "BaseUnit exponent {key} = '{value}' must be an integer"
                ));
            }
        }
    }
    let mut types = BTreeSet::new();
    for t in &md.type_definitions.types {
        if !types.insert(t.name.as_str()) {
            return Err(format!(
                "type '{}' is defined twice in TypeDefinitions",
                t.name
            ));
        }
    }
    let mut categories = BTreeSet::new();
    for c in md.log_categories.iter().flat_map(|l| &l.categories) {
        if !categories.insert(c.name.as_str()) {
            return Err(format!("log category '{}' is declared twice", c.name));
        }
    }
    Ok(())
}

fn check_experiment(md: &Description) -> Result<(), String> {
    let Some(e) = &md.default_experiment else {
        return Ok(());
    };
    let at = "DefaultExperiment";
    let start = number(e.start_time.as_deref(), "startTime", at)?.unwrap_or(0.0);
    if let Some(stop) = number(e.stop_time.as_deref(), "stopTime", at)? {
        if !(stop > start) {
            return Err(format!(
                "DefaultExperiment: stopTime {stop} must be after startTime {start}"
            ));
        }
    }
    for (key, value) in [("stepSize", &e.step_size), ("tolerance", &e.tolerance)] {
        if let Some(x) = number(value.as_deref(), key, at)? {
            if !(x > 0.0) {
                return Err(format!("DefaultExperiment: {key} {x} must be positive"));
            }
        }
    }
    Ok(())
}

/// The FMI 2.0 schema gives a `<Tool>` at most one child element (`xs:any`, `minOccurs="0"`).
fn check_vendor_annotations(md: &Description, form: Form) -> Result<(), String> {
    for tool in md.vendor_annotations.iter().flat_map(|a| &a.tools) {
        let counted = tool
            .elements
            .iter()
            .filter(|e| {
                form == Form::Shipped
                    || !matches!(e, ToolElement::Terminals(_) | ToolElement::Arrays(_))
            })
            .count();
        if counted > 1 {
            return Err(format!(
                "VendorAnnotations: Tool '{}' holds {counted} elements; FMI 2.0 allows at most one",
                tool.name
            ));
        }
    }
    Ok(())
}

/// The variables' own rules: structured names, attribute ranges, what each type may carry.
fn check_variables(md: &Description) -> Result<Vec<Variable>, String> {
    let structured_names = md.variable_naming_convention.as_deref() == Some("structured");
    let mut variables = Vec::new();
    for v in &md.model_variables.variables {
        let name = &v.name;
        if structured_names && !structured(name) {
            return Err(format!(
                "variable name '{name}' does not follow the structured naming convention"
            ));
        }
        let at = format!("variable '{name}'");
        let mut derivative = None;
        for (kind, attrs) in v.types() {
            if let Some(d) = &attrs.derivative {
                if kind != "Real" {
                    return Err(format!("{at}: only a Real has a derivative attribute"));
                }
                // A source names the state (build.rs resolves it); a shipped one indexes it.
                derivative = d.trim().parse().ok();
            }
            if matches!(kind, "Boolean" | "String") {
                let given = [
                    ("min", &attrs.min),
                    ("max", &attrs.max),
                    ("unit", &attrs.unit),
                    ("nominal", &attrs.nominal),
                    ("quantity", &attrs.quantity),
                ];
                if let Some((key, _)) = given.iter().find(|(_, value)| value.is_some()) {
                    return Err(format!("{at}: a {kind} has no attribute {key}"));
                }
                continue;
            }
            let min = number(attrs.min.as_deref(), "min", &at)?;
            let max = number(attrs.max.as_deref(), "max", &at)?;
            if let (Some(lo), Some(hi)) = (min, max) {
                if !(lo <= hi) {
                    return Err(format!("{at}: min {lo} is above max {hi}"));
                }
            }
            if let Some(start) = number(attrs.start.as_deref(), "start", &at)? {
                if min.is_some_and(|lo| start < lo) || max.is_some_and(|hi| start > hi) {
                    return Err(format!(
                        "{at}: start {start} is outside [{}, {}]",
                        min.unwrap_or(f64::NEG_INFINITY),
                        max.unwrap_or(f64::INFINITY)
                    ));
                }
            }
            if let Some(nominal) = number(attrs.nominal.as_deref(), "nominal", &at)? {
                if !(nominal > 0.0) {
                    return Err(format!("{at}: nominal {nominal} must be positive"));
                }
            }
        }
        let types = v.types();
        variables.push(Variable {
            name: name.clone(),
            causality: v.causality.clone(),
            derivative,
            continuous_real: v.variability == "continuous"
                && types.iter().all(|(kind, _)| *kind == "Real"),
        });
    }
    Ok(variables)
}

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

fn check_derivatives(variables: &[Variable], derivatives: &Unknowns) -> Result<(), String> {
    states(variables)?;
    for u in &derivatives.unknowns {
        if let Some(i) = u.index.as_deref().and_then(|i| i.parse::<usize>().ok()) {
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

fn check_unknowns(variables: &[Variable], md: &Description) -> Result<(), String> {
    let mut seen: BTreeSet<(&str, usize)> = BTreeSet::new();
    let states = states(variables)?;
    let lists = md.model_structure.lists();
    let unknowns = lists
        .iter()
        .flat_map(|(list, u)| u.unknowns.iter().map(move |u| (*list, u)));
    for (list, u) in unknowns {
        let at = format!("ModelStructure/{list}");
        if u.index.is_none() && u.name.is_some() {
            // A source description names its unknowns; build.rs resolves and checks them, and
            // these rules run again on the shipped indices.
            continue;
        }
        let index: usize = u
            .index
            .as_deref()
            .and_then(|i| i.parse().ok())
            .ok_or_else(|| format!("{at}: every Unknown needs a numeric index"))?;
        if !(1..=variables.len()).contains(&index) {
            return Err(format!(
                "{at}: Unknown index {index} is not a variable (1..{})",
                variables.len()
            ));
        }
        if !seen.insert((list, index)) {
            return Err(format!("{at}: Unknown index {index} is listed twice"));
        }
        let Some(deps) = &u.dependencies else {
            if u.dependencies_kind.is_some() {
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
            let allowed = match list {
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
        if let Some(kinds) = &u.dependencies_kind {
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
