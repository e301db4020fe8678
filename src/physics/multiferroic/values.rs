//! The motor's inputs held over a step, its state (the history an FMU state carries), its
//! outputs at one instant, and what one step did.

use super::ScheduleSwitch;

/// Inputs held over a communication step.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotorInputs {
    /// Direction of the principal tension (rad), used when `schedule` is `None`.
    pub strain_direction: f64,
    /// `sigma11 - sigma22` (Pa), used when `schedule` is `None`.
    pub stress: f64,
    /// External torque on the rotor (N m), positive in the direction of increasing angle.
    pub load_torque: f64,
    /// Holds the rotor still (to measure static torque).
    pub rotor_locked: bool,
    /// Built-in stepping schedule; overrides `strain_direction` and `stress`.
    pub schedule: ScheduleSwitch,
}

impl MotorInputs {
    pub fn fixed(strain_direction: f64, stress: f64) -> Self {
        Self {
            strain_direction,
            stress,
            load_torque: 0.0,
            rotor_locked: false,
            schedule: ScheduleSwitch::OFF,
        }
    }
}

/// The coupled state: history of the motor (part of the FMU state).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotorState {
    /// s.
    pub time: f64,
    /// Direction of the bar's positive end (rad), unwrapped.
    pub rotor_angle: f64,
    /// rad/s.
    pub rotor_speed: f64,
    /// Direction of the ring's negative domain wall (rad), unwrapped.
    pub onion_angle: f64,
    /// Out-of-plane tilt of the onion magnetization (rad); zero in the quasi-static model.
    pub onion_tilt: f64,
    /// Last substep size (s), to start the next step's error control.
    pub substep_hint: f64,
}

impl MotorState {
    /// At rest at time 0 with the onion state aligned with the bar at `angle`.
    pub fn aligned(angle: f64) -> Self {
        Self {
            time: 0.0,
            rotor_angle: angle,
            rotor_speed: 0.0,
            onion_angle: angle,
            onion_tilt: 0.0,
            substep_hint: 0.0,
        }
    }
}

/// Everything observable at one instant.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotorOutputs {
    /// Torque of the ring on the bar, `dU_m/d beta` (N m).
    pub torque: f64,
    /// rad, unwrapped.
    pub rotor_angle: f64,
    /// rad/s.
    pub rotor_speed: f64,
    /// rad, unwrapped.
    pub onion_angle: f64,
    /// `psi - phi` wrapped to (-pi, pi] (rad).
    pub offset_angle: f64,
    /// Eq. 3.3 (J).
    pub magnetostatic_energy: f64,
    /// Eq. 3.4's magnetoelastic term over the walls (J).
    pub magnetoelastic_energy: f64,
    /// Direction of the principal tension in effect (rad).
    pub applied_strain_direction: f64,
    /// Stress in effect (Pa).
    pub applied_stress: f64,
}

/// What one call of [`Motor::step`](super::Motor::step) did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    pub outputs: MotorOutputs,
    /// Attempted substeps (accepted and rejected).
    pub substeps: u32,
    /// True when the substep budget or a failed substep forced steps beyond the tolerance, a
    /// slipping rotor was advanced by whole turns (their phase is not held to the tolerance), or
    /// the Gilbert onion's dynamics carry the substeps' errors far beyond the tolerance
    /// (`amplification.rs`).
    pub accuracy_limited: bool,
}
