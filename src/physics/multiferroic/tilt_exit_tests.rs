//! A Gilbert onion whose soft tilt carries it out of the small-tilt model's bounds
//! ([`Motor::onion_leaves_bounds`]) against a plain RK4 of the motor's ODE.

use super::resolved_tests::{rk4_span, start_of};

/// A benchmark draw (the FMU's variables, full precision): the onion released 3.5e-4 rad from
/// the rim of its well at damping 1.5e-3, its tilt stiffness 4.5e-7 of the well's curvature, so
/// that its tilt passes 10 rad within a nanosecond on the way down; a viscous rotor the ring
/// cannot move.
const SOFT_TILT: &str = "strain_direction=-6.483190734194401e10 stress=9.148885507370604e0 \
     load_torque=-6.342054017010341e-7 ring_outer_diameter=2.0281253430826043e-1 \
     ring_inner_diameter=1.7195931123115504e-3 bar_length=1.150141068029748e-3 \
     bar_width=6.113191440904359e-4 thickness=3.698911349472927e-7 \
     saturation_magnetization=7.7871787197482565e0 magnetostriction=-3.4189069378967865e-3 \
     wall_volume=7.426380858789462e-11 density=6.425791927605693e3 \
     fluid_viscosity=9.143718105092719e2 gilbert_damping=1.5210967274062103e-3 \
     tolerance=6.440101616138383e-4 step_angle=2.0503166252534655e-1 \
     step_period=1.307531994262347e5 stress_amplitude=1.6514136978115024e4 \
     schedule_initial_direction=-9.218490099193359e-5 onion_model=1e0 max_substeps=1.174e3 \
     schedule=1e0 rotor_locked=0e0 initial_onion_offset=3.4581529992023835e-4 \
     strain=-2.4815865899201178e-2 youngs_modulus=3.8128205157885116e8 strain_drive=1e0";

/// The onion leaves its bounds in fact (a plain RK4 of the ODE, converged by halving its step,
/// carries its tilt past 10 rad within the step), the step is flagged, and the onion is dropped
/// into the minimum of the well in which the RK4's onion crosses the bound, the rotor where the
/// RK4 puts it. Found at the substep that carries the onion out, the step takes 10 substeps;
/// shrinking the substeps towards the bound until the budget's smallest is forced takes 77.
#[test]
fn onion_leaving_its_bounds_is_dropped_at_the_substep_that_carries_it_out() {
    let (m, start, inputs, d, y0) = start_of(SOFT_TILT);
    let span = 1e-6;
    let tol = m.params.tolerance;
    // The onion's angle where its tilt first passes 10 rad, and the rotor at the step's end.
    let truth = |h: f64| {
        let steps = (span / h).round() as usize;
        let mut y = y0;
        let mut crossing = None;
        for _ in 0..steps {
            y = rk4_span(&m, &d, y, h, 1);
            if crossing.is_none() && y[3].abs() > 10.0 {
                crossing = Some(y[2]);
            }
        }
        (crossing, y[0])
    };
    let (coarse, fine) = (truth(2e-12), truth(1e-12));
    let (Some(psi), Some(psi_fine)) = (coarse.0, fine.0) else {
        panic!("the RK4's onion stays within its bounds: {coarse:?} {fine:?}");
    };
    assert!((psi - psi_fine).abs() <= 0.01 && (coarse.1 - fine.1).abs() <= 0.01 * tol);
    let mut st = start;
    let report = m.step(&mut st, &inputs, span).unwrap();
    println!(
        "{report:?} {st:?} against crossing at {psi_fine}, rotor {}",
        fine.1
    );
    assert!(report.accuracy_limited);
    assert!(report.substeps <= 16, "{} substeps", report.substeps);
    let land = m.landscape(st.rotor_angle, d.direction, d.stress);
    assert!(
        (land.settle(psi_fine) - st.onion_angle).abs() <= tol,
        "{st:?}"
    );
    assert!((st.rotor_angle - fine.1).abs() <= tol, "{st:?}");
    assert_eq!(st.onion_tilt, 0.0);
}

/// A locked rotor's onion released 1.9e-11 rad from its minimum under a strain that holds it
/// 1.55 rad away, at damping 1.75e-3 and a tolerance of 0.021 rad: its soft tilt carries it past
/// 10 rad 11 ps into the step (73 rad at most), and the ringing dies out within the step.
const LOCKED_SOFT_TILT: &str = "strain_direction=1.998e-2 stress=2.826e-1 load_torque=-6.071e-7 \
     ring_outer_diameter=1.780e-1 ring_inner_diameter=1.087e-3 bar_length=5.789e-4 \
     bar_width=2.674e-7 thickness=6.384e-8 saturation_magnetization=1.241e4 \
     magnetostriction=4.181e-3 wall_volume=1.130e-11 density=1.847e4 fluid_viscosity=1.222e6 \
     gilbert_damping=1.751e-3 tolerance=2.093e-2 step_angle=2.419e0 step_period=4.403e4 \
     stress_amplitude=-1.897e-3 schedule_initial_direction=3.677e-7 onion_model=1 \
     max_substeps=8.773e3 rotor_locked=1 initial_onion_offset=1.852e-11 strain=-8.634e-2 \
     youngs_modulus=1.036e9 strain_drive=1";

/// Under a locked rotor too, the onion that leaves its bounds in fact (a plain RK4 of the ODE,
/// converged by halving its step, carries its tilt past 10 rad) is found at the substep that
/// carries it out: the step is flagged and ends where the RK4 does (its ringing decays within
/// the step into the minimum of the well it crosses the bound in), in the same state, bit for
/// bit, as where the budget's smallest substep lets it escape, with 6 substeps instead of 79.
#[test]
fn locked_onion_leaving_its_bounds_is_dropped_at_the_substep_that_carries_it_out() {
    let (m, start, inputs, d, y0) = start_of(LOCKED_SOFT_TILT);
    assert!(inputs.rotor_locked);
    let span = 1e-6;
    let tol = m.params.tolerance;
    let truth = |h: f64| {
        let mut y = y0;
        let mut crossed = false;
        for _ in 0..(span / h).round() as usize {
            y = rk4_span(&m, &d, y, h, 1);
            crossed |= y[3].abs() > 10.0;
        }
        (crossed, y)
    };
    let ((crossed, coarse), (crossed_fine, fine)) = (truth(2e-12), truth(1e-12));
    assert!(
        crossed && crossed_fine,
        "the RK4's onion stays within its bounds"
    );
    assert!((coarse[2] - fine[2]).abs() <= 0.01 * tol && (coarse[3] - fine[3]).abs() <= 0.01 * tol);
    let step = |exit_off: bool| {
        super::tilt_exit::LOCKED_EXIT_OFF.with(|c| c.set(exit_off));
        let mut st = start;
        let report = m.step(&mut st, &inputs, span).unwrap();
        super::tilt_exit::LOCKED_EXIT_OFF.with(|c| c.set(false));
        (report, st)
    };
    let ((report, st), (crept, st_crept)) = (step(false), step(true));
    println!(
        "{} substeps ({} creeping to the smallest), {st:?} against the RK4's {fine:?}",
        report.substeps, crept.substeps
    );
    assert!(report.accuracy_limited && crept.accuracy_limited);
    assert!(report.substeps <= 16, "{} substeps", report.substeps);
    assert!((st.onion_angle - fine[2]).abs() <= tol, "{st:?}");
    assert!((st.onion_tilt - fine[3]).abs() <= tol, "{st:?}");
    assert_eq!(st.onion_angle.to_bits(), st_crept.onion_angle.to_bits());
    assert_eq!(st.onion_tilt.to_bits(), st_crept.onion_tilt.to_bits());
    assert_eq!((st.rotor_angle, st.rotor_speed), (0.0, 0.0));
}

/// A locked rotor's onion ringing with a tilt of up to 8.6 rad (a plain RK4 of the ODE) at
/// damping 4.2e-4 and a loose tolerance, 0.11 rad: substeps within that tolerance carry their
/// onion past the 10 rad bound, and the step is flagged. Resolved as if within its bounds, the
/// step ended unflagged with the onion 8.7 and its tilt 55 tolerances off the RK4.
const LOCKED_LOOSE_RINGING: &str = "strain_direction=2.222e3 stress=-3.872e8 \
     load_torque=3.458e-7 ring_outer_diameter=8.923e-1 ring_inner_diameter=1.596e-3 \
     bar_length=4.268e-4 bar_width=1.041e-6 thickness=5.428e-7 saturation_magnetization=1.349e1 \
     magnetostriction=6.793e-3 wall_volume=4.223e-11 density=1.226e4 fluid_viscosity=1.577e-4 \
     gilbert_damping=4.240e-4 tolerance=1.129e-1 step_angle=-5.542e0 step_period=4.124e2 \
     stress_amplitude=-2.784e0 schedule_initial_direction=-1.984e1 onion_model=1 \
     max_substeps=5.451e3 schedule=1 rotor_locked=1 initial_onion_offset=3.162e-5 \
     strain=3.806e-2 youngs_modulus=7.958e7";

/// An unflagged step ends within the tolerance of a converged plain RK4 of the ODE.
#[test]
fn locked_loose_ringing_is_flagged_or_within_the_tolerance() {
    let (m, start, inputs, d, y0) = start_of(LOCKED_LOOSE_RINGING);
    let span = 1e-6;
    let tol = m.params.tolerance;
    let truth = |h: f64| rk4_span(&m, &d, y0, span, (span / h).round() as usize);
    let (coarse, fine) = (truth(2e-12), truth(1e-12));
    assert!((coarse[2] - fine[2]).abs() <= 0.01 * tol && (coarse[3] - fine[3]).abs() <= 0.01 * tol);
    let mut st = start;
    let report = m.step(&mut st, &inputs, span).unwrap();
    let off = [
        (st.onion_angle - fine[2]).abs() / tol,
        (st.onion_tilt - fine[3]).abs() / tol,
    ];
    println!("{report:?} {st:?} against the RK4's {fine:?}: {off:?} tolerances off");
    assert!(report.accuracy_limited || off.iter().all(|e| *e <= 1.0));
}
