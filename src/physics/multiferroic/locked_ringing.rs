//! A locked rotor's Gilbert onion ringing in its frozen well: the time its energy takes to decay
//! to the tolerance, bounded by the orbit-averaged loss ([`Motor::locked_ringing_decays`]).
//!
//! With the rotor locked the landscape `U(psi)` of eq. 3.3 plus eq. 3.4 is frozen and the
//! macrospin's energy `E = U - U(psi*) + T theta^2 / 2` only falls,
//! `dE/dt = -g alpha (U'^2 + T^2 theta^2)`: an onion below its well's lowest rim stays in the
//! well. The instantaneous rate vanishes twice an orbit (at the turning points `U'` is all, at
//! the bottom the tilt), so the sublevel-set bound of `ringing.rs`, which holds at every instant,
//! is `min(kappa, T) / ((k + T) / 2)` times slower than the ringing's decay over whole orbits,
//! 8 times for `k / T = 15` and never fast enough where the well is much softer or stiffer than
//! the tilt. Over an orbit the energy falls by the undamped orbit's
//! `alpha (T J + closed int U'^2 / (T |theta|) dpsi)` (`orbit.rs`) to first order in the loss per
//! orbit: the decay time from `E0` to `E1` is `int dE / |<E'>(E)|`, bounded here on bins of the
//! energy a factor [`BIN`] apart by each bin's slower end (`|<E'>| / E` falls towards the rim,
//! where the orbits linger, and rises to the linearization's `g alpha (k + T)` at the minimum).

use super::orbit::point;
use super::{Drive, Motor, Vector};

/// The orbit-averaged decay applies up to this fraction of the lowest rim's height above the
/// minimum (the orbit's quadrature is converged within 1e-10 there, see `orbit.rs`).
const RIM_MARGIN: f64 = 0.999;
/// At most this fraction of the energy lost per orbit (the averaging's small parameter).
const MAX_LOSS_PER_ORBIT: f64 = 0.1;
/// The averaged decay time is held within this fraction of the time left in the segment: the
/// actual energy, staircase-like over each orbit, lags the averaged one by at most an orbit's
/// loss, and the averaging errs by the loss per orbit to second order.
pub(super) const TIME_MARGIN: f64 = 0.75;
/// An orbit's quadrature in [`Motor::locked_ringing_decays`] (about 1.4 us) in the budget's
/// units, substeps of the quasi-static onion (0.32 us, see [`super::GILBERT_SUBSTEP_WEIGHT`]),
/// so that the budget bounds the check's cost as it bounds the substeps'.
pub(super) const ORBIT_WEIGHT: u32 = 4;
#[cfg(test)]
thread_local! {
    /// The orbits' quadratures of [`Motor::locked_ringing_decays`] and the units charged for
    /// them on this thread (tests count them).
    pub(super) static DECAY_CHARGE: std::cell::Cell<(u64, u64)> =
        const { std::cell::Cell::new((0, 0)) };
}

/// The energy's ratio between the nodes of the decay time's quadrature.
const BIN: f64 = 2.0;
/// Below this fraction of the window `k / (2 M)` in amplitude the orbit is linear: the curvature
/// is within `M |s| <= 0.025 k` of `k` along it.
const LINEAR_REACH: f64 = 0.05;

impl Motor {
    /// Whether the Gilbert onion at `y` with the rotor locked (drive `d`) rings in the well of
    /// the minimum it settles into and, at its orbit-averaged energy loss, ends the `remaining`
    /// time of its segment (s) within the tolerance of that minimum in angle and tilt: its
    /// averaged decay time to the energy `E1 = tol^2 min(5 k / 12, T / 2)` (below which the
    /// onion lies within `sqrt(12 E / (5 k))` of the minimum, inside the window of half the
    /// curvature, and its tilt within `sqrt(2 E / T)`) is at most [`TIME_MARGIN`] of
    /// `remaining`. Only from at most [`RIM_MARGIN`] of the lowest rim, losing at most
    /// [`MAX_LOSS_PER_ORBIT`] of the energy per orbit along the way. `settled` is the minimum the
    /// onion settles into; `retry` the energy above it (J) below which the check is tried again in
    /// this segment, set on each failure: half the energy where the decay time was too long (it
    /// only shrinks as the energy falls), just below it where the onion was too close to a rim.
    /// `orbits` counts the orbits' quadratures it evaluates (up to 14 a check, about 1.4 us
    /// each), for which the step pays [`ORBIT_WEIGHT`] units of its budget each.
    pub(super) fn locked_ringing_decays(
        &self,
        y: &Vector,
        d: &Drive,
        settled: f64,
        remaining: f64,
        retry: &mut f64,
        orbits: &mut u32,
    ) -> bool {
        if !d.locked || remaining.is_nan() || remaining <= 0.0 {
            return false;
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let (g, alpha, t) = (
            self.llg_rate,
            self.params.gilbert_damping,
            self.tilt_stiffness,
        );
        let tol = self.params.tolerance;
        // The linearization at the minimum first (no rims): its averaged energy decay rate
        // `g alpha (k + T)` bounds the decay time from below, its loss per orbit
        // `2 pi alpha (k + T) / sqrt(k T)` must be small.
        let k = land.curvature(settled);
        let m = land.third_derivative_bound();
        if !(k > 0.0 && k.is_finite() && m > 0.0 && m.is_finite()) {
            return false;
        }
        let linear_rate = g * alpha * (k + t);
        let linear_loss = 2.0 * std::f64::consts::PI * alpha * (k + t) / (k * t).sqrt();
        let floor = point(&land, settled).0;
        let e0 = point(&land, y[2]).0 - floor + 0.5 * t * y[3] * y[3];
        let e1 = tol * tol * (5.0 * k / 12.0).min(0.5 * t);
        let window = 0.5 * k / m;
        if !(linear_loss <= MAX_LOSS_PER_ORBIT
            && e0.is_finite()
            && e1 > 0.0
            && (12.0 * e1 / (5.0 * k)).sqrt() < window)
        {
            return false;
        }
        if e0 <= e1 {
            return true;
        }
        // A cheap refusal first, at twice the linearization's rate (the averaged rate falls below
        // it towards the rims of eq. 3.4's softening wells: 0.2 of it at 0.99 of the rim at
        // `k / T = 16`).
        if (e0 / e1).ln() > 2.0 * TIME_MARGIN * remaining * linear_rate || e0 > *retry {
            return false;
        }
        *retry = RIM_MARGIN * e0;
        let Some(well) = self.onion_well(&land, y[2]) else {
            return false;
        };
        if !(well.below < y[2]
            && y[2] < well.above
            && (well.minimum - settled).abs() <= 1e-9 * (1.0 + settled.abs())
            && e0 <= RIM_MARGIN * well.barrier)
        {
            return false;
        }
        *retry = 0.5 * e0;
        // The averaged rate `|<E'>| / E` (1/s) of the orbit at `e`, `None` where the orbit is
        // not found or loses too much per orbit.
        let mut guess = (well.minimum - 1e-3, well.minimum + 1e-3);
        let mut ratio = |e: f64| -> Option<f64> {
            *orbits = orbits.saturating_add(1);
            let o = self.orbit(&land, &well, e, guess)?;
            guess = (o.below, o.above);
            let loss = -o.damping_rate(alpha) * o.period / e;
            (loss > 0.0 && loss <= MAX_LOSS_PER_ORBIT).then_some(loss / o.period)
        };
        let budget = TIME_MARGIN * remaining;
        let linear_energy = 5.0 * k / 12.0 * (LINEAR_REACH * window).powi(2);
        let (mut e, mut rate) = match ratio(e0) {
            Some(r) => (e0, r),
            None => return false,
        };
        let mut time = 0.0;
        while e > e1.max(linear_energy) {
            let next = (e / BIN).max(e1);
            let Some(r) = ratio(next) else {
                return false;
            };
            time += (e / next).ln() / rate.min(r);
            if time > budget {
                return false;
            }
            (e, rate) = (next, r);
        }
        // The linear orbits left: curvature within 0.025 k of `k`, the averaged rate within
        // the linearization's at the lower curvature and the last orbit's.
        if e > e1 {
            let linear = g * alpha * (0.975 * k + t);
            time += (e / e1).ln() / rate.min(linear);
        }
        time <= budget
    }
}
