//! The motor's parameters (Table 3.1) and the bounds on its inputs.

use super::magnetics::{self, RingBar};

/// Largest accepted `|sigma11 - sigma22|` (Pa): far beyond any material's strength.
pub const MAX_STRESS: f64 = 1e12;
/// Largest accepted `|load_torque|` (N m): 1e12 times the motor's own torque.
pub const MAX_LOAD_TORQUE: f64 = 1e-6;
/// Largest accepted communication step (s).
pub const MAX_STEP: f64 = 1e3;
/// Largest accepted angle magnitude (rad), so that sines keep some precision.
pub const MAX_ANGLE: f64 = 1e12;

/// Nickel's isotropic saturation magnetostriction: lambda_s = -34e-6 (B. D. Cullity and
/// C. D. Graham, Introduction to Magnetic Materials, 2nd ed., Wiley 2009, Table 8.1 lists
/// lambda_s = -34 x 10^-6 for polycrystalline Ni).
pub const NICKEL_MAGNETOSTRICTION: f64 = -34e-6;
/// Nickel's density (kg/m^3), CRC Handbook of Chemistry and Physics.
pub const NICKEL_DENSITY: f64 = 8908.0;
/// Water's viscosity at 20 degrees C (Pa s), CRC Handbook.
pub const WATER_VISCOSITY: f64 = 1.0016e-3;

/// Fig. 3.3b calibration point: 200 MPa tension at -45 degrees holds the onion state 23 degrees
/// from the bar.
pub const CALIBRATION_STRESS: f64 = 200e6;
pub const CALIBRATION_DIRECTION_DEG: f64 = -45.0;
pub const CALIBRATION_OFFSET_DEG: f64 = 23.0;

/// How the onion state follows its torques.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum OnionModel {
    /// It sits at the minimum of eq. 3.4 reached downhill from where it was (section 3.2.2).
    QuasiStatic,
    /// It relaxes by the Landau-Lifshitz-Gilbert equation of a thin-film macrospin (see
    /// [`Motor::onion_relaxation_time`](super::Motor::onion_relaxation_time)).
    Gilbert,
}

/// Every geometric, material and numerical constant of the motor. SI units.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotorParams {
    pub ring_outer_diameter: f64,
    pub ring_inner_diameter: f64,
    pub bar_length: f64,
    pub bar_width: f64,
    /// Nickel thickness of ring and bar (m).
    pub thickness: f64,
    /// A/m.
    pub saturation_magnetization: f64,
    /// lambda_s (dimensionless; negative for nickel).
    pub magnetostriction: f64,
    /// Volume of the two domain walls over which eq. 3.4's integral runs (m^3); also the macrospin
    /// volume of the Gilbert option. See [`calibrated_wall_volume`].
    pub wall_volume: f64,
    /// Bar density (kg/m^3), for the rotor's inertia.
    pub density: f64,
    /// Viscosity of the fluid around the rotor (Pa s), for the rod drag.
    pub fluid_viscosity: f64,
    /// Gilbert damping alpha (Table 3.1: 0.045).
    pub gilbert_damping: f64,
    pub onion_model: OnionModel,
    /// Local error tolerance per substep on angles (rad); speeds are scaled by the undamped
    /// natural frequency. Smaller is more accurate and costs more substeps.
    pub tolerance: f64,
    /// Most attempted substeps per call of [`Motor::step`](super::Motor::step) (a settled
    /// interval counts as one, plus its march). When a step needs more, the minimum substep grows so that the
    /// budget still reaches the end of the step: accuracy degrades (reported in
    /// [`StepReport::accuracy_limited`](super::StepReport::accuracy_limited)) but the cost and
    /// stability do not. Substeps never span a schedule switch, so a step whose switches
    /// outnumber the budget and cannot be settled is refused. A substep of the Gilbert onion
    /// counts as [`GILBERT_SUBSTEP_WEIGHT`](super::GILBERT_SUBSTEP_WEIGHT) (its cost); the
    /// quasi-static onion's marches count one per four settles, a substep cut at an onion
    /// snap counts its bisection's substeps too, and the Gilbert onion's linear spans count one
    /// per two switches they chain (`onion_linear.rs`).
    pub max_substeps: u32,
}

/// Domain-wall volume for which the given geometry and magnetostriction reproduce Fig. 3.3b
/// (200 MPa at -45 degrees leaves the onion state at 23 degrees). About 3.05e-22 m^3 for Table 3.1:
/// two walls of 20 nm x 100 nm x 76 nm.
pub fn calibrated_wall_volume(params: &MotorParams) -> Result<f64, String> {
    let ring_bar = ring_bar_of(params)?;
    magnetics::calibrate_wall_volume(
        &ring_bar,
        params.magnetostriction,
        CALIBRATION_STRESS,
        CALIBRATION_DIRECTION_DEG.to_radians(),
        CALIBRATION_OFFSET_DEG.to_radians(),
    )
}

pub(super) fn ring_bar_of(p: &MotorParams) -> Result<RingBar, String> {
    RingBar::new(
        p.ring_outer_diameter,
        p.ring_inner_diameter,
        p.bar_length,
        p.bar_width,
        p.thickness,
        p.saturation_magnetization,
    )
}

/// The calibrated wall volume for Table 3.1 (checked against [`calibrated_wall_volume`] in tests).
pub const TABLE_3_1_WALL_VOLUME: f64 = 3.0433e-22;

impl MotorParams {
    /// Table 3.1: 700/500 nm ring, 350 x 100 nm bar, 20 nm nickel, damping 0.045, in water, with
    /// the wall volume calibrated to Fig. 3.3b.
    pub fn table_3_1() -> Self {
        let mut p = Self {
            ring_outer_diameter: 700e-9,
            ring_inner_diameter: 500e-9,
            bar_length: 350e-9,
            bar_width: 100e-9,
            thickness: 20e-9,
            saturation_magnetization: 485e3,
            magnetostriction: NICKEL_MAGNETOSTRICTION,
            wall_volume: TABLE_3_1_WALL_VOLUME,
            density: NICKEL_DENSITY,
            fluid_viscosity: WATER_VISCOSITY,
            gilbert_damping: 0.045,
            onion_model: OnionModel::QuasiStatic,
            tolerance: 1e-6,
            max_substeps: 20_000,
        };
        p.wall_volume = calibrated_wall_volume(&p).unwrap_or(TABLE_3_1_WALL_VOLUME);
        p
    }
}
