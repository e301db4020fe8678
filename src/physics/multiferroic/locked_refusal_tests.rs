//! When a locked rotor's ringing Gilbert onion refuses its step ([`Motor::locked_budget_drop`]):
//! only where the budget runs out before the step's last segment, which the parameters alone do
//! not decide. Configurations of the same kind as the refused ones that complete guard against a
//! refusal made before the budget is spent.

use super::onion_periods_tests::{case, values};
use super::*;
use std::f64::consts::PI;

/// The strain turned by -1.36e-2 rad every 22 ns, `gilbert_damping` 1.4e-4, tolerance 1e-8, on a
/// weak landscape: a switch's kick (1.36e-2 rad) outlasts a period by 6 orders of magnitude
/// beyond the tolerance even at the fastest decay any curvature of eq. 3.4 allows, so wherever
/// the budget runs out before the last of the step's 45 segments the step is refused.
const WEAK_LANDSCAPE_RINGING: &str = "stress=-3.355659770791531e0 \
    load_torque=-2.325342058539337e-7 ring_outer_diameter=5.987484398801978e-2 \
    ring_inner_diameter=3.915019237607755e-2 bar_length=1.390335597525003e-5 \
    bar_width=7.72515729537965e-7 thickness=1.5770459402502328e-9 \
    saturation_magnetization=2.608965978498557e3 magnetostriction=6.3412669514413805e-3 \
    wall_volume=1.5320589868062286e-12 density=5.77365371859443e3 \
    fluid_viscosity=4.801442843374604e-2 gilbert_damping=1.4477970361624273e-4 \
    tolerance=1.0121417667174117e-8 step_angle=-1.3583336313525152e-2 \
    step_period=2.224229686470455e-8 stress_amplitude=-4.2771447344594044e1 \
    schedule_initial_direction=4.3129678716614964e-7 onion_model=1 max_substeps=6861 \
    schedule=1 rotor_locked=1 initial_onion_offset=-4.8830057512558e-2";

/// Whether a switch's kick, the strain's turn folded into the half turn of eq. 3.4, outlasts a
/// period of the schedule beyond twice the tolerance at the onion's fastest decay, that at eq.
/// 3.4's curvature bound `K` (the decay rate does not decrease with the curvature): the class of
/// step whose drop the switches' test refuses wherever the budget runs out.
fn kick_outlasts_a_period(m: &Motor, s: &SteppingSchedule) -> bool {
    let land = m.landscape(0.0, s.direction(0.0), s.stress_amplitude);
    let bound = land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs();
    let folded = (s.step_angle - PI * (s.step_angle / PI).round()).abs();
    folded * (-m.onion_decay_rate(bound) * s.step_period).exp() > 2.0 * m.params.tolerance
}

/// Its first 1 us step spends the whole budget resolving the ringing and runs out in its last
/// segment, where the ringing is kept as the step's output: it completes, flagged. (The onion
/// swings over its wells' rims, 18 rad in the step; plain RK4s at 100 to 6000 steps a
/// nanosecond disagree by up to 8e-4 rad, so no RK4 is the truth here.) Its second step runs out
/// in its 44th segment of 45 and is refused. The two steps differ only in where the budget runs
/// out, 4% of the step apart: a refusal before the budget is spent would have to forecast that.
#[test]
fn ringing_whose_budget_runs_out_in_the_last_segment_completes() {
    let (m, mut st, inputs) = case(&values(WEAK_LANDSCAPE_RINGING)).unwrap();
    assert!(kick_outlasts_a_period(&m, inputs.schedule.get().unwrap()));
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    assert!(report.accuracy_limited, "{report:?}");
    if let Err(e) = m.step(&mut st, &inputs, 1e-6) {
        assert!(e.contains("max_substeps"), "{e}");
    }
}

/// Configurations whose switches' kicks outlast a period (as [`kick_outlasts_a_period`]) that
/// complete three 1 us steps: a budget of 352 over 102 switches of 9.8 ns that runs out only in
/// each step's last segment (`gilbert_damping` 5.9e-4, not creeping), and an onion that may creep
/// (`alpha^2 T` up to 3.2 times `4 |U''|`) whose forced substeps follow it once its budget of
/// 1561 runs out at the 16th of 82 switches of 12 ns; and, unflagged, ringing resolved through 25
/// switches of 40 ns in 335 substeps a step of a budget of 4891 (`gilbert_damping` 0.78 on a weak
/// landscape, `tolerance` 1.1e-2).
#[test]
fn kicks_that_outlast_a_period_complete_where_the_budget_allows() {
    for text in [
        "stress=-6.400e5 load_torque=5.102e-7 ring_outer_diameter=1.419e-2 \
         ring_inner_diameter=2.763e-5 bar_length=4.019e-6 bar_width=6.348e-8 \
         thickness=3.830e-9 saturation_magnetization=1.057e2 magnetostriction=-2.932e-3 \
         wall_volume=4.355e-11 density=1.345e3 fluid_viscosity=4.141e6 \
         gilbert_damping=7.835e-1 tolerance=1.107e-2 step_angle=-8.531e0 step_period=3.995e-8 \
         stress_amplitude=1.287e6 schedule_initial_direction=-3.720e-1 onion_model=1 \
         max_substeps=4891 schedule=1 rotor_locked=1 initial_onion_offset=2.084e1 \
         strain=6.591e-2 youngs_modulus=4.681e10",
        "stress=-9.586e8 load_torque=-4.828e-7 ring_outer_diameter=2.394e-4 \
         ring_inner_diameter=4.827e-5 bar_length=4.232e-6 bar_width=1.515e-8 \
         thickness=1.702e-9 saturation_magnetization=1.558e0 magnetostriction=-2.682e-3 \
         wall_volume=6.128e-11 density=2.645e4 fluid_viscosity=2.271e4 \
         gilbert_damping=5.851e-4 tolerance=3.505e-8 step_angle=7.761e0 step_period=9.799e-9 \
         stress_amplitude=-5.451e10 schedule_initial_direction=9.990e-7 onion_model=1 \
         max_substeps=352 schedule=1 rotor_locked=1 initial_onion_offset=1.025e-6 \
         strain=4.627e-2 youngs_modulus=3.429e6",
        "stress=3.682e7 load_torque=3.628e-7 ring_outer_diameter=6.585e-1 \
         ring_inner_diameter=6.196e-2 bar_length=1.989e-4 bar_width=1.525e-8 \
         thickness=9.572e-9 saturation_magnetization=2.716e5 magnetostriction=-6.231e-3 \
         wall_volume=8.089e-11 density=2.816e3 fluid_viscosity=3.923e-1 \
         gilbert_damping=1.380e-2 tolerance=7.626e-8 step_angle=-6.134e0 step_period=1.213e-8 \
         stress_amplitude=-7.405e1 schedule_initial_direction=-3.582e5 onion_model=1 \
         max_substeps=1561 schedule=1 rotor_locked=1 initial_onion_offset=4.130e-8",
    ] {
        let (m, mut st, inputs) = case(&values(text)).unwrap();
        assert!(kick_outlasts_a_period(&m, inputs.schedule.get().unwrap()));
        for k in 0..3 {
            let report = m.step(&mut st, &inputs, 1e-6);
            assert!(report.is_ok(), "step {k}: {report:?}");
        }
    }
}

/// Each locked Gilbert case of a benchmark log (`MOTOR_CASES`, its "slow step" lines) over
/// three 1 us steps: each step's substeps, flag and onion, or its refusal's kind, one line a
/// case (to `LOCKED_OUTCOMES` if set, to compare two versions' outcomes), with whether the
/// case's switch kicks outlast a period and each step's wall time (not a pass/fail figure).
#[test]
fn locked_outcomes_from_log() {
    let Ok(path) = std::env::var("MOTOR_CASES") else {
        return;
    };
    let mut out = String::new();
    let off = std::env::var("CLOSED_FORM_OFF").is_ok();
    super::block_phi::CLOSED_FORM_OFF.with(|c| c.set(off));
    for line in std::fs::read_to_string(path).unwrap().lines() {
        let Some(rest) = line.split("slow step: ").nth(1) else {
            continue;
        };
        let label = rest.split(':').next().unwrap_or_default();
        let text = line.rsplit('[').next().unwrap_or_default();
        let Ok((m, mut st, inputs)) = case(&values(text.trim_end_matches(']'))) else {
            continue;
        };
        if m.params.onion_model != OnionModel::Gilbert || !inputs.rotor_locked {
            continue;
        }
        let outlasts = inputs.schedule.get().map(|s| kick_outlasts_a_period(&m, s));
        let mut row = format!("{label}: kick outlasts {outlasts:?}:");
        let mut times = String::new();
        for _ in 0..3 {
            let begun = std::time::Instant::now();
            let report = m.step(&mut st, &inputs, 1e-6);
            times += &format!(" {:.1}", begun.elapsed().as_secs_f64() * 1e6);
            match report {
                Ok(r) => {
                    row += &format!(
                        " ok({} {} {:e} {:e});",
                        r.substeps, r.accuracy_limited, st.onion_angle, st.onion_tilt
                    );
                    if std::env::var("LOCKED_BOUNDS").is_ok() {
                        let bound = super::amplification::AMPLIFICATION.with(|c| c.replace(0.0));
                        let land = m.landscape(0.0, inputs.strain_direction, inputs.stress);
                        let stiffest =
                            land.ring_bar.stiffness_bound() + 2.0 * land.magnetoelastic.abs();
                        row += &format!(
                            " [bound {bound:.2e} aspect {:.2e}]",
                            (m.tilt_stiffness / stiffest).sqrt()
                        );
                    }
                }
                Err(e) => {
                    let kind = if e.contains("ringing on the locked rotor") {
                        "ringing"
                    } else if e.contains("schedule switches") {
                        "switches"
                    } else {
                        "other"
                    };
                    row += &format!(" refused({kind});");
                    break;
                }
            }
        }
        println!("{row} us{times}");
        out += &row;
        out.push('\n');
    }
    if let Ok(file) = std::env::var("LOCKED_OUTCOMES") {
        std::fs::write(file, out).unwrap();
    }
}

/// 970 switches of 1.03 ns against 60 passes (`max_substeps` 22) on a ring decoupled from the
/// onion (`gilbert_damping` 0.51): once its periods repeat, the onion takes the rest of each step
/// at once and the three 1 us steps complete. A refusal for the switches made before the loop
/// runs out of passes would refuse them.
#[test]
fn switches_beyond_the_passes_complete_where_the_onion_periods_repeat() {
    let (m, mut st, inputs) = case(&values(
        "load_torque=-1.841e-8 ring_outer_diameter=3.275e-1 ring_inner_diameter=2.096e-1 \
         bar_length=1.295e-2 bar_width=1.998e-8 thickness=1.017e-9 \
         saturation_magnetization=1.408e5 magnetostriction=-6.267e-3 wall_volume=4.211e-11 \
         density=1.439e3 fluid_viscosity=4.733e4 gilbert_damping=5.075e-1 \
         tolerance=4.847e-7 step_angle=-6.110e0 step_period=1.030e-9 \
         stress_amplitude=1.114e10 schedule_initial_direction=-3.920e-5 onion_model=1 \
         max_substeps=22 schedule=1 rotor_locked=1 initial_onion_offset=1.452e-1 \
         strain=5.779e-3 youngs_modulus=1.028e12 strain_drive=1",
    ))
    .unwrap();
    let s = *inputs.schedule.get().unwrap();
    let passes = 2.0 * f64::from(m.params.max_substeps) + 16.0;
    assert!(s.step_index(1e-6) - s.step_index(0.0) > 10.0 * passes);
    for k in 0..3 {
        let report = m.step(&mut st, &inputs, 1e-6);
        assert!(report.is_ok(), "step {k}: {report:?}");
    }
}
