//! The checks of a source description's variables against FMI 2.0 (sections 2.2.7 and 2.2.8):
//! each variable's causality, variability and attributes, the enumerations, the continuous states,
//! and the ModelStructure resolved to 1-based indices.

use super::description::{ModelStructure, ScalarVariable, TypeDefinitions, Unknowns};
use super::{field_name, ResolvedUnknown, Variable};
use std::collections::{BTreeMap, BTreeSet};

/// The (lowest, highest) item value of each Enumeration type by name. The items must be the
/// consecutive integers from the lowest: the export layer checks an Integer against its min and
/// max, which then admit exactly the items.
pub(super) fn check_enumerations(
    types: &TypeDefinitions,
) -> Result<BTreeMap<String, (i32, i32)>, String> {
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
pub(super) fn check_variable(
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
pub(super) fn resolve_states(variables: &[Variable]) -> Result<Vec<(usize, usize)>, String> {
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
pub(super) fn resolve_structure(
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
