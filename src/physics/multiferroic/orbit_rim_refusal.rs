//! A locked rotor's onion trapped in its well too near the rim for the orbit-averaged advance
//! ([`Motor::advance_orbits`]): the advance's check, which finds the well's rims by a search, is
//! repeated from the well it found only ([`Motor::rim_refusal_holds`]).
//!
//! With the rotor locked and the drive held, eq. 3.3 plus eq. 3.4 is a frozen landscape `U(psi)`
//! over the segment: the well that an onion strictly between its rims settles into, its
//! minimum's energy and its barrier are the same at every pass. The advance refuses an onion
//! whose energy above the minimum, `U(psi) - U(psi*) + T theta^2 / 2`, exceeds [`RIM_MARGIN`]
//! of the barrier; that is decided again from the well kept, at the cost of one evaluation of
//! the landscape, and the advance's check is made in full (its well found afresh) only where the
//! energy lies within [`ROUNDING`] of that level, where the minimum's and the rims' rounding
//! could decide, or the onion left the well kept.
//!
//! A free rotor's landscape turns with it, and no well is kept from one check to the next; its
//! onion is refused before the search ([`Motor::above_every_barrier`]) where its energy above the
//! minimum exceeds [`RIM_MARGIN`] of the landscape's whole range, which bounds every barrier.
//!
//! [`RIM_MARGIN`]: super::orbit::RIM_MARGIN

use super::onion::Landscape;
use super::orbit::{point, Well, RIM_MARGIN};
use super::{Drive, Motor, Vector};

/// The energy is compared with the refusal's level to within this fraction of the barrier.
const ROUNDING: f64 = 1e-6;

#[cfg(test)]
thread_local! {
    /// Checks of the averaged advance skipped on this thread (for tests).
    pub(super) static SKIPPED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Checks of the averaged advance made in full on this thread (for tests).
    pub(super) static FULL: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Free rotors' onions refused before the rims' search on this thread (for tests).
    pub(super) static FREE_REFUSED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Searches every free rotor's well on this thread (for tests: the results must not change).
    pub(super) static FREE_OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Makes every check in full on this thread (for tests: the results must not change).
    pub(super) static OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// A locked rotor's well in which the averaged advance refused an onion too near the rim: in
/// the segment ending at `segment_end`, with the rotor at `rotor`, the rims `below` and `above`,
/// the minimum's energy `floor` and the energy above it from which the advance refuses, `level`
/// (J).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct RimRefusal {
    segment_end: f64,
    rotor: f64,
    below: f64,
    above: f64,
    floor: f64,
    level: f64,
}

impl RimRefusal {
    pub(super) const NONE: RimRefusal = RimRefusal {
        segment_end: f64::NAN,
        rotor: f64::NAN,
        below: f64::NAN,
        above: f64::NAN,
        floor: f64::NAN,
        level: f64::NAN,
    };

    /// The refusal in `well` (the rotor at `rotor`) of an energy above `margin` times its
    /// barrier, in the segment ending at `segment_end`.
    pub(super) fn new(segment_end: f64, rotor: f64, well: &Well, margin: f64) -> RimRefusal {
        RimRefusal {
            segment_end,
            rotor,
            below: well.below,
            above: well.above,
            floor: well.floor,
            level: (margin + ROUNDING) * well.barrier,
        }
    }
}

/// A bound of the range of `U` in `land` (J): eq. 3.3's `K (1/B - 1/A)` is monotone in the
/// offset's cosine, from `-|K| (1 / |r - a| - 1 / (r + a))` to minus that, a span of twice
/// that, and eq. 3.4's `E sin^2` spans `|E|`; widened by far more than the energies' rounding.
pub(super) fn energy_range(land: &Landscape) -> f64 {
    let r = land.ring_bar;
    let (a, w) = (r.bar_charge_radius, r.wall_radius);
    let ring = 2.0 * r.coupling.abs() * (1.0 / (w - a).abs() - 1.0 / (w + a));
    (ring + land.magnetoelastic.abs()) * (1.0 + 1e-6)
}

impl Motor {
    /// Whether the averaged advance's check refuses a free rotor's onion at `psi` without the
    /// search for the rims of the well of `minimum` in `land`: its energy `e` above the minimum
    /// (J, as the check computes it) exceeds [`RIM_MARGIN`] of the range of `U`
    /// ([`energy_range`]), which bounds every barrier, so the check refuses that onion in
    /// whatever well the search finds, or none.
    pub(super) fn above_every_barrier(
        &self,
        land: &Landscape,
        d: &Drive,
        (psi, minimum): (f64, f64),
        e: f64,
    ) -> bool {
        let refused = !d.locked && e > RIM_MARGIN * energy_range(land);
        #[cfg(test)]
        let refused = refused && !FREE_OFF.with(|c| c.get());
        #[cfg(test)]
        if refused {
            FREE_REFUSED.with(|c| c.set(c.get() + 1));
            // The full check's refusal, from the well the search finds.
            if let Some(w) = self.well_of_minimum(land, minimum) {
                let inside = w.below < psi && psi < w.above;
                assert!(!(inside && e <= RIM_MARGIN * w.barrier), "{e} {w:?}");
            }
        }
        #[cfg(not(test))]
        let _ = (psi, minimum);
        refused
    }

    /// Whether the averaged advance would refuse the locked rotor's onion at `y` under the drive
    /// `d` in the segment ending at `segment_end` for its energy, by the well of the last such
    /// refusal `r` (see the module documentation).
    pub(super) fn rim_refusal_holds(
        &self,
        r: &RimRefusal,
        y: &Vector,
        d: &Drive,
        segment_end: f64,
    ) -> bool {
        let holds = self.energy_above_level(r, y, d, segment_end);
        #[cfg(test)]
        let holds = holds && !OFF.with(|c| c.get());
        #[cfg(test)]
        (if holds { &SKIPPED } else { &FULL }).with(|c| c.set(c.get() + 1));
        holds
    }

    /// The onion at `y` lies strictly between the rims of `r`'s well with its energy above the
    /// refusal's level, the rotor and the segment those of `r`.
    fn energy_above_level(&self, r: &RimRefusal, y: &Vector, d: &Drive, segment_end: f64) -> bool {
        if !(d.locked && r.segment_end == segment_end && r.rotor == y[0]) {
            return false;
        }
        if !(r.below < y[2] && y[2] < r.above) {
            return false;
        }
        let land = self.landscape(y[0], d.direction, d.stress);
        let e = point(&land, y[2]).0 - r.floor + 0.5 * self.tilt_stiffness * y[3] * y[3];
        e > r.level
    }
}
