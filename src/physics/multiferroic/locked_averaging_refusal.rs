//! Whether a locked rotor's ringing onion, trapped in its frozen well, stays refused by both
//! orbit-averaged paths (the averaged advance, `orbit_advance.rs`, and the averaged decay time,
//! `locked_ringing.rs`) over a horizon ([`Motor::averaging_refused_over`]), from bounds on what
//! the onion's energy and the time left can become within it.
//!
//! With the rotor locked and the landscape `U(psi)` of eq. 3.3 plus eq. 3.4 frozen, the energy
//! `E = U(psi) - U(psi*) + T theta^2 / 2` falls as `dE/dt = -g alpha (U'^2 + T^2 theta^2)`. With
//! `U'' <= K` everywhere (`K` the ring-bar stiffness's bound plus eq. 3.4's `2 |E_me|`, as in
//! [`Motor::period_floor`]) and `U >= U(psi*)` between the minimum and its rims,
//! `U'(psi)^2 <= 2 K (U(psi) - U(psi*))` inside the well (step `U' / K` downhill from `psi`: it
//! stays between `psi` and `psi*`, and lowers `U` by at least `U'^2 / (2 K)`), so
//! `|dE/dt| <= 2 g alpha max(K, T) E`: over a time `h` the energy keeps at least
//! `e^(-2 g alpha max(K, T) h)` of itself. The same bound holds for the orbit-averaged rate, the
//! loss per orbit over the period. Every orbit's turning points lie at least `sqrt(2 E / K)` from
//! the minimum (`U - U(psi*) <= K s^2 / 2`).

use super::locked_ringing::TIME_MARGIN;
use super::onion::Landscape;
use super::orbit::{Well, RIM_MARGIN};
use super::orbit_advance::{MAX_LOSS_PER_ORBIT, MIN_ORBITS};
use super::orbit_phase::{envelope, pendulum_anharmonicity, SAFETY};
use super::Motor;
use std::f64::consts::PI;

/// The energy held beyond the advance's rim margin, as a fraction of the barrier (the well's
/// rims found afresh by each check).
const RIM_ROUNDING: f64 = 1e-3;
/// The slack kept against the checks' own rounding (the well's curvature, the quadrature's
/// period and width, found afresh by each check): each bound is held this factor beyond its
/// check's threshold.
const SLACK: f64 = 2.0;

impl Motor {
    /// Whether the locked rotor's onion, at energy `energy` (J) above the minimum of `well` in the
    /// frozen landscape `land` (curvature `k` there), with `remaining` time (s) left in a step
    /// without switches, is refused by both averaged paths at every instant of the next `horizon`
    /// (s), whatever its ringing's phase (see the module documentation for the bounds):
    ///
    /// - **The averaged decay time** ([`Motor::locked_ringing_decays`]) refuses where the
    ///   energy's logarithm over the tolerance's energy `E1` exceeds `2 TIME_MARGIN` times the
    ///   time left at the linearization's rate `g alpha (k + T)`: both sides fall at most
    ///   linearly in time (the energy's logarithm at `2 g alpha max(K, T)` at most), so it holds
    ///   over the horizon where it holds at both its ends.
    /// - **The averaged advance** ([`Motor::advance_orbits`]) refuses where the energy stays
    ///   above its rim margin; else where neither drops the ringing (its decay to the relaxed
    ///   onion's slack takes `4 ln(width / slack) / loss` orbits, more than the time left holds
    ///   at the shortest period [`Motor::period_floor`]) nor bounds its phase's drift within the
    ///   tolerance. That drift is `2 pi sqrt(k / T)` times the ringing's width at the step's
    ///   end times the lesser of the linearization's shift `alpha^2 (T - k)^2 / (8 k T)` per orbit
    ///   and the pendulum's bound (its first term alone, `SAFETY alpha^2 c1 mu` summed over the
    ///   orbits at the linearization's loss), over at least `MIN_ORBITS` orbits (or the decay to
    ///   the slack at `MAX_LOSS_PER_ORBIT`); the width at the end is at least the least width
    ///   `sqrt(2 E_low / K)` decayed at `2 g alpha max(K, T)` over the time left.
    pub(super) fn averaging_refused_over(
        &self,
        land: &Landscape,
        well: &Well,
        k: f64,
        energy: f64,
        remaining: f64,
        horizon: f64,
    ) -> bool {
        let (g, alpha, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let tol = self.params.tolerance;
        let bound = land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs();
        let fastest = 2.0 * g * alpha * bound.max(t);
        // The least energy the onion can have within the horizon.
        let low = energy * (-fastest * horizon).exp();
        // (False for a NaN.)
        if !(k > 0.0 && low > 0.0 && horizon < remaining && fastest.is_finite()) {
            return false;
        }
        // The averaged decay time's cheap refusal at both ends of the horizon.
        let linear_rate = g * alpha * (k + t);
        let e1 = tol * tol * (5.0 * k / 12.0).min(0.5 * t);
        let refuses =
            |e: f64, left: f64| (e / e1).ln() > SLACK * 2.0 * TIME_MARGIN * left * linear_rate;
        let linear_loss = 2.0 * PI * alpha * (k + t) / (k * t).sqrt();
        let decay_refused =
            linear_loss > 0.1 || (refuses(energy, remaining) && refuses(low, remaining - horizon));
        if !decay_refused {
            return false;
        }
        // The averaged advance: refused at its rims, ...
        if low > (RIM_MARGIN + RIM_ROUNDING) * well.barrier {
            return true;
        }
        if linear_loss > 2.0 * MAX_LOSS_PER_ORBIT {
            return true;
        }
        // ... or neither dropping the ringing ...
        let width = (2.0 * low / bound).sqrt() / SLACK;
        let slack = self.relaxed_slack(true);
        // (False for a NaN.)
        let wider = width > slack;
        if !wider {
            return false;
        }
        let most_orbits = SLACK * remaining / self.period_floor(land);
        if 4.0 * (width / slack).ln() / linear_loss <= most_orbits {
            return false;
        }
        // ... nor bounding its phase's drift within the tolerance.
        let orbits = MIN_ORBITS.min(2.0 * (width / slack).ln() / MAX_LOSS_PER_ORBIT);
        let end_width = width * (-0.5 * fastest * remaining).exp();
        let shift = alpha * alpha * (t - k) * (t - k) / (8.0 * k * t);
        let mu = pendulum_anharmonicity(low / well.barrier);
        let sum = -(-linear_loss * orbits).exp_m1() / -(-linear_loss).exp_m1();
        let pendulum = SAFETY * alpha * alpha * envelope(k / t)[0] * mu * sum;
        let drift = 2.0 * PI * (k / t).sqrt() * end_width * pendulum.min(shift * orbits);
        // (False for a NaN.)
        drift > SLACK * tol
    }
}
