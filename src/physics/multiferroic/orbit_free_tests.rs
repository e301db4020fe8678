//! A free rotor's orbit-averaged ringing ([`Motor::advance_orbits`]) against a converged plain
//! RK4 of the macrospin and the rotor, with its cost in substeps.

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4;

/// A benchmark case (full precision): a free rotor under its load in a 0.15 m ring, its Gilbert
/// onion (damping 2e-3, `T / k` 1.1, a 130 ps precession) released 0.77 of the way up its
/// well's lowest rim, 1.1 rad off its minimum.
const C696918: &str = "strain_direction=1.1023352964311116e4 stress=3.5105261098953315e0 \
    load_torque=2.3805086438634438e-7 ring_outer_diameter=1.4561747831377544e-1 \
    ring_inner_diameter=5.302585300330648e-2 bar_length=3.822146827536929e-3 \
    bar_width=9.179847609481582e-5 thickness=1.081747049433442e-6 \
    saturation_magnetization=2.3302827471097466e5 magnetostriction=-4.107765471706939e-3 \
    wall_volume=3.314401431967586e-11 density=3.291634425773063e3 \
    fluid_viscosity=2.0724957635956002e-2 gilbert_damping=2.025972029671581e-3 \
    tolerance=6.927208551383143e-10 step_angle=1.8538301857859256e0 \
    step_period=2.355428142550079e-8 stress_amplitude=-7.954301484841882e8 \
    schedule_initial_direction=5.348949918530311e-5 onion_model=1e0 max_substeps=5.922e3 \
    schedule=0e0 rotor_locked=0e0 initial_onion_offset=3.0589335482115074e-8 \
    strain=3.384947337825256e-2 youngs_modulus=1.4404817012822273e8 strain_drive=1e0";

/// The first 1 us step: the ringing decays to the branch's slack in about 80 ns (some 600
/// orbits), averaged without its phase. The averaged steps advance the logarithm of the orbit's
/// energy, whose rate changes only with the orbit's shape, and span hundreds of orbits; steps
/// of the energy itself overshoot past the minimum once they span about a decay time (40
/// orbits), and took 52 substeps' worth of budget (253 evaluations of the averaged equations).
/// Rotor, onion and tilt end within a hundredth of the tolerance of an RK4 at 1,000 and 2,000
/// steps a nanosecond, which agree within a hundredth of it.
#[test]
fn free_ringing_averaged_by_its_energy_logarithm() {
    let (m, start, inputs) = case(&values(C696918)).unwrap();
    let tol = m.params.tolerance;
    let h = 1e-6;
    let reference = rk4(&m, &start, &inputs, h, 1e3);
    let finer = rk4(&m, &start, &inputs, h, 2e3);
    for i in [0, 2, 3] {
        assert!(
            (reference[i] - finer[i]).abs() <= 0.01 * tol,
            "RK4 not converged: {reference:?} {finer:?}"
        );
    }
    let mut st = start;
    let report = m.step(&mut st, &inputs, h).unwrap();
    let got = [
        st.rotor_angle,
        st.rotor_speed,
        st.onion_angle,
        st.onion_tilt,
    ];
    println!("{got:?} against {finer:?}: {} substeps", report.substeps);
    assert!(!report.accuracy_limited);
    for i in [0, 2, 3] {
        assert!(
            (got[i] - finer[i]).abs() <= 0.01 * tol,
            "{i}: {got:?} against {finer:?}"
        );
    }
    assert!(report.substeps <= 20, "{} substeps", report.substeps);
}
