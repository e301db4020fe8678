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
//! comes out by itself), while the quasi-static onion is re-solved at the end of every substep. The
//! method is second order. With the quasi-static onion the rotor block is 2x2, its `phi` functions
//! come in closed form and the third-order member of an embedded exponential Rosenbrock pair
//! (exprb32) estimates the local error. The Gilbert onion's ringing takes an explicit
//! Dormand-Prince 5(4) pair within its stability reach, an exponential RK4 where only the rotor's
//! drag keeps that pair out of reach (with the onion's block exact too where the two barely couple,
//! `etd_blocks.rs`; a locked rotor's creeping onion's block exact, and tried first near that pair's
//! stability limit, `locked_stiff.rs`), else an exponential Rosenbrock pair (`gilbert.rs`, its
//! defect also sampled at the substep's midpoint, `pair_midpoint.rs`); weakly damped ringing
//! trapped in its well advances orbit-averaged (`orbit.rs`, `orbit_advance.rs`,
//! `orbit_averager.rs`, its phase error bounded in `orbit_phase.rs`, the wells its checks find kept
//! per landscape, `orbit_kept_well.rs`; a locked rotor's last orbit is resolved at once,
//! `orbit_finish.rs`, its onion refused near the rim is refused again from the well kept,
//! `orbit_rim_refusal.rs` (a free rotor's, above every barrier, before the search for its rims),
//! and its ringing small enough to be linear advances by its exact linear flow,
//! `linear_ringing.rs`); a locked rotor's onion near or above its wells' rims is held to what
//! its energy, which only falls, can reach (`rim_energy.rs`), a free rotor's to what the rotor's
//! turn can feed it (`free_energy.rs`). A free rotor's onion is settled on its branch only where a
//! minimum can lie within the check's slack (`branch_settle.rs`), and the checks of its branch in
//! one pass share one settle of its state (`settle_memo.rs`). A free rotor that turns too little
//! between a schedule's switches for the ring's torque to change beyond the tolerance advances
//! under that torque held, in closed form, with the quasi-static onion settled once per segment
//! (`held_torque.rs`). On fast schedules whose ring barely couples the onion to the rotor, repeated
//! periods and cycles are taken at once (`onion_periods.rs`, `onion_cycles.rs`) and an onion near
//! its path advances by exact affine maps per switch (`onion_linear.rs`; a locked rotor's, the
//! ring's torque folded into them, by `onion_linear_locked.rs`; a free rotor's that the ring turns
//! the onion of but barely turns itself, by `onion_linear_free.rs`); a free rotor's onion that the
//! ring neither moves nor is moved by takes each whole period of such a schedule in one substep of
//! its own 2x2 system, the rotor on its exact drift (`decoupled_segment.rs`). The estimate sizes
//! the next substep. A budget of attempted substeps per call bounds the cost of a long step (see
//! [`MotorParams::max_substeps`]); where it runs out, forced substeps that the damped onion could
//! not follow are not taken (`forced_crossing.rs`), a free rotor's onion that the ring cannot move
//! is dropped into the well its ringing is trapped in (`decoupled_drop.rs`; at once where its
//! persisting ringing is forecast to spend the budget's fine half within its segment,
//! `budget_forecast.rs`; a locked rotor's onion trapped in its well, in a step without switches,
//! likewise where its ringing, too lossy for the averaged paths or provably refused by them over
//! the forecast's horizon (`locked_averaging_refusal.rs`), is forecast to spend it,
//! `locked_budget_forecast.rs`), and a locked rotor's ringing onion that neither a drop nor forced
//! substeps can follow through the schedule's switches refuses the step (`locked_switches.rs`), as
//! does a locked step whose switches outnumber its loop's passes once the linear spans fail or the
//! budget cannot pay for them (`switch_count.rs`; the spans count one unit per two switches they
//! chain). An onion whose tilt leaves its bounds escapes at the substep that carries it out, not
//! at the budget's smallest (`tilt_exit.rs`). A Gilbert step whose onion's dynamics carry its
//! resolved substeps' local errors far beyond the tolerance by its end is flagged
//! (`amplification.rs`).
//!
//! Long steps: a substep far longer than the relaxation time is never integrated
//! through a negative (past-the-peak) stiffness, which would amplify by `exp(h |k| / c)`. Instead
//! a constant-drive interval long enough for the rotor to settle is advanced in the overdamped
//! limit to its equilibrium (the same downhill memory rule as the onion's), whole periods of the
//! schedule that repeat are advanced at once, and a slipping rotor advances by whole overdamped
//! turns; what is left is integrated, and a forced substep drops the negative stiffness so it
//! cannot amplify. See [`Motor::step`].

mod amplification;
#[cfg(test)]
mod amplification_tests;
pub mod angles;
mod block_phi;
pub mod branch;
mod branch_settle;
#[cfg(test)]
mod branch_settle_tests;
mod budget_forecast;
#[cfg(test)]
mod budget_forecast_tests;
mod cycle;
#[cfg(test)]
mod decay_charge_tests;
mod decoupled;
mod decoupled_drop;
#[cfg(test)]
mod decoupled_drop_tests;
mod decoupled_segment;
#[cfg(test)]
mod decoupled_segment_tests;
#[cfg(test)]
mod decoupled_tests;
mod drift;
pub mod drive;
mod etd_blocks;
mod forced_crossing;
#[cfg(test)]
mod forced_crossing_tests;
mod free_energy;
#[cfg(test)]
mod free_energy_tests;
#[cfg(test)]
mod free_first_tests;
#[cfg(test)]
mod free_rim_refusal_tests;
mod gilbert;
mod held_torque;
#[cfg(test)]
mod held_torque_tests;
mod integrator;
mod linear_ringing;
#[cfg(test)]
mod linear_ringing_tests;
#[cfg(test)]
mod locked_accuracy_tests;
mod locked_averaging_refusal;
#[cfg(test)]
mod locked_averaging_refusal_tests;
mod locked_budget_forecast;
#[cfg(test)]
mod locked_budget_forecast_tests;
#[cfg(test)]
mod locked_onion_increments_tests;
#[cfg(test)]
mod locked_refusal_tests;
mod locked_ringing;
#[cfg(test)]
mod locked_ringing_tests;
mod locked_stiff;
#[cfg(test)]
mod locked_stiff_tests;
mod locked_switches;
#[cfg(test)]
mod locked_switches_tests;
#[cfg(test)]
mod locked_tilt_tests;
#[cfg(test)]
mod locked_unflagged_tests;
mod long_steps;
pub mod magnetics;
pub mod model_exchange;
#[cfg(test)]
mod model_exchange_tests;
pub mod onion;
mod onion_cycles;
#[cfg(test)]
mod onion_cycles_tests;
#[cfg(test)]
mod onion_flow_tests;
mod onion_linear;
mod onion_linear_free;
#[cfg(test)]
mod onion_linear_free_tests;
mod onion_linear_locked;
#[cfg(test)]
mod onion_linear_locked_tests;
#[cfg(test)]
mod onion_linear_tests;
mod onion_periods;
#[cfg(test)]
mod onion_periods_tests;
#[cfg(test)]
mod onion_tests;
mod orbit;
mod orbit_advance;
mod orbit_averager;
mod orbit_finish;
#[cfg(test)]
mod orbit_free_tests;
mod orbit_kept_well;
#[cfg(test)]
mod orbit_kept_well_tests;
#[cfg(test)]
mod orbit_loss_tests;
mod orbit_phase;
#[cfg(test)]
mod orbit_phase_tests;
mod orbit_rim_refusal;
#[cfg(test)]
mod orbit_rim_refusal_tests;
#[cfg(test)]
mod orbit_tests;
#[cfg(test)]
mod orbit_theory_tests;
#[cfg(test)]
mod orbit_turning_tests;
mod pair_midpoint;
#[cfg(test)]
mod pair_midpoint_tests;
mod params;
mod pass_trace;
mod periods;
pub mod phi;
#[cfg(test)]
mod placement_tests;
#[cfg(test)]
mod resolved_tests;
mod rhs;
mod rim_energy;
#[cfg(test)]
mod rim_energy_tests;
mod ringing;
#[cfg(test)]
mod ringing_drop_tests;
mod ringing_outlasts;
#[cfg(test)]
mod ringing_outlasts_tests;
pub mod schedule;
mod settle_memo;
#[cfg(test)]
mod settle_memo_tests;
#[cfg(test)]
mod slip_layer_tests;
#[cfg(test)]
mod slow_decay_tests;
mod slow_onion;
#[cfg(test)]
mod slow_onion_tests;
#[cfg(test)]
mod span_charge_tests;
mod spin;
#[cfg(test)]
mod spin_tests;
#[cfg(test)]
mod spinning_onion_tests;
mod step;
#[cfg(test)]
mod stiff_rotor_tests;
mod switch_count;
#[cfg(test)]
mod switch_count_tests;
#[cfg(test)]
mod tests;
mod tilt_exit;
#[cfg(test)]
mod tilt_exit_tests;
mod validation;
mod values;

use angles::Angles;
use drive::{reduced_direction, Drive};
use magnetics::{RingBar, GYROMAGNETIC_RATIO, MU0};
use onion::Landscape;
pub use params::*;
pub use schedule::{ScheduleSwitch, SteppingSchedule};
use std::f64::consts::PI;
use step::StepRun;
pub use step::GILBERT_SUBSTEP_WEIGHT;
use validation::{check_finite, within_limits};
pub use values::{MotorInputs, MotorOutputs, MotorState, StepReport};

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
    /// The inertia Model Exchange integrates the rotor with (see [`Motor::me_inertia`]).
    me_inertia: f64,
    /// `gamma / (Ms V (1 + alpha^2))` (1/(J s)), the Gilbert option's rate per unit torque.
    llg_rate: f64,
    /// `mu0 Ms^2 V_wall` (J): out-of-plane shape-anisotropy stiffness of the macrospin.
    tilt_stiffness: f64,
    /// Bound on the third derivative of eq. 3.3 (J/rad^3), for the onion's safe march.
    ring_bar_slope_bound: f64,
    /// The onion's cycles marched from their canonical start (a memo of pure functions of the
    /// drive: not part of the state; see [`Motor::canonical_cycle`]).
    #[serde(skip)]
    cycles: cycle::CycleCache,
}

/// State vector of the integrator: rotor angle, rotor speed, onion angle, onion tilt.
type Vector = [f64; 4];

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
        // The FMU declares at most 2e4 (a bounded step); references in tests resolve further.
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
            me_inertia: model_exchange::floored_inertia(inertia, drag, alignment_stiffness),
            llg_rate,
            tilt_stiffness,
            ring_bar_slope_bound: onion::curvature_slope_bound(&ring_bar),
            cycles: Default::default(),
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
            ring_bar_slope_bound: self.ring_bar_slope_bound,
        }
    }

    fn drive_at(&self, inputs: &MotorInputs, time: f64) -> Drive {
        let (applied_direction, stress) = match inputs.schedule.get() {
            Some(s) => (s.direction(time), s.stress_amplitude),
            None => (inputs.strain_direction, inputs.stress),
        };
        Drive {
            direction: reduced_direction(applied_direction),
            applied_direction,
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

    /// The angles at `y` for the drive `d`, turned from `hint` (any earlier state) when close.
    fn angles_at(y: &Vector, d: &Drive, hint: Option<&Angles>) -> Angles {
        match hint {
            Some(a) => a.moved(y[2], y[0], d.direction),
            None => Angles::exact(y[2], y[0], d.direction),
        }
    }

    /// [`Self::settle`] starting from the angles at `y` (turned from `hint`), returning the
    /// angles at the settled onion.
    fn settle_angles(&self, y: &Vector, d: &Drive, hint: Option<&Angles>) -> Angles {
        self.landscape(y[0], d.direction, d.stress)
            .settle_from(Self::angles_at(y, d, hint))
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
        Ok(self.outputs_of(state, &self.drive_at(inputs, state.time)))
    }

    /// [`Self::outputs`] of a valid state under the drive `d`.
    fn outputs_of(&self, state: &MotorState, d: &Drive) -> MotorOutputs {
        let mut y = [
            state.rotor_angle,
            if d.locked { 0.0 } else { state.rotor_speed },
            state.onion_angle,
            state.onion_tilt,
        ];
        if self.quasi_static() {
            y[2] = self.settle(&y, d);
        }
        self.outputs_at(&y, d)
    }

    fn outputs_at(&self, y: &Vector, d: &Drive) -> MotorOutputs {
        self.outputs_with(y, d, &Angles::exact(y[2], y[0], d.direction))
    }

    /// [`Self::outputs_at`] from the angles at `y` (no trigonometry but the wrap).
    fn outputs_with(&self, y: &Vector, d: &Drive, a: &Angles) -> MotorOutputs {
        let beta = y[2] - y[0];
        // sin^2(psi - gamma) = (1 - cos 2(psi - gamma)) / 2.
        let sin_squared = 0.5 * (1.0 - a.cos_double);
        let (torque, magnetostatic_energy) =
            self.ring_bar.torque_energy_of(a.sin_offset, a.cos_offset);
        MotorOutputs {
            torque,
            rotor_angle: y[0],
            rotor_speed: y[1],
            onion_angle: y[2],
            offset_angle: wrap_angle(beta),
            magnetostatic_energy,
            magnetoelastic_energy: self.magnetoelastic_per_stress * d.stress * sin_squared,
            applied_strain_direction: d.applied_direction,
            applied_stress: d.stress,
        }
    }
}
