//! A free rotor's decoupled Gilbert onion over whole segments
//! ([`Motor::advance_decoupled_segment`]) against an onion-only RK4 with the rotor on its exact
//! drift.

use super::decoupled_segment::{LOG, TAKEN};
use super::onion_linear_tests::{converged, drifted, SWINGING_FAST, SWINGING_SLOW_DECAY};
use super::onion_periods_tests::{case, values};
use super::*;

/// An overdamped onion (its tilt 2e4 times stiffer than eq. 3.4's curvature) slipping behind a
/// strain that a 2.24 ns schedule turns faster than it can follow, at a tolerance of 0.56 rad
/// (a benchmark draw, full precision).
const SLIPPING: &str = "strain_direction=4.5059466230394336e5 stress=9.84935167724793e-3 load_torque=9.735252176210894e-8 ring_outer_diameter=9.646425416221389e-1 ring_inner_diameter=3.520139674271862e-1 bar_length=1.5971770250015274e-1 bar_width=2.0874873905760543e-7 thickness=2.162366405402761e-9 saturation_magnetization=9.225907667555375e5 magnetostriction=-9.392607423701453e-4 wall_volume=2.5423423893863373e-11 density=7.404904357184041e3 fluid_viscosity=5.379477647136184e0 gilbert_damping=8.180130053052166e-2 tolerance=5.566669196623509e-1 step_angle=-9.251264299878647e0 step_period=2.2411946956575363e-9 stress_amplitude=-1.7243658723112974e4 schedule_initial_direction=1.6614134442543017e-7 onion_model=1e0 max_substeps=7.916e3 schedule=1e0 rotor_locked=0e0 initial_onion_offset=-7.885761944492388e0 strain=6.774645300132973e-2 youngs_modulus=5.7842162650969446e7 strain_drive=0e0";

fn taken() -> u32 {
    TAKEN.with(|c| c.get())
}

/// Three 1 us steps of a case: every segment taken within the tolerance of the RK4 from its
/// start (the local error the tolerance bounds), at least `least` segments a step, and, where
/// `bound` is given, each step unflagged and its end within `bound` tolerances of the RK4 from
/// the step's start.
fn segments_match_rk4(text: &str, least: u32, bound: Option<f64>) {
    let (m, mut st, inputs) = case(&values(text)).unwrap();
    let tol = m.params.tolerance;
    for _ in 0..3 {
        let start = st;
        let before = taken();
        LOG.with(|l| l.borrow_mut().clear());
        let r = m.step(&mut st, &inputs, 1e-6).unwrap();
        assert!(bound.is_none() || !r.accuracy_limited);
        assert!(taken() - before >= least, "{} segments", taken() - before);
        for (y, t0, t1, u) in LOG.with(|l| l.borrow_mut().split_off(0)) {
            let from = MotorState {
                time: t0,
                rotor_angle: y[0],
                rotor_speed: y[1],
                onion_angle: y[2],
                onion_tilt: y[3],
                ..start
            };
            let truth = drifted(&m, &from, &inputs, t1, converged(&m, &from, &inputs, t1));
            let err = [
                (u[2] - truth.onion_angle).abs(),
                (u[3] - truth.onion_tilt).abs(),
                (u[0] - truth.rotor_angle).abs(),
            ];
            assert!(err.iter().all(|&x| x <= tol), "{err:?} against {tol:e}");
        }
        if let Some(bound) = bound {
            let truth = drifted(
                &m,
                &start,
                &inputs,
                st.time,
                converged(&m, &start, &inputs, st.time),
            );
            let err = [
                (st.onion_angle - truth.onion_angle).abs(),
                (st.onion_tilt - truth.onion_tilt).abs(),
                (st.rotor_angle - truth.rotor_angle).abs(),
            ];
            assert!(
                err.iter().all(|&x| x <= bound * tol),
                "{err:?} against {tol:e}"
            );
        }
    }
}

/// Each of the 446 switches of a step was a full substep after a check of the onion's
/// relaxation (five budget units, 0.45 ms a step); the step ends 1e-4 tolerances off the RK4.
#[test]
fn a_slipping_overdamped_onion_takes_its_segments_at_once() {
    segments_match_rk4(SLIPPING, 440, Some(0.01));
}

/// A weakly damped onion (`alpha` 7.2e-3) that the strain turns past every 2.37 ns.
#[test]
fn a_ringing_onion_takes_its_segments_at_once() {
    segments_match_rk4(SWINGING_SLOW_DECAY, 400, Some(1.0));
}

/// A rotor spinning at 8.4e8 rad/s under its load (1.7 rad a period) with a heavily damped
/// onion: the segments taken between its averaged spins each within the tolerance, the rotor on
/// its drift among them (its steps are flagged by the spins).
#[test]
fn segments_of_a_spinning_rotor_follow_its_drift() {
    segments_match_rk4(SWINGING_FAST, 30, None);
}
