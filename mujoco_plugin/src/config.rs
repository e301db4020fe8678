//! The plugin's MJCF attributes, checked against the FMU's model description.

use crate::fmu::{self, Fmu, Kind, Value, Variable};
use std::ffi::CString;
use std::sync::Arc;

/// The `<config key=...>` names the plugin accepts (MuJoCo refuses any other key at compile time).
pub const ATTRIBUTES: [&str; 10] = [
    "fmu",
    "parameters",
    "length_input",
    "velocity_input",
    "ctrl_input",
    "force_output",
    "force_scale",
    "length_offset",
    "state_bytes",
    "history",
];

/// Preset names for the `preset` parameter of this project's FMUs (model, names by value).
const PRESETS: &[(&str, &[(&str, i32)])] = &[
    (
        "McKibbenMuscle",
        &[
            ("none", 0),
            ("A", 1),
            ("B", 2),
            ("C", 3),
            ("D", 4),
            ("DMSP-10", 5),
            ("DMSP-40", 6),
            ("DMSP-5", 7),
            ("DMSP-20", 8),
        ],
    ),
    (
        "McKibbenJoint",
        &[
            ("none", 0),
            ("A", 1),
            ("B", 2),
            ("C", 3),
            ("D", 4),
            ("DMSP-10", 5),
            ("DMSP-40", 6),
            ("DMSP-5", 7),
            ("DMSP-20", 8),
        ],
    ),
    (
        "KnittedMuscle",
        &[("none", 0), ("prototype", 1), ("fig1.16", 2)],
    ),
];

/// One actuator's configuration, resolved against its FMU.
pub struct Config {
    pub fmu: Arc<Fmu>,
    pub parameters: Vec<(Variable, Value)>,
    pub length: Option<Variable>,
    pub velocity: Option<Variable>,
    pub ctrl: Option<Variable>,
    pub force: Variable,
    pub force_scale: f64,
    pub length_offset: f64,
    pub state_bytes: Option<usize>,
    /// Whether the FMU's history is written to plugin_state after every step (`history`
    /// "plugin_state", the default) or stays inside the FMU instance ("fmu": faster, but
    /// mj_setState cannot move it).
    pub carry_history: bool,
}

fn number(key: &str, text: &str, default: f64) -> Result<f64, String> {
    if text.trim().is_empty() {
        return Ok(default);
    }
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("attribute '{key}' = '{text}' is not a finite number"))
}

fn value(fmu: &Fmu, variable: &Variable, text: &str) -> Result<Value, String> {
    let bad = |what: &str| format!("parameter '{}' = '{text}' is not {what}", variable.name);
    Ok(match variable.kind {
        Kind::Real => Value::Real(
            text.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad("a finite number"))?,
        ),
        Kind::Integer | Kind::Enumeration => match text.parse::<i32>() {
            Ok(i) => Value::Integer(i),
            Err(_) => {
                let names = PRESETS
                    .iter()
                    .find(|(model, _)| *model == fmu.md.model_name)
                    .filter(|_| variable.name == "preset")
                    .map(|(_, names)| *names)
                    .unwrap_or(&[]);
                let found = names.iter().find(|(n, _)| n.eq_ignore_ascii_case(text));
                match found {
                    Some((_, i)) => Value::Integer(*i),
                    None if names.is_empty() => return Err(bad("an integer")),
                    None => {
                        let list: Vec<&str> = names.iter().map(|(n, _)| *n).collect();
                        return Err(bad(&format!(
                            "an integer or a preset name ({})",
                            list.join(", ")
                        )));
                    }
                }
            }
        },
        Kind::Boolean => match text {
            "true" | "1" => Value::Boolean(true),
            "false" | "0" => Value::Boolean(false),
            _ => return Err(bad("true or false")),
        },
        Kind::String => Value::String(CString::new(text).map_err(|_| bad("a string"))?),
    })
}

/// `name=value` pairs separated by white space.
fn parameters(fmu: &Fmu, text: &str) -> Result<Vec<(Variable, Value)>, String> {
    let mut out: Vec<(Variable, Value)> = Vec::new();
    for pair in text.split_whitespace() {
        let (name, text) = pair
            .split_once('=')
            .ok_or_else(|| format!("'{pair}' in attribute 'parameters' is not name=value"))?;
        let variable = fmu.md.variable(name).ok_or_else(|| {
            format!(
                "parameter '{name}': {} has no such variable",
                fmu.md.model_name
            )
        })?;
        if variable.causality != "parameter" && variable.causality != "input" {
            return Err(format!(
                "'{name}' is {} {}, not a parameter or input",
                if variable.causality.starts_with(['a', 'e', 'i', 'o', 'u']) {
                    "an"
                } else {
                    "a"
                },
                variable.causality
            ));
        }
        out.retain(|(v, _)| v.name != name);
        out.push((variable.clone(), value(fmu, variable, text)?));
    }
    Ok(out)
}

/// A Real variable of the given causality named by attribute `key`, or None when it is empty.
fn mapped(fmu: &Fmu, key: &str, name: &str, causality: &str) -> Result<Option<Variable>, String> {
    let name = name.trim();
    if name.is_empty() {
        return Ok(None);
    }
    let variable = fmu.md.variable(name).ok_or_else(|| {
        format!(
            "attribute '{key}': {} has no variable '{name}'",
            fmu.md.model_name
        )
    })?;
    if variable.causality != causality || variable.kind != Kind::Real {
        return Err(format!(
            "attribute '{key}': '{name}' must be a Real {causality}, it is a {:?} {}",
            variable.kind, variable.causality
        ));
    }
    Ok(Some(variable.clone()))
}

impl Config {
    /// From the attribute values (in [`ATTRIBUTES`] order; missing ones empty).
    pub fn new(attribute: impl Fn(&str) -> String) -> Result<Self, String> {
        let fmu = fmu::load(attribute("fmu").trim())?;
        if !fmu.md.can_serialize {
            return Err(format!(
                "{} cannot serialize its FMU state (canGetAndSetFMUstate and \
                 canSerializeFMUstate), which the plugin carries in MuJoCo's plugin_state",
                fmu.md.model_name
            ));
        }
        let force_name = attribute("force_output");
        let force_name = if force_name.trim().is_empty() {
            "force".to_string()
        } else {
            force_name
        };
        let state_bytes = attribute("state_bytes");
        let state_bytes = if state_bytes.trim().is_empty() {
            None
        } else {
            Some(
                state_bytes
                    .trim()
                    .parse::<usize>()
                    .ok()
                    .filter(|&n| n > 0 && n <= 1 << 24)
                    .ok_or_else(|| {
                        format!("attribute 'state_bytes' = '{state_bytes}' is not a byte count")
                    })?,
            )
        };
        let carry_history = match attribute("history").trim() {
            "" | "plugin_state" => true,
            "fmu" => false,
            other => {
                return Err(format!(
                    "attribute 'history' = '{other}' is neither plugin_state nor fmu"
                ))
            }
        };
        Ok(Self {
            carry_history,
            parameters: parameters(&fmu, &attribute("parameters"))?,
            length: mapped(&fmu, "length_input", &attribute("length_input"), "input")?,
            velocity: mapped(
                &fmu,
                "velocity_input",
                &attribute("velocity_input"),
                "input",
            )?,
            ctrl: mapped(&fmu, "ctrl_input", &attribute("ctrl_input"), "input")?,
            force: mapped(&fmu, "force_output", &force_name, "output")?
                .ok_or("attribute 'force_output' is empty")?,
            force_scale: number("force_scale", &attribute("force_scale"), -1.0)?,
            length_offset: number("length_offset", &attribute("length_offset"), 0.0)?,
            state_bytes,
            fmu,
        })
    }
}
