//! The exponential RK4 substep of a free rotor with both 2x2 diagonal blocks of the Jacobian as
//! its linear part, the rotor's `[[0, 1], [-k/I, -c/I]]` and the onion's
//! `g [[-alpha U'', -T], [U'', -alpha T]]` (eq. 3.4's landscape at the substep's start), for a
//! ringing onion on a stiff rotor (the blocks' `phi` functions in [`super::block_phi`]).

use super::block_phi::BlockPhi;
use super::gilbert::{fifth_order_error, Linearized};
use super::{Drive, Motor, Vector};

/// A block-diagonal linear part's `phi` functions and matrices at one substep length: the rotor's
/// block (states 0, 1) and the onion's (states 2, 3), each times that length.
pub(super) struct Blocks {
    phi: [BlockPhi; 2],
    z: [[[f64; 2]; 2]; 2],
}

impl Blocks {
    /// `None` where a block's `phi` functions are not available ([`BlockPhi::new`]).
    #[inline(always)]
    pub(super) fn new(j: &[[f64; 4]; 4], h: f64) -> Option<Self> {
        let block = |b: usize| {
            [
                [h * j[b][b], h * j[b][b + 1]],
                [h * j[b + 1][b], h * j[b + 1][b + 1]],
            ]
        };
        let z = [block(0), block(2)];
        Some(Self {
            phi: [BlockPhi::new(&z[0])?, BlockPhi::new(&z[1])?],
            z,
        })
    }

    /// The blocks at twice the length.
    #[inline(always)]
    pub(super) fn doubled(&self) -> Self {
        let z = self.z.map(|b| b.map(|r| r.map(|x| 2.0 * x)));
        Self {
            phi: [
                self.phi[0].doubled(&self.z[0]),
                self.phi[1].doubled(&self.z[1]),
            ],
            z,
        }
    }

    /// `phi_k(Z) v` on both blocks.
    #[inline(always)]
    fn apply(&self, k: usize, v: &Vector) -> Vector {
        let [r0, r1] = self.phi[0].apply(k, [v[0], v[1]]);
        let [o0, o1] = self.phi[1].apply(k, [v[2], v[3]]);
        [r0, r1, o0, o1]
    }

    /// `e^Z v = v + Z phi_1(Z) v`.
    #[inline(always)]
    fn exp_apply(&self, v: &Vector) -> Vector {
        let p = self.apply(1, v);
        let mut out = *v;
        for (b, z) in self.z.iter().enumerate() {
            let (i, k) = (2 * b, 2 * b + 1);
            out[i] += z[0][0] * p[i] + z[0][1] * p[k];
            out[k] += z[1][0] * p[i] + z[1][1] * p[k];
        }
        out
    }
}

/// One ETDRK4 step of `h` from `y0` (rate `f0`) with the block-diagonal part of `j` as `L`
/// (the formulas of the one-block [`Motor::etd_rk4`]); `half` and `full` are its blocks at
/// `h/2` and `h`.
#[inline(always)]
pub(super) fn etd_rk4_blocks(
    y0: &Vector,
    f0: Vector,
    h: f64,
    j: &[[f64; 4]; 4],
    half: &Blocks,
    full: &Blocks,
    rate: impl Fn(&Vector) -> Vector,
) -> Vector {
    let n = |u: &Vector| -> Vector {
        let mut f = rate(&std::array::from_fn(|i| y0[i] + u[i]));
        for b in [0, 2] {
            f[b] -= j[b][b] * u[b] + j[b][b + 1] * u[b + 1];
            f[b + 1] -= j[b + 1][b] * u[b] + j[b + 1][b + 1] * u[b + 1];
        }
        f
    };
    let scaled = |c: f64, v: Vector| -> Vector { v.map(|x| c * x) };
    let n0 = f0;
    let a = scaled(0.5 * h, half.apply(1, &n0));
    let na = n(&a);
    let b_stage = scaled(0.5 * h, half.apply(1, &na));
    let nb = n(&b_stage);
    let ea = half.exp_apply(&a);
    let forcing: Vector = std::array::from_fn(|i| 2.0 * nb[i] - n0[i]);
    let c_half = scaled(0.5 * h, half.apply(1, &forcing));
    let c: Vector = std::array::from_fn(|i| ea[i] + c_half[i]);
    let nc = n(&c);
    let second: Vector = std::array::from_fn(|i| 2.0 * na[i] + 2.0 * nb[i] - nc[i] - 3.0 * n0[i]);
    let third: Vector = std::array::from_fn(|i| 4.0 * (n0[i] - na[i] - nb[i] + nc[i]));
    let (p1, p2, p3) = (
        full.apply(1, &n0),
        full.apply(2, &second),
        full.apply(3, &third),
    );
    std::array::from_fn(|i| y0[i] + h * (p1[i] + p2[i] + p3[i]))
}

impl Motor {
    /// A substep by the exponential Runge-Kutta method of Cox and Matthews (ETDRK4, J. Comput.
    /// Phys. 176, 2002) with the block-diagonal part of the Jacobian at the start as its linear
    /// part `L`: the rotor's block and the onion's, each taken exactly, and the rest (their
    /// coupling through the offset `psi - phi`, the change of the landscape's curvature along the
    /// substep) as its nonlinear part, for a free rotor. The onion's ringing, linear in its
    /// block, is then followed over many substeps with an error set by the ringing's departure
    /// from it alone; with the onion explicit ([`Motor::gilbert_exponential_rk4_step`] on the
    /// rotor's block) classical RK4's error on the ringing's phase added up to 40 tolerances a
    /// 1 us step. Tried where `dt` times the coupling's rates ([`Self::coupling_rate_bound`]) is
    /// within [`ETD_REACH`] and those rates are at most [`WEAK_COUPLING`] of the onion block's
    /// own. The error is step doubling's taken whole, as the one-block
    /// method's, and returned as `err^(5/8)`, with whether the exponential pair is worth a retry
    /// where this rejects: not where it rejects by less than [`RETRY_ABOVE`].
    ///
    /// `None` where it does not apply (out of reach, or a block's `phi` functions not available:
    /// [`BlockPhi::new`]); `Some(None)` when the substep fails.
    pub(super) fn gilbert_block_etd_step(
        &self,
        y: &Vector,
        dt: f64,
        d: &Drive,
        start: &Linearized,
    ) -> Option<Option<(Vector, f64, bool)>> {
        let j = &start.j;
        let coupling = self.coupling_rate_bound(j);
        let reach = dt * coupling / ETD_REACH;
        let onion =
            (j[2][2] + j[3][3]).abs() + (j[2][2] * j[3][3] - j[2][3] * j[3][2]).abs().sqrt();
        // (False for a NaN rate too.)
        let applies = reach <= 1.0 && coupling <= WEAK_COUPLING * onion;
        if d.locked || !applies {
            return None;
        }
        let quarter = Blocks::new(j, 0.25 * dt)?;
        let half = quarter.doubled();
        let full = half.doubled();
        let rate =
            |z: &Vector| self.gilbert_rate(z, d, &start.angles.moved(z[2], z[0], d.direction));
        let whole = etd_rk4_blocks(y, start.f, dt, j, &half, &full, rate);
        let first = etd_rk4_blocks(y, start.f, 0.5 * dt, j, &quarter, &half, rate);
        let two = etd_rk4_blocks(&first, rate(&first), 0.5 * dt, j, &quarter, &half, rate);
        let Some(u) = self.checked_end(two, y, d.locked) else {
            return Some(None);
        };
        let err = self.error_norm(|i| two[i] - whole[i], y, &u);
        // Raised to at least `(0.9 reach)^3` (at most 0.73 within reach, so acceptance is
        // unchanged), at which the step-size rule ([`super::integrator::step_factor`]) proposes no
        // substep beyond the reach: an onion that its block follows closely would otherwise
        // propose substeps out of reach, which the other pairs then reject.
        let floor = (0.9 * reach).powi(3);
        Some(err.is_finite().then(|| {
            let err = fifth_order_error(err).max(floor);
            (u, err, err > RETRY_ABOVE)
        }))
    }

    /// A bound on the moduli of the rates that [`Self::gilbert_block_etd_step`] treats
    /// explicitly (1/s): the onion's rates per rotor turn and the loop through the rotor, which
    /// answers the onion's torque over its drag, the rotor's relaxation rate `k/c` and
    /// `sqrt(|d psi'/d phi| (k/I) / (c/I))` (the one-block method's bound without the onion
    /// block's own rates). Infinite for a rotor without drag.
    pub(super) fn coupling_rate_bound(&self, j: &[[f64; 4]; 4]) -> f64 {
        let coupling = j[2][0].abs() + j[3][0].abs();
        let drag_rate = j[1][1].abs();
        let relaxation = j[1][0].abs() / drag_rate;
        let through_rotor = (coupling * j[1][2].abs() / drag_rate).sqrt();
        coupling + relaxation + through_rotor
    }
}

/// A rejection by [`Motor::gilbert_block_etd_step`] within this factor of the tolerance is not
/// retried by the exponential pair: there the onion's error changes along its orbit by about
/// that much between substeps of the same length (the step-size rule's proposal overshoots it),
/// and the pair, of second order, took none of about 1,000 such retries on the benchmark's
/// slowest free rotors, where it does take larger rejections on a nearly linear onion.
pub(super) const RETRY_ABOVE: f64 = std::f64::consts::SQRT_2;

/// The block-diagonal part is taken only where the coupling's rates are at most this fraction of
/// the onion block's own (`|trace| + sqrt(|det|)`): where the rotor's turn moves the onion faster
/// than its own precession (a large ring holding a light onion) the coupling is the dynamics, and
/// with it explicit a 1 us step ended hundreds of tolerances off a plain RK4 where the one-block
/// method stays within a few.
pub(super) const WEAK_COUPLING: f64 = 1.0 / 16.0;

/// The longest substep relative to the explicit rates: classical RK4's stability region reaches
/// about 2.8 along the negative real axis and the imaginary one (as the one-block method's).
pub(super) const ETD_REACH: f64 = 2.5;
