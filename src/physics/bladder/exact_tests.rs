//! The exact wall against independent truths: eq. 2.3 with no rubber stiffness, an adaptive
//! quadrature of the thick tube written here (in the deformed radius, with the rubber's force
//! by integration by parts rather than the kernel's exchange of integration order), the energy
//! of the same kinematics, the thin-wall limit, and the layers' order of convergence.

use super::*;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::MuscleGeometry;

const MUSCLES: [(char, MuscleGeometry); 4] = [
    ('A', MuscleGeometry::muscle_a()),
    ('B', MuscleGeometry::muscle_b()),
    ('C', MuscleGeometry::muscle_c()),
    ('D', MuscleGeometry::muscle_d()),
];

fn bladder_of(g: &MuscleGeometry, tube: BladderTube, wall: Wall) -> Bladder<Sleeve> {
    Bladder::with_wall(g.sleeve().unwrap(), tube, wall).unwrap()
}

/// Lengths from 0.6 of the listed length to just inside `max_length` (0.9999 of the way).
fn lengths(g: &MuscleGeometry, bl: &Bladder<Sleeve>, count: usize) -> Vec<f64> {
    let (lo, hi) = (
        (0.6 * g.length).max(bl.min_length() * 1.001),
        bl.max_length(),
    );
    (0..count)
        .map(|i| {
            let f = i as f64 / (count - 1) as f64;
            lo + (hi - lo) * f.min(0.9999)
        })
        .collect()
}

#[test]
fn zero_stiffness_gives_eq_2_3_for_the_consistent_walls_only() {
    // With C1 = C2 = 0 the rubber only takes up volume, so the force is eq. 2.3 exactly.
    let walls = [
        Wall::Exact(1),
        Wall::Exact(16),
        Wall::Layers(1),
        Wall::Layers(16),
    ];
    let mut worst: f64 = 0.0;
    for (_, g) in MUSCLES {
        let tube = BladderTube {
            mooney_c1: 0.0,
            mooney_c2: 0.0,
            ..g.tube()
        };
        let sleeve = g.sleeve().unwrap();
        for wall in walls {
            let bl = bladder_of(&g, tube, wall);
            for l in lengths(&g, &bl, 25) {
                for p in [0.0, 1e3, 100e3, 345e3, 690e3, 700e3] {
                    let s = bl.evaluate(p, l).unwrap();
                    let ideal = sleeve.force(p, l);
                    let err = (s.force - ideal).abs() / ideal.abs().max(f64::MIN_POSITIVE);
                    assert!(s.contact && s.effective_pressure == p, "{wall:?} {l} {p}");
                    if p == 0.0 {
                        assert!(s.force.abs() < 1e-12, "{wall:?} {l}: {}", s.force);
                    } else {
                        worst = worst.max(err);
                    }
                }
            }
        }
    }
    println!("zero stiffness: largest relative deviation from eq. 2.3 {worst:.2e}");
    assert!(worst < 1e-12, "{worst:e}");
    // The dissertation's walls as written fail it: muscle A at 690 kPa and 92.9 mm gives 53.0 N
    // by eq. 2.3, but 127.2 N (P_eff 1,445 kPa) thin and 132.9 N (1,588 kPa) with 16 layers.
    let g = MuscleGeometry::muscle_a();
    let tube = BladderTube {
        mooney_c1: 0.0,
        mooney_c2: 0.0,
        ..g.tube()
    };
    let ideal = g.sleeve().unwrap().force(690e3, 0.0929);
    assert!((ideal - 53.0).abs() < 0.05, "{ideal}");
    for (wall, force, p_eff) in [
        (Wall::DissertationLayers(1), 127.2, 1445e3),
        (Wall::DissertationLayers(16), 132.9, 1588e3),
        (Wall::DissertationContinuum(16), 133.4, 1600e3),
    ] {
        let s = bladder_of(&g, tube, wall).evaluate(690e3, 0.0929).unwrap();
        assert!((s.force - force).abs() < 0.05, "{wall:?}: {}", s.force);
        assert!((s.effective_pressure - p_eff).abs() < 0.5e3, "{wall:?}");
    }
}

/// Adaptive quadrature on `[a, b]`: 5-point Gauss-Legendre on an interval against the sum over
/// its halves, split until they agree to `tol` (absolute).
fn adaptive(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64, depth: usize) -> f64 {
    fn gauss5(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
        let s70 = 70f64.sqrt();
        let (x1, x2) = (
            (5.0 - 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0,
            (5.0 + 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0,
        );
        let (w0, w1, w2) = (
            128.0 / 225.0,
            (322.0 + 13.0 * s70) / 900.0,
            (322.0 - 13.0 * s70) / 900.0,
        );
        let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
        h * (w0 * f(m)
            + w1 * (f(m - h * x1) + f(m + h * x1))
            + w2 * (f(m - h * x2) + f(m + h * x2)))
    }
    fn go(f: &dyn Fn(f64) -> f64, a: f64, b: f64, whole: f64, tol: f64, depth: usize) -> f64 {
        let m = 0.5 * (a + b);
        let (l, r) = (gauss5(f, a, m), gauss5(f, m, b));
        // Converged, or at the rounding of the parts themselves.
        let floor = 1e-15 * (l.abs() + r.abs());
        if (l + r - whole).abs() <= tol.max(floor) || depth == 0 {
            l + r
        } else {
            go(f, a, m, l, 0.5 * tol, depth - 1) + go(f, m, b, r, 0.5 * tol, depth - 1)
        }
    }
    go(f, a, b, gauss5(f, a, b), tol, depth)
}

/// The thick tube written out in the deformed radius `r` (independent of the kernel's variables
/// and of its exchange of integration order). Material radius `R(r)` from incompressibility
/// (eq. 2.20), `R^2 = R_o^2 - lambda_z (r_o^2 - r^2)`.
struct Tube {
    c1: f64,
    c2: f64,
    r_in: f64,
    r_out: f64,
    lz: f64,
}

impl Tube {
    fn new(t: &BladderTube, length: f64) -> Self {
        Self {
            c1: t.mooney_c1,
            c2: t.mooney_c2,
            r_in: t.inner_diameter / 2.0,
            r_out: t.inner_diameter / 2.0 + t.thickness,
            lz: length / t.unstretched_length,
        }
    }

    /// `(h, g) = (sigma_tt - sigma_rr, sigma_zz - sigma_rr)` at deformed radius `r` of a wall
    /// whose outer radius is `ro` (eq. 2.9a-b with the principal stretches).
    fn differences(&self, r: f64, ro: f64) -> (f64, f64) {
        let big_r = (self.r_out * self.r_out - self.lz * (ro * ro - r * r)).sqrt();
        let lt = r / big_r;
        let lr = 1.0 / (self.lz * lt);
        let diff = |a: f64, b: f64| {
            2.0 * self.c1 * (a * a - b * b) - 2.0 * self.c2 * (1.0 / (a * a) - 1.0 / (b * b))
        };
        (diff(lt, lr), diff(self.lz, lr))
    }

    fn inner_radius(&self, ro: f64) -> f64 {
        (ro * ro - (self.r_out * self.r_out - self.r_in * self.r_in) / self.lz).sqrt()
    }

    /// `int h dr / r` through the wall (`P - P_eff`), in `ln r`.
    fn pressure_drop(&self, ro: f64, tol: f64) -> f64 {
        let ri = self.inner_radius(ro);
        let f = |t: f64| self.differences(t.exp(), ro).0;
        adaptive(&f, ri.ln(), ro.ln(), tol, 30)
    }

    /// `int (2 g - h) pi r dr` through the wall, in `ln r`: the rubber's axial force plus what
    /// the pressures on the wall add (integration by parts of `int p 2 pi r dr`).
    fn wall_force(&self, ro: f64, tol: f64) -> f64 {
        let ri = self.inner_radius(ro);
        let f = |t: f64| {
            let r = t.exp();
            let (h, g) = self.differences(r, ro);
            (2.0 * g - h) * std::f64::consts::PI * r * r
        };
        adaptive(&f, ri.ln(), ro.ln(), tol, 30)
    }
}

/// The muscle's force by the independent quadrature: in contact (`ro` = the sleeve's radius)
/// `F = P_eff (3 L^2 - b^2) / (4 pi n^2) + int (2 g - h) pi r dr`; free, `P_eff = 0` at the
/// outer radius found by bisection, and `F = int (2 g - h) pi r dr`.
fn independent_force(g: &MuscleGeometry, p: f64, l: f64) -> (f64, bool) {
    let tube = Tube::new(&g.tube(), l);
    let (b, n) = (g.strand_length, g.turns);
    let ro = ((b * b - l * l) / (n * n * PI * PI)).sqrt() / 2.0;
    let scale = 2.0 * (g.tube().mooney_c1 + g.tube().mooney_c2);
    let p_eff = p - tube.pressure_drop(ro, 1e-13 * scale);
    let force_scale = scale * ro * ro;
    if p_eff >= 0.0 {
        let f = p_eff * (3.0 * l * l - b * b) / (4.0 * PI * n * n)
            + tube.wall_force(ro, 1e-13 * force_scale);
        return (f, true);
    }
    // Free: P_eff rises from negative at the sleeve to P at the unstrained radius and beyond.
    let mut lo = ((tube.r_out.powi(2) - tube.r_in.powi(2)) / tube.lz).sqrt() * (1.0 + 1e-12);
    let mut hi = ro;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if p - tube.pressure_drop(mid, 1e-13 * scale) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-16 * hi {
            break;
        }
    }
    let root = 0.5 * (lo + hi);
    (tube.wall_force(root, 1e-13 * force_scale), false)
}

#[test]
fn exact_wall_matches_an_independent_adaptive_quadrature() {
    // Muscles A-D, 0-700 kPa, 0.6 of the listed length to just inside max_length, contact and
    // free; relative to the largest force of each pressure's curve.
    let mut worst: f64 = 0.0;
    let (mut contact, mut free) = (0, 0);
    for (name, g) in MUSCLES {
        let bl = bladder_of(&g, g.tube(), Wall::Exact(16));
        for p in [0.0, 50e3, 150e3, 345e3, 500e3, 700e3] {
            let ls = lengths(&g, &bl, 12);
            let rows: Vec<(f64, f64, bool, bool)> = ls
                .iter()
                .map(|&l| {
                    let s = bl.evaluate(p, l).unwrap();
                    let (f, c) = independent_force(&g, p, l);
                    (s.force, f, s.contact, c)
                })
                .collect();
            let peak = rows.iter().fold(0.0f64, |m, r| m.max(r.1.abs()));
            for (l, (ours, truth, c_ours, c_truth)) in ls.iter().zip(rows) {
                assert_eq!(c_ours, c_truth, "{name} {p} {l}");
                if c_ours {
                    contact += 1
                } else {
                    free += 1
                }
                let err = (ours - truth).abs() / peak;
                assert!(
                    err < 1e-9,
                    "{name} {p} Pa {l} m: {ours} vs {truth} ({err:e})"
                );
                worst = worst.max(err);
            }
        }
    }
    println!("exact wall (16 nodes) vs adaptive quadrature: {worst:.2e} of the curve's peak ({contact} in contact, {free} free)");
    assert!(contact > 50 && free > 20, "{contact} {free}");
}

#[test]
fn exact_wall_agrees_with_the_energy_of_the_same_kinematics() {
    // F = dW/dL + P (3 L^2 - b^2) / (4 pi n^2), W = L_R0 int W_MR 2 pi R dR (eq. 2.8): muscle A
    // at 690 kPa and 0.9 of its length gives 37.1549 N.
    let g = MuscleGeometry::muscle_a();
    let t = g.tube();
    let (b, n) = (g.strand_length, g.turns);
    let energy = |l: f64| {
        let lz = l / t.unstretched_length;
        let ro = ((b * b - l * l) / (n * n * PI * PI)).sqrt() / 2.0;
        let (ri0, ro0) = (t.inner_diameter / 2.0, t.inner_diameter / 2.0 + t.thickness);
        let density = |big_r: f64| {
            let r = (ro * ro - (ro0 * ro0 - big_r * big_r) / lz).sqrt();
            let lt = r / big_r;
            let lr = 1.0 / (lz * lt);
            let (a, b2, c) = (lz * lz, lt * lt, lr * lr);
            (t.mooney_c1 * (a + b2 + c - 3.0) + t.mooney_c2 * (a * b2 + b2 * c + c * a - 3.0))
                * 2.0
                * PI
                * big_r
        };
        t.unstretched_length * adaptive(&density, ri0, ro0, 0.0, 24)
    };
    let l = 0.9 * g.length;
    // Richardson-extrapolated central differences.
    let d = |h: f64| (energy(l + h) - energy(l - h)) / (2.0 * h);
    let h = 1e-4 * l;
    let dw = (4.0 * d(h / 2.0) - d(h)) / 3.0;
    let p = 690e3;
    let by_energy = dw + p * (3.0 * l * l - b * b) / (4.0 * PI * n * n);
    let exact = bladder_of(&g, t, Wall::Exact(16))
        .evaluate(p, l)
        .unwrap()
        .force;
    println!("muscle A, 690 kPa, 0.9 L: exact wall {exact:.6} N, energy {by_energy:.6} N");
    assert!((by_energy - 37.1549).abs() < 5e-4, "{by_energy}");
    assert!(
        (exact - by_energy).abs() < 1e-6 * by_energy,
        "{exact} {by_energy}"
    );
    // The dissertation's walls there: 102.6 N with 16 layers, 105.0 N in their limit.
    for (wall, force) in [
        (Wall::DissertationLayers(16), 102.6),
        (Wall::DissertationContinuum(16), 105.0),
    ] {
        let literal = bladder_of(&g, t, wall).evaluate(p, l).unwrap().force;
        assert!((literal - force).abs() < 0.05, "{wall:?}: {literal}");
    }
}

#[test]
fn exact_wall_tends_to_the_thin_wall_as_the_wall_thins() {
    // Muscle D's tube with its wall thinned: the wall's share of the force (F minus eq. 2.3)
    // of the exact wall and of its thin-wall limit differ by O(t / D).
    let g = MuscleGeometry::muscle_d();
    let mut last = f64::INFINITY;
    for scale in [1.0, 0.1, 0.01] {
        let tube = BladderTube {
            thickness: g.bladder_thickness * scale,
            ..g.tube()
        };
        let (exact, thin) = (
            bladder_of(&g, tube, Wall::Exact(16)),
            bladder_of(&g, tube, Wall::Layers(1)),
        );
        let ideal = g.sleeve().unwrap();
        let mut worst: f64 = 0.0;
        for l in lengths(&g, &exact, 20).into_iter().take(18) {
            let p = 300e3;
            let (e, t) = (
                exact.evaluate(p, l).unwrap().force,
                thin.evaluate(p, l).unwrap().force,
            );
            let wall_share = (e - ideal.force(p, l)).abs();
            worst = worst.max((e - t).abs() / wall_share.max(1e-12));
        }
        println!("thickness x{scale}: thin vs exact, {worst:.2e} of the wall's share");
        // First order in the thickness: 40% of the wall's share at muscle D's own wall
        // (t / D_RI = 6.6%), a tenth of that per tenth of the wall.
        assert!(
            worst < 0.5 * scale && worst < last / 8.0,
            "{scale}: {worst}"
        );
        last = worst;
    }
}

#[test]
fn layers_converge_to_the_exact_wall_at_first_order() {
    // The layer recursion read with the stress difference is a Riemann sum of the exact wall:
    // doubling the layers halves the error. Muscle A at 690 kPa and 0.9 L: 37.13 N at 1,024.
    let g = MuscleGeometry::muscle_a();
    let (p, l) = (690e3, 0.9 * g.length);
    let exact = bladder_of(&g, g.tube(), Wall::Exact(32))
        .evaluate(p, l)
        .unwrap()
        .force;
    let err = |n: usize| {
        bladder_of(&g, g.tube(), Wall::Layers(n))
            .evaluate(p, l)
            .unwrap()
            .force
            - exact
    };
    let errors: Vec<f64> = [64, 128, 256, 512, 1024].iter().map(|&n| err(n)).collect();
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("layers 64..1024: errors {errors:?} N, orders {orders:?}");
    for o in &orders {
        assert!((o - 1.0).abs() < 0.05, "{orders:?}");
    }
    assert!(
        (exact + errors[4] - 37.13).abs() < 0.005,
        "{}",
        exact + errors[4]
    );
}

#[test]
fn exact_wall_quadrature_converges_geometrically() {
    // Nodes against the 64-node wall over muscles A-D's ranges at 0 and 690 kPa.
    for (name, g) in MUSCLES {
        let reference = bladder_of(&g, g.tube(), Wall::Exact(64));
        let ls = lengths(&g, &reference, 30);
        let err = |nodes: usize| {
            let bl = bladder_of(&g, g.tube(), Wall::Exact(nodes));
            let mut worst: f64 = 0.0;
            for p in [0.0, 690e3] {
                let f: Vec<(f64, f64)> = ls
                    .iter()
                    .map(|&l| {
                        (
                            bl.evaluate(p, l).unwrap().force,
                            reference.evaluate(p, l).unwrap().force,
                        )
                    })
                    .collect();
                let peak = f.iter().fold(0.0f64, |m, r| m.max(r.1.abs()));
                worst = f.iter().fold(worst, |m, r| m.max((r.0 - r.1).abs() / peak));
            }
            worst
        };
        let e: Vec<f64> = [2, 4, 8, 16].iter().map(|&n| err(n)).collect();
        println!("muscle {name}: 2/4/8/16 nodes {e:?}");
        assert!(e[2] < 1e-6 && e[3] < 1e-11, "{name}: {e:?}");
    }
}
