//! Runs a scene (`scenes/*.json`, `actuator_fmus_tools::scene`) through the `fmi` crate, with FMPy's
//! recording convention: inputs are applied at t, the step runs to t + h, outputs are read at t + h.

use actuator_fmus_tools::scene::{Check, Scene, Signal, Value};
use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::schema::fmi2::ScalarVariableElement;
use fmi::traits::FmiImport;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Real,
    Integer,
    Boolean,
}

/// One run of a scene: the sweep value and the recorded columns (`time` first).
pub struct Run {
    pub sweep_value: Option<f64>,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Run {
    pub fn column(&self, name: &str) -> Vec<f64> {
        let i = self
            .columns
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name}"));
        self.rows.iter().map(|r| r[i]).collect()
    }
}

fn signal_at(
    signal: &Signal,
    t: f64,
    stop: f64,
    csv: &BTreeMap<String, (Vec<f64>, Vec<f64>)>,
    name: &str,
) -> f64 {
    signal.at(t, stop).unwrap_or_else(|| {
        let (times, values) = &csv[name];
        let i = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
        let w = ((t - times[i - 1]) / (times[i] - times[i - 1])).clamp(0.0, 1.0);
        values[i - 1] + w * (values[i] - values[i - 1])
    })
}

fn read_csv(path: &Path, column: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .unwrap_or_default()
        .split(',')
        .map(str::trim)
        .collect();
    let (ti, ci) = (
        header.iter().position(|h| *h == "time"),
        header.iter().position(|h| *h == column),
    );
    let (Some(ti), Some(ci)) = (ti, ci) else {
        return Err(format!("{}: needs time and {column}", path.display()));
    };
    let mut out = (Vec::new(), Vec::new());
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let cells: Vec<f64> = line
            .split(',')
            .map(|c| c.trim().parse().unwrap_or(f64::NAN))
            .collect();
        out.0.push(cells[ti]);
        out.1.push(cells[ci]);
    }
    Ok(out)
}

pub fn run(scene: &Scene, scene_dir: &Path, fmu_dir: &Path) -> Result<Vec<Run>, String> {
    let import: Fmi2Import = fmi::import::from_path(fmu_dir.join(format!("{}.fmu", scene.fmu)))
        .map_err(|e| format!("{e}"))?;
    let vars: BTreeMap<String, (u32, Kind)> = import
        .model_description()
        .model_variables
        .variables
        .iter()
        .filter_map(|v| {
            let kind = match v.elem {
                ScalarVariableElement::Real(_) => Kind::Real,
                // An Enumeration travels as an Integer (FMI 2.0 section 2.2.7).
                ScalarVariableElement::Integer(_) | ScalarVariableElement::Enumeration => {
                    Kind::Integer
                }
                ScalarVariableElement::Boolean(_) => Kind::Boolean,
                _ => return None,
            };
            Some((v.name.clone(), (v.value_reference, kind)))
        })
        .collect();
    let lookup = |name: &str| {
        vars.get(name)
            .copied()
            .ok_or_else(|| format!("{}: no variable {name}", scene.fmu))
    };
    let mut csv = BTreeMap::new();
    for (name, signal) in &scene.inputs {
        if let Signal::Csv { file, column } = signal {
            csv.insert(name.clone(), read_csv(&scene_dir.join(file), column)?);
        }
    }
    let n = (scene.stop_time / scene.step).round() as usize;
    let sweep_values: Vec<Option<f64>> = match &scene.sweep {
        Some(s) => s.values.iter().map(|&v| Some(v)).collect(),
        None => vec![None],
    };
    let mut runs = Vec::new();
    for (index, value) in sweep_values.into_iter().enumerate() {
        let mut parameters = scene.parameters.clone();
        let mut inputs = scene.inputs.clone();
        if let (Some(sweep), Some(v)) = (&scene.sweep, value) {
            if inputs.contains_key(&sweep.variable) {
                inputs.insert(sweep.variable.clone(), Signal::Constant { value: v });
            } else {
                parameters.insert(sweep.variable.clone(), Value::Number(v));
            }
            for (name, column) in &sweep.also {
                parameters.insert(name.clone(), Value::Number(column[index]));
            }
        }
        let mut cs = import
            .instantiate_cs("scene", false, false)
            .map_err(|e| format!("{e}"))?;
        let err = |what: &str| format!("{}: {what} failed", scene.fmu);
        cs.setup_experiment(None, 0.0, None)
            .map_err(|_| err("setup"))?;
        cs.enter_initialization_mode()
            .map_err(|_| err("enter initialization"))?;
        for (name, value) in &parameters {
            let (vr, kind) = lookup(name)?;
            let x = match value {
                Value::Bool(b) => *b as i32 as f64,
                Value::Number(x) => *x,
            };
            let status = match kind {
                Kind::Real => cs.set_real(&[vr], &[x]),
                Kind::Integer => cs.set_integer(&[vr], &[x as i32]),
                Kind::Boolean => cs.set_boolean(&[vr], &[(x != 0.0) as i32]),
            };
            status.map_err(|_| err(&format!("setting {name}")))?;
        }
        let input_vrs: Vec<(u32, &String, &Signal)> = inputs
            .iter()
            .map(|(name, s)| lookup(name).map(|(vr, _)| (vr, name, s)))
            .collect::<Result<_, _>>()?;
        let apply = |cs: &mut fmi::fmi2::instance::InstanceCS, t: f64| -> Result<(), String> {
            for (vr, name, signal) in &input_vrs {
                cs.set_real(&[*vr], &[signal_at(signal, t, scene.stop_time, &csv, name)])
                    .map_err(|_| format!("setting input {name}"))?;
            }
            Ok(())
        };
        apply(&mut cs, 0.0)?;
        cs.exit_initialization_mode()
            .map_err(|_| err("exit initialization"))?;
        let outputs: Vec<(u32, Kind)> = scene
            .outputs
            .iter()
            .map(|o| lookup(o))
            .collect::<Result<_, _>>()?;
        let record =
            |cs: &mut fmi::fmi2::instance::InstanceCS, t: f64| -> Result<Vec<f64>, String> {
                let mut row = vec![t];
                for (vr, kind) in &outputs {
                    row.push(match kind {
                        Kind::Real => {
                            let mut x = [0.0];
                            cs.get_real(&[*vr], &mut x).map_err(|_| "get".to_string())?;
                            x[0]
                        }
                        Kind::Integer => {
                            let mut x = [0];
                            cs.get_integer(&[*vr], &mut x)
                                .map_err(|_| "get".to_string())?;
                            x[0] as f64
                        }
                        Kind::Boolean => {
                            let mut x = [0];
                            cs.get_boolean(&[*vr], &mut x)
                                .map_err(|_| "get".to_string())?;
                            (x[0] != 0) as i32 as f64
                        }
                    });
                }
                Ok(row)
            };
        let mut rows = vec![record(&mut cs, 0.0)?];
        for k in 0..n {
            let t = k as f64 * scene.step;
            apply(&mut cs, t)?;
            cs.do_step(t, scene.step, true)
                .map_err(|_| err(&format!("step at t = {t}")))?;
            rows.push(record(&mut cs, (k + 1) as f64 * scene.step)?);
        }
        let mut columns = vec!["time".to_string()];
        columns.extend(scene.outputs.iter().cloned());
        runs.push(Run {
            sweep_value: value,
            columns,
            rows,
        });
    }
    Ok(runs)
}

fn zero_crossing(x: &[f64], y: &[f64]) -> f64 {
    for i in 0..y.len().saturating_sub(1) {
        if y[i].signum() * y[i + 1].signum() <= 0.0 {
            return if y[i + 1] == y[i] {
                x[i]
            } else {
                x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i])
            };
        }
    }
    f64::NAN
}

/// The scene's checks: (passed, what was compared).
pub fn checks(scene: &Scene, runs: &[Run]) -> Vec<(bool, String)> {
    let mut out = Vec::new();
    for check in &scene.checks {
        match check {
            Check::Max {
                output,
                expect,
                rel_tol,
                source,
            } => {
                let got = runs
                    .iter()
                    .flat_map(|r| r.column(output))
                    .fold(f64::NEG_INFINITY, f64::max);
                out.push((
                    (got - expect).abs() <= rel_tol * expect.abs(),
                    format!("max {output} = {got:e}, dissertation {expect:e} ({source})"),
                ));
            }
            Check::ZeroCrossing {
                output,
                x,
                expect,
                rel_tol,
                source,
            } => {
                for r in runs {
                    let got = zero_crossing(&r.column(x), &r.column(output));
                    out.push((
                        (got - expect).abs() <= rel_tol * expect.abs(),
                        format!("{output} = 0 at {x} = {got}, dissertation {expect} ({source})"),
                    ));
                }
            }
            Check::Final {
                output,
                expect,
                abs_tol,
                source,
            } => {
                for r in runs {
                    let got = *r.column(output).last().unwrap_or(&f64::NAN);
                    out.push((
                        (got - expect).abs() <= *abs_tol,
                        format!("final {output} = {got}, dissertation {expect} ({source})"),
                    ));
                }
            }
        }
    }
    out
}
