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

/// The angles a constrain turns from ([`super::settle_memo::SettleMemo::fresh_hint`]): the kept fresh
/// ones only where turning from its own hint would compute them afresh (no hint, a far move, a
/// hint turned too often), and then the same angles bit for bit as [`super::Angles::exact`];
/// a near hint is kept (its turn differs from the fresh angles in the last bits).
#[test]
fn constrain_turns_from_kept_fresh_angles_only_where_it_would_compute_them() {
    use super::settle_memo::SettleMemo;
    use super::{Angles, Drive};
    let bits =
        |a: &Angles| [a.sin_offset, a.cos_offset, a.sin_double, a.cos_double].map(f64::to_bits);
    let d = Drive {
        direction: 2.1,
        applied_direction: 2.1,
        stress: 1e6,
        load: 0.0,
        locked: false,
    };
    let y = [0.3, 0.0, 1.7, 0.0];
    let memo = SettleMemo::default();
    // Nothing kept yet: every hint stays.
    assert_eq!(memo.fresh_hint(None, &y, &d), None);
    let fresh = memo.fresh_angles(&y, &d);
    assert_eq!(bits(&fresh), bits(&Angles::exact(y[2], y[0], d.direction)));
    let near = Angles::exact(y[2] - 0.01, y[0], d.direction);
    let far = Angles::exact(y[2], y[0], d.direction - 1.0);
    let mut worn = near;
    // Turned as often as allowed (each move nonzero).
    for k in 1..=32 {
        worn = worn.at_onion(y[2] - 0.01 + 1e-4 * f64::from(k % 2));
    }
    assert!(!near.moves_afresh(y[2], y[0], d.direction));
    assert!(worn.moves_afresh(y[2], y[0], d.direction));
    let mut kept = 0;
    for hint in [None, Some(near), Some(far), Some(worn)] {
        let fresh_hint = memo.fresh_hint(hint.as_ref(), &y, &d);
        let chosen = fresh_hint.or(hint);
        let plain = match hint {
            Some(h) => h.moved(y[2], y[0], d.direction),
            None => Angles::exact(y[2], y[0], d.direction),
        };
        let turned = chosen.map_or(plain, |h| h.moved(y[2], y[0], d.direction));
        assert_eq!(bits(&turned), bits(&plain), "{hint:?}");
        if chosen.is_some_and(|c| bits(&c) == bits(&fresh)) && chosen != hint {
            kept += 1;
        }
    }
    // No hint, the far one and the one turned too often take the kept angles; the near one not.
    assert_eq!(kept, 3);
    assert_ne!(bits(&near.moved(y[2], y[0], d.direction)), bits(&fresh));
    // Another state (one bit off) is not theirs.
    let other = [y[0], 0.0, y[2].next_up(), 0.0];
    assert_eq!(memo.fresh_hint(None, &other, &d), None);
}
