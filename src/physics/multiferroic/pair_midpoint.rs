//! The exponential pair's error estimate from its linearization's defect at the substep's
//! midpoint as well as at its end ([`Motor::gilbert_embedded_step`]).

use super::gilbert::{pade_phi3_apply, Linearized};
use super::{Drive, Motor, Vector};

impl Motor {
    /// The exponential pair's error estimate from its linearization's defect at the substep's
    /// midpoint `u(h/2) = y + half` (`half = h/2 phi_1(hJ/2) F(y)`, the exponential Euler step
    /// over `h/2`), in units of the tolerance: `2 h phi_3(hJ) 4 D(h/2)`, the pair's correction
    /// for a defect growing as `s^2` along the substep (`D(h) = 4 D(h/2)`).
    ///
    /// The pair's own estimate samples the defect `D(s) = F(u(s)) - F(y) - J (u(s) - y)` at the
    /// substep's end only. The defect is quadratic in the onion angle's displacement from the
    /// start (eq. 3.4's landscape is curved in it; the tilt enters the rates linearly), and that
    /// displacement can come back near zero at the end while it was large inside: the angle's
    /// rate reverses under its growing tilt (`psi' = F_psi + J_psi,theta theta`) and it swings
    /// out and back within the substep, or the onion precesses about a whole period back near
    /// its start. The defect is then a hump that nearly vanishes at the end, and the estimate
    /// missed errors of 4 and 128 tolerances (against converged RK4) under estimates of 0.3 and
    /// 0.05. `None` if the half step fails.
    pub(super) fn pair_midpoint_error(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        start: &Linearized,
        half: &Vector,
    ) -> Option<f64> {
        let j = &start.j;
        let mid = self.finish_exponential_step(y, half, d)?;
        let f = self.gilbert_rate(&mid, d, &start.angles.moved(mid[2], mid[0], d.direction));
        let rhs: Vector = std::array::from_fn(|i| {
            let linear: f64 = (0..4).map(|k| j[i][k] * (mid[k] - y[k])).sum();
            8.0 * dt * (f[i] - start.f[i] - linear)
        });
        let correction = pade_phi3_apply(j, dt, &rhs, self.speed_unit())?;
        Some(self.error_norm(|i| correction[i], y, &mid))
    }
}
