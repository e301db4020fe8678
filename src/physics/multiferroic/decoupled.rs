//! A free rotor that the ring's torque cannot move within the tolerance over the rest of a
//! segment: the Gilbert onion's trapped ringing is then dropped at once (see
//! [`Motor::decoupled_ringing`]).

use super::ringing::{sublevel_gradient_bound, Rims, MAX_FOLLOWED_LAG, RIM_SLOWDOWN};
use super::{Drive, Motor, Vector};

impl Motor {
    /// Whether the Gilbert onion's ringing about the minimum `settled` may be dropped at once (the
    /// onion put on its quasi-static branch) because nothing it does over the `remaining` time of
    /// its segment (s) can move the free rotor: the ring's torque on the bar is at most `tau_max`
    /// in magnitude ([`torque_bound`]), so the branch's torque and the ringing onion's differ by at
    /// most `2 tau_max`, an impulse of at most `2 tau_max remaining`, which the rotor's drag turns
    /// into at most that over `c` of angle, however its inertia spreads it in time (as in
    /// [`Self::averaged_ringing`]); held below a hundredth of the tolerance. (Load-driven rotors of
    /// weak rings: the onion's ringing, resolved, only ever moves its own outputs.)
    ///
    /// The onion's outputs then follow the contract of [`Self::averaged_ringing`]: the ringing must
    /// be trapped in the minimum's well ([`Self::trapped_ringing`], its energy below the well's
    /// lowest rim), where the onion stays, so that it is reported at the centre of its ringing
    /// rather than at its phase; it must decay, at its bound on the decay rate, within the segment
    /// to the relaxed onion's slack ([`Self::relaxed_slack`] plus the tolerance), so that the onion
    /// ends the segment where the resolved one does; and its lag behind the minimum, which moves at
    /// `omega k_bar / k` with the rotor, within [`MAX_FOLLOWED_LAG`] over the ringing's decay time,
    /// as for the relaxed onion ([`Self::relaxed_onion`]). Where those instantaneous decay bounds
    /// fail (ringing near its rims), it may decay within the segment by its orbit-averaged loss
    /// instead ([`Self::decoupled_ringing_decays`]). A locked rotor is not served here: its
    /// onion's ringing is dropped only once it has decayed.
    pub(super) fn decoupled_ringing(
        &self,
        y: &Vector,
        d: &Drive,
        settled: f64,
        rims: &mut Rims,
        remaining: f64,
    ) -> bool {
        if d.locked || !self.onion_relaxes_fast() {
            return false;
        }
        let impulse = 2.0 * torque_bound(&self.ring_bar) * remaining;
        // (A NaN fails.)
        let negligible = impulse <= 0.01 * self.params.tolerance * self.drag;
        if !negligible {
            return false;
        }
        // The rims are looked for (a march over the well) only where ringing out to them, half
        // a turn wide at most, could decay to the slack within the segment at the faster of the
        // rates it is held to there (the sublevel bound's `kappa` is at most the curvature at
        // the minimum); near the minimum no search is needed.
        let slack = self.params.tolerance + self.relaxed_slack(false);
        let needed = (std::f64::consts::PI / slack).ln().max(0.0) / remaining;
        let land = self.landscape(y[0], d.direction, d.stress);
        let k = land.curvature(settled);
        let (g, alpha, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let linear = self
            .onion_decay_rate(0.5 * k)
            .max(self.onion_decay_rate(1.5 * k));
        let reachable = (linear / RIM_SLOWDOWN).max(g * alpha * k.min(t)) >= needed;
        let least_rate = if reachable { 0.0 } else { f64::INFINITY };
        let Some(trap) = self.trapped_ringing(y, d, settled, Some((&mut *rims, least_rate))) else {
            return self.decoupled_ringing_decays(y, d, settled, rims, remaining);
        };
        // The onion must meet the segment's end (a switch, or the step's end where the inputs
        // may change) where the resolved one does: its phase there decides which well it rings
        // into next. So the ringing must have decayed by then, at its bound on the decay rate,
        // to what the relaxed onion would drop anyway.
        let mut left = trap.amplitude * (-trap.rate * remaining).exp();
        if let Some((level, rims)) = trap.sublevel {
            // Out to the rims, also at the decay its energy's sublevel gradient bound guarantees.
            let floor = super::orbit::point(&land, settled).0;
            let kappa = sublevel_gradient_bound(&land, settled, floor, level, rims);
            if kappa > 0.0 {
                let rate = g * alpha * kappa.min(t);
                let reach = trap.amplitude.min((2.0 * level / kappa).sqrt());
                left = left.min(reach * (-rate * remaining).exp());
            }
        }
        let decays = left <= slack;
        if !decays {
            return self.decoupled_ringing_decays(y, d, settled, rims, remaining);
        }
        let k_bar = self.ring_bar.stiffness(settled - y[0]);
        let drift = (k_bar / trap.curvature * y[1]).abs();
        drift <= MAX_FOLLOWED_LAG * trap.rate
    }
}

/// A bound on the magnitude of the ring's torque on the bar (N m) at any angle: eq. 3.3's
/// energy `K (1/B - 1/A)` with `A, B = sqrt(a^2 + r^2 -+ 2 a r cos(beta))` has the derivative
/// `K a r sin(beta) (1/A^3 + 1/B^3)`, and both distances are at least `r - a` (`a` half the bar's
/// length, `r` the walls' radius; the bar turns inside the ring, `a < r`). Within a few percent
/// of the largest torque for a bar much shorter than the ring, as in the motors this serves.
pub(super) fn torque_bound(ring_bar: &super::magnetics::RingBar) -> f64 {
    let (a, r) = (ring_bar.bar_charge_radius, ring_bar.wall_radius);
    2.0 * ring_bar.coupling.abs() * a * r / (r - a).powi(3)
}
