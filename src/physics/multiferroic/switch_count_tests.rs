//! Locked rotors' Gilbert steps whose schedule switches outnumber the passes of the step's loop
//! ([`Motor::passes_run_out`]): carried by the onion's linear spans, against a plain RK4, or
//! refused once the spans are over.

use super::locked_accuracy_tests::onion_errors;
use super::onion_periods_tests::{case, values};
use super::*;

/// The first 1 us step of a benchmark case with `max_substeps` replaced, the passes of the
/// step's loop it took, and the onion's angle and tilt errors against [`converged_rk4`] at
/// `per_ns` from the same start, in tolerances (`None` if refused, the state then untouched).
fn first_step(
    text: &str,
    max_substeps: f64,
    per_ns: f64,
) -> (Result<StepReport, String>, u64, Option<[f64; 2]>) {
    let mut kv = values(text);
    kv.insert("max_substeps".into(), max_substeps);
    let (m, mut st, inputs) = case(&kv).unwrap();
    assert!(inputs.rotor_locked);
    let start = st;
    super::locked_switches::PASSES.with(|c| c.set(0));
    let report = m.step(&mut st, &inputs, 1e-6);
    let passes = super::locked_switches::PASSES.with(|c| c.get());
    let Ok(r) = &report else {
        assert_eq!(st, start);
        return (report, passes, None);
    };
    println!("{r:?} in {passes} passes");
    let errors = onion_errors(&m, &start, &st, &inputs, per_ns);
    println!("errors / tolerance against RK4 {errors:?}");
    (report, passes, Some(errors))
}

/// Strain turned by -3.80 rad every 1.06 ns, max_substeps 244: the step's 945 switches
/// outnumber the 504 passes of its loop (the ring coupled to the onion, the step angle 0.66 rad
/// from a half turn), but the onion's linear spans cross them a few dozen at a time. The step
/// ends within the tolerance of the RK4 in at most its budget; refused before its first pass,
/// it gave no answer at all. Unflagged.
#[test]
fn switches_outnumbering_the_passes_are_crossed_by_the_linear_spans() {
    let (report, passes, errors) = first_step(
        "ring_outer_diameter=4.302247854625061e-1 ring_inner_diameter=1.5054081044621184e-1 \
         bar_length=9.274267935169457e-3 bar_width=2.5693537220634243e-5 \
         thickness=9.440400270168416e-6 saturation_magnetization=1.188406483468047e5 \
         magnetostriction=9.233616109814114e-3 wall_volume=4.9630438246177514e-11 \
         density=5.624347808445323e3 fluid_viscosity=2.4343251316995634e1 \
         gilbert_damping=6.531395533724416e-2 tolerance=6.915035545887459e-8 \
         step_angle=-3.7968861455216523e0 step_period=1.0583607727844343e-9 \
         stress_amplitude=-2.173350085795131e-3 schedule_initial_direction=4.001602968982926e5 \
         onion_model=1 schedule=1 rotor_locked=1 \
         initial_onion_offset=2.637016264541723e-12 load_torque=-7.405277369757061e-7",
        244.0,
        100.0,
    );
    let report = report.unwrap();
    assert!(
        !report.accuracy_limited && report.substeps <= 244 && passes < 504,
        "{report:?} {passes}"
    );
    assert!(errors.unwrap().iter().all(|e| *e <= 1.0), "{errors:?}");
}

/// The locked onions of the linear spans' own tests (a creeping onion on a 1.47 ns schedule and
/// one at a loose tolerance on a 1.32 ns schedule) with max_substeps 100: 678 and 755 switches
/// against 216 passes. The spans carry both steps, unflagged, to within the tolerance of the RK4
/// in 80 and 191 passes, as with their own budgets of 2488 and 644.
#[test]
fn linear_spans_carry_steps_whose_switches_outnumber_a_small_budget() {
    use super::onion_linear_locked_tests::{CREEPING, LOOSE};
    for text in [CREEPING, LOOSE] {
        let (report, passes, errors) = first_step(text, 100.0, 20.0);
        let report = report.unwrap();
        assert!(
            !report.accuracy_limited && passes < 216,
            "{report:?} {passes}"
        );
        assert!(errors.unwrap().iter().all(|e| *e <= 1.0), "{errors:?}");
    }
}

/// Strain turned by 1.73 rad every 1.29 ns, gilbert_damping 9.4e-4, max_substeps 100: the
/// onion swings through eq. 3.4's nonlinear range, where the linear spans fail at the first
/// switch, and the step's 772 switches outnumber the 216 passes of its loop. It is refused then,
/// saying so, within a few passes of its start rather than after all 216, its state untouched.
#[test]
fn switches_outnumbering_the_passes_are_refused_once_the_spans_fail() {
    let (report, passes, _) =
        first_step(super::locked_switches_tests::SWINGING_ONION, 100.0, 200.0);
    let e = report.unwrap_err();
    assert!(
        e.contains("spans more schedule switches than max_substeps = 100"),
        "{e}"
    );
    assert!(passes <= 16, "{passes}");
}
