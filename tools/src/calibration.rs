//! Fitting McKibbenMuscle's physical parameters to measured force-contraction curves.
//!
//! The model is the FMU's own chapter 2 physics ([`McKibben`]: ideal sleeve, eq. 2.1-2.3, with the
//! Mooney-Rivlin bladder, thin wall eq. 2.6-2.18 or layered thick wall eq. 2.19-2.20), with no
//! empirical correction term. Free parameters: the braid angle at the nominal length and the
//! sleeve diameter there (together the strand length `b` and turns `n`), the bladder's bore, wall
//! and unstretched length (pre-strain), and the Mooney-Rivlin constants `C1`, `C2`. The residual of
//! a point is its force error as a fraction of its curve's largest force, each curve weighted
//! equally; a Levenberg-Marquardt search from several deterministic starts keeps the best.
//!
//! Pure: no I/O. `src/bin/calibrate.rs` reads the datasheet and writes the results. Offline, so
//! here in the tools crate: the FMU binary neither runs it nor links nalgebra.

use actuator_fmus::physics::friction::HysteresisState;
use actuator_fmus::physics::mckibben::McKibben;
pub use actuator_fmus::physics::muscle_params::MuscleParams;
use nalgebra::{SMatrix, SVector};

/// Number of free parameters.
pub const DIM: usize = 7;
/// Residual of a point the model cannot evaluate (length outside the bladder's range): ten times
/// its curve's largest force, large against any fit yet finite for the least-squares step.
const INFEASIBLE: f64 = 10.0;

/// One measured point: gauge pressure (Pa), contraction (fraction of the nominal length,
/// negative = stretched) and force (N, tension positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Datum {
    pub pressure: f64,
    pub contraction: f64,
    pub force: f64,
}

/// The points measured at one pressure.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub pressure: f64,
    pub points: Vec<Datum>,
}

impl Curve {
    /// The largest force magnitude on the curve, N (the scale of its errors).
    pub fn scale(&self) -> f64 {
        self.points
            .iter()
            .map(|d| d.force.abs())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE)
    }
}

/// Groups points by pressure (in the order the pressures first appear).
pub fn curves(data: &[Datum]) -> Vec<Curve> {
    let mut out: Vec<Curve> = Vec::new();
    for d in data {
        match out.iter_mut().find(|c| c.pressure == d.pressure) {
            Some(c) => c.points.push(*d),
            None => out.push(Curve {
                pressure: d.pressure,
                points: vec![*d],
            }),
        }
    }
    out
}

/// What to fit and how hard to search.
#[derive(Clone, Debug)]
pub struct FitConfig {
    /// Nominal length `L_N`, m (the curves' contraction is relative to it).
    pub nominal_length: f64,
    /// Nominal inner diameter of the muscle, m: the scale of the starting diameters.
    pub diameter: f64,
    /// `bladder_layers`: 1 = thin wall (`bladder_model` 4), more = layers (`bladder_model` 5).
    pub layers: i32,
    /// Number of starting points of the Levenberg-Marquardt search.
    pub starts: usize,
    /// Iteration cap per start.
    pub iterations: usize,
}

/// Error of the model against one curve, as fractions of the curve's largest force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveError {
    pub pressure: f64,
    pub rms: f64,
    pub max: f64,
    /// Points the model could not evaluate (outside its length range); they count as errors of
    /// 100% in `rms` and `max`.
    pub infeasible: usize,
}

/// The model's force at a datum, `Err` outside its range.
pub fn model_force(muscle: &McKibben, nominal_length: f64, d: &Datum) -> Result<f64, String> {
    let length = nominal_length * (1.0 - d.contraction);
    let rest = HysteresisState::at_rest(length);
    muscle.evaluate(d.pressure, length, &rest).map(|o| o.force)
}

/// Error of `params` against each curve.
pub fn errors(params: &MuscleParams, curves: &[Curve]) -> Vec<CurveError> {
    let muscle = params.muscle().ok();
    curves
        .iter()
        .map(|c| {
            let scale = c.scale();
            let (mut sum_sq, mut max, mut infeasible) = (0.0, 0.0f64, 0);
            for d in &c.points {
                let e = match muscle
                    .as_ref()
                    .map(|m| model_force(m, params.nominal_length, d))
                {
                    Some(Ok(f)) => (f - d.force).abs() / scale,
                    _ => {
                        infeasible += 1;
                        1.0
                    }
                };
                sum_sq += e * e;
                max = max.max(e);
            }
            CurveError {
                pressure: c.pressure,
                rms: (sum_sq / c.points.len() as f64).sqrt(),
                max,
                infeasible,
            }
        })
        .collect()
}

/// Rubber constants stay those of real rubbers, Pa: without the bound a vanishing wall of an
/// absurdly stiff rubber fits as well (only their product matters in the thin-wall limit).
const MOONEY: (f64, f64) = (1e3, 3e6);
/// Wall thickness as a fraction of the nominal diameter.
const WALL: (f64, f64) = (0.002, 0.3);

/// `lo .. hi` on a log scale from an unbounded `v` (logistic).
fn log_between(v: f64, (lo, hi): (f64, f64)) -> f64 {
    (lo.ln() + (hi / lo).ln() / (1.0 + (-v).exp())).exp()
}

/// The inverse of [`log_between`] (for starting points).
fn log_logit(x: f64, (lo, hi): (f64, f64)) -> f64 {
    let p = (x / lo).ln() / (hi / lo).ln();
    (p / (1.0 - p)).ln()
}

/// Maps an unbounded search vector to parameters (the bounds live in these maps).
fn decode(x: &SVector<f64, DIM>, cfg: &FitConfig) -> MuscleParams {
    let sigmoid = |v: f64| 1.0 / (1.0 + (-v).exp());
    let l_n = cfg.nominal_length;
    // Braid angle at L_N between 5 and 54 degrees (beyond 54.7 the sleeve pushes, eq. 2.3).
    let theta = (5.0 + 49.0 * sigmoid(x[0])).to_radians();
    // Sleeve diameter at L_N between 0.5 and 2 nominal diameters.
    let d_sleeve = cfg.diameter * (0.5 + 1.5 * sigmoid(x[1]));
    let b = l_n / theta.cos();
    let n = b * theta.sin() / (std::f64::consts::PI * d_sleeve);
    MuscleParams {
        nominal_length: l_n,
        strand_length: b,
        turns: n,
        bladder_model: if cfg.layers > 1 { 5 } else { 4 },
        bladder_layers: cfg.layers.max(1),
        bladder_length: l_n * x[4].exp(),
        bladder_inner_diameter: cfg.diameter * x[2].exp(),
        bladder_thickness: cfg.diameter * log_between(x[3], WALL),
        mooney_c1: log_between(x[5], MOONEY),
        mooney_c2: log_between(x[6], MOONEY),
    }
}

/// Weighted residuals of the fitted curves (each curve's errors over its largest force, divided
/// by the square root of its point count so that every curve weighs the same).
fn residuals(x: &SVector<f64, DIM>, cfg: &FitConfig, fit: &[Curve], out: &mut Vec<f64>) {
    out.clear();
    let params = decode(x, cfg);
    let muscle = params.muscle().ok();
    for c in fit {
        let w = 1.0 / (c.scale() * (c.points.len() as f64).sqrt());
        for d in &c.points {
            out.push(
                match muscle
                    .as_ref()
                    .map(|m| model_force(m, cfg.nominal_length, d))
                {
                    Some(Ok(f)) if f.is_finite() => (f - d.force) * w,
                    _ => INFEASIBLE * c.scale() * w,
                },
            );
        }
    }
}

fn cost(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// Levenberg-Marquardt (Marquardt's diagonal scaling, forward-difference Jacobian) from `x`.
fn levenberg_marquardt(
    mut x: SVector<f64, DIM>,
    cfg: &FitConfig,
    fit: &[Curve],
) -> (SVector<f64, DIM>, f64) {
    let mut r = Vec::new();
    residuals(&x, cfg, fit, &mut r);
    let mut c = cost(&r);
    let mut lambda = 1e-2;
    let (mut r_trial, mut jac_col) = (Vec::new(), Vec::new());
    let mut jac = vec![[0.0; DIM]; r.len()];
    for _ in 0..cfg.iterations {
        for k in 0..DIM {
            let h = 1e-6 * (1.0 + x[k].abs());
            let mut xh = x;
            xh[k] += h;
            residuals(&xh, cfg, fit, &mut jac_col);
            for (row, (rh, r0)) in jac.iter_mut().zip(jac_col.iter().zip(&r)) {
                row[k] = (rh - r0) / h;
            }
        }
        let mut jtj = SMatrix::<f64, DIM, DIM>::zeros();
        let mut jtr = SVector::<f64, DIM>::zeros();
        for (row, ri) in jac.iter().zip(&r) {
            let j = SVector::<f64, DIM>::from_row_slice(row);
            jtj += j * j.transpose();
            jtr += j * *ri;
        }
        let mut improved = false;
        while lambda < 1e12 {
            let mut a = jtj;
            for k in 0..DIM {
                a[(k, k)] += lambda * jtj[(k, k)].max(1e-12);
            }
            let Some(step) = a.cholesky().map(|ch| ch.solve(&(-jtr))) else {
                lambda *= 10.0;
                continue;
            };
            let trial = x + step;
            residuals(&trial, cfg, fit, &mut r_trial);
            let c_trial = cost(&r_trial);
            if c_trial.is_finite() && c_trial < c {
                let gain = (c - c_trial) / c.max(f64::MIN_POSITIVE);
                x = trial;
                std::mem::swap(&mut r, &mut r_trial);
                c = c_trial;
                lambda = (lambda / 3.0).max(1e-12);
                improved = gain > 1e-10;
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    (x, c)
}

/// Deterministic pseudo-random numbers in [0, 1) (xorshift64*), so that a fit is reproducible.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// A fit's result.
#[derive(Clone, Debug)]
pub struct Fit {
    pub params: MuscleParams,
    /// Sum of squared weighted residuals (mean square error per fitted curve, summed).
    pub cost: f64,
}

/// Fits `cfg`'s model to `fit` (the curves at the chosen pressures). `progress(start, starts,
/// best)` is called after every start. `Err` if no start gives a muscle that covers the data.
pub fn fit(
    cfg: &FitConfig,
    fit: &[Curve],
    mut progress: impl FnMut(usize, usize, &Fit),
) -> Result<Fit, String> {
    if fit.iter().all(|c| c.points.is_empty()) {
        return Err("no data points at the pressures to fit".into());
    }
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut best: Option<Fit> = None;
    for start in 0..cfg.starts.max(1) {
        // Starts spread over plausible muscles: braid 15-40 degrees, bladder near the bore,
        // walls 1-10% of the bore, 0-30% pre-strain, rubber 10 kPa - 1 MPa.
        let logit = |p: f64| (p / (1.0 - p)).ln();
        let x0 = SVector::<f64, DIM>::from_column_slice(&[
            logit((rng.between(15.0, 40.0) - 5.0) / 49.0),
            logit((rng.between(1.0, 1.4) - 0.5) / 1.5),
            rng.between(0.7, 1.0f64).ln(),
            log_logit(rng.between(0.005, 0.1), WALL),
            rng.between(0.75, 1.02f64).ln(),
            log_logit(rng.between(1e4, 1e6), MOONEY),
            log_logit(rng.between(1e4, 1e6), MOONEY),
        ]);
        let (x, c) = levenberg_marquardt(x0, cfg, fit);
        if best.as_ref().is_none_or(|b| c < b.cost) {
            best = Some(Fit {
                params: decode(&x, cfg),
                cost: c,
            });
        }
        if let Some(b) = &best {
            progress(start + 1, cfg.starts.max(1), b);
        }
    }
    let best = best.ok_or("no start")?;
    if errors(&best.params, fit).iter().any(|e| e.infeasible > 0) {
        return Err(format!(
            "no fitted muscle covers every data length (best cost {:e}): check LENGTH",
            best.cost
        ));
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thin-walled muscle inside the fit's bounds (about a 10 mm Festo-like muscle).
    fn truth() -> MuscleParams {
        MuscleParams {
            nominal_length: 0.25,
            strand_length: 0.25 / 25f64.to_radians().cos(),
            turns: 0.25 * 25f64.to_radians().tan() / (std::f64::consts::PI * 0.011),
            bladder_model: 4,
            bladder_layers: 1,
            bladder_length: 0.24,
            bladder_inner_diameter: 0.009,
            bladder_thickness: 0.5e-3,
            mooney_c1: 4e5,
            mooney_c2: 1e5,
        }
    }

    fn synthetic(p: &MuscleParams, kpa: &[f64]) -> Vec<Datum> {
        let m = p.muscle().unwrap();
        let mut data = Vec::new();
        for &k in kpa {
            for i in 0..9 {
                let mut d = Datum {
                    pressure: k * 1e3,
                    contraction: -0.02 + 0.025 * i as f64,
                    force: 0.0,
                };
                if let Ok(f) = model_force(&m, p.nominal_length, &d) {
                    d.force = f;
                    data.push(d);
                }
            }
        }
        data
    }

    #[test]
    fn fit_reproduces_curves_generated_by_the_model_itself() {
        // The model can represent its own curves exactly: the fit at 0 + 600 kPa must predict
        // the 300 kPa curve of the same muscle (a regression on the search, not on Festo data).
        let truth = truth();
        let cfg = FitConfig {
            nominal_length: 0.25,
            diameter: 0.01,
            layers: 1,
            starts: 12,
            iterations: 200,
        };
        let fitted = curves(&synthetic(&truth, &[0.0, 600.0]));
        let best = fit(&cfg, &fitted, |_, _, _| {}).unwrap();
        let check = curves(&synthetic(&truth, &[300.0]));
        for e in errors(&best.params, &check)
            .iter()
            .chain(&errors(&best.params, &fitted))
        {
            assert!(e.rms < 2e-3 && e.infeasible == 0, "{e:?}");
        }
    }

    #[test]
    fn scaling_the_nominal_length_keeps_force_at_each_contraction() {
        let p = truth();
        let q = p.scaled_to(0.6);
        let mq = q.muscle().unwrap();
        assert!((q.braid_angle() - p.braid_angle()).abs() < 1e-12);
        for d in synthetic(&p, &[0.0, 300.0, 600.0]) {
            let f = model_force(&mq, q.nominal_length, &d).unwrap();
            assert!(
                (f - d.force).abs() <= 1e-9 * d.force.abs().max(1.0),
                "{f} vs {d:?}"
            );
        }
    }

    #[test]
    fn errors_are_fractions_of_each_curves_largest_force() {
        let p = truth();
        let mut data = synthetic(&p, &[600.0]);
        let scale = data.iter().map(|d| d.force.abs()).fold(0.0, f64::max);
        let last = data.len() - 1; // the weakest point, so the largest force stays
        data[last].force += 0.1 * scale; // one point 10% off: max 0.1, rms 0.1/sqrt(n)
        let e = errors(&p, &curves(&data))[0];
        assert!((e.max - 0.1).abs() < 1e-9, "{e:?}");
        assert!(
            (e.rms - 0.1 / (data.len() as f64).sqrt()).abs() < 1e-9,
            "{e:?}"
        );
    }

    // The Festo presets of the FMU (`src/physics/festo.rs`) against their datasheets.
    use actuator_fmus::physics::festo::{DMSP_10, DMSP_40};

    fn datasheet(text: &str) -> Vec<Datum> {
        text.lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("pressure"))
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|s| s.trim().parse().unwrap()).collect();
                Datum {
                    pressure: v[0] * 1e3,
                    contraction: v[1],
                    force: v[2],
                }
            })
            .collect()
    }

    /// The presets predict every datasheet curve within 2% RMS and 5% max of its largest force
    /// (measured: at most 1.69% / 4.09%, DMSP-40 at 100 kPa).
    #[test]
    fn presets_match_their_datasheets_at_every_pressure() {
        for (preset, text) in [
            (DMSP_40, include_str!("../../data/festo/festo_dmsp40.csv")),
            (DMSP_10, include_str!("../../data/festo/festo_dmsp10.csv")),
        ] {
            let all = curves(&datasheet(text));
            assert!(all.len() >= 8);
            for e in errors(&preset, &all) {
                assert!(e.infeasible == 0 && e.rms < 0.02 && e.max < 0.05, "{e:?}");
            }
        }
    }
}
