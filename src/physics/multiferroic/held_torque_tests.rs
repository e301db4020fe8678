//! A free rotor on a nanosecond schedule that barely turns between switches: its segments
//! advance under the held torque ([`Motor::advance_held_torque`]) against a plain RK4 of the
//! rotor with the quasi-static onion settled at every stage.

use super::onion::{EVALUATIONS, SETTLES};
use super::onion_periods_tests::{case, values};
use super::*;
use crate::physics::numerics::rk4::rk4_step;

/// A benchmark case (full precision): a 5 mm bar in a 0.21 m ring on a 1.23 ns schedule under a
/// 7.3e-7 N m load, inertial time `I/c` 4.6 ms and relaxation time `c/k` 14 ms: the rotor turns
/// by about 3e-8 rad a period while the strain turns by 1.12 rad at every switch (811 a step).
pub(super) const C650914: &str = "\
    strain_direction=-4.230779005351924e10 stress=-2.0768930094875782e6 \
    load_torque=7.255841324728959e-7 ring_outer_diameter=2.1102862386012033e-1 \
    ring_inner_diameter=2.6367808444124004e-2 bar_length=5.1290034579635334e-3 \
    bar_width=3.0337186512897994e-3 thickness=2.911104816357152e-7 \
    saturation_magnetization=8.967364458189212e6 magnetostriction=4.390094673991148e-4 \
    wall_volume=2.889808802101761e-11 density=5.340800880247694e3 \
    fluid_viscosity=4.8436691231306853e-4 gilbert_damping=2.1758810299846677e-3 \
    tolerance=9.198653401805737e-9 step_angle=-1.1186056202541863e0 \
    step_period=1.2324615718284565e-9 stress_amplitude=-6.584342865167292e3 \
    schedule_initial_direction=-8.189781281874186e0 onion_model=0e0 max_substeps=1.683e3 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=1.5788836238484117e-4 \
    strain=-2.290403937885055e-2 youngs_modulus=9.928985761745161e7 strain_drive=1e0";

/// A benchmark case (full precision): a 0.3 mm bar in a 0.6 m ring on a 42 us schedule (the
/// strain turned by 0.94 rad modulo pi at its switches, none within the first 1 us steps), under
/// a 2.5e-7 N m load, inertial time `I/c` 0.46 us, at a budget of 6 substeps.
const C834513: &str = "\
    strain_direction=-6.206678340282502e-2 stress=-3.888039664317345e10 \
    load_torque=-2.4532684174125194e-7 ring_outer_diameter=6.046618264644538e-1 \
    ring_inner_diameter=4.073336194200837e-1 bar_length=3.0830997078225937e-4 \
    bar_width=7.77248151854942e-5 thickness=7.598412350130709e-5 \
    saturation_magnetization=1.3573584666718903e5 magnetostriction=2.6133278528536596e-3 \
    wall_volume=2.823865112026106e-11 density=2.421733033660989e3 \
    fluid_viscosity=2.284706052238498e0 gilbert_damping=5.084301656594387e-3 \
    tolerance=7.73079499024008e-5 step_angle=7.2227036388977695e0 \
    step_period=4.159159653837569e-5 stress_amplitude=-1.1588684806856845e2 \
    schedule_initial_direction=-2.7226175343269727e5 onion_model=0e0 max_substeps=6e0 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=4.224350972667426e-2 \
    strain=2.9305838689763136e-2 youngs_modulus=4.821236953532696e6 strain_drive=1e0";

/// Classical RK4 of `I phi'' = tau + load - c phi'` (section 3.2.2) with the quasi-static onion
/// settled at every stage from the onion at the last step's end (the memory rule), `n` equal
/// steps per segment of constant drive, from `start` to `t_end`: rotor angle, speed and onion.
/// A locked rotor stays where it starts, its onion settled at every switch.
fn quasi_static_rk4(
    m: &Motor,
    start: &MotorState,
    inputs: &MotorInputs,
    t_end: f64,
    n: usize,
) -> [f64; 3] {
    let mut y = [start.rotor_angle, start.rotor_speed];
    let mut psi = start.onion_angle;
    let mut t = start.time;
    let settle =
        |d: &Drive, phi: f64, from: f64| m.landscape(phi, d.direction, d.stress).settle(from);
    while t < t_end {
        let next = inputs
            .schedule
            .get()
            .map_or(t_end, |s| s.next_switch_after(t).min(t_end));
        let d = m.drive_at(inputs, t);
        if d.locked {
            y[1] = 0.0;
        }
        psi = settle(&d, y[0], psi);
        let h = (next - t) / n as f64;
        for _ in 0..if d.locked { 0 } else { n } {
            let rate = |z: &[f64; 2]| {
                let onion = settle(&d, z[0], psi);
                let torque = m.ring_bar.torque(onion - z[0]);
                [z[1], (torque + d.load - m.drag * z[1]) / m.inertia]
            };
            y = rk4_step(&rate, &y, h);
            psi = settle(&d, y[0], psi);
        }
        t = next;
    }
    let d = m.drive_at(inputs, t_end);
    [y[0], y[1], settle(&d, y[0], psi)]
}

/// [`quasi_static_rk4`] with `n` doubled from 1 until two runs agree within a hundredth of the
/// tolerance in the rotor and onion angles (and a hundredth of the tolerance on the error norm's
/// speed scale): the finer run.
pub(super) fn converged_quasi_static_rk4(
    m: &Motor,
    start: &MotorState,
    inputs: &MotorInputs,
    t_end: f64,
) -> [f64; 3] {
    let tol = m.params.tolerance;
    let mut coarse = quasi_static_rk4(m, start, inputs, t_end, 1);
    for k in 1..12 {
        let fine = quasi_static_rk4(m, start, inputs, t_end, 1 << k);
        let apart = [
            (fine[0] - coarse[0]).abs() / tol,
            (fine[1] - coarse[1]).abs() / (tol * m.speed_scale),
            (fine[2] - coarse[2]).abs() / tol,
        ];
        if apart.iter().all(|a| *a <= 0.01) {
            return fine;
        }
        coarse = fine;
    }
    panic!("RK4 not converged: {coarse:?}");
}

/// The errors of `state` against `truth` in tolerances: rotor angle, speed (on the error norm's
/// scale) and onion angle.
pub(super) fn errors(m: &Motor, state: &MotorState, truth: &[f64; 3]) -> [f64; 3] {
    let tol = m.params.tolerance;
    [
        (state.rotor_angle - truth[0]).abs() / tol,
        (state.rotor_speed - truth[1]).abs() / (tol * m.speed_scale),
        (state.onion_angle - truth[2]).abs() / tol,
    ]
}

/// Settles and landscape evaluations of one call.
fn counted<T>(f: impl FnOnce() -> T) -> (T, u64, u64) {
    let (s0, e0) = (SETTLES.with(|c| c.get()), EVALUATIONS.with(|c| c.get()));
    let out = f();
    (
        out,
        SETTLES.with(|c| c.get()) - s0,
        EVALUATIONS.with(|c| c.get()) - e0,
    )
}

/// [`C650914`]'s three 1 us steps, each against the converged RK4 from its start: rotor angle,
/// speed and onion within the tolerance, at one settle a switch (an exponential substep took
/// three, 2,440 a step, and 4,500-4,630 evaluations).
#[test]
fn draw_650914_switches_under_the_held_torque_against_rk4() {
    let (m, mut st, inputs) = case(&values(C650914)).unwrap();
    for k in 0..3 {
        let start = st;
        let (report, settles, evaluations) = counted(|| m.step(&mut st, &inputs, 1e-6).unwrap());
        let truth = converged_quasi_static_rk4(&m, &start, &inputs, st.time);
        let e = errors(&m, &st, &truth);
        println!(
            "step {k}: {} substeps, {settles} settles, {evaluations} evaluations; errors {e:?}",
            report.substeps
        );
        assert!(!report.accuracy_limited);
        assert!(e.iter().all(|x| *x <= 1.0), "step {k}: {e:?}");
        assert!(
            settles <= u64::from(report.substeps) + 2,
            "step {k}: {settles} settles"
        );
        assert!(evaluations <= 3200, "step {k}: {evaluations} evaluations");
    }
}

/// [`C834513`]'s three 1 us steps, each one segment of the schedule, against the converged RK4
/// from its start: within the tolerance, in one substep each (the exponential substeps took five,
/// then one).
#[test]
fn draw_834513_segment_under_the_held_torque_against_rk4() {
    let (m, mut st, inputs) = case(&values(C834513)).unwrap();
    for k in 0..3 {
        let start = st;
        let report = m.step(&mut st, &inputs, 1e-6).unwrap();
        let truth = converged_quasi_static_rk4(&m, &start, &inputs, st.time);
        let e = errors(&m, &st, &truth);
        println!("step {k}: {} substeps; errors {e:?}", report.substeps);
        assert!(!report.accuracy_limited);
        assert!(e.iter().all(|x| *x <= 1.0), "step {k}: {e:?}");
        assert_eq!(report.substeps, 1, "step {k}");
    }
}
