//! MultiferroicMotor FMU: strain direction and stress on the nickel ring in, torque and rotor angle
//! of the bar magnet out (dissertation chapter 3, eq. 3.1-3.4).
//!
//! The physics, its integrator and its history live in [`crate::physics::multiferroic`]; this file
//! maps the variables onto [`MotorParams`] and [`MotorInputs`] and keeps the [`MotorState`], which
//! is serialized with the FMU state.

use super::{EventUpdate, Model, Partials, Refusal, Report, Status};
use crate::physics::multiferroic::model_exchange::{by, MeGradient, MePartials};
use crate::physics::multiferroic::{
    drive, Motor, MotorInputs, MotorOutputs, MotorParams, MotorState, OnionModel, ScheduleSwitch,
    SteppingSchedule, GILBERT_SUBSTEP_WEIGHT,
};
use crate::variables::multiferroic_motor::{
    AppliedStrainDirectionBy, CalculatedParameters, Inputs, Known, MagnetoelasticEnergyBy,
    MagnetostaticEnergyBy, OffsetAngleBy, OnionAngleBy, Outputs, Parameters, RotorAngleBy,
    RotorSpeedBy, States, TorqueBy, Variables,
};
use crate::variables::Row as _;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MultiferroicMotor {
    motor: Motor,
    /// The built-in stepping schedule when `schedule = 1`.
    schedule: ScheduleSwitch,
    rotor_locked: bool,
    /// Young's modulus (Pa) when `strain_drive`: the `strain` input times it is the stress.
    strain_drive: Option<f64>,
    state: MotorState,
    /// Largest magnitude of the ring's torque on the bar (N m), for [`Self::implausible`].
    max_torque: f64,
    /// Model Exchange's discrete states (see [`model_exchange`]).
    me: model_exchange::Discrete,
}

mod model_exchange;

impl MultiferroicMotor {
    fn inputs(&self, inputs: &Inputs) -> MotorInputs {
        // An unrepresentable strain gives a NaN stress, which the physics refuses with a reason.
        let stress = match self.strain_drive {
            Some(modulus) => drive::uniaxial_stress(inputs.strain, modulus).unwrap_or(f64::NAN),
            None => inputs.stress,
        };
        MotorInputs {
            strain_direction: inputs.strain_direction,
            stress,
            load_torque: inputs.load_torque,
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

fn write_outputs(out: &mut Outputs, o: &MotorOutputs) {
    // The physics never returns non-finite outputs; this guard keeps that promise at the ABI
    // even if it ever did (the old value stays).
    let set = |slot: &mut f64, value: f64| {
        if value.is_finite() {
            *slot = value;
        }
    };
    set(&mut out.torque, o.torque);
    set(&mut out.rotor_angle, o.rotor_angle);
    set(&mut out.rotor_speed, o.rotor_speed);
    set(&mut out.onion_angle, o.onion_angle);
    set(&mut out.offset_angle, o.offset_angle);
    set(&mut out.magnetostatic_energy, o.magnetostatic_energy);
    set(&mut out.magnetoelastic_energy, o.magnetoelastic_energy);
    set(
        &mut out.applied_strain_direction,
        o.applied_strain_direction,
    );
}

/// The rows of `fmi2GetDirectionalDerivative` from the physics' partials: by each input (and, in
/// Model Exchange, `with_states`, by each state), of the outputs. With `strain_drive` the stress
/// comes from the `strain` input.
fn partial_rows(
    p: &MePartials,
    strain_modulus: Option<f64>,
    with_states: bool,
    rows: &mut Partials<Variables>,
) {
    let of = |g| move |known| column(g, known, strain_modulus, with_states);
    rows.row(TorqueBy::from_fn(of(&p.torque)))
        .row(RotorAngleBy::from_fn(of(&p.rotor_angle)))
        .row(RotorSpeedBy::from_fn(of(&p.rotor_speed)))
        .row(OnionAngleBy::from_fn(of(&p.onion_angle)))
        .row(OffsetAngleBy::from_fn(of(&p.offset_angle)))
        .row(MagnetostaticEnergyBy::from_fn(of(&p.magnetostatic_energy)))
        .row(MagnetoelasticEnergyBy::from_fn(
            of(&p.magnetoelastic_energy),
        ))
        .row(AppliedStrainDirectionBy::from_fn(of(
            &p.applied_strain_direction
        )));
}

/// The partial by `known` in the physics' gradient `g` (see [`partial_rows`]): a row takes those
/// of the knowns its unknown declares, whose partials are the only ones that may be nonzero.
fn column(g: &MeGradient, known: Known, strain_modulus: Option<f64>, with_states: bool) -> f64 {
    let state = |i: usize| if with_states { g[i] } else { 0.0 };
    match known {
        Known::StrainDirection => g[by::STRAIN_DIRECTION],
        Known::LoadTorque => g[by::LOAD_TORQUE],
        Known::Stress if strain_modulus.is_none() => g[by::STRESS],
        Known::Stress => 0.0,
        Known::Strain => strain_modulus.map_or(0.0, |modulus| modulus * g[by::STRESS]),
        Known::RotorAngle => state(by::ROTOR_ANGLE),
        Known::RotorSpeed => state(by::ROTOR_SPEED),
        Known::OnionStateAngle => state(by::ONION_ANGLE),
        Known::OnionTilt => state(by::ONION_TILT),
    }
}

/// An Integer switch that must be 0 or 1 (the model description's bounds say so too).
fn switch(value: i32, name: &str) -> Result<bool, String> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(format!("{name} must be 0 or 1, got {other}")),
    }
}

impl Model for MultiferroicMotor {
    type Variables = Variables;
    const DOCUMENTATION: &'static str = include_str!("multiferroic_motor.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        let validate = if saved.model_exchange_active() {
            Motor::me_validate_state
        } else {
            Motor::validate_state
        };
        validate(&saved.state).map_err(|e| format!("motor state: {e}"))?;
        self.state = saved.state;
        self.me = saved.me.validated()?;
        Ok(())
    }

    fn new(r: &Parameters, _: &Inputs) -> Result<Self, Refusal> {
        let max_substeps = u32::try_from(r.max_substeps)
            .map_err(|_| format!("max_substeps must be positive, got {}", r.max_substeps))?;
        let params = MotorParams {
            ring_outer_diameter: r.ring_outer_diameter,
            ring_inner_diameter: r.ring_inner_diameter,
            bar_length: r.bar_length,
            bar_width: r.bar_width,
            thickness: r.thickness,
            saturation_magnetization: r.saturation_magnetization,
            magnetostriction: r.magnetostriction,
            wall_volume: r.wall_volume,
            density: r.density,
            fluid_viscosity: r.fluid_viscosity,
            gilbert_damping: r.gilbert_damping,
            onion_model: if switch(r.onion_model, "onion_model")? {
                OnionModel::Gilbert
            } else {
                OnionModel::QuasiStatic
            },
            tolerance: r.tolerance,
            max_substeps,
        };
        // The schedule is validated here even when unused, so that a bad one fails
        // initialization rather than a later step.
        let stepping = SteppingSchedule::new(
            r.schedule_initial_direction,
            r.step_angle,
            r.step_period,
            r.stress_amplitude,
        )?;
        let schedule = ScheduleSwitch::new(switch(r.schedule, "schedule")?, stepping);
        let strain_drive = if r.strain_drive {
            drive::uniaxial_stress(0.0, r.youngs_modulus)?;
            Some(r.youngs_modulus)
        } else {
            None
        };
        let offset = r.initial_onion_offset;
        if !(offset.is_finite() && offset.abs() <= 1e3) {
            return Err(format!(
                "initial_onion_offset must be finite and within 1e3 rad, got {offset}"
            )
            .into());
        }
        let motor = Motor::new(params)?;
        Ok(Self {
            schedule,
            rotor_locked: r.rotor_locked,
            strain_drive,
            // The rotor starts at rest at angle 0, the onion state `initial_onion_offset` from
            // alignment with it (the quasi-static one settles downhill at the first evaluation).
            state: MotorState {
                onion_angle: offset,
                ..MotorState::aligned(0.0)
            },
            max_torque: motor.ring_bar.max_torque().1.abs(),
            motor,
            me: model_exchange::Discrete::default(),
        })
    }

    fn calculated_parameters(&self) -> CalculatedParameters {
        let motor = &self.motor;
        CalculatedParameters {
            inertia: motor.inertia,
            drag: motor.drag,
            bar_mass: motor.bar_mass,
            undamped_frequency: 2.0 * std::f64::consts::PI * motor.undamped_frequency(),
            relaxation_time: motor.rotor_relaxation_time(),
        }
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        if self.model_exchange_active() {
            // Between events the onion stays on its branch (Model Exchange never jumps it here).
            return self.me_outputs(inputs, outputs, report);
        }
        match self.motor.outputs(&self.state, &self.inputs(inputs)) {
            Ok(o) => write_outputs(outputs, &o),
            // Unreachable with inputs inside their declared bounds; the outputs keep their values.
            Err(e) => report.add(Status::Error, format!("cannot evaluate the motor: {e}")),
        }
    }

    const MODEL_EXCHANGE: bool = true;

    fn states(&self) -> States {
        let x = self.me_states();
        States {
            rotor_angle: x[0],
            rotor_speed: x[1],
            onion_state_angle: x[2],
            onion_tilt: x[3],
        }
    }

    fn set_states(&mut self, x: &States) -> Result<(), String> {
        self.me_set_states(&[
            x.rotor_angle,
            x.rotor_speed,
            x.onion_state_angle,
            x.onion_tilt,
        ])
    }

    fn set_time(&mut self, time: f64) {
        self.state.time = time;
    }

    fn derivatives(&mut self, inputs: &Inputs) -> Result<States, String> {
        let d = self.me_derivatives(inputs)?;
        Ok(States {
            rotor_angle: d[0],
            rotor_speed: d[1],
            onion_state_angle: d[2],
            onion_tilt: d[3],
        })
    }

    /// The quasi-static onion's fold (see [`model_exchange`]).
    fn event_indicators(&mut self, inputs: &Inputs, out: &mut [f64]) -> Result<(), String> {
        let z = self.me_event_indicators(inputs)?;
        out.iter_mut().zip(z).for_each(|(slot, z)| *slot = z);
        Ok(())
    }

    /// Model Exchange: the schedule's next switch or the Gilbert onion's window end (from its
    /// own event clock). Co-Simulation (FMI 3.0 event mode): the schedule's next switch after
    /// `time`; the steps integrate through the ringing on their own.
    fn next_time_event(&self, time: f64) -> Option<f64> {
        if self.model_exchange_active() {
            self.me_next_time_event()
        } else {
            self.schedule.get().map(|s| s.next_switch_after(time))
        }
    }

    /// Event mode: the schedule's direction in effect, the quasi-static onion settled by the
    /// Co-Simulation rule (to the next minimum past a fold).
    fn update_discrete_states(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        time: f64,
        report: &mut Report,
    ) -> EventUpdate {
        let first = !self.model_exchange_active();
        match self.me_event(inputs, time) {
            Ok(states_changed) => {
                if first {
                    if let Some(why) = self.me_light_damping() {
                        report.warn(why);
                    }
                }
                self.me_outputs(inputs, outputs, report);
                EventUpdate {
                    states_changed,
                    ..EventUpdate::default()
                }
            }
            Err(e) => {
                report.add(Status::Error, format!("motor event at t = {time} s: {e}"));
                EventUpdate::default()
            }
        }
    }

    /// The onion's anchor moves along its branch; nothing jumps outside event mode.
    fn completed_integrator_step(
        &mut self,
        inputs: &Inputs,
        _outputs: &mut Outputs,
        time: f64,
        report: &mut Report,
    ) -> bool {
        self.state.time = time;
        if let Err(e) = self.me_completed_step(inputs) {
            report.add(Status::Error, format!("motor at t = {time} s: {e}"));
        }
        false
    }

    /// Co-Simulation: the outputs by the inputs at the current history, on the branch
    /// [`Model::evaluate`] takes (the quasi-static onion settled for the present inputs first, by
    /// the memory rule; then the implicit function theorem on its minimum). Model Exchange: also
    /// by the states, and the state derivatives, on the branch the onion follows.
    fn partials(&mut self, inputs: &Inputs, rows: &mut Partials<Variables>) -> Result<(), String> {
        if self.model_exchange_active() {
            return self.me_partials(inputs, rows);
        }
        let inputs = self.inputs(inputs);
        let outputs = self.motor.outputs(&self.state, &inputs)?;
        let settled = MotorState {
            onion_angle: outputs.onion_angle,
            ..self.state
        };
        let p = self.motor.me_partials(&settled, &inputs, settled.time)?;
        partial_rows(&p, self.strain_drive, false, rows);
        Ok(())
    }

    fn step(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        time: f64,
        step: f64,
        report: &mut Report,
    ) {
        let inputs = self.inputs(inputs);
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
                write_outputs(outputs, &r.outputs);
                // Every warning is logged: a master that sees fmi2Warning can always say why.
                if r.accuracy_limited {
                    report.warn(format!(
                        "the step from t = {time} s by {step} s was completed beyond tolerance \
                         = {} rad (its substep budget max_substeps = {} ran out, a Gilbert \
                         onion substep counting as {GILBERT_SUBSTEP_WEIGHT}, a slipping rotor \
                         was advanced by whole turns, or the Gilbert onion's dynamics amplify \
                         its substeps' errors far beyond the tolerance); shorten the step or \
                         raise max_substeps where this matters",
                        self.motor.params.tolerance, self.motor.params.max_substeps
                    ));
                }
            }
            Err(e) => report.add(
                Status::Discard,
                format!("step from t = {time} s by {step} s refused, state kept: {e}"),
            ),
        }
    }
}
