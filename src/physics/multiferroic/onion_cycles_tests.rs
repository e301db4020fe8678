//! The Gilbert onion's repeated cycles of periods on a fast schedule
//! ([`Motor::skip_onion_cycles`]) against a plain RK4 of the same equations.

use super::onion_periods::SKIPS;
use super::onion_periods_tests::{case, values};
use super::*;

/// The onion's angle and tilt at `t_end` by the classical RK4 of the motor's equations
/// ([`super::resolved_tests::rk4`], a locked rotor held) from `start`, its substeps per
/// nanosecond doubled from 8 until two runs agree within a hundredth of the tolerance.
fn converged(m: &Motor, start: &MotorState, inputs: &MotorInputs, t_end: f64) -> [f64; 2] {
    let tol = m.params.tolerance;
    let mut per_ns = 8.0;
    let mut last = super::resolved_tests::rk4(m, start, inputs, t_end, per_ns);
    loop {
        per_ns *= 2.0;
        assert!(per_ns <= 2e4, "RK4 not converged");
        let y = super::resolved_tests::rk4(m, start, inputs, t_end, per_ns);
        if (y[2] - last[2]).abs().max((y[3] - last[3]).abs()) <= 0.01 * tol {
            return [y[2], y[3]];
        }
        last = y;
    }
}

/// `steps` 1 us steps of a benchmark case (after `warm` others) whose onion the strain turns
/// about faster than it relaxes, each step answered with the onion's angle and tilt within
/// `bound` tolerances of [`converged`] from the same start. Returns the repeated periods or
/// cycles skipped in each step answered (a refused step ends the run, and skips nothing).
fn against_rk4(text: &str, warm: usize, steps: usize, bound: f64) -> Vec<u32> {
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    let s = *inputs.schedule.get().unwrap();
    assert!(m.ring_decoupled(&s, inputs.rotor_locked, 1e-6));
    let tol = m.params.tolerance;
    for _ in 0..warm {
        m.step(&mut st, &inputs, 1e-6).unwrap();
    }
    let mut answered = Vec::new();
    for k in 0..steps {
        let start = st;
        let before = SKIPS.with(|c| c.get());
        let report = m.step(&mut st, &inputs, 1e-6);
        let skipped = SKIPS.with(|c| c.get()) - before;
        let Ok(report) = report else {
            println!("step {k}: refused, {skipped} skips");
            assert_eq!(skipped, 0, "step {k}");
            break;
        };
        let truth = converged(&m, &start, &inputs, st.time);
        let errors = [
            (st.onion_angle - truth[0]).abs() / tol,
            (st.onion_tilt - truth[1]).abs() / tol,
        ];
        println!(
            "step {k}: {} substeps, {skipped} skips, errors / tolerance against RK4 {errors:?}",
            report.substeps
        );
        assert!(
            errors.iter().all(|e| *e <= bound),
            "step {k}: {st:?} against {truth:?}"
        );
        answered.push(skipped);
    }
    answered
}

/// [`against_rk4`] with no period or cycle repeated in any step; returns the steps answered.
fn not_repeated(text: &str, warm: usize, steps: usize, bound: f64) -> usize {
    let skips = against_rk4(text, warm, steps, bound);
    assert!(skips.iter().all(|s| *s == 0), "periods repeated: {skips:?}");
    skips.len()
}

/// A locked rotor, the strain turned by 1.99 rad every 1.67 ns: the onion (damping 3.3e-2) stays
/// put while the strain turns about it, within the tolerance (4.3e-2) of a minimum of eq. 3.4 at
/// every 30th switch. Repeating the cycles between those placements would drift it by 0.68 rad,
/// 16 tolerances, a step; the linear spans follow it ([`Motor::advance_onion_linear`]), with
/// max_substeps 400 (its 592 switches a step cost the spans about 300 units; the draw's 120 pay
/// for fewer than half, and its step is refused).
#[test]
fn a_locked_onion_the_strain_turns_about_is_not_repeated() {
    let text = LOCKED_TURNED_ABOUT.replace("max_substeps=1.2e2", "max_substeps=4e2");
    let answered = not_repeated(&text, 0, 3, 0.01);
    assert_eq!(answered, 3);
    assert_eq!(not_repeated(LOCKED_TURNED_ABOUT, 0, 3, 0.01), 0);
}

/// A free rotor, the strain turned by -7.98 rad every 1.48 ns: the onion (damping 1.7e-4) within
/// the tolerance (0.31) of a minimum at every other switch. Repeating those cycles would drift it
/// by 83 rad, 267 tolerances, a step. No cycle is repeated: with max_substeps 400 the step's 667
/// switches are crossed by the linear spans ([`Motor::advance_onion_linear`], about 330 units);
/// with the draw's 5, which pays for none of them, the step is refused, its state untouched.
#[test]
fn a_free_rotor_onion_the_strain_turns_about_is_not_repeated() {
    let text = FREE_TURNED_ABOUT.replace("max_substeps=5e0", "max_substeps=4e2");
    let (m, mut st, inputs) = case(&values(&text)).unwrap();
    let before = SKIPS.with(|c| c.get());
    let report = m.step(&mut st, &inputs, 1e-6);
    assert_eq!(SKIPS.with(|c| c.get()), before);
    println!("{report:?}");
    assert!(report.is_ok(), "{report:?}");
    let (m, mut st, inputs) = case(&values(FREE_TURNED_ABOUT)).unwrap();
    let start = st;
    let e = m.step(&mut st, &inputs, 1e-6).unwrap_err();
    assert!(e.contains("max_substeps = 5"), "{e}");
    assert_eq!((st, SKIPS.with(|c| c.get())), (start, before));
}

/// The eleventh-switch case below with damping `damping` and the strain turned by `step_angle`.
fn eleventh_switch(damping: f64, step_angle: f64) -> String {
    format!(
        "strain_direction=1.339e8 stress=-1.679e6 load_torque=4.062e-7 \
         ring_outer_diameter=6.792e-1 ring_inner_diameter=3.939e-1 bar_length=9.345e-7 \
         bar_width=8.587e-7 thickness=6.104e-9 saturation_magnetization=6.218e4 \
         magnetostriction=9.855e-3 wall_volume=7.798e-11 density=1.016e4 fluid_viscosity=1.506e8 \
         gilbert_damping={damping:e} tolerance=3e-2 step_angle={step_angle:e} \
         step_period=1.124e-9 stress_amplitude=2.000e2 schedule_initial_direction=-2.932e-4 \
         onion_model=1 max_substeps=1.223e4 schedule=1 rotor_locked=1 \
         initial_onion_offset=-7.576e-11 strain=5.453e-3 youngs_modulus=4.263e6 strain_drive=1"
    )
}

/// A locked rotor, the strain turned by 0.083 rad every 1.1 ns, the onion (damping 4.9e-4,
/// slowest decay 0.004 per period, 4.4% over a cycle) within the tolerance, 3e-2 here, of its
/// branch at every 11th switch. A placement is made only where the gap it drops, carried over
/// the ~250 switches the onion remembers, is within a tenth of the tolerance
/// ([`Motor::relaxed_onion`]), so the periods between two placements are the onion's own and are
/// repeated: each step skips them and ends within the tolerance of the RK4. (Placed wherever it
/// came within the tolerance of its branch, the onion was shifted the same way at every 11th
/// switch; the periods were then not repeated, and the switches resolved one by one ended
/// 5 tolerances off the RK4 after the second step.)
#[test]
fn onion_relaxed_every_eleventh_switch_repeats_its_periods() {
    let skips = against_rk4(&eleventh_switch(4.936e-4, 3.225), 1, 2, 1.0);
    assert_eq!(skips.len(), 2);
    assert!(skips.iter().all(|s| *s > 0), "skips {skips:?}");
}

/// The same rotor with the strain turned by a quarter turn and 0.03 rad, damping 0.01 to 0.1: the
/// onion comes within the tolerance of its branch a few switches apart while it still carries
/// the last switch's jump. Placed there, it was shifted the same way at each such switch and the
/// cycles repeated that shift: 1.5 to 11.7 tolerances off the RK4 after each of two steps.
#[test]
fn a_locked_onion_turned_a_quarter_is_placed_only_once_relaxed() {
    for damping in [0.01, 0.02, 0.03, 0.05, 0.1] {
        let text = eleventh_switch(damping, std::f64::consts::FRAC_PI_2 + 0.03);
        assert_eq!(against_rk4(&text, 1, 2, 1.0).len(), 2, "damping {damping}");
    }
}

/// Benchmark draw 936996 (locked rotor).
const LOCKED_TURNED_ABOUT: &str =
    "strain_direction=-4.74761511933846e-3 stress=1.1732721293594975e3 \
    load_torque=4.6860837884336694e-7 ring_outer_diameter=4.339373172163493e-6 \
    ring_inner_diameter=2.260678627910082e-8 bar_length=1.2305301600356763e-8 \
    bar_width=1.2147211538960797e-8 thickness=2.2805144320307207e-9 \
    saturation_magnetization=3.6311439832285186e6 magnetostriction=-7.964481341114224e-3 \
    wall_volume=8.031679803708282e-11 density=1.2350809470274286e4 \
    fluid_viscosity=8.630112798722545e6 gilbert_damping=3.25620041378924e-2 \
    tolerance=4.27259168075606e-2 step_angle=1.9908071699727259e0 \
    step_period=1.665399803169521e-9 stress_amplitude=2.9624888412101003e0 \
    schedule_initial_direction=5.2528337527164966e-2 onion_model=1e0 max_substeps=1.2e2 \
    schedule=1e0 rotor_locked=1e0 initial_onion_offset=-5.9056026402278375e-2 \
    strain=-8.457043622605082e-2 youngs_modulus=9.14017960758741e12 strain_drive=0e0";

/// Benchmark draw 900176 (free rotor).
const FREE_TURNED_ABOUT: &str =
    "strain_direction=1.428679189987783e10 stress=2.0083632318446754e-3 \
    load_torque=-5.747250065872411e-7 ring_outer_diameter=4.1356954826705916e-5 \
    ring_inner_diameter=2.8707586778257322e-5 bar_length=1.4731217771739422e-5 \
    bar_width=3.110457753775959e-8 thickness=8.663675713828532e-9 \
    saturation_magnetization=1.4876507499335619e3 magnetostriction=-3.8548909855985e-3 \
    wall_volume=5.331963176231436e-12 density=6.104439087479686e3 \
    fluid_viscosity=9.572201622438905e-1 gilbert_damping=1.7166087810814205e-4 \
    tolerance=3.0930696081177056e-1 step_angle=-7.976543708695849e0 \
    step_period=1.4806314863322337e-9 stress_amplitude=1.1047399967040492e-1 \
    schedule_initial_direction=1.9585893543144706e-2 onion_model=1e0 max_substeps=5e0 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=-9.81120464316362e-12 \
    strain=-8.439150289952693e-2 youngs_modulus=8.432890598890305e12 strain_drive=0e0";
