//! McKibbenJoint FMU: an antagonistic pair of McKibben muscles on a pulley as one joint actuator,
//! with gazebo-fmi's variable names (`actuatorInput`, `jointPosition`, `jointVelocity` in,
//! `jointTorque` out).
//!
//! Both muscles are [`McKibben`] physics instances built from the same parameters as the
//! McKibbenMuscle FMU; the flexor's length is `L0f - r q`, the extensor's `L0e + r q`, so the
//! torque `r (F_flexor - F_extensor)` turns the joint towards the flexor. `actuatorInput` is the
//! pressure difference around the common mode, each pressure saturated to `0 .. max_pressure`;
//! with `command_mode` 1 it is a joint torque, met by solving for that difference through the same
//! muscle physics ([`crate::physics::inverse::difference_for_torque`]).

use super::{HistoryKey, Model, Partials, Refusal, Report, Status};
use crate::physics::bladder::{BladderTube, MOONEY_C1, MOONEY_C2};
use crate::physics::by_pressure_length::ByPressureLength;
use crate::physics::festo;
use crate::physics::friction::HysteresisState;
use crate::physics::gaylord::Sleeve;
use crate::physics::inverse::{difference_for_torque, pair_pressures};
use crate::physics::mckibben::{
    is_slack, strand_rigidity, BladderModel, FrictionParams, McKibben, McKibbenOutput,
    MuscleGeometry, OutOfRange,
};
use crate::variables::mckibben_joint::{
    CalculatedParameters, ExtensorForceBy, ExtensorLengthBy, ExtensorPressureBy, FlexorForceBy,
    FlexorLengthBy, FlexorPressureBy, Inputs, JointTorqueBy, Outputs, Parameters, Variables,
};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct McKibbenJoint {
    /// One physics model serves both muscles: they share geometry and differ only in history.
    muscle: McKibben,
    moment_arm: f64,
    flexor_rest_length: f64,
    extensor_rest_length: f64,
    common_mode_pressure: f64,
    max_pressure: f64,
    /// Friction histories (eq. 2.4), advanced only by accepted steps.
    flexor_friction: HysteresisState,
    extensor_friction: HysteresisState,
    /// Whether the last evaluation needed the length fallback (warned once per excursion).
    out_of_range: bool,
    /// Joint angles that keep both muscles inside their length range (rad).
    position_range: (f64, f64),
    /// `actuatorInput` is a joint torque (N m) to meet, not a pressure difference (Pa).
    torque_command: bool,
    /// The dissertation's signed muscle forces (`signed_force`); else tension only.
    signed_force: bool,
    /// The straight strands' axial stiffness `k_s = E A / b` of each muscle, N/m (from
    /// `strand_rigidity`): past `max_length` the strands stretch, as in McKibbenMuscle.
    strand_stiffness: f64,
    /// `out_of_range_policy` 2: a step whose input is out of range is refused, so a step that
    /// takes a muscle past its breaking length is refused before either muscle is evaluated.
    refuse_out_of_range: bool,
}

/// One muscle at one pressure and length: its outputs, why they are clamped (if so), and its
/// partials ([`McKibben::evaluate_and_partials_with_strands`]).
type Evaluated = (
    Option<McKibbenOutput>,
    Option<OutOfRange>,
    Result<ByPressureLength, String>,
);

/// Both muscles' operating point at the current inputs.
struct Pair {
    flexor: McKibbenOutput,
    extensor: McKibbenOutput,
    pressures: [f64; 2],
    lengths: [f64; 2],
    /// Command mode 1: the commanded torque was out of reach.
    saturated: bool,
    /// Whether each muscle (flexor, extensor) is slack: its signed force is negative.
    slack: [bool; 2],
}

fn muscle(p: &Parameters) -> Result<McKibben, String> {
    let model = BladderModel::from_switch(p.bladder_model, p.bladder_layers)?;
    let friction = p.friction.then_some(FrictionParams {
        coefficient: p.friction_coefficient,
        presliding_length: p.presliding_length,
    });
    match p.preset {
        0 => McKibben::new(
            Sleeve::new(p.strand_length, p.turns)?,
            BladderTube {
                inner_diameter: p.bladder_inner_diameter,
                thickness: p.bladder_thickness,
                unstretched_length: p.bladder_length,
                mooney_c1: MOONEY_C1,
                mooney_c2: MOONEY_C2,
            },
            model,
            friction,
            0.0,
        ),
        k @ 1..=4 => {
            let geometry = MuscleGeometry::preset((b'A' + k as u8 - 1) as char)
                .ok_or_else(|| format!("preset {k} has no Table 2.1 row"))?;
            McKibben::from_geometry(&geometry, model, friction, 0.0)
        }
        // The Festo muscles (the DMSP scaling law) carry their own rubber and exact wall.
        k @ 5..=8 => {
            let (festo, _) =
                festo::preset(k).ok_or_else(|| format!("preset {k} has no DMSP size"))?;
            McKibben::new(
                Sleeve::new(festo.strand_length, festo.turns)?,
                BladderTube {
                    inner_diameter: festo.bladder_inner_diameter,
                    thickness: festo.bladder_thickness,
                    unstretched_length: festo.bladder_length,
                    mooney_c1: festo.mooney_c1,
                    mooney_c2: festo.mooney_c2,
                },
                BladderModel::from_switch(festo.bladder_model, festo.bladder_layers)?,
                friction,
                0.0,
            )
        }
        k => Err(format!(
            "preset must be 0 (none), 1-4 (Table 2.1 A-D), 5 (Festo DMSP-10), 6 (DMSP-40), 7 (DMSP-5) or 8 (DMSP-20), got {k}"
        )),
    }
}

/// `E A` of all strands of one muscle, N: the user's `strand_rigidity`, or for the Festo presets
/// (unless set) their aramid strands, as McKibbenMuscle's.
fn rigidity(p: &Parameters) -> Result<f64, String> {
    let set = p.strand_rigidity != Parameters::default().strand_rigidity;
    strand_rigidity(p.strand_rigidity, set, festo::largest_force(p.preset))
}

fn positive(name: &str, x: f64) -> Result<f64, Refusal> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(format!("{name} must be finite and > 0, got {x}").into())
    }
}

impl McKibbenJoint {
    /// Whether a muscle with this signed force is slack: a braided muscle cannot push, so past
    /// its free contraction it carries no force and has no stiffness (unless `signed_force`).
    fn slack(&self, force: f64) -> bool {
        is_slack(force, self.signed_force)
    }

    /// The muscle's output, tension only unless `signed_force`.
    fn tension(&self, mut out: McKibbenOutput) -> McKibbenOutput {
        if self.slack(out.force) {
            out.force = 0.0;
            out.stiffness = 0.0;
        }
        out
    }

    /// Signed force and `[dF/dP, dF/dL]` of one muscle on the branch
    /// [`McKibben::evaluate_with_strands`] takes (on the strands, their slope; at a clamped length the length no longer moves it).
    fn signed_force_and_partials(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
    ) -> Option<(f64, [f64; 2])> {
        let k_s = self.strand_stiffness;
        self.muscle
            .force_and_partials_with_strands(pressure, length, k_s, history)
            .ok()
            .map(|(force, d)| (force, d.force))
    }

    /// Both muscles at the pressures from `difference`, at the given lengths and histories:
    /// each one's outputs (with why, if clamped) and partials, from one search for its strands'
    /// transition. A muscle whose pressure is one it was evaluated at in `earlier` (the torque
    /// solver's evaluations, at these lengths and histories) is taken from there: a pressure
    /// clipped to 0 or `max_pressure` stays so across most of the solver's iterations, and each
    /// evaluation past `max_length` searches for the strands' transition anew.
    fn pair_at(
        &self,
        difference: f64,
        lengths: [f64; 2],
        earlier: &[(f64, [Evaluated; 2])],
    ) -> [Evaluated; 2] {
        let (pc, pmax) = (self.common_mode_pressure, self.max_pressure);
        let p = pair_pressures(pc, difference, pmax);
        let k_s = self.strand_stiffness;
        let histories = [&self.flexor_friction, &self.extensor_friction];
        [0, 1].map(|i| {
            let same = |d: &f64| pair_pressures(pc, *d, pmax)[i].to_bits() == p[i].to_bits();
            match earlier.iter().find(|(d, _)| same(d)) {
                Some((_, pair)) => pair[i].clone(),
                None => self.muscle.evaluate_and_partials_with_strands(
                    p[i],
                    lengths[i],
                    k_s,
                    histories[i],
                ),
            }
        })
    }

    /// Torque of the pair evaluated at `difference` ([`Self::pair_at`]), and its slope in the
    /// difference.
    fn torque_at(&self, difference: f64, pair: &[Evaluated; 2]) -> Result<(f64, f64), String> {
        let (pc, pmax) = (self.common_mode_pressure, self.max_pressure);
        // dP/d(difference) is +-1/2 where a pressure is not clipped.
        let unclipped = |x: f64| if x > 0.0 && x < pmax { 0.5 } else { 0.0 };
        // Force and dF/dP of one muscle, tension only unless `signed_force`.
        let force_and_slope = |e: &Evaluated| match e {
            (Some(out), _, Ok(_)) if self.slack(out.force) => Some((0.0, 0.0)),
            (Some(out), _, Ok(d)) => Some((out.force, d.force[0])),
            _ => None,
        };
        match (force_and_slope(&pair[0]), force_and_slope(&pair[1])) {
            (Some((f, df)), Some((e, de))) => Ok((
                self.moment_arm * (f - e),
                self.moment_arm
                    * (df * unclipped(pc + 0.5 * difference)
                        + de * unclipped(pc - 0.5 * difference)),
            )),
            _ => Err("a muscle cannot be evaluated at this jointPosition".into()),
        }
    }

    fn compute(&mut self, inputs: &Inputs, report: &mut Report) -> Option<Pair> {
        let (u, q) = (inputs.actuator_input, inputs.joint_position);
        let lengths = [
            self.flexor_rest_length - self.moment_arm * q,
            self.extensor_rest_length + self.moment_arm * q,
        ];
        // The solver's evaluations, whose outputs serve again at the difference it returns.
        let mut solved_at: Vec<(f64, [Evaluated; 2])> = Vec::new();
        let (difference, saturated) = if self.torque_command {
            // The pressure difference that meets the torque, through the same muscle physics.
            let torque_of = |d: f64| {
                let pair = self.pair_at(d, lengths, &solved_at);
                let torque = self.torque_at(d, &pair);
                solved_at.push((d, pair));
                torque
            };
            match difference_for_torque(torque_of, u, self.max_pressure) {
                Ok(solved) => (solved.argument, solved.saturated),
                Err(reason) => {
                    report.add(
                        Status::Discard,
                        format!("jointPosition {q} rad, torque command {u} N m: {reason}"),
                    );
                    return None;
                }
            }
        } else {
            (u, false)
        };
        // Each pressure clipped to 0 .. max_pressure (a NaN maps to a bound).
        let pressures = pair_pressures(self.common_mode_pressure, difference, self.max_pressure);
        // Each muscle with its strands stretching past `max_length`; beyond the length no muscle
        // survives, the nearest point evaluated (why, in `clamped`).
        let evaluated = match solved_at
            .into_iter()
            .rfind(|(d, _)| d.to_bits() == difference.to_bits())
        {
            Some((_, [(f, fc, _), (e, ec, _)])) => [(f, fc), (e, ec)],
            None => {
                let k_s = self.strand_stiffness;
                let (f, e) = (&self.flexor_friction, &self.extensor_friction);
                [
                    self.muscle
                        .evaluate_with_strands(pressures[0], lengths[0], k_s, f),
                    self.muscle
                        .evaluate_with_strands(pressures[1], lengths[1], k_s, e),
                ]
            }
        };
        let clamped = evaluated
            .iter()
            .find_map(|(_, clamp)| clamp.as_ref().map(|c| c.message()));
        let [(flexor, _), (extensor, _)] = evaluated;
        match clamped {
            Some(reason) => {
                report.clamp(!self.out_of_range, || {
                    format!("jointPosition {q} rad: {reason}")
                });
                self.out_of_range = true;
            }
            None => self.out_of_range = false,
        }
        let (flexor, extensor) = (flexor?, extensor?);
        Some(Pair {
            slack: [self.slack(flexor.force), self.slack(extensor.force)],
            flexor: self.tension(flexor),
            extensor: self.tension(extensor),
            pressures,
            lengths,
            saturated,
        })
    }

    /// Why a step at `inputs` is refused under `out_of_range_policy` 2 without evaluating it: a
    /// muscle past its breaking length (McKibbenMuscle's reason; without a connector its range
    /// test decides, whatever the pressure). The flexor's reason if both are.
    fn refused_past_breaking(&self, inputs: &Inputs) -> Option<OutOfRange> {
        let q = inputs.joint_position;
        let lengths = [
            self.flexor_rest_length - self.moment_arm * q,
            self.extensor_rest_length + self.moment_arm * q,
        ];
        let (pc, pmax) = (self.common_mode_pressure, self.max_pressure);
        // With a torque command the pressures are not known before the solve; the range test
        // does not need them.
        let difference = if self.torque_command {
            0.0
        } else {
            inputs.actuator_input
        };
        let pressures = pair_pressures(pc, difference, pmax);
        let histories = [&self.flexor_friction, &self.extensor_friction];
        (0..2).find_map(|i| {
            self.muscle
                .refused_past_breaking(pressures[i], lengths[i], histories[i])
        })
    }

    /// `[dF/dP, dF/dL]` of one muscle on the branch `compute` takes: 0 while slack.
    fn muscle_partials(&self, pressure: f64, length: f64, history: &HysteresisState) -> [f64; 2] {
        match self.signed_force_and_partials(pressure, length, history) {
            Some((force, d)) if !self.slack(force) => d,
            _ => [0.0; 2],
        }
    }

    fn write(&self, out: &mut Outputs, pair: &Pair) {
        out.joint_torque = self.moment_arm * (pair.flexor.force - pair.extensor.force);
        out.flexor_pressure = pair.pressures[0];
        out.extensor_pressure = pair.pressures[1];
        out.flexor_force = pair.flexor.force;
        out.extensor_force = pair.extensor.force;
        out.flexor_length = pair.lengths[0];
        out.extensor_length = pair.lengths[1];
        out.torque_saturated = pair.saturated;
        [out.flexor_slack, out.extensor_slack] = pair.slack;
    }
}

impl Model for McKibbenJoint {
    type Variables = Variables;
    const ALGEBRAIC_MODEL_EXCHANGE: bool = true;
    const DOCUMENTATION: &'static str = include_str!("mckibben_joint.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        saved.flexor_friction.check("flexor friction history")?;
        saved.extensor_friction.check("extensor friction history")?;
        self.flexor_friction = saved.flexor_friction;
        self.extensor_friction = saved.extensor_friction;
        self.out_of_range = saved.out_of_range;
        Ok(())
    }

    fn new(p: &Parameters, start: &Inputs) -> Result<Self, Refusal> {
        let moment_arm = positive("moment_arm", p.moment_arm)?;
        let flexor_rest_length = positive("flexor_rest_length", p.flexor_rest_length)?;
        let extensor_rest_length = positive("extensor_rest_length", p.extensor_rest_length)?;
        let max_pressure = positive("max_pressure", p.max_pressure)?;
        let common_mode_pressure = p.common_mode_pressure;
        if !(common_mode_pressure.is_finite()
            && (0.0..=max_pressure).contains(&common_mode_pressure))
        {
            return Err(format!(
                "common_mode_pressure must lie in 0 .. max_pressure = {max_pressure} Pa, got {common_mode_pressure}"
            ).into());
        }
        let muscle = muscle(p)?;
        let strand_stiffness = muscle.strand_stiffness(rigidity(p)?);
        let (lo, hi) = (muscle.min_length(), muscle.max_length());
        // Flexor L0f - r q and extensor L0e + r q both inside (lo, hi).
        let min_position =
            ((flexor_rest_length - hi) / moment_arm).max((lo - extensor_rest_length) / moment_arm);
        let max_position =
            ((flexor_rest_length - lo) / moment_arm).min((hi - extensor_rest_length) / moment_arm);
        if min_position >= max_position {
            return Err(format!(
                "no joint angle keeps both muscles inside their length range {lo} .. {hi} m \
                 (flexor_rest_length {flexor_rest_length} m, extensor_rest_length {extensor_rest_length} m)"
            ).into());
        }
        let q = start.joint_position;
        let torque_command = match p.command_mode {
            0 => false,
            1 => true,
            k => {
                return Err(format!(
                    "command_mode must be 0 (pressure difference, Pa) or 1 (joint torque, N m), got {k}"
                )
                .into())
            }
        };
        Ok(Self {
            muscle,
            moment_arm,
            flexor_rest_length,
            extensor_rest_length,
            common_mode_pressure,
            max_pressure,
            // Friction starts relaxed (z = 0) at the initial lengths.
            flexor_friction: HysteresisState::at_rest(flexor_rest_length - moment_arm * q),
            extensor_friction: HysteresisState::at_rest(extensor_rest_length + moment_arm * q),
            out_of_range: false,
            position_range: (min_position, max_position),
            torque_command,
            signed_force: p.signed_force,
            strand_stiffness,
            refuse_out_of_range: p.out_of_range_policy == 2,
        })
    }

    fn calculated_parameters(&self) -> CalculatedParameters {
        CalculatedParameters {
            min_position: self.position_range.0,
            max_position: self.position_range.1,
        }
    }

    /// The chain rule through the pressure difference `d`, the split `P = pc +- d/2` (slope 0
    /// where a pressure is clipped to 0 or max_pressure) and the lengths `L0 -+ r q`. With
    /// `command_mode` 1, `d` solves `torque(d, q) = u`: `dd/du = 1/torque_d` and
    /// `dd/dq = -torque_q/torque_d` (implicit function theorem), both 0 when saturated.
    /// jointVelocity moves nothing.
    fn partials(&mut self, inputs: &Inputs, p: &mut Partials<Variables>) -> Result<(), String> {
        let q = inputs.joint_position;
        let (pmax, r) = (self.max_pressure, self.moment_arm);
        // The operating point as `evaluate` finds it (a copy: the warning state stays put).
        let pair = self
            .clone()
            .compute(inputs, &mut Report::default())
            .ok_or("a muscle cannot be evaluated at this jointPosition")?;
        let [pf, pe] = pair.pressures;
        let interior = |p: f64| p > 0.0 && p < pmax;
        let dpf = if interior(pf) { 0.5 } else { 0.0 };
        let dpe = if interior(pe) { -0.5 } else { 0.0 };
        let lf = self.flexor_rest_length - r * q;
        let le = self.extensor_rest_length + r * q;
        let ff = self.muscle_partials(pf, lf, &self.flexor_friction);
        let fe = self.muscle_partials(pe, le, &self.extensor_friction);
        // Forces per unit d and per unit q at fixed d.
        let (ff_d, fe_d) = (ff[0] * dpf, fe[0] * dpe);
        let (ff_q, fe_q) = (-r * ff[1], r * fe[1]);
        let (dd_du, dd_dq) = if !self.torque_command {
            (1.0, 0.0)
        } else {
            let torque_d = r * (ff_d - fe_d);
            if pair.saturated || torque_d == 0.0 {
                (0.0, 0.0)
            } else {
                (1.0 / torque_d, -r * (ff_q - fe_q) / torque_d)
            }
        };
        let flexor = [ff_d * dd_du, ff_d * dd_dq + ff_q];
        let extensor = [fe_d * dd_du, fe_d * dd_dq + fe_q];
        let torque = [r * (flexor[0] - extensor[0]), r * (flexor[1] - extensor[1])];
        p.row(JointTorqueBy {
            actuator_input: torque[0],
            joint_position: torque[1],
        })
        .row(FlexorForceBy {
            actuator_input: flexor[0],
            joint_position: flexor[1],
        })
        .row(ExtensorForceBy {
            actuator_input: extensor[0],
            joint_position: extensor[1],
        })
        .row(FlexorPressureBy {
            actuator_input: dpf * dd_du,
            joint_position: dpf * dd_dq,
        })
        .row(ExtensorPressureBy {
            actuator_input: dpe * dd_du,
            joint_position: dpe * dd_dq,
        })
        .row(FlexorLengthBy { joint_position: -r })
        .row(ExtensorLengthBy { joint_position: r });
        Ok(())
    }

    /// The partials read both muscles' friction histories besides the inputs.
    fn partials_key(&self) -> Option<HistoryKey> {
        let (f, e) = (&self.flexor_friction, &self.extensor_friction);
        Some(HistoryKey::of([f.z, f.position, e.z, e.position]))
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        if let Some(pair) = self.compute(inputs, report) {
            self.write(outputs, &pair);
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
        if self.refuse_out_of_range {
            // The step is refused (fmi2Discard): its outputs and histories stay.
            if let Some(e) = self.refused_past_breaking(inputs) {
                let q = inputs.joint_position;
                report.clamp(!self.out_of_range, || {
                    format!("jointPosition {q} rad: {}", e.message())
                });
                self.out_of_range = true;
                return;
            }
        }
        // Quasi-static, as McKibbenMuscle: the held inputs fix the outputs at the end of the step
        // and each friction history follows its muscle's length at the communication points.
        if let Some(pair) = self.compute(inputs, report) {
            self.write(outputs, &pair);
            self.flexor_friction = pair.flexor.friction_state;
            self.extensor_friction = pair.extensor.friction_state;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::all_partials;
    use super::*;
    use crate::variables::mckibben_joint::Unknown;
    use std::f64::consts::PI;

    fn joint(p: &Parameters) -> McKibbenJoint {
        McKibbenJoint::new(p, &Inputs::default()).unwrap()
    }

    fn at(j: &mut McKibbenJoint, u: f64, q: f64) -> (Outputs, bool) {
        let x = Inputs {
            actuator_input: u,
            joint_position: q,
            joint_velocity: 0.0,
        };
        let mut out = Outputs::default();
        let mut report = Report::default();
        j.step(&x, &mut out, 0.0, 1e-3, &mut report);
        (out, report.clamped())
    }

    /// The bare sleeves past b: the extensor (`L0 + r q`) follows eq. 2.3 at `b` plus the
    /// strands' `E A / b` times the stretch, computed here in closed form; nothing is clamped
    /// before 5% strand strain past b, and the torque is continuous through `max_position`.
    #[test]
    fn extensor_strands_stretch_past_b() {
        let p = Parameters::default();
        let mut j = joint(&p);
        let (b, n, r, l0) = (
            p.strand_length,
            p.turns,
            p.moment_arm,
            p.extensor_rest_length,
        );
        let k_s = p.strand_rigidity / b;
        let u = 1e5;
        let extensor_pressure = p.common_mode_pressure - 0.5 * u;
        let eq_2_3_at_b = extensor_pressure * 2.0 * b * b / (4.0 * PI * n * n);
        let max_position = j.calculated_parameters().max_position;
        assert!((max_position - (b - l0) / r).abs() < 1e-12);
        for stretch in [1e-4, 0.01, 0.049] {
            let q = (b * (1.0 + stretch) - l0) / r;
            let (out, clamped) = at(&mut j, u, q);
            let expected = eq_2_3_at_b + k_s * stretch * b;
            assert!(!clamped && !out.extensor_slack);
            assert!(
                (out.extensor_force - expected).abs() < 1e-9 * expected,
                "{stretch}: {} vs {expected}",
                out.extensor_force
            );
        }
        // Left and right limits at max_position.
        let eps = 1e-9;
        let (left, _) = at(&mut j, u, max_position - eps);
        let (right, _) = at(&mut j, u, max_position + eps);
        let jump = (right.joint_torque - left.joint_torque).abs();
        assert!(jump <= 2.0 * eps * r * r * k_s * 1.01, "{jump} N m");
        // Past 5% strand strain: held at the breaking length, flagged.
        let (out, clamped) = at(&mut j, u, (1.1 * b - l0) / r);
        assert!(clamped);
        let at_break = eq_2_3_at_b + k_s * 0.05 * b;
        assert!((out.extensor_force - at_break).abs() < 1e-9 * at_break);
    }

    /// Monotone and finite through the breaking length with a bladder (muscle A, thin wall): the
    /// extensor's force rises by at most `k_s` per metre of its length, by exactly `k_s` past
    /// `max_length`.
    #[test]
    fn bladder_muscle_is_continuous_through_max_length() {
        let p = Parameters {
            preset: 1,
            bladder_model: 1,
            ..Default::default()
        };
        let mut j = joint(&p);
        let (r, l0) = (p.moment_arm, p.extensor_rest_length);
        let hi = j.muscle.max_length();
        let k_s = p.strand_rigidity / j.muscle.sleeve().strand_length;
        let breaking = j.muscle.breaking_length();
        let (from, to) = (hi - 0.02 * (hi - j.muscle.min_length()), breaking);
        let steps = 2000;
        let dl = (to - from) / steps as f64;
        let force_at = |j: &mut McKibbenJoint, l: f64| at(j, 0.0, (l - l0) / r);
        let mut previous = force_at(&mut j, from).0.extensor_force;
        for i in 1..=steps {
            let l = from + dl * i as f64;
            let (out, clamped) = force_at(&mut j, l);
            let rise = out.extensor_force - previous;
            assert!(!clamped && out.extensor_force.is_finite(), "{l}");
            assert!(rise > 0.0 && rise <= k_s * dl * (1.0 + 1e-5), "{l}: {rise}");
            if l - dl > hi {
                assert!((rise - k_s * dl).abs() < 1e-5 * k_s * dl, "{l}: {rise}");
            }
            previous = out.extensor_force;
        }
    }

    /// Under `out_of_range_policy` 2 a step that takes the extensor past its breaking length is
    /// refused before either muscle is evaluated (no wall evaluation, in either command mode):
    /// the outputs and both friction histories stay as the last accepted step left them, and the
    /// report flags the excursion with McKibbenMuscle's reason. Under policy 0 the same step is
    /// evaluated, the extensor's strands held at the breaking length.
    #[test]
    fn a_refused_step_past_breaking_is_not_evaluated() {
        let kernels = crate::physics::bladder::kernel_count;
        for (policy, mode) in [(0, 0), (2, 0), (0, 1), (2, 1)] {
            let p = Parameters {
                preset: 1,
                bladder_model: 1,
                friction: true,
                command_mode: mode,
                out_of_range_policy: policy,
                ..Default::default()
            };
            let mut j = joint(&p);
            let u = if mode == 1 { 0.1 } else { 1e5 };
            let (before, clamped) = at(&mut j, u, 0.0);
            assert!(!clamped);
            let histories = (j.flexor_friction, j.extensor_friction);
            let far = (1.2 * j.muscle.breaking_length() - p.extensor_rest_length) / p.moment_arm;
            let x = Inputs {
                actuator_input: u,
                joint_position: far,
                joint_velocity: 0.0,
            };
            let mut out = before.clone();
            let mut report = Report::default();
            let evaluations = kernels();
            j.step(&x, &mut out, 1e-3, 1e-3, &mut report);
            let evaluations = kernels() - evaluations;
            assert!(report.clamped());
            let why = report.clamp_messages().join("");
            assert!(why.contains("past max_length"), "{why}");
            if policy == 2 {
                assert_eq!(evaluations, 0, "mode {mode}");
                assert_eq!(out.joint_torque, before.joint_torque);
                assert_eq!((j.flexor_friction, j.extensor_friction), histories);
                assert!(why.contains("holding the previous outputs"), "{why}");
            } else {
                assert!(evaluations > 0);
                assert!(out.extensor_force > before.extensor_force, "mode {mode}");
            }
        }
    }

    /// The Festo presets' strands are aramid sized by the datasheet's largest force (Kevlar 49,
    /// 112 GPa, at a tenth of its 3 GPa strength), unless `strand_rigidity` is set.
    #[test]
    fn festo_strands_are_aramid_unless_set() {
        for (preset, force) in [(5, 630.0), (6, 6000.0)] {
            let p = Parameters {
                preset,
                ..Default::default()
            };
            let j = joint(&p);
            let b = j.muscle.sleeve().strand_length;
            let aramid = 112e9 / 0.3e9 * force / b;
            assert!((j.strand_stiffness - aramid).abs() < 1e-9 * aramid);
            let set = joint(&Parameters {
                strand_rigidity: 5e4,
                ..p
            });
            assert!((set.strand_stiffness - 5e4 / b).abs() < 1e-9 * set.strand_stiffness);
        }
    }

    /// The partials are central differences of the outputs, on the strands, in both command
    /// modes, and 0 for a slack muscle's force.
    #[test]
    fn partials_are_the_slopes_on_the_strands_and_zero_while_slack() {
        for (preset, model, mode) in [(0, 0, 0), (0, 0, 1), (1, 3, 0), (1, 3, 1)] {
            let p = Parameters {
                preset,
                bladder_model: model,
                command_mode: mode,
                ..Default::default()
            };
            let mut j = joint(&p);
            let hi = j.muscle.max_length();
            let q = (hi + 0.01 * j.muscle.sleeve().strand_length - p.extensor_rest_length)
                / p.moment_arm;
            let u = if mode == 1 { 0.5 } else { 1e5 };
            let x = Inputs {
                actuator_input: u,
                joint_position: q,
                joint_velocity: 0.0,
            };
            let d = all_partials(&mut j, &x).unwrap();
            let names = [
                Unknown::JointTorque,
                Unknown::FlexorForce,
                Unknown::ExtensorForce,
            ];
            let value = |j: &mut McKibbenJoint, u: f64, q: f64| {
                let (o, clamped) = at(j, u, q);
                assert!(!clamped);
                [o.joint_torque, o.flexor_force, o.extensor_force]
            };
            for (column, h) in [(0, if mode == 1 { 1e-4 } else { 1.0 }), (1, 1e-7)] {
                let (du, dq) = if column == 0 { (h, 0.0) } else { (0.0, h) };
                let up = value(&mut j, u + du, q + dq);
                let down = value(&mut j, u - du, q - dq);
                for (k, name) in names.iter().enumerate() {
                    let fd = (up[k] - down[k]) / (2.0 * h);
                    let exact = d.get(*name).unwrap()[column];
                    let scale = fd.abs().max(exact.abs()).max(1e-9);
                    assert!(
                        (fd - exact).abs() < 1e-4 * scale,
                        "preset {preset} mode {mode} {name:?}[{column}]: {exact} vs {fd}"
                    );
                }
            }
        }
        // Short muscles: the flexor goes slack; its force's partials are 0.
        let p = Parameters {
            flexor_rest_length: 0.07,
            extensor_rest_length: 0.07,
            ..Default::default()
        };
        let mut j = joint(&p);
        let (out, _) = at(&mut j, 0.0, 0.6);
        assert!(out.flexor_slack && out.flexor_force == 0.0 && !out.extensor_slack);
        let x = Inputs {
            actuator_input: 0.0,
            joint_position: 0.6,
            joint_velocity: 0.0,
        };
        let d = all_partials(&mut j, &x).unwrap();
        assert!(d
            .get(Unknown::FlexorForce)
            .unwrap()
            .iter()
            .all(|v| *v == 0.0));
    }

    /// A torque command met on soft strands that take over where the flexor's rigid force turns
    /// to a pull (the Festo DMSP-10 with `strand_rigidity` 64 N, stretched past its breaking
    /// length): the delivered torque is the command, not the solver's last iterate short of it.
    #[test]
    fn torque_command_is_met_where_the_strands_take_over_at_zero_force() {
        let p = Parameters {
            preset: 5,
            strand_rigidity: 64.12,
            moment_arm: 0.2813,
            flexor_rest_length: 0.211,
            extensor_rest_length: 5.16e-3,
            common_mode_pressure: 2.035e5,
            max_pressure: 4.013e7,
            command_mode: 1,
            ..Default::default()
        };
        let mut j = joint(&p);
        let flexor = p.flexor_rest_length + p.moment_arm * 2.552;
        let t = j.muscle.strand_point(
            2e5,
            j.muscle.breaking_length(),
            j.strand_stiffness,
            &j.flexor_friction,
        );
        assert!(flexor > j.muscle.breaking_length() && t.is_some_and(|t| t.force_zero));
        for command in [2.5, 3.175, 5.0] {
            let (out, clamped) = at(&mut j, command, -2.552);
            assert!(clamped && !out.torque_saturated);
            assert!(
                (out.joint_torque - command).abs() < 1e-9 * command,
                "{command}: {}",
                out.joint_torque
            );
        }
    }

    /// A torque command with no common-mode pressure: the solver keeps one muscle's pressure
    /// clipped to 0 while it searches, the flexor on its stretching strands (the Festo DMSP-10
    /// with 324 N strands). The outputs are each muscle's physics at the pressures
    /// returned, evaluated here on their own, and the torque meets the command.
    #[test]
    fn torque_command_outputs_are_each_muscles_physics_at_its_pressure() {
        let p = Parameters {
            preset: 5,
            strand_rigidity: 324.2,
            moment_arm: 3.421e-3,
            flexor_rest_length: 0.2581,
            extensor_rest_length: 0.2665,
            common_mode_pressure: 0.0,
            max_pressure: 5.62e7,
            command_mode: 1,
            ..Default::default()
        };
        let mut j = joint(&p);
        let q = -4.319;
        let lengths = [
            p.flexor_rest_length - p.moment_arm * q,
            p.extensor_rest_length + p.moment_arm * q,
        ];
        let (k_s, rest) = (j.strand_stiffness, j.flexor_friction);
        assert!(j.muscle.strand_point(0.0, lengths[0], k_s, &rest).is_some());
        for command in [0.01689, 0.05, -0.01689] {
            let (out, _) = at(&mut j, command, q);
            let pressures = [out.flexor_pressure, out.extensor_pressure];
            assert!(pressures.contains(&0.0), "{command}: {pressures:?}");
            let forces: Vec<f64> = [&j.flexor_friction, &j.extensor_friction]
                .iter()
                .enumerate()
                .map(|(i, history)| {
                    let (o, _) =
                        j.muscle
                            .evaluate_with_strands(pressures[i], lengths[i], k_s, history);
                    o.unwrap().force.max(0.0)
                })
                .collect();
            assert_eq!([out.flexor_force, out.extensor_force], forces[..]);
            assert!(!out.torque_saturated, "{command}");
            assert!(
                (out.joint_torque - command).abs() < 1e-9 * command.abs(),
                "{command}: {}",
                out.joint_torque
            );
        }
    }
}
