//! KnittedMuscle FMU: gauge pressure and length in, tension force out (dissertation chapter 1).
//!
//! The sleeve's shape model (`shape_model` 0 ideal cylinder, 1 tubular knit, 2 non-cylindrical)
//! is built once from the parameters; the non-cylindrical volume-length table exists only when
//! that shape is selected. Strand friction (eq. 1.21, `friction`) is the shared stop-operator
//! hysteresis; its state is part of the FMU state and advances only in `step`. The Mooney-Rivlin
//! bladder of the McKibben muscle (`bladder_model` 1-6 as McKibbenMuscle's; section 1.3.6) is the
//! same [`Bladder`] code with the knitted cylinder's diameter; it is refused for the
//! non-cylindrical shape, which has no single bladder diameter.

use super::{Model, Partials, Refusal, Report, Status};
use crate::physics::bladder::{
    Bladder, BladderState, BladderTube, KnittedCylinder, SleeveGeometry,
};
use crate::physics::friction::{HysteresisState, StopOperator};
use crate::physics::knitted::{
    KnittedParams, KnittedSleeve, ShapeKind, ShapeModel, StrandFriction,
};
use crate::physics::knitted_bag::Bag;
use crate::physics::mckibben::BladderModel;
use crate::variables::knitted_muscle::{
    CalculatedParameters, Inputs, Outputs, Parameters, Variables,
};
use serde::{Deserialize, Serialize};

/// With a bladder the force grows without bound where the rubber fills the sleeve; a length beyond
/// such a limit is evaluated this fraction of the range inside it (finite, steep force), as in
/// the McKibbenMuscle FMU. Where the sleeve's own limit (strand thickness) comes first the
/// bladder is regular and only a rounding-level margin keeps the open interval.
const FILL_MARGIN: f64 = 1e-3;
const SLEEVE_MARGIN: f64 = 1e-12;

#[derive(Clone, Debug, Serialize, Deserialize)]
struct Friction {
    strand: StrandFriction,
    operator: StopOperator,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct KnittedMuscle {
    sleeve: KnittedSleeve,
    /// `None` when `bladder_model` is 0.
    bladder: Option<Bladder<KnittedCylinder>>,
    /// Lengths evaluated: the sleeve's range, or inside the bladder's open range.
    valid: (f64, f64),
    /// `None` when `friction` is off.
    friction: Option<Friction>,
    /// Section 1.4's bag, `None` when `bag_diameter` is 0.
    bag: Option<Bag>,
    /// Friction history (eq. 1.21), advanced only by accepted steps.
    history: HysteresisState,
    /// Whether the last evaluation was outside the valid lengths: its warning is logged once per
    /// excursion.
    out_of_range: bool,
    /// Whether the last evaluation needed the zero-pressure fallback of a collapsing bladder:
    /// logged once per excursion.
    collapsed: bool,
    /// The length range reported as `min_length`, `max_length` (m).
    length_range: (f64, f64),
    /// The last partials, the point (pressure, length, friction z and position, as bits) they
    /// were taken at, and whether they hold the bladder's stiffness row (a second-order pass): a
    /// Jacobian's further seeds reuse them. Not part of the FMU state.
    #[serde(skip)]
    partials_cache: Option<([u64; 4], bool, Partials)>,
}

/// Outputs at one input point, with the friction history after moving there.
struct Output {
    force: f64,
    volume: f64,
    effective_pressure: f64,
    friction_force: f64,
    max_radius: f64,
    stiffness: f64,
    history: HysteresisState,
}

fn sleeve_params(r: &Parameters) -> Result<KnittedParams, String> {
    Ok(match r.preset {
        0 => KnittedParams {
            stitches_per_row: r.stitches_per_row,
            rows: r.rows,
            row_strand_length: r.row_strand_length,
            strand_thickness: r.strand_thickness,
            bladder_outer_radius: 0.0,
        },
        1 => KnittedParams::prototype(),
        2 => KnittedParams::fig_1_16(r.strand_thickness),
        k => {
            return Err(format!(
                "preset must be 0 (none), 1 (section 1.4 prototype) or 2 (Fig. 1.16), got {k}"
            ))
        }
    })
}

fn bladder(
    r: &Parameters,
    sleeve: &KnittedSleeve,
) -> Result<Option<Bladder<KnittedCylinder>>, String> {
    let Some(wall) = BladderModel::from_switch(r.bladder_model, r.bladder_layers)?.wall() else {
        return Ok(None);
    };
    let tube = BladderTube {
        inner_diameter: r.bladder_inner_diameter,
        thickness: r.bladder_thickness,
        unstretched_length: r.bladder_length,
        mooney_c1: r.mooney_c1,
        mooney_c2: r.mooney_c2,
    };
    Bladder::knitted_wall(sleeve, tube, wall).map(Some)
}

/// The lengths evaluated: the sleeve's closed range, or the bladder's open range pulled in by a
/// margin at each end (larger where the rubber fills the sleeve and the force is singular).
fn valid_lengths(sleeve: &KnittedSleeve, bladder: Option<&Bladder<KnittedCylinder>>) -> (f64, f64) {
    let (s_lo, s_hi) = (sleeve.min_length(), sleeve.max_length());
    let Some(b) = bladder else {
        return (s_lo, s_hi);
    };
    let (lo, hi) = (b.min_length(), b.max_length());
    let margin = |sleeve_limited: bool| {
        (hi - lo)
            * if sleeve_limited {
                SLEEVE_MARGIN
            } else {
                FILL_MARGIN
            }
    };
    (lo + margin(lo <= s_lo), hi - margin(hi >= s_hi))
}

fn shape_kind(p: &Parameters) -> Result<ShapeKind, String> {
    Ok(match p.shape_model {
        0 => ShapeKind::Ideal,
        1 => ShapeKind::Tubular,
        2 => {
            let segments = p.shape_segments;
            // The range itself is checked by the shape solver; this only refuses negatives.
            let segments = usize::try_from(segments)
                .map_err(|_| format!("shape_segments must be at least 2, got {segments}"))?;
            ShapeKind::NonCylindrical { segments }
        }
        k => {
            return Err(format!(
                "shape_model must be 0 (ideal cylinder), 1 (tubular knit) or 2 (non-cylindrical), \
                 got {k}"
            ))
        }
    })
}

impl KnittedMuscle {
    /// The physics at the current inputs; a length outside `[min_length, max_length]` is
    /// evaluated at the nearer limit, where the sleeve is rigid (logged once per excursion).
    /// `None` when the physics refuses (logged); the outputs then keep their values.
    fn compute(&mut self, inputs: &Inputs, report: &mut Report) -> Option<Output> {
        let (pressure, length) = (inputs.pressure, inputs.length);
        let s = &self.sleeve;
        let (lo, hi) = self.valid;
        let l = if length.is_nan() {
            hi
        } else {
            length.max(lo).min(hi)
        };
        if l == length {
            self.out_of_range = false;
        } else {
            report.clamp(!self.out_of_range, || {
                format!(
                    "length {length} m is outside the valid lengths {} .. {} m (max_length {} m); \
                     evaluating at length {l} m until the inputs return",
                    lo, hi, self.length_range.1
                )
            });
            self.out_of_range = true;
        }
        if let Some(b) = &self.bladder {
            let (out, fallback) = self.compute_with_bladder(b, pressure, l);
            if let Some(reason) = &fallback {
                report.clamp(!self.collapsed, || {
                    format!("{reason}; evaluating at zero gauge pressure until the inputs return")
                });
            }
            self.collapsed = fallback.is_some();
            return Some(out);
        }
        // The thin bag inside the sleeve cannot pull it inwards: a vacuum acts as zero.
        let p_eff = if pressure.is_finite() {
            pressure.max(0.0)
        } else {
            0.0
        };
        let next = self
            .friction
            .as_ref()
            .map(|f| f.operator.advance(&self.history, l));
        let friction = self
            .friction
            .as_ref()
            .zip(next)
            .map(|(f, n)| (&f.strand, n.z));
        match s.evaluate_in_bag(p_eff, l, friction, self.bag.as_ref()) {
            Ok(state) => Some(Output {
                force: state.force,
                volume: state.volume,
                effective_pressure: p_eff,
                friction_force: state.friction_force,
                max_radius: state.max_radius,
                stiffness: state.stiffness,
                history: next.unwrap_or(self.history),
            }),
            Err(reason) => {
                // Unreachable with finite inputs in range.
                report.add(
                    Status::Error,
                    format!("cannot evaluate the sleeve: {reason}"),
                );
                None
            }
        }
    }

    /// Section 1.3.6: the bladder's force (eq. 2.16-2.17 with the knitted cylinder) and, with
    /// friction, eq. 1.21 fed by the sleeve's strand tension `P_eff (A - dV/dL)` (which is
    /// `F + P A` without a bladder). A vacuum so deep that the free bladder would collapse is
    /// evaluated at zero gauge pressure; the reason is returned for the log.
    fn compute_with_bladder(
        &self,
        b: &Bladder<KnittedCylinder>,
        pressure: f64,
        l: f64,
    ) -> (Output, Option<String>) {
        let p = if pressure.is_finite() { pressure } else { 0.0 };
        let mut fallback = None;
        let state = match b.evaluate(p, l) {
            Ok(state) => state,
            Err(reason) => {
                fallback = Some(reason);
                match b.evaluate(0.0, l) {
                    Ok(state) => state,
                    // Cannot happen inside the valid range; keep the outputs finite regardless.
                    Err(_) => BladderState {
                        force: 0.0,
                        strand_force: 0.0,
                        strand_stiffness: 0.0,
                        pressure_force: 0.0,
                        elastic_force: 0.0,
                        effective_pressure: 0.0,
                        effective_pressure_slope: 0.0,
                        contact: false,
                        threshold_pressure: 0.0,
                        fluid_volume: 0.0,
                        inner_diameter: 0.0,
                        outer_diameter: 0.0,
                        stretch_axial: 1.0,
                        stretch_hoop: 1.0,
                        stretch_radial: 1.0,
                        stress_axial: 0.0,
                        stress_hoop: 0.0,
                        stress_radial: 0.0,
                        stiffness: 0.0,
                    },
                }
            }
        };
        let mut out = Output {
            force: state.force,
            volume: state.fluid_volume,
            effective_pressure: state.effective_pressure,
            friction_force: 0.0,
            max_radius: 0.5 * b.sleeve().diameter_and_slope(l).0,
            stiffness: state.stiffness,
            history: self.history,
        };
        if let Some(f) = &self.friction {
            let next = f.operator.advance(&self.history, l);
            // Eq. 1.21 fed by the strand tension T = F - (F_pressure + F_elastic), with
            // d(offset)/dL = F_0' - T_0'.
            let offset = state.pressure_force + state.elastic_force;
            let offset_slope = state.stiffness - state.strand_stiffness;
            match f
                .strand
                .apply(state.force, state.stiffness, -offset, -offset_slope, next.z)
            {
                Ok(with) => {
                    out.force = with.force;
                    out.friction_force = with.friction_force;
                    out.stiffness = with.stiffness;
                    out.history = next;
                }
                // Unreachable for a finite bladder state; the frictionless force stands.
                Err(reason) => fallback = Some(format!("eq. 1.21 friction skipped: {reason}")),
            }
        }
        (out, fallback)
    }

    fn write(o: &mut Outputs, out: &Output) {
        o.force = out.force;
        o.volume = out.volume;
        o.effective_pressure = out.effective_pressure;
        o.friction_force = out.friction_force;
        o.max_radius = out.max_radius;
        o.stiffness = out.stiffness;
    }
}

/// `[d/dP, d/dL]` of the outputs at one point.
#[derive(Default)]
struct Rows {
    force: [f64; 2],
    volume: [f64; 2],
    effective_pressure: [f64; 2],
    friction_force: [f64; 2],
    max_radius: [f64; 2],
    /// `None` with a bladder unless asked for: its stiffness is itself a derivative, whose
    /// partials need the bladder's second-order pass.
    stiffness: Option<[f64; 2]>,
}

impl KnittedMuscle {
    /// Exact partials on the branch [`Self::compute`] takes (see the module's README section for
    /// the one-sided choices): eq. 1.6-1.14 or the table's interpolant differentiated, the
    /// bladder's [`Bladder::evaluate_with_partials`], eq. 1.21 with the stop operator's slope;
    /// with a bladder, the stiffness's row only if `stiffness` (from
    /// [`Bladder::stiffness_partials`]).
    fn partials_at(&self, inputs: &Inputs, stiffness: bool) -> Result<Partials, String> {
        let (pressure, length) = (inputs.pressure, inputs.length);
        if !(pressure.is_finite() && length.is_finite()) {
            return Err(format!(
                "partials need finite inputs, got pressure {pressure} Pa and length {length} m"
            ));
        }
        let (lo, hi) = self.valid;
        let l = length.max(lo).min(hi);
        // A clamped length no longer moves with the input.
        let length_moves = if l == length { 1.0 } else { 0.0 };
        let direction = if l >= self.history.position {
            1.0
        } else {
            -1.0
        };
        let mut r = match &self.bladder {
            Some(b) => self.bladder_rows(b, pressure, l, direction, stiffness)?,
            None => self.sleeve_rows(pressure, l, direction),
        };
        let mut table = Partials::default();
        let mut add = |name: &'static str, row: &mut [f64; 2]| {
            row[1] *= length_moves;
            table.row(name, &[("pressure", row[0]), ("length", row[1])]);
        };
        add("force", &mut r.force);
        add("volume", &mut r.volume);
        add("effective_pressure", &mut r.effective_pressure);
        add("friction_force", &mut r.friction_force);
        add("max_radius", &mut r.max_radius);
        if let Some(mut stiffness) = r.stiffness {
            add("stiffness", &mut stiffness);
        }
        Ok(table)
    }

    /// The sleeve alone: `F_0 = -P_eff V'`, stiffness `-P_eff V''` (eq. 1.8, 1.14 or the table),
    /// `P_eff = max(P, 0)` (slope 0 at `P = 0`), and eq. 1.21 with `k = sqrt(2) C_f z(L)`:
    /// `F = (F_0 + k P_eff A) / (1 - k)`, `A = V / L`.
    fn sleeve_rows(&self, pressure: f64, l: f64, direction: f64) -> Rows {
        let s = &self.sleeve;
        let p_eff = pressure.max(0.0);
        let on = if pressure > 0.0 { 1.0 } else { 0.0 };
        if let Some(bag) = &self.bag {
            if let Some(rows) = bag_rows(s, bag, p_eff, l, on) {
                return rows;
            }
        }
        let (v, v1, v2) = s.volume_derivatives(l);
        let v3 = s.volume_third_derivative(l);
        let mut r = Rows {
            force: [-on * v1, -p_eff * v2],
            volume: [0.0, v1],
            effective_pressure: [on, 0.0],
            friction_force: [0.0, 0.0],
            max_radius: [0.0, s.max_radius_slope(l)],
            stiffness: Some([-on * v2, -p_eff * v3]),
        };
        let Some(f) = &self.friction else {
            return r;
        };
        let next = f.operator.advance(&self.history, l);
        let k = std::f64::consts::SQRT_2 * f.strand.coefficient * next.z.clamp(-1.0, 1.0);
        let dk_dl =
            std::f64::consts::SQRT_2 * f.strand.coefficient * f.operator.slope(&next, direction);
        // A = V / L and its slopes (eq. 1.21's pressure area).
        let area = (v / l).max(0.0);
        let area_1 = (v1 * l - v) / (l * l);
        let area_2 = v2 / l - 2.0 * (v1 * l - v) / (l * l * l);
        let (f0, f0_l) = (-p_eff * v1, -p_eff * v2);
        let (offset, offset_l) = (p_eff * area, p_eff * area_1);
        let force = (f0 + k * offset) / (1.0 - k);
        if force + offset < 0.0 {
            // Slack strands carry no friction (StrandFriction::apply).
            return r;
        }
        let stiffness = (f0_l + k * offset_l) / (1.0 - k);
        let force_p = (-on * v1 + k * on * area) / (1.0 - k);
        let force_l = stiffness + dk_dl * (offset + force) / (1.0 - k);
        let stiffness_p = (-on * v2 + k * on * area_1) / (1.0 - k);
        let stiffness_l = (-p_eff * v3 + k * p_eff * area_2) / (1.0 - k)
            + dk_dl * (offset_l + stiffness) / (1.0 - k);
        r.friction_force = [force_p - r.force[0], force_l - r.force[1]];
        r.force = [force_p, force_l];
        r.stiffness = Some([stiffness_p, stiffness_l]);
        r
    }

    /// With the bladder (section 1.3.6): its partials, from the same pass as its state; a vacuum
    /// the free bladder cannot hold is evaluated at zero pressure (pressure column zero). Eq. 1.21
    /// adds `k T / (1 - k)` with `T = P_eff g` the strand tension.
    fn bladder_rows(
        &self,
        b: &Bladder<KnittedCylinder>,
        pressure: f64,
        l: f64,
        direction: f64,
        stiffness: bool,
    ) -> Result<Rows, String> {
        let ((state, d), on, used) = match b.evaluate_with_partials(pressure, l) {
            Ok(x) => (x, 1.0, pressure),
            Err(_) => (b.evaluate_with_partials(0.0, l)?, 0.0, 0.0),
        };
        let curvature = if stiffness {
            Some(b.stiffness_partials(used, l)?)
        } else {
            None
        };
        let mut r = Rows {
            force: d.force,
            volume: d.fluid_volume,
            effective_pressure: d.effective_pressure,
            friction_force: [0.0, 0.0],
            max_radius: [0.0, 0.5 * b.sleeve().diameter_and_slope(l).1],
            stiffness: curvature.map(|c| c.stiffness),
        };
        if let Some(f) = &self.friction {
            let next = f.operator.advance(&self.history, l);
            let k = std::f64::consts::SQRT_2 * f.strand.coefficient * next.z.clamp(-1.0, 1.0);
            let dk_dl = std::f64::consts::SQRT_2
                * f.strand.coefficient
                * f.operator.slope(&next, direction);
            let tension = state.strand_force;
            if tension >= 0.0 {
                let (g, _) = b.sleeve().strand_area(l);
                let tension_p = d.effective_pressure[0] * g;
                let tension_l = state.strand_stiffness;
                let gain = k / (1.0 - k);
                r.friction_force = [
                    gain * tension_p,
                    gain * tension_l + dk_dl * tension / ((1.0 - k) * (1.0 - k)),
                ];
                r.force = [
                    r.force[0] + r.friction_force[0],
                    r.force[1] + r.friction_force[1],
                ];
                // Stiffness S + k T_L / (1 - k) (eq. 1.21 with z held), T_L the strand slope.
                if let (Some(row), Some(c)) = (r.stiffness.as_mut(), curvature) {
                    let t = c.strand_stiffness;
                    row[0] += gain * t[0];
                    row[1] += gain * t[1] + dk_dl * tension_l / ((1.0 - k) * (1.0 - k));
                }
            }
        }
        for row in [
            &mut r.force,
            &mut r.volume,
            &mut r.effective_pressure,
            &mut r.friction_force,
        ] {
            row[0] *= on;
        }
        if let Some(row) = r.stiffness.as_mut() {
            row[0] *= on;
        }
        Ok(r)
    }
}

impl Model for KnittedMuscle {
    type Variables = Variables;
    const ALGEBRAIC_MODEL_EXCHANGE: bool = true;
    const DOCUMENTATION: &'static str = include_str!("knitted_muscle.html");

    fn adopt_history(&mut self, saved: &Self) -> Result<(), String> {
        saved.history.check("friction history")?;
        self.history = saved.history;
        self.out_of_range = saved.out_of_range;
        self.collapsed = saved.collapsed;
        Ok(())
    }

    fn new(p: &Parameters, start: &Inputs) -> Result<Self, Refusal> {
        let sleeve = KnittedSleeve::new(sleeve_params(p)?, shape_kind(p)?)?;
        let bladder = bladder(p, &sleeve)?;
        let valid = valid_lengths(&sleeve, bladder.as_ref());
        let bag = match p.bag_diameter {
            0.0 => None,
            diameter => {
                if bladder.is_some() || matches!(sleeve.shape(), ShapeModel::NonCylindrical(_)) {
                    return Err(
                        "bag_diameter needs a cylindrical sleeve (shape_model 0 or 1) \
                                and no rubber bladder (bladder_model 0)"
                            .into(),
                    );
                }
                Some(Bag::new(diameter, p.bag_membrane_stiffness)?)
            }
        };
        let friction = if p.friction {
            Some(Friction {
                strand: StrandFriction::new(p.friction_coefficient)?,
                operator: StopOperator::new(p.presliding_length)?,
            })
        } else {
            None
        };
        let length_range = match &bladder {
            Some(b) => (b.min_length(), b.max_length()),
            None => (sleeve.min_length(), sleeve.max_length()),
        };
        // Friction starts relaxed (z = 0) where the sleeve is at initialization.
        let start = start.length;
        let history = HysteresisState::at_rest(if start.is_nan() {
            valid.1
        } else {
            start.max(valid.0).min(valid.1)
        });
        Ok(Self {
            sleeve,
            bladder,
            valid,
            friction,
            bag,
            history,
            out_of_range: false,
            collapsed: false,
            length_range,
            partials_cache: None,
        })
    }

    fn calculated_parameters(&self) -> CalculatedParameters {
        CalculatedParameters {
            min_length: self.length_range.0,
            max_length: self.length_range.1,
            free_contraction_length: self.sleeve.free_contraction_length(),
        }
    }

    fn evaluate(&mut self, inputs: &Inputs, outputs: &mut Outputs, report: &mut Report) {
        if let Some(out) = self.compute(inputs, report) {
            Self::write(outputs, &out);
        }
    }

    fn step(
        &mut self,
        inputs: &Inputs,
        outputs: &mut Outputs,
        _time: f64,
        _step: f64,
        report: &mut Report,
    ) {
        // Quasi-static: the held inputs at the end of the step fix the outputs; the friction
        // history follows the length path sampled at the communication points.
        if let Some(out) = self.compute(inputs, report) {
            Self::write(outputs, &out);
            self.history = out.history;
        }
    }
    fn partials(&mut self, inputs: &Inputs) -> Result<Partials, String> {
        self.cached_partials(inputs, true)
    }

    fn partials_for(
        &mut self,
        inputs: &Inputs,
        outputs: &[&'static str],
    ) -> Result<Partials, String> {
        // With a bladder the stiffness's row costs a second-order pass: only when asked.
        self.cached_partials(inputs, outputs.contains(&"stiffness"))
    }
}

impl KnittedMuscle {
    fn cached_partials(&mut self, inputs: &Inputs, stiffness: bool) -> Result<Partials, String> {
        let h = &self.history;
        let key = [inputs.pressure, inputs.length, h.z, h.position].map(f64::to_bits);
        if let Some((cached, has_stiffness, rows)) = &self.partials_cache {
            if *cached == key && (*has_stiffness || !stiffness) {
                return Ok(rows.clone());
            }
        }
        let rows = self.partials_at(inputs, stiffness)?;
        self.partials_cache = Some((key, stiffness, rows.clone()));
        Ok(rows)
    }
}

/// Section 1.4's bag where it binds (`pi R(P)^2 L` below the sleeve's volume, see
/// [`Bag::volume_derivatives`]): `V = A(P) L` with `A = pi R^2`, `F = -P_eff A` pushing the
/// clamps apart, no stiffness, and the strands slack (eq. 1.21's tension `F + P A` is zero, so
/// no friction); the largest radius is the bag's. `None` where the sleeve sets the volume: the
/// sleeve's rows hold there, the largest radius being the sleeve's (the bag is wider).
fn bag_rows(s: &KnittedSleeve, bag: &Bag, p_eff: f64, l: f64, on: f64) -> Option<Rows> {
    if bag.volume_derivatives(s, p_eff, l) == s.volume_derivatives(l) {
        return None;
    }
    let r = bag.radius_at(p_eff);
    let area = std::f64::consts::PI * r * r;
    // dA/dP = 2 pi R dR/dP; R = R0 (1 + P R0 / (E t)) for P > 0.
    let area_p = on * 2.0 * std::f64::consts::PI * r * bag.radius_slope(p_eff);
    let max_radius = if r <= s.max_radius(l) {
        [on * bag.radius_slope(p_eff), 0.0]
    } else {
        [0.0, s.max_radius_slope(l)]
    };
    Some(Rows {
        force: [-on * area - p_eff * area_p, 0.0],
        volume: [area_p * l, area],
        effective_pressure: [on, 0.0],
        friction_force: [0.0, 0.0],
        max_radius,
        stiffness: Some([0.0, 0.0]),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::Status;
    use std::f64::consts::SQRT_2;

    fn parameters_with(shape: i32, friction: bool) -> Parameters {
        Parameters {
            shape_model: shape,
            friction,
            ..Parameters::default()
        }
    }

    /// A model from `p` at the start inputs, with its calculated parameters.
    fn built(p: &Parameters) -> (KnittedMuscle, Inputs, Outputs, CalculatedParameters) {
        let inputs = Inputs::default();
        let m = KnittedMuscle::new(p, &inputs).unwrap();
        let calculated = m.calculated_parameters();
        (m, inputs, Outputs::default(), calculated)
    }

    #[test]
    fn only_step_commits_the_friction_history() {
        let (mut m, mut inputs, mut out, _) = built(&parameters_with(0, true));
        let start = m.history;
        inputs.pressure = 14e3;
        inputs.length = 0.35;
        let mut report = Report::default();
        m.evaluate(&inputs, &mut out, &mut report);
        assert_eq!(m.history, start);
        // Shortening by far more than the presliding length: full friction against it (z = -1),
        // of magnitude sqrt(2) Cf (F + P A) (eq. 1.21).
        assert!(out.friction_force < 0.0);
        m.step(&inputs, &mut out, 0.0, 1e-3, &mut report);
        assert_eq!(m.history.z, -1.0);
        assert_eq!(m.history.position, 0.35);
        let (f, fr) = (out.force, out.friction_force);
        let tension = f + 14e3 * m.sleeve.mean_area(0.35);
        assert!((fr + SQRT_2 * 0.25 * tension).abs() < 1e-12 * f.abs());
        assert_eq!(report.status(), Status::Ok);
    }

    #[test]
    fn out_of_range_is_the_nearest_limit_warned_once_per_excursion() {
        let (mut m, mut inputs, mut out, calculated) = built(&parameters_with(2, false));
        let (lo, hi) = (calculated.min_length, calculated.max_length);
        inputs.pressure = 14e3;
        inputs.length = hi;
        let mut report = Report::default();
        m.evaluate(&inputs, &mut out, &mut report);
        let at_limit = out.clone();
        let mut warned = 0;
        for length in [hi + 1.0, 2.0 * hi, 0.4, 0.0, lo - 1e-9] {
            let mut report = Report::default();
            inputs.length = length;
            m.evaluate(&inputs, &mut out, &mut report);
            warned += report.clamp_messages().len();
            assert_eq!(report.status(), Status::Ok);
            assert_eq!(report.clamped(), !(lo..=hi).contains(&length));
            if length > hi {
                assert_eq!(out.force, at_limit.force);
            }
            let values = [
                out.force,
                out.volume,
                out.effective_pressure,
                out.friction_force,
                out.max_radius,
                out.stiffness,
            ];
            assert!(values.iter().all(|x| x.is_finite()));
        }
        assert_eq!(warned, 2);
    }

    #[test]
    fn bladder_is_refused_for_the_non_cylindrical_shape() {
        let mut p = parameters_with(2, false);
        p.bladder_model = 2;
        let e = KnittedMuscle::new(&p, &Inputs::default()).unwrap_err().0;
        assert!(e.contains("cylindrical sleeve"), "{e}");
        for shape in [0, 1] {
            let mut p = parameters_with(shape, false);
            p.preset = 2;
            p.bladder_model = 1;
            assert!(KnittedMuscle::new(&p, &Inputs::default()).is_ok());
        }
    }

    #[test]
    fn bladder_friction_stiffness_is_the_slope_with_z_held() {
        // Eq. 1.21 fed by the strand tension P_eff (A - dV/dL): dF/dL by central differences with
        // the hysteresis state held (step commits z = -1 first).
        let mut p = parameters_with(0, true);
        p.preset = 2;
        p.bladder_model = 2;
        let (mut m, mut inputs, mut out, _) = built(&p);
        let mut report = Report::default();
        inputs.pressure = 550e3;
        inputs.length = 0.07;
        m.step(&inputs, &mut out, 0.0, 1e-3, &mut report);
        assert_eq!(m.history.z, -1.0);
        let mut at = |m: &mut KnittedMuscle, l: f64| {
            inputs.length = l;
            m.evaluate(&inputs, &mut out, &mut Report::default());
            (out.force, out.stiffness, out.friction_force)
        };
        // Stay within the presliding length below 0.07 so that z stays -1.
        let h = 1e-6;
        let (fp, _, _) = at(&mut m, 0.07 - 1e-5 + h);
        let (fm, _, _) = at(&mut m, 0.07 - 1e-5 - h);
        let (f, k, friction_force) = at(&mut m, 0.07 - 1e-5);
        assert!(friction_force < 0.0);
        let fd = (fp - fm) / (2.0 * h);
        assert!((k - fd).abs() < 1e-4 * fd.abs(), "{k} {fd} (F {f})");
    }

    #[test]
    fn non_cylindrical_needs_a_thick_strand() {
        let mut p = parameters_with(2, false);
        p.strand_thickness = 0.0;
        let e = KnittedMuscle::new(&p, &Inputs::default()).unwrap_err().0;
        assert!(e.contains("positive minimum radius"), "{e}");
        p.shape_segments = -3;
        p.strand_thickness = 2e-4;
        assert!(KnittedMuscle::new(&p, &Inputs::default()).is_err());
    }

    const OUTPUTS: [&str; 6] = [
        "force",
        "volume",
        "effective_pressure",
        "friction_force",
        "max_radius",
        "stiffness",
    ];

    fn values(o: &Outputs) -> [f64; 6] {
        [
            o.force,
            o.volume,
            o.effective_pressure,
            o.friction_force,
            o.max_radius,
            o.stiffness,
        ]
    }

    /// Every partial against central differences of the model's own outputs, at points across
    /// every shape model, friction, and the bladder's walls (free and in contact). A point where
    /// the one-sided differences disagree straddles a kink (contact threshold, a table node) and
    /// is skipped; few may be.
    #[test]
    fn partials_match_central_differences_across_shapes_and_effects() {
        let mut configs = Vec::new();
        for shape in [0, 1, 2] {
            for friction in [false, true] {
                configs.push((parameters_with(shape, friction), vec![1.4e4, 5e4, -2e4]));
            }
        }
        for shape in [0, 1] {
            for bladder_model in [1, 2, 3] {
                for friction in [false, true] {
                    let mut p = parameters_with(shape, friction);
                    p.preset = 2;
                    p.bladder_model = bladder_model;
                    p.bladder_layers = 6;
                    configs.push((p, vec![2e4, 1.5e5, 5.5e5]));
                }
            }
        }
        // Section 1.4's prototype in its 85 mm bag, inextensible and stretching (E t = 1e4 N/m):
        // the bag binds at the shorter lengths.
        for shape in [0, 1] {
            for membrane in [0.0, 1e4] {
                for friction in [false, true] {
                    let mut p = parameters_with(shape, friction);
                    p.preset = 1;
                    p.bag_diameter = 0.085;
                    p.bag_membrane_stiffness = membrane;
                    configs.push((p, vec![1.4e4, 5e4, -2e4]));
                }
            }
        }
        let (mut checked, mut skipped, mut worst) = (0, 0, 0.0f64);
        let mut bag_binds = 0;
        for (p, pressures) in &configs {
            let calculated = KnittedMuscle::new(p, &Inputs::default())
                .unwrap()
                .calculated_parameters();
            let (lo, hi) = (calculated.min_length, calculated.max_length);
            for frac in [0.3, 0.6, 0.85] {
                let length = lo + frac * (hi - lo);
                // History 30 um behind: friction mid-presliding (0.1 mm), off the reversal.
                let start = Inputs {
                    length: length - 3e-5,
                    ..Default::default()
                };
                let mut m = KnittedMuscle::new(p, &start).unwrap();
                for &pressure in pressures {
                    let x = Inputs { pressure, length };
                    let exact = m.partials(&x).unwrap();
                    if let Some(bag) = &m.bag {
                        let p_eff = pressure.max(0.0);
                        bag_binds +=
                            usize::from(bag_rows(&m.sleeve, bag, p_eff, length, 1.0).is_some());
                    }
                    let mut at = |dp: f64, dl: f64| {
                        let mut out = Outputs::default();
                        let y = Inputs {
                            pressure: pressure + dp,
                            length: length + dl,
                        };
                        m.evaluate(&y, &mut out, &mut Report::default());
                        values(&out)
                    };
                    let base = at(0.0, 0.0);
                    let h = [1e-6 * pressure.abs() + 1e-3, 1e-7 * length];
                    let steps = [[h[0], 0.0], [0.0, h[1]]];
                    for (j, input) in ["pressure", "length"].into_iter().enumerate() {
                        let (up, down) =
                            (at(steps[j][0], steps[j][1]), at(-steps[j][0], -steps[j][1]));
                        for (k, name) in OUTPUTS.into_iter().enumerate() {
                            let row = exact.get(name).unwrap();
                            let e = row.iter().find(|(n, _)| *n == input).unwrap().1;
                            let central = (up[k] - down[k]) / (2.0 * h[j]);
                            let (right, left) =
                                ((up[k] - base[k]) / h[j], (base[k] - down[k]) / h[j]);
                            let scale = e.abs().max(central.abs()).max(1e-300);
                            if (right - left).abs() > 1e-3 * scale + 1e-9 {
                                skipped += 1;
                                continue;
                            }
                            let err = (e - central).abs() / scale;
                            assert!(
                                err < 1e-5 || (e - central).abs() < 1e-10 * (1.0 + base[k].abs()),
                                "shape {} bladder {} bag {} friction {} P {pressure} L {length}: \
                                 d{name}/d{input} exact {e} central {central}",
                                p.shape_model,
                                p.bladder_model,
                                p.bag_diameter,
                                p.friction
                            );
                            checked += 1;
                            if (e - central).abs() > 1e-10 * (1.0 + base[k].abs()) {
                                worst = worst.max(err);
                            }
                        }
                    }
                }
            }
        }
        eprintln!(
            "{checked} partials checked ({bag_binds} points where the bag binds), {skipped} at \
             kinks skipped, worst {worst:e}"
        );
        assert!(bag_binds >= 8, "{bag_binds}");
        assert!(
            checked > 800 && skipped * 20 < checked,
            "{checked} {skipped}"
        );
    }

    #[test]
    fn at_the_bags_binding_length_the_partials_are_the_sleeves() {
        // The bag binds strictly below the binding length: there the sleeve's branch, whose
        // force slope is the one-sided difference towards longer lengths.
        let mut p = parameters_with(0, false);
        p.preset = 1;
        p.bag_diameter = 0.085;
        let (mut m, _, _, _) = built(&p);
        let pressure = 14e3;
        let l = m.bag.unwrap().binding_length(&m.sleeve, pressure);
        let force = |m: &mut KnittedMuscle, length: f64| {
            let mut out = Outputs::default();
            m.evaluate(
                &Inputs { pressure, length },
                &mut out,
                &mut Report::default(),
            );
            out.force
        };
        let d = m
            .partials(&Inputs {
                pressure,
                length: l,
            })
            .unwrap();
        let exact = d.get("force").unwrap()[1].1;
        let h = 1e-7 * l;
        let above = (force(&mut m, l + h) - force(&mut m, l)) / h;
        assert!(
            (above - exact).abs() < 1e-4 * exact.abs(),
            "{above} {exact}"
        );
        // Just below, the bag carries the end load, F = -P pi R^2 (the force jumps there), with
        // no length slope.
        let bag_force = -pressure * std::f64::consts::PI * 0.0425f64.powi(2);
        assert!((force(&mut m, l - h) - bag_force).abs() < 1e-12 * bag_force.abs());
        let d = m.partials(&Inputs {
            pressure,
            length: l - h,
        });
        assert_eq!(d.unwrap().get("force").unwrap()[1], ("length", 0.0));
    }

    #[test]
    fn partials_are_zero_out_of_range() {
        let (mut m, _, _, c) = built(&parameters_with(1, false));
        let beyond = Inputs {
            pressure: 1e5,
            length: c.max_length + 0.01,
        };
        let d = m.partials(&beyond).unwrap();
        for name in OUTPUTS {
            assert_eq!(d.get(name).unwrap()[1], ("length", 0.0), "{name}");
        }
        assert!(d.get("force").unwrap()[0].1 != 0.0);
    }
}
