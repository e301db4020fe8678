//! The orbit-averaged ringing ([`Motor::advance_orbits`]) against a fine RK4 of the full
//! macrospin and rotor.

use super::orbit::{point, turning_point};
use super::step::StepRun;
use super::tests::{motor_with, rk4_step, schedule};
use super::{Drive, Motor, MotorInputs, MotorState, OnionModel, Vector};

/// Fine RK4 of the full macrospin and rotor from `y0` over `span` (a fiftieth of the onion's
/// fastest rate per step).
pub(super) fn resolved(m: &Motor, d: &Drive, y0: Vector, span: f64) -> Vector {
    let (_, j) = m.rhs_jacobian(&y0, d, 1e-12);
    let norm = (2..4)
        .map(|i| (2..4).map(|k| j[i][k].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let n = (span * norm / 0.02).ceil() as usize;
    let h = span / n as f64;
    let rate = |z: &Vector| m.rhs_jacobian(z, d, h).0;
    let mut y = (0..n).fold(y0, |z, _| rk4_step(&rate, &z, h));
    if d.locked {
        y[1] = 0.0;
    }
    y
}

fn gilbert(alpha: f64) -> Motor {
    motor_with(|p| {
        p.onion_model = OnionModel::Gilbert;
        p.gilbert_damping = alpha;
    })
}

/// Table 3.1's onion rings after the schedule's first switch (released from its settled state,
/// 0.3 of its well's lowest rim above the new minimum) or is entered mid-orbit (at the minimum,
/// either tilt): the orbit-averaged advance over 1 us or 300 ns against a fine RK4 of the full
/// macrospin and rotor, free, locked, and in a fluid 1e4 times as viscous as water (the rotor
/// overdamped). The averaged path is taken (its steps counted, at most 162, against the ~1e5
/// substeps of the resolved ringing) and ends at the last lower turning point (or where the
/// ringing is within the relaxed onion's slack, or, locked, where it ends the segment within the
/// tolerance of its minimum, as the resolved onion then does); the rotor ends within a tenth of the
/// tolerance (2.1e-8 rad at most, where the ringing moves it by 5.5e-4 rad at damping 1e-4) and its
/// speed within the tolerance on its scale; the onion's angle within 4.1e-8 rad and its tilt within
/// 3.4e-7 rad. At damping 1e-2 the energy drops by a third per orbit: the averaged path is not
/// taken.
#[test]
fn orbit_averaged_ringing_matches_a_fine_rk4_of_the_full_system() {
    for (alpha, entry, locked, span, viscosity) in [
        (1e-4, 0.0, false, 1e-6, 1e-3),
        (1e-4, 0.0, true, 1e-6, 1e-3),
        (1e-3, 0.0, false, 1e-6, 1e-3),
        (1e-3, 0.0, true, 1e-6, 1e-3),
        (1e-4, 1.0, false, 1e-6, 1e-3),
        (1e-3, -1.0, false, 3e-7, 1e-3),
        (3e-4, 0.5, true, 3e-7, 1e-3),
        (1e-2, 0.0, false, 1e-6, 1e-3),
        // An overdamped rotor (its speed relaxes in 2.2e-13 s, against 2.9e-10 s orbits).
        (1e-4, 0.0, false, 1e-6, 10.0),
        (1e-3, 1.0, false, 1e-6, 10.0),
    ] {
        let m = motor_with(|p| {
            p.onion_model = OnionModel::Gilbert;
            p.gilbert_damping = alpha;
            p.fluid_viscosity = viscosity;
        });
        let inputs = MotorInputs {
            rotor_locked: locked,
            ..schedule(20e-6)
        };
        let d = m.drive_at(&inputs, 0.0);
        let mut y0: Vector = [0.0; 4];
        if entry != 0.0 {
            // The same orbit entered at the minimum.
            let land = m.landscape(0.0, d.direction, d.stress);
            let min = land.settle(0.0);
            let e = point(&land, 0.0).0 - point(&land, min).0;
            y0 = [0.0, 0.0, min, entry * (2.0 * e / m.tilt_stiffness).sqrt()];
        }
        let state = MotorState {
            rotor_angle: y0[0],
            rotor_speed: y0[1],
            onion_angle: y0[2],
            onion_tilt: y0[3],
            ..MotorState::aligned(0.0)
        };
        let mut run = StepRun::new(&state, span);
        let taken = m.advance_orbits(&mut run, &d, span);
        if alpha >= 1e-2 {
            assert!(taken.is_none(), "{alpha}: {taken:?}");
            continue;
        }
        let taken = taken.expect("trapped weakly damped ringing averages");
        let truth = resolved(&m, &d, y0, run.t);
        let tol = m.params.tolerance;
        let error: Vec<f64> = (0..4).map(|i| (run.y[i] - truth[i]).abs()).collect();
        println!(
            "damping {alpha}, entry {entry}, locked {locked}, viscosity {viscosity}: {taken:?} to {:e} s: error {error:?} (rotor {})",
            run.t, truth[0]
        );
        assert!(taken.steps <= 400, "{alpha}: {taken:?}");
        // At the last lower turning point before the span's end (an orbit is 0.29 ns), or
        // earlier where the ringing has become narrower than the relaxed onion's slack (or,
        // locked, ends the segment within the tolerance).
        assert!(span - run.t < 0.3e-9 || alpha > 1e-4, "{alpha}: {}", run.t);
        assert!(
            error[0] <= 0.1 * tol,
            "{alpha} {entry} {locked}: rotor {error:?}"
        );
        assert!(
            error[1] <= tol * m.speed_scale,
            "{alpha} {entry} {locked}: {error:?}"
        );
        if span - run.t > 1e-9 && locked {
            // A locked onion is handed over where its ringing ends the segment within the
            // tolerance of its minimum (the branch then drops it): so does the resolved one.
            let end = resolved(&m, &d, y0, span);
            let minimum = m.landscape(end[0], d.direction, d.stress).settle(end[2]);
            assert!(
                (end[2] - minimum).abs() <= tol,
                "{alpha} {entry}: {end:?} {minimum}"
            );
            continue;
        }
        if span - run.t > 1e-9 {
            // Ended where the ringing is within the slack, which the branch then drops at
            // whatever phase it has: the resolved onion is within the slack of its minimum and
            // the averaged one on the same orbit, to the tolerance.
            let slack = m.relaxed_slack(locked);
            let minimum = m
                .landscape(truth[0], d.direction, d.stress)
                .settle(truth[2]);
            assert!(
                (truth[2] - minimum).abs() <= 2.0 * slack,
                "{alpha} {entry} {locked}: {truth:?} {minimum}"
            );
            assert!(
                error[2] <= 4.0 * slack + tol,
                "{alpha} {entry} {locked}: onion {error:?}"
            );
            continue;
        }
        assert!(error[2] <= tol, "{alpha} {entry} {locked}: onion {error:?}");
        assert!(error[3] <= tol, "{alpha} {entry} {locked}: tilt {error:?}");
    }
}

/// The averaged path is not taken near the rim of the well: an onion released from rest at
/// 0.95 of its well's lowest rim above the minimum (it would take it at 0.85); nor on a segment
/// shorter than a few orbits.
#[test]
fn orbit_averaging_is_not_taken_near_the_rim() {
    let m = gilbert(1e-4);
    let d = m.drive_at(&schedule(20e-6), 0.0);
    let land = m.landscape(0.0, d.direction, d.stress);
    let well = m.onion_well(&land, 0.0).unwrap();
    for (fraction, span, taken) in [(0.95, 1e-6, false), (0.85, 1e-6, true), (0.3, 1e-9, false)] {
        // The point below the minimum at that height.
        let (mut lo, mut hi) = (well.below, well.minimum);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if point(&land, mid).0 - well.floor > fraction * well.barrier {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let state = MotorState {
            onion_angle: hi,
            ..MotorState::aligned(0.0)
        };
        let mut run = StepRun::new(&state, span);
        let advance = m.advance_orbits(&mut run, &d, span);
        println!("{fraction} of the rim, {span} s: {advance:?}");
        assert_eq!(advance.is_some(), taken, "{fraction} {span}: {advance:?}");
    }
}

/// Table 3.1's motor on the stepping schedule (20 us periods) at the FMU's 1 us step with the
/// default budget, at dampings 1e-4 and 1e-3, where the ringing after a switch outlasts the
/// budget of resolved substeps (which then dropped it and flagged the step, 3 steps of 60): no
/// step is accuracy-limited (no fmi2Warning), every step takes at most 1000 substeps (the
/// averaged ringing's steps counted: 167 and 586; resolving the ringing takes 186,471 and
/// 18,877), and the rotor stays within the tolerance of a run that resolves the ringing (a
/// thousandth of the tolerance, whose rotor-angle oscillation bound `Q~ / I` keeps it off the
/// averaged path, and an unbounded budget) at every step (3.9e-7 and 2.3e-7 rad).
#[test]
fn weakly_damped_gilbert_onion_averages_its_ringing_at_one_microsecond() {
    for alpha in [1e-4, 1e-3] {
        let m = gilbert(alpha);
        let fine = motor_with(|p| {
            p.onion_model = OnionModel::Gilbert;
            p.gilbert_damping = alpha;
            p.tolerance = 1e-9;
            p.max_substeps = 10_000_000;
        });
        let inputs = schedule(20e-6);
        let (mut s, mut r) = (MotorState::aligned(0.0), MotorState::aligned(0.0));
        let (mut worst, mut most, mut fine_most) = (0.0f64, 0, 0);
        for _ in 0..60 {
            let report = m.step(&mut s, &inputs, 1e-6).unwrap();
            assert!(!report.accuracy_limited, "{alpha}: t = {}", s.time);
            most = most.max(report.substeps);
            let fine_report = fine.step(&mut r, &inputs, 1e-6).unwrap();
            fine_most = fine_most.max(fine_report.substeps);
            worst = worst.max((s.rotor_angle - r.rotor_angle).abs());
        }
        println!(
            "damping {alpha}: rotor {} rad against {} rad, worst {worst:e} rad, at most {most} substeps a step (resolved {fine_most})",
            s.rotor_angle, r.rotor_angle
        );
        assert!(most <= 1000, "{alpha}: {most}");
        assert!(fine_most > 10 * most, "{alpha}: {fine_most}");
        assert!(worst < m.params.tolerance, "{alpha}: {worst}");
        assert!(s.rotor_angle > 2.5, "{alpha}: {s:?}");
    }
}

/// Table 3.1's motor at the FMU's 1 us step with its onion released from rest at 0.9 of its
/// well's lowest rim above the minimum after the schedule's first switch, free and locked, at
/// dampings 1e-4 to 0.3 (the ringing decays in 190 ns to 0.07 ns): the step against a fine RK4
/// of the full macrospin and rotor. It is not accuracy-limited; a free rotor ends within the
/// tolerance; the onion ends within the tolerance of the resolved one plus the amplitude of
/// what is left of its ringing (which the branch drops, reporting its centre). The substeps
/// are counted (the averaged advance's steps and the relaxed onion's settles included): at
/// damping 1e-3 the free onion's ringing that decays within the step is averaged without its
/// phase (58 substeps, where resolving it took 616), and the locked onion's is dropped at once
/// (1 substep), as from 0.03 up, since its energy's guaranteed decay ends it within the step; at
/// 1e-2 that happens once the ringing has decayed far enough (318, against 575). The free
/// onion's ringing is resolved by the explicit pair until the relaxed onion takes over: 703,
/// 245, 80 and 45 substeps at 1e-2, 0.03, 0.1 and 0.3.
#[test]
fn ringing_after_a_release_keeps_to_a_fine_rk4_over_a_step() {
    for alpha in [1e-4, 1e-3, 1e-2, 0.03, 0.1, 0.3] {
        for locked in [false, true] {
            let m = gilbert(alpha);
            let inputs = MotorInputs {
                rotor_locked: locked,
                ..schedule(20e-6)
            };
            let d = m.drive_at(&inputs, 0.0);
            let land = m.landscape(0.0, d.direction, d.stress);
            let well = m.onion_well(&land, 0.0).unwrap();
            let (mut lo, mut hi) = (well.below, well.minimum);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if point(&land, mid).0 - well.floor > 0.9 * well.barrier {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let span = 1e-6;
            let mut s = MotorState {
                onion_angle: hi,
                ..MotorState::aligned(0.0)
            };
            let report = m.step(&mut s, &inputs, span).unwrap();
            let truth = resolved(&m, &d, [0.0, 0.0, hi, 0.0], span);
            let tol = m.params.tolerance;
            // What is left of the resolved ringing: its energy above the minimum bounds it.
            let end = m.landscape(truth[0], d.direction, d.stress);
            let minimum = end.settle(truth[2]);
            let excess = point(&end, truth[2]).0 - point(&end, minimum).0
                + 0.5 * m.tilt_stiffness * truth[3] * truth[3];
            let ringing = (2.4 * excess.max(0.0) / end.curvature(minimum)).sqrt();
            let (rotor, onion) = (
                (s.rotor_angle - truth[0]).abs(),
                (s.onion_angle - truth[2]).abs(),
            );
            println!(
                "damping {alpha}, locked {locked}: {} substeps, limited {}: rotor {:e} ({rotor:e}), onion {} ({onion:e}), ringing left {ringing:e}",
                report.substeps, report.accuracy_limited, truth[0], truth[2]
            );
            assert!(!report.accuracy_limited, "{alpha} {locked}");
            let most = match (alpha, locked) {
                (1e-3, false) => 70,
                (1e-2, true) => 400,
                (1e-2, false) => 800,
                (0.03, false) => 280,
                (0.1, false) => 90,
                (0.3, false) => 50,
                (_, true) if alpha == 1e-3 || alpha >= 0.03 => 1,
                _ => u32::MAX,
            };
            assert!(
                report.substeps <= most,
                "{alpha} {locked}: {}",
                report.substeps
            );
            assert!(rotor <= tol, "{alpha} {locked}: rotor {rotor:e}");
            assert!(
                onion <= tol + 1.01 * ringing,
                "{alpha} {locked}: onion {onion:e}, ringing {ringing:e}"
            );
        }
    }
}

/// The turning points of ever smaller orbits about a well's minimum (Table 3.1's ring and bar,
/// energies from 1e-2 down to 1e-11 of the lowest rim, the search started at the minimum): each
/// within 1e-4 of its distance from the minimum of a plain bisection on the level, in at most 64
/// of the landscape's evaluations. From 1e-9 of the rim down, the energy's rounding over the
/// small gradient there moves Newton's step beyond its stopping size everywhere; the search ran
/// on to its cap of 100 (0.86 of the landscape's evaluations in a locked onion's averaged
/// ringing's turning points).
#[test]
fn turning_points_of_small_orbits_stop_where_the_bracket_does() {
    let m = gilbert(1e-4);
    let land = m.landscape(0.0, 1.2, 4e7);
    let well = m.onion_well(&land, 0.3).expect("a well");
    let level = |x: f64, e: f64| point(&land, x).0 - well.floor - e;
    let mut capped = 0;
    for k in 2..=11 {
        let e = well.barrier * 10f64.powi(-k);
        for rim in [well.below, well.above] {
            let (x, n) = turning_point(&land, well.floor, e, well.minimum, rim, well.minimum)
                .expect("a turning point");
            let (mut inside, mut outside) = (well.minimum, rim);
            for _ in 0..200 {
                let mid = 0.5 * (inside + outside);
                if level(mid, e) < 0.0 {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            let reach = (x - well.minimum).abs();
            assert!(
                (x - inside).abs() <= 1e-4 * reach,
                "{e:e}: {x} against {inside}"
            );
            capped += usize::from(n > 64);
        }
    }
    assert_eq!(capped, 0);
}
