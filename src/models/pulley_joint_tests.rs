//! PulleyJoint's Model Exchange: the derivatives are the ODE Co-Simulation steps, the time events
//! are the reference's segment boundaries, and the exact partials agree with central differences.

use super::*;
use crate::variables::pulley_joint::{Known, Unknown};

fn joint(parameters: &Parameters) -> PulleyJoint {
    PulleyJoint::new(parameters, &Inputs::default()).expect("valid parameters")
}

/// Every unknown of the Jacobian: the outputs and the state derivatives.
fn unknowns(m: &mut PulleyJoint, inputs: &Inputs) -> Vec<(Unknown, f64)> {
    let mut o = Outputs::default();
    m.evaluate(inputs, &mut o, &mut Report::default());
    let d = m.derivatives(inputs).expect("finite torque");
    vec![
        (Unknown::FlexorLength, o.flexor_length),
        (Unknown::ExtensorLength, o.extensor_length),
        (Unknown::FlexorPressure, o.flexor_pressure),
        (Unknown::ExtensorPressure, o.extensor_pressure),
        (Unknown::JointAngle, o.joint_angle),
        (Unknown::JointVelocity, o.joint_velocity),
        (Unknown::ReferenceAngle, o.reference_angle),
        (Unknown::JointTorque, o.joint_torque),
        (Unknown::DerJointAngle, d.joint_angle),
        (Unknown::DerJointVelocity, d.joint_velocity),
    ]
}

/// The knowns: the inputs and the states, each with its getter and setter on (inputs, states).
type Getter = fn(&Inputs, &States) -> f64;
type Setter = fn(&mut Inputs, &mut States, f64);
const KNOWNS: [(Known, Getter, Setter); 6] = [
    (
        Known::FlexorForce,
        |i, _| i.flexor_force,
        |i, _, x| i.flexor_force = x,
    ),
    (
        Known::ExtensorForce,
        |i, _| i.extensor_force,
        |i, _, x| i.extensor_force = x,
    ),
    (
        Known::FlexorPressureCommand,
        |i, _| i.flexor_pressure_command,
        |i, _, x| i.flexor_pressure_command = x,
    ),
    (
        Known::ExtensorPressureCommand,
        |i, _| i.extensor_pressure_command,
        |i, _, x| i.extensor_pressure_command = x,
    ),
    (
        Known::JointAngle,
        |_, s| s.joint_angle,
        |_, s, x| s.joint_angle = x,
    ),
    (
        Known::JointVelocity,
        |_, s| s.joint_velocity,
        |_, s, x| s.joint_velocity = x,
    ),
];

/// Central differences of every unknown with respect to every known at (inputs, states, time),
/// against `partials` (a known missing from a row has slope 0).
fn check_partials(parameters: &Parameters, inputs: &Inputs, states: &States, time: f64) {
    let mut m = joint(parameters);
    m.set_time(time);
    m.set_states(states).expect("valid state");
    let partials = super::super::all_partials(&mut m, inputs).expect("provided");
    for (known, get, set) in KNOWNS {
        let x = get(inputs, states);
        let h = 1e-6 * x.abs().max(1e-2);
        let at = |x: f64| {
            let (mut i, mut s) = (inputs.clone(), *states);
            set(&mut i, &mut s, x);
            let mut m = joint(parameters);
            m.set_time(time);
            m.set_states(&s).expect("valid state");
            unknowns(&mut m, &i)
        };
        let (up, down) = (at(x + h), at(x - h));
        for ((unknown, a), (_, b)) in up.iter().zip(&down) {
            let numeric = (a - b) / (2.0 * h);
            let exact = partials
                .partial(*unknown, known)
                .unwrap_or_else(|| panic!("no row for {unknown:?}"));
            let scale = numeric.abs().max(exact.abs()).max(1.0);
            assert!(
                (exact - numeric).abs() <= 1e-6 * scale,
                "d {unknown:?} / d {known:?} at {states:?}, t = {time}: exact {exact}, central difference {numeric}"
            );
        }
    }
}

#[test]
fn partials_match_central_differences_across_the_controller_and_the_mechanics() {
    let inputs = Inputs {
        flexor_force: 120.0,
        extensor_force: 45.0,
        flexor_pressure_command: 2e5,
        extensor_pressure_command: 3e5,
    };
    let default = Parameters::default();
    // Mid-move (the controller unsaturated), past the last waypoint, and far from the
    // reference (both pressures saturated, so their rows vanish).
    for (q, dq, time) in [
        (0.1, 0.3, 0.4),
        (-0.2, -1.0, 2.5),
        (0.05, 0.0, 5.0),
        (1.5, 4.0, 0.5),
    ] {
        let states = States {
            joint_angle: q,
            joint_velocity: dq,
        };
        check_partials(&default, &inputs, &states, time);
        let external = Parameters {
            external_pressures: true,
            ..default.clone()
        };
        check_partials(&external, &inputs, &states, time);
    }
}

#[test]
fn the_saturated_pressures_have_no_slope_and_the_free_ones_the_gains() {
    let mut m = joint(&Parameters::default());
    // Far below the reference: u is huge, the flexor at max_pressure, the extensor at zero.
    m.set_states(&States {
        joint_angle: -2.0,
        joint_velocity: 0.0,
    })
    .expect("valid");
    let d = super::super::all_partials(&mut m, &Inputs::default()).expect("provided");
    for row in [Unknown::FlexorPressure, Unknown::ExtensorPressure] {
        assert!(
            d.get(row).expect("row").iter().all(|v| *v == 0.0),
            "{row:?}"
        );
    }
    // At rest on the reference: both inside, slopes -/+ kp/2 and -/+ kd/2.
    let mut m = joint(&Parameters::default());
    let d = super::super::all_partials(&mut m, &Inputs::default()).expect("provided");
    let p = Parameters::default();
    let slopes = |u: Unknown| {
        [Known::JointAngle, Known::JointVelocity, Known::FlexorForce]
            .map(|k| d.partial(u, k).expect("row"))
    };
    assert_eq!(
        slopes(Unknown::FlexorPressure),
        [-0.5 * p.kp, -0.5 * p.kd, 0.0]
    );
    assert_eq!(
        slopes(Unknown::ExtensorPressure),
        [0.5 * p.kp, 0.5 * p.kd, 0.0]
    );
}

#[test]
fn the_derivatives_are_the_ode_that_co_simulation_steps() {
    // Semi-implicit Euler: dq1 = dq0 + h a(q0, dq0), q1 = q0 + h dq1, so one short step gives the
    // acceleration Model Exchange reports, to rounding.
    let inputs = Inputs {
        flexor_force: 80.0,
        extensor_force: 20.0,
        ..Inputs::default()
    };
    let mut me = joint(&Parameters::default());
    let start = States {
        joint_angle: 0.3,
        joint_velocity: -0.7,
    };
    me.set_states(&start).expect("valid");
    let dx = me.derivatives(&inputs).expect("finite");
    assert_eq!(dx.joint_angle, start.joint_velocity);
    let mut cs = me.clone();
    let h = 1e-4;
    cs.step(
        &inputs,
        &mut Outputs::default(),
        0.0,
        h,
        &mut Report::default(),
    );
    let after = cs.states();
    let acceleration = (after.joint_velocity - start.joint_velocity) / h;
    assert!(
        (acceleration - dx.joint_velocity).abs() <= 1e-9 * dx.joint_velocity.abs(),
        "{acceleration} vs {}",
        dx.joint_velocity
    );
    // The hand check of the ODE: (r (F_f - F_e) - c dq - m g l sin q) / I.
    let p = Parameters::default();
    let expected = (p.moment_arm * 60.0
        - p.damping * -0.7
        - p.mass * p.gravity * p.com_distance * 0.3_f64.sin())
        / p.inertia;
    assert!((dx.joint_velocity - expected).abs() <= 1e-12 * expected.abs());
}

#[test]
fn time_events_fall_on_the_segment_boundaries_and_stop_after_the_last_move() {
    let m = joint(&Parameters {
        segment_time: 0.5,
        ..Parameters::default()
    });
    assert_eq!(m.next_time_event(0.0), Some(0.5));
    assert_eq!(m.next_time_event(0.5), Some(1.0));
    assert_eq!(m.next_time_event(1.2), Some(1.5));
    assert_eq!(m.next_time_event(1.5), Some(2.0));
    assert_eq!(m.next_time_event(2.0), None);
}

#[test]
fn a_state_whose_outputs_cannot_be_represented_is_refused_and_the_old_one_kept() {
    let mut m = joint(&Parameters::default());
    let good = States {
        joint_angle: 0.2,
        joint_velocity: 0.1,
    };
    m.set_states(&good).expect("valid");
    let bad = States {
        joint_angle: 0.2,
        joint_velocity: f64::INFINITY,
    };
    assert!(m.set_states(&bad).is_err());
    assert_eq!(m.states(), good);
}

/// Steps `m` `steps` times by `h` from t = 0 with `inputs`; every step must be accepted.
fn run_steps(m: &mut PulleyJoint, inputs: &Inputs, h: f64, steps: usize) {
    for k in 0..steps {
        let mut report = Report::default();
        m.step(
            inputs,
            &mut Outputs::default(),
            k as f64 * h,
            h,
            &mut report,
        );
        assert!(m.states().joint_angle.is_finite(), "step {k}");
    }
    assert!(
        (m.time - steps as f64 * h).abs() <= 1e-12,
        "a step was refused"
    );
}

#[test]
fn a_joint_too_stiff_for_explicit_substeps_follows_its_exact_overdamped_motion() {
    // Inertia 1e-12 kg m^2 against damping 1 N m s: explicit Euler would need 2e9 substeps of the
    // 1 ms step. I q'' + c q' = T from rest has q = (T/c) (t - tau (1 - e^(-t/tau))), tau = I/c.
    let p = Parameters {
        inertia: 1e-12,
        damping: 1.0,
        mass: 0.0,
        ..Parameters::default()
    };
    let inputs = Inputs {
        flexor_force: 80.0,
        extensor_force: 20.0,
        ..Inputs::default()
    };
    let mut m = joint(&p);
    let (h, steps) = (1e-3, 100);
    run_steps(&mut m, &inputs, h, steps);
    let (torque, t, tau) = (p.moment_arm * 60.0, steps as f64 * h, p.inertia / p.damping);
    let exact = torque / p.damping * (t - tau * (1.0 - (-t / tau).exp()));
    let s = m.states();
    // The first substep (1/64 of a step) lags the exact start: 1/(64 steps) of the angle.
    assert!(
        (s.joint_angle - exact).abs() <= 2e-4 * exact,
        "{} vs {exact}",
        s.joint_angle
    );
    assert!((s.joint_velocity - torque / p.damping).abs() <= 1e-9 * torque / p.damping);
}

#[test]
fn a_joint_too_stiff_for_explicit_substeps_settles_where_gravity_balances_the_torque() {
    // Inertia 1e-12 kg m^2, no damping, gravity torque m g l = 2.94 N m against 0.3 N m: the
    // substeps reach the static balance m g l sin q = T (the fast swing about it is not resolved).
    let p = Parameters {
        inertia: 1e-12,
        damping: 0.0,
        mass: 2.5,
        ..Parameters::default()
    };
    let inputs = Inputs {
        flexor_force: 30.0,
        extensor_force: 10.0,
        ..Inputs::default()
    };
    let mut m = joint(&p);
    run_steps(&mut m, &inputs, 1e-3, 3);
    let k = p.mass * p.gravity * p.com_distance;
    let balance = (p.moment_arm * 20.0 / k).asin();
    let s = m.states();
    assert!(
        (s.joint_angle - balance).abs() <= 1e-9,
        "{} vs {balance}",
        s.joint_angle
    );
    assert!(s.joint_velocity.abs() <= 1e-6, "{}", s.joint_velocity);
}
