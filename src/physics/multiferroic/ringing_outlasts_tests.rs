//! The locked onion's cheap refusal before the settle ([`Motor::ringing_outlasts_switches`]):
//! never where the switch test it bounds passes, and made where the onion rings.

use super::onion::SETTLES;
use super::onion_periods_tests::{case, values};
use super::settle_memo::SettleMemo;
use super::{Motor, MotorState};

/// A benchmark case: a locked rotor on a 26.9 ns schedule, its onion (damping 2.6e-4, tolerance
/// 1.4e-9 rad) ringing through its 1 us step, checked for its branch at each pass.
const RINGING_LOCKED: &str = "\
    strain_direction=2.944114384789648e1 stress=6.715843942572909e10 \
    load_torque=-7.160967977584702e-7 ring_outer_diameter=3.4668203546468635e-5 \
    ring_inner_diameter=1.0265677895812573e-5 bar_length=1.8504952802417988e-6 \
    bar_width=1.2949635446674366e-7 thickness=1.2289870383439651e-7 \
    saturation_magnetization=4.62641901671725e6 magnetostriction=5.96322535675738e-4 \
    wall_volume=7.964105300232371e-11 density=8.742290825860957e3 \
    fluid_viscosity=6.187853080246316e4 gilbert_damping=2.6373272349505984e-4 \
    tolerance=1.4405274132743459e-9 step_angle=-5.727540706129548e0 \
    step_period=2.6878205713337975e-8 stress_amplitude=-2.2753440008442223e4 \
    schedule_initial_direction=-1.8949574640887018e-9 onion_model=1e0 max_substeps=1.0303e4 \
    schedule=1e0 rotor_locked=1e0 initial_onion_offset=-2.191660329041401e-7 \
    strain=5.7827946261848256e-2 youngs_modulus=3.3531586875496403e10 strain_drive=1e0";

/// A benchmark case: a locked rotor on a 48 ns schedule, its onion (damping 0.018, tolerance
/// 2e-9 rad) trailing its moving minimum with a tilt of 1e-7 to 5e-4 rad.
const TRAILING_LOCKED: &str = "\
    strain_direction=-7.848078109076524e9 stress=2.8815080266853514e4 \
    load_torque=-3.0527236121838677e-7 ring_outer_diameter=4.620570236623522e-1 \
    ring_inner_diameter=9.628998606793736e-2 bar_length=1.1272508724791931e-4 \
    bar_width=8.890878860830067e-5 thickness=6.863770774669269e-9 \
    saturation_magnetization=1.9623337927919924e3 magnetostriction=3.2194179871585776e-3 \
    wall_volume=1.2296753632346036e-11 density=2.313049167367198e3 \
    fluid_viscosity=7.571355246126057e3 gilbert_damping=1.8401903301875435e-2 \
    tolerance=2.0039632500306106e-9 step_angle=-3.1359822719006747e0 \
    step_period=4.846993503448364e-8 stress_amplitude=4.340415253428115e4 \
    schedule_initial_direction=3.756758363280445e5 onion_model=1e0 max_substeps=5.466e3 \
    schedule=1e0 rotor_locked=1e0 initial_onion_offset=-9.387577425305618e-12 \
    strain=-1.042842111259934e-3 youngs_modulus=1.4935664119266244e6 strain_drive=0e0";

/// Wherever the bound refuses, the switch test it bounds (the gap to the minimum the onion
/// settles into, decayed to the next switch, times the switches remembered, within a tenth of
/// the tolerance) fails at that minimum and its curvature; and it refuses often over the
/// ringing's range of tilts, or the check would be empty.
#[test]
fn tilt_refusal_never_refuses_a_passing_switch_test() {
    let (mut refused, mut checked, mut passing) = (0, 0, 0);
    for text in [RINGING_LOCKED, TRAILING_LOCKED] {
        let (m, _, inputs): (Motor, MotorState, _) = case(&values(text)).unwrap();
        let stress = m.drive_at(&inputs, 0.0).stress;
        let period = inputs.schedule.get().unwrap().step_period;
        let slack = 0.1 * m.params.tolerance;
        for i in 0..6 {
            let rotor = -3.0 + 1.1 * f64::from(i);
            for j in 0..6 {
                let direction = 0.53 * f64::from(j);
                let land = m.landscape(rotor, direction, stress);
                for k in 0..24 {
                    let onion = rotor - 3.1 + 0.26 * f64::from(k);
                    let settled = land.settle(onion);
                    let curvature = land.curvature(settled);
                    for e in 0..12 {
                        let tilt = 10f64.powi(-e) * if k % 2 == 0 { 1.0 } else { -1.0 };
                        let y = [rotor, 0.0, onion, tilt];
                        for f in 0..5 {
                            let to_switch = period * 0.25 * f64::from(f);
                            checked += 1;
                            let memory = 1.0 + 1.0 / (m.onion_decay_rate(curvature) * period);
                            let gap = m.decayed_gap(&y, settled, curvature, to_switch) * memory;
                            let passes = curvature > 0.0 && gap <= slack;
                            passing += usize::from(passes);
                            if m.ringing_outlasts_switches(&land, &y, (to_switch, period), slack) {
                                refused += 1;
                                assert!(
                                    !passes,
                                    "rotor {rotor} strain {direction} onion {onion} tilt {tilt} \
                                     to switch {to_switch}: gap {gap} within {slack}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    println!("{refused} of {checked} refused, {passing} pass");
    assert!(4 * refused >= checked, "{refused} of {checked}");
    assert!(passing > 0);
}

/// The ringing locked onion's first step (refused: it needs more than its 10,303 substeps)
/// checks its branch at over a thousand passes, all of which fail: the refusal on the tilt
/// takes most of them before the settle's march (3 settles; 1,126 when each check settled).
#[test]
fn ringing_locked_check_skips_the_settle() {
    let (m, mut s, inputs) = case(&values(RINGING_LOCKED)).unwrap();
    SETTLES.with(|c| c.set(0));
    let report = m.step(&mut s, &inputs, 1e-6);
    let settles = SETTLES.with(|c| c.get());
    println!("{report:?}: {settles} settles");
    assert!(settles < 100, "{settles} settles");
}

/// Wherever the bounds on the slope refuse, the checks they bound fail at the minimum that the
/// settle's march returns from the onion and at its curvature there: the switch test, and the
/// ringing's end within the segment's time left ([`Motor::locked_ringing_ends`]); where they do
/// not refuse they return that minimum, bit for bit. Onions from 1e-12 to 1 rad either side of
/// a minimum, tilts from none to 1e-4 rad; and they refuse often, or the check would be empty.
#[test]
fn slope_refusal_never_refuses_a_passing_switch_test() {
    let (mut refused, mut checked, mut passing) = (0, 0, 0);
    let (mut far, mut ends) = (0, 0);
    for text in [RINGING_LOCKED, TRAILING_LOCKED] {
        let (m, _, inputs): (Motor, MotorState, _) = case(&values(text)).unwrap();
        let mut d = m.drive_at(&inputs, 0.0);
        let period = inputs.schedule.get().unwrap().step_period;
        let slack = 0.1 * m.params.tolerance;
        for i in 0..4 {
            let rotor = -3.0 + 1.7 * f64::from(i);
            for j in 0..4 {
                d.direction = 0.71 * f64::from(j);
                let land = m.landscape(rotor, d.direction, d.stress);
                let minimum = land.settle(rotor + 0.3 * f64::from(j));
                for e in 0..25 {
                    let side = if e % 2 == 0 { 1.0 } else { -1.0 };
                    let onion = minimum + side * 10f64.powf(-0.5 * f64::from(e));
                    let start = land.angles(onion);
                    let (g0, c0) = land.gradient_curvature_of(&start);
                    let settled = land.settle_from(start).onion;
                    let curvature = land.curvature(settled);
                    for tilt in [0.0, 1e-12, -1e-9, 1e-6, -1e-4] {
                        let y = [rotor, 0.0, onion, tilt];
                        for f in 0..5 {
                            let to_switch = period * 0.25 * f64::from(f);
                            let switches = (to_switch, period);
                            checked += 1;
                            let memory = 1.0 + 1.0 / (m.onion_decay_rate(curvature) * period);
                            let gap = m.decayed_gap(&y, settled, curvature, to_switch) * memory;
                            let passes = curvature > 0.0 && gap <= slack;
                            passing += usize::from(passes);
                            let slope = (&start, g0, c0);
                            if m.settle_outlasts_switches(&land, &y, slope, switches, slack) {
                                refused += 1;
                                assert!(
                                    !passes,
                                    "rotor {rotor} strain {} onion {onion} tilt {tilt} \
                                     to switch {to_switch}: gap {gap} within {slack}",
                                    d.direction
                                );
                            }
                            let ringing_ends = m.locked_ringing_ends(&y, &d, settled, to_switch);
                            ends += usize::from(ringing_ends);
                            let memo = SettleMemo::default();
                            match m.settled_unless_ringing_on(&memo, (&y, &d), to_switch) {
                                None => {
                                    far += 1;
                                    assert!(!ringing_ends, "onion {onion} tilt {tilt}");
                                }
                                Some(a) => assert_eq!(a.onion.to_bits(), settled.to_bits()),
                            }
                            let memo = SettleMemo::default();
                            let test = (switches, slack);
                            let left = Some(to_switch);
                            match m.settled_unless_outlasting(&land, &memo, (&y, &d), test, left) {
                                None => assert!(!passes || !ringing_ends, "onion {onion}"),
                                Some(a) => assert_eq!(a.onion.to_bits(), settled.to_bits()),
                            }
                        }
                    }
                }
            }
        }
    }
    println!("{refused} of {checked} refused, {passing} pass; {far} far, {ends} end");
    assert!(2 * refused >= checked, "{refused} of {checked}");
    assert!(2 * far >= checked, "{far} of {checked}");
    assert!(passing > 0 && ends > 0);
}

/// The trailing locked onion's first step checks its branch at each pass, and every check
/// fails on the onion's angle from its moving minimum while its tilt is small: the bound on
/// the slope takes them before the settle's march.
#[test]
fn trailing_locked_check_skips_the_settle() {
    let (m, mut s, inputs) = case(&values(TRAILING_LOCKED)).unwrap();
    SETTLES.with(|c| c.set(0));
    let report = m.step(&mut s, &inputs, 1e-6);
    let settles = SETTLES.with(|c| c.get());
    println!("{report:?}: {settles} settles");
    assert!(settles < 100, "{settles} settles");
}
