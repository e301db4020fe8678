//! A ringing onion on a stiff free rotor against a plain RK4 of the motor's ODE, and the `phi`
//! functions of a 2x2 block against their integral.

use super::block_phi::BlockPhi;
use super::onion_periods_tests::{case, values};
use super::resolved_tests::rk4_span;

/// A benchmark case: a Gilbert onion (damping 7.6e-3) ringing through whole microseconds, about
/// a radian off its minimum, on a rotor in a fluid 1.7e5 times as viscous as water (drag rate
/// `c/I` 6.3e13 1/s), on a 274 us schedule; here a 64 times less viscous fluid (`c/I` 9.8e11
/// 1/s), which leaves the substeps as they are and lets an RK4 resolve the rotor's inertial time
/// in a million steps a microsecond.
const RINGING_ON_A_STIFF_ROTOR: &str = "strain_direction=2.760727418263646e10 \
    stress=4.802060948441971e0 load_torque=7.005551409864961e-7 \
    ring_outer_diameter=2.7731906704463346e-2 ring_inner_diameter=3.4366325627905514e-3 \
    bar_length=2.470158495074675e-4 bar_width=1.2493309254726491e-4 \
    thickness=6.805756965095956e-9 saturation_magnetization=1.3576265824131094e3 \
    magnetostriction=4.1154134889003074e-3 wall_volume=7.928624741307107e-11 \
    density=6.525015925406461e3 fluid_viscosity=2.61685982212716e3 \
    gilbert_damping=7.590411535798485e-3 tolerance=6.748967980139128e-10 \
    step_angle=3.0241908676353937e0 step_period=2.735500930595152e-4 \
    stress_amplitude=-6.133278697980404e0 schedule_initial_direction=1.1478010554570153e-6 \
    onion_model=1 max_substeps=12161 schedule=1 initial_onion_offset=9.810646276129092e-7";

/// The second and third 1 us steps of [`RINGING_ON_A_STIFF_ROTOR`] (no switch inside them)
/// against a plain RK4 of the full system from each step's start at steps of the rotor's
/// inertial time `I/c` and of half of it, which agree within a hundredth of the tolerance: the
/// rotor, the onion and its tilt end within the tolerance of it, in fewer than 800 and 500
/// substeps. (With the onion's block explicit, classical RK4 on its ringing took 1,029 and 846
/// substeps and ended 37 and 39 tolerances off.) The first step is left out: its onion starts
/// 1e-6 rad from a maximum of its landscape, and a start moved by the tolerance ends 2e6
/// tolerances away.
#[test]
fn ringing_onion_on_a_stiff_rotor_keeps_to_a_rk4_span() {
    let (m, start, inputs) = case(&values(RINGING_ON_A_STIFF_ROTOR)).unwrap();
    let tol = m.params.tolerance;
    let mut s = start;
    m.step(&mut s, &inputs, 1e-6).unwrap();
    let n = (1e-6 * m.drag / m.inertia).ceil() as usize;
    for bound in [800, 500] {
        let d = m.drive_at(&inputs, s.time);
        let y = [s.rotor_angle, s.rotor_speed, s.onion_angle, s.onion_tilt];
        let report = m.step(&mut s, &inputs, 1e-6).unwrap();
        let coarse = rk4_span(&m, &d, y, 1e-6, n);
        let truth = rk4_span(&m, &d, y, 1e-6, 2 * n);
        let got = [s.rotor_angle, s.rotor_speed, s.onion_angle, s.onion_tilt];
        println!(
            "{} substeps: {got:?} against {truth:?} (off {:e}, {:e}, {:e} tolerances)",
            report.substeps,
            (got[0] - truth[0]).abs() / tol,
            (got[2] - truth[2]).abs() / tol,
            (got[3] - truth[3]).abs() / tol
        );
        for i in [0, 2, 3] {
            assert!(
                (coarse[i] - truth[i]).abs() <= 0.01 * tol,
                "{coarse:?} {truth:?}"
            );
            assert!((got[i] - truth[i]).abs() <= tol, "{i}: {got:?} {truth:?}");
        }
        assert!(!report.accuracy_limited);
        assert!(report.substeps < bound, "{}", report.substeps);
    }
}

/// `phi_k(A) v = 1/(k-1)! int_0^1 e^((1-s) A) s^(k-1) v ds` by composite Simpson's rule, with
/// `e^(tA) = S e^(tD) S^-1` for `A = S D S^-1` and `D` either diagonal (`[l1, l2]`) or the
/// rotation form of `-a +- i b`.
fn phi_by_quadrature(k: i32, s: [[f64; 2]; 2], d: (f64, f64, bool), v: [f64; 2]) -> [f64; 2] {
    let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
    let inv = [
        [s[1][1] / det, -s[0][1] / det],
        [-s[1][0] / det, s[0][0] / det],
    ];
    let mv = |m: &[[f64; 2]; 2], x: [f64; 2]| {
        [
            m[0][0] * x[0] + m[0][1] * x[1],
            m[1][0] * x[0] + m[1][1] * x[1],
        ]
    };
    let w = mv(&inv, v);
    let exp_d = |t: f64, x: [f64; 2]| -> [f64; 2] {
        let (p, q, rotation) = d;
        if rotation {
            let (sin, cos) = (q * t).sin_cos();
            let e = (p * t).exp();
            [e * (cos * x[0] - sin * x[1]), e * (sin * x[0] + cos * x[1])]
        } else {
            [(p * t).exp() * x[0], (q * t).exp() * x[1]]
        }
    };
    let n = 200_000;
    let mut sum = [0.0; 2];
    for i in 0..=n {
        let s_i = i as f64 / n as f64;
        let weight = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let e = exp_d(1.0 - s_i, w);
        for c in 0..2 {
            sum[c] += weight * s_i.powi(k - 1) * e[c];
        }
    }
    let factorial = (1..k).product::<i32>() as f64;
    let x = sum.map(|c| c / (3.0 * n as f64) / factorial);
    mv(&s, x)
}

/// [`BlockPhi`] of non-normal 2x2 blocks with complex eigenvalues (a precessing onion, from a
/// tenth of a turn to many turns), real ones (an overdamped onion, a saddle) and small norms,
/// and its doubling, against the quadrature of the `phi` functions' integral.
#[test]
fn block_phi_matches_the_integral_of_its_exponential() {
    let s = [[1.0, 0.3], [-0.2, 40.0]];
    let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
    let inv = [
        [s[1][1] / det, -s[0][1] / det],
        [-s[1][0] / det, s[0][0] / det],
    ];
    let matrix = |d: (f64, f64, bool)| -> [[f64; 2]; 2] {
        let (p, q, rotation) = d;
        let core = if rotation {
            [[p, -q], [q, p]]
        } else {
            [[p, 0.0], [0.0, q]]
        };
        let sd: [[f64; 2]; 2] = std::array::from_fn(|i| {
            std::array::from_fn(|k| s[i][0] * core[0][k] + s[i][1] * core[1][k])
        });
        std::array::from_fn(|i| {
            std::array::from_fn(|k| sd[i][0] * inv[0][k] + sd[i][1] * inv[1][k])
        })
    };
    let v = [0.7, -0.02];
    for d in [
        (-0.01, 0.6, true),
        (-0.05, 3.0, true),
        (-0.3, 20.0, true),
        (-2.0, 0.4, true),
        (-0.001, 0.004, true),
        (-3.0, -0.5, false),
        (1.5, -4.0, false),
        (-12.0, -0.002, false),
    ] {
        let a = matrix(d);
        let half: [[f64; 2]; 2] = a.map(|r| r.map(|x| 0.5 * x));
        let direct = BlockPhi::new(&a).unwrap();
        let doubled = BlockPhi::new(&half).unwrap().doubled(&half);
        for k in 1..=3 {
            let truth = phi_by_quadrature(k, s, d, v);
            for (name, got) in [
                ("direct", direct.apply(k as usize, v)),
                ("doubled", doubled.apply(k as usize, v)),
            ] {
                let scale = truth[0].abs().max(truth[1].abs());
                let error = (got[0] - truth[0]).abs().max((got[1] - truth[1]).abs());
                assert!(
                    error <= 1e-9 * scale,
                    "{d:?} phi_{k} {name}: {got:?} against {truth:?}"
                );
            }
        }
    }
    // Nearly repeated eigenvalues beyond the series' reach are declined.
    assert!(BlockPhi::new(&[[-1.0, 1e-14], [0.0, -1.0]]).is_none());
    assert!(BlockPhi::new(&[[f64::NAN, 0.0], [0.0, 1.0]]).is_none());
}

/// A benchmark case: a Gilbert onion (damping 5.6e-4) on a rotor in a fluid 109 times as viscous
/// as water, on a 78.5 ns schedule, that spends its whole substep budget (13,127) in a 1 us step
/// where its ringing is resolved until the budget's drop (without the forecast drop,
/// [`Motor::budget_forecast_drops`]).
/// The exponential RK4 with both blocks rejects about a fifth of its substeps, almost all by less
/// than [`super::etd_blocks::RETRY_ABOVE`] (its error changes along the onion's orbit between
/// substeps of one length).
pub(super) const BUDGET_BOUND_FREE_ROTOR: &str = "strain_direction=-1.554122678401819e2 stress=-3.479031041687615e9 load_torque=3.022337314507582e-7 ring_outer_diameter=5.9280961443378716e-5 ring_inner_diameter=3.8194746212636794e-5 bar_length=1.983684983299965e-5 bar_width=1.0339555921940574e-5 thickness=1.8907428537130158e-9 saturation_magnetization=1.3725082270133316e4 magnetostriction=6.175377615668639e-3 wall_volume=8.990225427710952e-11 density=5.6033971852967725e3 fluid_viscosity=1.0923420605366032e2 gilbert_damping=5.586777528696512e-4 tolerance=3.074548873010051e-5 step_angle=1.401337090158865e0 step_period=7.854046876472495e-8 stress_amplitude=-6.51759975053556e4 schedule_initial_direction=7.320039591034606e3 onion_model=1e0 max_substeps=1.3127e4 schedule=1e0 rotor_locked=0e0 initial_onion_offset=-7.309428939339728e-12 strain=-6.286104911029818e-2 youngs_modulus=7.850694041367646e6 strain_drive=0e0";

/// The exponential pair is not retried after the exponential RK4's rejections by little, none of
/// which it took: at most one retry in eight substeps (314 in 1,317 with every rejection retried),
/// over the substeps resolved until the budget's drop.
#[test]
fn marginal_rejections_are_not_retried_by_the_exponential_pair() {
    let (m, mut s, inputs) = case(&values(BUDGET_BOUND_FREE_ROTOR)).unwrap();
    super::integrator::PAIR_AFTER_RK4.with(|c| c.set(0));
    super::budget_forecast::FORECAST_OFF.with(|c| c.set(true));
    let report = m.step(&mut s, &inputs, 1e-6);
    super::budget_forecast::FORECAST_OFF.with(|c| c.set(false));
    let report = report.unwrap();
    let retries = super::integrator::PAIR_AFTER_RK4.with(|c| c.get());
    println!("{} substeps, {retries} retries", report.substeps);
    assert!(report.substeps >= 1300, "{}", report.substeps);
    assert!(8 * retries <= report.substeps, "{retries} retries");
}
