//! A Gilbert onion on a fast schedule that the ring barely couples to the rotor, or whose rotor
//! is locked, and that stays in its linear regime, advanced over many switches at once by exact
//! affine maps (see [`Motor::advance_onion_linear`]).

use super::angles::turned_back;
use super::block_phi::block_phi1;
use super::{Motor, MotorInputs, StepRun, SteppingSchedule};
use crate::physics::numerics::expm2::expm2;

pub(super) type M2 = [[f64; 2]; 2];

/// Part of the tolerance the bound of the dropped nonlinear term may take over one macro span.
const BOUND_SHARE: f64 = 0.01;
/// Switches of the first macro span tried in a step; later spans follow the last bound.
const FIRST_SPAN: usize = 4;
/// Fewest switches a macro span takes (but for the step's last): each span may leave up to
/// [`BOUND_SHARE`] of the tolerance, all the same way where the onion keeps its offset, so spans
/// of one to three switches add that up hundreds of times a step (a locked onion at damping
/// 2.4e-3 so ends its fifth 1 us step 1.8 tolerances off the RK4) and save little over resolving
/// those switches.
pub(super) const MIN_SPAN: usize = 4;
/// Declined spans in a row after which none is tried again in the step (an onion swinging
/// through eq. 3.4's nonlinear range declines at once); before, spans are retried after 1, 2,
/// 4, ... switches resolved by the other paths.
const MAX_DECLINES: u32 = 6;
/// Switches at which the repeated periods' skips ([`Motor::skip_onion_periods`]) must have
/// declined in a step before a span is tried: an onion that settles within a few periods
/// repeats them at no cost at all, which a span would end (it restarts their comparison). Where
/// the ring couples to the onion (a locked rotor's, [`Motor::linear_ring_term`]) there are no
/// skips to wait for, and spans are tried from the first switch.
const WAIT_SWITCHES: u32 = 8;
/// Largest growth of the onion block's exponential over a switch (`e^50`): beyond it the
/// linearization is far out of its reach anyway and the bound would overflow.
const MAX_GROWTH_EXPONENT: f64 = 50.0;
/// Switches of a macro span charged as one unit of the step's budget, tried or taken: a
/// switch's closed-form flow ([`flow`]), its entrywise bound and its share of the backward
/// products cost 0.12-0.15 us (thread CPU, release, x86-64), a budget unit up to 0.4 us (a
/// quasi-static substep, a quarter of a Gilbert one, [`super::GILBERT_SUBSTEP_WEIGHT`]), so
/// that the spans' work per unit stays below the substeps'.
pub(super) const SWITCHES_PER_UNIT: usize = 2;

#[cfg(test)]
thread_local! {
    /// Macro spans taken by [`Motor::advance_onion_linear`] on this thread (for tests).
    pub(super) static SPANS: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Switch intervals chained by the macro spans on this thread, taken or declined, and the
    /// budget units charged for them (for tests).
    pub(super) static CHAINED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    pub(super) static CHARGED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    /// Turns [`Motor::advance_onion_linear`] off on this thread (for tests: the other paths).
    pub(super) static OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Each span taken on this thread (for tests): the state and time at its start, its end,
    /// the onion and tilt there and their bound.
    pub(super) static SPAN_LOG: std::cell::RefCell<Vec<SpanRecord>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// A span taken (for tests): the state and time at its start, its end, the onion and tilt
/// there and their bound.
#[cfg(test)]
pub(super) type SpanRecord = (super::Vector, f64, f64, [f64; 2], f64);

/// The step's macro-span state: switches to try next (0 before the first), or disabled, the
/// switches passed before the first, the spans declined in a row and the switches to pass
/// before the next try.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct LinearSpan {
    next: usize,
    disabled: bool,
    waited: u32,
    declined: u32,
    retry_in: u32,
}

impl LinearSpan {
    /// Whether a span failed in this step: none is tried again before its end.
    pub(super) fn disabled(&self) -> bool {
        self.disabled
    }
}

/// One switch's exact affine map of the linearized onion and its flow's bound.
pub(super) struct Flow {
    /// `exp(A h)`.
    pub(super) e: M2,
    /// `int_0^h exp(A s) ds`.
    pub(super) j: M2,
    /// An entrywise bound on `|exp(A s)|` for `0 <= s <= h`.
    k: M2,
}

fn norm(a: &M2) -> f64 {
    (a[0][0].abs() + a[0][1].abs()).max(a[1][0].abs() + a[1][1].abs())
}

fn abs(a: &M2) -> M2 {
    [
        [a[0][0].abs(), a[0][1].abs()],
        [a[1][0].abs(), a[1][1].abs()],
    ]
}

fn mul(a: &M2, b: &M2) -> M2 {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

pub(super) fn apply(a: &M2, x: [f64; 2]) -> [f64; 2] {
    [
        a[0][0] * x[0] + a[0][1] * x[1],
        a[1][0] * x[0] + a[1][1] * x[1],
    ]
}

/// The exact flow of `w' = A w + b` over `h` for a 2x2 `A`, in closed form.
///
/// Hand-written rather than a general exponential: it runs once a switch, hundreds of times a step,
/// where a scaled-and-squared 3x3 exponential cost about as much as the substeps it replaces.
/// `exp(A h)` is the closed form of [`expm2`], finite over the whole range (a long overdamped
/// interval among it). With `A = m I + N`, `N^2 = q I` (trace-free), `exp(A s) = e^{m s} (C I + S
/// N)`, `C, S = cos(w s), sin(w s) / w` for `q = -w^2 < 0` and `cosh, sinh / w` for `q = w^2`;
/// hence, entry by entry, `|exp(A s)| <= max(1, e^{m h}) (I + min(h, 1/w) |N|)` in the first case
/// and `e^{max(m + w, 0) h} (I + min(h, 1/(2w)) |N|)` in the second (`|sin(w s)/w| <= min(s, 1/w)`,
/// `cosh(w s) <= e^{w s}`, `sinh(w s)/w <= e^{w s} min(s, 1/(2w))`). The integral is `A^{-1} (exp(A
/// h) - I)` where `A` is well conditioned and `h` long; else, beyond `||A|| h = 1/2`, `h phi_1(A
/// h)` from the eigenvalues ([`block_phi1`]: a nearly singular `A`, as a stiff tilt makes it, has
/// one eigenvalue near 0 and the other far off, or both near 0); else its Taylor series over `h /
/// 2^n` (`||A|| h / 2^n <= 1/2`) doubled `n` times (`J(2h) = (I + exp(A h)) J(h)`), which holds
/// through a singular `A`. `None` if the flow could grow beyond `e^50`.
pub(super) fn flow(a: &M2, h: f64) -> Option<Flow> {
    let m = 0.5 * (a[0][0] + a[1][1]);
    let n: M2 = [[a[0][0] - m, a[0][1]], [a[1][0], a[1][1] - m]];
    let q = n[0][0] * n[0][0] + n[0][1] * n[1][0];
    let oscillating = q < 0.0;
    let w = q.abs().sqrt();
    let top = if oscillating {
        m.max(0.0)
    } else {
        (m + w).max(0.0)
    };
    // (A NaN declines too.)
    if top * h > MAX_GROWTH_EXPONENT || top.is_nan() || h.is_nan() {
        return None;
    }
    let ah = [[a[0][0] * h, a[0][1] * h], [a[1][0] * h, a[1][1] * h]];
    let e = expm2(&ah)?;
    let reach = if oscillating {
        h.min(1.0 / w)
    } else {
        h.min(0.5 / w)
    };
    let grow = (top * h).exp();
    let k = [
        [
            grow * (1.0 + reach * n[0][0].abs()),
            grow * reach * n[0][1].abs(),
        ],
        [
            grow * reach * n[1][0].abs(),
            grow * (1.0 + reach * n[1][1].abs()),
        ],
    ];
    let size = norm(a);
    if !(size.is_finite() && h.is_finite()) {
        return None;
    }
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let j = if size * h >= 1.0 && det.abs() >= 1e-2 * size * size {
        let d = [[e[0][0] - 1.0, e[0][1]], [e[1][0], e[1][1] - 1.0]];
        let inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        mul(&inv, &d)
    } else if let Some(p) = (size * h > 0.5).then(|| block_phi1(&ah)).flatten() {
        [[p[0][0] * h, p[0][1] * h], [p[1][0] * h, p[1][1] * h]]
    } else {
        let mut halvings = 0;
        let mut hs = h;
        while size * hs > 0.5 {
            hs *= 0.5;
            halvings += 1;
        }
        // J = hs sum_n (A hs)^n / (n + 1)!, by Horner; 12 terms leave 0.5^13 / 14! ~ 1e-15.
        let x = [[a[0][0] * hs, a[0][1] * hs], [a[1][0] * hs, a[1][1] * hs]];
        let mut j: M2 = [[1.0, 0.0], [0.0, 1.0]];
        for i in (1..=12).rev() {
            let f = 1.0 / f64::from(i + 1);
            let xj = mul(&x, &j);
            j = [
                [1.0 + f * xj[0][0], f * xj[0][1]],
                [f * xj[1][0], 1.0 + f * xj[1][1]],
            ];
        }
        let mut j = [[j[0][0] * hs, j[0][1] * hs], [j[1][0] * hs, j[1][1] * hs]];
        for _ in 0..halvings {
            let ej = mul(a, &j);
            // I + exp(A hs) = 2 I + A J(hs).
            let p = [[2.0 + ej[0][0], ej[0][1]], [ej[1][0], 2.0 + ej[1][1]]];
            j = mul(&p, &j);
        }
        j
    };
    Some(Flow { e, j, k })
}

impl Motor {
    /// Advances the rest of the step's switches, or some of them, at once where eq. 3.3's
    /// ring-bar torque is negligible ([`Self::ring_decoupled`], as for
    /// [`Self::skip_onion_periods`]), the rotor is locked ([`Self::linear_ring_term`]) or the
    /// ring barely turns the free rotor ([`Self::free_ring_term`]), and the Gilbert onion stays
    /// close enough to where each switch of a macro span begins for eq. 3.4 to be linear over
    /// that switch. `true` if a span was taken.
    ///
    /// A locked rotor stays; a free one follows load and drag alone ([`Self::drift_response`]),
    /// exactly where the ring is dropped, within [`Self::free_ring_term`]'s bound where the onion
    /// keeps it. The bound below holds for the onion whatever its placements on its quasi-static
    /// branch would have been, which the skips of repeated periods rest on
    /// ([`Self::snaps_forgotten`]): an onion the strain turns fast about is advanced here. The
    /// onion obeys the macrospin's rates ([`Self::onion_rate`]) with the energy's gradient `E sin
    /// 2(psi - gamma_k)` in the strain direction `gamma_k` of switch interval `k` (eq. 3.4) plus
    /// the ring's torque (eq. 3.3). Each interval is linearized afresh about the chained maps'
    /// path at its start, `psi_k` (an exponential Rosenbrock-Euler step a switch long): with
    /// `delta = psi - psi_k` the gradient is `G_k + d_k delta + R`, `G_k = E sin 2(psi_k -
    /// gamma_k) + tau_k`, `d_k = 2 E cos 2(psi_k - gamma_k) + k_k` (`tau_k, k_k` the ring's
    /// linear term, zero where it is dropped, [`Self::linear_ring_term`]: under a held bar its
    /// torque and slope at `psi_k`, under a drifting one its value and slope at the span's start
    /// carried to `psi_k` along that slope): each interval is an exact affine map of `(delta,
    /// theta)` (see [`flow`]), chained over the span. The dropped term is bounded by `|R| <= 2 |E|
    /// delta^2 + rho (|delta| + l_k + |p|)^2 + |k_0| |p| + tau_r` (Taylor's remainder: `|d^2/dx^2
    /// sin 2x| <= 4`; the rest the ring term's, `l_k = |psi_k - psi_0|` where its slope stays the
    /// span's start's, `p` the bar's turn since then under a free rotor,
    /// [`Self::free_ring_term`]), and enters the rates as `g (-a R, R)`. The error obeys the
    /// same maps plus `R` along the path, so linearizing about the path, not the span's start,
    /// leaves only each interval's own turn in eq. 3.4's `delta`. All bounds on
    /// vectors are entry by entry (`|x|` the vector of the entries' magnitudes), with `K_k` the
    /// entrywise bound on the interval's propagator `|exp(A s)|` ([`flow`]). Over interval `k` of
    /// length `h_k` the remainder's effect is at most `c_k = K_k (h_k g a, h_k g) R_k` (variation
    /// of constants), `R_k` a bound on `|R|` there from `r_k`, a bound on `|delta|`: the linear
    /// path's reach within the interval (`|delta_k+1| + h_k (K_k |A u_k + b|)_0 / 2`, or `(K_k
    /// (|u_k| + h_k |b|))_0`, `u_k = (0, theta_k)`) widened by the forward bound of the error so
    /// far (`eps_k+1 = |exp(A h_k)| eps_k + c_k`, `K_k eps_k + c_k` within the interval). The
    /// bound at the span's end is the larger entry of `sum_k |P_k| c_k`, `P_k` the exact product
    /// of the later intervals' maps.
    /// Entry by entry, not in a norm: the tilt's stiffness `T` far exceeds the angle's `|d_k|`, so
    /// a switch's map carries the tilt into the angle many times over (a max norm of 5 to 32 on
    /// fast schedules) where its products over many switches stay near 1, and a norm's bound grows
    /// geometrically with the span. `R_k` is taken where it bounds the remainder on the reach it
    /// widens itself (`R_k >= R(r + (c_k)_0)`, `r` the reach widened by `eps_k` alone; tried at
    /// 1.25 times `R(r + (c(R(r)))_0)`), so that the true onion cannot first leave that reach: the
    /// bound is a real bound on the true onion's distance from the chained maps' (through eq. 3.4's
    /// trigonometric terms and eq. 3.3's torque alike), but for rounding. A span is taken only
    /// where that bound is within a hundredth of the tolerance and covers at least [`MIN_SPAN`]
    /// switches (or ends the step); otherwise a shorter one is tried, and where the shortest fails
    /// the next switches are left to the other paths, for good after [`MAX_DECLINES`] in a row (an
    /// onion swinging through eq. 3.4's nonlinear range, where the linearization fails at once).
    /// Tried, with a decoupled ring, once the skips of repeated periods have declined at
    /// [`WAIT_SWITCHES`] switches. Every switch chained, in a span taken or declined, is charged to
    /// the step's budget ([`SWITCHES_PER_UNIT`]), and the spans chain no more switches than the
    /// budget left pays for: they are over for the step once it cannot pay for [`MIN_SPAN`], so
    /// that `max_substeps` bounds their cost as it bounds the substeps'.
    pub(super) fn advance_onion_linear(
        &self,
        run: &mut StepRun,
        s: &SteppingSchedule,
        inputs: &MotorInputs,
    ) -> bool {
        #[cfg(test)]
        if OFF.with(|c| c.get()) {
            return false;
        }
        if self.quasi_static()
            || run.onion_linear.disabled
            || self.linear_ring_term(run, inputs).is_none()
        {
            return false;
        }
        // The switches the budget left pays for, over all the tries below: the spans are
        // over for the step where it cannot pay for the shortest (whether or not one is due).
        let spent = run.attempts.saturating_add(run.extra_cost);
        let affordable = (self.params.max_substeps.saturating_sub(spent) as usize)
            .saturating_mul(SWITCHES_PER_UNIT);
        if affordable < MIN_SPAN {
            run.onion_linear.disabled = true;
            return false;
        }
        if run.onion_linear.next == 0
            && run.onion_linear.waited < WAIT_SWITCHES
            && run.onion_decoupled == Some(true)
        {
            run.onion_linear.waited += 1;
            return false;
        }
        if run.onion_linear.retry_in > 0 {
            run.onion_linear.retry_in -= 1;
            return false;
        }
        let mut span = if run.onion_linear.next == 0 {
            FIRST_SPAN
        } else {
            run.onion_linear.next
        };
        let target = BOUND_SHARE * self.params.tolerance;
        // Switch intervals chained, taken or declined, charged to the budget.
        let mut chained = 0;
        let charge = |run: &mut StepRun, chained: usize| {
            let units = u32::try_from(chained.div_ceil(SWITCHES_PER_UNIT)).unwrap_or(u32::MAX);
            run.extra_cost = run.extra_cost.saturating_add(units);
            #[cfg(test)]
            CHARGED.with(|c| c.set(c.get() + u64::from(units)));
        };
        loop {
            let tried = self.onion_linear_span(run, s, inputs, span.min(affordable - chained));
            chained += tried.switches;
            if let Some((t, y, bound)) = tried.result {
                if bound <= target && (tried.switches >= MIN_SPAN || t >= run.t_end) {
                    let y_new = [run.y[0], run.y[1], y[0], y[1]];
                    #[cfg(test)]
                    let start = (run.y, run.t);
                    if self.commit_linear_span(run, inputs, t, y_new) {
                        charge(run, chained);
                        #[cfg(test)]
                        SPAN_LOG.with(|l| l.borrow_mut().push((start.0, start.1, t, y, bound)));
                        // Next span sized from this bound (it grows about as the span's cube).
                        let grow = (target / bound.max(1e-300)).cbrt().clamp(0.5, 2.0);
                        run.onion_linear.next =
                            ((tried.switches as f64 * 0.9 * grow).ceil() as usize).max(1);
                        run.onion_linear.declined = 0;
                        return true;
                    }
                    break;
                }
            }
            if tried.switches < 2 * MIN_SPAN || affordable - chained < MIN_SPAN {
                break;
            }
            span = (tried.switches / 2).max(1);
        }
        charge(run, chained);
        // Declined: retried after 1, 2, 4, ... switches, and not again in the step after
        // [`MAX_DECLINES`] in a row.
        let spans = &mut run.onion_linear;
        spans.declined += 1;
        spans.disabled = spans.declined > MAX_DECLINES;
        spans.retry_in = 1 << (spans.declined - 1).min(16);
        spans.next = MIN_SPAN;
        false
    }

    /// The chained maps over at most `span` switch intervals from `run.t` (to the step's end at
    /// most): the span's end, the onion and tilt there and the bound of
    /// [`Self::advance_onion_linear`].
    fn onion_linear_span(
        &self,
        run: &StepRun,
        s: &SteppingSchedule,
        inputs: &MotorInputs,
        span: usize,
    ) -> Tried {
        let (g, a, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let e = self.magnetoelastic_per_stress * s.stress_amplitude;
        let Some(ring) = self.linear_ring_term(run, inputs) else {
            return Tried {
                switches: 0,
                result: None,
            };
        };
        let psi0 = run.y[2];
        // `w`: the onion's turn since the span's start and its tilt, on the chained maps.
        let mut w = [0.0, run.y[3]];
        let mut time = run.t;
        let mut eps = [0.0, 0.0];
        let mut maps: Vec<(M2, [f64; 2])> = Vec::with_capacity(span.min(4096));
        let mut switches = 0;
        while switches < span && time < run.t_end {
            let next = s.next_switch_after(time).min(run.t_end);
            let h = next - time;
            let gamma = self.drive_at(inputs, time).direction;
            // Linearized about the maps' path at the switch, `centre`; the ring's torque there
            // too under a held bar, else about the span's start with the onion's turn since then
            // (`lead`) in its remainder.
            let centre = psi0 + w[0];
            let (value, stiffness, lead) = if ring.relinearized {
                let (value, stiffness) = self.ring_bar.torque_stiffness(centre - run.y[0]);
                (value, stiffness, 0.0)
            } else {
                (
                    ring.value + ring.stiffness * w[0],
                    ring.stiffness,
                    w[0].abs(),
                )
            };
            let (s2, c2) = turned_back(2.0 * (centre - gamma)).sin_cos();
            let (grad, d) = (e * s2 + value, 2.0 * e * c2 + stiffness);
            let am: M2 = [[-g * a * d, -g * t], [g * d, -g * a * t]];
            let b = [-g * a * grad, g * grad];
            switches += 1;
            #[cfg(test)]
            CHAINED.with(|c| c.set(c.get() + 1));
            let (Some(f), true) = (flow(&am, h), grad.is_finite() && d.is_finite()) else {
                return Tried {
                    switches,
                    result: None,
                };
            };
            // The onion's turn within the switch and its tilt.
            let u = [0.0, w[1]];
            let eu = apply(&f.e, u);
            let jb = apply(&f.j, b);
            let u_next = [eu[0] + jb[0], eu[1] + jb[1]];
            let au = apply(&am, u);
            let slope = apply(&f.k, [(au[0] + b[0]).abs(), (au[1] + b[1]).abs()])[0];
            let spread = apply(
                &f.k,
                [u[0].abs() + h * b[0].abs(), u[1].abs() + h * b[1].abs()],
            )[0];
            let reach = (u_next[0].abs() + 0.5 * h * slope).min(spread);
            // The dropped term's effect over the interval per unit of `|R|`: the rates
            // `g (-a R, R)` through `|exp(A s)|`.
            let unit = apply(&f.k, [h * g * a, h * g]);
            // The bar's turn since the span's start, at most, on a free rotor
            // ([`Motor::free_ring_term`]).
            let p = ring.drift_speed * (next - run.t);
            let quadratic = 2.0 * e.abs();
            let remainder = |r: f64| {
                let q = r + lead + p;
                quadratic * r * r + ring.curvature * q * q + stiffness.abs() * p + ring.constant
            };
            // A bound `rb` on `|R|` that holds given itself (`remainder(reach + (K eps)_0 +
            // unit_0 rb) < rb`) holds: the true path cannot first leave the reach it implies.
            let near = reach + apply(&f.k, eps)[0];
            let rb = 1.25 * remainder(near + unit[0] * remainder(near));
            let holds = remainder(near + unit[0] * rb) < rb || rb == 0.0;
            let c = [unit[0] * rb, unit[1] * rb];
            let carried = apply(&abs(&f.e), eps);
            eps = [carried[0] + c[0], carried[1] + c[1]];
            if !(holds
                && c[0].is_finite()
                && c[1].is_finite()
                && eps[0].is_finite()
                && eps[1].is_finite())
            {
                return Tried {
                    switches,
                    result: None,
                };
            }
            maps.push((f.e, c));
            w = [w[0] + u_next[0], u_next[1]];
            time = next;
        }
        // Carried to the end by the exact products of the later maps.
        let mut later: M2 = [[1.0, 0.0], [0.0, 1.0]];
        let mut ends = [0.0, 0.0];
        for (e_k, c_k) in maps.iter().rev() {
            let carried = apply(&abs(&later), *c_k);
            ends = [ends[0] + carried[0], ends[1] + carried[1]];
            later = mul(&later, e_k);
        }
        let bound = ends[0].max(ends[1]);
        let y = [psi0 + w[0], w[1]];
        Tried {
            switches,
            result: (bound.is_finite() && y[0].is_finite() && y[1].is_finite())
                .then_some((time, y, bound)),
        }
    }

    /// Moves the run to `t` with the onion and tilt of `y` and the rotor on its drift; `false`
    /// (nothing changed) if the state would leave its bounds.
    fn commit_linear_span(
        &self,
        run: &mut StepRun,
        inputs: &MotorInputs,
        t: f64,
        mut y: super::Vector,
    ) -> bool {
        self.drift_rotor(&mut y, inputs, t - run.t);
        if !(self.rotor_sane(&y) && Self::onion_sane(&y)) {
            return false;
        }
        // At a switch: the next pass tries the next span before resolving anything.
        run.jump_onion_to(y, t, t);
        run.following = f64::NAN;
        #[cfg(test)]
        SPANS.with(|c| c.set(c.get() + 1));
        true
    }
}

/// A tried macro span: the switch intervals chained, and the span's end, onion angle and tilt
/// and bound where they are finite.
struct Tried {
    switches: usize,
    result: Option<(f64, [f64; 2], f64)>,
}
