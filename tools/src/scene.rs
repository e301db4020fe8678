//! Scene files (`scenes/*.json`): which FMU, which parameters and effects, the input signals, the
//! communication step and stop time, the outputs to record, an optional sweep, the plot and the
//! numbers to check against the dissertation. The FMPy runner (`actuator-fmus scene`) reads the same files;
//! `examples/run_scene.rs` runs them through the `fmi` crate. The JSON Schema `scenes/schema/scene.schema.json`
//! is generated from these types (`cargo run --release --example run_scene -- --schema`); a test
//! keeps the shipped file equal to it. Unknown or mistyped fields are refused with their path.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A scene: one FMU, its parameters and input signals, how long to run it, what to record and
/// plot, and the numbers from the dissertation it must reproduce.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Optional path or URL of this schema, for editors that validate and complete as you type
    /// (for example `"schema/scene.schema.json"`); the runners ignore it.
    #[serde(rename = "$schema", default, skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    /// Model identifier of the FMU to run: `target/fmu/<fmu>.fmu` (for example `McKibbenMuscle`).
    pub fmu: String,
    /// What the scene reproduces (figure number, what the dissertation says about it).
    pub description: String,
    /// Start values of parameters (effects, fidelity levels, presets) by variable name, in the
    /// variable's SI unit. Booleans for Boolean parameters, numbers otherwise.
    #[serde(default)]
    pub parameters: BTreeMap<String, Value>,
    /// Input signals by input variable name, in the variable's SI unit.
    #[serde(default)]
    pub inputs: BTreeMap<String, Signal>,
    /// Communication step in s (positive).
    pub step: f64,
    /// Stop time in s (positive); every run starts at 0.
    pub stop_time: f64,
    /// Variables to record (outputs or any other variable), by name.
    pub outputs: Vec<String>,
    /// One run per value of a parameter or a constant input.
    #[serde(default)]
    pub sweep: Option<Sweep>,
    /// A shorter variant for `make test`: its fields replace the scene's.
    #[serde(default)]
    pub fast: Option<Fast>,
    /// The plot the runners draw (`out/<scene>.png`).
    #[serde(default)]
    pub plot: Option<Plot>,
    /// Numbers the dissertation gives, checked by the runners and in `make test`.
    #[serde(default)]
    pub checks: Vec<Check>,
}

/// A parameter value: a number or a Boolean.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum Value {
    /// For a Boolean parameter (an effect switch such as `friction`).
    Bool(bool),
    /// For a Real or Integer parameter, in its SI unit.
    Number(f64),
}

/// An input signal of time, chosen by its `type`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Signal {
    /// The same value throughout.
    Constant {
        /// The value, in the input's SI unit.
        value: f64,
    },
    /// Linear from `from` at time 0 to `to` at the stop time.
    Ramp {
        /// Value at time 0.
        from: f64,
        /// Value at the stop time.
        to: f64,
    },
    /// Triangle wave between `min` and `max`, starting at `min`, with the given period.
    Cycle {
        /// Lowest value, at time 0 and every period.
        min: f64,
        /// Highest value, at every half period.
        max: f64,
        /// Period in s (positive).
        period: f64,
    },
    /// Piecewise constant: `values[i]` from `times[i]` on (`times` ascending, from 0).
    Steps {
        /// Switch times in s, ascending, the first 0.
        times: Vec<f64>,
        /// One value per switch time.
        values: Vec<f64>,
    },
    /// Linear interpolation in a CSV file (path relative to the scene file) with a `time` column.
    Csv {
        /// CSV file with a header row, relative to the scene file.
        file: String,
        /// Header of the column to read.
        column: String,
    },
}

/// One run per value of `variable`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// A parameter or an input (which then becomes constant) by name.
    pub variable: String,
    /// The values, one run each, in the variable's SI unit.
    pub values: Vec<f64>,
    /// Parameters that change in step with `variable`, one value per run each.
    #[serde(default)]
    pub also: BTreeMap<String, Vec<f64>>,
}

/// Replacements for a shorter run in `make test`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Fast {
    /// Communication step in s.
    #[serde(default)]
    pub step: Option<f64>,
    /// Stop time in s.
    #[serde(default)]
    pub stop_time: Option<f64>,
    /// A subset of `sweep.values` (the `also` columns follow).
    #[serde(default)]
    pub sweep_values: Option<Vec<f64>>,
}

/// The plot: recorded variables against one another, scaled for display.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Plot {
    /// Variable on the x axis (`time` or a recorded variable).
    pub x: String,
    /// Variables on the y axis, one curve each (per sweep run).
    pub y: Vec<String>,
    /// Factor from the SI value to the x axis' unit (1000 for m to mm).
    #[serde(default = "one")]
    pub x_scale: f64,
    /// Factor from the SI value to the y axis' unit (1e-3 for Pa to kPa).
    #[serde(default = "one")]
    pub y_scale: f64,
    /// Label of the x axis, with its unit (for example `length (mm)`).
    pub x_label: String,
    /// Label of the y axis, with its unit (for example `force (N)`).
    pub y_label: String,
    /// Where the y axis ends, in axis units (a muscle's force grows without bound at its
    /// length limit).
    #[serde(default)]
    pub y_limits: Option<[f64; 2]>,
}

fn one() -> f64 {
    1.0
}

/// A number the dissertation gives, and how close the scene must come; chosen by its `kind`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Check {
    /// The largest value of `output` over the run (all sweep runs).
    Max {
        /// Recorded variable.
        output: String,
        /// The dissertation's value, in SI units.
        expect: f64,
        /// Allowed relative difference.
        rel_tol: f64,
        /// Where the dissertation gives it (section, figure, equation).
        source: String,
    },
    /// The value of `x` where `output` first crosses zero (linear interpolation), per sweep run.
    ZeroCrossing {
        /// Recorded variable that crosses zero.
        output: String,
        /// Recorded variable whose value at the crossing is checked.
        x: String,
        /// The dissertation's value of `x` there, in SI units.
        expect: f64,
        /// Allowed relative difference.
        rel_tol: f64,
        /// Where the dissertation gives it (section, figure, equation).
        source: String,
    },
    /// The last value of `output` (of every sweep run).
    Final {
        /// Recorded variable.
        output: String,
        /// The dissertation's value, in SI units.
        expect: f64,
        /// Allowed absolute difference, in SI units.
        abs_tol: f64,
        /// Where the dissertation gives it (section, figure, equation).
        source: String,
    },
}

/// The JSON Schema of scene files, as shipped in `scenes/schema/scene.schema.json`.
pub fn json_schema() -> String {
    let mut text = serde_json::to_string_pretty(&schemars::schema_for!(Scene))
        .expect("a schema always serializes");
    text.push('\n');
    text
}

impl Scene {
    /// Parses a scene; an unknown, missing or mistyped field is refused with its path
    /// (for example `inputs.pressure.valu`).
    pub fn from_json(text: &str) -> Result<Self, String> {
        let de = &mut serde_json::Deserializer::from_str(text);
        let scene: Scene = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            format!("scene: at `{path}`: {}", e.into_inner())
        })?;
        scene.validate()?;
        Ok(scene)
    }

    /// The scene with its fast variant applied (for `make test`).
    pub fn fast(&self) -> Self {
        let mut s = self.clone();
        if let Some(f) = &self.fast {
            s.step = f.step.unwrap_or(s.step);
            s.stop_time = f.stop_time.unwrap_or(s.stop_time);
            if let (Some(sweep), Some(values)) = (&mut s.sweep, &f.sweep_values) {
                // Keep the lockstep parameters of the sweep values that remain.
                let keep: Vec<usize> = values
                    .iter()
                    .filter_map(|v| sweep.values.iter().position(|x| x == v))
                    .collect();
                for column in sweep.also.values_mut() {
                    *column = keep.iter().map(|&i| column[i]).collect();
                }
                sweep.values = values.clone();
            }
        }
        s.fast = None;
        s
    }

    fn validate(&self) -> Result<(), String> {
        let positive = |x: f64| x > 0.0 && x.is_finite();
        if !positive(self.step) || !positive(self.stop_time) {
            return Err(format!(
                "scene: step {} and stop_time {} must be positive",
                self.step, self.stop_time
            ));
        }
        if self.outputs.is_empty() {
            return Err("scene: no outputs to record".into());
        }
        if let Some(sweep) = &self.sweep {
            if let Some((name, _)) = sweep
                .also
                .iter()
                .find(|(_, v)| v.len() != sweep.values.len())
            {
                return Err(format!(
                    "scene: sweep.also.{name} needs one value per sweep value"
                ));
            }
        }
        for (name, signal) in &self.inputs {
            if let Signal::Steps { times, values } = signal {
                if times.len() != values.len()
                    || times.is_empty()
                    || times.windows(2).any(|w| w[0] > w[1])
                {
                    return Err(format!(
                        "scene: input {name}: steps need ascending times, one value each"
                    ));
                }
            }
            if let Signal::Cycle { period, .. } = signal {
                if !positive(*period) {
                    return Err(format!(
                        "scene: input {name}: cycle period must be positive"
                    ));
                }
            }
        }
        Ok(())
    }
}

impl Signal {
    /// The signal's value at `time` of a run ending at `stop_time` (CSV signals are read by the
    /// runners, which know the scene's directory: `None` here).
    pub fn at(&self, time: f64, stop_time: f64) -> Option<f64> {
        Some(match self {
            Signal::Constant { value } => *value,
            Signal::Ramp { from, to } => from + (to - from) * (time / stop_time).clamp(0.0, 1.0),
            Signal::Cycle { min, max, period } => {
                let phase = (time / period).rem_euclid(1.0);
                let up = if phase < 0.5 {
                    2.0 * phase
                } else {
                    2.0 - 2.0 * phase
                };
                min + (max - min) * up
            }
            Signal::Steps { times, values } => {
                let i = times.partition_point(|&t| t <= time).saturating_sub(1);
                values[i]
            }
            Signal::Csv { .. } => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_catalogue_scene_parses() {
        let dir = crate::repository_root().join("scenes");
        let mut n = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "json") {
                let text = std::fs::read_to_string(&path).unwrap();
                Scene::from_json(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                n += 1;
            }
        }
        assert!(n >= 1);
    }

    #[test]
    fn signals() {
        let cycle = Signal::Cycle {
            min: 1.0,
            max: 3.0,
            period: 2.0,
        };
        assert_eq!(cycle.at(0.0, 10.0), Some(1.0));
        assert_eq!(cycle.at(0.5, 10.0), Some(2.0));
        assert_eq!(cycle.at(1.0, 10.0), Some(3.0));
        assert_eq!(cycle.at(1.5, 10.0), Some(2.0));
        let steps = Signal::Steps {
            times: vec![0.0, 1.0],
            values: vec![5.0, 7.0],
        };
        assert_eq!(steps.at(0.99, 2.0), Some(5.0));
        assert_eq!(steps.at(1.0, 2.0), Some(7.0));
        assert_eq!(
            Signal::Ramp {
                from: 0.0,
                to: 10.0
            }
            .at(0.5, 2.0),
            Some(2.5)
        );
    }

    #[test]
    fn bad_scenes_are_refused() {
        let base = r#"{"fmu":"McKibbenMuscle","description":"d","step":0.1,"stop_time":1,"outputs":["force"]}"#;
        assert!(Scene::from_json(base).is_ok());
        assert!(Scene::from_json(&base.replace("0.1", "-1")).is_err());
        assert!(
            Scene::from_json(&base.replace("\"outputs\":[\"force\"]", "\"outputs\":[]")).is_err()
        );
        assert!(
            Scene::from_json(&base.replace("\"step\"", "\"stepp\"")).is_err(),
            "unknown fields are errors"
        );
        // Unknown and mistyped fields are named by their path.
        let unknown = base.replace(
            "\"outputs\"",
            "\"inputs\":{\"pressure\":{\"type\":\"constant\",\"valu\":1}},\"outputs\"",
        );
        let e = Scene::from_json(&unknown).unwrap_err();
        assert!(e.contains("inputs.pressure") && e.contains("valu"), "{e}");
        let mistyped = base.replace("\"step\":0.1", "\"step\":\"0.1\"");
        let e = Scene::from_json(&mistyped).unwrap_err();
        assert!(e.contains("at `step`"), "{e}");
        let nested = base.replace(
            "\"outputs\"",
            "\"plot\":{\"x\":\"length\",\"y\":[\"force\"],\"x_label\":\"a\",\"y_label\":\"b\",\"y_limit\":[0,1]},\"outputs\"",
        );
        let e = Scene::from_json(&nested).unwrap_err();
        assert!(e.contains("plot") && e.contains("y_limit"), "{e}");
    }

    #[test]
    fn shipped_schema_is_the_generated_one() {
        let path = crate::repository_root().join("scenes/schema/scene.schema.json");
        let shipped = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            shipped == json_schema(),
            "{} is stale: regenerate it with `make scene-schema`",
            path.display()
        );
    }
}
