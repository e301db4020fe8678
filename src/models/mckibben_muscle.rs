//! McKibbenMuscle FMU: gauge pressure and length in, tension force out.
//!
//! Effects, each built only when switched on: the Mooney-Rivlin bladder (`bladder_model` 1 thin
//! wall, 2 thick wall of `bladder_layers` layers), friction hysteresis (`friction`) and a series
//! connector (`connector_stiffness` > 0). With all of them off a step is eq. 2.3 alone.

use super::{Model, Refusal, Report, Status};
use crate::physics::bladder::BladderTube;
use crate::physics::friction::HysteresisState;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::{
    BladderModel, FrictionParams, McKibben, McKibbenOutput, MuscleGeometry,
};
use crate::variables::mckibben_muscle::{
    CalculatedParameters, Inputs, Outputs, Parameters, Variables,
};
use serde::{Deserialize, Serialize};

/// With a bladder the force grows without bound at both length limits; an out-of-range length
/// is evaluated this fraction of the range inside the limit (finite, steep force).
const LIMIT_MARGIN: f64 = 1e-3;

/// The effects the parameters switch on, built once at initialization. The bare sleeve needs
/// none of the bladder, friction and connector machinery, and none of their outputs change.
#[derive(Clone, Debug, Serialize, Deserialize)]
enum Pipeline {
    /// Eq. 2.3 alone: no bladder, no friction, rigid connector.
    Sleeve(Sleeve),
    Full(McKibben),
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct McKibbenMuscle {
    pipeline: Pipeline,
    /// Friction history (eq. 2.4), advanced only by accepted steps.
    friction: HysteresisState,
    /// Whether the last evaluation needed the fallback: its warning is logged once per excursion.
    out_of_range: bool,
}

fn geometry(p: &Parameters) -> Result<(Sleeve, BladderTube), String> {
    let preset = match p.preset {
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
        mooney_c1: p.mooney_c1,
        mooney_c2: p.mooney_c2,
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
            Sleeve::new(p.strand_length, p.turns)?,
            tube(
                p.bladder_length,
                p.bladder_inner_diameter,
                p.bladder_thickness,
            ),
        ),
    })
}

/// The warning for an input without a solution: once per excursion, then only the status.
fn out_of_range(
    logged: &mut bool,
    report: &mut Report,
    reason: &str,
    (lo, hi): (f64, f64),
    fallback: Option<(f64, f64)>,
) {
    if !*logged {
        let what = match fallback {
            Some((p, l)) => format!("evaluating at pressure {p} Pa and length {l} m"),
            None => "holding the previous outputs".into(),
        };
        report.warn(format!(
            "{reason} (valid lengths {lo} .. {hi} m, max_length {hi} m); {what} until the inputs return"
        ));
    }
    report.status = report.status.max(Status::Warning);
    *logged = true;
}

/// Eq. 2.3 for the bare sleeve; the outputs of the absent effects keep their neutral values.
fn sleeve_outputs(
    sleeve: &Sleeve,
    inputs: &Inputs,
    out: &mut Outputs,
    logged: &mut bool,
    report: &mut Report,
) {
    let (pressure, requested) = (inputs.pressure, inputs.length);
    let b = sleeve.max_length();
    let length = if requested > b {
        let reason =
            format!("length {requested} m is outside [0, b = {b}] m, the ideal sleeve's range");
        out_of_range(logged, report, &reason, (0.0, b), Some((pressure, b)));
        b
    } else {
        *logged = false;
        requested
    };
    // The sleeve is only ever pushed outwards: under vacuum the bladder leaves it.
    let p_eff = pressure.max(0.0);
    out.force = sleeve.force(p_eff, length);
    out.volume = sleeve.volume(length);
    out.effective_pressure = p_eff;
    out.stiffness = sleeve.stiffness(p_eff, length);
    out.bladder_contact = pressure > 0.0;
    out.threshold_pressure = 0.0;
    out.stretch_axial = 1.0;
    out.stretch_hoop = 1.0;
    out.stretch_radial = 1.0;
    out.stress_axial = 0.0;
    out.stress_hoop = 0.0;
    out.stress_radial = 0.0;
    out.friction_force = 0.0;
}

impl McKibbenMuscle {
    /// Writes the outputs of the selected pipeline; `commit` advances the friction history.
    fn outputs(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        report: &mut Report,
        commit: bool,
    ) {
        match &self.pipeline {
            Pipeline::Sleeve(sleeve) => {
                sleeve_outputs(sleeve, inputs, outputs, &mut self.out_of_range, report)
            }
            Pipeline::Full(muscle) => {
                if let Some(out) = Self::compute(
                    muscle,
                    &self.friction,
                    &mut self.out_of_range,
                    inputs,
                    report,
                ) {
                    Self::write(outputs, &out);
                    if commit {
                        self.friction = out.friction_state;
                    }
                }
            }
        }
    }

    /// The full model at the current inputs; out of range, the nearest point inside it (logged).
    fn compute(
        muscle: &McKibben,
        friction: &HysteresisState,
        logged: &mut bool,
        inputs: &Inputs,
        report: &mut Report,
    ) -> Option<McKibbenOutput> {
        let (pressure, length) = (inputs.pressure, inputs.length);
        let reason = match muscle.evaluate(pressure, length, friction) {
            Ok(out) => {
                *logged = false;
                return Some(out);
            }
            Err(reason) => reason,
        };
        let (lo, hi) = (muscle.min_length(), muscle.max_length());
        let margin = if muscle.bladder().is_some() {
            LIMIT_MARGIN * (hi - lo)
        } else {
            0.0
        };
        // max/min rather than clamp: never panics, even on limits from a crafted FMU state.
        let clamped = length.max(lo + margin).min(hi - margin);
        let fallback = [(pressure, clamped), (pressure.max(0.0), clamped)]
            .into_iter()
            .find_map(|(p, l)| muscle.evaluate(p, l, friction).ok().map(|o| (p, l, o)));
        let point = fallback.as_ref().map(|(p, l, _)| (*p, *l));
        out_of_range(logged, report, &reason, (lo, hi), point);
        fallback.map(|(_, _, out)| out)
    }

    fn write(o: &mut Outputs, out: &McKibbenOutput) {
        o.force = out.force;
        o.volume = out.volume;
        o.effective_pressure = out.effective_pressure;
        o.threshold_pressure = out.threshold_pressure;
        o.stretch_axial = out.stretch_axial;
        o.stretch_hoop = out.stretch_hoop;
        o.stretch_radial = out.stretch_radial;
        o.stress_axial = out.stress_axial;
        o.stress_hoop = out.stress_hoop;
        o.stress_radial = out.stress_radial;
        o.friction_force = out.friction_force;
        o.stiffness = out.stiffness;
        o.bladder_contact = out.bladder_contact;
    }
}

impl Model for McKibbenMuscle {
    type Variables = Variables;
    const DOCUMENTATION: &'static str = include_str!("mckibben_muscle.html");

    fn new(p: &Parameters, start: &Inputs) -> Result<Self, Refusal> {
        let (sleeve, tube) = geometry(p)?;
        let model = BladderModel::from_switch(p.bladder_model, p.bladder_layers)?;
        let friction = p.friction.then(|| FrictionParams {
            coefficient: p.friction_coefficient,
            presliding_length: p.presliding_length,
        });
        let muscle = McKibben::new(sleeve, tube, model, friction, p.connector_stiffness)?;
        // Friction starts relaxed (z = 0) at the initial length.
        let friction = HysteresisState::at_rest(start.length);
        let pipeline =
            if muscle.bladder().is_none() && !muscle.has_friction() && !muscle.has_connector() {
                Pipeline::Sleeve(*muscle.sleeve())
            } else {
                Pipeline::Full(muscle)
            };
        Ok(Self {
            pipeline,
            friction,
            out_of_range: false,
        })
    }

    fn calculated_parameters(&self) -> CalculatedParameters {
        match &self.pipeline {
            // The bare sleeve spans 0 .. b (eq. 2.3).
            Pipeline::Sleeve(sleeve) => CalculatedParameters {
                max_length: sleeve.max_length(),
                min_length: 0.0,
            },
            Pipeline::Full(muscle) => CalculatedParameters {
                max_length: muscle.max_length(),
                min_length: muscle.min_length(),
            },
        }
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        self.outputs(inputs, outputs, report, false)
    }

    fn step(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        _time: f64,
        _step: f64,
        report: &mut Report,
    ) {
        // Quasi-static: the held inputs at the end of the step fix the outputs; the friction
        // history follows the length path sampled at the communication points.
        self.outputs(inputs, outputs, report, true)
    }
}
