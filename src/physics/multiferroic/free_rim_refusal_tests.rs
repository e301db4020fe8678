//! A free rotor's onion refused by the averaged advance's check before the rims' search, for
//! its energy against the landscape's range ([`Motor::above_every_barrier`]). Each refusal is
//! also checked against the full check's, from the well the search finds, inside
//! `above_every_barrier` itself under `cfg(test)`.

use super::onion_periods_tests::{case, values};
use super::orbit_rim_refusal::{energy_range, FREE_OFF, FREE_REFUSED};
use super::*;

/// A free rotor on a 148 ns schedule, gilbert_damping 6.1e-4, tolerance 0.36 rad: the onion
/// rings chaotically about wells it keeps leaving, mostly refused for its energy.
const CHAOTIC: &str = "strain_direction=1.9087674027677695e-1 stress=1.1350007912624836e-2 load_torque=2.590576462439583e-7 ring_outer_diameter=2.648514502119364e-3 ring_inner_diameter=4.1335535873901675e-4 bar_length=4.532641425623112e-5 bar_width=1.0639732046329858e-5 thickness=1.6058389738259973e-7 saturation_magnetization=2.38431494744953e3 magnetostriction=-3.4212792500328115e-3 wall_volume=5.9868584587886245e-12 density=1.697099807139386e4 fluid_viscosity=2.468116466070059e3 gilbert_damping=6.053927675786335e-4 tolerance=3.560022380381095e-1 step_angle=9.198994615173781e-1 step_period=1.4776389860623927e-7 stress_amplitude=-1.879794226775489e3 schedule_initial_direction=-1.0773113871354449e-3 onion_model=1e0 max_substeps=1.8944e4 schedule=1e0 rotor_locked=0e0 initial_onion_offset=-8.072311717358694e-3 strain=4.353636316653803e-2 youngs_modulus=1.2960551957357111e10 strain_drive=0e0 ";

/// A free rotor on a 79 ns schedule under 3.5 GPa, gilbert_damping 5.6e-4, tolerance 3.1e-5:
/// the onion rings above its well's rims at every check of the first steps.
const ABOVE_RIMS: &str = "strain_direction=-1.554e2 stress=-3.479e9 load_torque=3.022e-7 \
     ring_outer_diameter=5.928e-5 ring_inner_diameter=3.819e-5 bar_length=1.984e-5 \
     bar_width=1.034e-5 thickness=1.891e-9 saturation_magnetization=1.373e4 \
     magnetostriction=6.175e-3 wall_volume=8.990e-11 density=5.603e3 fluid_viscosity=1.092e2 \
     gilbert_damping=5.587e-4 tolerance=3.075e-5 step_angle=1.401e0 step_period=7.854e-8 \
     stress_amplitude=-6.518e4 schedule_initial_direction=7.320e3 onion_model=1e0 \
     max_substeps=1.313e4 schedule=1e0 initial_onion_offset=-7.309e-12 strain=-6.286e-2 \
     youngs_modulus=7.851e6";

/// A step's state bits and report (`None` once refused).
type Stepped = ([u64; 4], Option<StepReport>);

/// Three 1 us steps of `text`'s motor, every free rotor's well searched (`full`) or not: each
/// step's [`Stepped`] and the refusals before the search.
fn steps(text: &str, full: bool) -> (Vec<Stepped>, u32) {
    let Ok((m, mut st, inputs)) = case(&values(text)) else {
        return (Vec::new(), 0);
    };
    FREE_OFF.with(|c| c.set(full));
    FREE_REFUSED.with(|c| c.set(0));
    let mut out = Vec::new();
    for _ in 0..3 {
        let report = m.step(&mut st, &inputs, 1e-6).ok();
        let s = &st;
        let bits = [s.rotor_angle, s.rotor_speed, s.onion_angle, s.onion_tilt].map(f64::to_bits);
        let stop = report.is_none();
        out.push((bits, report));
        if stop {
            break;
        }
    }
    FREE_OFF.with(|c| c.set(false));
    (out, FREE_REFUSED.with(|c| c.get()))
}

/// The refusals before the search leave the steps bit for bit (states, outputs, substeps,
/// flags) as the full checks do.
#[test]
fn free_refusals_leave_the_steps_bit_for_bit() {
    for (text, least) in [(CHAOTIC, 20), (ABOVE_RIMS, 100)] {
        let (full, none) = steps(text, true);
        let (quick, refused) = steps(text, false);
        assert_eq!(none, 0);
        assert_eq!(full, quick);
        assert!(refused >= least, "{refused} refusals");
    }
}

/// The range bounds every well's barrier: wells searched from a grid of onion angles at a grid
/// of rotor angles, in both configurations' landscapes.
#[test]
fn energy_range_bounds_every_barrier() {
    for text in [CHAOTIC, ABOVE_RIMS] {
        let (m, _, inputs) = case(&values(text)).unwrap();
        let mut wells = 0;
        for i in 0..24 {
            let land = m.landscape(0.27 * f64::from(i), inputs.strain_direction, inputs.stress);
            let range = energy_range(&land);
            for j in 0..24 {
                let minimum = land.settle(0.26 * f64::from(j));
                let Some(w) = m.well_of_minimum(&land, minimum) else {
                    continue;
                };
                wells += 1;
                assert!(w.barrier <= range / (1.0 + 1e-6), "{w:?} {range}");
            }
        }
        assert!(wells > 100, "{wells} wells");
    }
}

/// Every Gilbert draw of a bench log (`MOTOR_CASES`, lines "slow step: ..."): the steps bit for
/// bit with and without the refusals before the search.
#[test]
fn free_refusals_over_a_bench_log() {
    let Ok(path) = std::env::var("MOTOR_CASES") else {
        return;
    };
    let (mut cases, mut fired, mut refusals) = (0, 0, 0u64);
    for line in std::fs::read_to_string(path).unwrap().lines() {
        let Some(rest) = line.split("slow step: ").nth(1) else {
            continue;
        };
        let text = rest
            .rsplit('[')
            .next()
            .unwrap_or_default()
            .trim_end_matches(']');
        let label = rest.split(':').next().unwrap_or_default();
        let (full, _) = steps(text, true);
        let (quick, refused) = steps(text, false);
        assert_eq!(full, quick, "{label}");
        cases += 1;
        if refused > 0 {
            println!("{label}: {refused} refusals before the search");
        }
        fired += u32::from(refused > 0);
        refusals += u64::from(refused);
    }
    println!("{cases} cases, identical; {fired} with refusals before the search ({refusals})");
}
