//! The linear propagator of a locked onion's small ringing ([`Motor::advance_linear_ringing`])
//! against a converged RK4 of the motor, written independently in `locked_accuracy_tests.rs`.

use super::linear_ringing::{OFF, TAKEN};
use super::locked_accuracy_tests::onion_errors;
use super::onion_periods_tests::{case, values};
use super::orbit_phase_tests::DRAW_471993;

/// Steps 1 to 3 (1 us each) of a locked-rotor bench draw with and without the propagator: per
/// step the substeps reported, whether the propagator ended the step, and the onion's angle and
/// tilt errors in tolerances against [`converged_rk4`] from the same start. With the propagator,
/// steps 2 and 3 are not flagged (the first may be, by the averaged advance's return to its
/// turning point).
fn three_steps(text: &str, off: bool) -> Vec<(u32, bool, [f64; 2])> {
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    assert!(inputs.rotor_locked);
    OFF.with(|c| c.set(off));
    let rows = (0..3)
        .map(|k| {
            let start = st;
            let taken = TAKEN.with(|c| c.get());
            let report = m.step(&mut st, &inputs, 1e-6).unwrap();
            assert!(off || k == 0 || !report.accuracy_limited, "{report:?}");
            let errors = onion_errors(&m, &start, &st, &inputs, 2000.0);
            (report.substeps, TAKEN.with(|c| c.get()) > taken, errors)
        })
        .collect();
    OFF.with(|c| c.set(false));
    rows
}

/// Draw 471993: `k / T` = 2.4, damping 2.5e-3, tolerance 2.2e-9. The first step averages the
/// ringing down from 0.06 rad; in the second and third it is ~1e-5 rad wide, where the averaged
/// advance's quadrature is swamped by rounding: without the propagator the second step took its
/// averaging's whole allowance and then resolved substeps (278 reported, the onion 4.2
/// tolerances off). With it the second step is one substep, 1e-5 tolerances off; the third,
/// the ringing then within the relaxed onion's slack, is one substep either way.
#[test]
fn draw_471993_small_ringing_propagated_against_rk4() {
    let text = DRAW_471993;
    let before = three_steps(text, true);
    let after = three_steps(text, false);
    println!("without: {before:?}\nwith: {after:?}");
    assert!(before[1].0 > 100, "{before:?}");
    assert!(after[1].1, "{after:?}");
    for (substeps, _, errors) in &after {
        assert!(errors.iter().all(|e| *e <= 1.0), "{after:?}");
        assert!(*substeps <= 20, "{after:?}");
    }
}

/// Draw 35330: damping 1.8e-4, tolerance 2.1e-10, a schedule 36 s long (no switch within the
/// steps), the ringing as small and the averaged advance as swamped: without the propagator
/// each step took 340 to 380 substeps and ended 43 to 48 tolerances off in tilt (not flagged);
/// with it one substep each, within 1e-6 tolerances.
#[test]
fn draw_35330_small_ringing_propagated_against_rk4() {
    let text = "strain_direction=-2.4887297613561966e10 stress=-1.1478000285683914e0 \
         load_torque=-8.560998127307619e-7 ring_outer_diameter=5.698328358444666e-1 \
         ring_inner_diameter=4.908127201129476e-2 bar_length=3.5474188019121105e-5 \
         bar_width=1.0416368922330127e-6 thickness=3.729398538216934e-8 \
         saturation_magnetization=4.497808966807779e1 magnetostriction=2.989605531459501e-4 \
         wall_volume=8.744836504297738e-11 density=4.600065875291123e4 \
         fluid_viscosity=5.593077743130147e8 gilbert_damping=1.8116047108784046e-4 \
         tolerance=2.1459221213069817e-10 step_angle=-7.862396980188089e0 \
         step_period=3.562262950270174e1 stress_amplitude=6.772715264070522e2 \
         schedule_initial_direction=-4.3422879126012625e-7 onion_model=1e0 max_substeps=9.019e3 \
         schedule=1e0 rotor_locked=1e0 initial_onion_offset=-1.366341937356066e-10 \
         strain=-9.38815565465337e-2 youngs_modulus=7.71477619434324e11 strain_drive=1e0";
    let before = three_steps(text, true);
    let after = three_steps(text, false);
    println!("without: {before:?}\nwith: {after:?}");
    assert!(before.iter().all(|r| r.0 > 100), "{before:?}");
    for (substeps, taken, errors) in &after {
        assert!(*taken, "{after:?}");
        assert!(errors.iter().all(|e| *e <= 1.0), "{after:?}");
        assert!(*substeps <= 20, "{after:?}");
    }
}
