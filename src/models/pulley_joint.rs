//! PulleyJoint FMU: the mechanical side of the robot-joint example as a system component.
//!
//! Muscle forces in; the pendulum joint `I q'' = r (F_f - F_e) - c q' - m g l sin q`, stepped by
//! semi-implicit Euler with the forces held over the communication step (the same update as
//! `python/actuator_fmus/robot_joint.py`; a joint too stiff for that, with a tiny inertia against
//! its damping or gravity, takes linearly implicit substeps, which settle its unresolved fast
//! mode instead of diverging); out come the muscle lengths `L0 -/+ r q` and the PD pressure
//! commands for the next step, so that two McKibbenMuscle FMUs wired to it by plain connections
//! (SSP, container FMU) close the loop. Rigid-body mechanics and a controller, no dissertation
//! physics: it lives here rather than in `src/physics/`. With `external_pressures` the controller is
//! bypassed and the pressure outputs pass on the `*_pressure_command` inputs (saturated).
//!
//! Model Exchange integrates the same ODE with the importer's solver: the continuous states are
//! `joint_angle` and `joint_velocity`, the forces are inputs at every right-hand side, and the
//! reference trajectory's segment boundaries are time events (the quintic is C2 there, but its
//! third derivative jumps, so a step-size controller is better off restarting there).

use super::{EventUpdate, Model, Partials, Refusal, Report, Status};
use crate::variables::pulley_joint::{
    DerJointAngleBy, DerJointVelocityBy, ExtensorLengthBy, ExtensorPressureBy, FlexorLengthBy,
    FlexorPressureBy, Inputs, JointAngleBy, JointTorqueBy, JointVelocityBy, Outputs, Parameters,
    ReferenceAngleBy, States, Variables,
};
use serde::{Deserialize, Serialize};

/// Substep cap: a long communication step is split so that each Euler substep stays well
/// inside the stability limit of the joint's fastest mode; a step that would need more is taken
/// in this many linearly implicit substeps instead, stable for any stiffness (bounded work).
const MAX_SUBSTEPS: usize = 64;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PulleyJoint {
    p: Params,
    /// Joint angle and velocity at `time`, the model's history.
    q: f64,
    dq: f64,
    /// End of the last accepted step (0 at initialization, as in the example).
    time: f64,
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
    /// The pressures come from the `*_pressure_command` inputs instead of the PD controller.
    external_pressures: bool,
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

    /// Quintic moves between the waypoints, as `reference` in python/actuator_fmus/robot_joint.py.
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

    /// The segment boundaries of [`Params::reference`]: moves start at k T, k = 0 .. 3, and
    /// the last ends at 4 T.
    fn next_boundary(&self, t: f64) -> Option<f64> {
        let period = self.segment_time;
        (1..self.waypoints.len())
            .map(|k| k as f64 * period)
            .find(|&boundary| boundary > t)
    }

    /// The angular acceleration `(torque - c dq - m g l sin q) / I` of the joint.
    fn acceleration(&self, torque: f64, q: f64, dq: f64) -> f64 {
        (torque - self.damping * dq - self.gravity_torque * q.sin()) / self.inertia
    }

    /// One substep `h` with the damping and the gravity torque taken at the substep's end, the
    /// latter linearized: `(I + h c + h^2 m g l cos q) dq' = I dq + h (torque - m g l sin q)`, then
    /// `q' = q + h dq'`. Stable for any `h` where gravity restores (`cos q > 0`); where it
    /// overturns, its slope stays explicit, as the physics is unstable there too.
    fn implicit_substep(&self, torque: f64, q: f64, dq: f64, h: f64) -> (f64, f64) {
        let (sin, cos) = q.sin_cos();
        let restoring = self.gravity_torque * cos.max(0.0);
        let dq = (self.inertia * dq + h * (torque - self.gravity_torque * sin))
            / (self.inertia + h * (self.damping + h * restoring));
        (q + h * dq, dq)
    }

    /// Slope of the saturation `x.max(0).min(max_pressure)` at `x`: 1 strictly inside, else 0
    /// (the one-sided slope of the saturated side at the kinks).
    fn saturation_slope(&self, x: f64) -> f64 {
        if x > 0.0 && x < self.max_pressure {
            1.0
        } else {
            0.0
        }
    }
}

fn non_negative(name: &str, x: f64) -> Result<f64, Refusal> {
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(format!("{name} must be finite and >= 0, got {x}").into())
    }
}

fn positive(name: &str, x: f64) -> Result<f64, Refusal> {
    match non_negative(name, x)? {
        x if x > 0.0 => Ok(x),
        x => Err(format!("{name} must be > 0, got {x}").into()),
    }
}

impl PulleyJoint {
    fn torque(&self, inputs: &Inputs) -> f64 {
        self.p.moment_arm * (inputs.flexor_force - inputs.extensor_force)
    }

    /// Every output at the current state and time.
    fn write(&self, inputs: &Inputs, out: &mut Outputs) {
        let p = &self.p;
        let (q_ref, dq_ref) = p.reference(self.time);
        let u =
            p.feedforward_gain * q_ref.sin() + p.kp * (q_ref - self.q) + p.kd * (dq_ref - self.dq);
        let (pc, pmax) = (p.common_mode_pressure, p.max_pressure);
        if p.external_pressures {
            // Your own commands, saturated (max/min map a NaN to a bound).
            out.flexor_pressure = inputs.flexor_pressure_command.max(0.0).min(pmax);
            out.extensor_pressure = inputs.extensor_pressure_command.max(0.0).min(pmax);
        } else {
            out.flexor_pressure = (pc + 0.5 * u).max(0.0).min(pmax);
            out.extensor_pressure = (pc - 0.5 * u).max(0.0).min(pmax);
        }
        out.flexor_length = p.rest_length - p.moment_arm * self.q;
        out.extensor_length = p.rest_length + p.moment_arm * self.q;
        out.joint_angle = self.q;
        out.joint_velocity = self.dq;
        out.reference_angle = q_ref;
        // A huge moment arm times huge forces overflows: the torque keeps its last value then
        // (evaluate says so).
        let torque = self.torque(inputs);
        if torque.is_finite() {
            out.joint_torque = torque;
        }
    }
}

impl Model for PulleyJoint {
    type Variables = Variables;
    const DOCUMENTATION: &'static str = include_str!("pulley_joint.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        // Any angle and velocity whose outputs are finite is a state the joint can be driven into.
        if !(self.p.representable(saved.q, saved.dq) && saved.time.is_finite()) {
            return Err(format!(
                "joint angle {} rad, velocity {} rad/s and time {} s must be finite, and so the \
                 muscle lengths they give",
                saved.q, saved.dq, saved.time
            ));
        }
        self.q = saved.q;
        self.dq = saved.dq;
        self.time = saved.time;
        Ok(())
    }

    fn new(v: &Parameters, _: &Inputs) -> Result<Self, Refusal> {
        let inertia = positive("inertia", v.inertia)?;
        let max_pressure = positive("max_pressure", v.max_pressure)?;
        let common_mode_pressure = non_negative("common_mode_pressure", v.common_mode_pressure)?;
        if common_mode_pressure > max_pressure {
            return Err(format!(
                "common_mode_pressure must not exceed max_pressure = {max_pressure} Pa, got {common_mode_pressure}"
            ).into());
        }
        let waypoints = [0.0, v.waypoint_1, v.waypoint_2, v.waypoint_3, v.waypoint_4];
        if let Some(w) = waypoints.iter().find(|w| !w.is_finite()) {
            return Err(format!("waypoints must be finite, got {w}").into());
        }
        let feedforward_gain = v.feedforward_gain;
        if !feedforward_gain.is_finite() {
            return Err(format!("feedforward_gain must be finite, got {feedforward_gain}").into());
        }
        let damping = non_negative("damping", v.damping)?;
        let gravity_torque = non_negative("mass", v.mass)?
            * non_negative("gravity", v.gravity)?
            * non_negative("com_distance", v.com_distance)?;
        // Semi-implicit Euler on I q'' + c q' + k q = 0 is stable for h < 2/omega (and h < I/c
        // keeps the damping explicit part stable); the gravity torque bounds k from the side of
        // the joint alone. The muscles' stiffness is outside this FMU: the importer's step sets it.
        let stiffness = gravity_torque.max(f64::MIN_POSITIVE);
        let max_substep = (0.5 * (inertia / stiffness).sqrt())
            .min(0.5 * inertia / damping.max(f64::MIN_POSITIVE));
        let p = Params {
            moment_arm: positive("moment_arm", v.moment_arm)?,
            rest_length: positive("rest_length", v.rest_length)?,
            inertia,
            damping,
            gravity_torque,
            common_mode_pressure,
            max_pressure,
            kp: non_negative("kp", v.kp)?,
            kd: non_negative("kd", v.kd)?,
            feedforward_gain,
            segment_time: positive("segment_time", v.segment_time)?,
            waypoints,
            external_pressures: v.external_pressures,
            max_substep,
        };
        Ok(Self {
            p,
            q: 0.0,
            dq: 0.0,
            time: 0.0,
        })
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        // Outputs at the current time: the torque follows the inputs directly, and so do the
        // pressures with external_pressures.
        self.write(inputs, outputs);
        if !self.torque(inputs).is_finite() {
            report.add(
                Status::Error,
                format!(
                    "the joint torque overflows (moment arm {} m times the force difference)",
                    self.p.moment_arm
                ),
            );
        }
    }

    fn step(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        time: f64,
        step: f64,
        report: &mut Report,
    ) {
        let p = &self.p;
        let torque = self.torque(inputs);
        // One Euler step per communication step, as the example does; a step longer than the
        // joint's own stability limit is split, into at most MAX_SUBSTEPS; a stiffer joint (tiny
        // inertia against its damping or gravity) takes MAX_SUBSTEPS implicit substeps.
        let stable_substeps = (step / p.max_substep).ceil();
        let (mut q, mut dq) = (self.q, self.dq);
        if stable_substeps <= MAX_SUBSTEPS as f64 {
            let n = (stable_substeps as usize).max(1);
            let h = step / n as f64;
            for _ in 0..n {
                dq += h * p.acceleration(torque, q, dq);
                q += h * dq;
            }
        } else {
            let h = step / MAX_SUBSTEPS as f64;
            for _ in 0..MAX_SUBSTEPS {
                (q, dq) = p.implicit_substep(torque, q, dq, h);
            }
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
        self.time = time + step;
        self.write(inputs, outputs);
    }

    const MODEL_EXCHANGE: bool = true;

    fn states(&self) -> States {
        States {
            joint_angle: self.q,
            joint_velocity: self.dq,
        }
    }

    fn set_states(&mut self, x: &States) -> Result<(), String> {
        if !self.p.representable(x.joint_angle, x.joint_velocity) {
            return Err(format!(
                "joint angle {} rad gives muscle lengths that overflow",
                x.joint_angle
            ));
        }
        self.q = x.joint_angle;
        self.dq = x.joint_velocity;
        Ok(())
    }

    fn set_time(&mut self, time: f64) {
        self.time = time;
    }

    /// `q' = dq`, `I dq' = r (F_f - F_e) - c dq - m g l sin q`, the forces being the inputs now.
    fn derivatives(&mut self, inputs: &Inputs) -> Result<States, String> {
        let torque = self.torque(inputs);
        if !torque.is_finite() {
            return Err(format!(
                "the joint torque overflows (moment arm {} m times the force difference)",
                self.p.moment_arm
            ));
        }
        Ok(States {
            joint_angle: self.dq,
            joint_velocity: self.p.acceleration(torque, self.q, self.dq),
        })
    }

    fn next_time_event(&self, time: f64) -> Option<f64> {
        self.p.next_boundary(time)
    }

    /// Nothing jumps at the segment boundaries: the event only restarts the integrator.
    fn update_discrete_states(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        time: f64,
        report: &mut Report,
    ) -> EventUpdate {
        self.time = time;
        self.evaluate(inputs, outputs, report);
        EventUpdate::default()
    }

    /// Exact partials of the outputs and of `der(joint_angle)`, `der(joint_velocity)` with
    /// respect to the inputs and the states, on the branch `write` takes (saturated pressures
    /// have slope 0, including at the kinks).
    fn partials(&mut self, inputs: &Inputs, d: &mut Partials<Variables>) -> Result<(), String> {
        let p = &self.p;
        let (r, inertia) = (p.moment_arm, p.inertia);
        let (q_ref, dq_ref) = p.reference(self.time);
        let u =
            p.feedforward_gain * q_ref.sin() + p.kp * (q_ref - self.q) + p.kd * (dq_ref - self.dq);
        d.row(FlexorLengthBy { joint_angle: -r })
            .row(ExtensorLengthBy { joint_angle: r });
        let (flexor, extensor) = if p.external_pressures {
            let flexor = p.saturation_slope(inputs.flexor_pressure_command);
            let extensor = p.saturation_slope(inputs.extensor_pressure_command);
            (
                FlexorPressureBy {
                    flexor_pressure_command: flexor,
                    joint_angle: 0.0,
                    joint_velocity: 0.0,
                },
                ExtensorPressureBy {
                    extensor_pressure_command: extensor,
                    joint_angle: 0.0,
                    joint_velocity: 0.0,
                },
            )
        } else {
            // p = pc +/- u/2 with du/dq = -kp, du/d(dq) = -kd.
            let flexor = 0.5 * p.saturation_slope(p.common_mode_pressure + 0.5 * u);
            let extensor = -0.5 * p.saturation_slope(p.common_mode_pressure - 0.5 * u);
            (
                FlexorPressureBy {
                    flexor_pressure_command: 0.0,
                    joint_angle: -p.kp * flexor,
                    joint_velocity: -p.kd * flexor,
                },
                ExtensorPressureBy {
                    extensor_pressure_command: 0.0,
                    joint_angle: -p.kp * extensor,
                    joint_velocity: -p.kd * extensor,
                },
            )
        };
        d.row(flexor)
            .row(extensor)
            .row(JointAngleBy { joint_angle: 1.0 })
            .row(JointVelocityBy {
                joint_velocity: 1.0,
            })
            .row(ReferenceAngleBy {})
            .row(JointTorqueBy {
                flexor_force: r,
                extensor_force: -r,
            })
            .row(DerJointAngleBy {
                joint_velocity: 1.0,
            })
            .row(DerJointVelocityBy {
                flexor_force: r / inertia,
                extensor_force: -r / inertia,
                joint_angle: -p.gravity_torque * self.q.cos() / inertia,
                joint_velocity: -p.damping / inertia,
            });
        Ok(())
    }
}

#[cfg(test)]
#[path = "pulley_joint_tests.rs"]
mod tests;
