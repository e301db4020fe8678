//! McKibbenJoint FMU: an antagonistic pair of McKibben muscles on a pulley as one joint actuator,
//! with gazebo-fmi's variable names (`actuatorInput`, `jointPosition`, `jointVelocity` in,
//! `jointTorque` out).
//!
//! Both muscles are [`McKibben`] physics instances built from the same parameters as the
//! McKibbenMuscle FMU; the flexor's length is `L0f - r q`, the extensor's `L0e + r q`, so the
//! torque `r (F_flexor - F_extensor)` turns the joint towards the flexor. `actuatorInput` is the
//! pressure difference around the common mode, each pressure saturated to `0 .. max_pressure`.

use super::{Model, Report, Status, Vars};
use crate::physics::bladder::{BladderTube, MOONEY_C1, MOONEY_C2};
use crate::physics::friction::HysteresisState;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::{
    BladderModel, FrictionParams, McKibben, McKibbenOutput, MuscleGeometry,
};
use crate::variables::mckibben_joint::{boolean, integer, real, INFO};
use crate::variables::ModelInfo;
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
}

/// Both muscles' operating point at the current inputs.
struct Pair {
    flexor: McKibbenOutput,
    extensor: McKibbenOutput,
    pressures: [f64; 2],
    lengths: [f64; 2],
}

fn muscle(vars: &Vars) -> Result<McKibben, String> {
    let r = &vars.real;
    let model = BladderModel::from_switch(
        vars.integer[integer::BLADDER_MODEL],
        vars.integer[integer::BLADDER_LAYERS],
    )?;
    let friction = vars.boolean[boolean::FRICTION].then(|| FrictionParams {
        coefficient: r[real::FRICTION_COEFFICIENT],
        presliding_length: r[real::PRESLIDING_LENGTH],
    });
    match vars.integer[integer::PRESET] {
        0 => McKibben::new(
            Sleeve::new(r[real::STRAND_LENGTH], r[real::TURNS])?,
            BladderTube {
                inner_diameter: r[real::BLADDER_INNER_DIAMETER],
                thickness: r[real::BLADDER_THICKNESS],
                unstretched_length: r[real::BLADDER_LENGTH],
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

fn positive(name: &str, x: f64) -> Result<f64, String> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(format!("{name} must be finite and > 0, got {x}"))
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

    fn compute(&mut self, vars: &Vars, report: &mut Report) -> Option<Pair> {
        let r = &vars.real;
        let (u, q) = (r[real::ACTUATORINPUT], r[real::JOINTPOSITION]);
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

    fn write(&self, vars: &mut Vars, pair: &Pair) {
        let r = &mut vars.real;
        r[real::JOINTTORQUE] = self.moment_arm * (pair.flexor.force - pair.extensor.force);
        r[real::FLEXOR_PRESSURE] = pair.pressures[0];
        r[real::EXTENSOR_PRESSURE] = pair.pressures[1];
        r[real::FLEXOR_FORCE] = pair.flexor.force;
        r[real::EXTENSOR_FORCE] = pair.extensor.force;
        r[real::FLEXOR_LENGTH] = pair.lengths[0];
        r[real::EXTENSOR_LENGTH] = pair.lengths[1];
    }
}

impl Model for McKibbenJoint {
    const INFO: &'static ModelInfo = &INFO;
    const DOCUMENTATION: &'static str = include_str!("mckibben_joint.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        saved.flexor_friction.check("flexor friction history")?;
        saved.extensor_friction.check("extensor friction history")?;
        self.flexor_friction = saved.flexor_friction;
        self.extensor_friction = saved.extensor_friction;
        self.out_of_range = saved.out_of_range;
        Ok(())
    }

    fn new(vars: &mut Vars) -> Result<Self, String> {
        let r = &vars.real;
        let moment_arm = positive("moment_arm", r[real::MOMENT_ARM])?;
        let flexor_rest_length = positive("flexor_rest_length", r[real::FLEXOR_REST_LENGTH])?;
        let extensor_rest_length = positive("extensor_rest_length", r[real::EXTENSOR_REST_LENGTH])?;
        let max_pressure = positive("max_pressure", r[real::MAX_PRESSURE])?;
        let common_mode_pressure = r[real::COMMON_MODE_PRESSURE];
        if !(common_mode_pressure.is_finite()
            && (0.0..=max_pressure).contains(&common_mode_pressure))
        {
            return Err(format!(
                "common_mode_pressure must lie in 0 .. max_pressure = {max_pressure} Pa, got {common_mode_pressure}"
            ));
        }
        let muscle = muscle(vars)?;
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
            ));
        }
        vars.real[real::MIN_POSITION] = min_position;
        vars.real[real::MAX_POSITION] = max_position;
        let q = vars.real[real::JOINTPOSITION];
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
        })
    }

    fn evaluate(&mut self, vars: &mut Vars, report: &mut Report) {
        if let Some(pair) = self.compute(vars, report) {
            self.write(vars, &pair);
        }
    }

    fn step(&mut self, vars: &mut Vars, _time: f64, _step: f64, report: &mut Report) {
        // Quasi-static, as McKibbenMuscle: the held inputs fix the outputs at the end of the step
        // and each friction history follows its muscle's length at the communication points.
        if let Some(pair) = self.compute(vars, report) {
            self.write(vars, &pair);
            self.flexor_friction = pair.flexor.friction_state;
            self.extensor_friction = pair.extensor.friction_state;
        }
    }
}
