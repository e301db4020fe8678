//! The Gilbert onion's branch checks in one pass settle its state once ([`super::settle_memo`]).

use super::onion::SETTLES;
use super::onion_periods_tests::{case, values};
use super::ringing_drop_tests::C370371;
use super::step::StepRun;
use super::MotorState;

/// A free rotor's onion 0.05 rad off its minimum once the step is accuracy-limited: the budget's
/// drop settles it to see whether it heads for that minimum within the step (it does not, the
/// step being a thousandth of its relaxation), and the drop of decoupled ringing looks for the
/// well of that minimum (whose rims its own settles find). The two share one march of the
/// onion's state, whose minimum each would reach alone, bit for bit: the pass settles once plus
/// the rims' settles.
#[test]
fn branch_checks_of_a_pass_settle_once() {
    let (m, s, inputs) = case(&values(C370371)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let land = m.landscape(s.rotor_angle, d.direction, d.stress);
    let state = MotorState {
        onion_angle: s.onion_angle + 0.05,
        onion_tilt: 0.0,
        ..s
    };
    let alone = land.settle(state.onion_angle);
    SETTLES.with(|c| c.set(0));
    assert!(m.well_of_minimum(&land, alone).is_some());
    let rims = SETTLES.with(|c| c.get());
    let h = 1e-3 * m.onion_relaxation_time();
    let mut run = StepRun::new(&state, h);
    run.limited = true;
    assert!(m.onion_relaxes_fast());
    SETTLES.with(|c| c.set(0));
    let end = run.t_end;
    let follows = m.follows_branch(&mut run, &d, end);
    let settles = SETTLES.with(|c| c.get());
    println!("follows {follows}, {settles} settles, {rims} of the rims");
    assert!(follows, "the decoupled ringing is dropped");
    assert_eq!(settles, 1 + rims);
    let y = [state.rotor_angle, state.rotor_speed, state.onion_angle, 0.0];
    let kept = run.settle_memo.kept(&y, &d).unwrap();
    assert_eq!(kept.onion.to_bits(), alone.to_bits());
    assert!(m.heads_for_settled(&y, &d, h, &run.settle_memo).is_none());
}
