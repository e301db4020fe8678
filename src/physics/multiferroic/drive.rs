//! The motor's drive: strain, and what a substep holds ([`Drive`]). Eq. 3.1 is written in
//! stress, `sigma11 - sigma22`; a piezoelectric substrate imposes strain. For uniaxial stress in
//! the ring's plane (`sigma22 = 0`) Hooke's law gives `sigma11 - sigma22 = E epsilon`.
//!
//! Two readings of section 3.3: its LLG simulation applies "a tensile strain of 200 micro-strain",
//! which in nickel is `200e-6 * 200 GPa = 40 MPa`, while Fig. 3.3b's 23 degree offset (to which
//! the wall volume is calibrated) is at 200 MPa. With the calibrated model, tension at -45 degrees
//! on a locked rotor gives (measured by `tests/fmpy/test_motor_drive.py` and `make motor-docs`):
//! - 200 micro-strain (40 MPa): an offset of 3.49 degrees and 6.2e-19 N m;
//! - 200 MPa (1000 micro-strain): 23.0 degrees and 2.16e-18 N m, the torque section 3.3 reports (2e-18 N m).
//!
//! So the section's torque matches the stress reading; its "200 micro-strain" would give a quarter
//! of it (a third) unless the domain walls are larger than the calibration makes them.

use std::f64::consts::PI;

/// Young's modulus of polycrystalline nickel, 200 GPa (CRC Handbook of Chemistry and Physics,
/// "Elastic constants of polycrystalline metals"; Cullity and Graham list the same).
pub const NICKEL_YOUNGS_MODULUS: f64 = 200e9;

/// `sigma11 - sigma22` (Pa) of a uniaxial `strain` in a material of Young's modulus
/// `youngs_modulus` (Pa).
pub fn uniaxial_stress(strain: f64, youngs_modulus: f64) -> Result<f64, String> {
    if !(youngs_modulus.is_finite() && youngs_modulus > 0.0 && youngs_modulus <= 1e13) {
        return Err(format!(
            "youngs_modulus must be positive and at most 1e13 Pa, got {youngs_modulus}"
        ));
    }
    let stress = strain * youngs_modulus;
    if stress.is_finite() && stress.abs() <= super::MAX_STRESS {
        Ok(stress)
    } else {
        Err(format!(
            "strain {strain} times youngs_modulus {youngs_modulus} Pa must be a finite stress \
             within {} Pa",
            super::MAX_STRESS
        ))
    }
}

/// Eq. 3.4 depends on the strain direction only modulo pi (through `2 (psi - gamma)`). A direction
/// of many turns is reduced modulo pi above this size: the onion's angle, which follows the rotor,
/// then meets a direction of its own size, so `psi - gamma` keeps the onion's precision instead of
/// the direction's (beside 1e12 rad it is 1e-4 rad), and the long-step paths, which turn the
/// rotor back near zero, hand libm small arguments ([`super::angles::turned_back`] guards the
/// rest). The rounding of pi times the turns stays below the direction's own spacing.
pub(super) const REDUCED_DIRECTION_ABOVE: f64 = 1e3;

/// The strain direction the physics uses for an applied one (see [`REDUCED_DIRECTION_ABOVE`]).
pub(super) fn reduced_direction(applied: f64) -> f64 {
    if applied.abs() > REDUCED_DIRECTION_ABOVE {
        // `applied.rem_euclid(PI)`, with its `%` by `rem_pi`.
        let r = rem_pi(applied);
        if r < 0.0 {
            r + PI
        } else {
            r
        }
    } else {
        applied
    }
}

/// `PI` with its low 27 significand bits cleared, and the rest: `q PI_HIGH` and `q PI_LOW` are
/// exact for an integer `q < 2^26`.
const PI_HIGH: f64 = f64::from_bits(PI.to_bits() & !((1 << 27) - 1));
const PI_LOW: f64 = PI - PI_HIGH;
/// Below this `|x|` the quotient `x / PI` is below 2^26 (and `x` below 2^28).
const REM_PI_FAST_BELOW: f64 = 2e8;

/// `x % PI`, bit for bit (the remainder is exact, so there is one right answer), without the
/// software `fmod`'s bit-by-bit loop, a schedule's switch's largest single cost: with `q` the
/// truncated quotient, `|x| - q PI_HIGH` is exact (both are multiples of `ulp(x)` below 2^28, with
/// the difference no larger), and subtracting `q PI_LOW` rounds the exact remainder, which is
/// representable, to itself. A quotient rounded up by one gives a negative difference, detected,
/// and then (as beyond 2^28, or for NaN) `%` itself is taken.
fn rem_pi(x: f64) -> f64 {
    let ax = x.abs();
    if ax < REM_PI_FAST_BELOW {
        let q = (ax / PI) as i64 as f64;
        let r = (ax - q * PI_HIGH) - q * PI_LOW;
        if (0.0..PI).contains(&r) {
            // `%` takes the sign of `x`, zero included.
            return r.copysign(x);
        }
    }
    x % PI
}

/// Strain, stress and load held over one substep.
#[derive(Clone, Copy, Debug)]
pub(super) struct Drive {
    /// The strain direction the physics uses: the applied one, brought into `[0, pi)` when far
    /// beyond a few turns (see [`REDUCED_DIRECTION_ABOVE`]).
    pub(super) direction: f64,
    /// The strain direction as applied, for the `applied_strain_direction` output.
    pub(super) applied_direction: f64,
    pub(super) stress: f64,
    pub(super) load: f64,
    pub(super) locked: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `rem_pi` against libm's `fmod` (Rust's `%`), bit for bit: random magnitudes across the
    /// fast range and beyond, both signs, and the arguments next to multiples of pi (where the
    /// rounded quotient is one too large), including the schedules' `initial + k step_angle`.
    #[test]
    fn rem_pi_is_fmod_bit_for_bit() {
        let mut checked = 0u32;
        let mut check = |x: f64| {
            for x in [x, -x] {
                assert_eq!(rem_pi(x).to_bits(), (x % PI).to_bits(), "{x:e}");
                checked += 1;
            }
        };
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200_000 {
            check(10f64.powf(-3.0 + 13.0 * next()));
        }
        for k in 0..=1_000_000u32 {
            let m = f64::from(k) * PI;
            let k2 = 10f64.powf(8.4 * next());
            for x in [
                m,
                k2.round() * PI,
                -717.9 + f64::from(k) * 4.598_700_042_196_322,
            ] {
                let mut y = x;
                for _ in 0..3 {
                    check(y);
                    y = y.next_up();
                }
                y = x;
                for _ in 0..3 {
                    y = y.next_down();
                    check(y);
                }
            }
        }
        check(0.0);
        check(REM_PI_FAST_BELOW);
        assert!(rem_pi(f64::NAN).is_nan() && rem_pi(f64::INFINITY).is_nan());
        assert!(checked > 10_000_000);
    }

    #[test]
    fn two_hundred_micro_strain_in_nickel_is_forty_megapascal() {
        let s = uniaxial_stress(200e-6, NICKEL_YOUNGS_MODULUS).unwrap();
        assert!((s - 40e6).abs() < 1e-6, "{s}");
        assert!(uniaxial_stress(1e-3, 0.0).is_err());
        assert!(uniaxial_stress(f64::NAN, 200e9).is_err());
        assert!(uniaxial_stress(1e3, 1e13).is_err());
    }
}
