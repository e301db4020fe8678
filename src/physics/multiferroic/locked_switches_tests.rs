//! A locked rotor's Gilbert onion on schedules of a few nanoseconds, where the step's budget runs
//! out, against a plain RK4 of the macrospin over the whole 1 us step
//! ([`Motor::locked_budget_drop`]).

use super::locked_accuracy_tests::onion_errors;
use super::onion_periods_tests::{case, values};
use super::*;

/// A locked onion swinging through eq. 3.4's nonlinear range: the strain turned by 1.73 rad every
/// 1.29 ns, `gilbert_damping` 9.4e-4, `tolerance` 4.2e-10 rad.
pub(super) const SWINGING_ONION: &str =
    "ring_outer_diameter=6.689773374482153e-1 ring_inner_diameter=5.229719702063255e-4 \
    bar_length=4.2246868198660125e-6 bar_width=4.0243948089677603e-7 \
    thickness=1.4288504805448858e-7 saturation_magnetization=3.665867080948071e5 \
    magnetostriction=9.351657340221425e-3 wall_volume=5.519678402375946e-11 \
    density=6.12984964452289e4 fluid_viscosity=1.4404841299204888e-2 \
    gilbert_damping=9.397088279062384e-4 tolerance=4.2497998935769707e-10 \
    step_angle=1.731028576858023e0 step_period=1.2947742291561714e-9 \
    stress_amplitude=2.239088779306622e2 schedule_initial_direction=8.628510614585825e5 \
    onion_model=1 schedule=1 rotor_locked=1 \
    initial_onion_offset=1.9820298572340874e-9 load_torque=-2.480124847198726e-7";

/// The first 1 us step of a benchmark case and the onion's angle and tilt errors against
/// [`converged_rk4`] at `per_ns` from the same start, in tolerances (`None` if refused).
fn first_step(text: &str, per_ns: f64) -> (Result<StepReport, String>, Option<[f64; 2]>) {
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    assert!(inputs.rotor_locked);
    let start = st;
    let report = m.step(&mut st, &inputs, 1e-6);
    if report.is_err() {
        return (report, None);
    }
    let errors = onion_errors(&m, &start, &st, &inputs, per_ns);
    println!("{report:?}: errors / tolerance against RK4 {errors:?}");
    assert_eq!(st.rotor_angle, start.rotor_angle);
    (report, Some(errors))
}

/// Strain turned by -2.8 rad every 1.47 ns, gilbert_damping 0.22 on a weak landscape: the onion
/// creeps (its tilt relaxes far faster than it turns) by 2e-5 rad over the step's 678 switches,
/// which spend the budget. The forced substeps follow it within the tolerance of the RK4, and
/// the step is not flagged; dropped into its minimum at every switch it turned with the strain,
/// 64 rad (4.5e7 tolerances) off.
#[test]
fn creeping_onion_on_a_1_ns_schedule_keeps_its_forced_substeps() {
    let (report, errors) = first_step(
        "ring_outer_diameter=2.8469494225458643e-2 ring_inner_diameter=6.604890130437266e-3 \
         bar_length=1.0779507175724333e-6 bar_width=4.503890913627021e-8 \
         thickness=2.18195679941534e-8 saturation_magnetization=5.126149671924257e4 \
         magnetostriction=-7.836896931303874e-3 wall_volume=9.347236765285793e-12 \
         density=2.4551449322208205e3 fluid_viscosity=7.559771757926201e4 \
         gilbert_damping=2.21062817452914e-1 tolerance=1.4276541243319657e-6 \
         step_angle=-2.8076869365881514e0 step_period=1.474231744190367e-9 \
         stress_amplitude=-4.209278983086497e-1 schedule_initial_direction=-2.0404417070533065e0 \
         onion_model=1 max_substeps=2488 schedule=1 rotor_locked=1 \
         initial_onion_offset=1.3736214822621958e-11 load_torque=-9.915438607453414e-7",
        100.0,
    );
    let report = report.unwrap();
    assert!(!report.accuracy_limited, "{report:?}");
    assert!(errors.unwrap().iter().all(|e| *e <= 1.0), "{errors:?}");
}

/// Strain turned by -3.136 rad (a half turn less 5.6e-3 rad) every 48 ns, gilbert_damping 1.8e-2:
/// each switch's ringing decays by e^-17 within its period, and the budget runs out in the
/// first step. Its ringing dropped at the switches before the last and resolved (forced) in the
/// last segment, the onion ends within the tolerance of the RK4; dropped in the last segment
/// too, it ended 46 tolerances off.
#[test]
fn ringing_that_ends_within_each_period_is_dropped_but_in_the_last() {
    let (report, errors) = first_step(
        "ring_outer_diameter=4.620570236623522e-1 ring_inner_diameter=9.628998606793736e-2 \
         bar_length=1.1272508724791931e-4 bar_width=8.890878860830067e-5 \
         thickness=6.863770774669269e-9 saturation_magnetization=1.9623337927919924e3 \
         magnetostriction=3.2194179871585776e-3 wall_volume=1.2296753632346036e-11 \
         density=2.313049167367198e3 fluid_viscosity=7.571355246126057e3 \
         gilbert_damping=1.8401903301875435e-2 tolerance=2.0039632500306106e-9 \
         step_angle=-3.1359822719006747e0 step_period=4.846993503448364e-8 \
         stress_amplitude=4.340415253428115e4 schedule_initial_direction=3.756758363280445e5 \
         onion_model=1 max_substeps=5466 schedule=1 rotor_locked=1 \
         initial_onion_offset=-9.387577425305618e-12 load_torque=-3.0527236121838677e-7",
        100.0,
    );
    assert!(report.unwrap().accuracy_limited);
    assert!(errors.unwrap().iter().all(|e| *e <= 1.0), "{errors:?}");
}

/// Strain turned by 1.73 rad every 1.29 ns, gilbert_damping 9.4e-4, tolerance 4.2e-10: the
/// onion precesses once in 13 ns and decays by 5% a period, so it barely follows the strain
/// (0.35 rad over the step's 772 switches), which the budget cannot resolve. The step is
/// refused, saying so, or ends within the tolerance of the RK4; dropped into its minimum at
/// every switch, it followed the strain 904 rad (2e12 tolerances) off.
#[test]
fn ringing_onion_the_budget_cannot_resolve_is_refused() {
    let (report, errors) = first_step(&format!("{SWINGING_ONION} max_substeps=5595"), 200.0);
    match (report, errors) {
        (Err(e), _) => assert!(e.contains("max_substeps"), "{e}"),
        (Ok(_), errors) => assert!(errors.unwrap().iter().all(|e| *e <= 1.0), "{errors:?}"),
    }
}

/// Strain turned by -1.23 rad every 1.26 ns, gilbert_damping 0.12, tolerance 1.1e-2, on a weak
/// landscape: the onion creeps (its curvature's `4 |U''|` is 1/160 of `alpha^2 T`) and its
/// budget of 803 pays for about one forced substep per switch. Those follow it within 1e-4
/// tolerances of the RK4 over three steps; dropped into its minimum at every switch it turned
/// with the strain, 786 rad (7e4 tolerances) a step.
#[test]
fn creeping_onion_with_a_substep_per_switch_stays_within_the_tolerance() {
    let text =
        "ring_outer_diameter=2.3732846645843895e-3 ring_inner_diameter=2.235360017070524e-3 \
         bar_length=2.5242264618915877e-5 bar_width=1.3645023005758869e-5 \
         thickness=5.547779367029385e-8 saturation_magnetization=4.272071942222984e5 \
         magnetostriction=4.698776092010361e-3 wall_volume=8.569481140353211e-11 \
         density=1.9368520390350972e4 fluid_viscosity=9.001813455484988e3 \
         gilbert_damping=1.2032259494896219e-1 tolerance=1.0854033961432157e-2 \
         step_angle=-1.2317253989238903e0 step_period=1.2569923667204684e-9 \
         stress_amplitude=-3.6475081819685323e2 schedule_initial_direction=7.520818991331611e-8 \
         onion_model=1 max_substeps=803 schedule=1 rotor_locked=1 \
         initial_onion_offset=6.040605507789597e-3 load_torque=8.906150444115635e-7";
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    for _ in 0..3 {
        let start = st;
        let report = m.step(&mut st, &inputs, 1e-6).unwrap();
        let errors = onion_errors(&m, &start, &st, &inputs, 100.0);
        assert!(!report.accuracy_limited, "{report:?}");
        assert!(errors.iter().all(|e| *e <= 1.0), "{errors:?}");
    }
}
