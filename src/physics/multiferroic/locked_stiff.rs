//! A locked rotor's creeping onion near the explicit pair's stability limit.
//!
//! With the rotor locked the onion's landscape is frozen and its linearization is the block
//! `g [[-alpha U'', -T], [U'', -alpha T]]` of eq. 3.4 with the Gilbert damping. Where the tilt
//! relaxes faster than the onion turns (`alpha^2 T > 4 |U''|`) the block's eigenvalues are real
//! and far apart: the fast one, the tilt's relaxation near `g alpha T`, is over within a few of
//! its time constants, but it still bounds the explicit Dormand-Prince pair's substep to its
//! stability reach, while the onion creeps downhill over nanoseconds. There the substep is tried
//! first with the exponential RK4 whose linear part is that block
//! ([`Motor::gilbert_exponential_rk4_step`]): the fast mode is taken exactly, so only the
//! landscape's change along the substep, held to its (stricter) error scale, limits the substep.

use super::gilbert::{Linearized, EXPLICIT_REACH};
use super::{Drive, Motor, Vector};

impl Motor {
    /// A locked rotor's exponential RK4 substep ([`Motor::gilbert_exponential_rk4_step`], which
    /// applies only to an onion whose tilt relaxes faster than it turns) where `dt` times the
    /// system's fastest rate ([`Motor::fastest_rate`]) is at least [`STIFF_FROM`] of the explicit
    /// pair's reach, and only where it accepts: the state and its error relative to the
    /// tolerance. `None` elsewhere, and the explicit pair takes the substep as before.
    pub(super) fn locked_stiff_step(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        start: &Linearized,
    ) -> Option<(Vector, f64)> {
        if !d.locked {
            return None;
        }
        // (False for a NaN rate too.)
        let near_limit = dt * self.fastest_rate(&start.j) >= STIFF_FROM * EXPLICIT_REACH;
        if !near_limit {
            return None;
        }
        let (u, err, _) = self.gilbert_exponential_rk4_step(y, dt, d, start)?;
        (err <= 1.0).then_some((u, err))
    }
}

/// The fraction of the explicit pair's stability reach from which a locked rotor's creeping
/// onion tries the exponential RK4 first: there the explicit pair's error estimate is dominated
/// by the fast mode's amplification, and its step-size rule holds the substep near the reach.
const STIFF_FROM: f64 = 0.5;
