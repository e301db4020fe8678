//! The locked onion's closed-form exponential increments ([`locked_onion_increments`]) against
//! the general scaling-and-squaring exponential where that is accurate, and against the exact
//! decay of a diagonal block's modes where it is not.

use super::block_phi::locked_onion_increments;
use crate::physics::numerics::expm::expm_affine;

/// A locked Jacobian with the onion block `g [[-a k, -T], [k, -a T]]` (its linearization at a
/// minimum, eq. 3.4's landscape of curvature `k`, tilt stiffness `T`).
fn locked_jacobian(g: f64, a: f64, k: f64, t: f64) -> [[f64; 4]; 4] {
    let mut j = [[0.0; 4]; 4];
    j[2][2] = -g * a * k;
    j[2][3] = -g * t;
    j[3][2] = g * k;
    j[3][3] = -g * a * t;
    j
}

/// Blocks of norm 1e3 to 1e5 (both real eigenvalues and complex pairs), where the general
/// exponential's rounding is below 1e-11: the closed form agrees with it, over `dt` and `dt / 2`.
#[test]
fn matches_the_general_exponential_on_moderate_blocks() {
    let f = [0.0, 0.0, 0.37, -1.3];
    let mut checked = 0;
    for (a, k, t) in [
        (0.12, 5.0e3, 1.0),
        (0.5, 1.0e3, 3.0e2),
        (0.01, 2.0e4, 2.0e4),
        (1.3, 7.0e4, 1.0e2),
        (0.05, 3.0e3, 9.0e2),
    ] {
        let j = locked_jacobian(1.0, a, k, t);
        for dt in [0.7, 1.0, 1.9] {
            let (Some((Some(half), full)), rounding) = locked_onion_increments(&f, &j, dt) else {
                continue;
            };
            assert_eq!(rounding, 0.0);
            for (h, ours) in [(0.5 * dt, half), (dt, full)] {
                let block = [[h * j[2][2], h * j[2][3]], [h * j[3][2], h * j[3][3]]];
                let (_, x) = expm_affine(&block, &[h * f[2], h * f[3]]).unwrap();
                let scale = x[0].abs().max(x[1].abs());
                for i in 0..2 {
                    assert!(
                        (ours[2 + i] - x[i]).abs() <= 1e-11 * scale,
                        "{a} {k} {t} {h}: {ours:?} {x:?}"
                    );
                }
                assert_eq!((ours[0], ours[1]), (0.0, 0.0));
            }
            checked += 1;
        }
    }
    assert!(checked >= 12, "{checked}");
}

/// A non-normal block with eigenvalues -1e10 and -1, exact in binary (`[[-1e10, 1e10 - 1], [0,
/// -1]]`, its slow mode `[1, 1]`): the slow mode's increment is `(e^-h - 1) [1, 1]` to rounding,
/// where the general exponential of the same block, of norm 2e10, loses digits.
#[test]
fn keeps_the_slow_mode_of_a_stiff_block() {
    let mut j = [[0.0; 4]; 4];
    j[2][2] = -1e10;
    j[2][3] = 1e10 - 1.0;
    j[3][3] = -1.0;
    // `f = J [1, 1]` exactly.
    let f = [0.0, 0.0, -1.0, -1.0];
    for h in [0.5, 2.0, 4.4] {
        let (Some((Some(half), full)), rounding) = locked_onion_increments(&f, &j, h) else {
            panic!("no closed form");
        };
        assert_eq!(rounding, 0.0);
        for (length, ours) in [(0.5 * h, half), (h, full)] {
            let block = [
                [length * j[2][2], length * j[2][3]],
                [length * j[3][2], length * j[3][3]],
            ];
            let (_, general) = expm_affine(&block, &[length * f[2], length * f[3]]).unwrap();
            let exact = (-length).exp_m1();
            let err = (2..4)
                .map(|i| (ours[i] - exact).abs() / exact.abs())
                .fold(0.0, f64::max);
            println!(
                "h {length}: closed form {err:.1e}, general {:.1e} relative",
                (general[1] - exact).abs() / exact.abs()
            );
            assert!(err <= 1e-13, "{length}: {ours:?} {exact:e}");
        }
    }
}

/// A stiff block with repeated eigenvalues has no closed form: the general exponential takes it
/// and its rounding is returned for the pair's estimate; a block of norm within the general
/// exponential's accuracy takes it with none.
#[test]
fn a_repeated_stiff_block_returns_its_rounding() {
    let f = [0.0, 0.0, 1.0, -2.0];
    let mut j = [[0.0; 4]; 4];
    j[2][2] = -1e8;
    j[3][3] = -1e8;
    let (increments, rounding) = locked_onion_increments(&f, &j, 1e-2);
    assert!(increments.is_none());
    assert!(rounding > 1e-10 && rounding < 1e-8, "{rounding:e}");
    let (increments, rounding) = locked_onion_increments(&f, &j, 1e-6);
    assert!(increments.is_none());
    assert_eq!(rounding, 0.0);
}
