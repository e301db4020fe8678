//! The minimum of eq. 3.4 that the Gilbert onion at a state settles into, marched once for that
//! state: a pass of [`Motor::step`]'s loop asks for it from several checks of the onion's branch
//! (the budget's forecast and drops, [`Motor::relaxed_onion`]) at the same state and drive.

use super::angles::Angles;
use super::{Drive, Motor, Vector};
use std::cell::Cell;

/// The last settled minimum ([`Kept`]), and the last angles computed afresh where a settle
/// started ([`SettleMemo::fresh_angles`]).
#[derive(Debug, Default)]
pub(super) struct SettleMemo(Cell<Option<Kept>>, Cell<Option<Angles>>);

/// A settled minimum with the state and drive it was marched for (rotor and onion angle, strain
/// direction and stress, bit for bit: the landscape and the march's start are theirs), and eq.
/// 3.4's curvature there once evaluated.
#[derive(Clone, Copy, Debug)]
struct Kept {
    key: [u64; 4],
    minimum: Angles,
    curvature: Option<f64>,
}

impl SettleMemo {
    fn key(y: &Vector, d: &Drive) -> [u64; 4] {
        [
            y[0].to_bits(),
            y[2].to_bits(),
            d.direction.to_bits(),
            d.stress.to_bits(),
        ]
    }

    /// The minimum kept for the onion at `y` under `d`, if one is.
    pub(super) fn kept(&self, y: &Vector, d: &Drive) -> Option<Angles> {
        self.0
            .get()
            .filter(|k| k.key == Self::key(y, d))
            .map(|k| k.minimum)
    }

    /// The minimum for the onion at `y` under `d`: the kept one, or `march`'s result, kept.
    /// `march` must be the settle of the onion at `y` in eq. 3.4's landscape for `d` from the
    /// angles there ([`Motor::settled_minimum`]'s march, whichever way its first slope is had).
    pub(super) fn get_or(&self, y: &Vector, d: &Drive, march: impl FnOnce() -> Angles) -> Angles {
        if let Some(a) = self.kept(y, d) {
            return a;
        }
        let a = march();
        self.0.set(Some(Kept {
            key: Self::key(y, d),
            minimum: a,
            curvature: None,
        }));
        a
    }
}

impl SettleMemo {
    /// [`Angles::exact`] at the onion at `y` under `d`, kept: right after a switch the
    /// [`Motor::constrain`] that follows the branch checks computes the same fresh angles
    /// ([`Self::fresh_hint`]).
    pub(super) fn fresh_angles(&self, y: &Vector, d: &Drive) -> Angles {
        if let Some(a) = self.fresh_at(y, d) {
            return a;
        }
        let a = Angles::exact(y[2], y[0], d.direction);
        self.1.set(Some(a));
        a
    }

    /// The kept fresh angles if they are those at `y` under `d`, bit for bit.
    fn fresh_at(&self, y: &Vector, d: &Drive) -> Option<Angles> {
        let same = |a: &Angles| {
            a.onion.to_bits() == y[2].to_bits()
                && a.bar.to_bits() == y[0].to_bits()
                && a.strain.to_bits() == d.direction.to_bits()
        };
        self.1.get().filter(same)
    }

    /// The kept fresh angles at `y` under `d` where turning from `hint` would compute those very
    /// angles afresh (the move from them is then nil, and gives them bit for bit), else `None`.
    pub(super) fn fresh_hint(
        &self,
        hint: Option<&Angles>,
        y: &Vector,
        d: &Drive,
    ) -> Option<Angles> {
        // The cheap bit test first: most passes keep nothing for this state.
        let fresh = self.fresh_at(y, d)?;
        hint.is_none_or(|h| h.moves_afresh(y[2], y[0], d.direction))
            .then_some(fresh)
    }
}

impl Motor {
    /// The angles at the minimum of eq. 3.4 that the onion at `y` settles into under `d`
    /// ([`super::onion::Landscape::settle`] from the angles at the onion), marched once per
    /// state and drive through `memo`.
    pub(super) fn settled_minimum(&self, memo: &SettleMemo, y: &Vector, d: &Drive) -> Angles {
        memo.get_or(y, d, || {
            let land = self.landscape(y[0], d.direction, d.stress);
            land.settle_from(memo.fresh_angles(y, d))
        })
    }

    /// [`Self::settled_minimum`] with eq. 3.4's curvature there, each evaluated once per state
    /// and drive.
    pub(super) fn settled_curvature(
        &self,
        memo: &SettleMemo,
        y: &Vector,
        d: &Drive,
    ) -> (Angles, f64) {
        let minimum = self.settled_minimum(memo, y, d);
        let key = SettleMemo::key(y, d);
        let kept = memo.0.get().filter(|kept| kept.key == key);
        if let Some(k) = kept.and_then(|kept| kept.curvature) {
            return (minimum, k);
        }
        let k = self
            .landscape(y[0], d.direction, d.stress)
            .curvature(minimum.onion);
        memo.0.set(Some(Kept {
            key,
            minimum,
            curvature: Some(k),
        }));
        (minimum, k)
    }
}
