//! The robot-joint co-simulation of `python/actuator_fmus/robot_joint.py`, through the `fmi` crate: the same
//! parameters (`examples/robot_joint.json`), the same controller and the same semi-implicit Euler
//! step, operation for operation, so both importers give the same trajectory to rounding.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common, InstanceCS};
use fmi::schema::fmi2::ScalarVariableElement;
use fmi::traits::FmiImport;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Column names of the recorded rows, as in the Python example's CSV.
pub const COLUMNS: [&str; 9] = [
    "time",
    "q",
    "dq",
    "q_ref",
    "p_flexor",
    "p_extensor",
    "f_flexor",
    "f_extensor",
    "torque",
];

#[derive(Clone, Debug, Deserialize)]
pub struct Parameters {
    pub step: f64,
    pub stop_time: f64,
    pub moment_arm: f64,
    pub rest_length: f64,
    pub inertia: f64,
    pub damping: f64,
    pub mass: f64,
    pub com_distance: f64,
    pub gravity: f64,
    pub common_mode_pressure: f64,
    pub max_pressure: f64,
    pub kp: f64,
    pub kd: f64,
    pub feedforward_gain: f64,
    pub waypoints: Vec<f64>,
    pub segment_time: f64,
    pub record_every: usize,
    /// McKibbenMuscle parameters by name (numbers; integers and booleans by their type).
    pub muscle_parameters: BTreeMap<String, f64>,
}

impl Parameters {
    pub fn load(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Quintic moves between the waypoints: (q_ref, dq_ref), as `reference` in the Python example.
    pub fn reference(&self, t: f64) -> (f64, f64) {
        let (points, period) = (&self.waypoints, self.segment_time);
        let k = ((t / period) as usize).min(points.len().saturating_sub(2));
        let s = ((t - k as f64 * period) / period).clamp(0.0, 1.0);
        let dq = points[k + 1] - points[k];
        let shape = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
        let slope = 30.0 * s * s * (1.0 - s) * (1.0 - s);
        (points[k] + dq * shape, dq * slope / period)
    }

    /// (q_ref, flexor pressure, extensor pressure): PD with gravity feed-forward, saturated.
    pub fn pressures(&self, t: f64, q: f64, dq: f64) -> (f64, f64, f64) {
        let (q_ref, dq_ref) = self.reference(t);
        let u =
            self.feedforward_gain * q_ref.sin() + self.kp * (q_ref - q) + self.kd * (dq_ref - dq);
        let (pc, pmax) = (self.common_mode_pressure, self.max_pressure);
        (
            q_ref,
            (pc + 0.5 * u).max(0.0).min(pmax),
            (pc - 0.5 * u).max(0.0).min(pmax),
        )
    }
}

struct Muscle {
    cs: InstanceCS,
    pressure: u32,
    length: u32,
    force: u32,
}

fn muscle(import: &Fmi2Import, name: &str, p: &Parameters, length: f64) -> Result<Muscle, String> {
    let vars: BTreeMap<String, (u32, &ScalarVariableElement)> = import
        .model_description()
        .model_variables
        .variables
        .iter()
        .map(|v| (v.name.clone(), (v.value_reference, &v.elem)))
        .collect();
    let vr = |n: &str| {
        vars.get(n)
            .map(|v| v.0)
            .ok_or_else(|| format!("McKibbenMuscle has no variable {n}"))
    };
    let mut cs = import
        .instantiate_cs(name, false, false)
        .map_err(|e| format!("{name}: {e}"))?;
    let fail = |what: &str| format!("{name}: {what} failed");
    cs.setup_experiment(None, 0.0, None)
        .map_err(|_| fail("setup"))?;
    cs.enter_initialization_mode()
        .map_err(|_| fail("enter initialization"))?;
    let mut values = p.muscle_parameters.clone();
    values.insert("length".into(), length);
    for (key, value) in &values {
        let (r, elem) = vars
            .get(key)
            .ok_or_else(|| format!("McKibbenMuscle has no variable {key}"))?;
        let status = match elem {
            ScalarVariableElement::Real(_) => cs.set_real(&[*r], &[*value]),
            ScalarVariableElement::Integer(_) => cs.set_integer(&[*r], &[*value as i32]),
            _ => cs.set_boolean(&[*r], &[(*value != 0.0) as i32]),
        };
        status.map_err(|_| fail(&format!("setting {key}")))?;
    }
    cs.exit_initialization_mode()
        .map_err(|_| fail("exit initialization"))?;
    Ok(Muscle {
        cs,
        pressure: vr("pressure")?,
        length: vr("length")?,
        force: vr("force")?,
    })
}

impl Muscle {
    fn step(&mut self, pressure: f64, length: f64, t: f64, h: f64) -> Result<f64, String> {
        self.cs
            .set_real(&[self.pressure, self.length], &[pressure, length])
            .map_err(|_| format!("set inputs at t = {t}"))?;
        self.cs
            .do_step(t, h, true)
            .map_err(|_| format!("do_step at t = {t}"))?;
        let mut f = [0.0];
        self.cs
            .get_real(&[self.force], &mut f)
            .map_err(|_| format!("get force at t = {t}"))?;
        Ok(f[0])
    }
}

/// Runs the co-simulation with the McKibbenMuscle FMU in `fmu_dir`; rows every `record_every`
/// steps and at the end, columns [`COLUMNS`]. `stop_time` overrides the parameter file's.
pub fn simulate(
    p: &Parameters,
    fmu_dir: &Path,
    stop_time: Option<f64>,
) -> Result<Vec<[f64; 9]>, String> {
    let import: Fmi2Import =
        fmi::import::from_path(fmu_dir.join("McKibbenMuscle.fmu")).map_err(|e| format!("{e}"))?;
    let (h, r, l0) = (p.step, p.moment_arm, p.rest_length);
    let n = (stop_time.unwrap_or(p.stop_time) / h).round() as usize;
    let mgl = p.mass * p.gravity * p.com_distance;
    let mut flexor = muscle(&import, "flexor", p, l0)?;
    let mut extensor = muscle(&import, "extensor", p, l0)?;
    let (mut q, mut dq) = (0.0f64, 0.0f64);
    let mut rows = Vec::new();
    for k in 0..n {
        let t = k as f64 * h;
        let (q_ref, p1, p2) = p.pressures(t, q, dq);
        let f1 = flexor.step(p1, l0 - r * q, t, h)?;
        let f2 = extensor.step(p2, l0 + r * q, t, h)?;
        let torque = r * (f1 - f2);
        dq += h * (torque - p.damping * dq - mgl * q.sin()) / p.inertia;
        q += h * dq;
        if (k + 1) % p.record_every.max(1) == 0 || k + 1 == n {
            rows.push([(k + 1) as f64 * h, q, dq, q_ref, p1, p2, f1, f2, torque]);
        }
    }
    Ok(rows)
}

/// The same co-simulation with the McKibbenJoint FMU in place of the two muscles, stepped the way
/// gazebo-fmi steps an actuator FMU: set `actuatorInput` (here the PD pressure difference),
/// `jointPosition` and `jointVelocity`, do the step, read `jointTorque`.
pub fn simulate_joint_fmu(
    p: &Parameters,
    fmu_dir: &Path,
    stop_time: Option<f64>,
) -> Result<Vec<[f64; 9]>, String> {
    let import: Fmi2Import =
        fmi::import::from_path(fmu_dir.join("McKibbenJoint.fmu")).map_err(|e| format!("{e}"))?;
    let vars: BTreeMap<String, u32> = import
        .model_description()
        .model_variables
        .variables
        .iter()
        .map(|v| (v.name.clone(), v.value_reference))
        .collect();
    let vr = |n: &str| {
        vars.get(n)
            .copied()
            .ok_or_else(|| format!("McKibbenJoint has no variable {n}"))
    };
    let mut cs = import
        .instantiate_cs("joint", false, false)
        .map_err(|e| format!("{e}"))?;
    let fail = |what: &str| format!("McKibbenJoint: {what} failed");
    cs.setup_experiment(None, 0.0, None)
        .map_err(|_| fail("setup"))?;
    cs.enter_initialization_mode()
        .map_err(|_| fail("enter initialization"))?;
    let parameters = [
        ("moment_arm", p.moment_arm),
        ("flexor_rest_length", p.rest_length),
        ("extensor_rest_length", p.rest_length),
        ("common_mode_pressure", p.common_mode_pressure),
        ("max_pressure", p.max_pressure),
    ];
    for (name, value) in parameters {
        cs.set_real(&[vr(name)?], &[value])
            .map_err(|_| fail(&format!("setting {name}")))?;
    }
    cs.exit_initialization_mode()
        .map_err(|_| fail("exit initialization"))?;
    let inputs = [
        vr("actuatorInput")?,
        vr("jointPosition")?,
        vr("jointVelocity")?,
    ];
    let outputs = [
        vr("jointTorque")?,
        vr("flexor_pressure")?,
        vr("extensor_pressure")?,
        vr("flexor_force")?,
        vr("extensor_force")?,
    ];
    let h = p.step;
    let n = (stop_time.unwrap_or(p.stop_time) / h).round() as usize;
    let mgl = p.mass * p.gravity * p.com_distance;
    let (mut q, mut dq) = (0.0f64, 0.0f64);
    let mut rows = Vec::new();
    for k in 0..n {
        let t = k as f64 * h;
        let (q_ref, dq_ref) = p.reference(t);
        let u = p.feedforward_gain * q_ref.sin() + p.kp * (q_ref - q) + p.kd * (dq_ref - dq);
        cs.set_real(&inputs, &[u, q, dq])
            .map_err(|_| fail(&format!("set inputs at t = {t}")))?;
        cs.do_step(t, h, true)
            .map_err(|_| fail(&format!("do_step at t = {t}")))?;
        let mut out = [0.0; 5];
        cs.get_real(&outputs, &mut out)
            .map_err(|_| fail(&format!("get outputs at t = {t}")))?;
        let [torque, p1, p2, f1, f2] = out;
        dq += h * (torque - p.damping * dq - mgl * q.sin()) / p.inertia;
        q += h * dq;
        if (k + 1) % p.record_every.max(1) == 0 || k + 1 == n {
            rows.push([(k + 1) as f64 * h, q, dq, q_ref, p1, p2, f1, f2, torque]);
        }
    }
    Ok(rows)
}

/// CSV with a header; `{:?}` prints the shortest representation that reads back exactly.
pub fn to_csv(rows: &[[f64; 9]]) -> String {
    let mut s = COLUMNS.join(",") + "\n";
    for row in rows {
        let cells: Vec<String> = row.iter().map(|x| format!("{x:?}")).collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}
