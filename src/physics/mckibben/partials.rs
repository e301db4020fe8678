//! Exact partial derivatives of the muscle's outputs with respect to its inputs (gauge pressure
//! and reported length), for the FMU's directional derivatives.
//!
//! The muscle's own partials come from eq. 2.3 (no bladder) or from [`Bladder::partials`]; friction
//! adds `C_f P_eff z` (eq. 2.4) with `z` the stop operator advanced to the length, whose slope is
//! `1/presliding_length` in the direction of motion unless saturated there; the connector's
//! `reported = L + F(P, L)/k` gives `dL/dP = -F_P / (k + F_L)` and `dL/dreported = k / (k + F_L)`.
//!
//! Where the model has a kink the partial is the one of the branch it evaluates: the contact
//! branch at the threshold pressure (`P_eff = 0`, `bladder_contact` true), `P_eff = 0` for the bare
//! sleeve at `P <= 0`, and at a friction reversal (length equal to the history's position) the
//! slope for increasing length.

use super::{McKibben, McKibbenOutput};
use crate::physics::by_pressure_length::ByPressureLength;
use crate::physics::friction::HysteresisState;

impl McKibben {
    /// The outputs of [`McKibben::evaluate`] and their partials at the same point.
    pub fn partials(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
    ) -> Result<(McKibbenOutput, ByPressureLength), String> {
        let (out, mut d) = self.own_partials(pressure, length, history)?;
        if let Some(c) = self.connector_compliance {
            // reported = L + c F(P, L): dL/dP = -c F_P / (1 + c F_L), dL/dreported = 1/(1 + c F_L).
            let denom = 1.0 + c * d.force[1];
            let (dl_dp, dl_dr) = (-c * d.force[0] / denom, 1.0 / denom);
            for y in d.rows_mut() {
                *y = [y[0] + y[1] * dl_dp, y[1] * dl_dr];
            }
        }
        if d.is_finite() {
            Ok((out, d))
        } else {
            Err(format!(
                "partial derivatives overflow at length {length} m (too close to a length limit)"
            ))
        }
    }

    /// The outputs and their partials with respect to `(P, L)`, `L` the muscle's own length
    /// (through a connector, the root [`McKibben::evaluate`] finds).
    fn own_partials(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
    ) -> Result<(McKibbenOutput, ByPressureLength), String> {
        // Without a connector the bladder's state and partials come from one pass; through a
        // connector the actual length is a root first.
        let (out, bladder) = match (&self.bladder, self.connector_compliance) {
            (Some(b), None) if pressure.is_finite() && length.is_finite() => {
                let (state, d) = b.evaluate_with_partials(pressure, length)?;
                let out = self.assemble(pressure, length, history, Some(state))?.out;
                (out, Some(d))
            }
            _ => {
                let out = self.evaluate(pressure, length, history)?;
                let d = match &self.bladder {
                    Some(b) => Some(b.partials(pressure, out.actual_length)?),
                    None => None,
                };
                (out, d)
            }
        };
        let l = out.actual_length;
        // Partials with respect to (P, actual length).
        let mut d = match bladder {
            None => {
                let s = &self.sleeve;
                let on = if pressure > 0.0 { 1.0 } else { 0.0 };
                // Eq. 2.3 and 2.2: F = P_eff (3L^2 - b^2)/(4 pi n^2), dV/dL = -F/P_eff.
                let per_pa = s.force(1.0, l);
                ByPressureLength {
                    force: [on * per_pa, s.stiffness(pressure.max(0.0), l)],
                    effective_pressure: [on, 0.0],
                    friction_force: [0.0, 0.0],
                    volume: [0.0, -per_pa],
                    ..Default::default()
                }
            }
            // The bladder's own rows: no friction yet.
            Some(p) => p,
        };
        if let Some(f) = &self.friction {
            let z = out.friction_state.z;
            let direction = if l >= history.position { 1.0 } else { -1.0 };
            let dz_dl = f.operator.slope(&out.friction_state, direction);
            let cf = f.coefficient;
            let pe = d.effective_pressure;
            d.friction_force = [
                cf * z * pe[0],
                cf * (z * pe[1] + out.effective_pressure * dz_dl),
            ];
            d.force[0] += d.friction_force[0];
            d.force[1] += d.friction_force[1];
        }
        Ok((out, d))
    }

    /// `[d/dP, d/dlength]` of `stiffness` (`length` the input, reported length), from the
    /// bladder's second-order pass ([`crate::physics::bladder::BladderCurvature`]) or eq. 2.3's
    /// `6 P_eff L / (4 pi n^2)`. Friction adds `C_f z dP_eff/dL` (z held in the stiffness), whose
    /// length slope brings the stop operator's slope `z_L dP_eff/dL`. Through the connector the
    /// series stiffness `K = K_m / (1 + K_m / k)` changes by `1 / (1 + K_m / k)^2` times `K_m`'s
    /// change, with the muscle length `L(P, reported)` as in [`McKibben::partials`].
    pub fn stiffness_partials(
        &self,
        pressure: f64,
        length: f64,
        history: &HysteresisState,
    ) -> Result<[f64; 2], String> {
        let (out, own) = self.own_partials(pressure, length, history)?;
        let l = out.actual_length;
        let mut k_m = match &self.bladder {
            None => {
                let on = if pressure > 0.0 { 1.0 } else { 0.0 };
                let s = &self.sleeve;
                // Eq. 2.3's stiffness is bilinear in P_eff and L.
                [
                    on * s.stiffness(1.0, l),
                    s.stiffness(pressure.max(0.0), 1.0),
                ]
            }
            Some(b) => {
                let c = b.stiffness_partials(pressure, l)?;
                let mut row = c.stiffness;
                if let Some(f) = &self.friction {
                    let next = out.friction_state;
                    let direction = if l >= history.position { 1.0 } else { -1.0 };
                    let z_l = f.operator.slope(&next, direction);
                    let (slope, by) = (own.effective_pressure[1], c.effective_pressure_slope);
                    row[0] += f.coefficient * next.z * by[0];
                    row[1] += f.coefficient * (z_l * slope + next.z * by[1]);
                }
                row
            }
        };
        if let Some(c) = self.connector_compliance {
            // K = K_m / (1 + c K_m), so K_m = K / (1 - c K); L(P, reported) as in `partials`.
            let muscle = out.stiffness / (1.0 - c * out.stiffness);
            let denom = 1.0 + c * own.force[1];
            let (dl_dp, dl_dr) = (-c * own.force[0] / denom, 1.0 / denom);
            let series = 1.0 / (1.0 + c * muscle).powi(2);
            k_m = [(k_m[0] + k_m[1] * dl_dp) * series, k_m[1] * dl_dr * series];
        }
        if k_m.iter().all(|x| x.is_finite()) {
            Ok(k_m)
        } else {
            Err(format!(
                "stiffness partials overflow at length {length} m (too close to a length limit)"
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{BladderModel, FrictionParams, MuscleGeometry};
    use super::*;

    /// The outputs in the order of [`ByPressureLength::rows`] (the muscle has no `max_radius`).
    const NAMES: [&str; 11] = [
        "force",
        "effective_pressure",
        "friction_force",
        "volume",
        "threshold_pressure",
        "stretch_axial",
        "stretch_hoop",
        "stretch_radial",
        "stress_axial",
        "stress_hoop",
        "stress_radial",
    ];

    /// The outputs in the order of [`NAMES`].
    fn values(o: &McKibbenOutput) -> [f64; 11] {
        [
            o.force,
            o.effective_pressure,
            o.friction_force,
            o.volume,
            o.threshold_pressure,
            o.stretch_axial,
            o.stretch_hoop,
            o.stretch_radial,
            o.stress_axial,
            o.stress_hoop,
            o.stress_radial,
        ]
    }

    /// Central differences of every output with respect to (P, length), steps `h`.
    fn central(m: &McKibben, p: f64, l: f64, s: &HysteresisState, h: [f64; 2]) -> [[f64; 2]; 11] {
        let f = |p: f64, l: f64| values(&m.evaluate(p, l, s).unwrap());
        let (ap, bp) = (f(p + h[0], l), f(p - h[0], l));
        let (al, bl) = (f(p, l + h[1]), f(p, l - h[1]));
        std::array::from_fn(|k| {
            [
                (ap[k] - bp[k]) / (2.0 * h[0]),
                (al[k] - bl[k]) / (2.0 * h[1]),
            ]
        })
    }

    /// Agreement of every partial with central differences, relative to the output's scale.
    fn check(m: &McKibben, p: f64, l: f64, s: &HysteresisState, what: &str) -> f64 {
        let (_, exact) = m.partials(p, l, s).unwrap();
        let fd = central(m, p, l, s, [p.abs() * 1e-6 + 1e-3, l * 1e-7]);
        let mut worst: f64 = 0.0;
        // Through a connector the actual length is a root (tolerance 1e-14 relative), whose
        // noise the central difference amplifies.
        let tolerance = if m.has_connector() { 1e-4 } else { 2e-5 };
        for ((name, e), c) in NAMES.into_iter().zip(exact.rows()).zip(fd) {
            for k in 0..2 {
                let scale = e[k].abs().max(c[k].abs()).max(1e-12);
                let err = (e[k] - c[k]).abs() / scale;
                assert!(
                    err < tolerance || (e[k] - c[k]).abs() < 1e-9 * (1.0 + scale),
                    "{what}: d{name}/d{} exact {} vs central {} (relative {err:e})",
                    ["P", "L"][k],
                    e[k],
                    c[k]
                );
                worst = worst.max(if scale > 1e-9 { err } else { 0.0 });
            }
        }
        worst
    }

    /// Agreement of the stiffness's partials with central differences of the stiffness output.
    fn check_stiffness(m: &McKibben, p: f64, l: f64, s: &HysteresisState, what: &str) -> f64 {
        let exact = m.stiffness_partials(p, l, s).unwrap();
        let k = |p: f64, l: f64| m.evaluate(p, l, s).unwrap().stiffness;
        let h = [p.abs() * 1e-6 + 1e-3, l * 1e-6];
        let central = [
            (k(p + h[0], l) - k(p - h[0], l)) / (2.0 * h[0]),
            (k(p, l + h[1]) - k(p, l - h[1])) / (2.0 * h[1]),
        ];
        // As for the first partials: the connector's root is noisier.
        let tolerance = if m.has_connector() { 1e-4 } else { 2e-5 };
        let mut worst: f64 = 0.0;
        for j in 0..2 {
            let (e, c) = (exact[j], central[j]);
            let scale = e.abs().max(c.abs()).max(1e-12);
            let err = (e - c).abs() / scale;
            // Rounding of the stiffness over the step.
            let floor = 1e-15 * (1.0 + k(p, l).abs()) / h[j];
            assert!(
                err < tolerance || (e - c).abs() < floor,
                "{what}: dstiffness/d{} exact {e} vs central {c} (relative {err:e})",
                ["P", "L"][j]
            );
            if (e - c).abs() >= floor {
                worst = worst.max(err);
            }
        }
        worst
    }

    fn muscle(g: &MuscleGeometry, model: BladderModel, friction: bool, k: f64) -> McKibben {
        let f = friction.then_some(FrictionParams {
            coefficient: 1e-5,
            presliding_length: 1e-4,
        });
        McKibben::from_geometry(g, model, f, k).unwrap()
    }

    #[test]
    fn partials_match_central_differences_across_effects() {
        let models = [
            BladderModel::None,
            BladderModel::DissertationThinWall,
            BladderModel::DissertationLayers { layers: 8 },
            BladderModel::DissertationContinuum { nodes: 6 },
        ];
        let (mut worst, mut worst_stiffness) = (0.0f64, 0.0f64);
        let (mut free_points, mut points) = (0, 0);
        for (gi, g) in [
            MuscleGeometry::muscle_a(),
            MuscleGeometry::muscle_b(),
            MuscleGeometry::muscle_c(),
            MuscleGeometry::muscle_d(),
        ]
        .iter()
        .enumerate()
        {
            for model in models {
                for friction in [false, true] {
                    for k in [0.0, 5e4] {
                        let m = muscle(g, model, friction, k);
                        let (lo, hi) = (m.min_length().max(0.0), m.max_length());
                        for frac in [0.6, 0.75, 0.9] {
                            let l = lo + frac * (hi - lo);
                            // History behind the length: friction mid-presliding (z = 0.3).
                            let s = HysteresisState::at_rest(l - 3e-5);
                            for p in [5e4, 2e5, 4e5] {
                                let Ok(o) = m.evaluate(p, l, &s) else {
                                    continue;
                                };
                                if model != BladderModel::None {
                                    let th = o.threshold_pressure;
                                    // Keep the central difference off the contact kink.
                                    if (p - th).abs() < 1e3 {
                                        continue;
                                    }
                                    free_points += usize::from(!o.bladder_contact);
                                }
                                let what = format!(
                                    "muscle {gi} {model:?} friction {friction} k {k} L {l} P {p}"
                                );
                                worst = worst.max(check(&m, p, l, &s, &what));
                                worst_stiffness =
                                    worst_stiffness.max(check_stiffness(&m, p, l, &s, &what));
                                points += 1;
                            }
                        }
                    }
                }
            }
        }
        // Both bladder branches were exercised (thin-walled A is free at low pressure).
        assert!(free_points > 0, "no free-bladder point was checked");
        assert!(points > 300, "only {points} points checked");
        eprintln!(
            "{points} points ({free_points} free bladder): worst relative difference {worst:e}, \
             of the stiffness's partials {worst_stiffness:e}"
        );
    }

    #[test]
    fn contact_kink_returns_the_contact_branch() {
        // At the threshold pressure P_eff = 0 but dP_eff/dP = a > 0: the contact branch.
        let m = muscle(
            &MuscleGeometry::muscle_a(),
            BladderModel::DissertationThinWall,
            false,
            0.0,
        );
        let l = 0.09;
        let s = HysteresisState::at_rest(l);
        let th = m.evaluate(0.0, l, &s).unwrap().threshold_pressure;
        let (o, d) = m.partials(th, l, &s).unwrap();
        assert!(o.bladder_contact);
        assert!(d.effective_pressure[0] > 0.0);
        // The one-sided difference from above agrees with it.
        let h = 1e-3 * th.abs().max(1.0);
        let above = (m.evaluate(th + h, l, &s).unwrap().force - o.force) / h;
        assert!((above - d.force[0]).abs() < 1e-3 * d.force[0].abs());
    }

    #[test]
    fn stiffness_partials_at_the_contact_kink_are_the_contact_branch() {
        // At the threshold pressure the stiffness's pressure slope jumps (free below, contact
        // above): the call returns the contact branch's, the one-sided difference from above.
        for model in [
            BladderModel::DissertationThinWall,
            BladderModel::DissertationContinuum { nodes: 6 },
        ] {
            let m = muscle(&MuscleGeometry::muscle_a(), model, false, 0.0);
            let l = 0.09;
            let s = HysteresisState::at_rest(l);
            let th = m.evaluate(0.0, l, &s).unwrap().threshold_pressure;
            let exact = m.stiffness_partials(th, l, &s).unwrap();
            let k = |p: f64| m.evaluate(p, l, &s).unwrap().stiffness;
            let h = 1e-4 * th.abs().max(1.0);
            let (above, below) = ((k(th + h) - k(th)) / h, (k(th) - k(th - h)) / h);
            assert!(
                (above - exact[0]).abs() < 1e-3 * exact[0].abs(),
                "{above} {exact:?}"
            );
            assert!(
                (below - exact[0]).abs() > 1e-2 * exact[0].abs(),
                "{below} {exact:?}"
            );
        }
    }

    #[test]
    fn friction_reversal_returns_the_slope_for_increasing_length() {
        // Saturated at z = +1 after extension: growing further adds no friction, shrinking does.
        let m = muscle(&MuscleGeometry::muscle_c(), BladderModel::None, true, 0.0);
        let l = 0.1;
        let s = HysteresisState {
            z: 1.0,
            position: l,
        };
        let (_, d) = m.partials(3e5, l, &s).unwrap();
        assert_eq!(d.friction_force[1], 0.0);
        let mid = HysteresisState {
            z: 0.0,
            position: l,
        };
        let (_, d) = m.partials(3e5, l, &mid).unwrap();
        assert!((d.friction_force[1] - 1e-5 * 3e5 / 1e-4).abs() < 1e-9);
    }
}
