//! The well in which the orbit-averaged advance ([`Motor::advance_orbits`]) checks the Gilbert
//! onion, kept from one check to the next ([`Motor::kept_onion_well`]).
//!
//! The advance's check settles the onion onto its well's minimum `psi*` and searches the rims
//! either side of it (the maxima of eq. 3.3 plus eq. 3.4, `Landscape::well_rims`), then
//! evaluates the floor `U(psi*)` and the barrier there. Those are a function of the landscape
//! and of `psi*` alone. Under a locked rotor and a held drive the landscape is frozen over the
//! segment, and the checks, refused attempt after attempt for the averaged phase's drift
//! (`orbit_phase.rs`) while the ringing decays, settle onto a handful of minima a few units of
//! roundoff apart: the well found for the same landscape (the rotor's angle, the strain
//! direction and eq. 3.4's coefficient, bit for bit) and the same minimum (bit for bit) is taken
//! again without the rims' search, and is the well that search would find.

use super::onion::Landscape;
use super::orbit::Well;
use super::Motor;

#[cfg(test)]
thread_local! {
    /// Wells of the averaged advance's checks taken from the one kept, on this thread (for tests).
    pub(super) static REUSED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Wells of the averaged advance's checks searched for, on this thread (for tests).
    pub(super) static SEARCHED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// Searches every well on this thread (for tests: the results must not change).
    pub(super) static OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// The wells that the averaged advance's checks found in one landscape (the bits of its rotor
/// angle, strain direction and magnetoelastic coefficient), each with the bits of the minimum it
/// was found for: the settled minimum differs by a few units of roundoff with the onion's place
/// on its orbit, up to [`KEPT`] of them are kept.
///
/// (Allocated at the first well found: a step that never checks costs nothing.)
#[derive(Clone, Debug)]
pub(super) struct KeptWell {
    landscape: [u64; 3],
    wells: Vec<(u64, Well)>,
    /// The entry replaced next once [`KEPT`] are kept.
    next: usize,
}

/// The wells kept per landscape.
const KEPT: usize = 8;

impl KeptWell {
    pub(super) const NONE: KeptWell = KeptWell {
        landscape: [0; 3],
        wells: Vec::new(),
        next: 0,
    };
}

impl Motor {
    /// The well of `land` whose minimum is `minimum` (`land.settle` of the onion), as
    /// [`Self::onion_well`] finds it: the one in `kept` where it was found for the same
    /// landscape and minimum, else searched for and kept (see the module documentation).
    pub(super) fn kept_onion_well(
        &self,
        kept: &mut KeptWell,
        land: &Landscape,
        minimum: f64,
    ) -> Option<Well> {
        let landscape =
            [land.bar_angle, land.strain_direction, land.magnetoelastic].map(f64::to_bits);
        if kept.landscape != landscape {
            kept.landscape = landscape;
            kept.wells.clear();
            kept.next = 0;
        }
        let key = minimum.to_bits();
        let found = kept.wells.iter().find(|e| e.0 == key).map(|e| e.1);
        #[cfg(test)]
        let found = found.filter(|_| !OFF.with(|c| c.get()));
        #[cfg(test)]
        (if found.is_some() { &REUSED } else { &SEARCHED }).with(|c| c.set(c.get() + 1));
        if found.is_some() {
            return found;
        }
        let well = self.well_of_minimum(land, minimum);
        if let Some(w) = well {
            if kept.wells.len() < KEPT {
                kept.wells.push((key, w));
            } else {
                kept.wells[kept.next] = (key, w);
                kept.next = (kept.next + 1) % KEPT;
            }
        }
        well
    }
}
