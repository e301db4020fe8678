//! The phase error of the orbit-averaged advance ([`Motor::advance_orbits`]) in a well of eq.
//! 3.4 alone ([`Motor::averaged_phase_error`]).
//!
//! The averaged equations advance the phase at the undamped orbit's frequency `1 / P(E)` times
//! the linearization's damping factor `sqrt(1 - alpha^2 (T - k)^2 / (4 k T))` (`orbit.rs`), exact
//! for a linear well at any damping. Along a nonlinear orbit the damped frequency's `O(alpha^2)`
//! part depends on the amplitude: the averaged phase errs per orbit by `alpha^2 f(r, mu)` cycles
//! per cycle (`r = k / T`, `mu = P(E) / P(0) - 1` the orbit's anharmonicity), zero at `mu = 0`.
//! The linearization's shift itself does not bound it: the shift vanishes at `k = T`, and the
//! error exceeds it from a tenth of the rim at `r` of 0.5 to 2 and from 0.7 of it at any `r`.
//!
//! Where the ring-bar coupling of eq. 3.3 is negligible against eq. 3.4, the well is the pendulum
//! `U = |m| sin^2(psi - psi*)` (`m` the magnetoelastic energy's amplitude, the rims `|m|` high):
//! its orbits are one family in `E / |m|`, `mu = 1 / agm(1, sqrt(1 - E / |m|)) - 1` (the complete
//! elliptic integral), and `f` depends on `r` and `mu` alone. Measured per orbit from the lower
//! turning point against a plain RK4 of the macrospin (`orbit_phase_tests.rs`), from `r` = 1e-3
//! to 1e4 and up to 0.7 of the rim, its part even in `alpha` lies within `c1 mu + c2 mu^2 + c3
//! mu^3` ([`envelope`]; `|f| / mu` tends to `1.7 / r` for `r << 1` and to `0.077 r` for
//! `r >> 1`, and changes sign near a fifth of the rim for `r` beyond 10), and all of it, the
//! third-order odd part at the largest loss per orbit the advance takes (5%) included, within
//! 0.9 of the envelope. Twice the envelope is taken as the bound (the energy's own second-order
//! error per orbit, below 2e-3 of the time's, is left to that margin). The energy falls by at
//! least `l` of itself per orbit (the least loss, see [`Motor::advance_orbits`]), and `mu` is
//! convex in the energy through zero: the `n`-th orbit's `mu` is at most `mu0 e^(-n l)`, and `N`
//! orbits gain at most `2 alpha^2 sum_j c_j mu0^j (1 - e^(-j N l)) / (1 - e^(-j l))` cycles.
//! The periods themselves, integrals of `1 / sqrt(E - U + U(psi*))`, err by the energy's rounding
//! at the landscape's scale over `E` (added, `N` times): ringing whose energy is within a
//! few thousand roundoffs of that scale (the quadrature swamped by the rounding) gains nothing.
//! The advance takes the smaller of this bound and the linearization's shift's.

use super::onion::Landscape;
use super::orbit::{Orbit, Well};
use super::Motor;

/// The well is taken as eq. 3.4's pendulum where eq. 3.3's stiffness is at most this fraction of
/// eq. 3.4's curvature `2 |m|` anywhere.
const PENDULUM: f64 = 1e-4;
/// The averaged phase's error is bounded in the pendulum well up to this fraction of the rim
/// (the envelope's reach; beyond it the error grows faster than `mu^3`).
const PENDULUM_REACH: f64 = 0.7;
/// Twice the measured envelope.
pub(super) const SAFETY: f64 = 2.0;
/// The relative error of an orbit's period from its energy `E` rounded at the landscape's
/// scale `|U(psi*)| + rim`: this many units of roundoff of that scale over `E`.
const ROUNDING: f64 = 16.0 * f64::EPSILON;

/// The coefficients `(c1, c2, c3)` of the envelope `c1 mu + c2 mu^2 + c3 mu^3` of the averaged
/// phase's relative error per orbit over `alpha^2` in a pendulum well of `r = k / T`
/// (measured, see the module documentation).
pub(super) fn envelope(r: f64) -> [f64; 3] {
    [
        1.9 / r + 0.5 + 0.085 * r,
        13.0 / r + 25.0 + 2.2 * r,
        65.0 / r + 100.0 + 7.5 * r,
    ]
}

/// The pendulum orbit's anharmonicity `P(E) / P(0) - 1` at `E / |m|` = `frac` in `[0, 1)`:
/// `1 / agm(1, sqrt(1 - frac)) - 1`.
pub(super) fn pendulum_anharmonicity(frac: f64) -> f64 {
    let (mut a, mut b) = (1.0, (1.0 - frac).sqrt());
    for _ in 0..8 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    (1.0 / a - 1.0).max(0.0)
}

impl Motor {
    /// A bound on the phase error (cycles) that the averaged advance gains over `orbits` orbits
    /// from the orbit `o` of `well` in the landscape `land`, its energy falling by at least
    /// `least_loss` of itself per orbit (see the module documentation). `None` where the well
    /// is not eq. 3.4's pendulum or lies beyond [`PENDULUM_REACH`] of its rim (the
    /// linearization's shift alone is taken there, see [`Self::advance_orbits`]).
    pub(super) fn averaged_phase_error(
        &self,
        land: &Landscape,
        well: &Well,
        o: &Orbit,
        orbits: f64,
        least_loss: f64,
    ) -> Option<f64> {
        let m = land.magnetoelastic.abs();
        if !(land.ring_bar.stiffness_bound() <= PENDULUM * 2.0 * m && m > 0.0) {
            return None;
        }
        let frac = o.energy / well.barrier;
        if !((0.0..=PENDULUM_REACH).contains(&frac) && orbits >= 0.0) {
            return None;
        }
        let mu = pendulum_anharmonicity(frac);
        let alpha = self.params.gilbert_damping;
        let r = well.curvature / self.tilt_stiffness;
        // Whole orbits: the last, partial one counted in full.
        let orbits = orbits.ceil();
        let mut cycles = 0.0;
        let mut power = 1.0;
        for (j, c) in envelope(r).iter().enumerate() {
            power *= mu;
            let decay = (j + 1) as f64 * least_loss;
            let sum = if decay > 0.0 {
                -(-decay * orbits).exp_m1() / -(-decay).exp_m1()
            } else {
                orbits
            };
            cycles += c * power * sum;
        }
        // The period's quadrature, from energies rounded at the landscape's scale.
        let rounding = orbits * ROUNDING * (well.floor.abs() + well.barrier) / o.energy;
        let cycles = SAFETY * alpha * alpha * cycles + rounding;
        Some(if cycles.is_finite() {
            cycles
        } else {
            f64::INFINITY
        })
    }
}
