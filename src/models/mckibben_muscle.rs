//! McKibbenMuscle FMU: gauge pressure and length in, tension force out.
//!
//! Effects, each built only when switched on: the Mooney-Rivlin bladder (`bladder_model` 1 thin
//! wall, 2 thick wall of `bladder_layers` layers), friction hysteresis (`friction`) and a series
//! connector (`connector_stiffness` > 0). With all of them off a step is eq. 2.3 alone.

use super::{Model, Report, Status, Vars};
use crate::physics::bladder::BladderTube;
use crate::physics::friction::HysteresisState;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::{
    BladderModel, FrictionParams, McKibben, McKibbenOutput, MuscleGeometry,
};
use crate::variables::mckibben_muscle::{boolean, integer, real, INFO};
use crate::variables::ModelInfo;
use serde::{Deserialize, Serialize};

/// With a bladder the force grows without bound at both length limits; an out-of-range length
/// is evaluated this fraction of the range inside the limit (finite, steep force).
const LIMIT_MARGIN: f64 = 1e-3;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct McKibbenMuscle {
    muscle: McKibben,
    /// Friction history (eq. 2.4), advanced only by accepted steps.
    friction: HysteresisState,
    /// Whether the last evaluation needed the fallback: its warning is logged once per excursion.
    out_of_range: bool,
}

fn geometry(vars: &Vars) -> Result<(Sleeve, BladderTube), String> {
    let r = &vars.real;
    let preset = match vars.integer[integer::PRESET] {
        0 => None,
        k @ 1..=4 => MuscleGeometry::preset((b'A' + k as u8 - 1) as char),
        k => {
            return Err(format!(
                "preset must be 0 (none) or 1-4 (Table 2.1 A-D), got {k}"
            ))
        }
    };
    let tube = |length, inner_diameter, thickness| BladderTube {
        inner_diameter,
        thickness,
        unstretched_length: length,
        mooney_c1: r[real::MOONEY_C1],
        mooney_c2: r[real::MOONEY_C2],
    };
    Ok(match preset {
        Some(g) => (
            g.sleeve()?,
            tube(
                g.bladder_length,
                g.bladder_inner_diameter,
                g.bladder_thickness,
            ),
        ),
        None => (
            Sleeve::new(r[real::STRAND_LENGTH], r[real::TURNS])?,
            tube(
                r[real::BLADDER_LENGTH],
                r[real::BLADDER_INNER_DIAMETER],
                r[real::BLADDER_THICKNESS],
            ),
        ),
    })
}

impl McKibbenMuscle {
    /// The physics at the current inputs; out of range, the nearest point inside it (logged).
    fn compute(&mut self, vars: &Vars, report: &mut Report) -> Option<McKibbenOutput> {
        let (pressure, length) = (vars.real[real::PRESSURE], vars.real[real::LENGTH]);
        let reason = match self.muscle.evaluate(pressure, length, &self.friction) {
            Ok(out) => {
                self.out_of_range = false;
                return Some(out);
            }
            Err(reason) => reason,
        };
        let (lo, hi) = (self.muscle.min_length(), self.muscle.max_length());
        let margin = if self.muscle.bladder().is_some() {
            LIMIT_MARGIN * (hi - lo)
        } else {
            0.0
        };
        let clamped = length.clamp(lo + margin, hi - margin);
        let fallback = [(pressure, clamped), (pressure.max(0.0), clamped)]
            .into_iter()
            .find_map(|(p, l)| {
                self.muscle
                    .evaluate(p, l, &self.friction)
                    .ok()
                    .map(|o| (p, l, o))
            });
        if !self.out_of_range {
            let what = match &fallback {
                Some((p, l, _)) => format!("evaluating at pressure {p} Pa and length {l} m"),
                None => "holding the previous outputs".into(),
            };
            report.warn(format!(
                "{reason} (valid lengths {lo} .. {hi} m, max_length {hi} m); {what} until the inputs return"
            ));
        }
        report.status = report.status.max(Status::Warning);
        self.out_of_range = true;
        fallback.map(|(_, _, out)| out)
    }

    fn write(vars: &mut Vars, out: &McKibbenOutput) {
        let r = &mut vars.real;
        r[real::FORCE] = out.force;
        r[real::VOLUME] = out.volume;
        r[real::EFFECTIVE_PRESSURE] = out.effective_pressure;
        r[real::THRESHOLD_PRESSURE] = out.threshold_pressure;
        r[real::STRETCH_AXIAL] = out.stretch_axial;
        r[real::STRETCH_HOOP] = out.stretch_hoop;
        r[real::STRETCH_RADIAL] = out.stretch_radial;
        r[real::STRESS_AXIAL] = out.stress_axial;
        r[real::STRESS_HOOP] = out.stress_hoop;
        r[real::STRESS_RADIAL] = out.stress_radial;
        r[real::FRICTION_FORCE] = out.friction_force;
        r[real::STIFFNESS] = out.stiffness;
        vars.boolean[boolean::BLADDER_CONTACT] = out.bladder_contact;
    }
}

impl Model for McKibbenMuscle {
    const INFO: &'static ModelInfo = &INFO;
    const DOCUMENTATION: &'static str = include_str!("mckibben_muscle.html");

    fn new(vars: &mut Vars) -> Result<Self, String> {
        let (sleeve, tube) = geometry(vars)?;
        let model = BladderModel::from_switch(
            vars.integer[integer::BLADDER_MODEL],
            vars.integer[integer::BLADDER_LAYERS],
        )?;
        let friction = vars.boolean[boolean::FRICTION].then(|| FrictionParams {
            coefficient: vars.real[real::FRICTION_COEFFICIENT],
            presliding_length: vars.real[real::PRESLIDING_LENGTH],
        });
        let muscle = McKibben::new(
            sleeve,
            tube,
            model,
            friction,
            vars.real[real::CONNECTOR_STIFFNESS],
        )?;
        vars.real[real::MAX_LENGTH] = muscle.max_length();
        vars.real[real::MIN_LENGTH] = muscle.min_length();
        // Friction starts relaxed (z = 0) at the initial length.
        let friction = HysteresisState::at_rest(vars.real[real::LENGTH]);
        Ok(Self {
            muscle,
            friction,
            out_of_range: false,
        })
    }

    fn evaluate(&mut self, vars: &mut Vars, report: &mut Report) {
        if let Some(out) = self.compute(vars, report) {
            Self::write(vars, &out);
        }
    }

    fn step(&mut self, vars: &mut Vars, _time: f64, _step: f64, report: &mut Report) {
        // Quasi-static: the held inputs at the end of the step fix the outputs; the friction
        // history follows the length path sampled at the communication points.
        if let Some(out) = self.compute(vars, report) {
            Self::write(vars, &out);
            self.friction = out.friction_state;
        }
    }
}
