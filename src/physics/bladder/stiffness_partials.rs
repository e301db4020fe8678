//! Exact partials of the bladder's length slopes (the stiffness `dF/dL`, `dP_eff/dL` and the
//! strand force's slope) with respect to the gauge pressure and the muscle length: second
//! derivatives of the force, from one pass of the kernel on [`HyperDual`] numbers.
//!
//! Everything the kernel returns is a function of the muscle length `L` and the outer diameter
//! `x`, affine in `P` (eq. 2.12 / 2.19 per layer): `P_eff = a P - c`, elastic force
//! `E = E_0 + P E_1` (eq. 2.17). With `F = P_eff g - P A_fluid + E` (eq. 2.16):
//!
//! - **In contact** `x = D(L)` (eq. 2.7, 2.20). The diameter is seeded as `D + D' dl + D'' dl^2/2`
//!   so the `l` derivatives are the totals along the contact branch, and
//!   `dS/dP = a' g + a g' - A' + E_1'`, `dS/dL = F''`.
//! - **Free** (`P_eff(P, L, x) = 0`, eq. 2.18): the implicit function theorem to second order,
//!   `x_LL = -(phi_LL + 2 phi_Lx x_L + phi_xx x_L^2) / phi_x` and
//!   `x_LP = -(a_L + phi_Lx x_P + a_x x_L + phi_xx x_P x_L) / phi_x`, then
//!   `dS/dL = F_LL + 2 F_Lx x_L + F_xx x_L^2 + F_x x_LL` and
//!   `dS/dP = F_LP + F_Lx x_P + (F_xP + F_xx x_P) x_L + F_x x_LP`.
//!
//! At the contact threshold the partials are the contact branch's, as for the first order.

use super::{Bladder, SleeveGeometry};
use crate::physics::numerics::hyper_dual::HyperDual;

/// `[d/dP, d/dL]` of the bladder's length slopes at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BladderCurvature {
    /// Of `stiffness` = `dF/dL`: N/(m Pa) and N/m^2.
    pub stiffness: [f64; 2],
    /// Of `effective_pressure_slope` = `dP_eff/dL`: 1/m and Pa/m^2 (zero when free).
    pub effective_pressure_slope: [f64; 2],
    /// Of `strand_stiffness` = `d(P_eff g)/dL`: N/(m Pa) and N/m^2 (zero when free).
    pub strand_stiffness: [f64; 2],
}

impl<S: SleeveGeometry> Bladder<S> {
    /// The partials of the length slopes at `pressure` and `length`, on the branch
    /// [`Bladder::evaluate`] takes there. Costs one first-order kernel (the branch test), the
    /// root of eq. 2.18 when free, and one second-order kernel.
    pub fn stiffness_partials(
        &self,
        pressure: f64,
        length: f64,
    ) -> Result<BladderCurvature, String> {
        let (x, contact) = self.contact_point(pressure, length)?;
        let l2 = HyperDual::seed(length, [1.0, 0.0], [0.0; 3]);
        let curvature = if contact.p_eff.v >= 0.0 {
            let (d, d1) = self.sleeve.diameter_and_slope(length);
            let (d2, g2) = self.sleeve.curvatures(length);
            let x2 = HyperDual::seed(d, [d1, 1.0], [d2, 0.0, 0.0]);
            let k = self
                .kernel(pressure, l2, x2)
                .ok_or_else(|| self.domain_error(length))?;
            let (g, g1) = self.sleeve.strand_area(length);
            let area = self.fluid_area(k.inner.l2_sq);
            let (a, pe) = (k.a, k.p_eff);
            let strand = [
                a.d[0] * g + a.v * g1,
                pe.h[0] * g + 2.0 * pe.d[0] * g1 + pe.v * g2,
            ];
            BladderCurvature {
                stiffness: [
                    strand[0] - area.d[0] + k.elastic_dp().d[0],
                    strand[1] - pressure * area.h[0] + k.elastic.h[0],
                ],
                effective_pressure_slope: [a.d[0], pe.h[0]],
                strand_stiffness: strand,
            }
        } else {
            let (root, _) = self.free_outer_diameter(pressure, length, x.v, &contact)?;
            let x2 = HyperDual::seed(root, [0.0, 1.0], [0.0; 3]);
            let k = self
                .kernel(pressure, l2, x2)
                .ok_or_else(|| self.domain_error(length))?;
            let (phi, a) = (k.p_eff, k.a);
            let [phi_l, phi_x] = phi.d;
            let [phi_ll, phi_lx, phi_xx] = phi.h;
            if phi_x == 0.0 {
                // As the first-order partials: the root does not move.
                return Ok(BladderCurvature::default());
            }
            let x_p = -a.v / phi_x;
            let x_l = -phi_l / phi_x;
            let x_ll = -(phi_ll + 2.0 * phi_lx * x_l + phi_xx * x_l * x_l) / phi_x;
            let x_lp = -(a.d[0] + phi_lx * x_p + a.d[1] * x_l + phi_xx * x_p * x_l) / phi_x;
            // F = -P A_fluid + E at fixed (L, x); its P-slope -A_fluid + E_1.
            let area = self.fluid_area(k.inner.l2_sq);
            let f = area * -pressure + k.elastic;
            let [_, f_x] = f.d;
            let [f_ll, f_lx, f_xx] = f.h;
            let elastic_dp = k.elastic_dp();
            let f_lp = -area.d[0] + elastic_dp.d[0];
            let f_xp = -area.d[1] + elastic_dp.d[1];
            BladderCurvature {
                stiffness: [
                    f_lp + f_lx * x_p + (f_xp + f_xx * x_p) * x_l + f_x * x_lp,
                    f_ll + 2.0 * f_lx * x_l + f_xx * x_l * x_l + f_x * x_ll,
                ],
                ..Default::default()
            }
        };
        let all = [
            curvature.stiffness,
            curvature.effective_pressure_slope,
            curvature.strand_stiffness,
        ];
        if all.iter().flatten().all(|v| v.is_finite()) {
            Ok(curvature)
        } else {
            Err(format!(
                "stiffness partials overflow at length {length} m (too close to a length limit)"
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{BladderTube, Wall};
    use super::*;
    use crate::physics::gaylord::Sleeve;
    use crate::physics::knitted::{KnittedParams, KnittedSleeve, ShapeKind};
    use crate::physics::knitted_cylinder::KnittedCylinder;

    /// Central differences of the three slopes of `evaluate` against the exact partials; returns
    /// the worst relative difference and whether the point was free.
    fn check<S: SleeveGeometry>(b: &Bladder<S>, p: f64, l: f64, what: &str) -> (f64, bool) {
        let slopes = |p: f64, l: f64| {
            let s = b.evaluate(p, l).unwrap();
            [s.stiffness, s.effective_pressure_slope, s.strand_stiffness]
        };
        let exact = b.stiffness_partials(p, l).unwrap();
        let exact = [
            exact.stiffness,
            exact.effective_pressure_slope,
            exact.strand_stiffness,
        ];
        let h = [p.abs() * 1e-6 + 1e-3, l * 1e-6];
        let (up_p, down_p) = (slopes(p + h[0], l), slopes(p - h[0], l));
        let (up_l, down_l) = (slopes(p, l + h[1]), slopes(p, l - h[1]));
        let mut worst: f64 = 0.0;
        for k in 0..3 {
            let central = [
                (up_p[k] - down_p[k]) / (2.0 * h[0]),
                (up_l[k] - down_l[k]) / (2.0 * h[1]),
            ];
            for j in 0..2 {
                let (e, c) = (exact[k][j], central[j]);
                let scale = e.abs().max(c.abs());
                let err = (e - c).abs() / scale.max(1e-300);
                // Absolute floor: rounding (and the root's 1e-14 tolerance) in the slope over
                // the step.
                let floor = 1e-14 * (1.0 + slopes(p, l)[k].abs()) / h[j];
                assert!(
                    err < 1e-5 || (e - c).abs() < floor,
                    "{what}: slope {k} by {} exact {e} central {c} ({err:e})",
                    ["P", "L"][j]
                );
                if (e - c).abs() >= floor {
                    worst = worst.max(err);
                }
            }
        }
        (worst, !b.evaluate(p, l).unwrap().contact)
    }

    fn walls() -> [Wall; 7] {
        [
            Wall::Exact(8),
            Wall::Exact(1),
            Wall::Layers(4),
            Wall::DissertationLayers(1),
            Wall::DissertationLayers(8),
            Wall::DissertationContinuum(6),
            Wall::DissertationContinuum(1),
        ]
    }

    #[test]
    fn helical_stiffness_partials_match_central_differences() {
        // Table 2.1 A-D (B and C pre-strained: bladder shorter than the muscle).
        let table = [
            (0.1005, 1.6e-3, 1.6e-3, 0.1113, 3.74),
            (0.0715, 1.6e-3, 1.6e-3, 0.1160, 3.87),
            (0.0541, 1.6e-3, 1.6e-3, 0.1051, 3.40),
            (0.1336, 3.8e-3, 0.25e-3, 0.1423, 4.53),
        ];
        let (mut points, mut free, mut worst) = (0, 0, 0.0f64);
        for (i, (lr0, d_ri, t, strand, turns)) in table.into_iter().enumerate() {
            let tube = BladderTube::latex(d_ri, t, lr0);
            for wall in walls() {
                let sleeve = Sleeve::new(strand, turns).unwrap();
                let b = Bladder::with_wall(sleeve, tube, wall).unwrap();
                let (lo, hi) = (b.min_length().max(0.0), b.max_length());
                for frac in [0.3, 0.6, 0.75, 0.9] {
                    let l = lo + frac * (hi - lo);
                    let threshold = b.threshold_pressure(l).unwrap();
                    for p in [-2e4, 5e4, 2e5, 4e5] {
                        // Keep the differences off the contact kink.
                        if (p - threshold).abs() < 2e3 || b.evaluate(p, l).is_err() {
                            continue;
                        }
                        let (w, f) = check(&b, p, l, &format!("muscle {i} {wall:?} L {l} P {p}"));
                        worst = worst.max(w);
                        free += usize::from(f);
                        points += 1;
                    }
                }
            }
        }
        eprintln!("helical: {points} points ({free} free), worst relative {worst:e}");
        assert!(points > 150 && free > 20, "{points} points, {free} free");
    }

    #[test]
    fn knitted_stiffness_partials_match_central_differences() {
        let (mut points, mut free, mut worst) = (0, 0, 0.0f64);
        for kind in [ShapeKind::Ideal, ShapeKind::Tubular] {
            let sleeve = KnittedSleeve::new(KnittedParams::fig_1_16(2e-4), kind).unwrap();
            let tube = BladderTube::latex(6.4e-3, 0.8e-3, 0.110);
            for wall in walls() {
                let b = Bladder::<KnittedCylinder>::knitted_wall(&sleeve, tube, wall).unwrap();
                let (lo, hi) = (b.min_length(), b.max_length());
                for frac in [0.2, 0.5, 0.8] {
                    let l = lo + frac * (hi - lo);
                    let threshold = b.threshold_pressure(l).unwrap();
                    for p in [2e4, 1.5e5, 5.5e5] {
                        if (p - threshold).abs() < 2e3 || b.evaluate(p, l).is_err() {
                            continue;
                        }
                        let (w, f) = check(&b, p, l, &format!("{kind:?} {wall:?} L {l} P {p}"));
                        worst = worst.max(w);
                        free += usize::from(f);
                        points += 1;
                    }
                }
            }
        }
        eprintln!("knitted: {points} points ({free} free), worst relative {worst:e}");
        assert!(points > 40 && free > 0, "{points} points, {free} free");
    }
}
