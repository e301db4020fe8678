//! McKibbenMuscle FMU: gauge pressure and length in, tension force out.
//!
//! Effects so far: the ideal Gaylord sleeve (eq. 2.1-2.3). The bladder and friction effects of
//! chapter 2 will be added as structural parameters that build nothing when switched off.

use super::{Model, Report, Vars};
use crate::physics::gaylord::Sleeve;
use crate::variables::mckibben_muscle::{real, INFO};
use crate::variables::ModelInfo;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct McKibbenMuscle {
    sleeve: Sleeve,
    /// Whether the last length was beyond `max_length`: the warning is logged once per excursion.
    length_clamped: bool,
}

impl McKibbenMuscle {
    fn write_outputs(&mut self, vars: &mut Vars, report: &mut Report) {
        let max_length = self.sleeve.max_length();
        let requested = vars.real[real::LENGTH];
        let length = requested.min(max_length);
        if requested > max_length {
            if !self.length_clamped {
                report.warn(format!(
                    "length {requested} m is beyond max_length {max_length} m, where the sleeve's \
                     diameter vanishes; evaluating at max_length until the length returns"
                ));
            } else {
                report.status = report.status.max(super::Status::Warning);
            }
        }
        self.length_clamped = requested > max_length;
        // The sleeve is only ever pushed outwards: under vacuum the bladder leaves it (eq. 2.3
        // holds for P >= 0 only).
        let pressure = vars.real[real::PRESSURE].max(0.0);
        vars.real[real::FORCE] = self.sleeve.force(pressure, length);
        vars.real[real::VOLUME] = self.sleeve.volume(length);
    }
}

impl Model for McKibbenMuscle {
    const INFO: &'static ModelInfo = &INFO;
    const DOCUMENTATION: &'static str = include_str!("mckibben_muscle.html");

    fn new(vars: &mut Vars) -> Result<Self, String> {
        let sleeve = Sleeve::new(vars.real[real::STRAND_LENGTH], vars.real[real::TURNS])?;
        vars.real[real::MAX_LENGTH] = sleeve.max_length();
        Ok(Self {
            sleeve,
            length_clamped: false,
        })
    }

    fn evaluate(&mut self, vars: &mut Vars, report: &mut Report) {
        self.write_outputs(vars, report)
    }

    fn step(&mut self, vars: &mut Vars, _time: f64, _step: f64, report: &mut Report) {
        // Quasi-static: the outputs at the end of the step follow from the held inputs alone.
        self.write_outputs(vars, report)
    }
}
