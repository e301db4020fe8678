//! MultiferroicMotor FMU: strain direction and stress on the nickel ring in, torque and rotor angle
//! of the bar magnet out (dissertation chapter 3, eq. 3.1-3.4).
//!
//! The physics, its integrator and its history live in [`crate::physics::multiferroic`]; this file
//! maps the variables onto [`MotorParams`] and [`MotorInputs`] and keeps the [`MotorState`], which
//! is serialized with the FMU state.

use super::{Model, Report, Status, Vars};
use crate::physics::multiferroic::{
    Motor, MotorInputs, MotorOutputs, MotorParams, MotorState, OnionModel, ScheduleSwitch,
    SteppingSchedule,
};
use crate::variables::multiferroic_motor::{boolean, integer, real, INFO};
use crate::variables::ModelInfo;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MultiferroicMotor {
    motor: Motor,
    /// The built-in stepping schedule when `schedule = 1`.
    schedule: ScheduleSwitch,
    rotor_locked: bool,
    state: MotorState,
    /// Largest magnitude of the ring's torque on the bar (N m), for [`Self::implausible`].
    max_torque: f64,
    /// Whether the accuracy warning was logged: it is logged once per run, later limited steps
    /// only return `fmi2Warning` (a 1 s step over thousands of switches is limited every time).
    accuracy_warned: bool,
}

impl MultiferroicMotor {
    fn inputs(&self, vars: &Vars) -> MotorInputs {
        MotorInputs {
            strain_direction: vars.real[real::STRAIN_DIRECTION],
            stress: vars.real[real::STRESS],
            load_torque: vars.real[real::LOAD_TORQUE],
            rotor_locked: self.rotor_locked,
            schedule: self.schedule,
        }
    }
}

impl MultiferroicMotor {
    /// Why a step's result is physically impossible, if it is. With drag `c`, `I w' = F - c w`
    /// and `|F| <= tau_max + |load|` keep `|w|` below `max(|w0|, (tau_max + |load|) / c)` at all
    /// times, so the rotor cannot turn further than that speed times the step. A result beyond
    /// (with a factor 1.5 of slack for the integrator's error) means the integration diverged:
    /// budget-limited substeps far longer than the relaxation time can do that.
    fn implausible(
        &self,
        before: &MotorState,
        after: &MotorState,
        inputs: &MotorInputs,
        step: f64,
    ) -> Option<String> {
        let drag = self.motor.drag;
        if inputs.rotor_locked || drag <= 0.0 {
            return None;
        }
        let speed = before
            .rotor_speed
            .abs()
            .max((self.max_torque + inputs.load_torque.abs()) / drag);
        let turn = after.rotor_angle - before.rotor_angle;
        let (turn_limit, speed_limit) = (1.5 * speed * step + 1e-12, 1.5 * speed);
        (turn.abs() > turn_limit || after.rotor_speed.abs() > speed_limit).then(|| {
            format!(
                "the integration diverged (rotor turned {turn:e} rad at up to {:e} rad/s where \
                 drag allows at most {turn_limit:e} rad and {speed_limit:e} rad/s): the step is too \
                 long for max_substeps = {}; shorten the step or raise max_substeps",
                after.rotor_speed, self.motor.params.max_substeps
            )
        })
    }
}

fn write_outputs(vars: &mut Vars, o: &MotorOutputs) {
    let values = [
        (real::TORQUE, o.torque),
        (real::ROTOR_ANGLE, o.rotor_angle),
        (real::ROTOR_SPEED, o.rotor_speed),
        (real::ONION_ANGLE, o.onion_angle),
        (real::OFFSET_ANGLE, o.offset_angle),
        (real::MAGNETOSTATIC_ENERGY, o.magnetostatic_energy),
        (real::MAGNETOELASTIC_ENERGY, o.magnetoelastic_energy),
        (real::APPLIED_STRAIN_DIRECTION, o.applied_strain_direction),
    ];
    // The physics never returns non-finite outputs; this guard keeps that promise at the ABI
    // even if it ever did (the old value stays).
    for (index, value) in values {
        if value.is_finite() {
            vars.real[index] = value;
        }
    }
}

/// An Integer switch that must be 0 or 1 (the model description's bounds say so too).
fn switch(vars: &Vars, index: usize, name: &str) -> Result<bool, String> {
    match vars.integer[index] {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(format!("{name} must be 0 or 1, got {other}")),
    }
}

impl Model for MultiferroicMotor {
    const INFO: &'static ModelInfo = &INFO;
    const DOCUMENTATION: &'static str = include_str!("multiferroic_motor.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        Motor::validate_state(&saved.state).map_err(|e| format!("motor state: {e}"))?;
        self.state = saved.state;
        self.accuracy_warned = saved.accuracy_warned;
        Ok(())
    }

    fn new(vars: &mut Vars) -> Result<Self, String> {
        let r = &vars.real;
        let max_substeps = u32::try_from(vars.integer[integer::MAX_SUBSTEPS]).map_err(|_| {
            format!(
                "max_substeps must be positive, got {}",
                vars.integer[integer::MAX_SUBSTEPS]
            )
        })?;
        let params = MotorParams {
            ring_outer_diameter: r[real::RING_OUTER_DIAMETER],
            ring_inner_diameter: r[real::RING_INNER_DIAMETER],
            bar_length: r[real::BAR_LENGTH],
            bar_width: r[real::BAR_WIDTH],
            thickness: r[real::THICKNESS],
            saturation_magnetization: r[real::SATURATION_MAGNETIZATION],
            magnetostriction: r[real::MAGNETOSTRICTION],
            wall_volume: r[real::WALL_VOLUME],
            density: r[real::DENSITY],
            fluid_viscosity: r[real::FLUID_VISCOSITY],
            gilbert_damping: r[real::GILBERT_DAMPING],
            onion_model: if switch(vars, integer::ONION_MODEL, "onion_model")? {
                OnionModel::Gilbert
            } else {
                OnionModel::QuasiStatic
            },
            tolerance: r[real::TOLERANCE],
            max_substeps,
        };
        // The schedule is validated here even when unused, so that a bad one fails
        // initialization rather than a later step.
        let stepping = SteppingSchedule::new(
            r[real::SCHEDULE_INITIAL_DIRECTION],
            r[real::STEP_ANGLE],
            r[real::STEP_PERIOD],
            r[real::STRESS_AMPLITUDE],
        )?;
        let schedule = ScheduleSwitch::new(switch(vars, integer::SCHEDULE, "schedule")?, stepping);
        let motor = Motor::new(params)?;
        vars.real[real::INERTIA] = motor.inertia;
        vars.real[real::DRAG] = motor.drag;
        vars.real[real::BAR_MASS] = motor.bar_mass;
        vars.real[real::UNDAMPED_FREQUENCY] =
            2.0 * std::f64::consts::PI * motor.undamped_frequency();
        vars.real[real::RELAXATION_TIME] = motor.rotor_relaxation_time();
        Ok(Self {
            schedule,
            rotor_locked: vars.boolean[boolean::ROTOR_LOCKED],
            // The rotor starts at rest with the onion state aligned with it, at angle 0.
            state: MotorState::aligned(0.0),
            max_torque: motor.ring_bar.max_torque().1.abs(),
            motor,
            accuracy_warned: false,
        })
    }

    fn evaluate(&mut self, vars: &mut Vars, report: &mut Report) {
        match self.motor.outputs(&self.state, &self.inputs(vars)) {
            Ok(o) => write_outputs(vars, &o),
            // Unreachable with inputs inside their declared bounds; the outputs keep their values.
            Err(e) => report.add(Status::Error, format!("cannot evaluate the motor: {e}")),
        }
    }

    fn step(&mut self, vars: &mut Vars, time: f64, step: f64, report: &mut Report) {
        let inputs = self.inputs(vars);
        // The importer's clock is the schedule's clock (they differ by rounding at most).
        let mut next = MotorState { time, ..self.state };
        let result = self.motor.step(&mut next, &inputs, step).and_then(|r| {
            match self.implausible(&self.state, &next, &inputs, step) {
                Some(why) => Err(why),
                None => Ok(r),
            }
        });
        match result {
            Ok(r) => {
                self.state = next;
                write_outputs(vars, &r.outputs);
                if r.accuracy_limited {
                    if self.accuracy_warned {
                        report.status = report.status.max(Status::Warning);
                    } else {
                        report.warn(format!(
                            "the step from t = {time} s by {step} s was completed beyond tolerance \
                             = {} rad (its substep budget max_substeps = {} ran out, or a slipping \
                             rotor or the Gilbert onion model was advanced over many periods at \
                             once); shorten the step or raise max_substeps where this matters \
                             (logged once per run)",
                            self.motor.params.tolerance, self.motor.params.max_substeps
                        ));
                        self.accuracy_warned = true;
                    }
                }
            }
            Err(e) => report.add(
                Status::Discard,
                format!("step from t = {time} s by {step} s refused, state kept: {e}"),
            ),
        }
    }
}
