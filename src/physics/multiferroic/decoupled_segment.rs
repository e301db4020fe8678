//! A free rotor's Gilbert onion that the ring neither moves nor is moved by, over the rest of a
//! segment of constant drive at once: the onion's own 2x2 system by an exponential RK4, the rotor
//! on its exact drift (see [`Motor::advance_decoupled_segment`]).

use super::angles::{turned_back, Angles};
use super::block_phi::BlockPhi;
use super::gilbert::fifth_order_error;
use super::integrator::step_factor;
use super::{Drive, Motor, StepRun, GILBERT_SUBSTEP_WEIGHT};

/// Declined tries in a row after which none is tried again in the step: an onion whose segments
/// the onion's system alone cannot take within the tolerance declines at every switch, each try
/// costing about a third of the substep that follows it.
const MAX_DECLINES: u32 = 4;

/// Relative shortfall of a segment's length below the schedule's period that still counts as a
/// whole period (the rounding of the switches' times).
const WHOLE_PERIOD_SLACK: f64 = 1e-9;

#[cfg(test)]
thread_local! {
    /// Segments taken by [`Motor::advance_decoupled_segment`] on this thread (for tests).
    pub(super) static TAKEN: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Each segment taken on this thread (for tests): the state and time at its start, and its
    /// end with the state there.
    pub(super) static LOG: std::cell::RefCell<Vec<(super::Vector, f64, f64, super::Vector)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// The step's tries: the segment (its end) last declined, and the declines in a row.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct DecoupledTries {
    declined_at: Option<f64>,
    declines: u32,
}

impl Motor {
    /// Advances a free rotor's Gilbert onion over a whole period of the schedule, from its switch
    /// to the next, in one substep where eq. 3.3's ring-bar torque is negligible over the rest of
    /// the step for the rotor and for the onion ([`Self::ring_decoupled`], the ground of
    /// [`Self::skip_onion_periods`] too) and the error-controlled substep would span the period
    /// anyway (a fast schedule's switches cut it). `true` if taken. Tried `early`, before the
    /// check of the onion's relaxation ([`Self::follows_branch`]), only where the switches outpace
    /// the onion ([`Self::outpaced`]); otherwise after that check declines, so that an onion that
    /// settles onto its branch keeps following it (and its relaxed switches' cycles,
    /// [`Self::skip_onion_cycles`]).
    ///
    /// Without the ring's torque the rotor follows `I phi'' = load - c phi'`, exactly
    /// ([`Self::drift_response`]), and the onion obeys the macrospin's rates
    /// ([`Self::onion_rate`]) under eq. 3.4's gradient `G = E sin 2(psi - gamma)` alone, an
    /// autonomous system in `(psi, theta)`. It is advanced by ETDRK4 (Cox and Matthews, J.
    /// Comput. Phys. 176, 2002) with its Jacobian at the start, `[[-g a G', -g T], [g G', -g a
    /// T]]` (`G' = 2 E cos 2(psi - gamma)`), as the linear part, exactly ([`BlockPhi`]), and its
    /// error estimated by step doubling as the full system's exponential RK4
    /// ([`Self::gilbert_block_etd_step`]): the rotor's block, its coupling to the onion and its
    /// error terms drop out, which is most of that substep's cost, and the check of the onion's
    /// relaxation, which declines at every switch, is not made. Taken only within the tolerance
    /// (it is never forced): a rejection leaves the period to the other paths, and after
    /// [`MAX_DECLINES`] in a row none is tried in the step. Charged as a Gilbert substep.
    pub(super) fn advance_decoupled_segment(
        &self,
        run: &mut StepRun,
        d: &Drive,
        segment_end: f64,
        budget: u32,
        early: bool,
    ) -> bool {
        if early && !self.outpaced(run, d) {
            return false;
        }
        let h = segment_end - run.t;
        // Whole periods of the schedule only, from their switch: the regime where its switches
        // cut every substep; a segment's rest after substeps is left to them.
        let whole = run
            .schedule
            .is_some_and(|s| h >= s.step_period * (1.0 - WHOLE_PERIOD_SLACK));
        let tries = run.decoupled_tries;
        let spent = run.attempts.saturating_add(run.extra_cost);
        if self.quasi_static()
            || !whole
            || d.locked
            || run.onion_decoupled != Some(true)
            || tries.declines >= MAX_DECLINES
            || tries.declined_at == Some(segment_end)
            || !(h > 0.0 && run.dt >= h)
            || spent.saturating_add(GILBERT_SUBSTEP_WEIGHT) > budget
        {
            return false;
        }
        // The start's angles (below) share this sine and cosine.
        let double = turned_back(2.0 * (run.y[2] - d.direction)).sin_cos();
        let Some((onion, err)) = self.decoupled_onion_step(run.y[2], run.y[3], h, d, double) else {
            run.decoupled_tries = DecoupledTries {
                declined_at: Some(segment_end),
                declines: tries.declines + 1,
            };
            return false;
        };
        let start = run.y;
        let mut y = [start[0], start[1], onion[0], onion[1]];
        let (coast, torque_speed, torque_angle) = self.drift_response(h);
        y[0] += start[1] * coast + d.load * torque_angle;
        y[1] = start[1] * (1.0 - self.drag * torque_speed) + d.load * torque_speed;
        let err = self.free_energy_checked_error(&mut run.free_ledger, (&start, &y), h, d, err);
        if !(err <= 1.0 && self.rotor_sane(&y) && Self::onion_sane(&y)) {
            run.decoupled_tries = DecoupledTries {
                declined_at: Some(segment_end),
                declines: tries.declines + 1,
            };
            return false;
        }
        // `Self::angles_at`, with the doubled angle's sine and cosine where afresh.
        let (psi, phi) = (start[2], start[0]);
        let angles = match run.angles {
            Some(a) if !a.moves_afresh(psi, phi, d.direction) => a.moved(psi, phi, d.direction),
            _ => Angles::exact_with_double(psi, phi, d.direction, double),
        };
        self.record_amplification(&mut run.amplification, h, d, &angles, err);
        run.decoupled_tries = DecoupledTries::default();
        // Tried before the segment is entered: its end is then a switch the next pass sees.
        run.enter_segment(segment_end, d.direction);
        run.attempts = run.attempts.saturating_add(1);
        run.extra_cost = run.extra_cost.saturating_add(GILBERT_SUBSTEP_WEIGHT - 1);
        run.y = y;
        run.t = segment_end;
        run.angles = None;
        run.settled = false;
        // Cut at the segment's end: the uncut proposal stays, as for a clipped substep.
        run.dt = run.dt.max(h * step_factor(err));
        #[cfg(test)]
        {
            TAKEN.with(|c| c.set(c.get() + 1));
            LOG.with(|l| {
                l.borrow_mut()
                    .push((start, segment_end - h, segment_end, y))
            });
        }
        true
    }

    /// Whether the schedule's switches outpace the onion: at eq. 3.4's curvature at a minimum,
    /// `2 |E|`, its slowest decay ([`Self::onion_decay_rate`]) falls short of a factor `e` over a
    /// period. Such an onion does not settle onto its quasi-static branch between switches, so
    /// its segments are tried before the check of its relaxation ([`Self::follows_branch`]),
    /// which would decline at every switch; elsewhere after it.
    fn outpaced(&self, run: &StepRun, d: &Drive) -> bool {
        let Some(s) = run.schedule else {
            return false;
        };
        let curvature = 2.0 * (self.magnetoelastic_per_stress * d.stress).abs();
        self.onion_decay_rate(curvature) * s.step_period < 1.0
    }

    /// The onion's angle and tilt after `h` from `(psi, theta)` under eq. 3.4 alone (see
    /// [`Self::advance_decoupled_segment`]) and the error estimate in tolerances (as
    /// [`fifth_order_error`] gives it); `None` where the `phi` functions are not available or the
    /// result is not finite. `double` is `turned_back(2 (psi - gamma)).sin_cos()`.
    pub(super) fn decoupled_onion_step(
        &self,
        psi: f64,
        theta: f64,
        h: f64,
        d: &Drive,
        double: (f64, f64),
    ) -> Option<([f64; 2], f64)> {
        let (g, a, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let e = self.magnetoelastic_per_stress * d.stress;
        // `sin 2(psi - gamma)` by the angle's turn from the start, `2 (psi - psi0)`, which stays
        // small and exact where `psi` and `gamma` are many turns.
        let (s0, c0) = double;
        let rate = |z: [f64; 2]| {
            let (s, c) = (2.0 * (z[0] - psi)).sin_cos();
            self.onion_rate(e * (s0 * c + c0 * s), z[1])
        };
        let slope = 2.0 * e * c0;
        let l = [[-g * a * slope, -g * t], [g * slope, -g * a * t]];
        let scaled = |c: f64| [[c * l[0][0], c * l[0][1]], [c * l[1][0], c * l[1][1]]];
        let (zq, zh) = (scaled(0.25 * h), scaled(0.5 * h));
        let quarter = BlockPhi::new(&zq)?;
        let half = quarter.doubled(&zq);
        let full = half.doubled(&zh);
        let y0 = [psi, theta];
        let f0 = rate(y0);
        let whole = etd_rk4_2(&l, y0, f0, h, (&half, &zh), &full, rate);
        let first = etd_rk4_2(&l, y0, f0, 0.5 * h, (&quarter, &zq), &half, rate);
        let two = etd_rk4_2(
            &l,
            first,
            rate(first),
            0.5 * h,
            (&quarter, &zq),
            &half,
            rate,
        );
        let tol = self.params.tolerance;
        let err = ((two[0] - whole[0]).abs()).max((two[1] - whole[1]).abs()) / tol;
        (err.is_finite() && two[0].is_finite() && two[1].is_finite())
            .then(|| (two, fifth_order_error(err)))
    }
}

/// One ETDRK4 step of `h` of `z' = rate(z)` from `y0` (rate `f0`) with `l` as the linear part;
/// `half` holds the `phi` functions at `h l / 2` with that matrix, `full` those at `h l` (the
/// formulas of [`super::etd_blocks::etd_rk4_blocks`] on one block).
fn etd_rk4_2(
    l: &[[f64; 2]; 2],
    y0: [f64; 2],
    f0: [f64; 2],
    h: f64,
    half: (&BlockPhi, &[[f64; 2]; 2]),
    full: &BlockPhi,
    rate: impl Fn([f64; 2]) -> [f64; 2],
) -> [f64; 2] {
    let n = |u: [f64; 2]| {
        let f = rate([y0[0] + u[0], y0[1] + u[1]]);
        [
            f[0] - l[0][0] * u[0] - l[0][1] * u[1],
            f[1] - l[1][0] * u[0] - l[1][1] * u[1],
        ]
    };
    let (ph, zh) = half;
    let scaled = |c: f64, v: [f64; 2]| [c * v[0], c * v[1]];
    let n0 = f0;
    let a = scaled(0.5 * h, ph.apply(1, n0));
    let na = n(a);
    let b = scaled(0.5 * h, ph.apply(1, na));
    let nb = n(b);
    // e^(Z/2) a = a + (Z/2) phi_1(Z/2) a.
    let pa = ph.apply(1, a);
    let ea = [
        a[0] + zh[0][0] * pa[0] + zh[0][1] * pa[1],
        a[1] + zh[1][0] * pa[0] + zh[1][1] * pa[1],
    ];
    let c_half = scaled(
        0.5 * h,
        ph.apply(1, [2.0 * nb[0] - n0[0], 2.0 * nb[1] - n0[1]]),
    );
    let c = [ea[0] + c_half[0], ea[1] + c_half[1]];
    let nc = n(c);
    let second: [f64; 2] = std::array::from_fn(|i| 2.0 * na[i] + 2.0 * nb[i] - nc[i] - 3.0 * n0[i]);
    let third: [f64; 2] = std::array::from_fn(|i| 4.0 * (n0[i] - na[i] - nb[i] + nc[i]));
    let (p1, p2, p3) = (
        full.apply(1, n0),
        full.apply(2, second),
        full.apply(3, third),
    );
    std::array::from_fn(|i| y0[i] + h * (p1[i] + p2[i] + p3[i]))
}
