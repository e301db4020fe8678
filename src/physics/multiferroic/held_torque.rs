//! A segment of constant drive over which the ring's torque on the bar barely changes: the rotor
//! advances exactly under the torque held at the segment's start, at the cost of one onion
//! settle a segment (see [`Motor::advance_held_torque`]).

use super::{phi, Drive, Motor, StepRun};

impl Motor {
    /// The quasi-static onion on a free rotor that turns too little within the segment (of
    /// constant drive, ending at `segment_end`) for the ring's torque to change by more than the
    /// tolerance allows: the rotor of section 3.2.2, `I phi'' = tau + load - c phi'`, advances
    /// exactly with `tau` held at its start value `tau_0` (eq. 3.3's torque at the settled onion),
    /// and the onion is settled on its branch of eq. 3.4 at the new rotor angle. This is the
    /// rotor of a nanosecond schedule whose inertial time `I/c` and relaxation time `c/k` are far
    /// longer than a period: a switch costs one closed-form advance and one settle, where an
    /// exponential substep took three (the old landscape's settle at the switch is left out where
    /// the new landscape is convex about the onion, see below).
    ///
    /// The bound. Over the segment of length `h` the rotor leaves its start by at most
    /// `D = |omega_0| I/c (1 - e^(-h c/I)) + (|load| + tau_max) g(h)`, with `g(h)` the angle a
    /// unit torque gives (`h^2 / 2I` without drag) and `tau_max` a bound of eq. 3.3's torque.
    /// With `M` the bound of eq. 3.4's third derivative ([`super::onion::Landscape`]), `C` the
    /// onion's curvature `d^2U/dpsi^2` and `k` the ring-bar stiffness at the start, while the
    /// rotor and the onion stay within `D` and `r D` of their starts, `r = 1 + 2 |k| / C`, the
    /// curvature stays above `C / 2` as long as `M D (1 + r) <= C / 2` (checked): the branch
    /// has no fold within the segment, the onion turns by at most `r` times the rotor
    /// (`k / (k + k_me)` by the implicit function theorem on `dU/dpsi = 0`), and the torque moves
    /// from `tau_0` by at most `dtau = (|k| + C / 2) (1 + r) D`. Its effect, `dtau g(h)` on the
    /// rotor angle (times `r` on the onion's) and `dtau s(h)` on the speed (`s(h) = h / I`
    /// without drag), is held below a tenth of the tolerance and below the tolerance on the
    /// error norm's speed scale, as a substep's local error. The settle starts from the onion
    /// turned along its branch, inside the convex stretch around the start, so it finds the
    /// minimum the memory rule gives.
    ///
    /// Applies (else `false`) with the onion settled for `d`, on a stepping schedule, under a free
    /// rotor (not a Gilbert onion's quasi-static twin following its branch).
    pub(super) fn advance_held_torque(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
    ) -> bool {
        #[cfg(test)]
        if HELD_TORQUE_OFF.with(|c| c.get()) {
            return false;
        }
        if d.locked
            || !self.quasi_static()
            || !run.following.is_nan()
            || run.schedule.is_none()
            || !run.is_settled(d)
        {
            return false;
        }
        let Some(a) = run.angles else {
            return false;
        };
        let h = segment_end - run.t;
        // Comparisons false for NaN, so that a NaN anywhere declines the advance.
        let positive = h > 0.0;
        if !positive {
            return false;
        }
        let landscape = self.landscape(run.y[0], d.direction, d.stress);
        let (tau, k) = self
            .ring_bar
            .torque_stiffness_of(a.sin_offset, a.cos_offset);
        let curvature = k + 2.0 * landscape.magnetoelastic * a.cos_double;
        let convex = curvature > 0.0;
        if !convex {
            return false;
        }
        let (i, c) = (self.inertia, self.drag);
        // phi_1 and phi_2 of `-h c / I`: the coasting angle `h phi_1`, the speed and the angle a
        // unit torque gives, `h phi_1 / I` and `h^2 phi_2 / I`, without cancellation.
        let [phi1, phi2, _] = phi::phis(-h * c / i);
        let (coast, torque_speed, torque_angle) = (h * phi1, h * phi1 / i, h * h * phi2 / i);
        let omega = run.y[1];
        let reach = omega.abs() * coast + (d.load.abs() + self.torque_bound()) * torque_angle;
        let ratio = 1.0 + 2.0 * k.abs() / curvature;
        let m = landscape.third_derivative_bound();
        let no_fold = m * reach * (1.0 + ratio) <= 0.5 * curvature;
        if !no_fold {
            return false;
        }
        let torque_change = (k.abs() + 0.5 * curvature) * (1.0 + ratio) * reach;
        let tol = self.params.tolerance;
        if !(torque_change * torque_angle * ratio <= 0.1 * tol
            && torque_change * torque_speed <= tol * self.speed_scale)
        {
            return false;
        }
        let force = tau + d.load;
        let turn = omega * coast + force * torque_angle;
        // e^(-h c/I) = 1 - (h c/I) phi_1.
        let speed = omega - (c * omega - force) * torque_speed;
        let rotor = run.y[0] + turn;
        if !(rotor.is_finite() && rotor.abs() <= super::MAX_ANGLE && speed.is_finite()) {
            return false;
        }
        let predicted = a.onion + k / curvature * turn;
        // The onion's branch bends by at most `|psi''| <= 4 M (1 + r) (2 C + |k|) / C^2` (its
        // slope `k / (k + k_me)` differentiated, with the bounds above), so the prediction is off
        // the minimum at the new rotor angle by at most `|psi''| turn^2 / 2`, plus the settles'
        // own tolerances.
        let bend = 4.0 * m * (1.0 + ratio) * (2.0 * curvature + k.abs()) / (curvature * curvature);
        let slack = 4.0
            * (landscape.root_tolerance(a.onion)
                + landscape.gradient_tolerance() / (0.5 * curvature));
        let miss = 0.5 * bend * turn * turn + slack;
        let next = (segment_end < run.t_end)
            .then(|| self.switched(run, d, segment_end))
            .flatten();
        let settled = match next {
            Some(new) => {
                // At a switch, the onion goes downhill in the new landscape from the old one's
                // minimum. Where the new landscape is convex within `miss` of the prediction,
                // which holds that minimum, the march from the prediction ends in the same
                // minimum: the old landscape's settle is left out.
                let landscape = self.landscape(rotor, new.direction, new.stress);
                let start = a.moved(predicted, rotor, new.direction);
                let (g, c) = landscape.gradient_curvature_of(&start);
                if c > 2.0 * landscape.third_derivative_bound() * miss {
                    Some(landscape.settle_from_slope(start, g, c))
                } else {
                    None
                }
            }
            None => None,
        };
        let settled = settled.unwrap_or_else(|| {
            self.landscape(rotor, d.direction, d.stress)
                .settle_from(a.moved(predicted, rotor, d.direction))
        });
        run.y = [rotor, speed, settled.onion, 0.0];
        run.angles = Some(settled);
        run.settled = true;
        run.t = segment_end;
        run.attempts = run.attempts.saturating_add(1);
        true
    }

    /// The drive of the segment after the switch at `switch` ([`Motor::drive_at`] there, the
    /// load and stress as in `d`).
    fn switched(&self, run: &StepRun, d: &Drive, switch: f64) -> Option<Drive> {
        let applied = run.schedule.as_ref()?.direction(switch);
        Some(Drive {
            direction: super::reduced_direction(applied),
            applied_direction: applied,
            ..*d
        })
    }
}

#[cfg(test)]
thread_local! {
    /// Turns [`Motor::advance_held_torque`] off (tests compare with the substeps it replaces).
    pub(super) static HELD_TORQUE_OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}
