//! PassThrough FMU: `y = u`. A measurement baseline: an importer's cost per step measured on it
//! is the share of any other FMU's step time that is not the model's (docs/accuracy-cost.md).

use super::{Model, Report, Vars};
use crate::variables::pass_through::{real, INFO};
use crate::variables::ModelInfo;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PassThrough;

impl Model for PassThrough {
    const INFO: &'static ModelInfo = &INFO;
    const DOCUMENTATION: &'static str = "<h2>Equations</h2><p><code>y</code> = <code>u</code>. \
        A baseline for timing importers: the cost of a step of this FMU is the importer's and the \
        FMI layer's own.</p>";

    fn new(_vars: &mut Vars) -> Result<Self, String> {
        Ok(Self)
    }

    fn evaluate(&mut self, vars: &mut Vars, _report: &mut Report) {
        vars.real[real::Y] = vars.real[real::U];
    }

    fn step(&mut self, vars: &mut Vars, _time: f64, _step: f64, _report: &mut Report) {
        vars.real[real::Y] = vars.real[real::U];
    }
}
