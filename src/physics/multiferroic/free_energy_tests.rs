//! A free rotor's Gilbert onion held to what its energy can do ([`Motor::free_energy_checked_error`])
//! on a benchmark draw, against a plain RK4 of the motor's equations.

use super::free_energy::FreeLedger;
use super::locked_accuracy_tests::converged_rk4;
use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4_span;
use super::ringing_drop_tests::C655285;
use super::*;

/// [`C655285`]: a load-driven rotor (3,006 rad/s) whose ring's torque (below 6e-20 N m) cannot
/// move it, its onion (damping 6.1e-4, tolerance 0.36 rad) ringing at half to 0.99 of its
/// well's rims after each switch of a 148 ns schedule.
const KNIFE_EDGE: &str = C655285;

/// After its fourth orbit-averaged advance the onion of [`KNIFE_EDGE`] rings at half its rim's
/// height. The exponential pair's substep of 4.2 ns from there, 4.7 tolerances off a converged
/// plain RK4 in the angle and 8 in the tilt, its energy raised 6.8 times, far over every rim,
/// estimated its error at 0.66 tolerances from its defect at the substep's end alone; its
/// defect at the midpoint ([`Motor::pair_midpoint_error`]) rejects it. The energy check rejects
/// the exponential Euler step it falls back to, and passes the RK4's end.
#[test]
fn a_substep_that_raises_the_energy_beyond_the_tolerance_is_rejected() {
    let (m, _, inputs) = case(&values(KNIFE_EDGE)).unwrap();
    let t0 = 5.826415707885185e-7;
    let y0: Vector = [
        0.0017515829132827658,
        3006.27864728672,
        1.965609388461483,
        2.4724048070287325e-15,
    ];
    let dt = 4.219977833675628e-9;
    let d = m.drive_at(&inputs, t0);
    let angles = Motor::angles_at(&y0, &d, None);
    let (u, err, taken, _) = m
        .controlled_step(&y0, dt, &d, &angles, false, &mut 0)
        .unwrap();
    assert_eq!(taken, dt);
    let (coarse, truth) = (
        rk4_span(&m, &d, y0, dt, 4000),
        rk4_span(&m, &d, y0, dt, 8000),
    );
    let tol = m.params.tolerance;
    assert!(
        (coarse[2] - truth[2]).abs() <= 1e-6 * tol && (coarse[3] - truth[3]).abs() <= 1e-6 * tol
    );
    let off = [(u[2] - truth[2]).abs() / tol, (u[3] - truth[3]).abs() / tol];
    println!("estimate {err}, off by {off:?} tolerances");
    assert!(err > 1.0, "{err} {off:?}");
    let start = m.linearized(&y0, &d, dt, &angles);
    let (pair, pair_err) = m.gilbert_embedded_step(&y0, dt, &d, &start).unwrap();
    let pair_off = [
        (pair[2] - truth[2]).abs() / tol,
        (pair[3] - truth[3]).abs() / tol,
    ];
    println!("pair estimate {pair_err}, off by {pair_off:?} tolerances");
    assert!(
        pair_err >= 0.5 * pair_off[0].max(pair_off[1]),
        "{pair_err} {pair_off:?}"
    );
    let mut ledger = FreeLedger::NONE;
    let checked = m.free_energy_checked_error(&mut ledger, (&y0, &pair), dt, &d, 0.5);
    assert!(checked > 1.0, "{checked}");
    // The RK4's own end passes.
    let mut ledger = FreeLedger::NONE;
    let exact = m.free_energy_checked_error(&mut ledger, (&y0, &truth), dt, &d, 0.5);
    assert_eq!(exact, 0.5);
}

/// [`KNIFE_EDGE`]'s first 1 us step against a converged plain RK4 from the same start: within 10
/// tolerances in 300 substeps. Without the energy check substeps carried the onion over its rims
/// and it spun 920 rad away (2,580 tolerances) in 419 substeps. Ringing at 0.99 of its rims, the
/// onion decides between wells on energy differences that a loose tolerance does not resolve:
/// its dynamics carry the substeps' errors far beyond the tolerance
/// ([`Motor::errors_amplified`]), it ends 4 tolerances off in angle, and the step is
/// flagged.
#[test]
fn draw_ringing_near_its_rims_stays_in_its_well_against_rk4() {
    let (m, mut st, inputs) = case(&values(KNIFE_EDGE)).unwrap();
    let start = st;
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let truth = converged_rk4(&m, &start, &inputs, st.time, 1000.0);
    let tol = m.params.tolerance;
    let errors = [
        (st.rotor_angle - truth[0]).abs() / tol,
        (st.onion_angle - truth[2]).abs() / tol,
        (st.onion_tilt - truth[3]).abs() / tol,
    ];
    println!(
        "{} substeps, errors / tolerance {errors:?}",
        report.substeps
    );
    assert!(report.accuracy_limited);
    assert!(errors.iter().all(|e| *e <= 10.0), "{errors:?}");
    assert!(report.substeps <= 300, "{}", report.substeps);
}
