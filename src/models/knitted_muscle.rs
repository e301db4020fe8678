//! KnittedMuscle FMU: gauge pressure and length in, tension force out (dissertation chapter 1).
//!
//! The sleeve's shape model (`shape_model` 0 ideal cylinder, 1 tubular knit, 2 non-cylindrical)
//! is built once from the parameters; the non-cylindrical volume-length table exists only when
//! that shape is selected. Strand friction (eq. 1.21, `friction`) is the shared stop-operator
//! hysteresis; its state is part of the FMU state and advances only in `step`. The Mooney-Rivlin
//! bladder of the McKibben muscle (`bladder_model` 1-6 as McKibbenMuscle's; section 1.3.6) is the
//! same [`Bladder`] code with the knitted cylinder's diameter; it is refused for the
//! non-cylindrical shape, which has no single bladder diameter.

use super::wall_arrays::{self, wall_quantity_of, WallQuantity};
use super::{HistoryKey, Model, Partials, Refusal, Report, Status};
use crate::physics::bladder::{Bladder, BladderTube};
use crate::physics::friction::{HysteresisState, StopOperator};
use crate::physics::knitted::{KnittedParams, KnittedSleeve, ShapeKind, StrandFriction};
use crate::physics::knitted_cylinder::{KnittedCylinder, NON_CYLINDRICAL_BLADDER};
use crate::physics::knitted_muscle::{
    Friction, KnittedAssembly, KnittedOutput, BAG_NEEDS_A_CYLINDER,
};
use crate::physics::mckibben::{is_slack, BladderModel};
use crate::variables::knitted_muscle::{
    ArrayOutput, CalculatedParameters, EffectivePressureBy, ForceBy, FrictionForceBy, Inputs,
    MaxRadiusBy, Outputs, Parameters, StiffnessBy, Unknown, Variables, VolumeBy,
};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct KnittedMuscle {
    /// The sleeve with the bladder, friction and bag the parameters switch on.
    assembly: KnittedAssembly,
    /// Friction history (eq. 1.21), advanced only by accepted steps.
    history: HysteresisState,
    /// Whether the last evaluation was outside the valid lengths: its warning is logged once per
    /// excursion.
    out_of_range: bool,
    /// Whether the last evaluation needed the zero-pressure fallback of a collapsing bladder:
    /// logged once per excursion.
    collapsed: bool,
    /// The dissertation's signed force (`signed_force`); else tension only (see [`tension_only`]).
    signed_force: bool,
    /// The straight yarn's axial stiffness `k_s = 2 m E A / L_max`, N/m (from
    /// `strand_rigidity`): past `max_length` the yarn stretches.
    yarn_stiffness: f64,
}

/// A knitted sleeve cannot push: past its free contraction (signed force < 0, eq. 1.8's
/// `-P dV/dL` changing sign) its strands go slack and so does the muscle: no force, no
/// stiffness. With `signed` the dissertation's force stands.
fn tension_only(out: &mut Outputs, signed: bool) {
    out.slack = is_slack(out.force, signed);
    if out.slack {
        out.force = 0.0;
        out.stiffness = 0.0;
    }
}

fn sleeve_params(r: &Parameters) -> Result<KnittedParams, String> {
    Ok(match r.preset {
        0 => KnittedParams {
            stitches_per_row: r.stitches_per_row,
            rows: r.rows,
            row_strand_length: r.row_strand_length,
            strand_thickness: r.strand_thickness,
            bladder_outer_radius: 0.0,
        },
        1 => KnittedParams::prototype(),
        2 => KnittedParams::fig_1_16(r.strand_thickness),
        k => {
            return Err(format!(
                "preset must be 0 (none), 1 (section 1.4 prototype) or 2 (Fig. 1.16), got {k}"
            ))
        }
    })
}

fn bladder(
    r: &Parameters,
    sleeve: &KnittedSleeve,
) -> Result<Option<Bladder<KnittedCylinder>>, String> {
    let Some(wall) = BladderModel::from_switch(r.bladder_model, r.bladder_layers)?.wall() else {
        return Ok(None);
    };
    let tube = BladderTube {
        inner_diameter: r.bladder_inner_diameter,
        thickness: r.bladder_thickness,
        unstretched_length: r.bladder_length,
        mooney_c1: r.mooney_c1,
        mooney_c2: r.mooney_c2,
    };
    Bladder::knitted_wall(sleeve, tube, wall).map(Some)
}

fn shape_kind(p: &Parameters) -> Result<ShapeKind, String> {
    Ok(match p.shape_model {
        0 => ShapeKind::Ideal,
        1 => ShapeKind::Tubular,
        2 => {
            let segments = p.shape_segments;
            // The range itself is checked by the shape solver; this only refuses negatives.
            let segments = usize::try_from(segments)
                .map_err(|_| format!("shape_segments must be at least 2, got {segments}"))?;
            ShapeKind::NonCylindrical { segments }
        }
        k => {
            return Err(format!(
                "shape_model must be 0 (ideal cylinder), 1 (tubular knit) or 2 (non-cylindrical), \
                 got {k}"
            ))
        }
    })
}

impl KnittedMuscle {
    /// The physics at the current inputs: past `max_length` on the stretching yarn; below
    /// `min_length` or past the breaking length evaluated at the nearest length (logged once per
    /// excursion). `None` when the physics refuses (logged); the outputs then keep their values.
    fn compute(&mut self, inputs: &Inputs, report: &mut Report) -> Option<KnittedOutput> {
        let (pressure, length) = (inputs.pressure, inputs.length);
        let k_s = self.yarn_stiffness;
        match self
            .assembly
            .evaluate_with_yarn(pressure, length, k_s, &self.history)
        {
            Ok(y) => {
                match &y.out_of_range {
                    Some(e) => {
                        report.clamp(!self.out_of_range, || e.message());
                        self.out_of_range = true;
                    }
                    None => self.out_of_range = false,
                }
                if let Some(reason) = &y.collapsed {
                    report.clamp(!self.collapsed, || {
                        format!(
                            "{reason}; evaluating at zero gauge pressure until the inputs return"
                        )
                    });
                }
                self.collapsed = y.collapsed.is_some();
                Some(y.out)
            }
            Err(reason) => {
                // Unreachable with finite inputs in range.
                report.add(
                    Status::Error,
                    format!("cannot evaluate the sleeve: {reason}"),
                );
                None
            }
        }
    }

    fn write(o: &mut Outputs, out: &KnittedOutput) {
        o.force = out.force;
        o.volume = out.volume;
        o.effective_pressure = out.effective_pressure;
        o.friction_force = out.friction_force;
        o.max_radius = out.max_radius;
        o.stiffness = out.stiffness;
    }
}

impl KnittedMuscle {
    /// Exact partials on the branch [`Self::compute`] takes (see docs/model-exchange.md for
    /// the one-sided choices), from [`KnittedAssembly::rows_with_yarn`]; with a bladder, the
    /// stiffness's row only if `stiffness`; force and stiffness 0 while `slack`.
    fn write_partials(
        &self,
        inputs: &Inputs,
        slack: bool,
        table: &mut Partials<Variables>,
    ) -> Result<(), String> {
        let stiffness = table.wants(Unknown::Stiffness);
        let (pressure, length) = (inputs.pressure, inputs.length);
        let k_s = self.yarn_stiffness;
        let mut r =
            self.assembly
                .rows_with_yarn(pressure, length, k_s, &self.history, stiffness)?;
        if slack {
            // Tension only: the slack muscle's force and stiffness are 0 nearby.
            r.force = [0.0; 2];
            r.stiffness = r.stiffness.map(|_| [0.0; 2]);
        }
        table
            .row(ForceBy {
                pressure: r.force[0],
                length: r.force[1],
            })
            .row(VolumeBy {
                pressure: r.volume[0],
                length: r.volume[1],
            })
            .row(EffectivePressureBy {
                pressure: r.effective_pressure[0],
                length: r.effective_pressure[1],
            })
            .row(FrictionForceBy {
                pressure: r.friction_force[0],
                length: r.friction_force[1],
            })
            .row(MaxRadiusBy {
                pressure: r.max_radius[0],
                length: r.max_radius[1],
            });
        if let Some([pressure, length]) = r.stiffness {
            table.row(StiffnessBy { pressure, length });
        }
        Ok(())
    }
}

impl Model for KnittedMuscle {
    type Variables = Variables;
    const ALGEBRAIC_MODEL_EXCHANGE: bool = true;
    const DOCUMENTATION: &'static str = include_str!("knitted_muscle.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        saved.history.check("friction history")?;
        self.history = saved.history;
        self.out_of_range = saved.out_of_range;
        self.collapsed = saved.collapsed;
        Ok(())
    }

    fn new(p: &Parameters, start: &Inputs) -> Result<Self, Refusal> {
        let shape = shape_kind(p)?;
        // Everything that does not need the sleeve is checked first: the non-cylindrical table
        // takes milliseconds to build, and a refusal after it would spend them for nothing.
        let has_bladder = BladderModel::from_switch(p.bladder_model, p.bladder_layers)?
            .wall()
            .is_some();
        let bag = (p.bag_diameter != 0.0).then_some((p.bag_diameter, p.bag_membrane_stiffness));
        if matches!(shape, ShapeKind::NonCylindrical { .. }) {
            if has_bladder {
                return Err(NON_CYLINDRICAL_BLADDER.to_string().into());
            }
            if bag.is_some() {
                return Err(BAG_NEEDS_A_CYLINDER.to_string().into());
            }
        }
        let friction = if p.friction {
            Some(Friction {
                strand: StrandFriction::new(p.friction_coefficient)?,
                operator: StopOperator::new(p.presliding_length)?,
            })
        } else {
            None
        };
        let rigidity = p.strand_rigidity;
        if !(rigidity.is_finite() && rigidity > 0.0) {
            return Err(
                format!("strand_rigidity must be positive and finite, got {rigidity} N").into(),
            );
        }
        let sleeve = KnittedSleeve::new(sleeve_params(p)?, shape)?;
        let bladder = bladder(p, &sleeve)?;
        let assembly = KnittedAssembly::new(sleeve, bladder, bag, friction)?;
        let yarn_stiffness = assembly.yarn_stiffness(rigidity);
        let valid = assembly.valid_lengths();
        // Friction starts relaxed (z = 0) where the sleeve is at initialization.
        let start = start.length;
        let history = HysteresisState::at_rest(if start.is_nan() {
            valid.1
        } else {
            start.max(valid.0).min(valid.1)
        });
        Ok(Self {
            assembly,
            history,
            out_of_range: false,
            collapsed: false,
            signed_force: p.signed_force,
            yarn_stiffness,
        })
    }

    fn calculated_parameters(&self) -> CalculatedParameters {
        CalculatedParameters {
            min_length: self.assembly.length_range().0,
            max_length: self.assembly.length_range().1,
            free_contraction_length: self.assembly.sleeve().free_contraction_length(),
        }
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        if let Some(out) = self.compute(inputs, report) {
            Self::write(outputs, &out);
            tension_only(outputs, self.signed_force);
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
        // Quasi-static: the held inputs at the end of the step fix the outputs; the friction
        // history follows the length path sampled at the communication points.
        if let Some(out) = self.compute(inputs, report) {
            Self::write(outputs, &out);
            tension_only(outputs, self.signed_force);
            self.history = out.history;
        }
    }
    /// Every row; with a bladder the stiffness's (a second-order pass) only when wanted.
    fn partials(&mut self, inputs: &Inputs, p: &mut Partials<Variables>) -> Result<(), String> {
        let slack = !self.signed_force && self.signed_force_at(inputs).is_some_and(|f| f < 0.0);
        self.write_partials(inputs, slack, p)
    }

    /// The partials read the friction history besides the inputs.
    fn partials_key(&self) -> Option<HistoryKey> {
        Some(HistoryKey::of([self.history.z, self.history.position]))
    }

    fn array(&self, inputs: &Inputs, array: ArrayOutput, out: &mut [f64]) -> Result<(), String> {
        let quantity = wall_quantity_of!(array);
        let Some(bladder) = self.assembly.bladder() else {
            return wall_arrays::absent(out);
        };
        // At the length the muscle is evaluated at (the nearer valid one beyond them).
        let (lo, hi) = self.assembly.valid_lengths();
        let length = inputs.length.max(lo).min(hi);
        wall_arrays::write(quantity, out, |f| {
            bladder.wall_field(inputs.pressure, length, f)
        })
    }
}

impl KnittedMuscle {
    /// The signed force [`Self::compute`] gives at `inputs`, leaving the excursion flags (and
    /// their log) as they were.
    fn signed_force_at(&mut self, inputs: &Inputs) -> Option<f64> {
        let flags = (self.out_of_range, self.collapsed);
        let force = self
            .compute(inputs, &mut Report::default())
            .map(|o| o.force);
        (self.out_of_range, self.collapsed) = flags;
        force
    }
}

#[cfg(test)]
mod tests {
    use super::super::all_partials;
    use super::*;
    use crate::models::Status;
    use crate::variables::knitted_muscle::Known;
    use std::f64::consts::SQRT_2;

    fn parameters_with(shape: i32, friction: bool) -> Parameters {
        Parameters {
            shape_model: shape,
            friction,
            ..Parameters::default()
        }
    }

    /// A model from `p` at the start inputs, with its calculated parameters.
    fn built(p: &Parameters) -> (KnittedMuscle, Inputs, Outputs, CalculatedParameters) {
        let inputs = Inputs::default();
        let m = KnittedMuscle::new(p, &inputs).unwrap();
        let calculated = m.calculated_parameters();
        (m, inputs, Outputs::default(), calculated)
    }

    #[test]
    fn only_step_commits_the_friction_history() {
        let (mut m, mut inputs, mut out, _) = built(&parameters_with(0, true));
        let start = m.history;
        inputs.pressure = 14e3;
        inputs.length = 0.35;
        let mut report = Report::default();
        m.evaluate(&inputs, &mut out, &mut report);
        assert_eq!(m.history, start);
        // Shortening by far more than the presliding length: full friction against it (z = -1),
        // of magnitude sqrt(2) Cf (F + P A) (eq. 1.21).
        assert!(out.friction_force < 0.0);
        m.step(&inputs, &mut out, 0.0, 1e-3, &mut report);
        assert_eq!(m.history.z, -1.0);
        assert_eq!(m.history.position, 0.35);
        let (f, fr) = (out.force, out.friction_force);
        let tension = f + 14e3 * m.assembly.sleeve().mean_area(0.35);
        assert!((fr + SQRT_2 * 0.25 * tension).abs() < 1e-12 * f.abs());
        assert_eq!(report.status(), Status::Ok);
    }

    #[test]
    fn out_of_range_is_the_nearest_limit_warned_once_per_excursion() {
        let (mut m, mut inputs, mut out, calculated) = built(&parameters_with(2, false));
        // Past max_length the yarn stretches; past the breaking length the force is held there.
        let (lo, hi) = (calculated.min_length, m.assembly.breaking_length());
        assert!(hi > calculated.max_length);
        inputs.pressure = 14e3;
        inputs.length = hi;
        let mut report = Report::default();
        m.evaluate(&inputs, &mut out, &mut report);
        assert!(!report.clamped());
        let at_limit = out.clone();
        let mut warned = 0;
        for length in [hi + 1.0, 2.0 * hi, 0.4, 0.0, lo - 1e-9] {
            let mut report = Report::default();
            inputs.length = length;
            m.evaluate(&inputs, &mut out, &mut report);
            warned += report.clamp_messages().len();
            assert_eq!(report.status(), Status::Ok);
            assert_eq!(report.clamped(), !(lo..=hi).contains(&length));
            if length > hi {
                assert_eq!(out.force, at_limit.force);
            }
            let values = [
                out.force,
                out.volume,
                out.effective_pressure,
                out.friction_force,
                out.max_radius,
                out.stiffness,
            ];
            assert!(values.iter().all(|x| x.is_finite()));
        }
        assert_eq!(warned, 2);
    }

    #[test]
    fn bladder_is_refused_for_the_non_cylindrical_shape() {
        let mut p = parameters_with(2, false);
        p.bladder_model = 2;
        let e = KnittedMuscle::new(&p, &Inputs::default()).unwrap_err().0;
        assert!(e.contains("cylindrical sleeve"), "{e}");
        // Before the sleeve's table is built: rows its table refuses still get the bladder's
        // reason.
        p.rows = 1000.0;
        let e = KnittedMuscle::new(&p, &Inputs::default()).unwrap_err().0;
        assert!(e.contains("no single bladder diameter"), "{e}");
        for shape in [0, 1] {
            let mut p = parameters_with(shape, false);
            p.preset = 2;
            p.bladder_model = 1;
            assert!(KnittedMuscle::new(&p, &Inputs::default()).is_ok());
        }
    }

    #[test]
    fn bag_is_refused_for_the_non_cylindrical_shape_before_its_table() {
        // A sampled point of the declared space that built its table before this refusal.
        let p = Parameters {
            stitches_per_row: 5.154,
            rows: 154.7,
            row_strand_length: 44.16,
            strand_thickness: 9.413e-3,
            shape_model: 2,
            shape_segments: 94,
            friction: true,
            friction_coefficient: 0.6372,
            presliding_length: 7.606e-2,
            bladder_layers: 17,
            bladder_length: 9.409e-4,
            bladder_inner_diameter: 4.087e-5,
            bladder_thickness: 2.477e-7,
            mooney_c1: 6.536,
            mooney_c2: 2.921e-4,
            bag_diameter: 2.977e-3,
            bag_membrane_stiffness: 9409.0,
            strand_rigidity: 1.115,
            ..Parameters::default()
        };
        let start = Inputs {
            pressure: -23.06,
            length: 8.137,
        };
        let e = KnittedMuscle::new(&p, &start).unwrap_err().0;
        assert_eq!(e, BAG_NEEDS_A_CYLINDER, "{e}");
        assert!(
            e.contains("bag_diameter") && e.contains("shape_model"),
            "{e}"
        );
        // Without the bag the same sleeve builds its table.
        let without = Parameters {
            bag_diameter: 0.0,
            ..p.clone()
        };
        assert!(KnittedMuscle::new(&without, &start).is_ok());
        // Before the table: rows the table refuses still get the bag's reason.
        let e = KnittedMuscle::new(&Parameters { rows: 1000.0, ..p }, &start)
            .unwrap_err()
            .0;
        assert_eq!(e, BAG_NEEDS_A_CYLINDER, "{e}");
        // The cylinders take the bag.
        for shape_model in [0, 1] {
            let p = Parameters {
                preset: 1,
                shape_model,
                bag_diameter: 0.085,
                ..Parameters::default()
            };
            assert!(KnittedMuscle::new(&p, &Inputs::default()).is_ok());
        }
    }

    #[test]
    fn a_sleeve_without_stroke_is_refused_naming_its_variables() {
        // Full extension n (S - 4 m t) / (2 m) (eq. 1.4 at eq. 1.16's radius) against the
        // thickness limit 2 n t (section 1.3.4): no stroke for S <= 8 m t, here S = 6 m t.
        for shape_model in [0, 2] {
            let p = Parameters {
                stitches_per_row: 3.0,
                rows: 10.0,
                row_strand_length: 6.0 * 3.0 * 1e-3,
                strand_thickness: 1e-3,
                shape_model,
                shape_segments: 10,
                ..Parameters::default()
            };
            let e = KnittedMuscle::new(&p, &Inputs::default()).unwrap_err().0;
            assert!(e.starts_with("no stroke"), "{e}");
            for name in ["rows", "strand_thickness", "row_strand_length"] {
                assert!(e.contains(name), "shape_model {shape_model}: {e}");
            }
            // At S = 9 m t it extends past the limit.
            let p = Parameters {
                row_strand_length: 9.0 * 3.0 * 1e-3,
                ..p
            };
            assert!(KnittedMuscle::new(&p, &Inputs::default()).is_ok());
        }
    }

    #[test]
    fn bladder_friction_stiffness_is_the_slope_with_z_held() {
        // Eq. 1.21 fed by the strand tension P_eff (A - dV/dL): dF/dL by central differences with
        // the hysteresis state held (step commits z = -1 first).
        let mut p = parameters_with(0, true);
        p.preset = 2;
        p.bladder_model = 2;
        let (mut m, mut inputs, mut out, _) = built(&p);
        let mut report = Report::default();
        inputs.pressure = 550e3;
        inputs.length = 0.07;
        m.step(&inputs, &mut out, 0.0, 1e-3, &mut report);
        assert_eq!(m.history.z, -1.0);
        let mut at = |m: &mut KnittedMuscle, l: f64| {
            inputs.length = l;
            m.evaluate(&inputs, &mut out, &mut Report::default());
            (out.force, out.stiffness, out.friction_force)
        };
        // Stay within the presliding length below 0.07 so that z stays -1.
        let h = 1e-6;
        let (fp, _, _) = at(&mut m, 0.07 - 1e-5 + h);
        let (fm, _, _) = at(&mut m, 0.07 - 1e-5 - h);
        let (f, k, friction_force) = at(&mut m, 0.07 - 1e-5);
        assert!(friction_force < 0.0);
        let fd = (fp - fm) / (2.0 * h);
        assert!((k - fd).abs() < 1e-4 * fd.abs(), "{k} {fd} (F {f})");
    }

    #[test]
    fn non_cylindrical_needs_a_thick_strand() {
        let mut p = parameters_with(2, false);
        p.strand_thickness = 0.0;
        let e = KnittedMuscle::new(&p, &Inputs::default()).unwrap_err().0;
        assert!(e.contains("positive minimum radius"), "{e}");
        p.shape_segments = -3;
        p.strand_thickness = 2e-4;
        assert!(KnittedMuscle::new(&p, &Inputs::default()).is_err());
    }

    const OUTPUTS: [Unknown; 6] = [
        Unknown::Force,
        Unknown::Volume,
        Unknown::EffectivePressure,
        Unknown::FrictionForce,
        Unknown::MaxRadius,
        Unknown::Stiffness,
    ];

    fn values(o: &Outputs) -> [f64; 6] {
        [
            o.force,
            o.volume,
            o.effective_pressure,
            o.friction_force,
            o.max_radius,
            o.stiffness,
        ]
    }

    /// Every partial against central differences of the model's own outputs, at points across
    /// every shape model, friction, and the bladder's walls (free and in contact). A point where
    /// the one-sided differences disagree straddles a kink (contact threshold, a table node) and
    /// is skipped; few may be.
    #[test]
    fn partials_match_central_differences_across_shapes_and_effects() {
        let mut configs = Vec::new();
        for shape in [0, 1, 2] {
            for friction in [false, true] {
                configs.push((parameters_with(shape, friction), vec![1.4e4, 5e4, -2e4]));
            }
        }
        for shape in [0, 1] {
            for bladder_model in [1, 2, 3] {
                for friction in [false, true] {
                    let mut p = parameters_with(shape, friction);
                    p.preset = 2;
                    p.bladder_model = bladder_model;
                    p.bladder_layers = 6;
                    configs.push((p, vec![2e4, 1.5e5, 5.5e5]));
                }
            }
        }
        // Section 1.4's prototype in its 85 mm bag, inextensible and stretching (E t = 1e4 N/m):
        // the bag binds at the shorter lengths.
        for shape in [0, 1] {
            for membrane in [0.0, 1e4] {
                for friction in [false, true] {
                    let mut p = parameters_with(shape, friction);
                    p.preset = 1;
                    p.bag_diameter = 0.085;
                    p.bag_membrane_stiffness = membrane;
                    configs.push((p, vec![1.4e4, 5e4, -2e4]));
                }
            }
        }
        let (mut checked, mut skipped, mut worst) = (0, 0, 0.0f64);
        let mut bag_binds = 0;
        for (p, pressures) in &configs {
            let calculated = KnittedMuscle::new(p, &Inputs::default())
                .unwrap()
                .calculated_parameters();
            let (lo, hi) = (calculated.min_length, calculated.max_length);
            for frac in [0.3, 0.6, 0.85] {
                let length = lo + frac * (hi - lo);
                // History 30 um behind: friction mid-presliding (0.1 mm), off the reversal.
                let start = Inputs {
                    length: length - 3e-5,
                    ..Default::default()
                };
                let mut m = KnittedMuscle::new(p, &start).unwrap();
                for &pressure in pressures {
                    let x = Inputs { pressure, length };
                    let exact = all_partials(&mut m, &x).unwrap();
                    if let Some(bag) = m.assembly.bag() {
                        let p_eff = pressure.max(0.0);
                        bag_binds += usize::from(
                            crate::physics::knitted_muscle::bag_rows(
                                m.assembly.sleeve(),
                                bag,
                                p_eff,
                                length,
                                1.0,
                            )
                            .is_some(),
                        );
                    }
                    let mut at = |dp: f64, dl: f64| {
                        let mut out = Outputs::default();
                        let y = Inputs {
                            pressure: pressure + dp,
                            length: length + dl,
                        };
                        m.evaluate(&y, &mut out, &mut Report::default());
                        values(&out)
                    };
                    let base = at(0.0, 0.0);
                    let h = [1e-6 * pressure.abs() + 1e-3, 1e-7 * length];
                    let steps = [[h[0], 0.0], [0.0, h[1]]];
                    for (j, input) in [Known::Pressure, Known::Length].into_iter().enumerate() {
                        let (up, down) =
                            (at(steps[j][0], steps[j][1]), at(-steps[j][0], -steps[j][1]));
                        for (k, name) in OUTPUTS.into_iter().enumerate() {
                            let e = exact.partial(name, input).unwrap();
                            let central = (up[k] - down[k]) / (2.0 * h[j]);
                            let (right, left) =
                                ((up[k] - base[k]) / h[j], (base[k] - down[k]) / h[j]);
                            let scale = e.abs().max(central.abs()).max(1e-300);
                            if (right - left).abs() > 1e-3 * scale + 1e-9 {
                                skipped += 1;
                                continue;
                            }
                            let err = (e - central).abs() / scale;
                            assert!(
                                err < 1e-5 || (e - central).abs() < 1e-10 * (1.0 + base[k].abs()),
                                "shape {} bladder {} bag {} friction {} P {pressure} L {length}: \
                                 d{name:?}/d{input:?} exact {e} central {central}",
                                p.shape_model,
                                p.bladder_model,
                                p.bag_diameter,
                                p.friction
                            );
                            checked += 1;
                            if (e - central).abs() > 1e-10 * (1.0 + base[k].abs()) {
                                worst = worst.max(err);
                            }
                        }
                    }
                }
            }
        }
        eprintln!(
            "{checked} partials checked ({bag_binds} points where the bag binds), {skipped} at \
             kinks skipped, worst {worst:e}"
        );
        assert!(bag_binds >= 8, "{bag_binds}");
        assert!(
            checked > 800 && skipped * 20 < checked,
            "{checked} {skipped}"
        );
    }

    #[test]
    fn at_the_bags_binding_length_the_partials_are_the_sleeves() {
        // The bag binds strictly below the binding length: there the sleeve's branch, whose
        // force slope is the one-sided difference towards longer lengths.
        let mut p = parameters_with(0, false);
        p.preset = 1;
        p.bag_diameter = 0.085;
        // The bag pushes the clamps apart below the binding length: the signed force.
        p.signed_force = true;
        let (mut m, _, _, _) = built(&p);
        let pressure = 14e3;
        let l = m
            .assembly
            .bag()
            .unwrap()
            .binding_length(m.assembly.sleeve(), pressure);
        let force = |m: &mut KnittedMuscle, length: f64| {
            let mut out = Outputs::default();
            m.evaluate(
                &Inputs { pressure, length },
                &mut out,
                &mut Report::default(),
            );
            out.force
        };
        let d = all_partials(
            &mut m,
            &Inputs {
                pressure,
                length: l,
            },
        )
        .unwrap();
        let exact = d.partial(Unknown::Force, Known::Length).unwrap();
        let h = 1e-7 * l;
        let above = (force(&mut m, l + h) - force(&mut m, l)) / h;
        assert!(
            (above - exact).abs() < 1e-4 * exact.abs(),
            "{above} {exact}"
        );
        // Just below, the bag carries the end load, F = -P pi R^2 (the force jumps there), with
        // no length slope.
        let bag_force = -pressure * std::f64::consts::PI * 0.0425f64.powi(2);
        assert!((force(&mut m, l - h) - bag_force).abs() < 1e-12 * bag_force.abs());
        let d = all_partials(
            &mut m,
            &Inputs {
                pressure,
                length: l - h,
            },
        );
        assert_eq!(d.unwrap().partial(Unknown::Force, Known::Length), Some(0.0));
    }

    #[test]
    fn partials_are_zero_out_of_range() {
        let (mut m, _, _, _) = built(&parameters_with(1, false));
        let beyond = Inputs {
            pressure: 1e5,
            length: m.assembly.breaking_length() + 0.01,
        };
        let d = all_partials(&mut m, &beyond).unwrap();
        for name in OUTPUTS {
            assert_eq!(d.partial(name, Known::Length), Some(0.0), "{name:?}");
        }
        assert!(d.partial(Unknown::Force, Known::Pressure).unwrap() != 0.0);
    }
}

#[cfg(test)]
mod yarn_tests {
    use super::super::all_partials;
    use super::*;
    use crate::physics::knitted_yarn::SPECTRA_LINE_RIGIDITY;

    fn step(m: &mut KnittedMuscle, pressure: f64, length: f64) -> (Outputs, bool) {
        let mut out = Outputs::default();
        let mut report = Report::default();
        m.step(
            &Inputs { pressure, length },
            &mut out,
            0.0,
            1e-3,
            &mut report,
        );
        (out, report.clamped())
    }

    /// The knit fully extended: `2 m` legs of `L_max / n` per row in parallel, `n` rows in
    /// series, computed here from the sleeve's parameters.
    fn yarn_stiffness(m: &KnittedMuscle, rigidity: f64) -> f64 {
        let s = m.assembly.sleeve();
        let (legs, rows) = (2.0 * s.params().stitches_per_row, s.params().rows);
        let leg = s.max_length() / rows;
        let row_stiffness = legs * rigidity / leg;
        row_stiffness / rows
    }

    /// The default strand rigidity is the prototype's Spectra line.
    #[test]
    fn default_rigidity_is_the_spectra_line() {
        assert_eq!(Parameters::default().strand_rigidity, SPECTRA_LINE_RIGIDITY);
        assert!((SPECTRA_LINE_RIGIDITY - 220.0 / 0.035).abs() < 0.01 * SPECTRA_LINE_RIGIDITY);
    }

    /// Through `max_length` the force is finite, continuous (left and right limits agree to the
    /// yarn's slope times the gap) and monotone; past it the slope is the yarn's `k_s` exactly,
    /// nothing is clamped before the breaking length, and past it the force is held there.
    fn continuous_through_max_length(p: Parameters, pressure: f64) -> (f64, f64, f64) {
        let mut m = KnittedMuscle::new(&p, &Inputs::default()).unwrap();
        let k_s = yarn_stiffness(&m, p.strand_rigidity);
        assert!((m.yarn_stiffness - k_s).abs() < 1e-12 * k_s);
        let hi = m.calculated_parameters().max_length;
        let breaking = m.assembly.breaking_length();
        let eps = 1e-9 * hi;
        let (left, _) = step(&mut m, pressure, hi - eps);
        let (right, _) = step(&mut m, pressure, hi + eps);
        let jump = right.force - left.force;
        assert!(
            jump.abs() <= 2.0 * eps * k_s.max(left.stiffness) * (1.0 + 1e-6) + 1e-9 * left.force,
            "{jump} N at {hi} m"
        );
        let n = 2000;
        let (from, to) = (hi - 0.01 * hi, breaking);
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
            // No jump anywhere; the rigid knit may soften towards its reach (its radius nears
            // the strand thickness), past it the yarn only rises.
            assert!(rise.abs() <= k_s * dl * (1.0 + 1e-6), "{l}: rise {rise} N");
            if l - dl >= hi {
                assert!(rise > 0.0, "{l}: rise {rise} N");
            }
            if l - dl > hi {
                assert_eq!(out.stiffness, m.yarn_stiffness);
                assert!((rise - k_s * dl).abs() < 1e-6 * k_s * dl, "{l}: {rise} N");
            }
            previous = out.force;
        }
        let (at_break, _) = step(&mut m, pressure, breaking);
        let (beyond, clamped) = step(&mut m, pressure, breaking + 0.01);
        assert!(clamped && beyond.force == at_break.force);
        let slope = (step(&mut m, pressure, hi + 2e-3).0.force
            - step(&mut m, pressure, hi + 1e-3).0.force)
            / 1e-3;
        (jump, slope, k_s)
    }

    #[test]
    fn sleeves_are_continuous_through_max_length() {
        for (shape, preset, bladder) in [(0, 0, 0), (1, 1, 0), (0, 2, 1), (1, 2, 2)] {
            let p = Parameters {
                shape_model: shape,
                preset,
                bladder_model: bladder,
                ..Default::default()
            };
            let (jump, slope, k_s) = continuous_through_max_length(p, 2e4);
            eprintln!(
                "shape {shape} preset {preset} bladder {bladder}: jump {jump:e} N, slope {slope:.6e} N/m, k_s {k_s:.6e} N/m"
            );
        }
    }

    /// On the yarn the partials are central differences of the outputs (both transitions: at
    /// the sleeve's reach without a bladder, interior where a bladder stiffens the knit).
    #[test]
    fn partials_on_the_yarn_are_the_slopes() {
        for (bladder, preset) in [(0, 0), (1, 2)] {
            let p = Parameters {
                preset,
                bladder_model: bladder,
                ..Default::default()
            };
            let mut m = KnittedMuscle::new(&p, &Inputs::default()).unwrap();
            let hi = m.calculated_parameters().max_length;
            let x = Inputs {
                pressure: 2e4,
                length: hi + 0.005,
            };
            let d = all_partials(&mut m, &x).unwrap();
            let value = |m: &mut KnittedMuscle, pressure: f64, length: f64| {
                let (o, _) = step(m, pressure, length);
                [
                    o.force,
                    o.volume,
                    o.effective_pressure,
                    o.max_radius,
                    o.stiffness,
                ]
            };
            let names = [
                Unknown::Force,
                Unknown::Volume,
                Unknown::EffectivePressure,
                Unknown::MaxRadius,
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
                        "bladder {bladder} {name:?}[{column}]: {exact} vs {fd}"
                    );
                }
            }
        }
    }

    /// Tension only holds on the yarn's side too: below the free contraction slack, force and
    /// stiffness 0 with partials 0; `signed_force` gives the negative force.
    #[test]
    fn slack_below_the_free_contraction() {
        let p = Parameters::default();
        let mut m = KnittedMuscle::new(&p, &Inputs::default()).unwrap();
        let free = m.calculated_parameters().free_contraction_length;
        let x = Inputs {
            pressure: 2e4,
            length: 0.9 * free,
        };
        let (out, _) = step(&mut m, x.pressure, x.length);
        assert!(out.slack && out.force == 0.0 && out.stiffness == 0.0);
        let d = all_partials(&mut m, &x).unwrap();
        assert!(d.get(Unknown::Force).unwrap().iter().all(|v| *v == 0.0));
        let mut signed = KnittedMuscle::new(
            &Parameters {
                signed_force: true,
                ..p
            },
            &Inputs::default(),
        )
        .unwrap();
        let (out, _) = step(&mut signed, x.pressure, x.length);
        assert!(!out.slack && out.force < 0.0);
    }
}
