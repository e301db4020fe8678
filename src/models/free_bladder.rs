//! FreeBladder FMU: the McKibben muscle's latex tube without its sleeve, gauge pressure and clamp
//! length in, diameter, volume, compliance, stretches, stresses and clamp force out (dissertation
//! section 2.2.2, eq. 2.6-2.9, 2.17, the thick wall solved exactly; physics in
//! [`crate::physics::free_bladder`]).
//!
//! It has no history: evaluate and step are the same algebraic map, so it also serves Model
//! Exchange. Inputs outside the solvable range are evaluated at the nearest valid point and
//! flagged (`input_clamped`, `out_of_range_policy`), each excursion logged once.

use super::wall_arrays::{self, wall_quantity_of, WallQuantity};
use super::{HistoryKey, Model, Partials, Refusal, Report, Status};
use crate::physics::bladder::BladderTube;
use crate::physics::free_bladder::{FreeBladder as Tube, FreeBladderState};
use crate::variables::free_bladder::{
    ArrayOutput, BallooningPressureBy, ComplianceBy, ForceBy, InnerDiameterBy, Inputs,
    OuterDiameterBy, Outputs, Parameters, StressAxialBy, StressHoopBy, StretchAxialBy,
    StretchHoopBy, StretchRadialBy, Variables, VolumeBy,
};
use serde::{Deserialize, Serialize};

/// Gauge pressure of an absolute vacuum at standard atmosphere, Pa: nothing lower is physical.
const VACUUM: f64 = -101_325.0;
/// A pressure at or above the ballooning pressure is evaluated this fraction below it (finite,
/// steeply rising volume), like the muscles' margin at their length limits.
const BALLOON_MARGIN: f64 = 1e-3;
/// Axial stretches evaluated: far beyond latex's use (it tears near 7), and the numbers stay finite.
const STRETCH_RANGE: (f64, f64) = (0.1, 10.0);

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FreeBladder {
    tube: Tube,
    /// Whether the last evaluation clamped an input: logged once per excursion.
    out_of_range: bool,
}

/// The point the model evaluates for some inputs: the inputs clamped into the solvable range,
/// with the slopes of that clamp (what the partials chain through).
struct OperatingPoint {
    pressure: f64,
    length: f64,
    /// `d pressure / d (input pressure, input length)`: `(1, 0)` inside the range; at the
    /// ballooning clamp the pressure follows the length through `ballooning_pressure(length)`.
    pressure_slope: [f64; 2],
    /// `d length / d input length`: 1 inside the range, 0 where it is clamped.
    length_slope: f64,
}

impl FreeBladder {
    /// The inputs clamped into the solvable range: NaN at the start value's default, a pressure
    /// below absolute vacuum at vacuum, one at or above the ballooning pressure 0.1% below it, the
    /// axial stretch into 0.1 .. 10. A bound itself is inside (its slopes are the interior's).
    fn operating_point(&self, inputs: &Inputs) -> OperatingPoint {
        let l0 = self.tube.tube().unstretched_length;
        let (lo, hi) = (STRETCH_RANGE.0 * l0, STRETCH_RANGE.1 * l0);
        let (length, length_slope) = if inputs.length.is_nan() {
            (l0, 0.0)
        } else if (lo..=hi).contains(&inputs.length) {
            (inputs.length, 1.0)
        } else {
            (inputs.length.clamp(lo, hi), 0.0)
        };
        let top = self.tube.ballooning_pressure(length) * (1.0 - BALLOON_MARGIN);
        let (pressure, pressure_slope) = if inputs.pressure.is_nan() {
            (0.0, [0.0; 2])
        } else if inputs.pressure > top {
            let d_top = (1.0 - BALLOON_MARGIN) * self.tube.ballooning_pressure_slope(length);
            (top, [0.0, d_top * length_slope])
        } else if inputs.pressure < VACUUM {
            (VACUUM, [0.0; 2])
        } else {
            (inputs.pressure, [1.0, 0.0])
        };
        OperatingPoint {
            pressure,
            length,
            pressure_slope,
            length_slope,
        }
    }

    /// The tube at the inputs, clamped into the solvable range (`report` says why, once per
    /// excursion). `None` if the physics still refuses (logged; unreachable for finite
    /// parameters), and the outputs then keep their values.
    fn compute(&mut self, inputs: &Inputs, report: &mut Report) -> Option<FreeBladderState> {
        let OperatingPoint {
            pressure, length, ..
        } = self.operating_point(inputs);
        if (pressure, length) == (inputs.pressure, inputs.length) {
            self.out_of_range = false;
        } else {
            let l0 = self.tube.tube().unstretched_length;
            let (lo, hi) = (STRETCH_RANGE.0 * l0, STRETCH_RANGE.1 * l0);
            let balloon = self.tube.ballooning_pressure(length);
            report.clamp(!self.out_of_range, || {
                format!(
                    "pressure {} Pa, length {} m lie outside the solvable range (absolute vacuum \
                     .. ballooning pressure {balloon} Pa, length {lo} .. {hi} m); evaluating at \
                     {pressure} Pa, {length} m until the inputs return",
                    inputs.pressure, inputs.length,
                )
            });
            self.out_of_range = true;
        }
        self.tube
            .evaluate(pressure, length)
            .map_err(|reason| report.add(Status::Error, reason))
            .ok()
    }

    fn write(outputs: &mut Outputs, s: &FreeBladderState) {
        outputs.inner_diameter = s.inner_diameter;
        outputs.outer_diameter = s.outer_diameter;
        outputs.volume = s.fluid_volume;
        outputs.compliance = s.compliance;
        outputs.stretch_axial = s.stretch_axial;
        outputs.stretch_hoop = s.stretch_hoop;
        outputs.stretch_radial = s.stretch_radial;
        outputs.stress_axial = s.stress_axial;
        outputs.stress_hoop = s.stress_hoop;
        outputs.force = s.force;
        outputs.ballooning_pressure = s.ballooning_pressure;
    }
}

impl Model for FreeBladder {
    type Variables = Variables;
    const ALGEBRAIC_MODEL_EXCHANGE: bool = true;
    const DOCUMENTATION: &'static str = include_str!("free_bladder.html");

    fn new(p: &Parameters, _: &Inputs) -> Result<Self, Refusal> {
        let tube = Tube::new(BladderTube {
            inner_diameter: p.bladder_inner_diameter,
            thickness: p.bladder_thickness,
            unstretched_length: p.bladder_length,
            mooney_c1: p.mooney_c1,
            mooney_c2: p.mooney_c2,
        })?;
        Ok(Self {
            tube,
            out_of_range: false,
        })
    }

    fn array(&self, inputs: &Inputs, array: ArrayOutput, out: &mut [f64]) -> Result<(), String> {
        let quantity = wall_quantity_of!(array);
        // At the point the outputs are computed at (the inputs clamped into the solvable range).
        let OperatingPoint {
            pressure, length, ..
        } = self.operating_point(inputs);
        wall_arrays::write(quantity, out, |f| self.tube.wall_field(pressure, length, f))
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        if let Some(state) = self.compute(inputs, report) {
            Self::write(outputs, &state);
        }
    }

    fn step(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        _: f64,
        _: f64,
        report: &mut Report,
    ) {
        self.evaluate(inputs, outputs, report)
    }

    /// Every Real output by `pressure` and `length`, exact (the free bladder's implicit function
    /// theorem on eq. 2.18), chained through the input clamp: a clamped input's column is 0, and
    /// at the ballooning clamp the pressure evaluated follows the length.
    fn partials(&mut self, inputs: &Inputs, p: &mut Partials<Variables>) -> Result<(), String> {
        let point = self.operating_point(inputs);
        let (_, d) = self
            .tube
            .evaluate_with_partials(point.pressure, point.length)?;
        let by_pressure = d.along(point.pressure_slope[0], 0.0);
        let by_length = d.along(point.pressure_slope[1], point.length_slope);
        let (dp, dl) = (&by_pressure, &by_length);
        p.row(InnerDiameterBy {
            pressure: dp.inner_diameter,
            length: dl.inner_diameter,
        })
        .row(OuterDiameterBy {
            pressure: dp.outer_diameter,
            length: dl.outer_diameter,
        })
        .row(VolumeBy {
            pressure: dp.fluid_volume,
            length: dl.fluid_volume,
        })
        .row(ComplianceBy {
            pressure: dp.compliance,
            length: dl.compliance,
        })
        .row(StretchAxialBy {
            length: dl.stretch_axial,
        })
        .row(StretchHoopBy {
            pressure: dp.stretch_hoop,
            length: dl.stretch_hoop,
        })
        .row(StretchRadialBy {
            pressure: dp.stretch_radial,
            length: dl.stretch_radial,
        })
        .row(StressAxialBy {
            pressure: dp.stress_axial,
            length: dl.stress_axial,
        })
        .row(StressHoopBy {
            pressure: dp.stress_hoop,
            length: dl.stress_hoop,
        })
        .row(ForceBy {
            pressure: dp.force,
            length: dl.force,
        })
        .row(BallooningPressureBy {
            length: dl.ballooning_pressure,
        });
        Ok(())
    }

    /// The partials are those of the inputs alone.
    fn partials_key(&self) -> Option<HistoryKey> {
        Some(HistoryKey::NONE)
    }

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        self.out_of_range = saved.out_of_range;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::all_partials;
    use super::*;
    use crate::variables::free_bladder::{Known, Unknown};

    fn run(p: &Parameters, pressure: f64, length: f64) -> (Outputs, Report) {
        let mut m = FreeBladder::new(p, &Inputs::default()).unwrap();
        let mut outputs = Outputs::default();
        let mut report = Report::default();
        m.step(
            &Inputs { pressure, length },
            &mut outputs,
            0.0,
            0.01,
            &mut report,
        );
        (outputs, report)
    }

    #[test]
    fn defaults_are_table_2_1_muscle_ds_tube_at_rest() {
        let p = Parameters::default();
        assert_eq!(
            (p.bladder_length, p.bladder_inner_diameter),
            (0.1336, 0.0038)
        );
        assert_eq!(
            (p.bladder_thickness, p.mooney_c1, p.mooney_c2),
            (0.00025, 161e3, 39e3)
        );
        let (o, report) = run(&p, 0.0, 0.1336);
        assert_eq!(report.status(), Status::Ok);
        assert!(!report.clamped());
        assert_eq!(
            (o.inner_diameter, o.stretch_hoop, o.force),
            (0.0038, 1.0, 0.0)
        );
        // 2 (C1 + C2) ln(D_RO / D_RI): the exact tube as its diameter grows without bound.
        assert!((o.ballooning_pressure - 49_445.58).abs() < 0.01);
    }

    #[test]
    fn ballooning_and_vacuum_are_clamped_once_per_excursion() {
        let p = Parameters::default();
        let mut m = FreeBladder::new(&p, &Inputs::default()).unwrap();
        let mut o = Outputs::default();
        let mut messages = 0;
        let mut volumes = Vec::new();
        for pressure in [1e5, 2e5, 3e4, -2e5, -3e5, 0.0] {
            let mut report = Report::default();
            let inputs = Inputs {
                pressure,
                length: 0.1336,
            };
            m.step(&inputs, &mut o, 0.0, 0.01, &mut report);
            assert_eq!(
                report.clamped(),
                !(-101_325.0..52_000.0).contains(&pressure)
            );
            assert!(o.volume.is_finite() && o.volume > 0.0);
            messages += report.clamp_messages().len();
            volumes.push(o.volume);
        }
        // Two excursions (ballooning, vacuum), one message each; a clamped pressure gives the
        // outputs at the limit.
        assert_eq!(messages, 2);
        assert_eq!(volumes[0], volumes[1]);
        assert_eq!(volumes[3], volumes[4]);
        assert!(volumes[0] > 20.0 * volumes[2] && volumes[3] < volumes[5]);
    }

    /// The Real outputs by identifier.
    fn reals(o: &Outputs) -> [(Unknown, f64); 11] {
        [
            (Unknown::InnerDiameter, o.inner_diameter),
            (Unknown::OuterDiameter, o.outer_diameter),
            (Unknown::Volume, o.volume),
            (Unknown::Compliance, o.compliance),
            (Unknown::StretchAxial, o.stretch_axial),
            (Unknown::StretchHoop, o.stretch_hoop),
            (Unknown::StretchRadial, o.stretch_radial),
            (Unknown::StressAxial, o.stress_axial),
            (Unknown::StressHoop, o.stress_hoop),
            (Unknown::Force, o.force),
            (Unknown::BallooningPressure, o.ballooning_pressure),
        ]
    }

    #[test]
    fn partials_match_central_differences_through_the_input_clamp() {
        // Muscle D's tube (thin) and muscle A's (thick, Table 2.1): inside the range, near
        // ballooning, pre-strained, and with each input clamped (above the ballooning pressure the
        // evaluated pressure follows the length; below vacuum and past the stretch range a
        // column is 0).
        let thick = Parameters {
            bladder_length: 0.1005,
            bladder_inner_diameter: 1.6e-3,
            bladder_thickness: 1.6e-3,
            ..Parameters::default()
        };
        let mut zero_columns = 0;
        for p in [Parameters::default(), thick] {
            let l0 = p.bladder_length;
            let mut m = FreeBladder::new(&p, &Inputs::default()).unwrap();
            for (lambda, fraction) in [
                (1.0, 0.5),
                (1.4, 0.99),
                (0.7, -0.3),
                (1.2, 1.5),
                (1.0, -3.0),
                (12.0, 0.3),
                (0.05, 0.3),
            ] {
                let length = lambda * l0;
                let top = m
                    .tube
                    .ballooning_pressure(length.clamp(0.1 * l0, 10.0 * l0));
                let pressure = fraction * top;
                let inputs = Inputs { pressure, length };
                let partials = all_partials(&mut m, &inputs).unwrap();
                let gap = if fraction < 1.0 { 1.0 - fraction } else { 1.0 };
                for (input, h) in [
                    (Known::Pressure, 1e-5 * gap * top),
                    (Known::Length, 1e-7 * l0),
                ] {
                    let at = |sign: f64| {
                        let mut shifted = inputs.clone();
                        match input {
                            Known::Pressure => shifted.pressure += sign * h,
                            Known::Length => shifted.length += sign * h,
                        }
                        run(&p, shifted.pressure, shifted.length).0
                    };
                    let (up, down) = (at(1.0), at(-1.0));
                    for ((name, hi), (_, lo)) in reals(&up).into_iter().zip(reals(&down)) {
                        let central = (hi - lo) / (2.0 * h);
                        let exact = partials
                            .partial(name, input)
                            .unwrap_or_else(|| panic!("no partial of {name:?} by {input:?}"));
                        let size = hi.abs().max(lo.abs()).max(1e-30);
                        // Near the ballooning pressure the volume ratio is ill-conditioned (the
                        // pressure is flat in it), so its rounding is larger there.
                        let noise = if fraction > 0.98 { 1e-5 } else { 1e-8 };
                        let scale = exact.abs().max(central.abs()) + noise * size / h.max(1e-30);
                        assert!(
                            (exact - central).abs() <= 1e-6 * scale,
                            "lambda {lambda}, P {pressure}: d{name:?}/d{input:?} exact {exact}, \
                             central {central}"
                        );
                        zero_columns += usize::from(exact == 0.0 && central == 0.0);
                    }
                }
            }
        }
        // The clamped columns are zero: vacuum's pressure column and the stretch clamps' length
        // columns (11 outputs each), beside the outputs that never depend on the input.
        assert!(zero_columns >= 2 * 3 * 11, "{zero_columns}");
    }

    #[test]
    fn refuses_a_tube_without_stiffness() {
        let p = Parameters {
            mooney_c1: 0.0,
            mooney_c2: 0.0,
            ..Parameters::default()
        };
        let reason = FreeBladder::new(&p, &Inputs::default()).unwrap_err().0;
        assert!(reason.contains("mooney_c1"), "{reason}");
    }
}
