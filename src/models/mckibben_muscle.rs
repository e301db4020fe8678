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

/// Eq. 2.3 for the bare sleeve; only the outputs that change are written.
fn sleeve_outputs(sleeve: &Sleeve, vars: &mut Vars, logged: &mut bool, report: &mut Report) {
    let (pressure, requested) = (vars.real[real::PRESSURE], vars.real[real::LENGTH]);
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
    let r = &mut vars.real;
    r[real::FORCE] = sleeve.force(p_eff, length);
    r[real::VOLUME] = sleeve.volume(length);
    r[real::EFFECTIVE_PRESSURE] = p_eff;
    r[real::STIFFNESS] = sleeve.stiffness(p_eff, length);
    vars.boolean[boolean::BLADDER_CONTACT] = pressure > 0.0;
}

impl McKibbenMuscle {
    /// Writes the outputs of the selected pipeline; `commit` advances the friction history.
    fn outputs(&mut self, vars: &mut Vars, report: &mut Report, commit: bool) {
        match &self.pipeline {
            Pipeline::Sleeve(sleeve) => {
                sleeve_outputs(sleeve, vars, &mut self.out_of_range, report)
            }
            Pipeline::Full(muscle) => {
                if let Some(out) =
                    Self::compute(muscle, &self.friction, &mut self.out_of_range, vars, report)
                {
                    Self::write(vars, &out);
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
        vars: &Vars,
        report: &mut Report,
    ) -> Option<McKibbenOutput> {
        let (pressure, length) = (vars.real[real::PRESSURE], vars.real[real::LENGTH]);
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

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        saved.friction.check("friction history")?;
        self.friction = saved.friction;
        self.out_of_range = saved.out_of_range;
        Ok(())
    }

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
        let pipeline =
            if muscle.bladder().is_none() && !muscle.has_friction() && !muscle.has_connector() {
                // The outputs of the absent effects keep these values for the whole run.
                let r = &mut vars.real;
                for (index, value) in [
                    (real::THRESHOLD_PRESSURE, 0.0),
                    (real::STRETCH_AXIAL, 1.0),
                    (real::STRETCH_HOOP, 1.0),
                    (real::STRETCH_RADIAL, 1.0),
                    (real::STRESS_AXIAL, 0.0),
                    (real::STRESS_HOOP, 0.0),
                    (real::STRESS_RADIAL, 0.0),
                    (real::FRICTION_FORCE, 0.0),
                ] {
                    r[index] = value;
                }
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

    fn evaluate(&mut self, vars: &mut Vars, report: &mut Report) {
        self.outputs(vars, report, false)
    }

    fn step(&mut self, vars: &mut Vars, _time: f64, _step: f64, report: &mut Report) {
        // Quasi-static: the held inputs at the end of the step fix the outputs; the friction
        // history follows the length path sampled at the communication points.
        self.outputs(vars, report, true)
    }
}
