//! The onion state settles in the basin it is in after any input jump (section 3.2.2,
//! "the minimum closest to its orientation"), against a slow-ramp reference.

use super::*;
use proptest::prelude::*;

/// Onion angle after ramping the stress on a locked rotor at 0 from zero to `to` in `n` equal
/// increments, each settled from the last (a quasi-static ramp).
fn ramp(m: &Motor, direction: f64, from: (f64, f64), to: f64, n: usize) -> f64 {
    let (stress0, mut psi) = from;
    for i in 1..=n {
        let stress = stress0 + (to - stress0) * i as f64 / n as f64;
        psi = m.landscape(0.0, direction, stress).settle(psi);
    }
    psi
}

#[test]
fn jump_near_a_fold_keeps_the_narrow_basin() {
    // Locked rotor, tension at -15 degrees: ramp slowly to 146 MPa, then one step to 148 MPa.
    // A minimum still exists at 16.69 degrees, where a slow ramp ends; the old fixed stride
    // stepped over its basin (< 1 degree wide) and left the onion at 58.97 degrees.
    let m = Motor::new(MotorParams::table_3_1()).unwrap();
    let direction = (-15f64).to_radians();
    let at_146 = ramp(&m, direction, (0.0, 0.0), 146e6, 14_600);
    let jumped = m.landscape(0.0, direction, 148e6).settle(at_146);
    let slow = ramp(&m, direction, (146e6, at_146), 148e6, 2000);
    assert!(
        (slow.to_degrees() - 16.69).abs() < 0.01,
        "{}",
        slow.to_degrees()
    );
    assert!(
        (jumped - slow).abs() < 1e-9,
        "{} {}",
        jumped.to_degrees(),
        slow.to_degrees()
    );
    // The same through the motor's step (the FMU's path).
    let mut s = MotorState::aligned(0.0);
    for i in 1..=1460 {
        let input = MotorInputs {
            rotor_locked: true,
            ..MotorInputs::fixed(direction, 146e6 * i as f64 / 1460.0)
        };
        m.step(&mut s, &input, 1e-9).unwrap();
    }
    let input = MotorInputs {
        rotor_locked: true,
        ..MotorInputs::fixed(direction, 148e6)
    };
    let r = m.step(&mut s, &input, 1e-9).unwrap();
    assert!(
        (r.outputs.offset_angle.to_degrees() - 16.69).abs() < 0.01,
        "{}",
        r.outputs.offset_angle.to_degrees()
    );
}

/// The stress of the fold on the near branch (where the minimum next to alignment disappears) for
/// tension at `direction`: the largest equilibrium stress along that branch.
fn fold_stress(m: &Motor, direction: f64) -> Option<f64> {
    let e = m.magnetoelastic_per_stress;
    let mut best: f64 = 0.0;
    for i in 1..200_000 {
        let b = i as f64 * 1e-5;
        let lever = -e * (2.0 * (b - direction)).sin();
        if lever <= 0.0 {
            return None;
        }
        let s = m.ring_bar.torque(b) / lever;
        if s < best {
            return Some(best);
        }
        best = s;
    }
    None
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Near the fold of every strain direction that has one, a slow ramp to just below it and one
    /// jump of any size that stays below it ends where the slow ramp ends.
    #[test]
    fn any_jump_below_the_fold_ends_where_a_slow_ramp_ends(
        direction_deg in -44.0f64..-1.0,
        start_fraction in 0.90f64..0.9999,
        jump_fraction in 0.0f64..1.0,
    ) {
        let m = Motor::new(MotorParams::table_3_1()).unwrap();
        let direction = direction_deg.to_radians();
        let Some(fold) = fold_stress(&m, direction) else { return Ok(()); };
        let start = fold * start_fraction;
        let end = start + (fold * 0.999_99 - start) * jump_fraction;
        prop_assume!(end > start);
        let psi = ramp(&m, direction, (0.0, 0.0), start, 2000);
        let jumped = m.landscape(0.0, direction, end).settle(psi);
        let slow = ramp(&m, direction, (start, psi), end, 500);
        prop_assert!((jumped - slow).abs() < 1e-8,
            "jump {} deg, slow ramp {} deg", jumped.to_degrees(), slow.to_degrees());
    }

    /// Past the fold the minimum is gone: a jump from below to above it goes downhill to the same
    /// far minimum as a slow ramp across it.
    #[test]
    fn a_jump_across_the_fold_lands_where_a_slow_ramp_does(
        direction_deg in -44.0f64..-1.0,
        beyond in 1.0001f64..1.5,
    ) {
        let m = Motor::new(MotorParams::table_3_1()).unwrap();
        let direction = direction_deg.to_radians();
        let Some(fold) = fold_stress(&m, direction) else { return Ok(()); };
        let start = 0.99 * fold;
        let end = beyond * fold;
        let psi = ramp(&m, direction, (0.0, 0.0), start, 2000);
        let jumped = m.landscape(0.0, direction, end).settle(psi);
        let slow = ramp(&m, direction, (start, psi), end, 2000);
        prop_assert!((jumped - slow).abs() < 1e-8,
            "jump {} deg, slow ramp {} deg", jumped.to_degrees(), slow.to_degrees());
    }
}

#[test]
fn a_rotor_far_out_settles_to_the_resolution_its_angles_have() {
    // A restored or fuzzed state: the rotor 1.094e12 rad out, the onion near 5 rad. The gradient
    // sees psi only through psi - phi, spaced 1.2e-4 rad there; a root tolerance finer than that
    // (relative to psi alone) made every refinement bisect some 35 times.
    let m = Motor::new(MotorParams::table_3_1()).unwrap();
    let bar = 1.0940563349461193e12f64;
    let spacing = bar - f64::from_bits(bar.to_bits() - 1);
    for stress in [0.0, 50e6, 148e6] {
        let landscape = m.landscape(bar, 0.3, stress);
        assert!(landscape.root_tolerance(5.0) >= 4.0 * spacing);
        assert!(landscape.root_tolerance(5.0) <= 16.0 * spacing);
        let psi = landscape.settle(5.0);
        // A minimum to that resolution: the energy rises a few spacings either side.
        let step = 64.0 * spacing;
        let (e, left, right) = (
            landscape.energy(psi),
            landscape.energy(psi - step),
            landscape.energy(psi + step),
        );
        assert!(
            psi.is_finite() && left >= e && right >= e,
            "{stress}: {psi}"
        );
    }
    // Where the angles are small, the tolerance stays 1e-15 relative.
    let near = m.landscape(0.1, 0.3, 50e6);
    assert!((near.root_tolerance(2.0) - 3e-15).abs() < 1e-29);
}
