//! Locked rotors' Gilbert steps whose schedule switches outnumber the passes of the step's loop
//! ([`Motor::passes_run_out`]): carried by the onion's linear spans, against a plain RK4, or
//! refused once the spans are over.

use super::locked_accuracy_tests::onion_errors;
use super::onion_periods_tests::{case, values};
use super::*;

/// The first 1 us step of a benchmark case with `max_substeps` replaced, the passes of the
/// step's loop it took, and the onion's angle and tilt errors against [`converged_rk4`] at
/// `per_ns` from the same start, in tolerances (`None` if refused, the state then untouched).
pub(super) fn first_step(
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

/// Draw 1383114 of the worst-case bench: strain turned by -3.80 rad every 1.06 ns, the ring
/// coupled to a locked rotor's onion, the step angle 0.66 rad from a half turn.
pub(super) const MANY_SWITCHES: &str =
    "ring_outer_diameter=4.302247854625061e-1 ring_inner_diameter=1.5054081044621184e-1 \
     bar_length=9.274267935169457e-3 bar_width=2.5693537220634243e-5 \
     thickness=9.440400270168416e-6 saturation_magnetization=1.188406483468047e5 \
     magnetostriction=9.233616109814114e-3 wall_volume=4.9630438246177514e-11 \
     density=5.624347808445323e3 fluid_viscosity=2.4343251316995634e1 \
     gilbert_damping=6.531395533724416e-2 tolerance=6.915035545887459e-8 \
     step_angle=-3.7968861455216523e0 step_period=1.0583607727844343e-9 \
     stress_amplitude=-2.173350085795131e-3 schedule_initial_direction=4.001602968982926e5 \
     onion_model=1 schedule=1 rotor_locked=1 \
     initial_onion_offset=2.637016264541723e-12 load_torque=-7.405277369757061e-7";

/// [`MANY_SWITCHES`]: the 1 us step's 945 switches, which the onion's linear spans cross a few
/// dozen at a time, cost about 470 budget units (two switches a unit). With max_substeps 600
/// (1216 passes) the spans carry the step to within the tolerance of the RK4, unflagged; with
/// 244 (504 passes, the bench's draw) the budget pays for half the switches, and the step is
/// refused once it is spent, saying to raise max_substeps, well before its last pass.
#[test]
fn linear_spans_cross_the_switches_the_budget_pays_for() {
    let (report, passes, errors) = first_step(MANY_SWITCHES, 600.0, 100.0);
    let report = report.unwrap();
    assert!(
        !report.accuracy_limited && passes < 100,
        "{report:?} {passes}"
    );
    assert!(errors.unwrap().iter().all(|e| *e <= 1.0), "{errors:?}");
    let (report, passes, _) = first_step(MANY_SWITCHES, 244.0, 100.0);
    let e = report.unwrap_err();
    assert!(e.contains("max_substeps = 244"), "{e}");
    assert!(passes < 100, "{passes}");
}

/// The locked onions of the linear spans' own tests (a creeping onion on a 1.47 ns schedule and
/// one at a loose tolerance on a 1.32 ns schedule) with max_substeps 100: 678 and 755 switches,
/// which the spans would cross in a few dozen passes, against 216 passes. The budget pays for
/// 200 of them: both steps are refused once it is spent, their states untouched.
#[test]
fn a_small_budget_ends_the_linear_spans_of_steps_whose_switches_outnumber_it() {
    use super::onion_linear_locked_tests::{CREEPING, LOOSE};
    for text in [CREEPING, LOOSE] {
        let (report, passes, _) = first_step(text, 100.0, 20.0);
        let e = report.unwrap_err();
        assert!(e.contains("max_substeps = 100"), "{e}");
        assert!(passes < 100, "{passes}");
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
