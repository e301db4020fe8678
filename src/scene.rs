//! Scene files (`scenes/*.json`): which FMU, which parameters and effects, the input signals, the
//! communication step and stop time, the outputs to record, an optional sweep, the plot and the
//! numbers to check against the dissertation. The FMPy runner (`scenes/run.py`) reads the same files;
//! `examples/run_scene.rs` runs them through the `fmi` crate.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Model identifier: `target/fmu/<fmu>.fmu`.
    pub fmu: String,
    /// What the scene reproduces (figure number, what the dissertation says about it).
    pub description: String,
    /// Start values of parameters (effects, fidelity levels, presets) by variable name.
    #[serde(default)]
    pub parameters: BTreeMap<String, Value>,
    /// Input signals by variable name.
    #[serde(default)]
    pub inputs: BTreeMap<String, Signal>,
    /// Communication step (s).
    pub step: f64,
    pub stop_time: f64,
    /// Outputs (or any variable) to record.
    pub outputs: Vec<String>,
    /// One run per value: of a parameter or a constant input.
    pub sweep: Option<Sweep>,
    /// A shorter scene for `make test`: replaces these fields.
    pub fast: Option<Fast>,
    pub plot: Option<Plot>,
    /// Numbers the dissertation gives, checked by the runners and in `make test`.
    #[serde(default)]
    pub checks: Vec<Check>,
}

/// A parameter value: a number or a Boolean.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    Bool(bool),
    Number(f64),
}

/// An input signal of time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Signal {
    Constant {
        value: f64,
    },
    /// Linear from `from` at time 0 to `to` at the stop time.
    Ramp {
        from: f64,
        to: f64,
    },
    /// Triangle wave between `min` and `max`, starting at `min`, with the given period.
    Cycle {
        min: f64,
        max: f64,
        period: f64,
    },
    /// Piecewise constant: `values[i]` from `times[i]` on (`times` ascending, from 0).
    Steps {
        times: Vec<f64>,
        values: Vec<f64>,
    },
    /// Linear interpolation in a CSV file (path relative to the scene file) with a `time` column.
    Csv {
        file: String,
        column: String,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// A parameter or an input (which then becomes constant) by name.
    pub variable: String,
    pub values: Vec<f64>,
    /// Parameters that change in step with `variable`, one value per run each.
    #[serde(default)]
    pub also: BTreeMap<String, Vec<f64>>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fast {
    pub step: Option<f64>,
    pub stop_time: Option<f64>,
    pub sweep_values: Option<Vec<f64>>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plot {
    pub x: String,
    pub y: Vec<String>,
    #[serde(default = "one")]
    pub x_scale: f64,
    #[serde(default = "one")]
    pub y_scale: f64,
    pub x_label: String,
    pub y_label: String,
    /// Where the y axis ends (a muscle's force grows without bound at its length limit).
    pub y_limits: Option<[f64; 2]>,
}

fn one() -> f64 {
    1.0
}

/// A number the dissertation gives, and how close the scene must come.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Check {
    /// The largest value of `output` over the run (all sweep runs).
    Max {
        output: String,
        expect: f64,
        rel_tol: f64,
        source: String,
    },
    /// The value of `x` where `output` first crosses zero (linear interpolation), per sweep run.
    ZeroCrossing {
        output: String,
        x: String,
        expect: f64,
        rel_tol: f64,
        source: String,
    },
    /// The last value of `output` (of every sweep run).
    Final {
        output: String,
        expect: f64,
        abs_tol: f64,
        source: String,
    },
}

impl Scene {
    pub fn from_json(text: &str) -> Result<Self, String> {
        let scene: Scene = serde_json::from_str(text).map_err(|e| format!("scene: {e}"))?;
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
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
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
    }
}
