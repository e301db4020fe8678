//! The Gilbert onion's error-controlled substeps: the exponential pair, the explicit
//! Dormand-Prince pair while the onion rings, and an exponential RK4 on a stiff rotor or a locked
//! rotor's overdamped onion.

use super::block_phi::locked_onion_increments;
use super::phi::Phi2x2;
use super::{Angles, Drive, Motor, Vector};
use crate::physics::numerics::dormand_prince;

/// The full system's right-hand side `f` and Jacobian `j` at a substep's start for its length,
/// with the angles there: evaluated once and shared by the explicit pair and the exponential
/// one ([`Motor::linearized`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Linearized {
    pub(super) f: Vector,
    pub(super) j: [[f64; 4]; 4],
    pub(super) angles: Angles,
}

impl Motor {
    /// [`Linearized`] at `y` (whose angles are `angles`) for a substep `dt`.
    pub(super) fn linearized(&self, y: &Vector, d: &Drive, dt: f64, angles: &Angles) -> Linearized {
        let (f, j) = self.rhs_jacobian_at(y, d, dt, angles);
        Linearized {
            f,
            j,
            angles: *angles,
        }
    }
}

impl Motor {
    /// The exponential Rosenbrock pair 2(3) of Hochbruck, Ostermann and Schweitzer (exprb32, SIAM
    /// J. Numer. Anal. 47, 2009) on the full system `(phi, omega, psi, theta)` of the Gilbert
    /// onion: the exponential Euler step `u1 = y + h phi_1(hJ) F(y)` (one 4x4 exponential with
    /// its `phi_1` column, as [`Self::exponential_step`]), then with the linearization's defect
    /// `D = F(u1) - F(y) - J (u1 - y)` the correction `2 h phi_3(hJ) D`, which is the error
    /// estimate of `u1` and, within the tolerance, is added to it (as in the quasi-static
    /// rotor's [`Self::embedded_step`]). A locked rotor's stiff onion block takes `u1` in closed
    /// form from its eigenvalues instead ([`locked_onion_increments`]), which keeps its slow
    /// mode's decay where the 4x4 exponential's rounding would not.
    ///
    /// `phi_3(hJ)` is taken as its (0,1) Padé approximant `(6 I - 1.5 hJ)^-1`, one 4x4 solve
    /// instead of a second (7x7) exponential: it matches `phi_3` to second order at 0, and over
    /// the closed left half-plane (damped rotor and precessing onion alike) its modulus stays
    /// within 0.96 to 1.33 times `|phi_3|` (both fall as `1/|z|` far out). The correction is of
    /// order `h^3` where the exact one is, so the step size control is unchanged
    /// ([`super::integrator::step_factor`]). Step doubling took two exponentials (one of them
    /// squared) and three Jacobians per substep. `None` when the step or the solve fails (the
    /// caller then falls back to step doubling); the error is relative to the tolerance.
    pub(super) fn gilbert_embedded_step(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        start: &Linearized,
    ) -> Option<(Vector, f64)> {
        let (f0, j) = (start.f, start.j);
        let unit = self.speed_unit();
        let (closed_form, rounding) = if d.locked {
            locked_onion_increments(&f0, &j, dt)
        } else {
            (None, 0.0)
        };
        let (half, increments) = match closed_form {
            Some(increments) => increments,
            None => self.increments_of::<4>(&f0, &j, dt, true, unit)?,
        };
        let u1 = self.finish_exponential_step(y, &increments, d)?;
        // A locked onion's stiff block without the closed form: the exponential's rounding.
        let exponential_rounding = |i: usize| match i {
            0 | 1 => 0.0,
            _ => {
                let scale = |k: usize| increments[k].abs().max(dt * f0[k].abs());
                rounding * scale(2).max(scale(3))
            }
        };
        let f1 = self.gilbert_rate(&u1, d, &start.angles.moved(u1[2], u1[0], d.direction));
        let step: Vector = std::array::from_fn(|i| u1[i] - y[i]);
        let rhs: Vector = std::array::from_fn(|i| {
            let linear: f64 = (0..4).map(|k| j[i][k] * step[k]).sum();
            2.0 * dt * (f1[i] - f0[i] - linear)
        });
        let correction = pade_phi3_apply(&j, dt, &rhs, unit)?;
        let mut u3 = u1;
        for (x, c) in u3.iter_mut().zip(correction) {
            *x += c;
        }
        let u3 = self.checked_end(u3, y, d.locked)?;
        let err = self
            .error_norm(|i| correction[i], y, &u3)
            .max(self.pair_midpoint_error(y, dt, d, start, &half?)?);
        let err = if rounding > 0.0 {
            err + self.error_norm(exponential_rounding, y, &u3)
        } else {
            err
        };
        // Beyond the tolerance the correction is no longer small and the substep, if taken at
        // all (forced at the budget's minimum size), is the exponential Euler step, which is
        // exact for the linear part and cannot amplify (see [`Self::rhs_jacobian`]).
        match err.is_finite() {
            true if err <= 1.0 => Some((u3, err)),
            true => Some((u1, err)),
            false => None,
        }
    }
}

impl Motor {
    /// An explicit Dormand-Prince 5(4) substep of the full system (Dormand and Prince, J. Comput.
    /// Appl. Math. 6, 1980), for the Gilbert onion's ringing: seven right-hand sides and no
    /// exponential. While the onion precesses far from its minimum the exponential pair's
    /// linearization is good for a small fraction of a precession period only, so its substeps
    /// are short anyway; there the explicit pair's fifth order takes substeps several times
    /// longer, each a few times cheaper. It is tried only where `dt` times the system's fastest
    /// rate ([`Self::fastest_rate`]) is within [`EXPLICIT_REACH`], inside the method's stability
    /// region; a forced substep (taken whatever its error) takes the exponential pair, which
    /// cannot amplify. `None` outside its reach or when the step fails. The error is returned as
    /// `err^(5/8)` ([`fifth_order_error`]): the integrator's step-size rule is the second-order
    /// pair's `err^(-1/3)`, and this makes it `err^(-5/24)`, about the fifth order's `err^(-1/5)`.
    pub(super) fn gilbert_explicit_step(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        start: &Linearized,
    ) -> Option<(Vector, f64)> {
        let k1 = start.f;
        // (False for a NaN rate too.)
        let within_reach = dt * self.fastest_rate(&start.j) <= EXPLICIT_REACH;
        if !within_reach {
            return None;
        }
        // Each stage's angles turned from the start's (see [`Angles::moved`]).
        let rate = |z: &Vector| {
            Some(self.gilbert_rate(z, d, &start.angles.moved(z[2], z[0], d.direction)))
        };
        let (u, k) = dormand_prince::step(y, &k1, dt, rate)?;
        let u = self.checked_end(u, y, d.locked)?;
        let err = self.error_norm(|i| dormand_prince::error(dt, &k, i), y, &u);
        err.is_finite().then(|| (u, fifth_order_error(err)))
    }

    /// A substep's end `u` with a locked rotor put back where it was (`y`'s angle, at rest);
    /// `None` if the rotor or the onion is not sane there.
    pub(super) fn checked_end(&self, mut u: Vector, y: &Vector, locked: bool) -> Option<Vector> {
        if locked {
            u[0] = y[0];
            u[1] = 0.0;
        }
        (self.rotor_sane(&u) && Self::onion_sane(&u)).then_some(u)
    }

    /// The error estimate `e` of a substep from `y` to `u` in units of the tolerance: the
    /// largest `|e_i|` over the angles' tolerance and the speed's on its scale, the latter no
    /// finer than [`SPEED_ROUNDING`] of the speed. (A motor whose ring barely holds its bar has an
    /// undamped frequency, the speed's scale, of 1e-4 rad/s and less: at a load's 500 rad/s its
    /// speed's tolerance fell below the speed's own rounding, and the error estimates, then
    /// rounding noise, held the substeps to picoseconds.)
    pub(super) fn error_norm(&self, e: impl Fn(usize) -> f64, y: &Vector, u: &Vector) -> f64 {
        let tol = self.params.tolerance;
        let speed = (tol * self.speed_scale).max(SPEED_ROUNDING * y[1].abs().max(u[1].abs()));
        let scales = [tol, speed, tol, tol];
        (0..4).map(|i| e(i).abs() / scales[i]).fold(0.0, f64::max)
    }

    /// The right-hand side of [`Self::rhs_jacobian`] alone, for the Gilbert onion, from the
    /// angles at `y`.
    #[inline]
    pub(super) fn gilbert_rate(&self, y: &Vector, d: &Drive, a: &Angles) -> Vector {
        let (tau, _) = self
            .ring_bar
            .torque_stiffness_of(a.sin_offset, a.cos_offset);
        let grad = tau + self.magnetoelastic_per_stress * d.stress * a.sin_double;
        let rotor = if d.locked {
            [0.0, 0.0]
        } else {
            [y[1], (tau + d.load - self.drag * y[1]) / self.inertia]
        };
        let [onion, tilt] = self.onion_rate(grad, y[3]);
        [rotor[0], rotor[1], onion, tilt]
    }

    /// A bound on the moduli of the eigenvalues of the Jacobian `j` (1/s): the onion block's
    /// `|trace| + sqrt(|det|)` (its eigenvalues' sum and product), the rotor's drag rate and
    /// undamped frequency, and the onion's rates per rotor turn. The explicit pair's stability needs `dt` times it
    /// within [`EXPLICIT_REACH`].
    pub(super) fn fastest_rate(&self, j: &[[f64; 4]; 4]) -> f64 {
        let onion_trace = (j[2][2] + j[3][3]).abs();
        let onion_det = (j[2][2] * j[3][3] - j[2][3] * j[3][2]).abs();
        let rotor = j[1][1].abs() + j[1][0].abs().sqrt() + j[1][2].abs().sqrt();
        let coupling = j[2][0].abs() + j[3][0].abs();
        onion_trace + onion_det.sqrt() + rotor + coupling
    }
}

impl Motor {
    /// A substep by the exponential Runge-Kutta method of Cox and Matthews (ETDRK4, J. Comput.
    /// Phys. 176, 2002). A free rotor takes both diagonal blocks of the Jacobian as its linear
    /// part ([`Self::gilbert_block_etd_step`]) wherever their `phi` functions are available;
    /// elsewhere (an onion block with nearly repeated eigenvalues) it takes the rotor's
    /// linearization at the start, `L = [[0, 1], [-k/I, -c/I]]`,
    /// exactly and everything else (the onion, the torque's change along the substep) as
    /// its nonlinear part, for the Gilbert onion's ringing on a stiff rotor: a viscous fluid puts
    /// the rotor's drag rate `c/I` far above the onion's precession, which keeps the explicit pair
    /// ([`Self::gilbert_explicit_step`]) out of reach and left the second-order exponential pair
    /// to resolve the ringing with many short substeps. On the onion (where `L` is zero) the
    /// method is classical RK4, so it is tried where `dt` times the onion's rates
    /// ([`Self::onion_rate_bound`]) is within [`ETD_REACH`]; the rotor's stiff modes are in `L`,
    /// the `phi` functions of its 2x2 block in closed form ([`Phi2x2`]). The error is step
    /// doubling's (one full step against two halves, which share the start's stage), taken
    /// whole rather than divided by `2^4 - 1`, so that an order lost to stiffness cannot hide;
    /// the two halves are the result. Returned as `err^(5/8)`, as the explicit pair's (about the
    /// fourth order's `err^(-1/5)` step rule), with whether the exponential pair is worth a retry
    /// where it rejects ([`Self::gilbert_block_etd_step`] says for itself). `None` out of reach,
    /// for an underdamped block (complex eigenvalues) or when the step fails.
    ///
    /// With the rotor locked `L` is the onion's own block `g [[-alpha U'', -T], [U'', -alpha T]]`
    /// (eq. 3.4's landscape frozen) and the rest, the change of the landscape's curvature along
    /// the substep, is explicit: it is tried where the explicit pair is out of reach or near its
    /// stability limit ([`Self::locked_stiff_step`]) and the onion's tilt relaxes faster than it
    /// turns (`alpha^2 T > 4 |U''|`, real eigenvalues): an onion that creeps downhill over its
    /// wells' rims after a release far from its minimum, where the second-order pair takes about
    /// a thousand substeps a microsecond at tolerances
    /// near 2e-10 rad. Its error estimate is held to [`LOCKED_ETD_ERROR_SCALE`] times
    /// less.
    pub(super) fn gilbert_exponential_rk4_step(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        start: &Linearized,
    ) -> Option<(Vector, f64, bool)> {
        let j = &start.j;
        // A free rotor's onion block is part of the linear part wherever its `phi` functions
        // are available.
        if let Some(result) = self.gilbert_block_etd_step(y, dt, d, start) {
            return result;
        }
        // With the rotor locked the onion's own block is the linear part (its rates then all
        // in it); otherwise the rotor's, the onion's rates within the explicit reach.
        // (False for a NaN rate too.)
        let within_reach = d.locked || dt * self.onion_rate_bound(j) <= ETD_REACH;
        if !within_reach {
            return None;
        }
        if d.locked {
            // A locked onion's block is taken only where its tilt relaxes faster than the onion
            // turns, `alpha^2 T > 4 |U''|` (the block's eigenvalues real whatever the
            // curvature's sign; `U''` is its (3, 2) entry over `g`): where it rings, the
            // exponential RK4 takes no fewer substeps than the exponential pair, each costing
            // more.
            let (alpha, t) = (self.params.gilbert_damping, self.tilt_stiffness);
            let curvature = j[3][2] / self.llg_rate;
            if curvature.is_nan() || alpha * alpha * t <= 4.0 * curvature.abs() {
                return None;
            }
        }
        let b = if d.locked { 2 } else { 0 };
        let block = |h: f64| {
            [
                [h * j[b][b], h * j[b][b + 1]],
                [h * j[b + 1][b], h * j[b + 1][b + 1]],
            ]
        };
        let (full, half, quarter) = (block(dt), block(0.5 * dt), block(0.25 * dt));
        let phi_full = Phi2x2::new(&full)?;
        let phi_half = Phi2x2::new(&half)?;
        let phi_quarter = Phi2x2::new(&quarter)?;
        let rate =
            |z: &Vector| self.gilbert_rate(z, d, &start.angles.moved(z[2], z[0], d.direction));
        // The block's index is a constant of each instance (the free rotor's substeps are the
        // hot path of viscous motors).
        let etd = |y0: &Vector, f0: Vector, h: f64, half, full| {
            if d.locked {
                self.etd_rk4::<2>(y0, f0, h, j, half, full, rate)
            } else {
                self.etd_rk4::<0>(y0, f0, h, j, half, full, rate)
            }
        };
        let whole = etd(y, start.f, dt, (&phi_half, &half), (&phi_full, &full));
        let first = etd(
            y,
            start.f,
            0.5 * dt,
            (&phi_quarter, &quarter),
            (&phi_half, &half),
        );
        let two = etd(
            &first,
            rate(&first),
            0.5 * dt,
            (&phi_quarter, &quarter),
            (&phi_half, &half),
        );
        let u = self.checked_end(two, y, d.locked)?;
        let scale = if d.locked {
            LOCKED_ETD_ERROR_SCALE
        } else {
            1.0
        };
        let err = scale * self.error_norm(|i| two[i] - whole[i], y, &u);
        err.is_finite().then(|| (u, fifth_order_error(err), true))
    }

    /// One ETDRK4 step of `h` from `y0` (where the rate is `f0`) with the 2x2 block of `j` at
    /// `(B, B)` as the linear part `L` (the rotor's at 0, the onion's at 2); `half` and `full`
    /// are its `phi` functions at `h L / 2` and `h L` with those matrices. With `u` the
    /// deviation from `y0` and `N(u) = F(y0 + u) - L u`:
    /// `a = h/2 phi_1(z/2) N(0)`, `b = h/2 phi_1(z/2) N(a)`,
    /// `c = e^(z/2) a + h/2 phi_1(z/2) (2 N(b) - N(0))` and the end
    /// `h [phi_1 N(0) + phi_2 (2 N(a) + 2 N(b) - N(c) - 3 N(0)) + 4 phi_3 D]` with
    /// `D = N(0) - N(a) - N(b) + N(c)` (`phi_k` at `z = h L`; at `L = 0`, on the other block,
    /// this is classical RK4).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn etd_rk4<const B: usize>(
        &self,
        y0: &Vector,
        f0: Vector,
        h: f64,
        j: &[[f64; 4]; 4],
        half: (&Phi2x2, &[[f64; 2]; 2]),
        full: (&Phi2x2, &[[f64; 2]; 2]),
        rate: impl Fn(&Vector) -> Vector,
    ) -> Vector {
        // phi_k of the linear part (the block at B; zero on the other) applied to v.
        let apply = |(p, a): (&Phi2x2, &[[f64; 2]; 2]), k: u32, v: &Vector| -> Vector {
            let [r0, r1] = p.apply(k, a, [v[B], v[B + 1]]);
            let other = [1.0, 0.5, 1.0 / 6.0][k as usize - 1];
            if B == 0 {
                [r0, r1, other * v[2], other * v[3]]
            } else {
                [other * v[0], other * v[1], r0, r1]
            }
        };
        let n = |u: &Vector| -> Vector {
            let mut f = rate(&std::array::from_fn(|i| y0[i] + u[i]));
            f[B] -= j[B][B] * u[B] + j[B][B + 1] * u[B + 1];
            f[B + 1] -= j[B + 1][B] * u[B] + j[B + 1][B + 1] * u[B + 1];
            f
        };
        let scaled = |c: f64, v: Vector| -> Vector { v.map(|x| c * x) };
        let n0 = f0;
        let a = scaled(0.5 * h, apply(half, 1, &n0));
        let na = n(&a);
        let b_stage = scaled(0.5 * h, apply(half, 1, &na));
        let nb = n(&b_stage);
        // e^(z/2) a = a + (z/2) phi_1(z/2) a, with z/2 the half matrix on the block.
        let pa = apply(half, 1, &a);
        let ha = half.1;
        let mut ea = a;
        ea[B] += ha[0][0] * pa[B] + ha[0][1] * pa[B + 1];
        ea[B + 1] += ha[1][0] * pa[B] + ha[1][1] * pa[B + 1];
        let forcing: Vector = std::array::from_fn(|i| 2.0 * nb[i] - n0[i]);
        let c_half = scaled(0.5 * h, apply(half, 1, &forcing));
        let c: Vector = std::array::from_fn(|i| ea[i] + c_half[i]);
        let nc = n(&c);
        let second: Vector =
            std::array::from_fn(|i| 2.0 * na[i] + 2.0 * nb[i] - nc[i] - 3.0 * n0[i]);
        let third: Vector = std::array::from_fn(|i| 4.0 * (n0[i] - na[i] - nb[i] + nc[i]));
        let (p1, p2, p3) = (
            apply(full, 1, &n0),
            apply(full, 2, &second),
            apply(full, 3, &third),
        );
        std::array::from_fn(|i| y0[i] + h * (p1[i] + p2[i] + p3[i]))
    }

    /// A bound on the moduli of the rates that the exponential RK4 substep
    /// ([`Self::gilbert_exponential_rk4_step`]) treats explicitly (1/s): the onion block's
    /// `|trace| + sqrt(|det|)`, its rates per rotor turn, and the loop through the rotor, which
    /// answers the onion's torque over its drag: the rotor's relaxation rate `k/c` and
    /// `sqrt(|d psi'/d phi| (k/I) / (c/I))`. Infinite for a rotor without drag.
    fn onion_rate_bound(&self, j: &[[f64; 4]; 4]) -> f64 {
        let onion_trace = (j[2][2] + j[3][3]).abs();
        let onion_det = (j[2][2] * j[3][3] - j[2][3] * j[3][2]).abs();
        let coupling = j[2][0].abs() + j[3][0].abs();
        let drag_rate = j[1][1].abs();
        let relaxation = j[1][0].abs() / drag_rate;
        let through_rotor = (coupling * j[1][2].abs() / drag_rate).sqrt();
        onion_trace + onion_det.sqrt() + coupling + relaxation + through_rotor
    }
}

/// `err^(5/8)` by three square roots (libm's `pow` was 5% of a Gilbert step): the error of a
/// fifth- or fourth-order substep in the second-order step-size rule's terms (see
/// [`Motor::gilbert_explicit_step`]); 1 at 1, increasing, so acceptance (`<= 1`) is unchanged.
pub(super) fn fifth_order_error(err: f64) -> f64 {
    let root = err.sqrt();
    root * root.sqrt().sqrt()
}

/// The finest speed error (relative to the speed) that the Gilbert substeps' error norm asks
/// for: 64 ulp, about the rounding that a substep's sums of stages leave in the speed.
const SPEED_ROUNDING: f64 = 64.0 * f64::EPSILON;

/// The longest exponential RK4 substep relative to the onion's rates (see
/// [`Motor::gilbert_exponential_rk4_step`]): classical RK4's stability region reaches about 2.8
/// along the negative real axis and the imaginary one.
const ETD_REACH: f64 = 2.5;

/// A locked rotor's exponential RK4 substep holds its error estimate to 1/this of the
/// tolerance: along an overdamped onion's creep over the rims of its wells the substeps' errors
/// add up (at the tolerance itself a 1 us step ended 2.6 tolerances off a fine RK4; the
/// second-order pair, at many more substeps, 1.3; at a sixteenth 0.45).
const LOCKED_ETD_ERROR_SCALE: f64 = 16.0;

/// The longest explicit substep relative to the fastest rate (see
/// [`Motor::gilbert_explicit_step`]): Dormand-Prince 5(4)'s stability region reaches about 3.3
/// along the negative real axis and 3.4 along the imaginary one.
pub(super) const EXPLICIT_REACH: f64 = 3.0;

/// `(6 I - 1.5 dt J)^-1 v`, the (0,1) Padé approximant of `phi_3(dt J)` applied to `v`, solved
/// with the speed in units of `unit` (as the exponential is balanced, see
/// [`Motor::exponential_increments`]) by Gaussian elimination with partial pivoting; `None` if
/// the matrix is singular or the result not finite. Hand-written: one fixed 4x4 solve per
/// Gilbert substep, on the hot path, where the library has no linear-algebra dependency.
pub(super) fn pade_phi3_apply(j: &[[f64; 4]; 4], dt: f64, v: &Vector, unit: f64) -> Option<Vector> {
    let scale = |i: usize| if i == 1 { unit } else { 1.0 };
    let mut m = [[0.0; 5]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (k, x) in row.iter_mut().take(4).enumerate() {
            let identity = if i == k { 6.0 } else { 0.0 };
            *x = identity - 1.5 * dt * j[i][k] * scale(k) / scale(i);
        }
        row[4] = v[i] / scale(i);
    }
    for col in 0..4 {
        let pivot = (col..4).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        m.swap(col, pivot);
        let p = m[col][col];
        if !(p.abs() > 0.0 && p.is_finite()) {
            return None;
        }
        let pivot_row = m[col];
        for row in m.iter_mut().skip(col + 1) {
            let factor = row[col] / p;
            for (x, y) in row.iter_mut().zip(&pivot_row).skip(col) {
                *x -= factor * y;
            }
        }
    }
    let mut x = [0.0; 4];
    for i in (0..4).rev() {
        let known: f64 = (i + 1..4).map(|k| m[i][k] * x[k]).sum();
        x[i] = (m[i][4] - known) / m[i][i];
    }
    let out: Vector = std::array::from_fn(|i| x[i] * scale(i));
    out.iter().all(|c| c.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::super::ringing::Rims;
    use super::super::tests::{motor_with, rk4_step, schedule};
    use super::super::{Angles, Drive, MotorInputs, MotorState, OnionModel, Vector};
    use super::pade_phi3_apply;

    /// The Gilbert onion across its declared damping from 0.003 up, on the stepping schedule (20
    /// us periods) at the FMU's default 1 us step with the default budget: the ringing after each
    /// of three switches (about 7 tau_o: 43 ns at 0.003, 13 ns at 0.01, 2.9 ns at nickel's 0.045)
    /// fits the budget, so no step is accuracy-limited (no fmi2Warning), and the rotor is that of
    /// a run at a thousandth of the tolerance within 1e-5 rad at every step.
    #[test]
    fn gilbert_onion_at_one_microsecond_needs_no_forced_substep_from_damping_0_003() {
        for alpha in [0.003, 0.01, 0.045, 0.3, 1.0] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.gilbert_damping = alpha;
            });
            let fine = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.gilbert_damping = alpha;
                p.tolerance = 1e-9;
                p.max_substeps = 10_000_000;
            });
            let inputs = schedule(20e-6);
            let (mut s, mut r) = (MotorState::aligned(0.0), MotorState::aligned(0.0));
            let mut worst: f64 = 0.0;
            for _ in 0..60 {
                let report = m.step(&mut s, &inputs, 1e-6).unwrap();
                assert!(
                    !report.accuracy_limited,
                    "{alpha}: t = {}: {report:?}",
                    s.time
                );
                fine.step(&mut r, &inputs, 1e-6).unwrap();
                worst = worst.max((s.rotor_angle - r.rotor_angle).abs());
            }
            println!(
                "damping {alpha}: rotor {} rad, worst {worst:e} rad",
                s.rotor_angle
            );
            assert!(worst < 1e-5, "{alpha}: {worst}");
            // It stepped: two 60-degree steps done and the third one under way.
            assert!(s.rotor_angle > 2.5, "{alpha}: {s:?}");
        }
    }

    /// A Gilbert onion whose budget cannot pay for a substep (`max_substeps` below its weight, or
    /// spent) follows its quasi-static branch, flagged, rather than take a forced substep across
    /// the step: the rotor never turns faster than drag allows, `max(|omega_0|, (tau_max +
    /// |load|) / c)` with `tau_max` the ring's largest torque (sampled here), on the schedule's
    /// first switches at the FMU's 1 us step. (A forced Gilbert substep over the first 1 us
    /// reached 1.4 times that speed.)
    #[test]
    fn gilbert_onion_without_budget_follows_its_branch_within_the_drag_limit() {
        for budget in [1, 2, 3, 4, 5, 8, 16] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.max_substeps = budget;
            });
            let tau_max = (0..=20_000)
                .map(|k| {
                    m.ring_bar
                        .torque_stiffness(k as f64 * 1e-4 * std::f64::consts::PI)
                        .0
                        .abs()
                })
                .fold(0.0, f64::max);
            let inputs = schedule(20e-6);
            let mut s = MotorState::aligned(0.0);
            for _ in 0..60 {
                let before = s;
                let report = m.step(&mut s, &inputs, 1e-6).unwrap();
                let limit = before.rotor_speed.abs().max(tau_max / m.drag);
                assert!(
                    s.rotor_speed.abs() <= limit * (1.0 + 1e-9),
                    "{budget}: {s:?} {limit}"
                );
                assert!(
                    (s.rotor_angle - before.rotor_angle).abs() <= limit * 1e-6 * (1.0 + 1e-9),
                    "{budget}: {before:?} -> {s:?}"
                );
                if budget < 4 {
                    assert!(report.accuracy_limited, "{budget}: {report:?}");
                }
            }
            // Still a motor: it took its first steps of 60 degrees.
            assert!(s.rotor_angle > 2.0, "{budget}: {s:?}");
        }
    }

    /// Fine classical RK4 of the full nonlinear system from `y` over `span` in steps of `h`,
    /// calling `visit` with every state.
    fn rk4(
        m: &super::super::Motor,
        d: &Drive,
        y: Vector,
        span: f64,
        h: f64,
        mut visit: impl FnMut(&Vector),
    ) -> Vector {
        let rate = |z: &Vector| m.rhs_jacobian(z, d, h).0;
        let mut z = y;
        for _ in 0..(span / h).ceil() as usize {
            z = rk4_step(&rate, &z, h);
            visit(&z);
        }
        z
    }

    /// The trap of [`Motor::trapped_ringing`] against a fine RK4 of the full LLG with the rotor
    /// locked (the landscape frozen), from onions released all around the turn with and without
    /// tilt: every onion it calls trapped (near the minimum and out to the rims of its well)
    /// stays within its amplitude bound of the minimum and ends there; some it does not call
    /// trapped leave the well, so the check can tell.
    #[test]
    fn trapped_ringing_stays_in_its_well() {
        for alpha in [0.05, 0.3] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.gilbert_damping = alpha;
                // A slow rotor, so that the onion relaxes within a tenth of its time.
                p.fluid_viscosity = 1.0;
            });
            let d = Drive {
                direction: -0.7,
                applied_direction: -0.7,
                stress: 2e8,
                load: 0.0,
                locked: true,
            };
            let land = m.landscape(0.0, d.direction, d.stress);
            let (_, j) = m.rhs_jacobian(&[0.0, 0.0, land.settle(0.0), 0.0], &d, 1e-12);
            let norm = (2..4)
                .map(|i| (2..4).map(|k| j[i][k].abs()).sum::<f64>())
                .fold(0.0, f64::max);
            let h = 0.01 / norm;
            let span = 40.0 * m.onion_relaxation_time();
            let (mut near, mut rims, mut escaped) = (0, 0, 0);
            for i in 0..24 {
                for tilt in [0.0, 0.05, -0.3] {
                    let start = match i {
                        0..=3 => land.settle(0.0) + [0.01, -0.02, 0.1, -0.15][i],
                        _ => -3.1 + 0.27 * i as f64,
                    };
                    let y: Vector = [0.0, 0.0, start, tilt];
                    let settled = land.settle(y[2]);
                    let mut rim = Rims::NONE;
                    let trapped = m
                        .trapped_ringing(&y, &d, settled, Some((&mut rim, 0.0)))
                        .map(|t| (t.amplitude, t.rate));
                    let mut reach: f64 = 0.0;
                    let end = rk4(&m, &d, y, span, h, |z| {
                        reach = reach.max((z[2] - settled).abs());
                    });
                    let left = (end[2] - settled).abs();
                    match trapped {
                        Some((amplitude, _)) => {
                            assert!(
                                reach <= amplitude * (1.0 + 1e-9) && left < 1e-6,
                                "{alpha}: {y:?}: reached {reach} (bound {amplitude}), ended {left} from the minimum"
                            );
                            if amplitude < 0.25 {
                                near += 1;
                            } else {
                                rims += 1;
                            }
                        }
                        None => escaped += usize::from(left > 0.5),
                    }
                }
            }
            println!("damping {alpha}: {near} trapped near the minimum, {rims} out to the rims, {escaped} untrapped left the well");
            assert!(
                near > 0 && rims > 0 && escaped > 0,
                "{alpha}: {near} {rims} {escaped}"
            );
        }
    }

    /// Table 3.1's first 1 us step on the schedule at `gilbert_damping` 0.003, the lightest
    /// damping whose ringing fits a step's budget, against a fine RK4 of the full macrospin and
    /// rotor written here: not accuracy-limited, rotor and onion within the tolerance of it
    /// (2e-8 and 1e-8 rad; following the branch may drop a lag of up to `tau_o` times the
    /// rotor's fastest speed, 3.3e-4 rad here, see [`Motor::relaxed_onion`], but by the step's
    /// end the rotor has slowed down).
    #[test]
    fn gilbert_ringing_at_damping_0_003_against_rk4() {
        let m = motor_with(|p| {
            p.onion_model = OnionModel::Gilbert;
            p.gilbert_damping = 0.003;
        });
        let inputs = schedule(20e-6);
        let mut s = MotorState::aligned(0.0);
        let report = m.step(&mut s, &inputs, 1e-6).unwrap();
        assert!(!report.accuracy_limited, "{report:?}");
        let d = m.drive_at(&inputs, 0.0);
        let y0: Vector = [0.0, 0.0, 0.0, 0.0];
        let (_, j) = m.rhs_jacobian(&y0, &d, 1e-12);
        let norm = (2..4)
            .map(|i| (2..4).map(|k| j[i][k].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let n = (1e-6 * norm / 0.05).ceil();
        let mut fastest: f64 = 0.0;
        let truth = rk4(&m, &d, y0, 1e-6, 1e-6 / n, |z| {
            fastest = fastest.max(z[1].abs())
        });
        let tol = m.params.tolerance;
        let lag = m.onion_relaxation_time() * fastest;
        println!(
            "{} substeps: rotor {} against {} (lag bound {lag:e}), onion {} against {}",
            report.substeps, s.rotor_angle, truth[0], s.onion_angle, truth[2]
        );
        assert!((s.rotor_angle - truth[0]).abs() <= tol, "{s:?} {truth:?}");
        assert!((s.onion_angle - truth[2]).abs() <= tol, "{s:?} {truth:?}");
    }

    /// A locked rotor on Table 3.1's schedule: the ringing after the first switch is dropped
    /// once trapped where it dies out within the rest of its segment, and kept where it does
    /// not; a step of 1 us ends with the onion and its tilt within the tolerance of a fine RK4
    /// of the locked onion run for 60 decay times.
    #[test]
    fn locked_rotor_drops_trapped_ringing_that_dies_out_within_the_step() {
        for alpha in [0.01, 0.045, 0.3] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.gilbert_damping = alpha;
            });
            let inputs = MotorInputs {
                rotor_locked: true,
                ..schedule(20e-6)
            };
            let d = Drive {
                locked: true,
                ..m.drive_at(&inputs, 0.0)
            };
            let y0: Vector = [0.0, 0.0, 0.0, 0.0];
            let (_, j) = m.rhs_jacobian(&y0, &d, 1e-12);
            let norm = (2..4)
                .map(|i| (2..4).map(|k| j[i][k].abs()).sum::<f64>())
                .fold(0.0, f64::max);
            let h = 0.02 / norm;
            // Right after the switch the onion is trapped out to the rims of its new well, too
            // far out for the rotor-based bounds: dropped where it dies out within the rest of
            // the segment (the schedule's 20 us), kept where it does not (1 ps).
            let settled = m.settle(&y0, &d);
            for (remaining, dropped) in [(20e-6, true), (1e-12, false)] {
                let mut rims = Rims::NONE;
                let kick = m.averaged_ringing(&y0, &d, settled, &mut rims, remaining);
                assert_eq!(kick.is_some(), dropped, "{alpha}: {remaining}: {kick:?}");
            }
            // One long step, against the ringing run out.
            let mut s = MotorState::aligned(0.0);
            let report = m.step(&mut s, &inputs, 1e-6).unwrap();
            let span = 60.0 * m.onion_relaxation_time();
            let truth = rk4(&m, &d, y0, span, h, |_| {});
            let error = (s.onion_angle - truth[2])
                .abs()
                .max((s.onion_tilt - truth[3]).abs());
            println!(
                "damping {alpha}: 1 us step in {} substeps, onion {} against {}, error {error:e}",
                report.substeps, s.onion_angle, truth[2]
            );
            assert!(error <= m.params.tolerance, "{alpha}: {error:e}");
            assert!(!report.accuracy_limited, "{alpha}");
        }
    }

    /// Table 3.1's motor in a fluid 100 and 1000 times as viscous as water (rotor relaxation 0.3
    /// and 3 ms, against the onion's 0.1-2 ns: its ringing after a switch is averaged out once
    /// trapped) on a 20 us schedule at the FMU's 1 us step, against a resolved run (a thousandth
    /// of the tolerance, whose averaging bound is a thousand times tighter, and an unbounded
    /// budget), across dampings and loads: the rotor stays within the tolerance of the resolved
    /// one (within 1e-8 rad in fact) while it swings hundreds of times further.
    #[test]
    fn averaged_ringing_keeps_the_rotor_of_a_resolved_run() {
        for (viscosity, alpha, load) in [
            (0.1, 0.01, 0.0),
            (0.1, 0.045, 0.0),
            (0.1, 0.3, 0.0),
            (1.0, 0.045, 0.0),
            (1.0, 0.045, 1e-18),
            (0.1, 0.045, -3e-18),
        ] {
            let with = |tolerance: f64, budget: u32| {
                motor_with(|p| {
                    p.onion_model = OnionModel::Gilbert;
                    p.gilbert_damping = alpha;
                    p.fluid_viscosity = viscosity;
                    p.tolerance = tolerance;
                    p.max_substeps = budget;
                })
            };
            let (m, fine) = (with(1e-6, 20_000), with(1e-9, 10_000_000));
            let inputs = MotorInputs {
                load_torque: load,
                ..schedule(20e-6)
            };
            let (mut s, mut r) = (MotorState::aligned(0.0), MotorState::aligned(0.0));
            let (mut worst, mut swing, mut cost, mut fine_cost, mut flagged) =
                (0.0f64, 0.0f64, 0, 0, 0);
            for _ in 0..60 {
                let report = m.step(&mut s, &inputs, 1e-6).unwrap();
                flagged += usize::from(report.accuracy_limited);
                cost += report.substeps;
                fine_cost += fine.step(&mut r, &inputs, 1e-6).unwrap().substeps;
                worst = worst.max((s.rotor_angle - r.rotor_angle).abs());
                swing = swing.max(r.rotor_angle.abs());
            }
            println!(
                "viscosity {viscosity}, damping {alpha}, load {load:e}: swing {swing:e} rad, worst {worst:e} rad, {cost} substeps, {flagged} flagged (resolved run {fine_cost})"
            );
            assert!(worst < 1e-6, "{alpha} {load}: {worst}");
            assert!(swing > 5e-4, "{alpha} {load}: {swing}");
        }
    }

    /// The kick [`Motor::averaged_ringing`] gives the rotor for small ringing is the ring-bar
    /// stiffness times the time integral of the onion's offset from its minimum, which a fine RK4
    /// of the full macrospin with the landscape held (rotor locked) integrates directly: for
    /// offsets and tilts of either sign they differ by less than the second-order rest bounded
    /// there, and by less than 0.5% for an offset of 2e-4 rad.
    #[test]
    fn averaged_ringing_kicks_the_rotor_by_the_ringing_s_impulse() {
        for alpha in [0.02, 0.3] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.gilbert_damping = alpha;
                p.fluid_viscosity = 1.0;
            });
            let free = Drive {
                direction: -0.7,
                applied_direction: -0.7,
                stress: 2e8,
                load: 0.0,
                locked: false,
            };
            let held = Drive {
                locked: true,
                ..free
            };
            let land = m.landscape(0.0, free.direction, free.stress);
            let settled = land.settle(0.0);
            let (_, j) = m.rhs_jacobian(&[0.0, 0.0, settled, 0.0], &held, 1e-12);
            let norm = (2..4)
                .map(|i| (2..4).map(|k| j[i][k].abs()).sum::<f64>())
                .fold(0.0, f64::max);
            let h = 0.002 / norm;
            let span = 60.0 * m.onion_relaxation_time();
            for (offset, tilt) in [
                (2e-4, 0.0),
                (2e-3, 0.0),
                (-2e-3, 0.0),
                (0.0, 1e-3),
                (1e-3, -2e-3),
            ] {
                let y: Vector = [0.0, 0.0, settled + offset, tilt];
                let mut rim = Rims::NONE;
                let kick = m
                    .averaged_ringing(&y, &free, settled, &mut rim, f64::INFINITY)
                    .expect("small ringing on a slow rotor averages out");
                // The trapezoidal rule over the RK4 states.
                let (mut integral, mut last) = (0.0, offset);
                rk4(&m, &held, y, span, h, |z| {
                    integral += 0.5 * h * (last + z[2] - settled);
                    last = z[2] - settled;
                });
                let k_bar = m.ring_bar.stiffness(settled);
                let impulse = k_bar * integral;
                // The second-order rest the kick leaves out, as bounded there.
                let t = m.trapped_ringing(&y, &free, settled, None).unwrap();
                let rest = (m.ring_bar_slope_bound
                    + 2.0 * k_bar.abs() * t.slope_bound / t.curvature)
                    * t.amplitude
                    * t.amplitude
                    / (4.0 * t.rate);
                let error = (kick * m.inertia - impulse).abs();
                println!(
                    "damping {alpha}, offset {offset:e}, tilt {tilt:e}: kick {kick:e} rad/s, RK4 {:e}, error {:.1e} of the bound",
                    impulse / m.inertia,
                    error / rest
                );
                assert!(
                    error <= rest,
                    "{alpha} {y:?}: {kick:e} against {:e}",
                    impulse / m.inertia
                );
                if offset.abs() < 1e-3 && tilt == 0.0 {
                    assert!(error <= 5e-3 * impulse.abs(), "{alpha} {y:?}");
                }
            }
        }
    }

    /// The pair's substep from a ringing onion on a turning rotor against classical RK4 of the
    /// full nonlinear system at 1e-16 s steps: its error estimate is the exponential Euler
    /// step's true error within a factor of 3, and the corrected result it returns is closer to
    /// the truth than that step, for substeps from a tenth of the ~80 ps precession period on.
    #[test]
    fn gilbert_pair_estimates_its_error_and_improves_on_exponential_euler() {
        let m = motor_with(|p| p.onion_model = OnionModel::Gilbert);
        let d = Drive {
            direction: -0.7,
            applied_direction: -0.7,
            stress: 2e8,
            load: 3e-19,
            locked: false,
        };
        let y: Vector = [0.2, 3e4, 0.7, 0.01];
        let tol = m.params.tolerance;
        let scales = [tol, tol * m.speed_scale, tol, tol];
        let scaled = |a: &Vector, b: &Vector| {
            (0..4)
                .map(|i| (a[i] - b[i]).abs() / scales[i])
                .fold(0.0, f64::max)
        };
        for dt in [1e-13, 3e-13, 1e-12, 3e-12, 1e-11] {
            let rate = |z: &Vector| m.rhs_jacobian(z, &d, dt).0;
            let n = (dt / 1e-16).round() as usize;
            let h = dt / n as f64;
            let mut truth = y;
            for _ in 0..n {
                truth = rk4_step(&rate, &truth, h);
            }
            let euler = m.exponential_step(&y, dt, &d).unwrap();
            let start = m.linearized(&y, &d, dt, &Angles::exact(y[2], y[0], d.direction));
            let (pair, estimate) = m.gilbert_embedded_step(&y, dt, &d, &start).unwrap();
            let (euler_error, pair_error) = (scaled(&euler, &truth), scaled(&pair, &truth));
            println!(
                "dt {dt:e}: estimate {estimate:e}, Euler {euler_error:e}, pair {pair_error:e}"
            );
            assert!(
                estimate <= 3.0 * euler_error && euler_error <= 3.0 * estimate,
                "dt {dt:e}: estimate {estimate:e} against {euler_error:e}"
            );
            if estimate <= 1.0 {
                assert!(
                    pair_error < 0.5 * euler_error + 1e-6,
                    "dt {dt:e}: {pair_error:e}"
                );
            }
        }
    }

    /// The explicit pair's substep from a ringing onion on a turning rotor against classical RK4
    /// of the full nonlinear system at 1e-16 s steps: where its error estimate accepts the
    /// substep, that substep is within the tolerance of the truth, for substeps from a hundredth
    /// of the ~80 ps precession period on; longer ones it rejects or declines (out of reach).
    #[test]
    fn explicit_pair_keeps_its_substeps_within_the_tolerance() {
        let m = motor_with(|p| p.onion_model = OnionModel::Gilbert);
        let tol = m.params.tolerance;
        let scales = [tol, tol * m.speed_scale, tol, tol];
        let scaled = |a: &Vector, b: &Vector| {
            (0..4)
                .map(|i| (a[i] - b[i]).abs() / scales[i])
                .fold(0.0, f64::max)
        };
        let (mut taken, mut declined) = (0, 0);
        for (locked, y) in [
            (false, [0.2, 3e4, 0.7, 0.01]),
            (false, [0.2, -1e4, 1.9, -0.05]),
            (true, [0.0, 0.0, -0.5, 0.02]),
        ] {
            let d = Drive {
                direction: -0.7,
                applied_direction: -0.7,
                stress: 2e8,
                load: 3e-19,
                locked,
            };
            for dt in [1e-13, 3e-13, 1e-12, 3e-12, 1e-11, 3e-11, 1e-10] {
                let start = m.linearized(&y, &d, dt, &Angles::exact(y[2], y[0], d.direction));
                let (u, estimate) = match m.gilbert_explicit_step(&y, dt, &d, &start) {
                    Some((u, estimate)) if estimate <= 1.0 => (u, estimate),
                    _ => {
                        declined += 1;
                        continue;
                    }
                };
                taken += 1;
                let rate = |z: &Vector| m.rhs_jacobian(z, &d, dt).0;
                let n = (dt / 1e-16).round() as usize;
                let h = dt / n as f64;
                let mut truth = y;
                for _ in 0..n {
                    truth = rk4_step(&rate, &truth, h);
                }
                if locked {
                    truth[0] = y[0];
                    truth[1] = 0.0;
                }
                let error = scaled(&u, &truth);
                println!("{y:?} dt {dt:e}: estimate {estimate:e}, error {error:e}");
                assert!(error <= 1.0, "{y:?} dt {dt:e}: {error:e}");
            }
        }
        assert!(taken >= 6 && declined >= 3, "{taken} {declined}");
    }

    /// On a rotor in a fluid 1e4 to 1e6 times as viscous as water (drag rate `c/I` 4e12 to
    /// 4e14 1/s, beyond the explicit pair's reach at every substep tried) the exponential RK4
    /// substep from a ringing onion, against classical RK4 of the full nonlinear system at steps
    /// of a twentieth of the inertial time `I/c`: where its error estimate accepts the substep,
    /// that substep is within the tolerance of the truth, for substeps from a hundredth of the
    /// ~80 ps precession period on; longer ones it rejects or declines (out of reach).
    #[test]
    fn exponential_rk4_keeps_its_substeps_within_the_tolerance_on_a_stiff_rotor() {
        let (mut taken, mut declined) = (0, 0);
        for viscosity in [10.0, 1000.0] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.fluid_viscosity = viscosity;
            });
            let tol = m.params.tolerance;
            let scales = [tol, tol * m.speed_scale, tol, tol];
            let scaled = |a: &Vector, b: &Vector| {
                (0..4)
                    .map(|i| (a[i] - b[i]).abs() / scales[i])
                    .fold(0.0, f64::max)
            };
            let d = Drive {
                direction: -0.7,
                applied_direction: -0.7,
                stress: 2e8,
                load: 3e-19,
                locked: false,
            };
            let h = 0.05 * m.inertia / m.drag;
            for y in [[0.2, 3.0, 0.7, 0.01], [0.2, -1.0, 1.9, -0.05]] {
                for dt in [1e-12, 3e-12, 1e-11, 3e-11, 1e-10] {
                    let start = m.linearized(&y, &d, dt, &Angles::exact(y[2], y[0], d.direction));
                    assert!(m.gilbert_explicit_step(&y, dt, &d, &start).is_none());
                    let (u, estimate) = match m.gilbert_exponential_rk4_step(&y, dt, &d, &start) {
                        Some((u, estimate, _)) if estimate <= 1.0 => (u, estimate),
                        _ => {
                            declined += 1;
                            continue;
                        }
                    };
                    taken += 1;
                    let truth = rk4(&m, &d, y, dt, dt / (dt / h).ceil(), |_| {});
                    let error = scaled(&u, &truth);
                    println!(
                        "viscosity {viscosity}, {y:?} dt {dt:e}: estimate {estimate:e}, error {error:e}"
                    );
                    assert!(error <= 1.0, "{viscosity} {y:?} dt {dt:e}: {error:e}");
                }
            }
        }
        assert!(taken >= 6 && declined >= 2, "{taken} {declined}");
    }

    /// A whole step of a stiff rotor (fluid 1e4 times as viscous as water) while its onion rings
    /// from 0.3 rad off its minimum, at the dampings where the ringing lasts a few and many
    /// precession periods, against classical RK4 of the full system at a twentieth of the
    /// inertial time: the rotor and the onion end within ten tolerances of it, and the rotor's
    /// turn (about 1.5e-8 rad, far below the tolerance) within a thousandth of its own.
    #[test]
    fn stiff_rotor_under_a_ringing_onion_keeps_to_a_fine_integration() {
        for alpha in [0.02, 0.3] {
            let m = motor_with(|p| {
                p.onion_model = OnionModel::Gilbert;
                p.gilbert_damping = alpha;
                p.fluid_viscosity = 10.0;
            });
            let inputs = MotorInputs {
                load_torque: 3e-19,
                ..MotorInputs::fixed(-0.7, 2e8)
            };
            let d = m.drive_at(&inputs, 0.0);
            let settled = m.landscape(0.0, d.direction, d.stress).settle(0.0);
            let y: Vector = [0.0, 0.0, settled + 0.3, 0.0];
            let mut s = MotorState {
                onion_angle: y[2],
                ..MotorState::aligned(0.0)
            };
            let span = 2e-9;
            let report = m.step(&mut s, &inputs, span).unwrap();
            let truth = rk4(&m, &d, y, span, 0.05 * m.inertia / m.drag, |_| {});
            let tol = m.params.tolerance;
            let (rotor, onion) = (
                (s.rotor_angle - truth[0]).abs(),
                (s.onion_angle - truth[2]).abs(),
            );
            println!(
                "damping {alpha}: {} substeps, rotor {:e} against {:e} ({rotor:e}), onion {} against {} ({onion:e})",
                report.substeps, s.rotor_angle, truth[0], s.onion_angle, truth[2]
            );
            assert!(!report.accuracy_limited, "{alpha}");
            assert!(rotor <= 10.0 * tol && onion <= 10.0 * tol, "{alpha}");
            assert!(rotor <= 1e-3 * truth[0].abs(), "{alpha}");
        }
    }

    /// A motor whose ring barely holds its bar (magnetization 7.4 A/m, a millimetre bar in a
    /// 28 cm ring: undamped frequency, the speed's error scale, 5e-5 rad/s) spun by a load to
    /// 500 rad/s, at `tolerance` 1.5e-10, its onion creeping off the maximum it starts at: the
    /// speed's tolerance alone would be below the speed's rounding. The 1 us step is not
    /// accuracy-limited and ends within the tolerance of classical RK4 of the full system at
    /// 1 ps steps (the step that spent its budget on rounding noise dropped the onion into its
    /// minimum, 1.5 rad away, flagged).
    #[test]
    fn a_tiny_speed_scale_does_not_hold_the_substeps_to_rounding() {
        use super::super::{Motor, MotorParams, ScheduleSwitch, SteppingSchedule};
        let m = Motor::new(MotorParams {
            ring_outer_diameter: 2.769e-1,
            ring_inner_diameter: 4.122e-3,
            bar_length: 9.822e-4,
            bar_width: 2.873e-4,
            thickness: 1.252e-8,
            saturation_magnetization: 7.393,
            magnetostriction: -4.109e-3,
            wall_volume: 8.62e-11,
            density: 3.235e4,
            fluid_viscosity: 4.195,
            gilbert_damping: 0.3482,
            onion_model: OnionModel::Gilbert,
            tolerance: 1.504e-10,
            max_substeps: 12730,
        })
        .unwrap();
        assert!(m.speed_scale < 1e-4, "{}", m.speed_scale);
        let schedule = SteppingSchedule::new(8.259e-3, 5.249, 4.575e-6, 1.282e-2).unwrap();
        let inputs = MotorInputs {
            load_torque: 3.911e-7,
            schedule: ScheduleSwitch::new(true, schedule),
            ..MotorInputs::fixed(0.0, 0.0)
        };
        let mut s = MotorState::aligned(0.0);
        let y0 = [0.0; 4];
        let report = m.step(&mut s, &inputs, 1e-6).unwrap();
        let truth = rk4(&m, &m.drive_at(&inputs, 0.0), y0, 1e-6, 1e-12, |_| {});
        let got = [s.rotor_angle, s.rotor_speed, s.onion_angle, s.onion_tilt];
        println!("{} substeps: {got:?} against {truth:?}", report.substeps);
        assert!(!report.accuracy_limited);
        let tol = m.params.tolerance;
        for i in [0, 2, 3] {
            assert!(
                (got[i] - truth[i]).abs() <= 2.0 * tol,
                "{i}: {got:?} {truth:?}"
            );
        }
        assert!(
            (got[1] - truth[1]).abs() <= 1e-9 * truth[1].abs(),
            "{got:?} {truth:?}"
        );
    }

    #[test]
    fn fifth_order_error_is_the_five_eighths_power() {
        for err in [0.0, 1e-12, 0.003, 0.5, 1.0, 1.7, 40.0, 1e9] {
            let got = super::fifth_order_error(err);
            assert!(
                (got - f64::powf(err, 0.625)).abs() <= 1e-15 * got.max(1.0),
                "{err}"
            );
        }
        assert_eq!(super::fifth_order_error(1.0), 1.0);
        assert!(super::fifth_order_error(f64::NAN).is_nan());
    }

    /// `phi_3(z) = (e^z - 1 - z - z^2/2) / z^3` for a 2x2 real block with eigenvalues
    /// `-a +- i b` (a damped precession, as the onion's) against the approximant: its action stays
    /// within 0.9 to 1.4 times that of the exact `phi_3` from slow to very stiff.
    #[test]
    fn pade_phi3_tracks_phi3_on_a_damped_rotation() {
        for (a, b) in [
            (0.01, 0.1),
            (0.1, 1.0),
            (0.05, 5.0),
            (1.0, 3.0),
            (0.5, 50.0),
            (40.0, 1e3),
        ] {
            // J = [[-a, -b], [b, -a]] acts on (x, y) as multiplication by z = -a + i b.
            let j = [
                [-a, -b, 0.0, 0.0],
                [b, -a, 0.0, 0.0],
                [0.0, 0.0, -1.0, 0.0],
                [0.0, 0.0, 0.0, -1.0],
            ];
            let v = [1.0, 0.0, 0.0, 0.0];
            let got = pade_phi3_apply(&j, 1.0, &v, 1.0).unwrap();
            // Exact phi_3(z) by complex arithmetic: (re, im) of the image of 1.
            let (zr, zi) = (-a, b);
            let mul = |p: (f64, f64), q: (f64, f64)| (p.0 * q.0 - p.1 * q.1, p.0 * q.1 + p.1 * q.0);
            let e = (zr.exp() * zi.cos(), zr.exp() * zi.sin());
            let z2 = mul((zr, zi), (zr, zi));
            let z3 = mul(z2, (zr, zi));
            let num = (e.0 - 1.0 - zr - 0.5 * z2.0, e.1 - zi - 0.5 * z2.1);
            let den = z3.0 * z3.0 + z3.1 * z3.1;
            let exact = mul(num, (z3.0 / den, -z3.1 / den));
            let ratio = got[0].hypot(got[1]) / exact.0.hypot(exact.1);
            assert!((0.9..=1.4).contains(&ratio), "z = -{a} + {b}i: {ratio}");
        }
    }
}
