//! One switch's exact flow of the linearized onion ([`flow`]) against the exponential of the
//! augmented 4x4 matrix `[[A h, I h], [0, 0]]`, whose blocks are `exp(A h)` and `int_0^h exp(A
//! s) ds` (scaling and squaring of a Taylor series, `numerics::expm`, independent of the 2x2
//! closed forms).

use super::block_phi::block_phi1;
use super::onion_linear::{flow, Flow, M2};
use crate::physics::numerics::expm::expm;

/// `exp(A h)` and `J` by the augmented exponential.
fn reference(a: &M2, h: f64) -> (M2, M2) {
    let mut m = [[0.0; 4]; 4];
    for i in 0..2 {
        for k in 0..2 {
            m[i][k] = a[i][k] * h;
        }
        m[i][i + 2] = h;
    }
    let x = expm(&m).unwrap();
    let e = [[x[0][0], x[0][1]], [x[1][0], x[1][1]]];
    let j = [[x[0][2], x[0][3]], [x[1][2], x[1][3]]];
    (e, j)
}

/// Every entry of the flow's `exp(A h)` and `J` within `bound_e` and `bound_j` of the truth's.
fn assert_flow_near(
    f: &Flow,
    (e, j): (&M2, &M2),
    (bound_e, bound_j): (f64, f64),
    (a, h): (&M2, f64),
) {
    for i in 0..2 {
        for k in 0..2 {
            assert!(
                (f.e[i][k] - e[i][k]).abs() <= bound_e,
                "{a:?} {h}: exp {:?} vs {e:?}",
                f.e
            );
            assert!(
                (f.j[i][k] - j[i][k]).abs() <= bound_j,
                "{a:?} {h}: J {:?} vs {j:?}",
                f.j
            );
        }
    }
}

/// The onion block of eq. 3.4 linearized (rate `g` = 1): `[[-alpha d, -T], [d, -alpha T]]`.
fn onion_block(alpha: f64, d: f64, t: f64) -> M2 {
    [[-alpha * d, -t], [d, -alpha * t]]
}

/// Over the regimes a switch meets (a stiff tilt over a soft, stiff or unstable angle, heavy
/// and light damping: real eigenvalues far apart or close, a complex pair, a singular block,
/// `||A|| h` from 1e-3 to 60) and a few generic ones, nearly repeated eigenvalues among them, `exp(A h)` and `J` agree with the
/// reference to 1e-13 of each column's scale `max(|exp(A h)|)`, `h max(|exp(A s)|)` (the
/// reference's own rounding over a stiff span), and the closed form of `J` is the one taken
/// where the block is nearly singular (one eigenvalue near 0, the other far off).
#[test]
fn flow_matches_the_augmented_exponential() {
    let mut blocks: Vec<(M2, f64)> = Vec::new();
    for &alpha in &[1e-4, 2e-3, 0.03, 0.3, 1.5] {
        for &d in &[
            -3.0, -0.2, -1e-3, 0.0, 1e-6, 1e-3, 0.05, 0.5, 2.0, 30.0, 200.0,
        ] {
            for &h in &[1e-3, 0.02, 0.4, 1.0] {
                blocks.push((onion_block(alpha, d, 40.0), h));
                blocks.push((onion_block(alpha, d, 1.0), h));
            }
        }
    }
    for (a, h) in [
        ([[0.3, -2.0], [0.7, -0.1]], 1.3),
        ([[-1.0, 5.0], [0.0, -1.0 - 1e-9]], 2.0),
        ([[2.0, 1.0], [-1.0, 2.0]], 3.0),
        ([[0.0, 1.0], [-1.0, 0.0]], std::f64::consts::TAU),
        ([[0.0, 0.0], [0.0, 0.0]], 1.0),
        ([[-7.0, 0.0], [0.0, 3.0]], 2.0),
        // Nearly repeated eigenvalues on a nearly singular block, real and complex.
        ([[-1e-3, 5.0], [0.0, -1e-3 - 1e-9]], 2.0),
        ([[-1e-3, 5.0], [-1e-12, -1e-3]], 2.0),
        ([[0.3, 40.0], [-1e-7, 0.3]], 1.0),
        ([[-0.5, 40.0], [1e-5, -0.5]], 1.0),
        ([[-0.2, 40.0], [0.0, -0.2]], 1.0),
        ([[0.6, -0.3], [0.3, 0.0]], 1.0),
    ] {
        blocks.push((a, h));
    }
    let mut closed = 0;
    for (a, h) in blocks {
        let Some(f) = flow(&a, h) else {
            continue;
        };
        let (e, j) = reference(&a, h);
        let scale_e = e.iter().flatten().fold(1.0f64, |s, x| s.max(x.abs()));
        // `h max |exp(A s)|` over the interval: sampled at the reference's end and start.
        let scale_j = h * scale_e;
        assert_flow_near(&f, (&e, &j), (1e-13 * scale_e, 1e-13 * scale_j), (&a, h));
        let ah = [[a[0][0] * h, a[0][1] * h], [a[1][0] * h, a[1][1] * h]];
        if block_phi1(&ah).is_some() {
            closed += 1;
        }
    }
    assert!(closed > 150, "{closed}");
    // A stiff tilt over a soft angle (`||A|| h` ~ 45, determinant ~ 1e-4 of `||A||^2`) takes the
    // closed form.
    let a = onion_block(0.03, 1e-2, 44.0);
    assert!(block_phi1(&a).is_some());
}

/// A strongly overdamped switch interval, `m h = -1000` and `w h` about 999 (eigenvalues about
/// -1 and -1999 per interval; `e^{m h} cosh(w h)` formed apart is `0 x inf`): the flow is taken
/// and is the eigen-decomposition's, `sum_i f(mu_i) P_i`, `P_1 = (A - mu_2 I) / (mu_1 - mu_2)`,
/// with `f = e^{mu h}` and `(e^{mu h} - 1) / mu`, for a symmetric block and eq. 3.4's onion
/// block under heavy damping.
#[test]
fn a_long_overdamped_interval_is_taken() {
    let alpha = 3.0;
    let (d, t) = (1e-3, 40.0);
    let onion = onion_block(alpha, d, t);
    let h_onion = 1000.0 / (0.5 * alpha * (d + t));
    for (a, h) in [
        ([[-1000.0, 999.0], [999.0, -1000.0]], 1.0),
        (onion, h_onion),
    ] {
        let m = 0.5 * (a[0][0] + a[1][1]);
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let fast = m - (m * m - det).sqrt();
        let slow = det / fast;
        assert!((m * h + 1000.0).abs() < 1e-9 && slow * h > -1.5 && fast * h < -1998.0);
        let projector = |mu: f64, other: f64| -> M2 {
            let r = 1.0 / (mu - other);
            [
                [(a[0][0] - other) * r, a[0][1] * r],
                [a[1][0] * r, (a[1][1] - other) * r],
            ]
        };
        let (p_slow, p_fast) = (projector(slow, fast), projector(fast, slow));
        let combine = |fs: f64, ff: f64| -> M2 {
            std::array::from_fn(|i| std::array::from_fn(|k| fs * p_slow[i][k] + ff * p_fast[i][k]))
        };
        let e = combine((slow * h).exp(), (fast * h).exp());
        let j = combine((slow * h).exp_m1() / slow, (fast * h).exp_m1() / fast);
        let f = flow(&a, h).unwrap_or_else(|| panic!("{a:?} {h}: declined"));
        let scale_e = e.iter().flatten().fold(0.0f64, |s, x| s.max(x.abs()));
        let scale_j = j.iter().flatten().fold(0.0f64, |s, x| s.max(x.abs()));
        assert_flow_near(&f, (&e, &j), (1e-12 * scale_e, 1e-12 * scale_j), (&a, h));
    }
}
