//! A free rotor's Gilbert onion whose soft tilt carries it out of the small-tilt model's bounds
//! ([`Motor::onion_leaves_bounds`]) against a plain RK4 of the motor's ODE.

use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4_span;

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
    let (m, start, inputs) = case(&values(SOFT_TILT)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let span = 1e-6;
    let tol = m.params.tolerance;
    let y0 = [
        start.rotor_angle,
        start.rotor_speed,
        start.onion_angle,
        start.onion_tilt,
    ];
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
