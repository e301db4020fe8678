//! A locked rotor's averaged advance back to its last lower turning point
//! ([`Motor::advance_orbits`]): the secant stops once the phase misses that point by less than
//! the averaged steps' own errors allow, and the step still ends within the tolerance of a
//! converged RK4; where the quadratures' noise keeps the miss beyond that slack, by enough to
//! misplace the onion along its orbit by half the tolerance, the step is flagged.

use super::locked_accuracy_tests::{onion_errors, step_against_rk4};
use super::onion_periods_tests::{case, values};
use super::orbit_advance::RETURN_STEPS;

/// A locked onion whose ringing the averaged advance carries over most of the step (the
/// benchmark's draws 866182 and 131924, printed to four digits).
const LOCKED_RINGING: [&str; 2] = [
    "strain_direction=8.281e7 stress=-6.490e4 load_torque=4.511e-7 ring_outer_diameter=1.024e-1 \
     ring_inner_diameter=2.725e-2 bar_length=1.427e-2 bar_width=2.111e-3 thickness=1.398e-9 \
     saturation_magnetization=2.529e4 magnetostriction=-6.242e-3 wall_volume=6.580e-11 \
     density=7.775e4 fluid_viscosity=1.654e7 gilbert_damping=6.594e-4 tolerance=1.227e-4 \
     step_angle=8.332e-2 step_period=1.622e4 stress_amplitude=1.114e-2 \
     schedule_initial_direction=1.767e-5 onion_model=1.000e0 max_substeps=1.046e4 \
     rotor_locked=1.000e0 initial_onion_offset=-1.425e-5 strain=3.513e-2 youngs_modulus=3.366e12",
    "strain_direction=-1.096e-3 stress=-7.985e9 load_torque=-6.730e-7 ring_outer_diameter=1.445e-3 \
     ring_inner_diameter=1.279e-4 bar_length=8.677e-5 bar_width=9.107e-6 thickness=4.538e-6 \
     saturation_magnetization=3.986e4 magnetostriction=-5.935e-3 wall_volume=7.462e-11 \
     density=8.420e4 fluid_viscosity=3.655e7 gilbert_damping=1.054e-3 tolerance=1.033e-5 \
     step_angle=-9.058e0 step_period=5.628e1 stress_amplitude=1.157e9 \
     schedule_initial_direction=-1.839e1 onion_model=1.000e0 max_substeps=3.444e3 \
     rotor_locked=1.000e0 initial_onion_offset=-8.616e-7 strain=3.780e-2 youngs_modulus=4.352e6 \
     strain_drive=1.000e0",
];

#[test]
fn locked_return_to_the_turning_point_stops_within_the_slack() {
    for (text, most) in LOCKED_RINGING.iter().zip([2, 1]) {
        RETURN_STEPS.with(|c| c.set(0));
        // Within a fifth of the tolerance of an RK4 at 200 and 400 substeps per nanosecond.
        let (errors, _) = step_against_rk4(text, 0, 200.0, 0.2);
        let steps = RETURN_STEPS.with(|c| c.get());
        println!("return steps {steps}, errors {errors:?}");
        // A secant run on to a miss of 1e-12 cycles takes all four (the quadratures' noise, 4e-4
        // cycles on 131924, never lets it reach that).
        assert!(
            steps >= 1 && steps <= most,
            "{steps} steps back to the turning point"
        );
    }
}

/// A locked onion whose return to its last turning point, one averaged step over 1,022 orbits,
/// the quadratures' noise leaves 6.3e-3 cycles off after four tries, against a slack of 1.9e-5
/// (the benchmark's draw 395829, printed to four digits, its second 1 us step).
const NOISY_RETURN: &str = "strain_direction=-2.996e2 stress=-1.780e3 load_torque=-5.691e-7 \
     ring_outer_diameter=1.021e-1 ring_inner_diameter=1.773e-3 bar_length=1.390e-3 \
     bar_width=2.839e-8 thickness=1.721e-9 saturation_magnetization=5.120e3 \
     magnetostriction=7.674e-3 wall_volume=3.221e-11 density=3.256e3 fluid_viscosity=2.185e-5 \
     gilbert_damping=1.408e-4 tolerance=1.168e-6 step_angle=2.813e0 step_period=2.259e-4 \
     stress_amplitude=4.011e7 schedule_initial_direction=8.974e-5 onion_model=1.000e0 \
     max_substeps=4.614e3 rotor_locked=1.000e0 initial_onion_offset=-2.504e-8 strain=-7.700e-2 \
     youngs_modulus=1.205e6 strain_drive=1.000e0";

#[test]
fn locked_return_beyond_its_slack_is_flagged_or_within_the_tolerance() {
    let (m, mut st, inputs) = case(&values(NOISY_RETURN)).unwrap();
    m.step(&mut st, &inputs, 1e-6).unwrap();
    let start = st;
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    // Against an RK4 at 400 and 800 substeps per nanosecond.
    let errors = onion_errors(&m, &start, &st, &inputs, 400.0);
    println!("{report:?}, errors / tolerance {errors:?}");
    // Unflagged, the onion's tilt ended 1.16 tolerances off.
    assert!(
        report.accuracy_limited || errors.iter().all(|e| *e <= 1.0),
        "{errors:?} tolerances off, unflagged"
    );
}
