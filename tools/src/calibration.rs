//! Fitting McKibbenMuscle's physical parameters to measured force-contraction curves.
//!
//! The model is the FMU's own chapter 2 physics ([`McKibben`]: ideal sleeve, eq. 2.1-2.3, with the
//! Mooney-Rivlin bladder, by default the exact thick wall, `bladder_model` 3), with no empirical
//! correction term. The parameters ([`Param`]): the braid angle at the nominal length and the
//! sleeve diameter there (together the strand length `b` and turns `n`), the bladder's bore, wall
//! and unstretched length (pre-strain), and the Mooney-Rivlin constants `C1`, `C2`; any of them can
//! be held fixed (by default the rubber's, [`RUBBER`]). The residual of a point is its force error
//! as a fraction of its curve's largest force, each curve weighted equally; the
//! `levenberg-marquardt` crate's search from several deterministic starts keeps the best.
//!
//! Pure: no I/O. `src/bin/calibrate.rs` reads the datasheet and writes the results. Offline, so
//! here in the tools crate: the FMU binary neither runs it nor links nalgebra.

use actuator_fmus::physics::friction::HysteresisState;
use actuator_fmus::physics::mckibben::McKibben;
pub use actuator_fmus::physics::muscle_params::MuscleParams;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, VecStorage, U1};

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

/// The parameters the calibration can fit, in the order of its search vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Param {
    /// Braid angle at the nominal length, rad (with the nominal length: `strand_length`).
    BraidAngle,
    /// Sleeve diameter at the nominal length, m (with the braid angle: `turns`).
    SleeveDiameter,
    BladderInnerDiameter,
    BladderThickness,
    BladderLength,
    MooneyC1,
    MooneyC2,
}

pub const PARAMS: [Param; 7] = [
    Param::BraidAngle,
    Param::SleeveDiameter,
    Param::BladderInnerDiameter,
    Param::BladderThickness,
    Param::BladderLength,
    Param::MooneyC1,
    Param::MooneyC2,
];

impl Param {
    pub fn name(self) -> &'static str {
        match self {
            Param::BraidAngle => "braid_angle",
            Param::SleeveDiameter => "sleeve_diameter",
            Param::BladderInnerDiameter => "bladder_inner_diameter",
            Param::BladderThickness => "bladder_thickness",
            Param::BladderLength => "bladder_length",
            Param::MooneyC1 => "mooney_c1",
            Param::MooneyC2 => "mooney_c2",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            Param::BraidAngle => "rad",
            Param::MooneyC1 | Param::MooneyC2 => "Pa",
            _ => "m",
        }
    }

    /// The search's bounds for a muscle of nominal length `l_n` and inner diameter `d`, and
    /// whether the search runs on a log scale.
    pub fn bounds(self, l_n: f64, d: f64) -> (f64, f64, bool) {
        match self {
            // Beyond 54.7 degrees the sleeve pushes (eq. 2.3).
            Param::BraidAngle => (5f64.to_radians(), 54f64.to_radians(), false),
            Param::SleeveDiameter => (0.5 * d, 2.5 * d, false),
            Param::BladderInnerDiameter => (0.3 * d, 1.5 * d, false),
            Param::BladderThickness => (0.01 * d, 0.5 * d, true),
            // A bladder longer than the muscle it sits in is no real muscle's.
            Param::BladderLength => (0.6 * l_n, l_n, false),
            Param::MooneyC1 | Param::MooneyC2 => (1e3, 3e6, true),
        }
    }

    fn get(self, p: &Geometry) -> f64 {
        match self {
            Param::BraidAngle => p.braid_angle,
            Param::SleeveDiameter => p.sleeve_diameter,
            Param::BladderInnerDiameter => p.bladder_inner_diameter,
            Param::BladderThickness => p.bladder_thickness,
            Param::BladderLength => p.bladder_length,
            Param::MooneyC1 => p.mooney_c1,
            Param::MooneyC2 => p.mooney_c2,
        }
    }

    fn set(self, p: &mut Geometry, v: f64) {
        match self {
            Param::BraidAngle => p.braid_angle = v,
            Param::SleeveDiameter => p.sleeve_diameter = v,
            Param::BladderInnerDiameter => p.bladder_inner_diameter = v,
            Param::BladderThickness => p.bladder_thickness = v,
            Param::BladderLength => p.bladder_length = v,
            Param::MooneyC1 => p.mooney_c1 = v,
            Param::MooneyC2 => p.mooney_c2 = v,
        }
    }
}

/// A muscle in the calibration's own coordinates (the braid by its angle and diameter at the
/// nominal length rather than by `b` and `n`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    pub braid_angle: f64,
    pub sleeve_diameter: f64,
    pub bladder_inner_diameter: f64,
    pub bladder_thickness: f64,
    pub bladder_length: f64,
    pub mooney_c1: f64,
    pub mooney_c2: f64,
}

impl Geometry {
    /// The muscle's parameters at nominal length `l_n` with bladder `model` (`bladder_model`,
    /// `bladder_layers`): `b = L_N / cos theta`, `n = b sin theta / (pi D)` (eq. 2.1's geometry).
    pub fn params(&self, l_n: f64, (model, layers): (i32, i32)) -> MuscleParams {
        let b = l_n / self.braid_angle.cos();
        MuscleParams {
            nominal_length: l_n,
            strand_length: b,
            turns: b * self.braid_angle.sin() / (std::f64::consts::PI * self.sleeve_diameter),
            bladder_model: model,
            bladder_layers: layers,
            bladder_length: self.bladder_length,
            bladder_inner_diameter: self.bladder_inner_diameter,
            bladder_thickness: self.bladder_thickness,
            mooney_c1: self.mooney_c1,
            mooney_c2: self.mooney_c2,
        }
    }

    /// The inverse of [`Self::params`].
    pub fn of(p: &MuscleParams) -> Self {
        let theta = p.braid_angle();
        Self {
            braid_angle: theta,
            sleeve_diameter: p.strand_length * theta.sin() / (std::f64::consts::PI * p.turns),
            bladder_inner_diameter: p.bladder_inner_diameter,
            bladder_thickness: p.bladder_thickness,
            bladder_length: p.bladder_length,
            mooney_c1: p.mooney_c1,
            mooney_c2: p.mooney_c2,
        }
    }
}

/// The bladder's rubber, `mooney_c1` and `mooney_c2` in Pa, fixed: force curves identify the
/// wall's stiffness (thickness times the constants), not the constants apart from the wall. One
/// compound for every size: small-strain shear modulus `2 (C1 + C2)` = 1.26 MPa (a chloroprene
/// rubber near Shore A 60) with its stiffness in `C2`, which the DMSP-40's curves ask for (with
/// `C2 = C1 / 4` its 100 kPa curve errs by 3.7% RMS).
pub const RUBBER: (f64, f64) = (3e4, 6e5);

/// What to fit and how hard to search.
#[derive(Clone, Debug)]
pub struct FitConfig {
    /// Nominal length `L_N`, m (the curves' contraction is relative to it).
    pub nominal_length: f64,
    /// Nominal inner diameter of the muscle, m: the scale of the bounds and starts.
    pub diameter: f64,
    /// `bladder_model` and `bladder_layers` (3, 16: the exact wall).
    pub model: (i32, i32),
    /// Parameters held at a value instead of fitted.
    pub fixed: Vec<(Param, f64)>,
    /// The braid sits on the bladder's outer wall at the nominal length (Festo's strands are
    /// embedded in it): sleeve diameter = bore + 2 wall, not searched.
    pub sleeve_on_wall: bool,
    /// Number of starting points of the Levenberg-Marquardt search.
    pub starts: usize,
    /// Iteration cap per start.
    pub iterations: usize,
}

impl FitConfig {
    /// What `make calibrate` fits: the exact wall (16 nodes) with the bladder unstretched at the
    /// nominal length (a datasheet's force at 0 kPa and 0% contraction is 0), the rubber
    /// [`RUBBER`] and the braid on the wall. Fitted: braid angle, bore and wall thickness.
    pub fn exact_wall(nominal_length: f64, diameter: f64) -> Self {
        Self {
            nominal_length,
            diameter,
            model: (3, 16),
            fixed: vec![
                (Param::BladderLength, nominal_length),
                (Param::MooneyC1, RUBBER.0),
                (Param::MooneyC2, RUBBER.1),
            ],
            sleeve_on_wall: true,
            starts: 24,
            iterations: 200,
        }
    }

    /// The parameters searched, in order.
    pub fn free(&self) -> Vec<Param> {
        PARAMS
            .into_iter()
            .filter(|p| !self.fixed.iter().any(|(f, _)| f == p))
            .filter(|p| !(self.sleeve_on_wall && *p == Param::SleeveDiameter))
            .collect()
    }

    fn bounds(&self, p: Param) -> (f64, f64, bool) {
        p.bounds(self.nominal_length, self.diameter)
    }

    /// Search coordinate (unbounded) to value: a logistic between the bounds, on a log scale
    /// where the bounds span decades.
    fn value(&self, p: Param, x: f64) -> f64 {
        let (lo, hi, log) = self.bounds(p);
        let s = 1.0 / (1.0 + (-x).exp());
        if log {
            (lo.ln() + (hi / lo).ln() * s).exp()
        } else {
            lo + (hi - lo) * s
        }
    }

    /// The inverse of [`Self::value`] (for starting points).
    fn coordinate(&self, p: Param, v: f64) -> f64 {
        let (lo, hi, log) = self.bounds(p);
        let s = if log {
            (v / lo).ln() / (hi / lo).ln()
        } else {
            (v - lo) / (hi - lo)
        };
        let s = s.clamp(1e-9, 1.0 - 1e-9);
        (s / (1.0 - s)).ln()
    }

    /// Where a value sits between its bounds, 0 at the lower and 1 at the upper (on the search's
    /// scale).
    pub fn position(&self, p: Param, v: f64) -> f64 {
        let (lo, hi, log) = self.bounds(p);
        if log {
            (v / lo).ln() / (hi / lo).ln()
        } else {
            (v - lo) / (hi - lo)
        }
    }

    fn decode(&self, x: &DVector<f64>) -> Geometry {
        let mut g = Geometry {
            braid_angle: 0.0,
            sleeve_diameter: 0.0,
            bladder_inner_diameter: 0.0,
            bladder_thickness: 0.0,
            bladder_length: 0.0,
            mooney_c1: 0.0,
            mooney_c2: 0.0,
        };
        for &(p, v) in &self.fixed {
            p.set(&mut g, v);
        }
        for (p, xi) in self.free().into_iter().zip(x.iter()) {
            p.set(&mut g, self.value(p, *xi));
        }
        if self.sleeve_on_wall {
            g.sleeve_diameter = g.bladder_inner_diameter + 2.0 * g.bladder_thickness;
        }
        g
    }
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

/// The model's force at a datum, `Err` outside its range: the signed force with inextensible
/// strands (the datasheets list signed forces; the FMU's `signed_force`).
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

/// The least-squares problem: weighted residuals of the fitted curves (each curve's errors over
/// its largest force, divided by the square root of its point count so that every curve weighs
/// the same), in the search coordinates, for the `levenberg-marquardt` crate.
struct Problem<'a> {
    cfg: &'a FitConfig,
    fit: &'a [Curve],
    x: DVector<f64>,
}

impl Problem<'_> {
    fn residuals_at(&self, x: &DVector<f64>) -> DVector<f64> {
        let params = self
            .cfg
            .decode(x)
            .params(self.cfg.nominal_length, self.cfg.model);
        let muscle = params.muscle().ok();
        let mut out = Vec::new();
        for c in self.fit {
            let w = 1.0 / (c.scale() * (c.points.len() as f64).sqrt());
            for d in &c.points {
                out.push(
                    match muscle
                        .as_ref()
                        .map(|m| model_force(m, self.cfg.nominal_length, d))
                    {
                        Some(Ok(f)) if f.is_finite() => (f - d.force) * w,
                        _ => INFEASIBLE * c.scale() * w,
                    },
                );
            }
        }
        DVector::from_vec(out)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = VecStorage<f64, Dyn, U1>;
    type JacobianStorage = VecStorage<f64, Dyn, Dyn>;
    type ParameterStorage = VecStorage<f64, Dyn, U1>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        Some(self.residuals_at(&self.x))
    }

    /// Forward differences: the physics has no parameter derivatives.
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let r0 = self.residuals_at(&self.x);
        let mut jac = DMatrix::zeros(r0.len(), self.x.len());
        for k in 0..self.x.len() {
            let h = 1e-6 * (1.0 + self.x[k].abs());
            let mut xh = self.x.clone();
            xh[k] += h;
            jac.set_column(k, &((self.residuals_at(&xh) - &r0) / h));
        }
        Some(jac)
    }
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
    let (l_n, d) = (cfg.nominal_length, cfg.diameter);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut best: Option<Fit> = None;
    let free = cfg.free();
    for start in 0..cfg.starts.max(1) {
        // Starts spread over plausible muscles: braid 15-40 degrees, a bore near the nominal
        // diameter, walls 5-25% of it, 0-20% pre-strain, rubber 30 kPa - 1 MPa.
        let bore = d * rng.between(0.7, 1.1);
        let wall = d * rng.between(0.05, 0.25);
        let start_at = Geometry {
            braid_angle: rng.between(15.0, 40.0).to_radians(),
            sleeve_diameter: (bore + 2.0 * wall) * rng.between(1.0, 1.2),
            bladder_inner_diameter: bore,
            bladder_thickness: wall,
            bladder_length: l_n * rng.between(0.8, 0.99),
            mooney_c1: rng.between(3e4, 1e6),
            mooney_c2: rng.between(3e4, 1e6),
        };
        let x0 = DVector::from_iterator(
            free.len(),
            free.iter().map(|&p| cfg.coordinate(p, p.get(&start_at))),
        );
        let problem = Problem { cfg, fit, x: x0 };
        let (problem, _report) = LevenbergMarquardt::new()
            .with_patience(cfg.iterations)
            .minimize(problem);
        let r = problem.residuals_at(&problem.x);
        let c = r.norm_squared();
        if c.is_finite() && best.as_ref().is_none_or(|b| c < b.cost) {
            best = Some(Fit {
                params: cfg.decode(&problem.x).params(l_n, cfg.model),
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

/// One fitted or fixed parameter beside its bounds, for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamReport {
    pub name: &'static str,
    pub unit: &'static str,
    pub value: f64,
    pub lower: f64,
    pub upper: f64,
    /// Fixed (not fitted).
    pub fixed: bool,
    /// Where the value sits between the bounds on the search's scale, 0 .. 1.
    pub position: f64,
}

/// Share of a bound's range within which a fitted value counts as sitting at the bound.
pub const AT_BOUND: f64 = 0.01;

/// Every parameter of `params` beside its bounds.
pub fn parameter_report(cfg: &FitConfig, params: &MuscleParams) -> Vec<ParamReport> {
    let g = Geometry::of(params);
    PARAMS
        .iter()
        .map(|&p| {
            let (lower, upper, _) = cfg.bounds(p);
            let value = p.get(&g);
            ParamReport {
                name: p.name(),
                unit: p.unit(),
                value,
                lower,
                upper,
                fixed: !cfg.free().contains(&p),
                position: cfg.position(p, value),
            }
        })
        .collect()
}

#[cfg(test)]
#[path = "calibration_tests.rs"]
mod tests;
