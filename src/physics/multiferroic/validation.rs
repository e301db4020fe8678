//! The motor's inputs and states checked before a step: every value finite and within its
//! declared limit, a schedule's own parameters valid.

use super::{
    Motor, MotorInputs, MotorState, SteppingSchedule, MAX_ANGLE, MAX_LOAD_TORQUE, MAX_STEP,
    MAX_STRESS,
};

/// Inline with the message out of line: every step checks a dozen values.
#[inline]
pub(super) fn check_finite(name: &str, value: f64, limit: f64, unit: &str) -> Result<(), String> {
    if value.is_finite() && value.abs() <= limit {
        Ok(())
    } else {
        Err(not_finite(name, value, limit, unit))
    }
}

/// Each `(name, value, limit, unit)` finite and within its limit: on the usual path one test of
/// all of them (`abs() <= limit` is false for NaN), then [`check_finite`] names the first that
/// is not.
#[inline]
pub(super) fn within_limits(checks: &[(&str, f64, f64, &str)]) -> Result<(), String> {
    if checks
        .iter()
        .fold(true, |ok, &(_, v, limit, _)| ok & (v.abs() <= limit))
    {
        return Ok(());
    }
    checks
        .iter()
        .try_for_each(|&(name, v, limit, unit)| check_finite(name, v, limit, unit))
}

#[cold]
#[inline(never)]
fn not_finite(name: &str, value: f64, limit: f64, unit: &str) -> String {
    format!("{name} must be finite and within {limit:e} {unit}, got {value}")
}

impl Motor {
    pub(super) fn validate_inputs(&self, inputs: &MotorInputs) -> Result<(), String> {
        within_limits(&[
            (
                "strain_direction",
                inputs.strain_direction,
                MAX_ANGLE,
                "rad",
            ),
            ("stress", inputs.stress, MAX_STRESS, "Pa"),
            ("load_torque", inputs.load_torque, MAX_LOAD_TORQUE, "N m"),
        ])?;
        match inputs.schedule.get() {
            Some(s) if !s.is_valid() => SteppingSchedule::new(
                s.initial_direction,
                s.step_angle,
                s.step_period,
                s.stress_amplitude,
            )
            .map(|_| ()),
            _ => Ok(()),
        }
    }

    /// Why `state` is not one [`Motor::step`] can start from (non-finite or beyond its bounds).
    pub fn validate_state(state: &MotorState) -> Result<(), String> {
        within_limits(&[
            ("time", state.time, 1e12, "s"),
            ("rotor_angle", state.rotor_angle, MAX_ANGLE, "rad"),
            ("rotor_speed", state.rotor_speed, 1e30, "rad/s"),
            ("onion_angle", state.onion_angle, MAX_ANGLE, "rad"),
            ("onion_tilt", state.onion_tilt, 10.0, "rad"),
            ("substep_hint", state.substep_hint, MAX_STEP, "s"),
        ])
    }
}
