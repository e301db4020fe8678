//! The orbit-averaged equations' right-hand side ([`Averager`]) that [`Motor::advance_orbits`]
//! integrates: the rotor driven by the orbit's mean torque, the orbit's energy lowered by the
//! damping and by the landscape turning under it, its phase at the damped orbit's frequency (the
//! method is described in `orbit.rs`).

use super::onion::Landscape;
use super::orbit::{Orbit, Well};
use super::{Drive, Motor};

/// The averaged ringing's state: rotor angle and speed (rad, rad/s), the orbit's energy above
/// the minimum (J; or its logarithm, see [`Averager::log_energy`]) and its
/// phase (cycles).
pub(super) type Slow = [f64; 4];

/// The averaged equations' right-hand side at one rotor angle after another, each well and orbit
/// found from the last (the landscape moves little between calls).
pub(super) struct Averager<'a> {
    pub(super) m: &'a Motor,
    pub(super) d: &'a Drive,
    pub(super) well: Well,
    pub(super) orbit: Orbit,
    /// Evaluations of the right-hand side.
    pub(super) evaluations: u32,
    /// The rotor is overdamped (see `orbit_advance.rs`).
    pub(super) overdamped: bool,
    /// The slow state carries the energy's logarithm (a locked rotor, or ringing dropped at the
    /// advance's end): the energy then decays at a rate `<E'> / E` that changes only with the
    /// orbit's shape, which the explicit steps follow at any length, where an explicit step of
    /// the energy itself overshoots past the minimum once it spans about a decay time. The error
    /// held on it is the energy's relative one, as on the energy.
    pub(super) log_energy: bool,
}

impl Averager<'_> {
    /// The well at rotor angle `phi`: the last one's rims moved with its minimum (they bracket
    /// the turning points; [`turning_point`](super::orbit::turning_point) checks that they
    /// still do).
    pub(super) fn well_at(&self, land: &Landscape) -> Option<Well> {
        let minimum = land.settle(self.well.minimum);
        let shift = minimum - self.well.minimum;
        let k = land.curvature(minimum);
        let rims = (self.well.below + shift, self.well.above + shift);
        Some(Well::between(land, minimum, rims, k)).filter(|w| k > 0.0 && w.barrier > 0.0)
    }

    /// The orbit's energy above the minimum (J) at the slow state `s`.
    pub(super) fn energy(&self, s: &Slow) -> f64 {
        if self.log_energy {
            s[2].exp()
        } else {
            s[2]
        }
    }

    /// The energy's relative rate `<E'> / E` (1/s) at the slow state `s` of rates `rate`.
    pub(super) fn relative_rate(&self, s: &Slow, rate: &Slow) -> f64 {
        if self.log_energy {
            rate[2]
        } else {
            rate[2] / s[2]
        }
    }

    /// The well and orbit at the slow state `s`, the turning points' iterations started from the
    /// last orbit's moved with its minimum.
    pub(super) fn orbit_at(&self, s: &Slow) -> Option<(Well, Orbit)> {
        let land = self.m.landscape(s[0], self.d.direction, self.d.stress);
        let well = self.well_at(&land)?;
        let shift = well.minimum - self.well.minimum;
        let guess = (self.orbit.below + shift, self.orbit.above + shift);
        let o = self.m.orbit(&land, &well, self.energy(s), guess)?;
        Some((well, o))
    }

    /// The averaged equations: the rotor driven by the orbit's mean torque, the energy lowered by
    /// the damping and by the landscape turning under the orbit (the orbit's mean of
    /// `dU/dphi omega` less the minimum's), the phase at the damped orbit's frequency.
    pub(super) fn rate(&mut self, s: &Slow) -> Option<Slow> {
        self.evaluations += 1;
        let m = self.m;
        let (well, o) = self.orbit_at(s)?;
        let (alpha, t) = (m.params.gilbert_damping, m.tilt_stiffness);
        let k = well.curvature;
        let shift = 1.0 - alpha * alpha * (t - k) * (t - k) / (4.0 * k * t);
        if shift.is_nan() || shift <= 0.0 {
            return None;
        }
        self.well = well;
        self.orbit = o;
        let rotor = if self.d.locked {
            [0.0, 0.0]
        } else if self.overdamped {
            [(o.torque + self.d.load) / m.drag, 0.0]
        } else {
            [s[1], (o.torque + self.d.load - m.drag * s[1]) / m.inertia]
        };
        let energy_rate = o.damping_rate(alpha) - rotor[0] * (o.torque - o.torque_at_minimum);
        Some([
            rotor[0],
            rotor[1],
            if self.log_energy {
                energy_rate / o.energy
            } else {
                energy_rate
            },
            shift.sqrt() / o.period,
        ])
    }
}
