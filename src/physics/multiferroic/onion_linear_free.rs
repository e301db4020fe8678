//! The ring's torque in the Gilbert onion's linear macro spans (see
//! [`Motor::advance_onion_linear`]) for a free rotor that the ring turns the onion of but barely
//! turns itself.

use super::decoupled::torque_bound;
use super::onion_linear_locked::{stiffness_slope_bound, RingTerm};
use super::{Motor, MotorInputs, StepRun};

impl Motor {
    /// The ring's term for a macro span of a free rotor whose ring torque is not negligible for
    /// the onion but is for the rotor over the rest of the step ([`Self::ring_is_negligible`]),
    /// or `None`.
    ///
    /// The rotor then follows load and drag alone ([`Self::drift_rotor`]): dropping the ring's
    /// torque, at most `tau_max` ([`torque_bound`]) whatever the offset, moves it by at most a
    /// tenth of the tolerance in angle and the tolerance in speed by the step's end, as the
    /// rotor's equation is linear in its torque. The onion keeps the torque's value and slope at
    /// the span's start, `tau(beta0 + delta - p)` (eq. 3.3, `beta = psi - phi`) with `p` the
    /// bar's turn since then: Taylor's remainder is at most `|tau'(beta0)| |p| + |tau''| / 2
    /// (|delta| + |p|)^2`, with `|tau''|` at most [`stiffness_slope_bound`]. Under any torque of
    /// at most `|load| + tau_max` the drag `c` holds the rotor's speed within `max(|omega0|,
    /// (|load| + tau_max) / c)`, which bounds `|p|` over the span (the bound's
    /// [`RingTerm::drift_speed`]). An undamped rotor (`c = 0`) is left to the other paths.
    pub(super) fn free_ring_term(&self, run: &StepRun, inputs: &MotorInputs) -> Option<RingTerm> {
        if inputs.rotor_locked || self.drag <= 0.0 {
            return None;
        }
        let (_, torque_speed, torque_angle) = self.drift_response(run.t_end - run.t);
        if !self.ring_is_negligible(torque_speed, torque_angle) {
            return None;
        }
        let (value, stiffness) = self.ring_bar.torque_stiffness(run.y[2] - run.y[0]);
        let tau_max = torque_bound(&self.ring_bar);
        let term = RingTerm {
            value,
            stiffness,
            curvature: 0.5 * stiffness_slope_bound(&self.ring_bar),
            constant: 0.0,
            drift_speed: run.y[1]
                .abs()
                .max((inputs.load_torque.abs() + tau_max) / self.drag),
            relinearized: false,
        };
        [value, stiffness, term.curvature, term.drift_speed]
            .iter()
            .all(|v| v.is_finite())
            .then_some(term)
    }
}
