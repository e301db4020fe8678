//! A locked rotor's Gilbert onion under a held drive: its energy bounds which wells it can
//! reach, and a substep that breaks that bound is rejected ([`Motor::energy_checked_error`]).
//!
//! With the rotor locked and the drive held, eq. 3.3 plus eq. 3.4 is a frozen landscape
//! `U(psi)`, and the macrospin's energy `E = U(psi) + T theta^2 / 2` only falls,
//! `dE/dt = -g alpha (U'^2 + T^2 theta^2)` (`locked_ringing.rs`), at most at
//! `g alpha (G^2 + 2 T (E - U_min))` (`G` a bound of `|U'|`, `U_min` the landscape's lowest
//! minimum: the tilt's energy `T theta^2 / 2` is at most `E - U_min`). So the exact solution
//! from any state never passes a maximum of `U` (a rim) higher than its energy, and the energy
//! crosses a rim's height only downwards, no faster than that rate: its energy sets how many
//! turns it can still make and which well can capture it.
//!
//! The error control measures the angles alone, and the energy decides between wells on
//! differences far below what an angle of the tolerance is worth. An onion released 2e-5 of
//! its well's depth below the rim was carried over it by a substep whose error estimate passed
//! (0.68 of a 0.19 rad tolerance), then pumped by later substeps to 30 times the depth, and
//! ended 80 turns (2,676 tolerances) from a plain RK4, which keeps it in its well; the same
//! onion given a tilt that spins it above every rim lost energy 25 and 127 times faster than
//! the damping can take in its third and fourth substeps, and was captured in a well. A substep that the angles' control accepts
//! is rejected (its error estimate raised to [`BEYOND_RIM`]) that
//! - ends beyond a rim of the well it starts in that is higher than the energy it can have
//!   (its energy at the substep's start, at most its energy where the step first met this
//!   landscape);
//! - carries the energy up across the height of a rim, or down across one faster than the
//!   damping's bound allows;
//! - starts above every rim (where no rim's height bounds the energy's drift, which sets how
//!   far the onion spins) and ends with more energy than it started with, or less than the
//!   damping's bound leaves;
//! - turns the tilt back while the onion is above every rim (that needs a turning point,
//!   `U(psi) = E`, which no point of the landscape reaches).
//!
//! It is retried shorter; at the budget's smallest size it is taken flagged, as any forced
//! substep. Between the rims' heights, the energy's error is left to the angles' control. The rims' heights are found by walking the landscape's wells over a turn (a few
//! settles), once per landscape and only where it matters: from its second substep on, once a
//! substep's energy rose, or fell faster than the damping can take for any `U_min` (a fast
//! schedule's segments of one substep, and onions whose error keeps their energy within these
//! bounds, never walk).

use super::decoupled::torque_bound;
use super::onion::Landscape;
use super::orbit::point;
use super::{Drive, Motor, Vector};

/// The error given to a substep that breaks the energy bound: the step-size rule then shortens
/// it to about 0.45 of its size.
pub(super) const BEYOND_RIM: f64 = 8.0;
/// The most wells walked over a turn of the landscape to find its rims.
const MAX_WELLS: usize = 8;
/// Energies within this fraction of the landscape's span over a turn are equal to rounding.
pub(super) const ROUNDING: f64 = 1e-9;
/// The rims are looked for from this many substeps in one landscape on (see
/// [`Motor::energy_checked_error`]).
const LEVELS_AFTER: u32 = 2;

/// The rims and the lowest minimum of a landscape over a turn.
#[derive(Clone, Copy, Debug)]
pub(super) struct Levels {
    /// The rims' heights (J), the first `count` of them.
    rims: [f64; MAX_WELLS + 1],
    count: usize,
    /// The lowest minimum (J).
    floor: f64,
}

impl Levels {
    fn rims(&self) -> &[f64] {
        &self.rims[..self.count]
    }

    fn highest(&self) -> f64 {
        self.rims().iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
    }

    /// Whether a rim's height lies in `(low, high]`.
    pub(super) fn between(&self, low: f64, high: f64) -> bool {
        self.rims().iter().any(|&h| low < h && h <= high)
    }
}

/// What the energy check knows of the landscape in effect (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(super) struct RimLedger {
    /// The landscape: rotor angle, strain direction and stress.
    key: [f64; 3],
    /// The onion's energy (J) where the step first met this landscape.
    ceiling: f64,
    /// The landscape's rims over a turn; `None` where they were not found (nothing is checked).
    levels: Option<Levels>,
    /// The well the onion was last found in: its rims (rad) and their heights (J).
    well: Option<[f64; 4]>,
    /// Substeps checked in this landscape, and whether its rims were looked for.
    substeps: u32,
    walked: bool,
    /// The last substep's start and end with their energies (J).
    last: [(Vector, f64); 2],
}

impl RimLedger {
    pub(super) const NONE: RimLedger = RimLedger {
        key: [f64::NAN; 3],
        ceiling: f64::INFINITY,
        levels: None,
        well: None,
        substeps: 0,
        walked: false,
        last: [([f64::NAN; 4], 0.0); 2],
    };
}

impl Motor {
    /// The error estimate `err` (in tolerances) of the substep of `dt` (s) from `y` to `y_new`
    /// under the drive `d`, raised to [`BEYOND_RIM`] where it breaks the energy bound of a locked
    /// rotor's Gilbert onion (see the module documentation); `err` itself otherwise.
    pub(super) fn energy_checked_error(
        &self,
        ledger: &mut RimLedger,
        (y, y_new): (&Vector, &Vector),
        dt: f64,
        d: &Drive,
        err: f64,
    ) -> f64 {
        // A substep rejected already needs nothing more; one forced beyond it is flagged.
        if !d.locked || self.quasi_static() || err > 1.0 || err.is_nan() {
            return err;
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let t = self.tilt_stiffness;
        let key = [y[0], d.direction, d.stress];
        if ledger.key != key {
            *ledger = RimLedger {
                key,
                ..RimLedger::NONE
            };
        }
        // The start's energy is usually the last accepted substep's end's, or a rejected one's.
        let energy = |y: &Vector| point(&land, y[2]).0 + 0.5 * t * y[3] * y[3];
        let before = match ledger.last.iter().find(|(state, _)| state == y) {
            Some(&(_, e)) => e,
            None => energy(y),
        };
        let after = energy(y_new);
        ledger.last = [(*y, before), (*y_new, after)];
        if ledger.substeps == 0 {
            ledger.ceiling = before;
        }
        ledger.substeps = ledger.substeps.saturating_add(1);
        // `|U'| <= G`, and `U` spans at most `2 pi G` over a turn.
        let gradient = torque_bound(&self.ring_bar) + land.magnetoelastic.abs();
        let span = 2.0 * std::f64::consts::PI * gradient;
        let rate = self.llg_rate * self.params.gilbert_damping;
        // The fastest loss for a lowest minimum `floor` (the tilt's energy is at most `E - floor`).
        let loss = |floor: f64| rate * (gradient * gradient + 2.0 * t * (before - floor).max(0.0));
        let rounding = ROUNDING * span;
        let possible = |floor: f64| {
            before - dt * loss(floor) - rounding <= after && after <= before + rounding
        };
        // The rims are looked for once the landscape has held for a few substeps (a fast
        // schedule's short segments are not worth the walk) and the energy moved as it cannot
        // for any `U_min` (at least `U(psi) - 2 pi G`).
        if ledger.levels.is_none() {
            if ledger.substeps < LEVELS_AFTER
                || ledger.walked
                || possible(point(&land, y[2]).0 - span)
            {
                return err;
            }
            ledger.walked = true;
            ledger.levels = self.levels(&land, y[2]);
        }
        let Some(levels) = ledger.levels else {
            return err;
        };
        let least = before - dt * loss(levels.floor) - rounding;
        // (A NaN fails the comparisons and keeps `err`, which the caller bounds.)
        // Above every rim the tilt cannot pass zero: that needs a turning point, `U = E`.
        let turned = y[3] * y_new[3] < 0.0 && least > levels.highest();
        // Above every rim no rim's height bounds the energy's drift, which sets how far the onion
        // spins: held to what the damping allows.
        let spinning = before > levels.highest() && !possible(levels.floor);
        if turned
            || spinning
            || levels.between(before + rounding, after)
            || levels.between(after, least)
        {
            return err.max(BEYOND_RIM);
        }
        let reach = ledger.ceiling.min(before) + rounding;
        // Above the highest rim nothing holds the onion back.
        if reach >= levels.highest() || reach.is_nan() {
            return err;
        }
        let inside = |w: &[f64; 4]| w[0] < y[2] && y[2] < w[1];
        if !ledger.well.as_ref().is_some_and(inside) {
            ledger.well = self.onion_well(&land, y[2]).map(|w| {
                [
                    w.below,
                    w.above,
                    point(&land, w.below).0,
                    point(&land, w.above).0,
                ]
            });
        }
        match ledger.well.filter(inside) {
            Some([below, above, low, high])
                if (y_new[2] <= below && reach < low) || (y_new[2] >= above && reach < high) =>
            {
                err.max(BEYOND_RIM)
            }
            _ => err,
        }
    }

    /// The rims and lowest minimum of the landscape `land` over a turn, from the wells met
    /// walking up from the one about `near`; `None` where a well is not found.
    pub(super) fn levels(&self, land: &Landscape, near: f64) -> Option<Levels> {
        let first = self.onion_well(land, near)?;
        let end = first.below + 2.0 * std::f64::consts::PI;
        let mut levels = Levels {
            rims: [0.0; MAX_WELLS + 1],
            count: 1,
            floor: first.floor,
        };
        levels.rims[0] = point(land, first.below).0;
        let mut above = first.above;
        for _ in 0..MAX_WELLS {
            if above >= end - 1e-9 * (1.0 + end.abs()) {
                return Some(levels);
            }
            levels.rims[levels.count] = point(land, above).0;
            levels.count += 1;
            // Just past the rim the landscape falls away forward: the next well's settle.
            let w = self.onion_well(land, above + 1e-6 * (1.0 + above.abs()))?;
            if w.above <= above {
                return None;
            }
            levels.floor = levels.floor.min(w.floor);
            above = w.above;
        }
        None
    }
}
