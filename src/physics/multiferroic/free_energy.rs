//! A free rotor's Gilbert onion: its energy rises only by what the rotor's turn feeds it, and a
//! substep that breaks that is rejected ([`Motor::free_energy_checked_error`]), as a locked
//! rotor's is (`rim_energy.rs`).
//!
//! The macrospin's energy `E = U(psi; phi) + T theta^2 / 2` (eq. 3.3 plus eq. 3.4 and the
//! tilt's) changes at `dE/dt = -g alpha (U'^2 + T^2 theta^2) + (dU/dphi) phi'`
//! (`locked_ringing.rs`). Only eq. 3.3's ring-bar term depends on the rotor's angle, through
//! `psi - phi`, so `|dU/dphi| <= tau_max` ([`torque_bound`]): the energy rises by at most
//! `tau_max` times the rotor's turn, and at any onion angle the landscape, its rims' heights
//! with it, moves by at most that. The rotor obeys `I omega' = tau_bar + tau_load - c omega`
//! with `|tau_bar| <= tau_max`, so `|omega|` never exceeds `max(|omega_0|, (|tau_load| +
//! tau_max) / c)`, and the turn over a substep of `dt` is at most that times `dt`.
//!
//! A substep that the angles' control accepts is rejected (its error estimate raised to
//! [`BEYOND_RIM`]) whose end
//! - has more energy than the start's plus the rotor's feed plus what an error of the
//!   tolerance `tol` in `psi` and `theta` accounts for, `G tol + T tol (|theta| + tol / 2)`
//!   (`G` a bound on `|U'|`, `theta` the end's tilt): it is off by more than the tolerance,
//!   whatever its estimate says;
//! - has the energy, which the exact flow from its start cannot reach, to pass a rim: the
//!   energy decides between wells on differences far below what an angle of the tolerance is
//!   worth.
//!
//! Ringing at half its rim's height was carried far over every rim by one exponential
//! Rosenbrock substep spanning half an orbit (estimate 0.66 tolerances, 4.7 in fact in the
//! angle and 8 in the tilt); ringing at 0.985 of its rim was carried over it by exponential
//! RK4 substeps whose angles were within the tolerance. Either then spun for thousands of
//! radians where a plain RK4 keeps it in its well.
//!
//! The rims' heights over a turn are found once per drive, where the energy first rises beyond
//! the rotor's feed, at the rotor's angle then; at another angle each is within `tau_max` times
//! the rotor's turn since.

use super::decoupled::torque_bound;
use super::orbit::point;
use super::rim_energy::{Levels, BEYOND_RIM, ROUNDING};
use super::{Drive, Motor, Vector};

/// What the free rotor's energy check knows of the present drive's landscape.
#[derive(Clone, Copy, Debug)]
pub(super) struct FreeLedger {
    /// The drive: strain direction and stress.
    key: [f64; 2],
    /// The rotor's angle where the rims were looked for, and the rims found there (`None`
    /// where they were not, or not looked for yet).
    angle: f64,
    levels: Option<Levels>,
    walked: bool,
    /// The last substep's start and end with their energies (J).
    last: [(Vector, f64); 2],
}

impl FreeLedger {
    pub(super) const NONE: FreeLedger = FreeLedger {
        key: [f64::NAN; 2],
        angle: f64::NAN,
        levels: None,
        walked: false,
        last: [([f64::NAN; 4], 0.0); 2],
    };
}

impl Motor {
    /// The error estimate `err` (in tolerances) of a free rotor's Gilbert substep of `dt` (s)
    /// from `y` to `y_new` under the drive `d`, raised to [`BEYOND_RIM`] where the onion's energy
    /// rises beyond what the rotor's turn allows (see the module documentation); `err` itself
    /// otherwise.
    pub(super) fn free_energy_checked_error(
        &self,
        ledger: &mut FreeLedger,
        (y, y_new): (&Vector, &Vector),
        dt: f64,
        d: &Drive,
        err: f64,
    ) -> f64 {
        // A substep rejected already needs nothing more; one forced beyond it is flagged.
        if self.quasi_static() || err > 1.0 || err.is_nan() {
            return err;
        }
        let key = [d.direction, d.stress];
        if ledger.key != key {
            *ledger = FreeLedger {
                key,
                ..FreeLedger::NONE
            };
        }
        let t = self.tilt_stiffness;
        let energy = |y: &Vector| {
            let land = self.landscape(y[0], d.direction, d.stress);
            point(&land, y[2]).0 + 0.5 * t * y[3] * y[3]
        };
        // The start is usually the last accepted substep's end, or a rejected one's start.
        let before = match ledger.last.iter().find(|(state, _)| state == y) {
            Some(&(_, e)) => e,
            None => energy(y),
        };
        let after = energy(y_new);
        ledger.last = [(*y, before), (*y_new, after)];
        let tau_max = torque_bound(&self.ring_bar);
        let speed = y[1].abs().max((d.load.abs() + tau_max) / self.drag);
        // `|U'| <= G`, and `U` spans at most `2 pi G` over a turn.
        let gradient = tau_max + (self.magnetoelastic_per_stress * d.stress).abs();
        let rounding = ROUNDING * 2.0 * std::f64::consts::PI * gradient;
        let reach = before + tau_max * speed * dt + rounding;
        // (A NaN fails the comparisons and keeps `err`, which the caller bounds.)
        let rose = after > reach;
        if !rose {
            return err;
        }
        let tol = self.params.tolerance;
        if after > reach + tol * (gradient + t * (y_new[3].abs() + 0.5 * tol)) {
            return err.max(BEYOND_RIM);
        }
        if !ledger.walked {
            ledger.walked = true;
            ledger.angle = y[0];
            ledger.levels = self.levels(&self.landscape(y[0], d.direction, d.stress), y[2]);
        }
        let Some(levels) = ledger.levels else {
            return err;
        };
        let shift = tau_max
            * (y[0] - ledger.angle)
                .abs()
                .max((y_new[0] - ledger.angle).abs());
        // A rim the exact flow cannot reach at the end, which the end passes.
        if levels.between(reach + shift, after - shift - rounding) {
            err.max(BEYOND_RIM)
        } else {
            err
        }
    }
}
