//! The budget's charge for a locked rotor's decay check ([`Motor::locked_ringing_decays`]):
//! every orbit's quadrature it evaluates is paid for.

use super::locked_ringing::{DECAY_CHARGE, ORBIT_WEIGHT};
use super::onion_periods_tests::{case, values};

/// Draw 941344 of the worst-case bench: a locked rotor's onion released 307.6 rad from the
/// strain on a 98.6 ms schedule, `max_substeps` 32; its first 1 us step drops the ringing where
/// the decay check finds that it ends the segment within the tolerance.
const DECAYING: &str = "strain_direction=-6.137477461165479e7 stress=-2.2250156512845986e5 \
     load_torque=3.527697408908876e-7 ring_outer_diameter=1.4429424221101186e-1 \
     ring_inner_diameter=8.190966141480008e-5 bar_length=2.0470416126033837e-5 \
     bar_width=4.882493712698658e-6 thickness=4.798937090337843e-8 \
     saturation_magnetization=3.1189380172331625e5 magnetostriction=-5.722115276299618e-3 \
     wall_volume=5.539841150965584e-11 density=1.1668778556392965e4 \
     fluid_viscosity=4.895640768622574e5 gilbert_damping=1.0590724776523323e-3 \
     tolerance=1.2029326611341423e-3 step_angle=1.5254904602538986e0 \
     step_period=9.863383817399161e-2 stress_amplitude=1.1983589956299987e7 \
     schedule_initial_direction=1.2126371547126666e3 onion_model=1e0 max_substeps=3.2e1 \
     schedule=1e0 rotor_locked=1e0 initial_onion_offset=3.0756019472312323e2 \
     strain=8.576418575524944e-2 youngs_modulus=3.695176504673859e9 strain_drive=0e0";

/// [`DECAYING`]'s first step with `max_substeps` replaced: its result, the orbits' quadratures
/// the decay check evaluated and the units charged for them.
fn first_step(max_substeps: f64) -> (Result<super::StepReport, String>, u64, u64) {
    let mut kv = values(DECAYING);
    kv.insert("max_substeps".into(), max_substeps);
    let (m, mut st, inputs) = case(&kv).unwrap();
    DECAY_CHARGE.with(|c| c.set((0, 0)));
    let report = m.step(&mut st, &inputs, 1e-6);
    let (orbits, units) = DECAY_CHARGE.with(|c| c.get());
    println!("{report:?}: {orbits} orbits evaluated, {units} units charged for them");
    (report, orbits, units)
}

/// The check evaluates its 14 orbits (with the draw's budget and an ample one alike) and the
/// step pays [`ORBIT_WEIGHT`] units for each (the check's own unit aside).
#[test]
fn the_decay_check_pays_for_its_orbits() {
    for max_substeps in [32.0, 2e4] {
        let (report, orbits, units) = first_step(max_substeps);
        assert!(report.is_ok(), "{report:?}");
        assert!(orbits >= 8, "{orbits}");
        assert_eq!(units, u64::from(ORBIT_WEIGHT) * orbits);
    }
}
