//! Multiferroic nano-motor (dissertation chapter 3): a magnetostrictive nickel ring in the onion
//! state around a bar magnet (the rotor). Stress on the ring turns the onion state (eq. 3.1, 3.4);
//! the misaligned onion state torques the bar (eq. 3.2, 3.3).
//!
//! State: rotor angle `phi` and speed `omega`, onion angle `psi` (direction of the ring's negative
//! domain wall; the ring's magnetization points the other way, antiparallel to the bar's), and in
//! the Gilbert option the onion magnetization's out-of-plane tilt `theta`. All angles are
//! unwrapped (continuous); the offset `beta = psi - phi` is reported wrapped to (-pi, pi].
//!
//! Rotor (section 3.2.2 with a viscous rotor): `I phi'' = tau_bar(beta) + tau_load - c phi'`.
//! With the Table 3.1 geometry, `I` ~ 6.9e-32 kg m^2, `c` ~ 3e-23 N m s and the alignment
//! stiffness ~ 1e-17 N m/rad: undamped ~ 2 MHz, inertial time `I/c` ~ 2 ns, relaxation `c/k`
//! ~ 3 us. The problem is stiff and strongly overdamped, and a communication step may be anything
//! from 1e-12 s to 1 s.
//!
//! Integration (see [`Motor::step`]): exponential Rosenbrock-Euler substeps. Each substep
//! linearizes the rotor (and in the Gilbert option the onion) about its start and advances that
//! linear system exactly with a matrix exponential, so the 2 ns inertial mode and the GHz onion
//! precession never limit the substep (no stiffness instability; the overdamped first-order limit
//! comes out by itself), while the quasi-static onion is re-solved at the end of every substep.
//! The method is second order; step doubling estimates the local error and sizes the next substep.
//! A budget of attempted substeps per call bounds the cost of a long step (see [`MotorParams::max_substeps`]).
//!
//! Long steps (issue 5): a substep far longer than the relaxation time is never integrated
//! through a negative (past-the-peak) stiffness, which would amplify by `exp(h |k| / c)`. Instead
//! a constant-drive interval long enough for the rotor to settle is advanced in the overdamped
//! limit to its equilibrium (the same downhill memory rule as the onion's), whole periods of the
//! schedule that repeat are advanced at once, and a slipping rotor advances by whole overdamped
//! turns; what is left is integrated, and a forced substep drops the negative stiffness so it
//! cannot amplify. See [`Motor::step`].

pub mod expm;
pub mod magnetics;
pub mod onion;
pub mod schedule;
#[cfg(test)]
mod tests;

use magnetics::{RingBar, GYROMAGNETIC_RATIO, MU0};
use onion::Landscape;
pub use schedule::{ScheduleSwitch, SteppingSchedule};
use std::f64::consts::PI;

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
    /// [`Motor::onion_relaxation_time`]).
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
    /// Most attempted substeps per call of [`Motor::step`] (a settled interval counts as one).
    /// When a step needs more, the minimum substep grows so that the budget still reaches the end
    /// of the step: accuracy degrades (reported in [`StepReport::accuracy_limited`]) but the cost
    /// and stability do not. Substeps never span a schedule switch, so a step whose switches
    /// outnumber the budget and cannot be settled is refused.
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

fn ring_bar_of(p: &MotorParams) -> Result<RingBar, String> {
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

/// The motor built from its parameters, with everything that depends only on them precomputed.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Motor {
    pub params: MotorParams,
    pub ring_bar: RingBar,
    /// `(3/2) lambda_s V_wall` (J/Pa): eq. 3.4's energy is this times stress times `sin^2`.
    pub magnetoelastic_per_stress: f64,
    /// kg.
    pub bar_mass: f64,
    /// kg m^2.
    pub inertia: f64,
    /// Rotational drag coefficient (N m s).
    pub drag: f64,
    /// `d tau_bar / d beta` at alignment (N m/rad).
    pub alignment_stiffness: f64,
    /// Speed scale for the error norm: the undamped natural angular frequency (rad/s).
    speed_scale: f64,
    /// `gamma / (Ms V (1 + alpha^2))` (1/(J s)), the Gilbert option's rate per unit torque.
    llg_rate: f64,
    /// `mu0 Ms^2 V_wall` (J): out-of-plane shape-anisotropy stiffness of the macrospin.
    tilt_stiffness: f64,
}

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

/// What one call of [`Motor::step`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    pub outputs: MotorOutputs,
    /// Attempted substeps (accepted and rejected).
    pub substeps: u32,
    /// True when the substep budget or a failed substep forced steps beyond the tolerance, or a
    /// slipping rotor was advanced by whole turns (their phase is not held to the tolerance).
    pub accuracy_limited: bool,
}

/// Strain, stress and load held over one substep.
#[derive(Clone, Copy, Debug)]
struct Drive {
    direction: f64,
    stress: f64,
    load: f64,
    locked: bool,
}

/// State vector of the integrator: rotor angle, rotor speed, onion angle, onion tilt.
type Vector = [f64; 4];

fn check_finite(name: &str, value: f64, limit: f64, unit: &str) -> Result<(), String> {
    if value.is_finite() && value.abs() <= limit {
        Ok(())
    } else {
        Err(format!(
            "{name} must be finite and within {limit:e} {unit}, got {value}"
        ))
    }
}

/// Wraps an angle to (-pi, pi].
pub fn wrap_angle(angle: f64) -> f64 {
    let w = angle - 2.0 * PI * (angle / (2.0 * PI)).round();
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

impl Motor {
    /// Validates the parameters and precomputes the charges, inertia, drag and rates.
    pub fn new(params: MotorParams) -> Result<Self, String> {
        let ring_bar = ring_bar_of(&params)?;
        let p = &params;
        check_finite("magnetostriction", p.magnetostriction, 1e-2, "")?;
        if !(p.wall_volume.is_finite() && p.wall_volume >= 0.0 && p.wall_volume < 1e-9) {
            return Err(format!(
                "wall_volume must be finite, non-negative and below 1e-9 m3, got {}",
                p.wall_volume
            ));
        }
        if p.onion_model == OnionModel::Gilbert && p.wall_volume == 0.0 {
            return Err(
                "wall_volume must be positive in the Gilbert onion model: it is the \
                        macrospin's volume"
                    .into(),
            );
        }
        if !(p.density.is_finite() && p.density > 0.0 && p.density < 1e6) {
            return Err(format!(
                "density must be positive and below 1e6 kg/m3, got {}",
                p.density
            ));
        }
        if !(p.fluid_viscosity.is_finite() && p.fluid_viscosity >= 0.0 && p.fluid_viscosity <= 1e9)
        {
            return Err(format!(
                "fluid_viscosity must be within [0, 1e9] Pa s, got {}",
                p.fluid_viscosity
            ));
        }
        if !(p.gilbert_damping.is_finite() && (0.0..=1e3).contains(&p.gilbert_damping)) {
            return Err(format!(
                "gilbert_damping must be within [0, 1000], got {}",
                p.gilbert_damping
            ));
        }
        if !(p.tolerance.is_finite() && (1e-12..=1.0).contains(&p.tolerance)) {
            return Err(format!(
                "tolerance must be within [1e-12, 1] rad, got {}",
                p.tolerance
            ));
        }
        if p.max_substeps == 0 || p.max_substeps > 100_000_000 {
            return Err(format!(
                "max_substeps must be within [1, 1e8], got {}",
                p.max_substeps
            ));
        }
        let (bar_mass, inertia) =
            magnetics::bar_mass_inertia(p.bar_length, p.bar_width, p.thickness, p.density);
        let drag = magnetics::rod_rotational_drag(
            p.fluid_viscosity,
            p.bar_length,
            magnetics::equivalent_rod_diameter(p.bar_width, p.thickness),
        );
        let alignment_stiffness = ring_bar.stiffness(0.0);
        let alpha = p.gilbert_damping;
        let ms = p.saturation_magnetization;
        let (llg_rate, tilt_stiffness) = if p.wall_volume > 0.0 {
            (
                GYROMAGNETIC_RATIO / (ms * p.wall_volume * (1.0 + alpha * alpha)),
                MU0 * ms * ms * p.wall_volume,
            )
        } else {
            (0.0, 0.0)
        };
        Ok(Self {
            magnetoelastic_per_stress: magnetics::magnetoelastic_coefficient(
                p.magnetostriction,
                p.wall_volume,
            ),
            bar_mass,
            inertia,
            drag,
            alignment_stiffness,
            speed_scale: (alignment_stiffness / inertia).sqrt(),
            llg_rate,
            tilt_stiffness,
            ring_bar,
            params,
        })
    }

    /// Natural frequency of the bar on the ring-bar spring with the onion held (Hz).
    pub fn undamped_frequency(&self) -> f64 {
        self.speed_scale / (2.0 * PI)
    }

    /// Overdamped relaxation time of the bar with the onion held, `c / k` (s).
    pub fn rotor_relaxation_time(&self) -> f64 {
        self.drag / self.alignment_stiffness
    }

    /// Inertial time `I / c` (s); infinite without drag.
    pub fn inertial_time(&self) -> f64 {
        if self.drag > 0.0 {
            self.inertia / self.drag
        } else {
            f64::INFINITY
        }
    }

    /// Decay time of the onion state's motion in the Gilbert option (s):
    /// `2 (1 + alpha^2) / (alpha gamma mu0 Ms)` (~0.41 ns for nickel), infinite without damping.
    ///
    /// The option treats the domain-wall magnetization as one macrospin of volume `V_wall` with
    /// in-plane angle `psi` and small out-of-plane tilt `theta`, whose energy is eq. 3.4 plus the
    /// thin film's shape anisotropy `mu0 Ms^2 V theta^2 / 2`. The LLG equation in these angles is
    /// `psi' = -g (mu0 Ms^2 V theta + alpha dU/dpsi)`, `theta' = g (dU/dpsi - alpha mu0 Ms^2 V theta)`
    /// with `g = gamma / (Ms V (1 + alpha^2))`: a damped precession (GHz for Table 3.1) whose
    /// envelope decays at `alpha gamma mu0 Ms / (2 (1 + alpha^2))` because the shape anisotropy
    /// dominates the in-plane stiffness. That is ~1e4 times faster than the rotor, which is why the
    /// quasi-static onion is the default.
    pub fn onion_relaxation_time(&self) -> f64 {
        let alpha = self.params.gilbert_damping;
        if alpha > 0.0 {
            2.0 * (1.0 + alpha * alpha)
                / (alpha * GYROMAGNETIC_RATIO * MU0 * self.params.saturation_magnetization)
        } else {
            f64::INFINITY
        }
    }

    /// Torque per volume of the motor's footprint, the disc under the ring's outer edge times the
    /// thickness (N m/m^3). With 2.0e-18 N m this volume reproduces the text's 260 N m/m^3.
    pub fn torque_density(&self, torque: f64) -> f64 {
        let r = 0.5 * self.params.ring_outer_diameter;
        torque / (PI * r * r * self.params.thickness)
    }

    /// Eq. 3.4's landscape for the onion state.
    pub fn landscape(&self, bar_angle: f64, strain_direction: f64, stress: f64) -> Landscape<'_> {
        Landscape {
            ring_bar: &self.ring_bar,
            bar_angle,
            strain_direction,
            magnetoelastic: self.magnetoelastic_per_stress * stress,
        }
    }

    fn validate_inputs(&self, inputs: &MotorInputs) -> Result<(), String> {
        check_finite(
            "strain_direction",
            inputs.strain_direction,
            MAX_ANGLE,
            "rad",
        )?;
        check_finite("stress", inputs.stress, MAX_STRESS, "Pa")?;
        check_finite("load_torque", inputs.load_torque, MAX_LOAD_TORQUE, "N m")?;
        if let Some(s) = inputs.schedule.get() {
            SteppingSchedule::new(
                s.initial_direction,
                s.step_angle,
                s.step_period,
                s.stress_amplitude,
            )?;
        }
        Ok(())
    }

    /// Why `state` is not one [`Motor::step`] can start from (non-finite or beyond its bounds).
    pub fn validate_state(state: &MotorState) -> Result<(), String> {
        check_finite("time", state.time, 1e12, "s")?;
        check_finite("rotor_angle", state.rotor_angle, MAX_ANGLE, "rad")?;
        check_finite("rotor_speed", state.rotor_speed, 1e30, "rad/s")?;
        check_finite("onion_angle", state.onion_angle, MAX_ANGLE, "rad")?;
        check_finite("onion_tilt", state.onion_tilt, 10.0, "rad")?;
        check_finite("substep_hint", state.substep_hint, MAX_STEP, "s")
    }

    fn drive_at(&self, inputs: &MotorInputs, time: f64) -> Drive {
        let (direction, stress) = match inputs.schedule.get() {
            Some(s) => (s.direction(time), s.stress_amplitude),
            None => (inputs.strain_direction, inputs.stress),
        };
        Drive {
            direction,
            stress,
            load: inputs.load_torque,
            locked: inputs.rotor_locked,
        }
    }

    fn quasi_static(&self) -> bool {
        self.params.onion_model == OnionModel::QuasiStatic
    }

    fn settle(&self, y: &Vector, d: &Drive) -> f64 {
        self.landscape(y[0], d.direction, d.stress).settle(y[2])
    }

    /// Outputs for the current state and inputs without advancing (in the quasi-static model the
    /// onion state is settled for the present inputs, starting from its stored orientation).
    pub fn outputs(
        &self,
        state: &MotorState,
        inputs: &MotorInputs,
    ) -> Result<MotorOutputs, String> {
        self.validate_inputs(inputs)?;
        Self::validate_state(state)?;
        let d = self.drive_at(inputs, state.time);
        let mut y = [
            state.rotor_angle,
            if d.locked { 0.0 } else { state.rotor_speed },
            state.onion_angle,
            state.onion_tilt,
        ];
        if self.quasi_static() {
            y[2] = self.settle(&y, &d);
        }
        Ok(self.outputs_at(&y, &d))
    }

    fn outputs_at(&self, y: &Vector, d: &Drive) -> MotorOutputs {
        let beta = y[2] - y[0];
        let s = (y[2] - d.direction).sin();
        MotorOutputs {
            torque: self.ring_bar.torque(beta),
            rotor_angle: y[0],
            rotor_speed: y[1],
            onion_angle: y[2],
            offset_angle: wrap_angle(beta),
            magnetostatic_energy: self.ring_bar.energy(beta),
            magnetoelastic_energy: self.magnetoelastic_per_stress * d.stress * s * s,
            applied_strain_direction: d.direction,
            applied_stress: d.stress,
        }
    }

    /// Right-hand side and Jacobian of the ODE in `(phi, omega, psi, theta)`, for a substep `dt`.
    ///
    /// Past the torque peak the rotor's linearized stiffness is negative and `exp(dt J)` grows
    /// like `exp(lambda dt)` with the unstable rate `lambda`. That growth is real only while the
    /// rotor stays near the linearization point; over a substep much longer than `1/lambda` (~ the
    /// relaxation time `c/|k|`) the rotor has long left the region and the true motion is bounded by
    /// the drag speed `|F|/c`. So when `lambda dt > 1` the negative stiffness is dropped (set to 0):
    /// the substep then drifts at most at the terminal speed of its starting force and cannot
    /// amplify. Such substeps are only ever taken when budget-forced (the error control rejects
    /// them otherwise: their half steps keep the stiffness and disagree), and they are flagged.
    fn rhs_jacobian(&self, y: &Vector, d: &Drive, dt: f64) -> (Vector, [[f64; 4]; 4]) {
        let mut f = [0.0; 4];
        let mut j = [[0.0; 4]; 4];
        let beta = y[2] - y[0];
        let tau = self.ring_bar.torque(beta);
        let k_bar = self.ring_bar.stiffness(beta);
        let e = self.magnetoelastic_per_stress * d.stress;
        let (s2, c2) = (2.0 * (y[2] - d.direction)).sin_cos();
        let k_me = 2.0 * e * c2;
        let quasi = self.quasi_static();
        if !d.locked {
            let (i, c) = (self.inertia, self.drag);
            f[0] = y[1];
            f[1] = (tau + d.load - c * y[1]) / i;
            j[0][1] = 1.0;
            j[1][1] = -c / i;
            if quasi {
                // Onion in equilibrium: bar spring in series with the magnetoelastic spring,
                // k = k_bar k_me / (k_bar + k_me) (implicit function theorem on dU/dpsi = 0).
                // Near a fold the sum vanishes; bound it so the linearization stays finite.
                let sum = (k_bar + k_me).max(0.05 * (k_bar.abs() + k_me.abs()));
                let k_eff = if sum > 0.0 { k_bar * k_me / sum } else { 0.0 };
                j[1][0] = -self.bounded_stiffness(k_eff, dt) / i;
            } else {
                let k = self.bounded_stiffness(k_bar, dt);
                j[1][0] = -k / i;
                j[1][2] = k / i;
            }
        }
        if !quasi {
            let (g, a, t) = (
                self.llg_rate,
                self.params.gilbert_damping,
                self.tilt_stiffness,
            );
            let grad = tau + e * s2;
            let (d_psi, d_phi) = (k_bar + k_me, -k_bar);
            f[2] = g * (-t * y[3] - a * grad);
            f[3] = g * (grad - a * t * y[3]);
            j[2][2] = -g * a * d_psi;
            j[2][3] = -g * t;
            j[3][2] = g * d_psi;
            j[3][3] = -g * a * t;
            if !d.locked {
                j[2][0] = -g * a * d_phi;
                j[3][0] = g * d_phi;
            }
        }
        (f, j)
    }

    /// The rotor stiffness `k` for the linearization over `dt`: unchanged unless it is negative
    /// and the unstable rate `lambda = (sqrt(c^2 - 4 I k) - c) / (2 I)` of `I x'' + c x' + k x = 0`
    /// times `dt` exceeds 1; then 0 (see [`Self::rhs_jacobian`]).
    fn bounded_stiffness(&self, k: f64, dt: f64) -> f64 {
        if k >= 0.0 {
            return k;
        }
        let (i, c) = (self.inertia, self.drag);
        let rate = ((c * c - 4.0 * i * k).sqrt() - c) / (2.0 * i);
        if rate * dt > 1.0 {
            0.0
        } else {
            k
        }
    }

    /// One exponential Rosenbrock-Euler substep: `y + dt phi1(dt J) f(y)`, computed as the last
    /// column of the exponential of the augmented matrix `dt [[J, f], [0, 0]]`. Exact for linear
    /// dynamics; the quasi-static onion is re-settled at the new rotor angle.
    fn exponential_step(&self, y: &Vector, dt: f64, d: &Drive) -> Option<Vector> {
        let (f, j) = self.rhs_jacobian(y, d, dt);
        let mut out = *y;
        if self.quasi_static() {
            // The onion rows are zero here (it is re-settled below), so the onion does not move
            // within the substep and the rotor block evolves alone: a 3x3 exponential of
            // (angle, speed, forcing) gives the same increments as the 5x5 one at a fifth of
            // the cost (the matrix products were 60% of a motor step).
            let mut m = [[0.0; 3]; 3];
            for i in 0..2 {
                m[i][0] = dt * j[i][0];
                m[i][1] = dt * j[i][1];
                m[i][2] = dt * f[i];
            }
            let e = expm::expm(&m)?;
            out[0] += e[0][2];
            out[1] += e[1][2];
        } else {
            let mut m = [[0.0; expm::N]; expm::N];
            for i in 0..4 {
                for k in 0..4 {
                    m[i][k] = dt * j[i][k];
                }
                m[i][4] = dt * f[i];
            }
            let e = expm::expm(&m)?;
            for (i, x) in out.iter_mut().enumerate() {
                *x += e[i][4];
            }
        }
        if d.locked {
            out[0] = y[0];
            out[1] = 0.0;
        }
        if self.quasi_static() {
            out[2] = self.settle(&out, d);
            out[3] = 0.0;
        }
        let sane = out[0].abs() <= MAX_ANGLE && out[2].abs() <= MAX_ANGLE && out[3].abs() <= 10.0;
        (out.iter().all(|x| x.is_finite()) && sane).then_some(out)
    }

    /// Force on the rotor at `phi` with the onion settled at `psi`, `F = tau_bar + load`, and its
    /// reduced stiffness `k = -dF/dphi` (the bar spring in series with the magnetoelastic one,
    /// bounded near a fold as in [`Self::rhs_jacobian`]).
    fn rotor_force(&self, phi: f64, psi: f64, d: &Drive) -> (f64, f64) {
        let beta = psi - phi;
        let k_bar = self.ring_bar.stiffness(beta);
        let k_me =
            2.0 * self.magnetoelastic_per_stress * d.stress * (2.0 * (psi - d.direction)).cos();
        let sum = (k_bar + k_me).max(0.05 * (k_bar.abs() + k_me.abs()));
        let k = if sum > 0.0 { k_bar * k_me / sum } else { 0.0 };
        (self.ring_bar.torque(beta) + d.load, k)
    }

    /// The rotor after `available` seconds at constant drive, in the overdamped limit, when by
    /// then it has come within [`MAX_SETTLE_RESIDUAL`] of its equilibrium; `None` when it has not
    /// or that limit does not apply (locked rotor, Gilbert onion, no drag, a fast initial speed,
    /// a rotor that slips without end, or a degenerate equilibrium).
    ///
    /// The rotor is strongly overdamped (`I/c` ~ 2 ns against `c/k` ~ 3 us), so after its speed's
    /// initial layer (`omega I / c` of coasting, a few `I/c`) it moves as `c phi' = F(phi)`, a
    /// gradient flow: it goes downhill from where it is and stops at the first zero of `F`, i.e.
    /// the same memory rule as the onion's, with the onion re-settled (memory and folds included)
    /// at every point of the path. The march follows `F` in strides that change `F` by at most a
    /// quarter (and at most [`MAX_ROTOR_STRIDE`]) and adds up the travel time `int c / |F| dphi`
    /// (trapezoid in `1/F`). Once the root is bracketed, the rest is the linear exponential
    /// approach: the distance `d` left decays as `d exp(-k t / c)` with the stiffness `k` at the
    /// root, which gives the end state and speed (an error of `delta` in the travel time moves the
    /// end by `residual k delta / c`, below the tolerance for the residuals allowed). A fold that flips the force's sign (the onion jumps) turns the
    /// rotor back and the march goes on from the jumped state. Hand-written for the hot path:
    /// every loop is capped.
    fn settle_rotor(&self, y: &Vector, d: &Drive, available: f64) -> Option<Vector> {
        let (i, c) = (self.inertia, self.drag);
        if d.locked || !self.quasi_static() || c <= 0.0 {
            return None;
        }
        let coast = y[1] * i / c;
        if coast.abs() > MAX_ROTOR_STRIDE {
            return None;
        }
        let eps = 1e-2 * self.params.tolerance;
        // Torque scale (N m): the alignment stiffness times one radian, plus the load.
        let force_scale = self.alignment_stiffness.abs() + d.load.abs();
        let continuous = 1e-6 * force_scale;
        let mut phi = y[0] + coast;
        let mut psi = self.landscape(phi, d.direction, d.stress).settle(y[2]);
        // The initial layer: the speed has decayed by e^-20 after 20 I/c.
        let mut time = 20.0 * i / c;
        let mut travelled = 0.0;
        let mut turnarounds = 0;
        for _ in 0..MAX_ROTOR_MARCH {
            let (force, k) = self.rotor_force(phi, psi, d);
            if force == 0.0 && k > 0.0 {
                return (time < available).then_some([phi, 0.0, psi, 0.0]);
            }
            let dir = force.signum();
            let stride = if k > 0.0 && force.abs() <= k * MAX_ROTOR_STRIDE {
                // Near the root: aim past it to bracket it.
                (1.5 * force.abs() / k).max(eps)
            } else if k != 0.0 {
                crate::physics::bounds::limit(0.25 * force.abs() / k.abs(), eps, MAX_ROTOR_STRIDE)
            } else {
                MAX_ROTOR_STRIDE
            };
            let next_phi = phi + dir * stride;
            let next_psi = self.landscape(next_phi, d.direction, d.stress).settle(psi);
            let (next_force, _) = self.rotor_force(next_phi, next_psi, d);
            if dir * next_force > 0.0 {
                time += 0.5 * c * stride * (1.0 / force.abs() + 1.0 / next_force.abs());
                travelled += stride;
                if travelled > MAX_ROTOR_TRAVEL {
                    return None; // slipping: no equilibrium ahead
                }
                phi = next_phi;
                psi = next_psi;
                continue;
            }
            // The force changed sign within the stride: refine by false position (Illinois),
            // the onion settled from the near side each time.
            let (mut lo, mut hi) = (phi, next_phi);
            let (mut f_lo, mut f_hi) = (force, next_force);
            let (mut psi_hi, mut psi_root, mut f_root) = (next_psi, psi, force);
            let mut root = phi;
            for _ in 0..MAX_ROOT_STEPS {
                let mut x = hi - f_hi * (hi - lo) / (f_hi - f_lo);
                let width = (hi - lo).abs();
                if !(x - lo).is_finite()
                    || (x - lo).abs() < 0.01 * width
                    || (hi - x).abs() < 0.01 * width
                {
                    x = 0.5 * (lo + hi);
                }
                let x_psi = self.landscape(x, d.direction, d.stress).settle(psi);
                let (fx, _) = self.rotor_force(x, x_psi, d);
                root = x;
                psi_root = x_psi;
                f_root = fx;
                if fx.abs() <= 1e-14 * force_scale {
                    break;
                }
                if fx * f_lo > 0.0 {
                    lo = x;
                    f_lo = fx;
                    f_hi *= 0.5;
                } else {
                    hi = x;
                    f_hi = fx;
                    psi_hi = x_psi;
                    f_lo *= 0.5;
                }
                if (hi - lo).abs() <= 1e-15 * (1.0 + x.abs()) {
                    break;
                }
            }
            if f_root.abs() <= continuous {
                let (_, k_root) = self.rotor_force(root, psi_root, d);
                if k_root <= 0.0 {
                    return None; // tangential equilibrium: no exponential approach
                }
                // The last stretch, from `phi` at `time`, is the linear exponential approach.
                let rate = k_root / c;
                let residual = (root - phi).abs() * (-(available - time) * rate).exp();
                if !(time < available && residual <= MAX_SETTLE_RESIDUAL) {
                    return None;
                }
                let end = root + (phi - root).signum() * residual;
                let end_psi = self.landscape(end, d.direction, d.stress).settle(psi_root);
                let speed = (root - end) * rate;
                return Some([end, speed, end_psi, 0.0]);
            }
            // A jump of the onion flipped the force: the rotor turns back from the fold.
            turnarounds += 1;
            if turnarounds > MAX_TURNAROUNDS {
                return None;
            }
            let reached = (hi - phi).abs();
            time += c * reached / force.abs();
            travelled += reached;
            phi = hi;
            psi = psi_hi;
        }
        None
    }

    /// Time for one turn (2 pi) of a rotor that slips (its force never vanishes) from `phi`, in
    /// the overdamped limit, and the onion angle after it; `None` if the force vanishes on the
    /// way. `int c / |F| dphi` by Simpson's rule on strides that change `F` by at most a quarter;
    /// a stride over which the onion jumps (a fold: `F` is discontinuous there) is halved down to
    /// 1e-7 rad, so the jump costs no accuracy. The first inertial correction to the turn time is
    /// `(I/c) [ln F]` over the turn, which vanishes on a periodic orbit; the next is of order
    /// `(I k / c^2)^2` ~ 1e-6.
    fn slip_turn(&self, phi0: f64, psi0: f64, d: &Drive) -> Option<(f64, f64)> {
        let c = self.drag;
        let (f0, _) = self.rotor_force(phi0, psi0, d);
        if f0 == 0.0 {
            return None;
        }
        let dir = f0.signum();
        let target = phi0 + dir * 2.0 * PI;
        let (mut phi, mut psi, mut force) = (phi0, psi0, f0);
        let mut stride = MAX_ROTOR_STRIDE;
        let mut time = 0.0;
        let settle = |at: f64, from: f64| self.landscape(at, d.direction, d.stress).settle(from);
        for _ in 0..MAX_SLIP_STRIDES {
            let left = dir * (target - phi);
            if left <= 0.0 {
                return Some((time, psi));
            }
            let h = stride.min(left);
            let mid = phi + 0.5 * dir * h;
            let end = if h == left { target } else { phi + dir * h };
            let psi_mid = settle(mid, psi);
            let psi_end = settle(end, psi_mid);
            let (f_mid, _) = self.rotor_force(mid, psi_mid, d);
            let (f_end, k_end) = self.rotor_force(end, psi_end, d);
            if dir * f_mid <= 0.0 || dir * f_end <= 0.0 {
                return None;
            }
            // A jump moves the onion by tenths of a radian; the continuous branch moves by
            // its slope times the stride, which grows without bound only right at a fold.
            let jump = (5.0 * h).max(1e-3);
            if ((psi_mid - psi).abs() > jump || (psi_end - psi_mid).abs() > jump) && h > 1e-7 {
                stride = 0.5 * h;
                continue;
            }
            time += c * h / 6.0 * (1.0 / force.abs() + 4.0 / f_mid.abs() + 1.0 / f_end.abs());
            phi = end;
            psi = psi_end;
            force = f_end;
            let smooth = if k_end != 0.0 {
                0.25 * force.abs() / k_end.abs()
            } else {
                MAX_ROTOR_STRIDE
            };
            stride = (2.0 * h).min(smooth).clamp(1e-7, MAX_ROTOR_STRIDE);
        }
        None
    }

    /// A slipping rotor over `available` seconds at constant drive: one overdamped turn from the
    /// present state (its start shifted by the speed's coast `omega I / c`), then, when a second
    /// turn repeats it (onion back to the same place modulo 2 pi within `tolerance / 1000`), as
    /// many more such turns as fit while leaving at least one turn of the interval to the error-
    /// controlled integrator. Returns the time advanced and the state; `None` if the rotor does
    /// not slip or too little time is left.
    fn slip_turns(&self, y: &Vector, d: &Drive, available: f64) -> Option<(f64, Vector)> {
        let (i, c) = (self.inertia, self.drag);
        if d.locked || !self.quasi_static() || c <= 0.0 {
            return None;
        }
        let coast = y[1] * i / c;
        if coast.abs() > MAX_ROTOR_STRIDE {
            return None;
        }
        let phi0 = y[0] + coast;
        let psi0 = self.landscape(phi0, d.direction, d.stress).settle(y[2]);
        let (first, psi1) = self.slip_turn(phi0, psi0, d)?;
        let (f0, _) = self.rotor_force(phi0, psi0, d);
        let turn = f0.signum() * 2.0 * PI;
        let (period, psi2) = self.slip_turn(phi0 + turn, psi1, d)?;
        let onion_turn = psi2 - psi1;
        let winding = (onion_turn / (2.0 * PI)).round() * 2.0 * PI;
        if (onion_turn - winding).abs() > 1e-3 * self.params.tolerance || period <= 0.0 {
            return None;
        }
        // Turns after the first, leaving at least one period for the integrator.
        let repeats = ((available - first) / period).floor() - 1.0;
        if !(1.0..1e12).contains(&repeats) {
            return None;
        }
        let phi = phi0 + turn * (1.0 + repeats);
        let psi = psi1 + winding * repeats;
        let (force, _) = self.rotor_force(phi, psi, d);
        Some((first + repeats * period, [phi, force / c, psi, 0.0]))
    }

    /// Step doubling: returns the two-half-step result and its error relative to the tolerance.
    fn doubled_step(&self, y: &Vector, dt: f64, d: &Drive) -> Option<(Vector, f64)> {
        let full = self.exponential_step(y, dt, d)?;
        let mid = self.exponential_step(y, 0.5 * dt, d)?;
        let two = self.exponential_step(&mid, 0.5 * dt, d)?;
        let tol = self.params.tolerance;
        let scales = [tol, tol * self.speed_scale, tol, tol];
        let err = (0..4)
            .map(|i| (two[i] - full[i]).abs() / scales[i])
            .fold(0.0, f64::max);
        Some((two, err))
    }

    /// Advances `state` by `h` seconds with `inputs` held (the schedule, if any, switching inside
    /// the step) and returns the outputs at the end. On `Err` the state is untouched.
    ///
    /// The step is cut at every switch of the schedule (no substep ever spans one), and each
    /// piece of constant drive (a "segment") is advanced by one of:
    /// - the overdamped settle ([`Self::settle_rotor`]) when the segment is longer than 10 rotor
    ///   relaxation times and the rotor ends it within [`MAX_SETTLE_RESIDUAL`] of its
    ///   equilibrium, on the exponential tail (agrees with resolved integration within 3e-7 rad
    ///   for the default schedule), at the cost of one substep;
    /// - otherwise exponential substeps sized by the step-doubling error estimate (growth and
    ///   shrink at most 5x per substep). The minimum substep is `remaining time / remaining
    ///   budget`; a substep at that minimum is accepted even if its error exceeds the tolerance
    ///   (flagged), and cannot amplify (see [`Self::rhs_jacobian`]);
    /// - a slipping rotor (no equilibrium ahead) advances by whole overdamped turns
    ///   ([`Self::slip_turns`], flagged).
    ///
    /// Each segment may use at most 1/16 of the substeps left. With the stepping schedule, once
    /// three consecutive whole periods have ended in the same state relative to the strain
    /// direction (within `tolerance / 100` and then `tolerance / 1000`), every later whole period
    /// repeats the last one turned by `step_angle` (the equations are invariant under a common
    /// rotation of rotor, onion and strain), so those periods are advanced at once. This covers
    /// periods that let the rotor settle and faster ones where it turns continuously on a
    /// periodic orbit. Hence what "accurate" means for a long step: the state at its end, and at
    /// every switch inside it, is the resolved trajectory's within the tolerance; the transients
    /// inside it are not reported.
    ///
    /// Costs (release): a 1 s step of a steady rotor takes one settle; a 1 s step over the
    /// 10 000 switches of the default schedule a few settles (~0.1 ms); with 25-60 us periods a
    /// few hundred to two thousand substeps (~6 ms). A step whose switches outnumber the budget
    /// and never repeat (a schedule too fast for the rotor, which loses steps) is refused.
    pub fn step(
        &self,
        state: &mut MotorState,
        inputs: &MotorInputs,
        h: f64,
    ) -> Result<StepReport, String> {
        self.validate_inputs(inputs)?;
        Self::validate_state(state)?;
        if !(h.is_finite() && h > 0.0 && h <= MAX_STEP) {
            return Err(format!(
                "communication step must be positive and at most {MAX_STEP} s, got {h}"
            ));
        }
        let t_start = state.time;
        let t_end = t_start + h;
        let budget = self.params.max_substeps;
        let mut y: Vector = [
            state.rotor_angle,
            state.rotor_speed,
            state.onion_angle,
            state.onion_tilt,
        ];
        let mut t = t_start;
        let mut attempts = 0u32;
        let mut limited = false;
        let mut dt = if state.substep_hint > 0.0 {
            state.substep_hint
        } else {
            1e-10
        };
        // The segment whose settle was tried.
        let mut settle_tried_for = f64::NAN;
        // The segment in progress: its end, strain direction, and whether it began at a switch
        // (a whole period of the schedule).
        let (mut segment_end_prev, mut segment_direction, mut whole_period) =
            (f64::NAN, 0.0, false);
        // The state at the end of the last whole period relative to its strain direction
        // (rotor, onion, speed) and how far it was from the one before (rad).
        let mut period_end: Option<[f64; 3]> = None;
        let mut period_mismatch = f64::INFINITY;
        let long_segment = 10.0 * self.rotor_relaxation_time();
        // Each pass accepts a substep, counts a rejected attempt, settles a segment or jumps over
        // repeated periods; the minimum substep reaches the segment's end once the budget is
        // spent, so the cap ends the loop early only when the switches outnumber the budget.
        for _ in 0..(2 * budget as u64 + 16) {
            if t >= t_end {
                break;
            }
            if let (Some(s), true) = (inputs.schedule.get(), t == segment_end_prev) {
                // A switch reached. The equations are invariant under a common rotation of rotor,
                // onion and strain, so once whole periods end in the same relative state, every
                // later period repeats the last one turned by step_angle. Required: three
                // period ends within tolerance / 100 and then tolerance / 1000 of each other,
                // i.e. the period map has converged onto its fixed point (a settled end state,
                // or the rotor's periodic orbit) and contracts towards it.
                let relative = [
                    y[0] - segment_direction,
                    y[2] - segment_direction,
                    y[1] / self.speed_scale,
                ];
                let tol = self.params.tolerance;
                if whole_period {
                    let mismatch = period_end.map_or(f64::INFINITY, |p| {
                        (0..3)
                            .map(|i| (p[i] - relative[i]).abs())
                            .fold(0.0, f64::max)
                    });
                    let periods = s.step_index(t_end) - s.step_index(t);
                    if mismatch <= 1e-3 * tol && period_mismatch <= 1e-2 * tol && periods >= 1.0 {
                        y[0] += periods * s.step_angle;
                        y[2] += periods * s.step_angle;
                        t = (s.step_index(t_end) * s.step_period).min(t_end);
                        segment_end_prev = f64::NAN;
                        period_end = None;
                        period_mismatch = f64::INFINITY;
                        continue;
                    }
                    period_mismatch = mismatch;
                }
                period_end = Some(relative);
            }
            let d = self.drive_at(inputs, t);
            if d.locked {
                y[1] = 0.0;
            }
            if self.quasi_static() {
                y[2] = self.settle(&y, &d);
            }
            let segment_end = match inputs.schedule.get() {
                Some(s) => s.next_switch_after(t).min(t_end),
                None => t_end,
            };
            if segment_end != segment_end_prev {
                whole_period = t == segment_end_prev;
                segment_end_prev = segment_end;
                segment_direction = d.direction;
            }
            if settle_tried_for != segment_end && segment_end - t > long_segment {
                settle_tried_for = segment_end;
                if let Some(settled) = self.settle_rotor(&y, &d, segment_end - t) {
                    attempts = attempts.saturating_add(1);
                    y = settled;
                    t = segment_end;
                    continue;
                }
                if let Some((advanced, slipped)) = self.slip_turns(&y, &d, segment_end - t) {
                    // The turns' phase is only as good as their quadrature and the overdamped
                    // limit (~1e-6 relative against resolved steps, see the tests): over
                    // thousands of turns that is beyond the tolerance in angle, so flagged.
                    attempts = attempts.saturating_add(1);
                    limited = true;
                    y = slipped;
                    t = (t + advanced).min(segment_end);
                    continue;
                }
            }
            let remaining = t_end - t;
            let left = budget.saturating_sub(attempts).max(1);
            // The budget is shared over the rest of the step, but each segment may use at most
            // 1/16 of what is left, so that the first periods of a schedule are resolved well
            // enough for their repetition to be detected (and then the rest costs nothing).
            let per_segment = (left / SEGMENT_BUDGET_SHARE).max(1);
            let dt_min = (remaining / left as f64).min((segment_end - t) / per_segment as f64);
            let mut dt_try = dt.max(dt_min).min(segment_end - t);
            if dt_try < 1e-300 {
                dt_try = segment_end - t;
            }
            attempts = attempts.saturating_add(1);
            if d.locked && self.quasi_static() {
                // Nothing moves but the onion, which follows the inputs: jump to the next switch.
                t = segment_end.max(t + dt_try).min(t_end);
                continue;
            }
            let forced = dt_try <= dt_min * (1.0 + 1e-12);
            match self.doubled_step(&y, dt_try, &d) {
                Some((y_new, err)) if err <= 1.0 || forced => {
                    if err > 1.0 {
                        limited = true;
                    }
                    y = y_new;
                    t = if t + dt_try >= segment_end || segment_end - (t + dt_try) < 1e-15 * t_end {
                        segment_end.max(t + dt_try).min(t_end)
                    } else {
                        t + dt_try
                    };
                    dt = dt_try * step_factor(err);
                }
                Some((_, err)) => dt = (dt_try * step_factor(err)).max(dt_min),
                None if forced => {
                    // The linearization overflowed even at the smallest allowed substep: hold
                    // the state over it rather than produce garbage.
                    limited = true;
                    y[1] = 0.0;
                    t = (t + dt_try).min(t_end);
                    dt = dt_try;
                }
                None => dt = (0.2 * dt_try).max(dt_min),
            }
        }
        if t < t_end {
            return Err(format!(
                "the step from t = {t_start} s by {h} s spans more schedule switches than \
                 max_substeps = {budget} allows to resolve (the rotor cannot settle within a \
                 period of the schedule); shorten the step or raise max_substeps"
            ));
        }
        let d = self.drive_at(inputs, t_end);
        if d.locked {
            y[1] = 0.0;
        }
        if self.quasi_static() {
            y[2] = self.settle(&y, &d);
        }
        *state = MotorState {
            time: t_end,
            rotor_angle: y[0],
            rotor_speed: y[1],
            onion_angle: y[2],
            onion_tilt: y[3],
            substep_hint: dt.clamp(1e-300, MAX_STEP),
        };
        Ok(StepReport {
            outputs: self.outputs_at(&y, &d),
            substeps: attempts,
            accuracy_limited: limited,
        })
    }
}

/// A segment of constant drive may use at most 1/this of the substeps left (see [`Motor::step`]).
const SEGMENT_BUDGET_SHARE: u32 = 16;
/// Largest stride of the rotor march in [`Motor::settle_rotor`] (rad), as the onion's.
const MAX_ROTOR_STRIDE: f64 = 0.05;
/// Rotor march caps: strides, travel (two turns: farther means it slips) and fold turnarounds.
const MAX_ROTOR_MARCH: usize = 1000;
const MAX_ROTOR_TRAVEL: f64 = 4.0 * PI;
const MAX_TURNAROUNDS: usize = 8;
const MAX_ROOT_STEPS: usize = 100;
/// Strides of one slipping turn in [`Motor::slip_turn`]: 126 at the largest stride, plus the
/// halvings at folds.
const MAX_SLIP_STRIDES: usize = 20_000;
/// Largest distance from its equilibrium (rad) at which [`Motor::settle_rotor`] may leave the
/// rotor at the end of an interval: close enough that the exponential tail is linear.
const MAX_SETTLE_RESIDUAL: f64 = 1e-4;

/// Next-substep factor for a second-order method (local error ~ dt^3), bounded to [0.2, 5].
fn step_factor(err: f64) -> f64 {
    if err <= 0.0 {
        5.0
    } else {
        (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 5.0)
    }
}
