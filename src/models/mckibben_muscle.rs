//! McKibbenMuscle FMU: gauge pressure and length in, tension force out.
//!
//! Effects, each built only when switched on: the Mooney-Rivlin bladder (`bladder_model` 1-6, see
//! [`BladderModel::from_switch`]; 3 is the exact wall of `bladder_layers` quadrature nodes),
//! friction hysteresis (`friction`) and a series connector (`connector_stiffness` > 0).
//! With all of them off a step is eq. 2.3 alone.

use super::wall_arrays::{self, wall_quantity_of, WallQuantity};
use super::{HistoryKey, Model, Partials, Refusal, Report, Status};
use crate::physics::bladder::BladderTube;
use crate::physics::by_pressure_length::ByPressureLength;
use crate::physics::festo;
use crate::physics::friction::HysteresisState;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::{
    bare_sleeve, is_slack, strand_rigidity, BladderModel, FrictionParams, McKibben, McKibbenOutput,
    MuscleGeometry, OutOfRange,
};
use crate::physics::muscle_params::MuscleParams;
use crate::variables::mckibben_muscle::{
    ArrayOutput, CalculatedParameters, ContractionBy, EffectivePressureBy, ForceBy,
    FrictionForceBy, Inputs, Outputs, Parameters, StiffnessBy, StressAxialBy, StressHoopBy,
    StressRadialBy, StretchAxialBy, StretchHoopBy, StretchRadialBy, TargetPressureBy,
    ThresholdPressureBy, Unknown, Variables, VolumeBy,
};
use serde::{Deserialize, Serialize};

/// The effects the parameters switch on, built once at initialization. The bare sleeve needs
/// none of the bladder, friction and connector machinery, and none of their outputs change.
// Built once per instance and never moved on the per-step path: its size does not matter, and a
// box would add a load to every step of the full model.
#[allow(clippy::large_enum_variant)]
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
    /// The parameters in use (the preset's or the user's), read back as `effective_*`.
    effective: MuscleParams,
    /// The bare sleeve, once its first evaluation has logged the notice and written the neutral
    /// outputs of the absent effects (which never change) into the outputs this model is paired
    /// with, and when no pressure solver runs: then a step is eq. 2.3 alone, behind one test. A
    /// model built or deserialized afresh starts without it.
    #[serde(skip)]
    bare_sleeve: Option<Sleeve>,
    /// Which user-set parameters the preset replaced: a warning with the first outputs.
    notice: Option<String>,
    /// `pressure_solver` on: the muscle to invert and `max_pressure`.
    solver: Option<(McKibben, f64)>,
    /// The dissertation's signed force (`signed_force`); else tension only (see [`tension_only`]).
    signed_force: bool,
    /// The straight strands' axial stiffness `k_s = E A / b`, N/m (from `strand_rigidity`).
    strand_stiffness: f64,
    /// `out_of_range_policy` 2: a step whose input is out of range is refused, so a step past
    /// the breaking length is not evaluated where one rigid evaluation shows it out of range.
    refuse_out_of_range: bool,
}

/// The muscle the parameters (or the preset) describe, with the parameters the user set that
/// the preset replaced.
struct Resolved {
    params: MuscleParams,
    /// Parameters the user set that the preset replaced (logged once).
    overridden: Vec<&'static str>,
}

/// Applies `preset`: 1-4 Table 2.1's geometry (the user's rubber and bladder model), 5-6 a Festo
/// muscle fitted to its datasheet (geometry, rubber and thin wall; scaled to `nominal_length` if
/// the user set it). Names the parameters the user set (away from their start values) that the
/// preset replaces.
fn geometry(p: &Parameters) -> Result<Resolved, String> {
    let start = Parameters::default();
    let own = MuscleParams {
        nominal_length: p.nominal_length,
        strand_length: p.strand_length,
        turns: p.turns,
        bladder_model: p.bladder_model,
        bladder_layers: p.bladder_layers,
        bladder_length: p.bladder_length,
        bladder_inner_diameter: p.bladder_inner_diameter,
        bladder_thickness: p.bladder_thickness,
        mooney_c1: p.mooney_c1,
        mooney_c2: p.mooney_c2,
    };
    let params = match p.preset {
        0 => own,
        k @ 1..=4 => {
            let g = MuscleGeometry::preset((b'A' + k as u8 - 1) as char)
                .ok_or_else(|| format!("preset {k} has no Table 2.1 row"))?;
            MuscleParams {
                nominal_length: g.length,
                strand_length: g.strand_length,
                turns: g.turns,
                bladder_length: g.bladder_length,
                bladder_inner_diameter: g.bladder_inner_diameter,
                bladder_thickness: g.bladder_thickness,
                ..own
            }
        }
        k @ 5..=8 => {
            let (festo, _) =
                festo::preset(k).ok_or_else(|| format!("preset {k} has no DMSP size"))?;
            if p.nominal_length != start.nominal_length {
                festo.scaled_to(p.nominal_length)
            } else {
                festo
            }
        }
        k => {
            return Err(format!(
                "preset must be 0 (none), 1-4 (Table 2.1 A-D), 5 (Festo DMSP-10), 6 (DMSP-40), 7 (DMSP-5) or 8 (DMSP-20), got {k}"
            ))
        }
    };
    let mut overridden = Vec::new();
    if p.preset != 0 {
        let mut replaced = vec![
            ("strand_length", p.strand_length != start.strand_length),
            ("turns", p.turns != start.turns),
            ("bladder_length", p.bladder_length != start.bladder_length),
            (
                "bladder_inner_diameter",
                p.bladder_inner_diameter != start.bladder_inner_diameter,
            ),
            (
                "bladder_thickness",
                p.bladder_thickness != start.bladder_thickness,
            ),
        ];
        if p.preset <= 4 {
            replaced.push(("nominal_length", p.nominal_length != start.nominal_length));
        } else {
            replaced.push(("mooney_c1", p.mooney_c1 != start.mooney_c1));
            replaced.push(("mooney_c2", p.mooney_c2 != start.mooney_c2));
            let festo_model =
                BladderModel::from_switch(params.bladder_model, params.bladder_layers)?;
            let own_model = BladderModel::from_switch(p.bladder_model, p.bladder_layers).ok();
            replaced.push((
                "bladder_model",
                p.bladder_model != start.bladder_model && own_model != Some(festo_model),
            ));
        }
        overridden.extend(replaced.iter().filter(|(_, set)| *set).map(|(n, _)| *n));
    }
    if !(params.nominal_length.is_finite() && params.nominal_length > 0.0) {
        return Err(format!(
            "nominal_length must be positive and finite, got {} m",
            params.nominal_length
        ));
    }
    Ok(Resolved { params, overridden })
}

/// `E A` of all strands together, N: the user's `strand_rigidity`, or for the Festo presets
/// (unless set) their aramid strands, sized by the catalogue's largest force.
fn rigidity(p: &Parameters) -> Result<f64, String> {
    let set = p.strand_rigidity != Parameters::default().strand_rigidity;
    strand_rigidity(p.strand_rigidity, set, festo::largest_force(p.preset))
}

/// An input without a solution: explained once per excursion, then only flagged. No excursion
/// (`None`) ends the one logged.
fn log_excursion(logged: &mut bool, report: &mut Report, excursion: Option<OutOfRange>) {
    match excursion {
        None => *logged = false,
        Some(e) => {
            report.clamp(!*logged, || e.message());
            *logged = true;
        }
    }
}

/// The bare sleeve on its stretching strands, logged past the breaking length. Out of line, so
/// that the per-step path of the ideal muscle stays small enough to inline.
#[cold]
#[inline(never)]
fn sleeve_on_strands(
    sleeve: &Sleeve,
    strand_stiffness: f64,
    inputs: &Inputs,
    logged: &mut bool,
    report: &mut Report,
) -> bare_sleeve::SleeveState {
    let (pressure, length) = (inputs.pressure, inputs.length);
    let (state, excursion) =
        bare_sleeve::on_the_strands_state(sleeve, strand_stiffness, pressure, length);
    log_excursion(logged, report, excursion);
    state
}

/// Eq. 2.3 for the bare sleeve, with its stretching strands.
#[inline(always)]
fn sleeve_outputs(
    sleeve: &Sleeve,
    strand_stiffness: f64,
    inputs: &Inputs,
    out: &mut Outputs,
    logged: &mut bool,
    report: &mut Report,
) {
    let (pressure, length) = (inputs.pressure, inputs.length);
    let state = match bare_sleeve::below_the_strands(sleeve, strand_stiffness, pressure, length) {
        Some(state) => {
            *logged = false;
            state
        }
        None => sleeve_on_strands(sleeve, strand_stiffness, inputs, logged, report),
    };
    out.force = state.force;
    out.volume = state.volume;
    out.effective_pressure = state.effective_pressure;
    out.stiffness = state.stiffness;
    out.bladder_contact = state.contact;
}

/// A braided muscle cannot push: past its free contraction (signed force < 0, where eq. 2.3's
/// `3 L^2 - b^2` changes sign for the bare sleeve) the strands buckle and the muscle is slack,
/// carrying no force and having no stiffness. With `signed` the dissertation's force stands.
#[inline(always)]
fn tension_only(out: &mut Outputs, signed: bool) {
    out.slack = is_slack(out.force, signed);
    if out.slack {
        out.force = 0.0;
        out.stiffness = 0.0;
    }
}

/// The outputs of the effects the bare sleeve lacks, at their neutral values: no bladder (no
/// threshold, no stretch, no stress) and no friction.
fn neutral_outputs(out: &mut Outputs) {
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
    /// The bare sleeve's path (eq. 2.3 alone) is inline; the rest is out of line.
    #[inline(always)]
    fn outputs(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        report: &mut Report,
        commit: bool,
    ) {
        if let Some(sleeve) = &self.bare_sleeve {
            outputs.contraction = 1.0 - inputs.length / self.effective.nominal_length;
            let k_s = self.strand_stiffness;
            sleeve_outputs(sleeve, k_s, inputs, outputs, &mut self.out_of_range, report);
        } else {
            self.all_outputs(inputs, outputs, report, commit);
        }
        tension_only(outputs, self.signed_force);
    }

    /// [`McKibbenMuscle::outputs`] of any pipeline, with the notice and the pressure solver.
    #[inline(never)]
    fn all_outputs(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        report: &mut Report,
        commit: bool,
    ) {
        if let Some(notice) = self.notice.take() {
            // Logged at fmi2OK (category logStatusWarning), so that strict masters still run.
            report.add(Status::Ok, notice);
        }
        let history = self.friction;
        outputs.contraction = 1.0 - inputs.length / self.effective.nominal_length;
        match &self.pipeline {
            Pipeline::Sleeve(sleeve) => {
                neutral_outputs(outputs);
                let k_s = self.strand_stiffness;
                sleeve_outputs(sleeve, k_s, inputs, outputs, &mut self.out_of_range, report);
                if self.solver.is_none() {
                    self.bare_sleeve = Some(*sleeve);
                }
            }
            Pipeline::Full(muscle) => {
                if commit && self.refuse_out_of_range {
                    // The step is refused (fmi2Discard): its outputs and history stay.
                    let (p, l) = (inputs.pressure, inputs.length);
                    if let Some(e) = muscle.refused_past_breaking(p, l, &self.friction) {
                        log_excursion(&mut self.out_of_range, report, Some(e));
                        return;
                    }
                }
                let (out, excursion) = muscle.evaluate_with_strands(
                    inputs.pressure,
                    inputs.length,
                    self.strand_stiffness,
                    &self.friction,
                );
                log_excursion(&mut self.out_of_range, report, excursion);
                if let Some(out) = out {
                    Self::write(outputs, &out);
                    if commit {
                        self.friction = out.friction_state;
                    }
                }
            }
        }
        if let Some((muscle, max_pressure)) = &self.solver {
            // Solved from the history the step started with, as the forward model is.
            let (length, force) = (inputs.length, inputs.target_force);
            if let Some(s) = muscle.target_pressure(*max_pressure, &history, length, force) {
                outputs.target_pressure = s.argument;
                outputs.target_force_saturated = s.saturated;
            }
        }
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

/// Writes the rows of the physics' partials, by pressure and length.
fn write_rows(d: &ByPressureLength, p: &mut Partials<Variables>) {
    p.row(ForceBy {
        pressure: d.force[0],
        length: d.force[1],
    })
    .row(EffectivePressureBy {
        pressure: d.effective_pressure[0],
        length: d.effective_pressure[1],
    })
    .row(FrictionForceBy {
        pressure: d.friction_force[0],
        length: d.friction_force[1],
    })
    .row(VolumeBy {
        pressure: d.volume[0],
        length: d.volume[1],
    })
    .row(ThresholdPressureBy {
        pressure: d.threshold_pressure[0],
        length: d.threshold_pressure[1],
    })
    .row(StretchAxialBy {
        pressure: d.stretch_axial[0],
        length: d.stretch_axial[1],
    })
    .row(StretchHoopBy {
        pressure: d.stretch_hoop[0],
        length: d.stretch_hoop[1],
    })
    .row(StretchRadialBy {
        pressure: d.stretch_radial[0],
        length: d.stretch_radial[1],
    })
    .row(StressAxialBy {
        pressure: d.stress_axial[0],
        length: d.stress_axial[1],
    })
    .row(StressHoopBy {
        pressure: d.stress_hoop[0],
        length: d.stress_hoop[1],
    })
    // The radial stress at the inner wall is minus the pressure, whatever the length.
    .row(StressRadialBy {
        pressure: d.stress_radial[0],
    });
}

impl McKibbenMuscle {
    /// `[d/dpressure, d/dlength]` of `stiffness` on the branch [`Model::evaluate`] takes: 0
    /// while slack and on the strands; else eq. 2.3's for the bare sleeve, or
    /// [`McKibben::stiffness_partials`] (a second-order pass through the bladder).
    fn stiffness_row(&self, inputs: &Inputs) -> Result<[f64; 2], String> {
        let (pressure, length, k_s) = (inputs.pressure, inputs.length, self.strand_stiffness);
        if self.slack_at(inputs)? {
            return Ok([0.0; 2]);
        }
        match &self.pipeline {
            Pipeline::Sleeve(s) => Ok(bare_sleeve::stiffness_partials(s, k_s, pressure, length)),
            Pipeline::Full(m) => {
                m.stiffness_partials_with_strands(pressure, length, k_s, &self.friction)
            }
        }
    }

    /// Partials on the branch [`Model::evaluate`] takes (see
    /// [`McKibben::partials_with_strands`]); the force's 0 while slack.
    fn partials_at(&self, inputs: &Inputs) -> Result<ByPressureLength, String> {
        let (pressure, length, k_s) = (inputs.pressure, inputs.length, self.strand_stiffness);
        let mut d = match &self.pipeline {
            Pipeline::Sleeve(s) => bare_sleeve::partials(s, k_s, pressure, length),
            Pipeline::Full(m) => m.partials_with_strands(pressure, length, k_s, &self.friction)?,
        };
        if self.slack_at(inputs)? {
            d.force = [0.0; 2];
        }
        Ok(d)
    }

    /// Whether [`tension_only`] makes the muscle slack at `inputs`: its signed force, on the
    /// branch [`Model::evaluate`] takes, is negative.
    fn slack_at(&self, inputs: &Inputs) -> Result<bool, String> {
        if self.signed_force {
            return Ok(false);
        }
        let (pressure, length) = (inputs.pressure, inputs.length);
        let force = match &self.pipeline {
            Pipeline::Sleeve(s) => bare_sleeve::signed_force(s, pressure, length),
            Pipeline::Full(m) => m.signed_force_on_branch(pressure, length, &self.friction)?,
        };
        Ok(is_slack(force, false))
    }
}

impl Model for McKibbenMuscle {
    type Variables = Variables;
    const ALGEBRAIC_MODEL_EXCHANGE: bool = true;
    const DOCUMENTATION: &'static str = include_str!("mckibben_muscle.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        saved.friction.check("friction history")?;
        self.friction = saved.friction;
        self.out_of_range = saved.out_of_range;
        // The parameter notice is logged once: not again if the saved model had logged it.
        if saved.notice.is_none() {
            self.notice = None;
        }
        Ok(())
    }

    fn new(p: &Parameters, start: &Inputs) -> Result<Self, Refusal> {
        let Resolved { params, overridden } = geometry(p)?;
        let sleeve = Sleeve::new(params.strand_length, params.turns)?;
        let tube = BladderTube {
            inner_diameter: params.bladder_inner_diameter,
            thickness: params.bladder_thickness,
            unstretched_length: params.bladder_length,
            mooney_c1: params.mooney_c1,
            mooney_c2: params.mooney_c2,
        };
        let model = BladderModel::from_switch(params.bladder_model, params.bladder_layers)?;
        let notice = (!overridden.is_empty()).then(|| {
            format!(
                "preset {} replaces the value you set for {} (the effective_* calculated parameters show the values in use)",
                p.preset,
                overridden.join(", ")
            )
        });
        let friction = p.friction.then_some(FrictionParams {
            coefficient: p.friction_coefficient,
            presliding_length: p.presliding_length,
        });
        let muscle = McKibben::new(sleeve, tube, model, friction, p.connector_stiffness)?;
        if !(p.max_pressure.is_finite() && p.max_pressure >= 0.0) {
            return Err(format!(
                "max_pressure must be finite and >= 0 Pa, got {}",
                p.max_pressure
            )
            .into());
        }
        let solver = p.pressure_solver.then(|| (muscle.clone(), p.max_pressure));
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
            bare_sleeve: None,
            effective: params,
            notice,
            solver,
            signed_force: p.signed_force,
            strand_stiffness: rigidity(p)? / params.strand_length,
            refuse_out_of_range: p.out_of_range_policy == 2,
        })
    }

    fn calculated_parameters(&self) -> CalculatedParameters {
        let (max_length, min_length) = match &self.pipeline {
            // The bare sleeve spans 0 .. b (eq. 2.3).
            Pipeline::Sleeve(sleeve) => (sleeve.max_length(), 0.0),
            Pipeline::Full(muscle) => (muscle.max_length(), muscle.min_length()),
        };
        let e = &self.effective;
        CalculatedParameters {
            max_length,
            min_length,
            effective_nominal_length: e.nominal_length,
            effective_strand_length: e.strand_length,
            effective_turns: e.turns,
            effective_bladder_length: e.bladder_length,
            effective_bladder_inner_diameter: e.bladder_inner_diameter,
            effective_bladder_thickness: e.bladder_thickness,
            effective_mooney_c1: e.mooney_c1,
            effective_mooney_c2: e.mooney_c2,
            effective_braid_angle: e.braid_angle(),
            effective_bladder_model: e.bladder_model,
        }
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        self.outputs(inputs, outputs, report, false)
    }

    fn array(&self, inputs: &Inputs, array: ArrayOutput, out: &mut [f64]) -> Result<(), String> {
        let quantity = wall_quantity_of!(array);
        let Pipeline::Full(muscle) = &self.pipeline else {
            return wall_arrays::absent(out);
        };
        let Some(bladder) = muscle.bladder() else {
            return wall_arrays::absent(out);
        };
        // The bladder's own length: the input less the connector's stretch, as evaluated.
        let (p, k_s) = (inputs.pressure, self.strand_stiffness);
        let (state, _) = muscle.evaluate_with_strands(p, inputs.length, k_s, &self.friction);
        let state = state.ok_or("no solution at these inputs")?;
        let length = state.actual_length;
        wall_arrays::write(quantity, out, |f| bladder.wall_field(p, length, f))
    }

    #[inline]
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

    /// Every row; the stiffness's (a second-order pass through the bladder) only when wanted
    /// (for the bare sleeve always: it is eq. 2.3's closed form).
    fn partials(&mut self, inputs: &Inputs, p: &mut Partials<Variables>) -> Result<(), String> {
        write_rows(&self.partials_at(inputs)?, p);
        if p.wants(Unknown::Stiffness) || matches!(self.pipeline, Pipeline::Sleeve(_)) {
            let [pressure, length] = self.stiffness_row(inputs)?;
            p.row(StiffnessBy { pressure, length });
        }
        // contraction = 1 - length / nominal_length.
        let per_length = -1.0 / self.effective.nominal_length;
        p.row(ContractionBy { length: per_length });
        let target = match &self.solver {
            Some((muscle, max_pressure)) => muscle.target_pressure_partials(
                *max_pressure,
                &self.friction,
                inputs.length,
                inputs.target_force,
            ),
            None => [0.0; 2],
        };
        p.row(TargetPressureBy {
            length: target[0],
            target_force: target[1],
        });
        Ok(())
    }

    /// The partials read the friction history besides the inputs.
    fn partials_key(&self) -> Option<HistoryKey> {
        Some(HistoryKey::of([self.friction.z, self.friction.position]))
    }
}

#[cfg(test)]
mod tests {
    use super::super::all_partials;
    use super::*;

    /// The stiffness's row (a second-order pass through the bladder) is written only for a call
    /// that wants it, and then equals the physics' partials.
    #[test]
    fn stiffness_row_only_when_wanted() {
        let p = Parameters {
            preset: 4,
            bladder_model: 2,
            bladder_layers: 4,
            friction: true,
            connector_stiffness: 5e4,
            ..Default::default()
        };
        let x = Inputs {
            pressure: 3e5,
            length: 0.12,
            ..Default::default()
        };
        let mut m = McKibbenMuscle::new(&p, &x).unwrap();
        let mut first = Partials::default();
        first.ask_for([Unknown::Force].into_iter());
        m.partials(&x, &mut first).unwrap();
        assert!(first.get(Unknown::Stiffness).is_none());
        let with = all_partials(&mut m, &x).unwrap();
        let Pipeline::Full(muscle) = &m.pipeline else {
            panic!("a bladder needs the full pipeline");
        };
        let exact = muscle.stiffness_partials(3e5, 0.12, &m.friction).unwrap();
        assert_eq!(
            with.get(Unknown::Stiffness),
            Some(&[exact[0], exact[1], 0.0][..])
        );
        assert!(exact.iter().all(|d| *d != 0.0));
        assert_eq!(with.get(Unknown::Force), first.get(Unknown::Force));
    }

    /// Under `out_of_range_policy` 2 a step past the breaking length is refused before it is
    /// evaluated: the outputs and the friction history stay as the last accepted step left them,
    /// and the report flags the excursion with the breaking length's reason; under policy 0 the
    /// same step is evaluated (the strands at the breaking length).
    #[test]
    fn a_refused_step_past_breaking_is_not_evaluated() {
        let base = Parameters {
            preset: 1,
            bladder_model: 1,
            friction: true,
            ..Default::default()
        };
        let x = Inputs {
            pressure: 3e5,
            length: 0.1,
            ..Default::default()
        };
        let far = Inputs {
            length: 0.2,
            ..x.clone()
        };
        for policy in [0, 2] {
            let p = Parameters {
                out_of_range_policy: policy,
                ..base.clone()
            };
            let mut m = McKibbenMuscle::new(&p, &x).unwrap();
            let mut out = Outputs::default();
            m.step(&x, &mut out, 0.0, 1e-3, &mut Report::default());
            let (before, history) = (out.clone(), m.friction);
            let mut report = Report::default();
            m.step(&far, &mut out, 1e-3, 1e-3, &mut report);
            assert!(report.clamped());
            let why = report.clamp_messages().join("");
            assert!(why.contains("past max_length"), "{why}");
            if policy == 2 {
                assert_eq!(out.force, before.force);
                assert_eq!(m.friction, history);
                assert!(why.contains("holding the previous outputs"), "{why}");
            } else {
                // The strands stretched to the breaking length.
                assert!(out.force > before.force, "{} {}", out.force, before.force);
            }
        }
    }

    /// The bare sleeve writes the neutral outputs of the absent effects once per model, and every
    /// model built or deserialized afresh writes them again: outputs that came with an importer's
    /// bytes (whatever they hold) are right after the first step.
    #[test]
    fn neutral_outputs_are_written_by_every_fresh_model() {
        let p = Parameters::default();
        let x = Inputs {
            pressure: 3e5,
            length: 0.1,
            ..Default::default()
        };
        let garbage = Outputs {
            threshold_pressure: 7.0,
            stretch_axial: 7.0,
            stretch_hoop: 7.0,
            stretch_radial: 7.0,
            stress_axial: 7.0,
            stress_hoop: 7.0,
            stress_radial: 7.0,
            friction_force: 7.0,
            ..Default::default()
        };
        let neutral = |o: &Outputs| {
            [
                o.threshold_pressure,
                o.stress_axial,
                o.stress_hoop,
                o.stress_radial,
            ]
            .iter()
            .all(|&v| v == 0.0)
                && o.friction_force == 0.0
                && [o.stretch_axial, o.stretch_hoop, o.stretch_radial] == [1.0; 3]
        };
        let mut m = McKibbenMuscle::new(&p, &x).unwrap();
        assert!(matches!(m.pipeline, Pipeline::Sleeve(_)));
        let mut out = garbage.clone();
        for _ in 0..2 {
            m.step(&x, &mut out, 0.0, 1e-3, &mut Report::default());
            assert!(neutral(&out), "{out:?}");
            assert!(m.bare_sleeve.is_some());
        }
        let bytes = postcard::to_allocvec(&m).unwrap();
        let mut restored: McKibbenMuscle = postcard::from_bytes(&bytes).unwrap();
        assert!(restored.bare_sleeve.is_none());
        let mut out = garbage;
        restored.step(&x, &mut out, 0.0, 1e-3, &mut Report::default());
        assert!(neutral(&out), "{out:?}");
        // Eq. 2.3 itself.
        let sleeve = Sleeve::new(p.strand_length, p.turns).unwrap();
        assert_eq!(out.force, sleeve.force(3e5, 0.1));
    }
}

#[cfg(test)]
mod slack_tests {
    use super::super::all_partials;
    use super::*;
    use crate::variables::mckibben_muscle::Known;

    fn at(m: &mut McKibbenMuscle, pressure: f64, length: f64) -> Outputs {
        let x = Inputs {
            pressure,
            length,
            ..Default::default()
        };
        let mut out = Outputs::default();
        m.step(&x, &mut out, 0.0, 1e-3, &mut Report::default());
        out
    }

    fn built(p: &Parameters, length: f64) -> McKibbenMuscle {
        let x = Inputs {
            length,
            ..Default::default()
        };
        McKibbenMuscle::new(p, &x).unwrap()
    }

    /// Eq. 2.3, F = P (3 L^2 - b^2) / (4 pi n^2), crosses zero at L = b / sqrt(3): below it the
    /// bare sleeve is slack (force and stiffness 0, `slack` set), above it eq. 2.3 stands, and
    /// `signed_force` gives eq. 2.3 everywhere.
    #[test]
    fn bare_sleeve_is_slack_below_its_free_contraction() {
        let p = Parameters::default();
        let (b, n, pressure) = (p.strand_length, p.turns, 3e5);
        let eq_2_3 =
            |l: f64| pressure * (3.0 * l * l - b * b) / (4.0 * std::f64::consts::PI * n * n);
        let free = b / 3f64.sqrt();
        let mut m = built(&p, 0.09);
        for l in [0.5 * free, 0.99 * free, free * (1.0 - 1e-9)] {
            let out = at(&mut m, pressure, l);
            assert!(
                out.slack && out.force == 0.0 && out.stiffness == 0.0,
                "{l}: {out:?}"
            );
        }
        for l in [free * (1.0 + 1e-9), 1.01 * free, 0.9 * b] {
            let out = at(&mut m, pressure, l);
            assert!(!out.slack, "{l}");
            assert!(
                (out.force - eq_2_3(l)).abs() <= 1e-12 * eq_2_3(0.9 * b),
                "{l}"
            );
            assert!(out.force >= 0.0);
        }
        // Continuous through the free contraction: the force there is 0 to rounding.
        let near = at(&mut m, pressure, free * (1.0 + 1e-9)).force;
        assert!(near.abs() < 1e-6 * eq_2_3(b), "{near}");
        let mut signed = built(
            &Parameters {
                signed_force: true,
                ..p
            },
            0.09,
        );
        let out = at(&mut signed, pressure, 0.8 * free);
        assert!(!out.slack);
        assert!((out.force - eq_2_3(0.8 * free)).abs() < 1e-9 * eq_2_3(b).abs());
        assert!(out.force < 0.0);
    }

    /// The Festo DMSP-10 (preset 5) at nominal length 0.2 m and 300 kPa: the dissertation's
    /// signed force, +24.50 N at 10 % contraction and -13.33 N at 15 %, is tension only by
    /// default: positive at 10 %, 0 and slack at 15 %, and continuous through the zero crossing
    /// found by bisection on the signed force.
    #[test]
    fn festo_dmsp_10_goes_slack_past_its_free_contraction() {
        let p = Parameters {
            preset: 5,
            nominal_length: 0.2,
            ..Default::default()
        };
        let signed_p = Parameters {
            signed_force: true,
            ..p.clone()
        };
        let (mut m, mut s) = (built(&p, 0.18), built(&signed_p, 0.18));
        let pressure = 3e5;
        let l = |contraction: f64| 0.2 * (1.0 - contraction);
        let signed = |s: &mut McKibbenMuscle, c: f64| at(s, pressure, l(c)).force;
        assert!((signed(&mut s, 0.10) - 24.50).abs() < 0.01);
        assert!((signed(&mut s, 0.15) + 13.33).abs() < 0.01);
        let tension = at(&mut m, pressure, l(0.10));
        assert!(!tension.slack && (tension.force - signed(&mut s, 0.10)).abs() < 1e-12);
        for c in [0.15, 0.2, 0.25] {
            let out = at(&mut m, pressure, l(c));
            assert!(
                out.slack && out.force == 0.0 && out.stiffness == 0.0,
                "{c}: {out:?}"
            );
        }
        // The zero crossing of the signed force, between 10 % and 15 % contraction.
        let (mut lo, mut hi) = (0.10, 0.15);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if signed(&mut s, mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let before = at(&mut m, pressure, l(lo - 1e-7));
        let after = at(&mut m, pressure, l(hi + 1e-7));
        assert!(!before.slack && after.slack, "{before:?} {after:?}");
        assert!(
            before.force > 0.0 && before.force < 1e-3,
            "{}",
            before.force
        );
        assert_eq!(after.force, 0.0);
    }

    /// While slack the force's and the stiffness's partials are 0 (the force is 0 nearby); taut,
    /// they are the signed model's.
    #[test]
    fn partials_vanish_while_slack() {
        let p = Parameters {
            preset: 5,
            nominal_length: 0.2,
            ..Default::default()
        };
        let mut m = built(&p, 0.18);
        let mut s = built(
            &Parameters {
                signed_force: true,
                ..p.clone()
            },
            0.18,
        );
        let x = |length: f64| Inputs {
            pressure: 3e5,
            length,
            ..Default::default()
        };
        let slack = all_partials(&mut m, &x(0.17)).unwrap();
        for output in [Unknown::Force, Unknown::Stiffness] {
            assert!(
                slack.get(output).unwrap().iter().all(|d| *d == 0.0),
                "{output:?}"
            );
        }
        let signed = all_partials(&mut s, &x(0.17)).unwrap();
        assert_ne!(signed.partial(Unknown::Force, Known::Pressure), Some(0.0));
        assert_eq!(
            all_partials(&mut m, &x(0.19)).unwrap(),
            all_partials(&mut s, &x(0.19)).unwrap()
        );
    }
}

#[cfg(test)]
mod strand_tests {
    use super::super::all_partials;
    use super::*;

    /// Whether [`Model::evaluate`] puts `inputs` on the stretching strands of `m`.
    fn on_strands(m: &McKibbenMuscle, inputs: &Inputs) -> bool {
        let (pressure, length, k_s) = (inputs.pressure, inputs.length, m.strand_stiffness);
        match &m.pipeline {
            Pipeline::Sleeve(s) => bare_sleeve::on_the_strands(s, k_s, pressure, length),
            Pipeline::Full(full) => full
                .strand_point(pressure, length, k_s, &m.friction)
                .is_some(),
        }
    }

    fn step(m: &mut McKibbenMuscle, pressure: f64, length: f64) -> (Outputs, bool) {
        let x = Inputs {
            pressure,
            length,
            ..Default::default()
        };
        let mut out = Outputs::default();
        let mut report = Report::default();
        m.step(&x, &mut out, 0.0, 1e-3, &mut report);
        (out, report.clamped())
    }

    /// Through `max_length` the force is finite and continuous: it rises, never by more than the
    /// strands' `k_s = E A / b` times the length step (no jump), keeps rising past `max_length`
    /// (no plateau) with slope `k_s`, and nothing is clamped before the breaking length.
    fn continuous_through_max_length(p: Parameters, pressure: f64) {
        let mut m = McKibbenMuscle::new(&p, &Inputs::default()).unwrap();
        let c = m.calculated_parameters();
        let k_s = p.strand_rigidity / m.effective.strand_length;
        let (hi, b) = (c.max_length, m.effective.strand_length);
        let (from, to) = (hi - 0.02 * (hi - c.min_length), hi + 0.04 * b);
        let n = 4000;
        let dl = (to - from) / n as f64;
        let mut previous = step(&mut m, pressure, from).0.force;
        for i in 1..=n {
            let l = from + dl * i as f64;
            let (out, clamped) = step(&mut m, pressure, l);
            assert!(
                out.force.is_finite() && !clamped && !out.slack,
                "{l}: {out:?}"
            );
            let rise = out.force - previous;
            assert!(
                rise > 0.0 && rise <= k_s * dl * (1.0 + 1e-6),
                "{l}: rise {rise} N"
            );
            if l - dl > hi {
                assert_eq!(out.stiffness, k_s);
                assert!(
                    (rise - k_s * dl).abs() < 1e-6 * k_s * dl,
                    "{l}: rise {rise} N"
                );
            }
            previous = out.force;
        }
        // Past the breaking length the policy holds the force there, and says so.
        let (out, clamped) = step(&mut m, pressure, hi + 0.1 * b);
        let (at_break, _) = step(&mut m, pressure, hi + 0.05 * b);
        assert!(clamped && out.force == at_break.force);
    }

    #[test]
    fn bare_sleeve_is_continuous_through_b() {
        continuous_through_max_length(Parameters::default(), 3e5);
        // Eq. 2.3 at b, then the strands: F(b) + k_s (L - b).
        let p = Parameters::default();
        let mut m = McKibbenMuscle::new(&p, &Inputs::default()).unwrap();
        let b = p.strand_length;
        let eq_2_3_at_b = 3e5 * 2.0 * b * b / (4.0 * std::f64::consts::PI * p.turns * p.turns);
        let (out, _) = step(&mut m, 3e5, 1.01 * b);
        let expected = eq_2_3_at_b + p.strand_rigidity / b * 0.01 * b;
        assert!((out.force - expected).abs() < 1e-9 * expected, "{out:?}");
    }

    #[test]
    fn bladder_muscles_are_continuous_through_max_length() {
        for (preset, model) in [(1, 1), (1, 3), (4, 3), (2, 4)] {
            let p = Parameters {
                preset,
                bladder_model: model,
                ..Default::default()
            };
            continuous_through_max_length(p, 4e5);
        }
    }

    /// On the strands the partials are central differences of the outputs.
    #[test]
    fn partials_on_the_strands_are_the_slopes() {
        for (p, length) in [
            (Parameters::default(), 0.113),
            (
                Parameters {
                    preset: 1,
                    bladder_model: 3,
                    ..Default::default()
                },
                0.0985,
            ),
        ] {
            let mut m = McKibbenMuscle::new(&p, &Inputs::default()).unwrap();
            let x = Inputs {
                pressure: 4e5,
                length,
                ..Default::default()
            };
            assert!(on_strands(&m, &x));
            let d = all_partials(&mut m, &x).unwrap();
            let value = |m: &mut McKibbenMuscle, pressure: f64, length: f64| {
                let (o, _) = step(m, pressure, length);
                [o.force, o.volume, o.effective_pressure, o.stiffness]
            };
            let names = [
                Unknown::Force,
                Unknown::Volume,
                Unknown::EffectivePressure,
                Unknown::Stiffness,
            ];
            for (column, h) in [(0, 1.0), (1, 1e-7)] {
                let (dp, dl) = if column == 0 { (h, 0.0) } else { (0.0, h) };
                let up = value(&mut m, x.pressure + dp, x.length + dl);
                let down = value(&mut m, x.pressure - dp, x.length - dl);
                for (k, name) in names.iter().enumerate() {
                    let fd = (up[k] - down[k]) / (2.0 * h);
                    let exact = d.get(*name).unwrap()[column];
                    let scale = fd.abs().max(exact.abs()).max(1e-12);
                    assert!(
                        (fd - exact).abs() < 1e-4 * scale,
                        "{name:?}[{column}]: {exact} vs {fd}"
                    );
                }
            }
        }
    }
}
