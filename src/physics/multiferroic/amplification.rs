//! A step whose Gilbert onion carries its substeps' local errors far beyond the tolerance by the
//! step's end is flagged ([`Motor::errors_amplified`]).
//!
//! The error control holds each resolved substep's local error to the tolerance. An error `e_i`
//! made over substep `i` reaches the step's end as `G_i e_i` to first order, `G_i` the propagator
//! of the linearized flow over the later substeps: the product of their `exp(J_o dt)`, `J_o` the
//! onion's block of the Jacobian of the macrospin's equations (eq. 3.4 plus the tilt's shape
//! anisotropy, [`Motor::onion_relaxation_time`]) at each substep's start. The step's end is then
//! off by at most `sum_i e_i |G_i|` tolerances to first order ([`Amplification::bound`], `|G|`
//! the largest row sum). Where another path interrupts the resolved substeps, `G_i` still runs
//! through every later resolved substep: the errors made before the interruption are amplified
//! by the substeps after it as by those before.
//!
//! Where the onion passes close above a rim of its well (a saddle of the macrospin's energy),
//! the time it takes to pass, and so its angle and tilt after it, depend on its energy there
//! like the logarithm of the energy's margin over the rim: a weakly damped onion spinning just
//! above its rims while the schedule turns the landscape under it passes many rims, and each
//! passage multiplies the errors. `|G|` then grows by many orders of magnitude within a step
//! (an RK4 of the motor's equations started 1e-11 rad away ends 3.4e-3 rad away after 1 us),
//! and the step's end is off by far more than its substeps' errors: resolving it would take a
//! tolerance that many times finer, which the budget cannot pay for. Such a step is flagged as
//! one the budget could not resolve.
//!
//! The bound takes every local error at the tolerance its estimate reports and in the direction
//! the flow amplifies most; ringing onions whose tilt is far stiffer than their well (`|G|` up
//! to `sqrt(T / k)` along the ellipse of their precession) stay within the tolerance at bounds
//! up to about 1e6. Only a bound beyond [`AMPLIFIED_BEYOND`] flags the step. The onion's own
//! block is taken alone: the rotor's coupling to it and the paths that do not resolve the
//! onion's substeps (averaged, settled, linear spans) carry the errors unchanged in the bound.

use super::{Angles, Drive, Motor};
use crate::physics::numerics::expm2::expm2;

type Mat2 = [[f64; 2]; 2];

/// A step whose [`Amplification::bound`] exceeds this many tolerances is flagged.
const AMPLIFIED_BEYOND: f64 = 1e6;

/// The resolved Gilbert substeps of one step: each one's propagator of the onion's angle and
/// tilt and its error estimate in tolerances.
#[derive(Clone, Debug, Default)]
pub(super) struct Amplification {
    substeps: Vec<(Mat2, f64)>,
}

impl Amplification {
    /// `sum_i e_i |G_i|` (tolerances) over the substeps recorded, `|G_i|` the largest row sum of
    /// the product of the propagators of the substeps recorded after substep `i`; a path other
    /// than the resolved substeps between two of them is taken to carry the errors unchanged.
    pub(super) fn bound(&self) -> f64 {
        let mut p: Mat2 = [[1.0, 0.0], [0.0, 1.0]];
        let mut total = 0.0;
        for (phi, err) in self.substeps.iter().rev() {
            let gain = (p[0][0].abs() + p[0][1].abs()).max(p[1][0].abs() + p[1][1].abs());
            // (A NaN flags the step too.)
            if gain.is_nan() || gain > 1e100 {
                total = f64::INFINITY;
                break;
            }
            total += err * gain;
            p = [
                [
                    p[0][0] * phi[0][0] + p[0][1] * phi[1][0],
                    p[0][0] * phi[0][1] + p[0][1] * phi[1][1],
                ],
                [
                    p[1][0] * phi[0][0] + p[1][1] * phi[1][0],
                    p[1][0] * phi[0][1] + p[1][1] * phi[1][1],
                ],
            ];
        }
        total
    }
}

impl Motor {
    /// Records a resolved Gilbert substep over `dt` (s) from a state at angles `angles` under
    /// `d`, its error estimate `err` in tolerances (see [`Amplification`]).
    pub(super) fn record_amplification(
        &self,
        amp: &mut Amplification,
        dt: f64,
        d: &Drive,
        angles: &Angles,
        err: f64,
    ) {
        // The onion's block of the Jacobian ([`Self::rhs_jacobian`]).
        let (_, k_bar) = self
            .ring_bar
            .torque_stiffness_of(angles.sin_offset, angles.cos_offset);
        let curvature = k_bar + 2.0 * self.magnetoelastic_per_stress * d.stress * angles.cos_double;
        let (g, alpha, tilt) = (
            self.llg_rate * dt,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let a = [
            [-g * alpha * curvature, -g * tilt],
            [g * curvature, -g * alpha * tilt],
        ];
        // An exponential beyond the range ([`expm2`]) carries any earlier error beyond
        // [`AMPLIFIED_BEYOND`].
        let propagator = expm2(&a).unwrap_or([[f64::MAX, 0.0], [0.0, f64::MAX]]);
        amp.substeps.push((propagator, err));
    }

    /// Whether the resolved Gilbert substeps' errors recorded in `amp` are carried beyond
    /// [`AMPLIFIED_BEYOND`] tolerances by the step's end (see the module documentation): such a
    /// step is flagged.
    pub(super) fn errors_amplified(&self, amp: &Amplification) -> bool {
        if self.quasi_static() {
            return false;
        }
        let bound = amp.bound();
        #[cfg(test)]
        AMPLIFICATION.with(|c| c.set(bound));
        bound > AMPLIFIED_BEYOND
    }
}

#[cfg(test)]
thread_local! {
    /// The last unflagged step's [`Amplification::bound`] (tests read it).
    pub(super) static AMPLIFICATION: std::cell::Cell<f64> = const { std::cell::Cell::new(0.0) };
}
