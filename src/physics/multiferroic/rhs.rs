//! The motor's ordinary differential equation in `(phi, omega, psi, theta)`: its right-hand side
//! and Jacobian, shared by every substep pair ([`super::integrator`], [`super::gilbert`]).

use super::{Angles, Drive, Motor, Vector};

impl Motor {
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
    pub(super) fn rhs_jacobian(&self, y: &Vector, d: &Drive, dt: f64) -> (Vector, [[f64; 4]; 4]) {
        self.rhs_jacobian_at(y, d, dt, &Angles::exact(y[2], y[0], d.direction))
    }

    /// [`Self::rhs_jacobian`] from the angles at `y`.
    #[inline]
    pub(super) fn rhs_jacobian_at(
        &self,
        y: &Vector,
        d: &Drive,
        dt: f64,
        angles: &Angles,
    ) -> (Vector, [[f64; 4]; 4]) {
        let (tau, k_bar) = self
            .ring_bar
            .torque_stiffness_of(angles.sin_offset, angles.cos_offset);
        self.rhs_jacobian_of(y, d, dt, angles, tau, k_bar)
    }

    /// [`Self::rhs_jacobian_at`] given the ring-bar torque and stiffness there. Inlined: the
    /// 160-byte result went through memory, where the embedded pair uses four of its entries.
    #[inline(always)]
    pub(super) fn rhs_jacobian_of(
        &self,
        y: &Vector,
        d: &Drive,
        dt: f64,
        angles: &Angles,
        tau: f64,
        k_bar: f64,
    ) -> (Vector, [[f64; 4]; 4]) {
        let mut f = [0.0; 4];
        let mut j = [[0.0; 4]; 4];
        let e = self.magnetoelastic_per_stress * d.stress;
        let (s2, c2) = (angles.sin_double, angles.cos_double);
        let k_me = 2.0 * e * c2;
        let quasi = self.quasi_static();
        if !d.locked {
            // One division by the inertia for the whole row.
            let (inv_i, c) = (1.0 / self.inertia, self.drag);
            f[0] = y[1];
            f[1] = (tau + d.load - c * y[1]) * inv_i;
            j[0][1] = 1.0;
            j[1][1] = -c * inv_i;
            if quasi {
                // Onion in equilibrium: bar spring in series with the magnetoelastic spring,
                // k = k_bar k_me / (k_bar + k_me) (implicit function theorem on dU/dpsi = 0).
                // Near a fold the sum vanishes; bound it so the linearization stays finite.
                let sum = (k_bar + k_me).max(0.05 * (k_bar.abs() + k_me.abs()));
                let k_eff = if sum > 0.0 { k_bar * k_me / sum } else { 0.0 };
                j[1][0] = -self.bounded_stiffness(k_eff, dt) * inv_i;
            } else {
                let k = self.bounded_stiffness(k_bar, dt);
                j[1][0] = -k * inv_i;
                j[1][2] = k * inv_i;
            }
        }
        if !quasi {
            let (g, a, t) = (
                self.llg_rate,
                self.params.gilbert_damping,
                self.tilt_stiffness,
            );
            let (d_psi, d_phi) = (k_bar + k_me, -k_bar);
            [f[2], f[3]] = self.onion_rate(tau + e * s2, y[3]);
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

    /// The Gilbert onion's in-plane and tilt rates (the macrospin's Landau-Lifshitz-Gilbert rates,
    /// linear in the tilt) for the energy's gradient `grad` along the onion angle and the tilt
    /// `theta`, shared by the exponential pair's right-hand side and the explicit pair's.
    #[inline(always)]
    pub(super) fn onion_rate(&self, grad: f64, theta: f64) -> [f64; 2] {
        let (g, a, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        [g * (-t * theta - a * grad), g * (grad - a * t * theta)]
    }

    /// The rotor stiffness `k` for the linearization over `dt`: unchanged unless it is negative
    /// and the unstable rate `lambda = (sqrt(c^2 - 4 I k) - c) / (2 I)` of `I x'' + c x' + k x = 0`
    /// times `dt` exceeds 1; then 0 (see [`Self::rhs_jacobian`]).
    pub(super) fn bounded_stiffness(&self, k: f64, dt: f64) -> f64 {
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
}
