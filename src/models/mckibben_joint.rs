//! McKibbenJoint FMU: an antagonistic pair of McKibben muscles on a pulley as one joint actuator,
//! with gazebo-fmi's variable names (`actuatorInput`, `jointPosition`, `jointVelocity` in,
//! `jointTorque` out).
//!
//! Both muscles are [`McKibben`] physics instances built from the same parameters as the
//! McKibbenMuscle FMU; the flexor's length is `L0f - r q`, the extensor's `L0e + r q`, so the
//! torque `r (F_flexor - F_extensor)` turns the joint towards the flexor. `actuatorInput` is the
//! pressure difference around the common mode, each pressure saturated to `0 .. max_pressure`.

use super::{Model, Refusal, Report, Status};
use crate::physics::bladder::{BladderTube, MOONEY_C1, MOONEY_C2};
use crate::physics::friction::HysteresisState;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::{
    BladderModel, FrictionParams, McKibben, McKibbenOutput, MuscleGeometry,
};
use crate::variables::mckibben_joint::{
    CalculatedParameters, Inputs, Outputs, Parameters, Variables,
};
use serde::{Deserialize, Serialize};

/// As in McKibbenMuscle: with a bladder the force grows without bound at both length limits, so
/// an out-of-range length is evaluated this fraction of the range inside the limit.
const LIMIT_MARGIN: f64 = 1e-3;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct McKibbenJoint {
    /// One physics model serves both muscles: they share geometry and differ only in history.
    muscle: McKibben,
    moment_arm: f64,
    flexor_rest_length: f64,
    extensor_rest_length: f64,
    common_mode_pressure: f64,
    max_pressure: f64,
    /// Friction histories (eq. 2.4), advanced only by accepted steps.
    flexor_friction: HysteresisState,
    extensor_friction: HysteresisState,
    /// Whether the last evaluation needed the length fallback (warned once per excursion).
    out_of_range: bool,
    /// Joint angles that keep both muscles inside their length range (rad).
    position_range: (f64, f64),
}

/// Both muscles' operating point at the current inputs.
struct Pair {
    flexor: McKibbenOutput,
    extensor: McKibbenOutput,
    pressures: [f64; 2],
    lengths: [f64; 2],
}

fn muscle(p: &Parameters) -> Result<McKibben, String> {
    let model = BladderModel::from_switch(p.bladder_model, p.bladder_layers)?;
    let friction = p.friction.then(|| FrictionParams {
        coefficient: p.friction_coefficient,
        presliding_length: p.presliding_length,
    });
    match p.preset {
        0 => McKibben::new(
            Sleeve::new(p.strand_length, p.turns)?,
            BladderTube {
                inner_diameter: p.bladder_inner_diameter,
                thickness: p.bladder_thickness,
                unstretched_length: p.bladder_length,
                mooney_c1: MOONEY_C1,
                mooney_c2: MOONEY_C2,
            },
            model,
            friction,
            0.0,
        ),
        k @ 1..=4 => {
            let geometry = MuscleGeometry::preset((b'A' + k as u8 - 1) as char)
                .ok_or_else(|| format!("preset {k} has no Table 2.1 row"))?;
            McKibben::from_geometry(&geometry, model, friction, 0.0)
        }
        k => Err(format!(
            "preset must be 0 (none) or 1-4 (Table 2.1 A-D), got {k}"
        )),
    }
}

fn positive(name: &str, x: f64) -> Result<f64, Refusal> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(format!("{name} must be finite and > 0, got {x}").into())
    }
}

impl McKibbenJoint {
    /// One muscle at (pressure, length); out of range, the nearest valid length (flagged).
    fn evaluate_muscle(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
        clamped: &mut Option<String>,
    ) -> Option<McKibbenOutput> {
        let reason = match self.muscle.evaluate(pressure, length, history) {
            Ok(out) => return Some(out),
            Err(reason) => reason,
        };
        let (lo, hi) = (self.muscle.min_length(), self.muscle.max_length());
        let margin = if self.muscle.bladder().is_some() {
            LIMIT_MARGIN * (hi - lo)
        } else {
            0.0
        };
        let inside = length.max(lo + margin).min(hi - margin); // max/min: no panic on odd limits
        clamped.get_or_insert(format!(
            "{reason} (valid muscle lengths {lo} .. {hi} m); evaluating at {inside} m until the inputs return"
        ));
        self.muscle.evaluate(pressure, inside, history).ok()
    }

    fn compute(&mut self, inputs: &Inputs, report: &mut Report) -> Option<Pair> {
        let (u, q) = (inputs.actuator_input, inputs.joint_position);
        let (pc, pmax) = (self.common_mode_pressure, self.max_pressure);
        // f64::clamp would pass a NaN through; max/min map it to a bound (inputs are finite anyway).
        let pressures = [
            (pc + 0.5 * u).max(0.0).min(pmax),
            (pc - 0.5 * u).max(0.0).min(pmax),
        ];
        let lengths = [
            self.flexor_rest_length - self.moment_arm * q,
            self.extensor_rest_length + self.moment_arm * q,
        ];
        let mut clamped = None;
        let flexor = self.evaluate_muscle(
            pressures[0],
            lengths[0],
            &self.flexor_friction,
            &mut clamped,
        );
        let extensor = self.evaluate_muscle(
            pressures[1],
            lengths[1],
            &self.extensor_friction,
            &mut clamped,
        );
        match clamped {
            Some(reason) => {
                if !self.out_of_range {
                    report.warn(format!("jointPosition {q} rad: {reason}"));
                }
                report.status = report.status.max(Status::Warning);
                self.out_of_range = true;
            }
            None => self.out_of_range = false,
        }
        Some(Pair {
            flexor: flexor?,
            extensor: extensor?,
            pressures,
            lengths,
        })
    }

    fn write(&self, out: &mut Outputs, pair: &Pair) {
        out.joint_torque = self.moment_arm * (pair.flexor.force - pair.extensor.force);
        out.flexor_pressure = pair.pressures[0];
        out.extensor_pressure = pair.pressures[1];
        out.flexor_force = pair.flexor.force;
        out.extensor_force = pair.extensor.force;
        out.flexor_length = pair.lengths[0];
        out.extensor_length = pair.lengths[1];
    }
}

impl Model for McKibbenJoint {
    type Variables = Variables;
    const DOCUMENTATION: &'static str = include_str!("mckibben_joint.html");

    fn new(p: &Parameters, start: &Inputs) -> Result<Self, Refusal> {
        let moment_arm = positive("moment_arm", p.moment_arm)?;
        let flexor_rest_length = positive("flexor_rest_length", p.flexor_rest_length)?;
        let extensor_rest_length = positive("extensor_rest_length", p.extensor_rest_length)?;
        let max_pressure = positive("max_pressure", p.max_pressure)?;
        let common_mode_pressure = p.common_mode_pressure;
        if !(common_mode_pressure.is_finite()
            && (0.0..=max_pressure).contains(&common_mode_pressure))
        {
            return Err(format!(
                "common_mode_pressure must lie in 0 .. max_pressure = {max_pressure} Pa, got {common_mode_pressure}"
            ).into());
        }
        let muscle = muscle(p)?;
        let (lo, hi) = (muscle.min_length(), muscle.max_length());
        // Flexor L0f - r q and extensor L0e + r q both inside (lo, hi).
        let min_position =
            ((flexor_rest_length - hi) / moment_arm).max((lo - extensor_rest_length) / moment_arm);
        let max_position =
            ((flexor_rest_length - lo) / moment_arm).min((hi - extensor_rest_length) / moment_arm);
        if min_position >= max_position {
            return Err(format!(
                "no joint angle keeps both muscles inside their length range {lo} .. {hi} m \
                 (flexor_rest_length {flexor_rest_length} m, extensor_rest_length {extensor_rest_length} m)"
            ).into());
        }
        let q = start.joint_position;
        Ok(Self {
            muscle,
            moment_arm,
            flexor_rest_length,
            extensor_rest_length,
            common_mode_pressure,
            max_pressure,
            // Friction starts relaxed (z = 0) at the initial lengths.
            flexor_friction: HysteresisState::at_rest(flexor_rest_length - moment_arm * q),
            extensor_friction: HysteresisState::at_rest(extensor_rest_length + moment_arm * q),
            out_of_range: false,
            position_range: (min_position, max_position),
        })
    }

    fn calculated_parameters(&self) -> CalculatedParameters {
        CalculatedParameters {
            min_position: self.position_range.0,
            max_position: self.position_range.1,
        }
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        if let Some(pair) = self.compute(inputs, report) {
            self.write(outputs, &pair);
        }
    }

    fn step(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        _time: f64,
        _step: f64,
        report: &mut Report,
    ) {
        // Quasi-static, as McKibbenMuscle: the held inputs fix the outputs at the end of the step
        // and each friction history follows its muscle's length at the communication points.
        if let Some(pair) = self.compute(inputs, report) {
            self.write(outputs, &pair);
            self.flexor_friction = pair.flexor.friction_state;
            self.extensor_friction = pair.extensor.friction_state;
        }
    }
}
