//! Sines and cosines of the two angles of eq. 3.3-3.4, carried from one evaluation to the next.
//!
//! Every evaluation of the quasi-static onion (its Newton iteration) and of the rotor's force needs
//! `sin`/`cos` of the offset `beta = psi - phi` (eq. 3.3) and of `2 (psi - gamma)` (eq. 3.4). Along
//! a substep both angles move by tiny amounts, so the new values are the old ones turned by the
//! small increment (angle addition with a short Taylor series of the increment's `sin`/`cos`)
//! instead of two libm `sin_cos` calls, which were a third of a motor step. Far moves, and every
//! [`MAX_ROTATIONS`]-th move (so rounding cannot build up), are computed afresh.

/// Increments (rad) up to which angle addition is used: the series below are then exact to
/// rounding (the first omitted terms are `d^15/15!` ~ 1e-23 d and `d^16/16!` ~ 2e-24 at 0.3
/// rad). The Gilbert onion turns by tenths of a radian per substep while it rings.
const MAX_TURN: f64 = 0.3;
/// Moves by angle addition before the next fresh `sin_cos`.
const MAX_ROTATIONS: u32 = 32;

/// Above this size (rad) glibc's `sin` and `cos` take the Payne-Hanek reduction (from about 1e8),
/// ten to fifty times a normal call: restored or fuzzed states with an onion 1e12 rad from its
/// rotor cut the fuzzer to a few sequences a second.
const SLOW_ARGUMENT: f64 = 5e7;

/// `x` less whole turns (`rem_euclid(2 pi)`) where libm would take its slow reduction, else `x`
/// unchanged. The rounding of 2 pi times the turns (about `|x| 4e-17`) stays below the spacing of
/// `x` itself (`|x| 1.1e-16`), so the argument loses no accuracy it had.
#[inline(always)]
pub fn turned_back(x: f64) -> f64 {
    if x.abs() < SLOW_ARGUMENT {
        x
    } else {
        x.rem_euclid(std::f64::consts::TAU)
    }
}

/// `sin`/`cos` of `psi - phi` and of `2 (psi - gamma)` at one onion angle `psi`, rotor angle `phi`
/// and strain direction `gamma`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Angles {
    pub onion: f64,
    pub bar: f64,
    pub strain: f64,
    pub sin_offset: f64,
    pub cos_offset: f64,
    pub sin_double: f64,
    pub cos_double: f64,
    rotations: u32,
}

impl Angles {
    /// Fresh from libm.
    pub fn exact(onion: f64, bar: f64, strain: f64) -> Self {
        let offset = turned_back(onion - bar).sin_cos();
        let double = turned_back(2.0 * (onion - strain)).sin_cos();
        Self::fresh(onion, bar, strain, offset, double)
    }

    /// [`Self::exact`] with `turned_back(2 (onion - strain)).sin_cos()` computed already.
    pub fn exact_with_double(onion: f64, bar: f64, strain: f64, double: (f64, f64)) -> Self {
        let offset = turned_back(onion - bar).sin_cos();
        Self::fresh(onion, bar, strain, offset, double)
    }

    fn fresh(
        onion: f64,
        bar: f64,
        strain: f64,
        (sin_offset, cos_offset): (f64, f64),
        (sin_double, cos_double): (f64, f64),
    ) -> Self {
        Self {
            onion,
            bar,
            strain,
            sin_offset,
            cos_offset,
            sin_double,
            cos_double,
            rotations: 0,
        }
    }

    /// At another point: turned from this one when both angles moved by at most [`MAX_TURN`],
    /// else fresh.
    #[inline]
    pub fn moved(&self, onion: f64, bar: f64, strain: f64) -> Self {
        let d_offset = (onion - bar) - (self.onion - self.bar);
        let d_double = 2.0 * ((onion - strain) - (self.onion - self.strain));
        if d_offset == 0.0 && d_double == 0.0 {
            return Self {
                onion,
                bar,
                strain,
                ..*self
            };
        }
        if !(d_offset.abs() <= MAX_TURN
            && d_double.abs() <= MAX_TURN
            && self.rotations < MAX_ROTATIONS)
        {
            return Self::exact(onion, bar, strain);
        }
        let (s1, c1) = small_sin_cos(d_offset);
        let (s2, c2) = small_sin_cos(d_double);
        Self {
            onion,
            bar,
            strain,
            sin_offset: self.sin_offset * c1 + self.cos_offset * s1,
            cos_offset: self.cos_offset * c1 - self.sin_offset * s1,
            sin_double: self.sin_double * c2 + self.cos_double * s2,
            cos_double: self.cos_double * c2 - self.sin_double * s2,
            rotations: self.rotations + 1,
        }
    }

    /// Whether [`Self::moved`] to this point computes the angles afresh (as [`Self::exact`]):
    /// its own tests, apart so that `moved` itself stays as the hot substeps inline it.
    pub fn moves_afresh(&self, onion: f64, bar: f64, strain: f64) -> bool {
        let d_offset = (onion - bar) - (self.onion - self.bar);
        let d_double = 2.0 * ((onion - strain) - (self.onion - self.strain));
        let still = d_offset == 0.0 && d_double == 0.0;
        let turned = d_offset.abs() <= MAX_TURN
            && d_double.abs() <= MAX_TURN
            && self.rotations < MAX_ROTATIONS;
        !(still || turned)
    }

    /// The same angles at another onion angle (rotor and strain held).
    #[inline]
    pub fn at_onion(&self, onion: f64) -> Self {
        self.moved(onion, self.bar, self.strain)
    }
}

/// `sin d`, `cos d` for `|d| <= MAX_TURN` by their Taylor series (Horner in `d^2` on constant
/// coefficients). Below [`SHORT_TURN`] two terms fewer suffice: the first omitted ones are
/// `d^7/7!` ~ 2e-25 d and `d^6/6!` ~ 1.4e-21; most turns along a substep are that small. Up to
/// [`MEDIUM_TURN`] the next two (`d^9/9!` ~ 5e-18 d and `d^10/10!` ~ 3e-20 at 0.05 rad).
#[inline]
fn small_sin_cos(d: f64) -> (f64, f64) {
    const S3: f64 = -1.0 / 6.0;
    const S5: f64 = 1.0 / 120.0;
    const S7: f64 = -1.0 / 5040.0;
    const S9: f64 = 1.0 / 362_880.0;
    const S11: f64 = -1.0 / 39_916_800.0;
    const S13: f64 = 1.0 / 6_227_020_800.0;
    const C2: f64 = -0.5;
    const C4: f64 = 1.0 / 24.0;
    const C6: f64 = -1.0 / 720.0;
    const C8: f64 = 1.0 / 40320.0;
    const C10: f64 = -1.0 / 3_628_800.0;
    const C12: f64 = 1.0 / 479_001_600.0;
    const C14: f64 = -1.0 / 87_178_291_200.0;
    let d2 = d * d;
    if d.abs() <= SHORT_TURN {
        return (d + d * d2 * (S3 + d2 * S5), 1.0 + d2 * (C2 + d2 * C4));
    }
    if d.abs() <= MEDIUM_TURN {
        let sin = d + d * d2 * (S3 + d2 * (S5 + d2 * S7));
        let cos = 1.0 + d2 * (C2 + d2 * (C4 + d2 * (C6 + d2 * C8)));
        return (sin, cos);
    }
    let sin = d + d * d2 * (S3 + d2 * (S5 + d2 * (S7 + d2 * (S9 + d2 * (S11 + d2 * S13)))));
    let cos =
        1.0 + d2 * (C2 + d2 * (C4 + d2 * (C6 + d2 * (C8 + d2 * (C10 + d2 * (C12 + d2 * C14))))));
    (sin, cos)
}

/// Turns (rad) up to which [`small_sin_cos`] takes its middle series.
const MEDIUM_TURN: f64 = 0.05;

/// Turns (rad) up to which [`small_sin_cos`] takes its short series.
const SHORT_TURN: f64 = 1e-3;

#[cfg(test)]
mod tests {
    use super::*;

    /// Chains of small moves agree with libm to a few ulp, and far moves are computed afresh.
    #[test]
    fn moves_agree_with_libm() {
        let mut a = Angles::exact(0.3, -0.1, 1.2);
        let (mut psi, mut phi) = (0.3, -0.1);
        let mut worst = 0.0f64;
        for k in 0..1000 {
            psi += 1e-3 * (k as f64 * 0.37).sin();
            phi += 7e-4 * (k as f64 * 0.11).cos();
            a = a.moved(psi, phi, 1.2);
            let e = Angles::exact(psi, phi, 1.2);
            for (x, y) in [
                (a.sin_offset, e.sin_offset),
                (a.cos_offset, e.cos_offset),
                (a.sin_double, e.sin_double),
                (a.cos_double, e.cos_double),
            ] {
                worst = worst.max((x - y).abs());
            }
        }
        assert!(worst < 2e-15, "{worst:e}");
        // Moves of tenths of a radian, as a ringing Gilbert onion's along a substep.
        let mut b = Angles::exact(0.3, -0.1, 1.2);
        let (mut psi, mut phi) = (0.3, -0.1);
        let mut worst = 0.0f64;
        for k in 0..1000 {
            psi += 0.14 * (k as f64 * 0.37).sin();
            phi += 0.01 * (k as f64 * 0.11).cos();
            b = b.moved(psi, phi, 1.2);
            // Turned, not fresh, but for the fresh start every MAX_ROTATIONS + 1 moves.
            assert_eq!(b.rotations == 0, k % 33 == 32, "{k}");
            let e = Angles::exact(psi, phi, 1.2);
            for (x, y) in [
                (b.sin_offset, e.sin_offset),
                (b.cos_offset, e.cos_offset),
                (b.sin_double, e.sin_double),
                (b.cos_double, e.cos_double),
            ] {
                worst = worst.max((x - y).abs());
            }
        }
        assert!(worst < 2e-15, "{worst:e}");
        // A far move, and the series at its limit against libm (within an ulp of the result).
        assert_eq!(a.moved(3.0, 0.0, 1.2), Angles::exact(3.0, 0.0, 1.2));
        for d in [
            MAX_TURN,
            -MAX_TURN,
            0.2,
            MEDIUM_TURN,
            -MEDIUM_TURN,
            1.01 * MEDIUM_TURN,
            SHORT_TURN,
            0.99 * SHORT_TURN,
            -3e-4,
            1e-9,
        ] {
            let (s, c) = small_sin_cos(d);
            assert!(
                (s - d.sin()).abs() < 1e-17f64.max(1.2e-16 * d.abs())
                    && (c - d.cos()).abs() < 1.2e-16,
                "{d}"
            );
        }
    }

    #[test]
    fn huge_arguments_are_turned_back_without_losing_what_they_had() {
        for x in [0.0, -3.0, 1e3, 4.9e7, -4.9e7] {
            assert_eq!(turned_back(x).to_bits(), x.to_bits());
        }
        // libm's exact reduction against ours: within the argument's own spacing (|x| 2.2e-16).
        for x in [5e7, -5e7, 1.234e9, 1e12, -7.7e11] {
            let t = turned_back(x);
            assert!((0.0..std::f64::consts::TAU).contains(&t), "{x}: {t}");
            let (s, c) = x.sin_cos();
            let (st, ct) = t.sin_cos();
            assert!(
                (s - st).abs() < x.abs() * 2.2e-16 && (c - ct).abs() < x.abs() * 2.2e-16,
                "{x}"
            );
        }
        assert!(turned_back(f64::NAN).is_nan());
    }
}
