//! A Gilbert onion too slow to follow a fast schedule, on a step whose budget runs out: it keeps
//! its ringing instead of being put on the quasi-static branch ([`Motor::heads_for_minimum`]).

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4;
use super::*;

/// A benchmark case: a free rotor on a 1.26 ns schedule turning the strain by 0.199 rad (mod pi)
/// a switch, under a weak stress (0.04 Pa): the onion's in-plane decay takes 2.5e5 periods
/// (`lambda T` 4e-6), so it barely moves (1e-5 rad over a step) while the strain turns past it.
/// Resolving each switch takes about 4.5 Gilbert substeps; the 794 switches of a 1 us step
/// outrun the budget of 12,920 (a Gilbert substep counting 4).
const SLOW_ONION: &str = "load_torque=-4.507e-7 ring_outer_diameter=9.277e-1 \
    ring_inner_diameter=8.434e-1 bar_length=2.843e-1 bar_width=8.968e-8 thickness=4.304e-8 \
    saturation_magnetization=3.706e4 magnetostriction=1.731e-3 wall_volume=9.034e-12 \
    density=8.755e4 fluid_viscosity=4.943e-3 gilbert_damping=3.156e-1 tolerance=2.624e-10 \
    step_angle=6.482e0 step_period=1.259e-9 stress_amplitude=4.043e-2 \
    schedule_initial_direction=-1.994e1 onion_model=1 max_substeps=1.292e4 schedule=1 \
    initial_onion_offset=-2.046e-8";

/// The decay rate against the eigenvalues of the onion block of the motor's own Jacobian at a
/// minimum (a locked rotor's landscape under the schedule's stress): the slower real part.
#[test]
fn slowest_decay_is_the_onion_blocks_slower_eigenvalue() {
    let (m, _, inputs) = case(&values(SLOW_ONION)).unwrap();
    for stress in [4.043e-2, 1e2, 1e6, 1e9] {
        let d = Drive {
            locked: true,
            stress,
            ..m.drive_at(&inputs, 0.0)
        };
        let land = m.landscape(0.0, d.direction, d.stress);
        let minimum = land.settle(d.direction + 0.1);
        let k = land.curvature(minimum);
        let (_, j) = m.rhs_jacobian(&[0.0, 0.0, minimum, 0.0], &d, 1e-300);
        // Eigenvalues of [[j22, j23], [j32, j33]].
        let (a, b, c, e) = (j[2][2], j[2][3], j[3][2], j[3][3]);
        let (half_trace, det) = (0.5 * (a + e), a * e - b * c);
        let disc = half_trace * half_trace - det;
        let slower = if disc > 0.0 {
            -(half_trace + disc.sqrt())
        } else {
            -half_trace
        };
        let rate = m.onion_decay_rate(k);
        println!("stress {stress}: curvature {k:e}, rate {rate:e} against {slower:e}");
        assert!(k > 0.0);
        assert!(
            (rate - slower).abs() <= 1e-6 * slower.abs(),
            "{rate} {slower}"
        );
    }
}

/// A 1 us step of [`SLOW_ONION`] against an RK4 of the motor's equations (0.5 ps and 0.25 ps
/// steps, agreeing within a thousandth of the tolerance): the rotor and the onion within the
/// tolerance, in at most one substep a switch (2,785 when only the explicit pair was tried
/// within its reach, whose rejections each switch's tilt transient drew), and, with a budget
/// too small for that (3,000: 600 Gilbert substeps), once the budget runs out. Putting the
/// onion on its quasi-static branch then turned it with the strain at each of the last ~200
/// switches: 38.5 rad off, 1.5e11 tolerances.
#[test]
fn a_slow_onion_keeps_its_place_when_the_budget_runs_out() {
    keeps_its_place(None);
    keeps_its_place(Some(3e3));
}

fn keeps_its_place(budget: Option<f64>) {
    let mut kv = values(SLOW_ONION);
    if let Some(b) = budget {
        kv.insert("max_substeps".into(), b);
    }
    let (m, start, inputs) = case(&kv).unwrap();
    let tol = m.params.tolerance;
    // The first period resolved alone (the step under test then spans whole periods only).
    let s = *inputs.schedule.get().unwrap();
    let mut st = start;
    m.step(&mut st, &inputs, s.next_switch_after(0.0)).unwrap();
    let t_end = st.time + 1e-6;
    let reference = rk4(&m, &st, &inputs, t_end, 2e3);
    let finer = rk4(&m, &st, &inputs, t_end, 4e3);
    assert!(
        (reference[2] - finer[2]).abs() <= 1e-3 * tol
            && (reference[0] - finer[0]).abs() <= 1e-3 * tol,
        "{reference:?} {finer:?}"
    );
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    println!("{st:?} against {reference:?}: {} substeps", report.substeps);
    assert!(!report.accuracy_limited);
    assert!(
        (st.onion_angle - reference[2]).abs() <= tol
            && (st.rotor_angle - reference[0]).abs() <= tol,
        "{st:?} against {reference:?}"
    );
    assert!((st.onion_tilt - reference[3]).abs() <= tol);
    // The step's 794 switches.
    assert!(report.substeps <= 800, "{} substeps", report.substeps);
}

/// A benchmark case: a free rotor on a 1.03 ns schedule at damping 1.2e-4 whose onion decays by
/// `lambda T = 0.04` a period (it remembers 25 switches) under a ring that barely holds its bar:
/// dropping ringing that the rotor cannot feel may not move the onion beyond the tolerance.
const RINGING_ONION: &str = "load_torque=-5.019e-7 ring_outer_diameter=7.356e-2 \
    ring_inner_diameter=1.665e-3 bar_length=4.017e-5 bar_width=6.878e-7 thickness=1.757e-7 \
    saturation_magnetization=5.244e6 magnetostriction=-7.977e-3 wall_volume=6.021e-11 \
    density=8.954e4 fluid_viscosity=8.305e3 gilbert_damping=1.158e-4 tolerance=2.793e-8 \
    step_angle=4.599e0 step_period=1.031e-9 stress_amplitude=-3.935e0 \
    schedule_initial_direction=-7.179e2 onion_model=1 max_substeps=9.249e3 schedule=1 \
    initial_onion_offset=2.536e-5";

/// A 1 us step of [`RINGING_ONION`] against an RK4 of the motor's equations (0.2 ps and 0.1 ps
/// steps, within a hundredth of the tolerance of each other; the rotor's drag rate is 2.4e12/s):
/// the onion within ten tolerances after 971 switches resolved one substep each. Snapping the
/// onion onto a minimum it would not reach before the next switch (within 1e-3 rad, where the
/// rotor could not feel the difference) ended the step 1.5e-3 rad off, 5e4 tolerances.
#[test]
fn ringing_the_rotor_cannot_feel_is_dropped_only_where_it_ends_in_its_segment() {
    let (m, start, inputs) = case(&values(RINGING_ONION)).unwrap();
    let tol = m.params.tolerance;
    let s = *inputs.schedule.get().unwrap();
    let mut st = start;
    m.step(&mut st, &inputs, s.next_switch_after(0.0)).unwrap();
    let t_end = st.time + 1e-6;
    let reference = rk4(&m, &st, &inputs, t_end, 5e3);
    let finer = rk4(&m, &st, &inputs, t_end, 1e4);
    assert!(
        (0..4).all(|i| (reference[i] - finer[i]).abs() <= 1e-2 * tol * [1.0, 1e3, 1.0, 1.0][i]),
        "{reference:?} {finer:?}"
    );
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    println!("{st:?} against {reference:?}: {} substeps", report.substeps);
    assert!(!report.accuracy_limited);
    assert!(
        (st.onion_angle - reference[2]).abs() <= 10.0 * tol
            && (st.rotor_angle - reference[0]).abs() <= 10.0 * tol
            && (st.onion_tilt - reference[3]).abs() <= 10.0 * tol,
        "{st:?} against {reference:?}"
    );
}
