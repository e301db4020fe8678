//! The wall's stress field against independent truths: the boundary conditions of the thick tube
//! (`-P` inside, the contact pressure the wall's own solve found outside, 0 when free), the
//! equilibrium of a half tube (`int sigma_22 dr = P r_in - P_eff r_out`, by a trapezoid rule
//! written here), the hydrostatic state of a rubber without stiffness, and the inner surface's
//! stresses that `evaluate` reports.

use super::*;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::MuscleGeometry;

fn bladder(wall: Wall, tube: Option<BladderTube>) -> (MuscleGeometry, Bladder<Sleeve>) {
    let g = MuscleGeometry::muscle_a();
    let b = Bladder::with_wall(g.sleeve().unwrap(), tube.unwrap_or(g.tube()), wall).unwrap();
    (g, b)
}

fn field(b: &Bladder<Sleeve>, pressure: f64, length: f64, points: usize) -> Vec<WallPoint> {
    let mut out = vec![WallPoint::default(); points];
    b.wall_field(pressure, length, &mut out).unwrap();
    out
}

/// `int sigma_22 dr` over the wall by the trapezoid rule.
fn hoop_integral(f: &[WallPoint]) -> f64 {
    f.windows(2)
        .map(|w| 0.5 * (w[0].stress_hoop + w[1].stress_hoop) * (w[1].radius - w[0].radius))
        .sum()
}

#[test]
fn the_exact_wall_meets_both_boundary_conditions_and_balances_a_half_tube() {
    let (_, b) = bladder(Wall::Exact(24), None);
    let mut free = 0;
    for length in [0.7, 0.85, 0.95].map(|f| f * b.max_length()) {
        let threshold = b.threshold_pressure(length).unwrap();
        // Free (below the threshold: nothing outside, sigma_33 = 0 there) and in contact.
        for pressure in [0.5 * threshold, threshold + 50e3, 690e3] {
            let s = b.evaluate(pressure, length).unwrap();
            let f = field(&b, pressure, length, 4001);
            let (inner, outer) = (f[0], f[f.len() - 1]);
            assert_eq!(inner.stress_radial, -pressure);
            assert_eq!(s.contact, pressure >= threshold);
            free += usize::from(!s.contact);
            let p_eff = s.effective_pressure;
            let scale = pressure.abs().max(1e3);
            assert!(
                (outer.stress_radial + p_eff).abs() < 1e-9 * scale,
                "L {length} P {pressure}: sigma_33 outside {} vs -P_eff {}",
                outer.stress_radial,
                -p_eff
            );
            assert!((inner.radius - 0.5 * s.inner_diameter).abs() < 1e-15);
            assert!((outer.radius - 0.5 * s.outer_diameter).abs() < 1e-15);
            // A half tube cut along its axis: the hoop force balances the pressures on its
            // inner and outer surfaces (Lame's equilibrium, d(r sigma_33)/dr = sigma_22).
            let balance = pressure * inner.radius - p_eff * outer.radius;
            let hoop = hoop_integral(&f);
            assert!(
                (hoop - balance).abs() < 1e-6 * scale * outer.radius,
                "L {length} P {pressure}: int sigma_22 dr {hoop} vs {balance}"
            );
            // The inner surface is the innermost layer `evaluate` reports.
            assert!((inner.stress_hoop - s.stress_hoop).abs() < 1e-6 * scale);
            assert!((inner.stress_axial - s.stress_axial).abs() < 1e-6 * scale);
        }
    }
    assert!(free >= 2, "free cases: {free}");
}

#[test]
fn the_dissertation_continuum_meets_its_own_contact_pressure() {
    let (_, b) = bladder(Wall::DissertationContinuum(24), None);
    for pressure in [100e3, 345e3, 690e3] {
        let s = b.evaluate(pressure, 0.9 * b.max_length()).unwrap();
        let f = field(&b, pressure, 0.9 * b.max_length(), 33);
        assert_eq!(f[0].stress_radial, -pressure);
        let outer = f[32].stress_radial;
        assert!(
            (outer + s.effective_pressure).abs() < 1e-9 * pressure,
            "P {pressure}: {outer} vs {}",
            -s.effective_pressure
        );
    }
}

#[test]
fn a_rubber_without_stiffness_is_hydrostatic_in_the_exact_family_only() {
    let g = MuscleGeometry::muscle_a();
    let tube = BladderTube {
        mooney_c1: 0.0,
        mooney_c2: 0.0,
        ..g.tube()
    };
    let pressure = 300e3;
    for wall in [Wall::Exact(8), Wall::Layers(8), Wall::Layers(1)] {
        let (_, b) = bladder(wall, Some(tube));
        for p in field(&b, pressure, 0.85 * b.max_length(), 9) {
            for sigma in [p.stress_radial, p.stress_hoop, p.stress_axial] {
                assert!(
                    (sigma + pressure).abs() < 1e-9 * pressure,
                    "{wall:?}: {p:?}"
                );
            }
        }
    }
    // The dissertation's balance (eq. 2.12 per layer) keeps p r / r_in without any stiffness:
    // the term its thin layers drop (see `Wall::DissertationLayers`).
    let (_, b) = bladder(Wall::DissertationContinuum(8), Some(tube));
    let f = field(&b, pressure, 0.85 * b.max_length(), 9);
    for p in &f {
        let expected = pressure * p.radius / f[0].radius;
        assert!(
            (p.stress_radial + expected).abs() < 1e-9 * pressure,
            "{p:?}"
        );
    }
    assert!(f[8].stress_radial < -1.5 * pressure);
}

#[test]
fn outside_the_fill_range_is_an_error_not_a_number() {
    let (_, b) = bladder(Wall::Exact(8), None);
    let mut out = [WallPoint::default(); 5];
    assert!(b
        .wall_field(300e3, b.max_length() * 1.01, &mut out)
        .is_err());
    assert!(b.wall_field(f64::NAN, 0.1, &mut out).is_err());
}

#[test]
fn a_field_with_an_overflowing_point_is_an_error() {
    let finite = WallPoint {
        radius: 1e-3,
        stress_radial: -2e5,
        stress_hoop: 1e6,
        stress_axial: 5e5,
    };
    assert!(WallPoint::check_field(&[finite; 3], 0.1).is_ok());
    for overflow in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        for k in 0..4 {
            let mut point = finite;
            let field = [
                &mut point.radius,
                &mut point.stress_radial,
                &mut point.stress_hoop,
                &mut point.stress_axial,
            ];
            *field[k] = overflow;
            let e = WallPoint::check_field(&[finite, point], 0.1).unwrap_err();
            assert!(e.contains("overflows at length 0.1 m"), "{e}");
        }
    }
}
