//! A locked rotor's heavily damped onion whose tilt is far softer than its curvature: after each
//! switch it falls into its minimum within picoseconds and its tilt then creeps back over tens of
//! nanoseconds. The tilt is an output: the averaged ringing may not drop it while it lasts.

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4_span;
use super::ringing::Rims;

/// Damping 0.78, tolerance 0.011 rad, a 40 ns schedule: the tilt stiffness `T` is 1e-6 of the
/// curvature at the minimum, the tilt's creep ~33 ns (`alpha / (g (1 + alpha^2) T)`).
const SOFT_TILT: &str = "strain_direction=-3.142e9 stress=-6.400e5 load_torque=5.102e-7 \
    ring_outer_diameter=1.419e-2 ring_inner_diameter=2.763e-5 bar_length=4.019e-6 \
    bar_width=6.348e-8 thickness=3.830e-9 saturation_magnetization=1.057e2 \
    magnetostriction=-2.932e-3 wall_volume=4.355e-11 density=1.345e3 fluid_viscosity=4.141e6 \
    gilbert_damping=7.835e-1 tolerance=1.107e-2 step_angle=-8.531e0 step_period=3.995e-8 \
    stress_amplitude=1.287e6 schedule_initial_direction=-3.720e-1 onion_model=1.000e0 \
    max_substeps=4.891e3 schedule=1.000e0 rotor_locked=1.000e0 initial_onion_offset=2.084e1 \
    strain=6.591e-2 youngs_modulus=4.681e10";

/// The onion in its minimum with the tilt of 1.14 rad it has there after a switch: over the
/// 40 ns left of its segment an RK4 of the macrospin (0.1 ps steps, checked against 0.05 ps)
/// keeps the tilt beyond 20 tolerances, so the averaged ringing must not drop it (it did: its
/// locked bound held only the angle's reach, which the soft tilt barely moves).
#[test]
fn soft_tilt_is_not_dropped_while_it_lasts() {
    let (m, _, inputs) = case(&values(SOFT_TILT)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(0.0, d.direction, d.stress);
    let minimum = land.settle(20.9);
    let y = [0.0, 0.0, minimum, -1.14];
    let remaining = 3.99e-8;
    let end = rk4_span(&m, &d, y, remaining, 400_000);
    let finer = rk4_span(&m, &d, y, remaining, 800_000);
    let tol = m.params.tolerance;
    assert!((end[3] - finer[3]).abs() <= 1e-3 * tol, "{end:?} {finer:?}");
    println!(
        "tilt after {remaining} s: {} ({} tolerances)",
        finer[3],
        finer[3].abs() / tol
    );
    assert!(finer[3].abs() >= 20.0 * tol);
    let mut rims = Rims::NONE;
    let kept = m.averaged_ringing(&y, &d, minimum, &mut rims, remaining);
    assert!(kept.is_none(), "dropped: {kept:?}");
}

/// The same onion, in its minimum with that tilt, over a 20 ns step inside one segment of the
/// schedule: the step's tilt is the RK4's (0.1 ps steps, checked against 0.05 ps) within the
/// tolerance, unflagged, where dropping the ringing would report no tilt at all, over 20
/// tolerances off.
#[test]
fn soft_tilt_step_ends_at_the_rk4_tilt() {
    let (m, mut st, inputs) = case(&values(SOFT_TILT)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let minimum = m.landscape(0.0, d.direction, d.stress).settle(20.9);
    let y = [0.0, 0.0, minimum, -1.14];
    let h = 2e-8;
    let end = rk4_span(&m, &d, y, h, 200_000);
    let finer = rk4_span(&m, &d, y, h, 400_000);
    let tol = m.params.tolerance;
    assert!((end[3] - finer[3]).abs() <= 1e-2 * tol, "{end:?} {finer:?}");
    assert!(finer[3].abs() >= 20.0 * tol, "{finer:?}");
    (st.onion_angle, st.onion_tilt) = (minimum, -1.14);
    let report = m.step(&mut st, &inputs, h).unwrap();
    let off = [st.onion_angle - finer[2], st.onion_tilt - finer[3]].map(|e| e.abs() / tol);
    println!(
        "{report:?}: off the RK4 by {off:?} tolerances (tilt {})",
        finer[3]
    );
    assert!(
        !report.accuracy_limited && off[0] <= 1.0 && off[1] <= 1.0,
        "{off:?}"
    );
}
