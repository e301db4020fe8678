//! KnittedMuscle FMU: gauge pressure and length in, tension force out (dissertation chapter 1).
//!
//! The sleeve's shape model (`shape_model` 0 ideal cylinder, 1 tubular knit, 2 non-cylindrical)
//! is built once from the parameters; the non-cylindrical volume-length table exists only when
//! that shape is selected. Strand friction (eq. 1.21, `friction`) is the shared stop-operator
//! hysteresis; its state is part of the FMU state and advances only in `step`. The Mooney-Rivlin
//! bladder of the McKibben muscle (`bladder_model` 1-6 as McKibbenMuscle's; section 1.3.6) is the
//! same [`Bladder`] code with the knitted cylinder's diameter; it is refused for the
//! non-cylindrical shape, which has no single bladder diameter.

use super::{Model, Partials, Refusal, Report, Status};
use crate::physics::bladder::{Bladder, BladderTube, KnittedCylinder};
use crate::physics::friction::{HysteresisState, StopOperator};
use crate::physics::knitted::{KnittedParams, KnittedSleeve, ShapeKind, StrandFriction};
use crate::physics::knitted_muscle::{Friction, KnittedAssembly, KnittedOutput};
use crate::physics::mckibben::BladderModel;
use crate::variables::knitted_muscle::{
    CalculatedParameters, Inputs, Outputs, Parameters, Variables,
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
    /// The last partials, the point (pressure, length, friction z and position, as bits) they
    /// were taken at, and whether they hold the bladder's stiffness row (a second-order pass): a
    /// Jacobian's further seeds reuse them. Not part of the FMU state.
    #[serde(skip)]
    partials_cache: Option<([u64; 4], bool, Partials)>,
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
    /// The physics at the current inputs; a length outside `[min_length, max_length]` is
    /// evaluated at the nearer limit, where the sleeve is rigid (logged once per excursion).
    /// `None` when the physics refuses (logged); the outputs then keep their values.
    fn compute(&mut self, inputs: &Inputs, report: &mut Report) -> Option<KnittedOutput> {
        let (pressure, length) = (inputs.pressure, inputs.length);
        let (lo, hi) = self.assembly.valid_lengths();
        let l = if length.is_nan() {
            hi
        } else {
            length.max(lo).min(hi)
        };
        if l == length {
            self.out_of_range = false;
        } else {
            report.clamp(!self.out_of_range, || {
                format!(
                    "length {length} m is outside the valid lengths {} .. {} m (max_length {} m); \
                     evaluating at length {l} m until the inputs return",
                    lo,
                    hi,
                    self.assembly.length_range().1
                )
            });
            self.out_of_range = true;
        }
        match self.assembly.evaluate(pressure, l, &self.history) {
            Ok((out, fallback)) => {
                if let Some(reason) = &fallback {
                    report.clamp(!self.collapsed, || {
                        format!(
                            "{reason}; evaluating at zero gauge pressure until the inputs return"
                        )
                    });
                }
                self.collapsed = fallback.is_some();
                Some(out)
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
    /// the one-sided choices), from [`KnittedAssembly::partial_rows`]; with a bladder, the
    /// stiffness's row only if `stiffness`.
    fn partials_at(&self, inputs: &Inputs, stiffness: bool) -> Result<Partials, String> {
        let (pressure, length) = (inputs.pressure, inputs.length);
        if !(pressure.is_finite() && length.is_finite()) {
            return Err(format!(
                "partials need finite inputs, got pressure {pressure} Pa and length {length} m"
            ));
        }
        let (lo, hi) = self.assembly.valid_lengths();
        let l = length.max(lo).min(hi);
        // A clamped length no longer moves with the input.
        let length_moves = if l == length { 1.0 } else { 0.0 };
        let direction = if l >= self.history.position {
            1.0
        } else {
            -1.0
        };
        let mut r = self
            .assembly
            .partial_rows(pressure, l, &self.history, direction, stiffness)?;
        let mut table = Partials::default();
        let mut add = |name: &'static str, row: &mut [f64; 2]| {
            row[1] *= length_moves;
            table.row(name, &[("pressure", row[0]), ("length", row[1])]);
        };
        add("force", &mut r.force);
        add("volume", &mut r.volume);
        add("effective_pressure", &mut r.effective_pressure);
        add("friction_force", &mut r.friction_force);
        add("max_radius", &mut r.max_radius);
        if let Some(mut stiffness) = r.stiffness {
            add("stiffness", &mut stiffness);
        }
        Ok(table)
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
        let sleeve = KnittedSleeve::new(sleeve_params(p)?, shape_kind(p)?)?;
        let bladder = bladder(p, &sleeve)?;
        let bag = (p.bag_diameter != 0.0).then_some((p.bag_diameter, p.bag_membrane_stiffness));
        let friction = if p.friction {
            Some(Friction {
                strand: StrandFriction::new(p.friction_coefficient)?,
                operator: StopOperator::new(p.presliding_length)?,
            })
        } else {
            None
        };
        let assembly = KnittedAssembly::new(sleeve, bladder, bag, friction)?;
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
            partials_cache: None,
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
            self.history = out.history;
        }
    }
    fn partials(&mut self, inputs: &Inputs) -> Result<Partials, String> {
        self.cached_partials(inputs, true)
    }

    fn partials_for(
        &mut self,
        inputs: &Inputs,
        outputs: &[&'static str],
    ) -> Result<Partials, String> {
        // With a bladder the stiffness's row costs a second-order pass: only when asked.
        self.cached_partials(inputs, outputs.contains(&"stiffness"))
    }
}

impl KnittedMuscle {
    fn cached_partials(&mut self, inputs: &Inputs, stiffness: bool) -> Result<Partials, String> {
        let h = &self.history;
        let key = [inputs.pressure, inputs.length, h.z, h.position].map(f64::to_bits);
        if let Some((cached, has_stiffness, rows)) = &self.partials_cache {
            if *cached == key && (*has_stiffness || !stiffness) {
                return Ok(rows.clone());
            }
        }
        let rows = self.partials_at(inputs, stiffness)?;
        self.partials_cache = Some((key, stiffness, rows.clone()));
        Ok(rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::Status;
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
        let (lo, hi) = (calculated.min_length, calculated.max_length);
        inputs.pressure = 14e3;
        inputs.length = hi;
        let mut report = Report::default();
        m.evaluate(&inputs, &mut out, &mut report);
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
        for shape in [0, 1] {
            let mut p = parameters_with(shape, false);
            p.preset = 2;
            p.bladder_model = 1;
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

    const OUTPUTS: [&str; 6] = [
        "force",
        "volume",
        "effective_pressure",
        "friction_force",
        "max_radius",
        "stiffness",
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
                    let exact = m.partials(&x).unwrap();
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
                    for (j, input) in ["pressure", "length"].into_iter().enumerate() {
                        let (up, down) =
                            (at(steps[j][0], steps[j][1]), at(-steps[j][0], -steps[j][1]));
                        for (k, name) in OUTPUTS.into_iter().enumerate() {
                            let row = exact.get(name).unwrap();
                            let e = row.iter().find(|(n, _)| *n == input).unwrap().1;
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
                                 d{name}/d{input} exact {e} central {central}",
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
        let d = m
            .partials(&Inputs {
                pressure,
                length: l,
            })
            .unwrap();
        let exact = d.get("force").unwrap()[1].1;
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
        let d = m.partials(&Inputs {
            pressure,
            length: l - h,
        });
        assert_eq!(d.unwrap().get("force").unwrap()[1], ("length", 0.0));
    }

    #[test]
    fn partials_are_zero_out_of_range() {
        let (mut m, _, _, c) = built(&parameters_with(1, false));
        let beyond = Inputs {
            pressure: 1e5,
            length: c.max_length + 0.01,
        };
        let d = m.partials(&beyond).unwrap();
        for name in OUTPUTS {
            assert_eq!(d.get(name).unwrap()[1], ("length", 0.0), "{name}");
        }
        assert!(d.get("force").unwrap()[0].1 != 0.0);
    }
}
