//! A budget-bound free rotor that the ring cannot move: its Gilbert onion's ringing, trapped in
//! its well, is dropped into the well's minimum once forced substeps are all that is left.

use super::decoupled_tests::driven_rk4;
use super::onion_periods_tests::{case, values};
use super::orbit::point;
use super::ringing::Rims;

/// A benchmark case: a load-driven rotor (inertial time 1.6e-19 s) at 2.1e8 rad/s whose ring's
/// torque (below 1.3e-31 N m) cannot move it, its onion (damping 2.9e-4, relaxation 15 us)
/// released 1e-5 rad past a rim of eq. 3.4's well: it rings at 0.9 to 1 of the rim through the
/// 1 us step, which its budget of 4008 cannot resolve at a tolerance of 4.6e-10 rad.
const RIM_RINGING: &str = "strain_direction=-2.1478444320800782e-1 stress=1.494672102948667e5 \
    load_torque=6.76477542741344e-7 ring_outer_diameter=2.535981365092965e-1 \
    ring_inner_diameter=4.074077288254449e-7 bar_length=3.919199457203557e-7 \
    bar_width=4.08183712394939e-9 thickness=1.2006636434075051e-9 \
    saturation_magnetization=2.098483915888461e3 magnetostriction=-9.793326336040362e-3 \
    wall_volume=5.7040183589091213e-11 density=2.1215001005328344e4 \
    fluid_viscosity=2.2728933188253743e5 gilbert_damping=2.9311561130911324e-4 \
    tolerance=4.646719407612572e-10 step_angle=6.0988194078027185e0 \
    step_period=1.3482140563259026e-4 stress_amplitude=6.499021081278089e1 \
    schedule_initial_direction=7.201706939976832e-9 onion_model=1 max_substeps=4008 schedule=1 \
    rotor_locked=0 initial_onion_offset=9.673988940251601e-6 strain=-8.106170389141597e-2 \
    youngs_modulus=1.948002627303002e6 strain_drive=1";

/// [`RIM_RINGING`]'s first step against the exact load-and-drag rotor and a converged RK4 of the
/// macrospin driven by it ([`driven_rk4`]): flagged, its rotor within a hundredth of the
/// tolerance, its onion in the resolved onion's well (at its minimum, the centre of the
/// ringing, 1.04 rad from the resolved onion's phase, within the well's reach). Once the
/// budget runs out the ringing is dropped there at once: 403 substeps, where the forced
/// substeps that followed it took 728.
#[test]
fn budget_bound_decoupled_onion_is_dropped_into_its_well() {
    let (m, start, inputs) = case(&values(RIM_RINGING)).unwrap();
    let h = 1e-6;
    let s = inputs.schedule.get().unwrap();
    assert!(s.next_switch_after(0.0) > h);
    let d = m.drive_at(&inputs, 0.0);
    let y0 = [start.rotor_angle, 0.0, start.onion_angle, start.onion_tilt];
    let (coarse, truth) = (driven_rk4(&m, &d, y0, h, 4), driven_rk4(&m, &d, y0, h, 8));
    let tol = m.params.tolerance;
    assert!(
        (coarse[2] - truth[2]).abs() <= 0.1 * tol && (coarse[0] - truth[0]).abs() <= 0.01 * tol,
        "{coarse:?} {truth:?}"
    );
    let mut st = start;
    let report = m.step(&mut st, &inputs, h).unwrap();
    let land = m.landscape(truth[0], d.direction, d.stress);
    let well = m.onion_well(&land, truth[2]).unwrap();
    // The resolved onion still rings in the well it started in, near its rims.
    let excess = point(&land, truth[2]).0 - well.floor + 0.5 * m.tilt_stiffness * truth[3].powi(2);
    println!(
        "{} substeps, flagged {}: onion {} against {truth:?}, well {:?}, ringing at {} of the rim",
        report.substeps,
        report.accuracy_limited,
        st.onion_angle,
        (well.below, well.minimum, well.above),
        excess / well.barrier
    );
    assert!(report.accuracy_limited);
    assert!(excess > 0.5 * well.barrier);
    assert!((st.rotor_angle - truth[0]).abs() <= 0.01 * tol);
    assert!(
        (st.onion_angle - well.minimum).abs() <= 1e-9,
        "onion {} off the resolved onion's well's minimum {}",
        st.onion_angle,
        well.minimum
    );
    assert!(report.substeps <= 450, "{}", report.substeps);
}

/// A benchmark case: a free rotor whose drag (2.1e-14 N m s) is too weak for its ring's torque
/// (up to 3e-14 N m) to be negligible over a step, its onion ringing in its well.
const HEAVY_ROTOR: &str = "strain_direction=4.348412889627226e6 stress=1.9573159653070974e2 \
    load_torque=-8.070960266705514e-7 ring_outer_diameter=5.818144910189025e-1 \
    ring_inner_diameter=2.0451565212652238e-2 bar_length=5.15067653755647e-4 \
    bar_width=1.1776251942244318e-4 thickness=6.658697198184579e-5 \
    saturation_magnetization=5.196469177655726e3 magnetostriction=-9.969506942915016e-3 \
    wall_volume=4.5812051580117864e-11 density=7.613190827328188e4 \
    fluid_viscosity=1.7319706556730814e-4 gilbert_damping=6.114196349121509e-3 \
    tolerance=2.413962318950689e-10 step_angle=-6.744563630818385e0 \
    step_period=4.248177753865677e-8 stress_amplitude=-7.149385756889192e10 \
    schedule_initial_direction=6.9125825502763414e-3 onion_model=1 max_substeps=1.0742e4 \
    schedule=0e0 rotor_locked=0e0 initial_onion_offset=-4.201015739485816e-10 \
    strain=-8.970641473247581e-2 youngs_modulus=1.7013266942489056e6 strain_drive=0e0";

/// The drop's conditions on [`RIM_RINGING`]'s start: it holds with the drive constant to the
/// step's end; not with a switch before it, nor where the ring can move the rotor
/// ([`HEAVY_ROTOR`]), nor for an onion beyond its well's rims.
#[test]
fn decoupled_drop_needs_a_constant_drive_a_weak_ring_and_a_trapped_onion() {
    let (m, start, inputs) = case(&values(RIM_RINGING)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let y = [start.rotor_angle, 0.0, start.onion_angle, start.onion_tilt];
    let h = 1e-6;
    assert!(m.decoupled_budget_drop(&y, &d, (h, f64::INFINITY), &Default::default()));
    assert!(m.decoupled_budget_drop(&y, &d, (h, h), &Default::default()));
    assert!(!m.decoupled_budget_drop(&y, &d, (h, 0.5 * h), &Default::default()));
    let (w, other, other_inputs) = case(&values(HEAVY_ROTOR)).unwrap();
    let e = w.drive_at(&other_inputs, 0.0);
    let z = [other.rotor_angle, 0.0, other.onion_angle, other.onion_tilt];
    assert!(w
        .onion_well(&w.landscape(z[0], e.direction, e.stress), z[2])
        .is_some());
    assert!(!w.decoupled_budget_drop(&z, &e, (h, f64::INFINITY), &Default::default()));
    // Tilted out of the well: its energy above the lowest rim.
    let land = m.landscape(y[0], d.direction, d.stress);
    let well = m.onion_well(&land, y[2]).unwrap();
    let tilt = (2.0 * well.barrier / m.tilt_stiffness).sqrt() * 1.01;
    assert!(!m.decoupled_budget_drop(
        &[y[0], y[1], y[2], tilt],
        &d,
        (h, f64::INFINITY),
        &Default::default()
    ));
}

/// A benchmark case: a load-driven rotor (inertial time 3e-13 s) at 1.2e7 rad/s whose ring's
/// torque (below 3e-23 N m) cannot move it, no schedule, its onion (damping 2.4e-3, relaxation
/// 10 ns) released at 0.99 of its well's lowest rim.
const NEAR_RIM: &str = "strain_direction=4.9573496376592675e3 stress=-2.9063956307800426e10 \
    load_torque=1.3911610755181714e-8 ring_outer_diameter=4.9724188941146524e-1 \
    ring_inner_diameter=1.1278201485996085e-2 bar_length=3.021870150038794e-6 \
    bar_width=2.9384524405437306e-7 thickness=5.952528605027693e-9 \
    saturation_magnetization=3.625129236553573e5 magnetostriction=7.92609670438753e-3 \
    wall_volume=1.8111051577475945e-12 density=8.860038477290867e4 \
    fluid_viscosity=1.4281887716978093e2 gilbert_damping=2.412727593685618e-3 \
    tolerance=2.1841371437116797e-7 step_angle=4.719108860732808e0 \
    step_period=2.3134189274696487e-2 stress_amplitude=-1.213480749478304e4 \
    schedule_initial_direction=-6.654105375290676e2 onion_model=1 max_substeps=6242 \
    schedule=0 rotor_locked=0 initial_onion_offset=1.247482838385613e-2 \
    strain=-9.477238940835138e-2 youngs_modulus=5.526073415009557e6 strain_drive=1";

/// [`NEAR_RIM`]'s first step against the exact load-and-drag rotor and a converged RK4 of the
/// macrospin driven by it ([`driven_rk4`]): the ringing's orbit-averaged decay ends it within the
/// step, so it is dropped at once, the step not flagged, within the tolerance of the reference
/// (the rotor within a hundredth of it). Resolved until its budget ran out (the instantaneous
/// decay bounds fail near the rim), it took 626 substeps and was flagged.
#[test]
fn decoupled_ringing_near_its_rim_is_dropped_at_its_averaged_decay() {
    let (m, start, inputs) = case(&values(NEAR_RIM)).unwrap();
    let h = 1e-6;
    let d = m.drive_at(&inputs, 0.0);
    let y0 = [start.rotor_angle, 0.0, start.onion_angle, start.onion_tilt];
    let (coarse, truth) = (driven_rk4(&m, &d, y0, h, 1), driven_rk4(&m, &d, y0, h, 2));
    let tol = m.params.tolerance;
    assert!(
        (coarse[2] - truth[2]).abs() <= 0.01 * tol && (coarse[3] - truth[3]).abs() <= 0.01 * tol,
        "{coarse:?} {truth:?}"
    );
    let land = m.landscape(y0[0], d.direction, d.stress);
    let well = m.onion_well(&land, y0[2]).unwrap();
    let excess = point(&land, y0[2]).0 - well.floor;
    assert!(excess > 0.98 * well.barrier, "{}", excess / well.barrier);
    let mut st = start;
    let report = m.step(&mut st, &inputs, h).unwrap();
    let errors = [
        (st.rotor_angle - truth[0]).abs() / tol,
        (st.onion_angle - truth[2]).abs() / tol,
        (st.onion_tilt - truth[3]).abs() / tol,
    ];
    println!(
        "{} substeps, flagged {}; errors / tolerance {errors:?}",
        report.substeps, report.accuracy_limited
    );
    assert!(!report.accuracy_limited);
    assert!(report.substeps <= 60, "{}", report.substeps);
    assert!(
        errors[0] <= 0.01 && errors[1] <= 1.0 && errors[2] <= 1.0,
        "{errors:?}"
    );
}

/// [`NEAR_RIM`]'s ringing is dropped at its averaged decay only in the step's last segment: with
/// a switch before the step's end the check declines at once.
#[test]
fn averaged_decay_drop_waits_for_the_last_segment() {
    let (m, start, inputs) = case(&values(NEAR_RIM)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let y0 = [start.rotor_angle, 0.0, start.onion_angle, start.onion_tilt];
    let settled = m.settle(&y0, &d);
    for ends_step in [true, false] {
        let mut rims = Rims {
            ends_step,
            ..Rims::NONE
        };
        let dropped = m.decoupled_ringing_decays(&y0, &d, settled, &mut rims, 1e-6);
        assert_eq!(dropped, ends_step);
    }
}

/// A benchmark draw on a 21 ns schedule: its rotor spins at 1.7e7 rad/s and each 1 us step ends
/// flagged. The averaged decay check fired in a segment before a switch, and its drop made the
/// step's last segment dearer: 90, 100 and 82 substeps against 64, 60 and 70 with the check kept
/// to the last segment (the outputs the same to rounding, 1e-15 relative).
const FAST_SCHEDULE: &str = "strain_direction=1.4075364617265551e1 stress=2.8543287707805307e3 \
    load_torque=-1.0990045539582491e-7 ring_outer_diameter=4.1655923907639133e-4 \
    ring_inner_diameter=1.802537997044728e-5 bar_length=2.3454218334403427e-6 \
    bar_width=3.4092340692847017e-7 thickness=5.380848925506371e-9 \
    saturation_magnetization=1.040751026230234e5 magnetostriction=-3.6054716973367732e-3 \
    wall_volume=2.9760542237790954e-11 density=7.719725302755383e3 \
    fluid_viscosity=1.5339130872946726e3 gilbert_damping=2.4473006438643983e-4 \
    tolerance=1.3558428485313861e-6 step_angle=5.302896656617921e0 \
    step_period=2.124350001335623e-8 stress_amplitude=6.959834193658602e8 \
    schedule_initial_direction=2.715045124322908e3 onion_model=1e0 max_substeps=1.282e4 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=-3.4184209281342444e-6 \
    strain=6.295116901366998e-2 youngs_modulus=3.0279534408241425e9 strain_drive=1e0";

#[test]
fn fast_schedule_steps_do_not_try_the_averaged_decay_before_a_switch() {
    let (m, mut st, inputs) = case(&values(FAST_SCHEDULE)).unwrap();
    for _ in 0..3 {
        let report = m.step(&mut st, &inputs, 1e-6).unwrap();
        println!(
            "{} substeps, flagged {}",
            report.substeps, report.accuracy_limited
        );
        assert!(report.accuracy_limited);
        assert!(report.substeps <= 72, "{}", report.substeps);
    }
}
