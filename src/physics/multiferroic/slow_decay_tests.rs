//! A free rotor's Gilbert onion that approaches its minimum slowly, handed over to its
//! quasi-static branch, against a plain RK4 of the macrospin ([`Motor::ends_at_minimum`]).

use super::locked_accuracy_tests::converged_rk4;
use super::onion_periods_tests::{case, values};
use super::tests::rk4_step;
use super::{MotorState, Vector};

/// A benchmark draw: gilbert_damping 0.5, tolerance 3.3e-6, a load that spins the rotor from
/// rest to 1.8e7 rad/s within the 1 us step. The onion starts 0.039 rad from the minimum of
/// eq. 3.4 that the strain holds it in, which it approaches at `lambda = 1e6 /s` (a weak well:
/// `Ms` 1.2e3 A/m): it decays by a factor `e` over the step, yet ends 0.014 rad from it.
const SPUN_UP: &str = "strain_direction=2.831707175446057e0 stress=-4.263456709690666e1 \
    load_torque=8.819564974949527e-7 ring_outer_diameter=7.722696735518704e-1 \
    ring_inner_diameter=9.399703726968881e-3 bar_length=1.0936850592135104e-4 \
    bar_width=6.375113544672636e-5 thickness=4.497893326350123e-6 \
    saturation_magnetization=1.2029470381554663e3 magnetostriction=-9.339694190975514e-3 \
    wall_volume=1.43627298942828e-11 density=1.1639487361050292e3 \
    fluid_viscosity=8.173845444016835e-5 gilbert_damping=5.045949362413119e-1 \
    tolerance=3.278096304330736e-6 step_angle=6.597877186031798e0 \
    step_period=2.6354109986202224e4 stress_amplitude=-1.2474082363880158e-1 \
    schedule_initial_direction=-8.344388154479304e4 onion_model=1e0 max_substeps=1.228e3 \
    schedule=1e0 rotor_locked=0e0 initial_onion_offset=-2.9365805498205793e-6 \
    strain=3.764097700905106e-2 youngs_modulus=2.523774204639009e6 strain_drive=1e0";

/// The step is resolved, not handed to the branch: the onion's angle and tilt end within a
/// tolerance of the RK4 (0.19 and 0.003 tolerances), the rotor's angle too. Handing the onion
/// over at the start (its ringing "decays" by a factor `e` within the step) took one substep,
/// unflagged, and ended 4,320 tolerances off.
#[test]
fn slowly_relaxing_onion_of_a_free_rotor_against_rk4() {
    let (m, start, inputs) = case(&values(SPUN_UP)).unwrap();
    let mut st = start;
    let report = m.step(&mut st, &inputs, 1e-6).unwrap();
    let truth = converged_rk4(&m, &start, &inputs, st.time, 2.0);
    let tol = m.params.tolerance;
    let errors = [
        (st.rotor_angle - truth[0]).abs() / tol,
        (st.onion_angle - truth[2]).abs() / tol,
        (st.onion_tilt - truth[3]).abs() / tol,
    ];
    println!("{report:?}, errors / tolerance {errors:?}");
    assert!(!report.accuracy_limited, "{report:?}");
    assert!(errors.iter().all(|e| *e <= 1.0), "{st:?} against {truth:?}");
}

/// A benchmark draw (gilbert_damping 0.39, tolerance 1.2e-5, constant strain, a load that spins
/// the rotor at 810 rad/s, the ring's torque on it 1e-31 N m) at the state its onion reaches
/// 0.1 ps into its first step: settled in angle, its tilt -3.35 rad. The tilt is `2.7e9` times
/// softer than the well, and decays at `lambda = 2.9e6 /s`.
const SOFT_TILT: &str = "strain_direction=7.254482590093983e2 stress=3.3729455811587206e2 \
    load_torque=7.089562254598222e-7 ring_outer_diameter=7.537587471988355e-2 \
    ring_inner_diameter=1.5443807809586665e-2 bar_length=2.019559793654614e-5 \
    bar_width=6.496611795486012e-6 thickness=2.159442353319226e-9 \
    saturation_magnetization=5.1896036654112e0 magnetostriction=9.85062213271871e-3 \
    wall_volume=4.116622168459587e-11 density=7.89218605399984e3 \
    fluid_viscosity=4.427336481589265e5 gilbert_damping=3.909358260535708e-1 \
    tolerance=1.204966115814138e-5 step_angle=-2.303737370212982e0 \
    step_period=4.064879135300949e1 stress_amplitude=2.1894149347300527e2 \
    schedule_initial_direction=1.2012322623375769e0 onion_model=1e0 max_substeps=5.73e2 \
    schedule=0e0 rotor_locked=0e0 initial_onion_offset=-8.356523884138085e-8 \
    strain=-5.082928612976903e-2 youngs_modulus=6.088262986149726e7 strain_drive=1e0";

/// The onion's angle and tilt after `h` of the linearization about the minimum `psi_min` of its
/// well, exactly: `exp(A h) (psi - psi_min, theta)` by the eigenvalues of the 2x2 block `A`
/// (real and distinct here). Exact for the draw up to the well's curvature over the angle's
/// excursion (below 1e-9 rad) and the ring's torque, which turns neither.
fn linear_onion(a: [[f64; 2]; 2], x: [f64; 2], h: f64) -> [f64; 2] {
    let (tr, det) = (a[0][0] + a[1][1], a[0][0] * a[1][1] - a[0][1] * a[1][0]);
    let disc = tr * tr - 4.0 * det;
    assert!(disc > 0.0, "complex eigenvalues: {a:?}");
    let fast = 0.5 * (tr - disc.sqrt());
    let slow = det / fast;
    // exp(A h) = (e^{slow h} (A - fast) - e^{fast h} (A - slow)) / (slow - fast)
    let term = |mu: f64, i: usize| (a[i][0] * x[0] + a[i][1] * x[1]) - mu * x[i];
    let (es, ef) = ((slow * h).exp(), (fast * h).exp());
    [0, 1].map(|i| (es * term(fast, i) - ef * term(slow, i)) / (slow - fast))
}

/// The onion with its tilt far softer than its well is not handed to its branch while its tilt
/// is beyond the tolerance at the step's end: the step ends within a tolerance of the exact
/// linear decay, unflagged. Its distance in the energy's norm (the tilt weighed by
/// `sqrt(t / k)`) put it within the tolerance at once; the step reported no tilt, 14,700
/// tolerances off.
#[test]
fn soft_tilt_is_not_handed_over_until_it_decays() {
    let (m, start, inputs) = case(&values(SOFT_TILT)).unwrap();
    let d = m.drive_at(&inputs, 0.0);
    let y0: Vector = [
        0.0,
        809.785_240_714_605_6,
        1.311_152_360_125_773_7,
        -3.353_880_480_706_091,
    ];
    // The well's minimum by Newton's method on the tilt's rate at no tilt, `g dU/dpsi`.
    let mut psi = y0[2];
    for _ in 0..20 {
        let (f, j) = m.rhs_jacobian(&[y0[0], y0[1], psi, 0.0], &d, 1e-300);
        psi -= f[3] / j[3][2];
    }
    let j = m.rhs_jacobian(&[y0[0], y0[1], psi, 0.0], &d, 1e-300).1;
    let a = [[j[2][2], j[2][3]], [j[3][2], j[3][3]]];
    let h = 1e-6;
    let [dpsi, theta] = linear_onion(a, [y0[2] - psi, y0[3]], h);
    let mut st = MotorState {
        rotor_angle: y0[0],
        rotor_speed: y0[1],
        onion_angle: y0[2],
        onion_tilt: y0[3],
        ..start
    };
    let report = m.step(&mut st, &inputs, h).unwrap();
    let tol = m.params.tolerance;
    let errors = [
        (st.onion_angle - (psi + dpsi)).abs() / tol,
        (st.onion_tilt - theta).abs() / tol,
    ];
    println!("{report:?}, errors / tolerance {errors:?}, truth tilt {theta}");
    assert!(!report.accuracy_limited, "{report:?}");
    assert!(errors.iter().all(|e| *e <= 1.0), "{st:?}: {errors:?}");
}

/// [`Motor::propagated_gap`] against a plain RK4 of the linearized onion at a minimum of
/// curvature `k` (the Jacobian's rows of the onion, [`Motor::rhs_jacobian`]): overdamped (real
/// eigenvalues), near the critical damping and underdamped (complex), from an offset in angle
/// and in tilt.
#[test]
fn propagated_gap_is_the_linearized_onions_flow() {
    for (alpha, ratio) in [
        (0.39, 100.0),
        (0.39, 28.0),
        (0.39, 28.3),
        (0.39, 2.0),
        (0.01, 100.0),
        (0.01, 1.0),
    ] {
        let mut kv = values(SOFT_TILT);
        kv.insert("gilbert_damping".into(), alpha);
        let (m, _, inputs) = case(&kv).unwrap();
        let d = m.drive_at(&inputs, 0.0);
        let (g, t) = (m.llg_rate, m.tilt_stiffness);
        let k = ratio * t;
        let j = [[-g * alpha * k, -g * t], [g * k, -g * alpha * t]];
        // The rows of the motor's Jacobian with the curvature `k` in place of eq. 3.4's.
        let jm = m.rhs_jacobian(&[0.0, 0.0, 0.0, 0.0], &d, 1e-300).1;
        assert_eq!((j[0][1], j[1][1]), (jm[2][3], jm[3][3]));
        let h = 1e-6;
        for x0 in [[1e-3, 0.0], [0.0, 1e-3], [3e-4, -2e-3]] {
            let y = [0.0, 0.0, 0.7 + x0[0], x0[1]];
            let rate = |x: &[f64; 2]| [0, 1].map(|i| j[i][0] * x[0] + j[i][1] * x[1]);
            let n = 200_000;
            let mut x = x0;
            for _ in 0..n {
                x = rk4_step(&rate, &x, h / n as f64);
            }
            let truth = x[0].abs().max(x[1].abs());
            let gap = m.propagated_gap(&y, 0.7, k, h);
            assert!(
                (gap - truth).abs() <= 1e-9 * x0[0].abs().max(x0[1].abs()),
                "alpha {alpha} k/t {ratio} from {x0:?}: {gap:e} against {truth:e} ({x:?})"
            );
        }
    }
}
