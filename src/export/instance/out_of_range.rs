//! The out-of-range policy: what an importer hears when an input lies outside the model's
//! solvable range and the model evaluates the nearest valid point instead.
//!
//! Strict masters (OMSimulator) stop on any status but fmi2OK, so by default the call succeeds,
//! the Boolean output `input_clamped` says so and the log explains each excursion once. The
//! Integer parameter `out_of_range_policy` asks for fmi2Warning (1) or, from fmi2DoStep,
//! fmi2Discard (2) instead.

use crate::export::runtime::Runtime;
use crate::models::{Report, Status};
use crate::variables::{ModelInfo, VarType};

/// Name of the Integer parameter that selects the policy.
pub const POLICY: &str = "out_of_range_policy";
/// Name of the Boolean output that flags outputs computed at a clamped input.
pub const FLAG: &str = "input_clamped";

/// Where a model keeps the policy parameter and the flag, if it has them.
#[derive(Clone, Copy, Debug, Default)]
pub struct OutOfRange {
    policy: Option<usize>,
    flag: Option<usize>,
}

impl OutOfRange {
    pub fn new(info: &ModelInfo) -> Self {
        let index = |name: &str, kind: VarType| {
            info.variables
                .iter()
                .find(|v| v.name == name && v.kind == kind)
                .map(|v| v.vr as usize)
        };
        Self {
            policy: index(POLICY, VarType::Integer),
            flag: index(FLAG, VarType::Boolean),
        }
    }

    /// The status a clamped input earns under the policy; `in_step` is true for fmi2DoStep,
    /// the only call for which fmi2Discard means something (elsewhere it is a warning).
    pub fn status(&self, runtime: &dyn Runtime, in_step: bool) -> Status {
        match self.policy.map_or(0, |i| runtime.integer(i)) {
            0 => Status::Ok,
            2 if in_step => Status::Discard,
            _ => Status::Warning,
        }
    }

    /// A report with nothing clamped: the flag says so (what [`OutOfRange::apply`] does then).
    #[inline]
    pub fn clear_flag(&self, runtime: &mut dyn Runtime) {
        if let Some(i) = self.flag {
            runtime.set_boolean(i, false);
        }
    }

    /// Writes the flag, turns the clamp into the policy's status and its explanations into
    /// messages of that status (logged even at fmi2OK: one line per excursion).
    pub fn apply(
        &self,
        runtime: &mut dyn Runtime,
        report: &mut Report,
        in_step: bool,
    ) -> Vec<String> {
        if let (true, Some(i)) = (report.evaluated, self.flag) {
            runtime.set_boolean(i, report.clamped());
        }
        if !report.clamped() {
            return Vec::new();
        }
        let status = self.status(runtime, in_step);
        report.raise(status);
        let messages = report.take_clamp_messages();
        if status > Status::Ok {
            if messages.is_empty() {
                // The model explains an excursion once, when it begins (perhaps in another
                // call); a status other than OK still needs its reason in this call.
                report.add(
                    status,
                    format!(
                        "an input is still outside the model's valid range (explained when the \
                         excursion began); outputs are those of the nearest valid point \
                         (`{FLAG}` is true; `{POLICY}` asks for this status)"
                    ),
                );
            }
            for m in messages {
                report.add(status, m);
            }
            Vec::new()
        } else {
            messages
        }
    }
}
