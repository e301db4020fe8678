//! McKibbenMuscle FMU: gauge pressure and length in, tension force out.
//!
//! Effects, each built only when switched on: the Mooney-Rivlin bladder (`bladder_model` 1 thin
//! wall, 2 thick wall of `bladder_layers` layers), friction hysteresis (`friction`) and a series
//! connector (`connector_stiffness` > 0). With all of them off a step is eq. 2.3 alone.

use super::{Model, Report, Status, Vars};
use crate::physics::bladder::BladderTube;
use crate::physics::calibration::MuscleParams;
use crate::physics::festo::{DMSP_10, DMSP_40};
use crate::physics::friction::HysteresisState;
use crate::physics::gaylord::Sleeve;
use crate::physics::inverse::pressure_for_force;
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
    /// `L_N` of `contraction = 1 - L / L_N`, m (the parameter, or the preset's listed length).
    nominal_length: f64,
    /// Which user-set parameters the preset replaced: a warning with the first outputs.
    notice: Option<String>,
    /// `pressure_solver` on: the muscle to invert and `max_pressure`.
    solver: Option<(McKibben, f64)>,
}

/// The muscle the parameters (or the preset) describe.
struct Resolved {
    sleeve: Sleeve,
    tube: BladderTube,
    nominal_length: f64,
    model: BladderModel,
    /// Parameters the user set that the preset replaced (logged once).
    overridden: Vec<&'static str>,
}

/// Applies `preset`: 1-4 Table 2.1's geometry (the user's rubber and bladder model), 5-6 a Festo
/// muscle fitted to its datasheet (geometry, rubber and thin wall; scaled to `nominal_length` if
/// the user set it). Names the parameters the user set (away from their start values) that the
/// preset replaces.
fn geometry(vars: &Vars) -> Result<Resolved, String> {
    let (r, i) = (&vars.real, &vars.integer);
    let start = Vars::from_start(&INFO);
    let user_set = |index: usize| r[index] != start.real[index];
    let own_model =
        BladderModel::from_switch(i[integer::BLADDER_MODEL], i[integer::BLADDER_LAYERS])?;
    let params = match i[integer::PRESET] {
        0 => MuscleParams {
            nominal_length: r[real::NOMINAL_LENGTH],
            strand_length: r[real::STRAND_LENGTH],
            turns: r[real::TURNS],
            bladder_model: i[integer::BLADDER_MODEL],
            bladder_layers: i[integer::BLADDER_LAYERS],
            bladder_length: r[real::BLADDER_LENGTH],
            bladder_inner_diameter: r[real::BLADDER_INNER_DIAMETER],
            bladder_thickness: r[real::BLADDER_THICKNESS],
            mooney_c1: r[real::MOONEY_C1],
            mooney_c2: r[real::MOONEY_C2],
        },
        k @ 1..=4 => {
            let g = MuscleGeometry::preset((b'A' + k as u8 - 1) as char)
                .ok_or_else(|| format!("preset {k} has no Table 2.1 row"))?;
            MuscleParams {
                nominal_length: g.length,
                strand_length: g.strand_length,
                turns: g.turns,
                bladder_model: i[integer::BLADDER_MODEL],
                bladder_layers: i[integer::BLADDER_LAYERS],
                bladder_length: g.bladder_length,
                bladder_inner_diameter: g.bladder_inner_diameter,
                bladder_thickness: g.bladder_thickness,
                mooney_c1: r[real::MOONEY_C1],
                mooney_c2: r[real::MOONEY_C2],
            }
        }
        k @ 5..=6 => {
            let festo = if k == 5 { DMSP_10 } else { DMSP_40 };
            if user_set(real::NOMINAL_LENGTH) {
                festo.scaled_to(r[real::NOMINAL_LENGTH])
            } else {
                festo
            }
        }
        k => {
            return Err(format!(
                "preset must be 0 (none), 1-4 (Table 2.1 A-D), 5 (Festo DMSP-10) or 6 (Festo DMSP-40), got {k}"
            ))
        }
    };
    let mut overridden = Vec::new();
    if i[integer::PRESET] != 0 {
        let mut reals = vec![
            ("strand_length", real::STRAND_LENGTH),
            ("turns", real::TURNS),
            ("bladder_length", real::BLADDER_LENGTH),
            ("bladder_inner_diameter", real::BLADDER_INNER_DIAMETER),
            ("bladder_thickness", real::BLADDER_THICKNESS),
        ];
        if i[integer::PRESET] <= 4 {
            reals.push(("nominal_length", real::NOMINAL_LENGTH));
        } else {
            reals.push(("mooney_c1", real::MOONEY_C1));
            reals.push(("mooney_c2", real::MOONEY_C2));
            let festo_model = BladderModel::from_switch(params.bladder_model, 1)?;
            if i[integer::BLADDER_MODEL] != start.integer[integer::BLADDER_MODEL]
                && own_model != festo_model
            {
                overridden.push("bladder_model");
            }
        }
        overridden.extend(reals.iter().filter(|(_, k)| user_set(*k)).map(|(n, _)| *n));
    }
    let model = BladderModel::from_switch(params.bladder_model, params.bladder_layers)?;
    if !(params.nominal_length.is_finite() && params.nominal_length > 0.0) {
        return Err(format!(
            "nominal_length must be positive and finite, got {} m",
            params.nominal_length
        ));
    }
    Ok(Resolved {
        sleeve: Sleeve::new(params.strand_length, params.turns)?,
        tube: BladderTube {
            inner_diameter: params.bladder_inner_diameter,
            thickness: params.bladder_thickness,
            unstretched_length: params.bladder_length,
            mooney_c1: params.mooney_c1,
            mooney_c2: params.mooney_c2,
        },
        nominal_length: params.nominal_length,
        model,
        overridden,
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
        let history = self.friction;
        if let Some(notice) = self.notice.take() {
            // A warning: OK-status messages reach the log only with debug logging on.
            report.warn(notice);
        }
        vars.real[real::CONTRACTION] = 1.0 - vars.real[real::LENGTH] / self.nominal_length;
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
        if let Some((muscle, max_pressure)) = &self.solver {
            // Solved from the history the step started with, as the forward model is.
            Self::solve_pressure(muscle, *max_pressure, &history, vars);
        }
    }

    /// `target_pressure`: the pressure that gives `target_force` at the input length (clamped
    /// into the valid range as the forward model is), by the joint's torque-mode solver.
    fn solve_pressure(
        muscle: &McKibben,
        max_pressure: f64,
        history: &HysteresisState,
        vars: &mut Vars,
    ) {
        let (length, force) = (vars.real[real::LENGTH], vars.real[real::TARGET_FORCE]);
        let (lo, hi) = (muscle.min_length(), muscle.max_length());
        let margin = if muscle.bladder().is_some() {
            LIMIT_MARGIN * (hi - lo)
        } else {
            0.0
        };
        let inside = length.max(lo + margin).min(hi - margin);
        let solved = pressure_for_force(muscle, length, force, max_pressure, history)
            .or_else(|_| pressure_for_force(muscle, inside, force, max_pressure, history));
        if let Ok(s) = solved {
            vars.real[real::TARGET_PRESSURE] = s.argument;
            vars.boolean[boolean::TARGET_FORCE_SATURATED] = s.saturated;
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

    fn new(vars: &mut Vars) -> Result<Self, String> {
        let Resolved {
            sleeve,
            tube,
            nominal_length,
            model,
            overridden,
        } = geometry(vars)?;
        let r = &mut vars.real;
        for (index, value) in [
            (real::EFFECTIVE_NOMINAL_LENGTH, nominal_length),
            (real::EFFECTIVE_STRAND_LENGTH, sleeve.strand_length),
            (real::EFFECTIVE_TURNS, sleeve.turns),
            (real::EFFECTIVE_BLADDER_LENGTH, tube.unstretched_length),
            (real::EFFECTIVE_BLADDER_INNER_DIAMETER, tube.inner_diameter),
            (real::EFFECTIVE_BLADDER_THICKNESS, tube.thickness),
            (real::EFFECTIVE_MOONEY_C1, tube.mooney_c1),
            (real::EFFECTIVE_MOONEY_C2, tube.mooney_c2),
            (
                real::EFFECTIVE_BRAID_ANGLE,
                (nominal_length / sleeve.strand_length).min(1.0).acos(),
            ),
        ] {
            r[index] = value;
        }
        vars.integer[integer::EFFECTIVE_BLADDER_MODEL] = match model {
            BladderModel::None => 0,
            BladderModel::ThinWall => 1,
            BladderModel::ThickWall { .. } => 2,
        };
        let notice = (!overridden.is_empty()).then(|| {
            format!(
                "preset {} replaces the value you set for {} (the effective_* calculated parameters show the values in use)",
                vars.integer[integer::PRESET],
                overridden.join(", ")
            )
        });
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
        let max_pressure = vars.real[real::MAX_PRESSURE];
        if !(max_pressure.is_finite() && max_pressure >= 0.0) {
            return Err(format!(
                "max_pressure must be finite and >= 0 Pa, got {max_pressure}"
            ));
        }
        let solver = vars.boolean[boolean::PRESSURE_SOLVER].then(|| (muscle.clone(), max_pressure));
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
            nominal_length,
            notice,
            solver,
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
