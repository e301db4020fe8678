use super::*;
use crate::physics::bladder::{Bladder, Wall, MOONEY_C1, MOONEY_C2};
use crate::physics::gaylord::Sleeve;
use approx::assert_relative_eq;

/// Table 2.1's tubes: (unstretched length, inner diameter, thickness), SI units.
const TUBE_A: (f64, f64, f64) = (0.1005, 1.6e-3, 1.6e-3);
const TUBE_D: (f64, f64, f64) = (0.1336, 3.8e-3, 0.25e-3);

fn tube((unstretched_length, inner_diameter, thickness): (f64, f64, f64)) -> BladderTube {
    BladderTube {
        inner_diameter,
        thickness,
        unstretched_length,
        mooney_c1: MOONEY_C1,
        mooney_c2: MOONEY_C2,
    }
}

fn free(t: (f64, f64, f64)) -> FreeBladder {
    FreeBladder::new(tube(t)).unwrap()
}

#[test]
fn holds_the_pressure_by_rivlins_integral() {
    // Independently of the closed form: P = int h dr / r through the deformed wall (eq. 2.9b's
    // hoop difference, radial equilibrium), by composite Simpson in ln r from the state's radii.
    for (t, p, lam) in [
        (TUBE_A, 345e3, 0.75),
        (TUBE_A, -5e4, 1.2),
        (TUBE_D, 3e4, 1.0),
        (TUBE_D, 4e4, 1.5),
        (TUBE_D, -101325.0, 0.8),
    ] {
        let b = free(t);
        let s = b.evaluate(p, lam * t.0).unwrap();
        let (ri, ro) = (s.inner_diameter / 2.0, s.outer_diameter / 2.0);
        let r_out0 = t.1 / 2.0 + t.2;
        let h = |r: f64| {
            let big_r = (r_out0 * r_out0 - lam * (ro * ro - r * r)).sqrt();
            let (lt, lr) = (r / big_r, big_r / (lam * r));
            2.0 * MOONEY_C1 * (lt * lt - lr * lr)
                - 2.0 * MOONEY_C2 * (1.0 / (lt * lt) - 1.0 / (lr * lr))
        };
        let n = 20_000;
        let (a, z) = (ri.ln(), ro.ln());
        let step = (z - a) / n as f64;
        let held: f64 = (0..=n)
            .map(|i| {
                let weight = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                weight * h((a + step * i as f64).exp())
            })
            .sum::<f64>()
            * step
            / 3.0;
        assert!(
            (held - p).abs() <= 1e-9 * (MOONEY_C1 + p.abs()),
            "{p} {lam}: {held}"
        );
        assert_relative_eq!(s.stretch_axial, lam, max_relative = 1e-15);
        assert_relative_eq!(
            b.equilibrium_pressure(s.stretch_axial, s.stretch_hoop),
            p,
            max_relative = 1e-12,
            epsilon = 1e-6
        );
        // The inner wall's hoop stress: sigma_33 = -P there, exactly.
        let (l1, l2) = (s.stretch_axial, s.stretch_hoop);
        let l3 = 1.0 / (l1 * l2);
        let hoop = 2.0 * MOONEY_C1 * (l2 * l2 - l3 * l3)
            - 2.0 * MOONEY_C2 * (1.0 / (l2 * l2) - 1.0 / (l3 * l3))
            - p;
        assert_relative_eq!(s.stress_hoop, hoop, max_relative = 1e-12, epsilon = 1e-6);
    }
}

#[test]
fn is_the_mckibben_bladders_free_branch() {
    // The same tube inside Table 2.1 muscle A's sleeve, off the sleeve (P below the threshold
    // pressure): the muscle's exact wall integrates through the wall by quadrature and finds the
    // free diameter numerically, this one in closed form.
    let sleeved = Bladder::with_wall(
        Sleeve::new(0.1113, 3.74).unwrap(),
        tube(TUBE_A),
        Wall::Exact(32),
    )
    .unwrap();
    let b = free(TUBE_A);
    for (p, f) in [(345e3, 0.7), (1e5, 0.85), (0.0, 0.6), (-5e4, 0.8)] {
        let l = f * 0.10325;
        let m = sleeved.evaluate(p, l).unwrap();
        assert!(!m.contact);
        let s = b.evaluate(p, l).unwrap();
        assert_relative_eq!(s.inner_diameter, m.inner_diameter, max_relative = 1e-12);
        assert_relative_eq!(s.outer_diameter, m.outer_diameter, max_relative = 1e-12);
        assert_relative_eq!(s.fluid_volume, m.fluid_volume, max_relative = 1e-12);
        assert_relative_eq!(
            s.stress_axial,
            m.stress_axial,
            max_relative = 1e-10,
            epsilon = 1e-3
        );
        assert_relative_eq!(
            s.stress_hoop,
            m.stress_hoop,
            max_relative = 1e-10,
            epsilon = 1e-3
        );
        assert_relative_eq!(s.force, m.force, max_relative = 1e-10, epsilon = 1e-9);
    }
}

#[test]
fn unpressurized_tube_is_uniaxial_mooney_rivlin() {
    // P = 0: the hoop is unstressed, lambda_2 = lambda_3 = lambda^-1/2, and the clamp force is the
    // uniaxial Mooney-Rivlin curve of Fig. 2.9, 2 (C1 + C2/lambda)(lambda - 1/lambda^2) A_0.
    for t in [TUBE_A, TUBE_D] {
        let b = free(t);
        let a0 = b.rubber_volume() / t.0;
        for lam in [0.6, 1.0, 1.5, 3.0, 6.0] {
            let s = b.evaluate(0.0, lam * t.0).unwrap();
            let expect = 2.0 * (MOONEY_C1 + MOONEY_C2 / lam) * (lam - 1.0 / (lam * lam)) * a0;
            assert_relative_eq!(s.force, expect, max_relative = 1e-12, epsilon = 1e-15);
            assert_relative_eq!(s.stretch_hoop, 1.0 / lam.sqrt(), max_relative = 1e-14);
            assert!(s.stress_hoop.abs() < 1e-9);
        }
        // At its own length and zero pressure the tube is relaxed.
        let s = b.evaluate(0.0, t.0).unwrap();
        assert_eq!(s.stretch_hoop, 1.0);
        assert_eq!(s.inner_diameter, t.1);
        assert_relative_eq!(s.outer_diameter, t.1 + 2.0 * t.2, max_relative = 1e-15);
        assert_eq!(s.force, 0.0);
    }
}

#[test]
fn balloons_at_the_exact_asymptote() {
    // Muscle D's thin wide tube at its own length: 2 (C1 + C2) ln(D_RO / D_RI) = 49.45 kPa (the
    // dissertation's thin wall, eq. 2.18, gives 2 (C1 + C2) 2t / D_RI = 52.63 kPa); muscles A-C's
    // tube 439.4 kPa (eq. 2.18: 800 kPa).
    let b = free(TUBE_D);
    let l = TUBE_D.0;
    let limit = 2.0 * (MOONEY_C1 + MOONEY_C2) * (4.3f64 / 3.8).ln();
    assert_relative_eq!(b.ballooning_pressure(l), limit, max_relative = 1e-14);
    assert_relative_eq!(limit, 49_445.58, max_relative = 1e-6);
    assert_relative_eq!(
        free(TUBE_A).ballooning_pressure(TUBE_A.0),
        439_444.9,
        max_relative = 1e-6
    );
    assert!(b.evaluate(limit, l).is_err());
    assert!(b.evaluate(2.0 * limit, l).is_err());
    // Below it the volume rises monotonically, and without bound as the limit nears.
    let mut last = 0.0;
    for k in 0..=1000 {
        let p = -101325.0 + (limit + 101325.0) * (1.0 - 1e-6) * k as f64 / 1000.0;
        let s = b.evaluate(p, l).unwrap();
        assert!(s.fluid_volume > last && s.compliance > 0.0, "{p}");
        last = s.fluid_volume;
    }
    let near = |gap: f64| b.evaluate(limit * (1.0 - gap), l).unwrap().fluid_volume;
    // As the gap's inverse square root: the wall's 1/w terms cancel in Rivlin's integral.
    assert!(near(1e-6) > 30.0 * near(1e-3));
    // Stretching the tube axially stiffens its C2 term and softens its C1 term (the modulus A).
    assert!(b.ballooning_pressure(0.5 * l) > limit);
}

#[test]
fn compliance_is_the_pressure_slope_of_volume() {
    for (t, p, lam) in [
        (TUBE_A, 2e5_f64, 1.0),
        (TUBE_D, 4e4, 1.3),
        (TUBE_D, -5e4, 0.9),
    ] {
        let b = free(t);
        let l = lam * t.0;
        let v = |p: f64| b.evaluate(p, l).unwrap().fluid_volume;
        let h = 1e-5 * p.abs();
        let slope = (v(p + h) - v(p - h)) / (2.0 * h);
        assert_relative_eq!(
            b.evaluate(p, l).unwrap().compliance,
            slope,
            max_relative = 1e-6
        );
    }
}

#[test]
fn rejects_bad_parameters_and_inputs() {
    let good = tube(TUBE_D);
    for bad in [
        BladderTube {
            inner_diameter: 0.0,
            ..good
        },
        BladderTube {
            thickness: f64::NAN,
            ..good
        },
        BladderTube {
            unstretched_length: -1.0,
            ..good
        },
        BladderTube {
            mooney_c1: 0.0,
            mooney_c2: 0.0,
            ..good
        },
        BladderTube {
            mooney_c2: -1.0,
            ..good
        },
    ] {
        assert!(FreeBladder::new(bad).is_err(), "{bad:?}");
    }
    let b = free(TUBE_D);
    assert!(b.evaluate(f64::NAN, 0.1).is_err());
    assert!(b.evaluate(0.0, 0.0).is_err());
    assert!(b.evaluate(0.0, f64::INFINITY).is_err());
}

/// Every field of a state, named, in one order (for comparing partials field by field).
fn fields(s: &FreeBladderState) -> [(&'static str, f64); 11] {
    [
        ("inner_diameter", s.inner_diameter),
        ("outer_diameter", s.outer_diameter),
        ("fluid_volume", s.fluid_volume),
        ("compliance", s.compliance),
        ("stretch_axial", s.stretch_axial),
        ("stretch_hoop", s.stretch_hoop),
        ("stretch_radial", s.stretch_radial),
        ("stress_axial", s.stress_axial),
        ("stress_hoop", s.stress_hoop),
        ("force", s.force),
        ("ballooning_pressure", s.ballooning_pressure),
    ]
}

#[test]
fn partials_match_central_differences_across_the_range() {
    // Both tubes of Table 2.1 (thin D, thick A), vacuum to 99.9% of the ballooning pressure,
    // compressed, relaxed and pre-strained (axial stretch 0.5 to 3).
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for t in [TUBE_A, TUBE_D] {
        let b = free(t);
        for lam in [0.5, 0.8, 1.0, 1.3, 2.0, 3.0] {
            let l = lam * t.0;
            let top = b.ballooning_pressure(l);
            for p in [
                -101_325.0,
                -3e4,
                0.0,
                0.2 * top,
                0.6 * top,
                0.9 * top,
                0.99 * top,
                0.999 * top,
            ] {
                let (state, partials) = b.evaluate_with_partials(p, l).unwrap();
                // Natural sizes of the fields: diameters, volumes, compliance, stretches, stresses
                // (Pa), force (N), ballooning pressure.
                let d_ro = t.1 + 2.0 * t.2;
                let stress = MOONEY_C1 + MOONEY_C2 + p.abs();
                let floors = [
                    d_ro,
                    d_ro,
                    state.fluid_volume,
                    state.compliance,
                    1.0,
                    1.0,
                    1.0,
                    stress,
                    stress,
                    stress * b.rubber_volume() / l,
                    stress,
                ];
                assert_eq!(state, b.evaluate(p, l).unwrap());
                // Steps well inside the distance to the ballooning pressure, where w blows up
                // (the length moves that pressure: 1e-6 of the length is 1e-3 of the gap at
                // 0.999 of it).
                let gap = (top - p).min(top) / top;
                let hp = 1e-4 * gap * top;
                let hl = 1e-4 * gap.min(1e-2) * l;
                let at = |p: f64, l: f64| fields(&b.evaluate(p, l).unwrap());
                for (h, input_scale, up, down, exact) in [
                    (
                        hp,
                        top,
                        at(p + hp, l),
                        at(p - hp, l),
                        fields(&partials.by_pressure),
                    ),
                    (
                        hl,
                        l,
                        at(p, l + hl),
                        at(p, l - hl),
                        fields(&partials.by_length),
                    ),
                ] {
                    let zipped = up.iter().zip(&down).zip(&exact).zip(floors);
                    for ((((name, hi), (_, lo)), (_, e)), floor) in zipped {
                        let central = (hi - lo) / (2.0 * h);
                        // Relative, with an absolute floor for partials that vanish (the hoop
                        // stress's at zero pressure): 1e-8 of the output's natural size per the
                        // input's, above the differences' rounding.
                        let scale = e.abs().max(central.abs()) + 1e-2 * floor / input_scale;
                        let err = (e - central).abs() / scale;
                        assert!(
                            err < 1e-6,
                            "{t:?} P={p} lambda={lam}: d{name} exact {e}, central {central}"
                        );
                        worst = worst.max(err);
                        checked += 1;
                    }
                }
            }
        }
    }
    eprintln!("free bladder partials: {checked} against central differences, worst {worst:.1e}");
    assert!(checked > 900);
}

#[test]
fn partials_are_eq_2_18s_slopes_where_known_in_closed_form() {
    let b = free(TUBE_D);
    let l = TUBE_D.0;
    let (s, d) = b.evaluate_with_partials(2e4, l).unwrap();
    // Compliance is dV/dP (the field and the partial are one formula apart).
    assert_relative_eq!(
        d.by_pressure.fluid_volume,
        s.compliance,
        max_relative = 1e-12
    );
    // The axial stretch and the ballooning pressure do not depend on the pressure.
    assert_eq!(d.by_pressure.stretch_axial, 0.0);
    assert_eq!(d.by_pressure.ballooning_pressure, 0.0);
    assert_eq!(d.by_length.stretch_axial, 1.0 / l);
    // Relaxed tube (P = 0, lambda = 1): lambda_2 = lambda_1^-1/2, so dlambda_2/dL = -1/(2 L_0),
    // and the uniaxial clamp force's slope is 6 (C1 + C2) A_0 / L_0 (Fig. 2.9 at lambda = 1).
    let (_, d) = b.evaluate_with_partials(0.0, l).unwrap();
    assert_relative_eq!(d.by_length.stretch_hoop, -0.5 / l, max_relative = 1e-12);
    let a0 = b.rubber_volume() / l;
    assert_relative_eq!(
        d.by_length.force,
        6.0 * (MOONEY_C1 + MOONEY_C2) * a0 / l,
        max_relative = 1e-12
    );
    let along = d.along(2.0, -3.0);
    assert_relative_eq!(
        along.force,
        2.0 * d.by_pressure.force - 3.0 * d.by_length.force,
        max_relative = 1e-15
    );
}
