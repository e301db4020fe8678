//! PassThrough FMU: `y = u`. A measurement baseline: an importer's cost per step measured on it
//! is the share of any other FMU's step time that is not the model's (docs/accuracy-cost.md).

use super::{HistoryKey, Model, Partials, Refusal, Report};
use crate::variables::pass_through::{Inputs, Outputs, Parameters, Variables, YBy};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PassThrough;

impl Model for PassThrough {
    type Variables = Variables;
    const ALGEBRAIC_MODEL_EXCHANGE: bool = true;
    const DOCUMENTATION: &'static str = "<h2>Equations</h2><p><code>y</code> = <code>u</code>. \
        A baseline for timing importers: the cost of a step of this FMU is the importer's and the \
        FMI layer's own.</p>";

    fn new(_: &Parameters, _: &Inputs) -> Result<Self, Refusal> {
        Ok(Self)
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, _: &mut Report) {
        outputs.y = inputs.u;
    }

    fn step(&mut self, inputs: &Inputs, outputs: &mut Outputs, _: f64, _: f64, _: &mut Report) {
        outputs.y = inputs.u;
    }

    fn partials(&mut self, _: &Inputs, p: &mut Partials<Variables>) -> Result<(), String> {
        p.row(YBy { u: 1.0 });
        Ok(())
    }

    fn partials_key(&self) -> Option<HistoryKey> {
        Some(HistoryKey::NONE)
    }
}
