//! The knitted muscle assembled (dissertation chapter 1): the knitted sleeve (eq. 1.5-1.14, or
//! the non-cylindrical table), optionally the Mooney-Rivlin bladder of the McKibben muscle with the
//! knitted cylinder's diameter (section 1.3.6), strand friction (eq. 1.21) on the stop-operator
//! hysteresis, and section 1.4's polyethylene bag. The counterpart of [`super::mckibben`]: the
//! FMU (`models/knitted_muscle.rs`) maps its variables to this and logs what it reports.

use crate::physics::bladder::{Bladder, BladderState, SleeveGeometry};
use crate::physics::by_pressure_length::ByPressureLength;
use crate::physics::friction::{HysteresisState, StopOperator};
use crate::physics::knitted::{FluidContainer, KnittedSleeve, ShapeModel, StrandFriction};
use crate::physics::knitted_bag::Bag;
use crate::physics::knitted_cylinder::KnittedCylinder;
use serde::{Deserialize, Serialize};

/// With a bladder the force grows without bound where the rubber fills the sleeve; a length beyond
/// such a limit is evaluated this fraction of the range inside it (finite, steep force), as in
/// the McKibbenMuscle FMU. Where the sleeve's own limit (strand thickness) comes first the
/// bladder is regular and only a rounding-level margin keeps the open interval.
const FILL_MARGIN: f64 = 1e-3;
const SLEEVE_MARGIN: f64 = 1e-12;

/// Eq. 1.21's strand friction and the stop operator whose state it reads.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Friction {
    pub strand: StrandFriction,
    pub operator: StopOperator,
}

/// The sleeve with what the parameters switch on around it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct KnittedAssembly {
    sleeve: KnittedSleeve,
    /// `None` without a rubber bladder.
    bladder: Option<Bladder<KnittedCylinder>>,
    /// Lengths evaluated: the sleeve's range, or inside the bladder's open range.
    valid: (f64, f64),
    /// `None` when friction is off.
    friction: Option<Friction>,
    /// Section 1.4's bag, `None` without one.
    bag: Option<Bag>,
    /// The length range reported as `min_length`, `max_length` (m).
    length_range: (f64, f64),
}

/// Outputs at one input point, with the friction history after moving there.
pub struct KnittedOutput {
    pub force: f64,
    pub volume: f64,
    pub effective_pressure: f64,
    pub friction_force: f64,
    pub max_radius: f64,
    pub stiffness: f64,
    pub history: HysteresisState,
}

/// Why a bag is refused with the non-cylindrical shape or a rubber bladder (see
/// [`KnittedAssembly::new`]): the bag caps a single radius, and the rubber bladder already holds
/// the air.
pub const BAG_NEEDS_A_CYLINDER: &str = "bag_diameter needs a cylindrical sleeve (shape_model 0 \
     or 1; the non-cylindrical shape has no single radius the bag could cap) and no rubber \
     bladder (bladder_model 0)";

impl KnittedAssembly {
    /// The assembly, with a bag of `(diameter (m), membrane stiffness E t (N/m))` if given; a bag
    /// needs a cylindrical sleeve and no rubber bladder.
    pub fn new(
        sleeve: KnittedSleeve,
        bladder: Option<Bladder<KnittedCylinder>>,
        bag: Option<(f64, f64)>,
        friction: Option<Friction>,
    ) -> Result<Self, String> {
        if bag.is_some()
            && (bladder.is_some() || matches!(sleeve.shape(), ShapeModel::NonCylindrical(_)))
        {
            return Err(BAG_NEEDS_A_CYLINDER.into());
        }
        let bag = match bag {
            Some((diameter, membrane_stiffness)) => Some(Bag::new(diameter, membrane_stiffness)?),
            None => None,
        };
        let valid = valid_lengths(&sleeve, bladder.as_ref());
        let length_range = match &bladder {
            Some(b) => (b.min_length(), b.max_length()),
            None => (sleeve.min_length(), sleeve.max_length()),
        };
        Ok(Self {
            sleeve,
            bladder,
            valid,
            friction,
            bag,
            length_range,
        })
    }

    pub fn sleeve(&self) -> &KnittedSleeve {
        &self.sleeve
    }

    pub fn bag(&self) -> Option<&Bag> {
        self.bag.as_ref()
    }

    pub fn bladder(&self) -> Option<&Bladder<KnittedCylinder>> {
        self.bladder.as_ref()
    }

    /// The lengths evaluated (m): inputs beyond them are evaluated at the nearer one.
    pub fn valid_lengths(&self) -> (f64, f64) {
        self.valid
    }

    /// The length range reported as `min_length`, `max_length` (m).
    pub fn length_range(&self) -> (f64, f64) {
        self.length_range
    }

    /// The state at gauge pressure `pressure` (Pa) and length `l` (m, within
    /// [`Self::valid_lengths`]) from friction history `history`, with the history after moving
    /// there; with a bladder, why a vacuum it cannot hold was evaluated at zero pressure. An error
    /// when the sleeve has no finite state (not with finite inputs in range).
    pub fn evaluate(
        &self,
        pressure: f64,
        l: f64,
        history: &HysteresisState,
    ) -> Result<(KnittedOutput, Option<String>), String> {
        if let Some(b) = &self.bladder {
            return Ok(self.evaluate_with_bladder(b, pressure, l, history));
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
            .map(|f| f.operator.advance(history, l));
        let friction = self
            .friction
            .as_ref()
            .zip(next)
            .map(|(f, n)| (&f.strand, n.z));
        let container = self.bag.as_ref().map(|b| b as &dyn FluidContainer);
        let state = self
            .sleeve
            .evaluate_contained(p_eff, l, friction, container)?;
        Ok((
            KnittedOutput {
                force: state.force,
                volume: state.volume,
                effective_pressure: p_eff,
                friction_force: state.friction_force,
                max_radius: state.max_radius,
                stiffness: state.stiffness,
                history: next.unwrap_or(*history),
            },
            None,
        ))
    }

    /// Section 1.3.6: the bladder's force (eq. 2.16-2.17 with the knitted cylinder) and, with
    /// friction, eq. 1.21 fed by the sleeve's strand tension `P_eff (A - dV/dL)` (which is
    /// `F + P A` without a bladder). A vacuum so deep that the free bladder would collapse is
    /// evaluated at zero gauge pressure; the reason is returned for the log.
    fn evaluate_with_bladder(
        &self,
        b: &Bladder<KnittedCylinder>,
        pressure: f64,
        l: f64,
        history: &HysteresisState,
    ) -> (KnittedOutput, Option<String>) {
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
        let mut out = KnittedOutput {
            force: state.force,
            volume: state.fluid_volume,
            effective_pressure: state.effective_pressure,
            friction_force: 0.0,
            max_radius: 0.5 * b.sleeve().diameter_and_slope(l).0,
            stiffness: state.stiffness,
            history: *history,
        };
        if let Some(f) = &self.friction {
            let next = f.operator.advance(history, l);
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

    /// `[d/dP, d/dL]` of the outputs at `l` (within [`Self::valid_lengths`]), moving in
    /// `direction` (+1 lengthening, -1 shortening) from `history`. Exact on the branch
    /// [`Self::evaluate`] takes: eq. 1.6-1.14 or the table's interpolant differentiated, the
    /// bladder's [`Bladder::evaluate_with_partials`], eq. 1.21 with the stop operator's slope;
    /// with a bladder, the stiffness's row only if `stiffness` (from
    /// [`Bladder::stiffness_partials`]).
    pub fn partial_rows(
        &self,
        pressure: f64,
        l: f64,
        history: &HysteresisState,
        direction: f64,
        stiffness: bool,
    ) -> Result<ByPressureLength, String> {
        match &self.bladder {
            Some(b) => self.bladder_rows(b, pressure, l, history, direction, stiffness),
            None => Ok(self.sleeve_rows(pressure, l, history, direction)),
        }
    }

    /// The sleeve alone: `F_0 = -P_eff V'`, stiffness `-P_eff V''` (eq. 1.8, 1.14 or the table),
    /// `P_eff = max(P, 0)` (slope 0 at `P = 0`), and eq. 1.21 with `k = sqrt(2) C_f z(L)`:
    /// `F = (F_0 + k P_eff A) / (1 - k)`, `A = V / L`.
    fn sleeve_rows(
        &self,
        pressure: f64,
        l: f64,
        history: &HysteresisState,
        direction: f64,
    ) -> ByPressureLength {
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
        let mut r = ByPressureLength {
            force: [-on * v1, -p_eff * v2],
            volume: [0.0, v1],
            effective_pressure: [on, 0.0],
            friction_force: [0.0, 0.0],
            max_radius: [0.0, s.max_radius_slope(l)],
            stiffness: Some([-on * v2, -p_eff * v3]),
            ..Default::default()
        };
        let Some(f) = &self.friction else {
            return r;
        };
        let next = f.operator.advance(history, l);
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
        history: &HysteresisState,
        direction: f64,
        stiffness: bool,
    ) -> Result<ByPressureLength, String> {
        let ((state, d), on, used) = match b.evaluate_with_partials(pressure, l) {
            Ok(x) => (x, 1.0, pressure),
            Err(_) => (b.evaluate_with_partials(0.0, l)?, 0.0, 0.0),
        };
        let curvature = if stiffness {
            Some(b.stiffness_partials(used, l)?)
        } else {
            None
        };
        let mut r = ByPressureLength {
            force: d.force,
            volume: d.volume,
            effective_pressure: d.effective_pressure,
            friction_force: [0.0, 0.0],
            max_radius: [0.0, 0.5 * b.sleeve().diameter_and_slope(l).1],
            stiffness: curvature.map(|c| c.stiffness),
            ..Default::default()
        };
        if let Some(f) = &self.friction {
            let next = f.operator.advance(history, l);
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

/// Section 1.4's bag where it binds (`pi R(P)^2 L` below the sleeve's volume, see
/// [`Bag::volume_derivatives`]): `V = A(P) L` with `A = pi R^2`, `F = -P_eff A` pushing the
/// clamps apart, no stiffness, and the strands slack (eq. 1.21's tension `F + P A` is zero, so
/// no friction); the largest radius is the bag's. `None` where the sleeve sets the volume: the
/// sleeve's rows hold there, the largest radius being the sleeve's (the bag is wider).
pub(crate) fn bag_rows(
    s: &KnittedSleeve,
    bag: &Bag,
    p_eff: f64,
    l: f64,
    on: f64,
) -> Option<ByPressureLength> {
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
    Some(ByPressureLength {
        force: [-on * area - p_eff * area_p, 0.0],
        volume: [area_p * l, area],
        effective_pressure: [on, 0.0],
        friction_force: [0.0, 0.0],
        max_radius,
        stiffness: Some([0.0, 0.0]),
        ..Default::default()
    })
}
