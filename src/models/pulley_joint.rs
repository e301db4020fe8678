//! PulleyJoint FMU: the mechanical side of the robot-joint example as a system component.
//!
//! Muscle forces in; the pendulum joint `I q'' = r (F_f - F_e) - c q' - m g l sin q`, stepped by
//! semi-implicit Euler with the forces held over the communication step (the same update as
//! `examples/robot_joint.py`); out come the muscle lengths `L0 -/+ r q` and the PD pressure
//! commands for the next step, so that two McKibbenMuscle FMUs wired to it by plain connections
//! (SSP, container FMU) close the loop. Rigid-body mechanics and a controller, no dissertation
//! physics: it lives here rather than in `src/physics/`.

use super::{Model, Report, Status, Vars};
use crate::variables::pulley_joint::{real, INFO};
use crate::variables::ModelInfo;
use serde::{Deserialize, Serialize};

/// Substep cap: a long communication step is split so that each Euler substep stays well
/// inside the stability limit of the joint's fastest mode (bounded work per step).
const MAX_SUBSTEPS: usize = 100_000;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PulleyJoint {
    p: Params,
    /// Joint angle and velocity, the model's history.
    q: f64,
    dq: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct Params {
    moment_arm: f64,
    rest_length: f64,
    inertia: f64,
    damping: f64,
    gravity_torque: f64,
    common_mode_pressure: f64,
    max_pressure: f64,
    kp: f64,
    kd: f64,
    feedforward_gain: f64,
    segment_time: f64,
    waypoints: [f64; 5],
    /// Largest stable Euler substep, from the stiffest linearized mode (s).
    max_substep: f64,
}

impl Params {
    /// Whether angle `q` and velocity `dq` give finite outputs: huge (but legal) moment arms or
    /// rest lengths can overflow the muscle lengths `L0 -/+ r q`.
    fn representable(&self, q: f64, dq: f64) -> bool {
        dq.is_finite()
            && (self.rest_length - self.moment_arm * q).is_finite()
            && (self.rest_length + self.moment_arm * q).is_finite()
    }

    /// Quintic moves between the waypoints, as `reference` in examples/robot_joint.py.
    fn reference(&self, t: f64) -> (f64, f64) {
        let (w, period) = (&self.waypoints, self.segment_time);
        let k = if t.is_finite() && t > 0.0 {
            ((t / period) as usize).min(w.len() - 2)
        } else {
            0
        };
        let s = ((t - k as f64 * period) / period).clamp(0.0, 1.0);
        let dq = w[k + 1] - w[k];
        let shape = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
        let slope = 30.0 * s * s * (1.0 - s) * (1.0 - s);
        (w[k] + dq * shape, dq * slope / period)
    }
}

fn non_negative(vars: &Vars, name: &str, i: usize) -> Result<f64, String> {
    let x = vars.real[i];
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(format!("{name} must be finite and >= 0, got {x}"))
    }
}

fn positive(vars: &Vars, name: &str, i: usize) -> Result<f64, String> {
    match non_negative(vars, name, i)? {
        x if x > 0.0 => Ok(x),
        x => Err(format!("{name} must be > 0, got {x}")),
    }
}

impl PulleyJoint {
    fn write(&self, vars: &mut Vars, t: f64) {
        let p = &self.p;
        let (q_ref, dq_ref) = p.reference(t);
        let u =
            p.feedforward_gain * q_ref.sin() + p.kp * (q_ref - self.q) + p.kd * (dq_ref - self.dq);
        let (pc, pmax) = (p.common_mode_pressure, p.max_pressure);
        let r = &mut vars.real;
        r[real::FLEXOR_PRESSURE] = (pc + 0.5 * u).max(0.0).min(pmax);
        r[real::EXTENSOR_PRESSURE] = (pc - 0.5 * u).max(0.0).min(pmax);
        r[real::FLEXOR_LENGTH] = p.rest_length - p.moment_arm * self.q;
        r[real::EXTENSOR_LENGTH] = p.rest_length + p.moment_arm * self.q;
        r[real::JOINT_ANGLE] = self.q;
        r[real::JOINT_VELOCITY] = self.dq;
        r[real::REFERENCE_ANGLE] = q_ref;
        r[real::JOINT_TORQUE] = p.moment_arm * (r[real::FLEXOR_FORCE] - r[real::EXTENSOR_FORCE]);
    }
}

impl Model for PulleyJoint {
    const INFO: &'static ModelInfo = &INFO;
    const DOCUMENTATION: &'static str = include_str!("pulley_joint.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        // Any angle and velocity whose outputs are finite is a state the joint can be driven into.
        if !self.p.representable(saved.q, saved.dq) {
            return Err(format!(
                "joint angle {} rad and velocity {} rad/s must be finite, and so the muscle \
                 lengths they give",
                saved.q, saved.dq
            ));
        }
        self.q = saved.q;
        self.dq = saved.dq;
        Ok(())
    }

    fn new(vars: &mut Vars) -> Result<Self, String> {
        let inertia = positive(vars, "inertia", real::INERTIA)?;
        let max_pressure = positive(vars, "max_pressure", real::MAX_PRESSURE)?;
        let common_mode_pressure =
            non_negative(vars, "common_mode_pressure", real::COMMON_MODE_PRESSURE)?;
        if common_mode_pressure > max_pressure {
            return Err(format!(
                "common_mode_pressure must not exceed max_pressure = {max_pressure} Pa, got {common_mode_pressure}"
            ));
        }
        let r = &vars.real;
        let waypoints = [
            0.0,
            r[real::WAYPOINT_1],
            r[real::WAYPOINT_2],
            r[real::WAYPOINT_3],
            r[real::WAYPOINT_4],
        ];
        if let Some(w) = waypoints.iter().find(|w| !w.is_finite()) {
            return Err(format!("waypoints must be finite, got {w}"));
        }
        let feedforward_gain = r[real::FEEDFORWARD_GAIN];
        if !feedforward_gain.is_finite() {
            return Err(format!(
                "feedforward_gain must be finite, got {feedforward_gain}"
            ));
        }
        let damping = non_negative(vars, "damping", real::DAMPING)?;
        let gravity_torque = non_negative(vars, "mass", real::MASS)?
            * non_negative(vars, "gravity", real::GRAVITY)?
            * non_negative(vars, "com_distance", real::COM_DISTANCE)?;
        // Semi-implicit Euler on I q'' + c q' + k q = 0 is stable for h < 2/omega (and h < I/c
        // keeps the damping explicit part stable); the gravity torque bounds k from the side of
        // the joint alone. The muscles' stiffness is outside this FMU: the importer's step sets it.
        let stiffness = gravity_torque.max(f64::MIN_POSITIVE);
        let max_substep = (0.5 * (inertia / stiffness).sqrt())
            .min(0.5 * inertia / damping.max(f64::MIN_POSITIVE));
        let p = Params {
            moment_arm: positive(vars, "moment_arm", real::MOMENT_ARM)?,
            rest_length: positive(vars, "rest_length", real::REST_LENGTH)?,
            inertia,
            damping,
            gravity_torque,
            common_mode_pressure,
            max_pressure,
            kp: non_negative(vars, "kp", real::KP)?,
            kd: non_negative(vars, "kd", real::KD)?,
            feedforward_gain,
            segment_time: positive(vars, "segment_time", real::SEGMENT_TIME)?,
            waypoints,
            max_substep,
        };
        let joint = Self { p, q: 0.0, dq: 0.0 };
        joint.write(vars, 0.0);
        Ok(joint)
    }

    fn evaluate(&mut self, vars: &mut Vars, report: &mut Report) {
        // Outputs at the current time: only the torque follows the inputs directly.
        let p = &self.p;
        let torque =
            p.moment_arm * (vars.real[real::FLEXOR_FORCE] - vars.real[real::EXTENSOR_FORCE]);
        if torque.is_finite() {
            vars.real[real::JOINT_TORQUE] = torque;
        } else {
            report.add(
                Status::Error,
                format!(
                    "the joint torque overflows (moment arm {} m times the force difference)",
                    p.moment_arm
                ),
            );
        }
    }

    fn step(&mut self, vars: &mut Vars, time: f64, step: f64, report: &mut Report) {
        let p = &self.p;
        let torque =
            p.moment_arm * (vars.real[real::FLEXOR_FORCE] - vars.real[real::EXTENSOR_FORCE]);
        // One Euler step per communication step, as the example does; a step longer than the
        // joint's own stability limit is split (bounded by MAX_SUBSTEPS).
        let n = ((step / p.max_substep).ceil() as usize).clamp(1, MAX_SUBSTEPS);
        let h = step / n as f64;
        let (mut q, mut dq) = (self.q, self.dq);
        for _ in 0..n {
            dq += h * (torque - p.damping * dq - p.gravity_torque * q.sin()) / p.inertia;
            q += h * dq;
        }
        if !(p.representable(q, dq) && torque.is_finite()) {
            report.add(
                Status::Discard,
                format!("the joint diverged in the step from t = {time} s (torque {torque} N.m); state kept"),
            );
            return;
        }
        self.q = q;
        self.dq = dq;
        self.write(vars, time + step);
    }
}
