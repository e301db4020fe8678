//! The exponential pair's error estimate ([`Motor::gilbert_embedded_step`]) against the true
//! error of its substep: a converged classical RK4 of the motor's ODE from the substep's start.

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4_span;
use super::*;

/// Classical RK4 from `y` over `dt` under `d`, its step halved until the angles and the tilt
/// change by less than a thousandth of the tolerance.
fn converged(m: &Motor, d: &Drive, y: &Vector, dt: f64) -> Vector {
    let tol = m.params.tolerance;
    let mut n = 64;
    let mut coarse = rk4_span(m, d, *y, dt, n);
    while n < 1 << 20 {
        n *= 2;
        let fine = rk4_span(m, d, *y, dt, n);
        let change = [0, 2, 3]
            .iter()
            .map(|&i| (fine[i] - coarse[i]).abs())
            .fold(0.0, f64::max);
        if change <= 1e-3 * tol {
            return fine;
        }
        coarse = fine;
    }
    panic!("RK4 not converged at {n} steps");
}

/// The pair's substep from `y` over `dt`: its error estimate and the true error of the state it
/// returns (rotor angle, onion angle and tilt), both in tolerances.
fn estimate_and_error(m: &Motor, d: &Drive, y: &Vector, dt: f64) -> (f64, f64) {
    let angles = Motor::angles_at(y, d, None);
    let start = m.linearized(y, d, dt, &angles);
    let (u, estimate) = m.gilbert_embedded_step(y, dt, d, &start).unwrap();
    let truth = converged(m, d, y, dt);
    let error = [0, 2, 3]
        .iter()
        .map(|&i| (u[i] - truth[i]).abs() / m.params.tolerance)
        .fold(0.0, f64::max);
    (estimate, error)
}

/// The pair's substep from `y` over `dt` is off by more than the tolerance, and its estimate says
/// at least half of that.
fn assert_estimate_sees_the_error(m: &Motor, d: &Drive, y: &Vector, dt: f64) {
    let (estimate, error) = estimate_and_error(m, d, y, dt);
    println!("estimate {estimate}, true error {error} tolerances");
    assert!(
        error > 1.0,
        "the substep's result is within the tolerance: {error}"
    );
    assert!(
        estimate >= 0.5 * error,
        "estimate {estimate}, true error {error}"
    );
}

/// A free rotor at 4.5e5 rad/s under a lightly damped Gilbert onion (damping 3.6e-4) whose
/// substep of 0.21 us turns its onion by 5.6 rad, about a precession period, back near its
/// start, where the defect at the end is small. The pair's estimate was 0.30 for a true error
/// of 3.7 tolerances: the substep was accepted.
#[test]
fn pair_estimate_sees_an_onion_precessing_about_a_period() {
    let (m, _, _) = case(&values(
        "ring_outer_diameter=9.402e-2 ring_inner_diameter=1.308e-2 bar_length=1.054e-3 \
         bar_width=3.186e-6 thickness=4.532e-8 saturation_magnetization=3.972e2 \
         magnetostriction=-3.017e-4 wall_volume=9.069e-11 density=1.355e4 \
         fluid_viscosity=8.139e-3 gilbert_damping=3.569e-4 tolerance=2.788e-10 onion_model=1",
    ))
    .unwrap();
    let d = Drive {
        direction: -6.962e-4,
        applied_direction: -6.962e-4,
        stress: -20.84,
        load: -6.342e-7,
        locked: false,
    };
    let y = [
        -2.4817379269469445e-1,
        -4.510033775710594e5,
        -5.059926003919625e-5,
        -7.332586240895857e-5,
    ];
    assert_estimate_sees_the_error(&m, &d, &y, 2.0686140866954464e-7);
}

/// A rotor held at its drag speed (3.2e6 rad/s, `c/I` 7e16 1/s) under an onion whose angle's
/// rate reverses within the 7.9 ns substep under its growing tilt: the angle swings out and
/// back, and the defect at the end is near zero. The pair's estimate was 0.05 for a true error
/// of 128 tolerances in the tilt.
#[test]
fn pair_estimate_sees_an_onion_angle_that_swings_out_and_back() {
    let (m, _, _) = case(&values(
        "ring_outer_diameter=2.328019920117382e-5 ring_inner_diameter=1.3971126118686758e-5 \
         bar_length=1.2465065486519635e-6 bar_width=7.792947586471934e-8 \
         thickness=4.382655488177338e-9 saturation_magnetization=1.6168645470287504e2 \
         magnetostriction=9.668147759750336e-3 wall_volume=5.185848349922059e-11 \
         density=5.1316092076778135e4 fluid_viscosity=3.4249442004361376e5 \
         gilbert_damping=6.51136503669907e-2 tolerance=6.065398934711097e-9 onion_model=1",
    ))
    .unwrap();
    let d = Drive {
        direction: 2.685557171745465,
        applied_direction: -1637.2258080021265,
        stress: 0.8247097731619921,
        load: 6.543439832921072e-7,
        locked: false,
    };
    let y = [
        6.1730259168612545,
        3.244088962235748e6,
        -3.12791620149206,
        -6.121052072423149e-2,
    ];
    assert_estimate_sees_the_error(&m, &d, &y, 7.895657523891764e-9);
}
