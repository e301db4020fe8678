//! The settles of the Gilbert onion's branch checks ([`super::branch_settle`]): skipped where
//! the minimum lies provably beyond the checks' slack, never where it does not, and made once
//! where the onion joins its branch.

use super::onion::{EVALUATIONS, SETTLES};
use super::onion_periods_tests::{case, values};
use super::ringing_drop_tests::C370371;
use super::step::StepRun;
use super::{Drive, Motor, MotorInputs, MotorState};

/// [`C370371`]: a free rotor on a 1.26 ns schedule turning the strain 0.2 rad (mod pi) a
/// switch, its onion (damping 0.32, relaxation 0.85 ns) taking one Gilbert substep a switch
/// and checked for its branch at each, right after the switch, about 0.1 rad from the new
/// minimum (tolerance 2.6e-10 rad).
const ONE_SUBSTEP_A_SWITCH: &str = C370371;

/// A benchmark case: a free rotor on a 1.26 ns schedule that the ring cannot move, its onion
/// (damping 1e-4) beyond what the budget of 688 resolves: after its first forced substep the
/// onion follows its quasi-static branch, one drift of the rotor and one settle a switch.
const FOLLOWING_A_FAST_SCHEDULE: &str = "\
    strain_direction=1.1938852703548655e10 stress=-7.391567662659486e7 \
    load_torque=-7.481785331667492e-7 ring_outer_diameter=4.1652660572696176e-2 \
    ring_inner_diameter=1.4993937742691938e-2 bar_length=6.575094542054891e-4 \
    bar_width=3.878465305252394e-4 thickness=1.909710243474712e-6 \
    saturation_magnetization=7.06519375159366e4 magnetostriction=-8.726228788196901e-3 \
    wall_volume=4.798877264815253e-11 density=8.687423239669195e3 \
    fluid_viscosity=5.861185618793041e5 gilbert_damping=1.00730013719039e-4 \
    tolerance=1.3164962329533714e-5 step_angle=-5.8277599620295035e0 \
    step_period=1.2625803204088805e-9 stress_amplitude=-4.124965751129465e7 \
    schedule_initial_direction=-5.3586534477716075e-6 onion_model=1e0 max_substeps=6.88e2 \
    schedule=1e0 initial_onion_offset=1.8770881420846723e-8 strain=1.745452766916182e-2 \
    youngs_modulus=2.3108692736752393e12 strain_drive=1e0";

/// One 1 us step from the state after `warm` such steps: its substeps, switches and the
/// settles it makes.
fn settles_in_a_step(text: &str, warm: usize) -> (u32, usize, u64) {
    let (m, mut s, inputs): (Motor, MotorState, MotorInputs) = case(&values(text)).unwrap();
    for _ in 0..warm {
        m.step(&mut s, &inputs, 1e-6).unwrap();
    }
    let schedule = *inputs.schedule.get().unwrap();
    let mut switches = 0;
    let mut t = schedule.next_switch_after(s.time);
    while t < s.time + 1e-6 {
        switches += 1;
        t = schedule.next_switch_after(t);
    }
    SETTLES.with(|c| c.set(0));
    let report = m.step(&mut s, &inputs, 1e-6).unwrap();
    (report.substeps, switches, SETTLES.with(|c| c.get()))
}

/// The onion checked for its branch right after each switch, far from the new minimum, is not
/// settled there: its second step, over 795 switches, settles 46 times. Without the bound
/// each check settled it.
#[test]
fn branch_check_skips_the_settle_far_from_the_minimum() {
    let (substeps, switches, settles) = settles_in_a_step(ONE_SUBSTEP_A_SWITCH, 1);
    println!("{substeps} substeps, {switches} switches, {settles} settles");
    assert!(switches > 700, "{switches}");
    assert!(
        10 * settles <= switches as u64,
        "{settles} settles, {switches} switches"
    );
}

/// The onion following its branch after the budget is spent is settled once at each switch by
/// the check that it heads for its minimum, which the branch then starts from, and once by the
/// rotor's drift: at most two settles a switch, where the branch's start settled it again
/// (three a switch).
#[test]
fn following_onion_settles_twice_a_switch() {
    let (substeps, switches, settles) = settles_in_a_step(FOLLOWING_A_FAST_SCHEDULE, 1);
    println!("{substeps} substeps, {switches} switches, {settles} settles");
    assert!(switches > 700, "{switches}");
    assert!(
        settles <= 2 * switches as u64 + 100,
        "{settles} settles, {switches} switches"
    );
}

/// [`Motor::settle_start_within`] against the settle itself, over both cases' landscapes, every
/// rotor angle, strain direction and onion angle on a grid and gaps from 1e-12 to 1 rad: where
/// it says the minimum is beyond the gap, the settle lands beyond it. It must also say so
/// often, or the check would be empty.
#[test]
fn settle_bound_never_misses_a_minimum_within_the_gap() {
    let mut farther = 0;
    let mut checked = 0;
    for text in [ONE_SUBSTEP_A_SWITCH, FOLLOWING_A_FAST_SCHEDULE] {
        let (m, _, inputs) = case(&values(text)).unwrap();
        let stress = m.drive_at(&inputs, 0.0).stress;
        for i in 0..24 {
            let rotor = -3.0 + 0.26 * f64::from(i);
            for j in 0..12 {
                let direction = 0.27 * f64::from(j);
                let d = Drive {
                    direction,
                    applied_direction: direction,
                    stress,
                    load: 0.0,
                    locked: false,
                };
                let land = m.landscape(rotor, direction, stress);
                for k in 0..60 {
                    let onion = rotor - 3.1 + 0.105 * f64::from(k);
                    let y = [rotor, 0.0, onion, 0.0];
                    let settled = land.settle(onion);
                    for e in 0..13 {
                        let gap = 10f64.powi(-e);
                        checked += 1;
                        if m.settle_start_within(&y, &d, gap, &Default::default())
                            .is_none()
                        {
                            farther += 1;
                            assert!(
                                (settled - onion).abs() > gap,
                                "rotor {rotor} strain {direction} onion {onion} gap {gap}: \
                                 settles {settled}"
                            );
                        }
                    }
                }
            }
        }
    }
    println!("{farther} of {checked} beyond the gap");
    assert!(2 * farther >= checked, "{farther} of {checked}");
}

/// The settles and landscape evaluations (gradient or curvature of eq. 3.4) that `f` makes.
fn counted<T>(f: impl FnOnce() -> T) -> (T, u64, u64) {
    SETTLES.with(|c| c.set(0));
    EVALUATIONS.with(|c| c.set(0));
    let out = f();
    (
        out,
        SETTLES.with(|c| c.get()),
        EVALUATIONS.with(|c| c.get()),
    )
}

/// A free rotor's relaxed onion (a thousandth of the tolerance off its minimum, untilted) joins
/// its branch after one settle: the relaxed check's, whose slope at the start is the bound's,
/// whose minimum the check that the onion heads for it reuses with its curvature, and which
/// the branch starts from (the constrain has nothing left to do). The landscape is evaluated
/// exactly as often as by that settle alone plus the curvature at its minimum, with or without
/// the averaged ringing's check; the onion lands on that settle's minimum, bit for bit.
#[test]
fn relaxed_onion_joins_its_branch_after_one_settle() {
    let (m, s, inputs) = case(&values(ONE_SUBSTEP_A_SWITCH)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(s.rotor_angle, d.direction, d.stress);
    let onion = land.settle(s.onion_angle) + 1e-3 * m.params.tolerance;
    let state = MotorState {
        onion_angle: onion,
        onion_tilt: 0.0,
        ..s
    };
    let (minimum, _, alone) = counted(|| {
        let a = land.settle_from(land.angles(onion));
        land.curvature(a.onion);
        a
    });
    for average_check_at in [0, u32::MAX] {
        let mut run = StepRun::new(&state, 1e-6);
        run.average_check_at = average_check_at;
        let segment_end = run.t_end;
        let (follows, settles, evaluations) =
            counted(|| m.follows_branch(&mut run, &d, segment_end));
        assert!(follows, "averaged check at {average_check_at}");
        assert_eq!(settles, 1, "averaged check at {average_check_at}");
        assert_eq!(evaluations, alone, "averaged check at {average_check_at}");
        assert!(run.is_settled(&d));
        assert_eq!(run.y[2].to_bits(), minimum.onion.to_bits());
    }
}
