//! FreeBladder FMU: the McKibben muscle's latex tube without its sleeve, gauge pressure and clamp
//! length in, diameter, volume, compliance, stretches, stresses and clamp force out (dissertation
//! section 2.2.2, eq. 2.6-2.12, 2.17, 2.18; physics in [`crate::physics::free_bladder`]).
//!
//! It has no history: evaluate and step are the same algebraic map, so it also serves Model
//! Exchange. Inputs outside the solvable range are evaluated at the nearest valid point and
//! flagged (`input_clamped`, `out_of_range_policy`), each excursion logged once.

use super::{Model, Refusal, Report, Status};
use crate::physics::bladder::BladderTube;
use crate::physics::free_bladder::{FreeBladder as Tube, FreeBladderState};
use crate::variables::free_bladder::{Inputs, Outputs, Parameters, Variables};
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

impl FreeBladder {
    /// The tube at the inputs, clamped into the solvable range (`report` says why, once per
    /// excursion). `None` if the physics still refuses (logged; unreachable for finite
    /// parameters), and the outputs then keep their values.
    fn compute(&mut self, inputs: &Inputs, report: &mut Report) -> Option<FreeBladderState> {
        let l0 = self.tube.tube().unstretched_length;
        let (lo, hi) = (STRETCH_RANGE.0 * l0, STRETCH_RANGE.1 * l0);
        let length = if inputs.length.is_nan() {
            l0
        } else {
            inputs.length.clamp(lo, hi)
        };
        let top = self.tube.ballooning_pressure(length) * (1.0 - BALLOON_MARGIN);
        let pressure = if inputs.pressure.is_nan() {
            0.0
        } else {
            inputs.pressure.clamp(VACUUM, top)
        };
        if (pressure, length) == (inputs.pressure, inputs.length) {
            self.out_of_range = false;
        } else {
            report.clamp(!self.out_of_range, || {
                format!(
                    "pressure {} Pa, length {} m lie outside the solvable range (absolute vacuum \
                     .. ballooning pressure {} Pa, length {lo} .. {hi} m); evaluating at {pressure} \
                     Pa, {length} m until the inputs return",
                    inputs.pressure,
                    inputs.length,
                    top / (1.0 - BALLOON_MARGIN)
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

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        self.out_of_range = saved.out_of_range;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(report.status, Status::Ok);
        assert!(!report.clamped);
        assert_eq!(
            (o.inner_diameter, o.stretch_hoop, o.force),
            (0.0038, 1.0, 0.0)
        );
        // 2 (C1 + C2) 2t / D_RI (eq. 2.18 as the diameter grows without bound).
        assert!((o.ballooning_pressure - 52_631.58).abs() < 0.01);
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
            assert_eq!(report.clamped, !(-101_325.0..52_000.0).contains(&pressure));
            assert!(o.volume.is_finite() && o.volume > 0.0);
            messages += report.clamp_messages.len();
            volumes.push(o.volume);
        }
        // Two excursions (ballooning, vacuum), one message each; a clamped pressure gives the
        // outputs at the limit.
        assert_eq!(messages, 2);
        assert_eq!(volumes[0], volumes[1]);
        assert_eq!(volumes[3], volumes[4]);
        assert!(volumes[0] > 50.0 * volumes[2] && volumes[3] < volumes[5]);
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
