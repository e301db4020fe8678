use super::*;
use crate::physics::bladder::{Bladder, MOONEY_C1, MOONEY_C2};
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
fn solves_eq_2_18_and_eq_2_11_as_written() {
    for (t, p, lam) in [
        (TUBE_A, 345e3, 0.75),
        (TUBE_A, -5e4, 1.2),
        (TUBE_D, 3e4, 1.0),
        (TUBE_D, 4e4, 1.5),
        (TUBE_D, -101325.0, 0.8),
    ] {
        let b = free(t);
        let (d_ri, d_ro) = (t.1, t.1 + 2.0 * t.2);
        let s = b.evaluate(p, lam * t.0).unwrap();
        let (l1, l2) = (s.stretch_axial, s.stretch_hoop);
        let l3 = 1.0 / (l1 * l2);
        assert_relative_eq!(l1, lam, max_relative = 1e-15);
        assert_relative_eq!(s.stretch_radial, l3, max_relative = 1e-15);
        // Eq. 2.18.
        let lhs = p * (l3 + l2 * d_ri / (d_ro - d_ri));
        let rhs = 2.0 * MOONEY_C1 * (l2 / l1 - 1.0 / (l1.powi(3) * l2.powi(3)))
            - 2.0 * MOONEY_C2 * (1.0 / (l1 * l2.powi(3)) - l1 * l2);
        assert!(
            (lhs - rhs).abs() <= 1e-12 * (MOONEY_C1 + p.abs()),
            "{p} {lam}: {lhs} {rhs}"
        );
        // Eq. 2.11 with P_eff = 0: the hoop stress carries the pressure across the wall.
        let hoop = p * s.inner_diameter / (l3 * (d_ro - d_ri));
        assert_relative_eq!(s.stress_hoop, hoop, max_relative = 1e-11, epsilon = 1e-6);
        assert_relative_eq!(
            b.equilibrium_pressure(l1, l2),
            p,
            max_relative = 1e-12,
            epsilon = 1e-6
        );
    }
}

#[test]
fn is_the_mckibben_bladders_free_branch() {
    // The same thin tube inside Table 2.1 muscle A's sleeve, off the sleeve (P below the threshold
    // pressure): the shared bladder code solves eq. 2.18 numerically, this one in closed form.
    let sleeved = Bladder::new(Sleeve::new(0.1113, 3.74).unwrap(), tube(TUBE_A), 1).unwrap();
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
fn balloons_at_the_limit_of_eq_2_18() {
    // Muscle D's thin wide tube at its own length: A / r = 2 (C1 + C2) 2t / D_RI = 52.63 kPa.
    let b = free(TUBE_D);
    let l = TUBE_D.0;
    let limit = 2.0 * (MOONEY_C1 + MOONEY_C2) * 2.0 * 0.25 / 3.8 * 1.0;
    assert_relative_eq!(b.ballooning_pressure(l), limit, max_relative = 1e-14);
    assert_relative_eq!(limit, 52_631.6, max_relative = 1e-6);
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
    assert!(near(1e-6) > 100.0 * near(1e-3));
    // Stretching the tube axially stiffens its C2 term and softens its C1 term (eq. 2.18's A).
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
