//! Hyperelastic McKibben bladder, dissertation section 2.2.2 (eq. 2.6-2.20).
//!
//! The bladder is an incompressible Mooney-Rivlin tube (eq. 2.8) clamped inside the ideal sleeve of
//! [`crate::physics::gaylord`]. Its wall is integrated through the thickness in one of four ways
//! ([`Wall`]):
//! - [`Wall::Exact`]: the exact thick tube (Rivlin's integral, `exact.rs`), the physics;
//! - [`Wall::Layers`]: nested thin layers, each balanced by eq. 2.12 read with the stress
//!   difference `sigma_22 - sigma_33` (the layer's own pressure drop); it converges to the exact
//!   wall at first order, and one layer is the exact wall's consistent thin-wall limit;
//! - [`Wall::DissertationLayers`]: eq. 2.19-2.20 as written (`sigma_33 = -P` inside each layer and
//!   the inner diameter for both pressures of eq. 2.10); one layer is the thin wall of
//!   eq. 2.6-2.17 as written. The neglected term `p_out (d_out - d_in)` is first order in each
//!   layer's thickness, so more layers never remove it: with no rubber stiffness at all the wall
//!   still more than doubles the contact pressure (muscle A, 690 kPa: `P_eff` 1,445 kPa thin,
//!   1,588 kPa with 16 layers). Kept to reproduce the dissertation's figures;
//! - [`Wall::DissertationContinuum`]: that recursion's limit of infinitely many layers
//!   (`continuum.rs`).
//!
//! Every layer is described by its stretch in squared form, so the per-call work is a handful of
//! multiplications per layer and one reciprocal; the partial derivatives with respect to the muscle
//! length and the bladder's outer diameter are carried along in forward mode (a small dual number),
//! which gives an analytic stiffness and the Newton slope of the free-bladder equation (eq. 2.18).
//!
//! The sleeve enters only through its diameter `D(L)` ([`SleeveGeometry`]). The strand force of
//! eq. 2.16 is written as `P_eff (A - dV/dL)` with `A = pi D^2 / 4` (for a closed cylindrical sleeve
//! `F + P A` is its strand tension, eq. 1.1 / 2.1), which is `P_eff L^2 / (2 pi n^2)` for the
//! helical sleeve of chapter 2 and applies unchanged to the cylindrical knitted sleeves of chapter 1
//! (section 1.3.6: "the same results apply to a knitted muscle"). The bladder is generic over the
//! geometry, so the helical path is monomorphised and costs what it did before the generalisation.

mod continuum;
#[cfg(test)]
mod continuum_tests;
mod exact;
#[cfg(test)]
mod exact_tests;
mod free;
mod geometry;
mod kernel_scalar;
mod layers;
mod partials;
mod state;
mod stiffness_partials;
#[cfg(test)]
mod tests;
mod wall_field;
#[cfg(test)]
mod wall_field_tests;

use crate::physics::numerics::dual::Dual;
use continuum::KernelScalar;
use continuum::WallNode;
pub use geometry::SleeveGeometry;
use state::check_state;
pub use state::BladderState;
use std::f64::consts::PI;
pub use stiffness_partials::BladderCurvature;
pub use wall_field::WallPoint;

/// Mooney-Rivlin `C1` of natural latex used throughout chapter 2 (Fig. 2.9), Pa.
pub const MOONEY_C1: f64 = 161e3;
/// Mooney-Rivlin `C2` of natural latex used throughout chapter 2 (Fig. 2.9), Pa.
pub const MOONEY_C2: f64 = 39e3;
/// Largest accepted number of layers: far past convergence, and it bounds the per-call work.
pub const MAX_LAYERS: usize = 4096;
/// The bore's squared hoop stretch below which a free bladder's axial force is taken from the
/// outside in (see `free_kernel`). The outward form's rounding grows as its inverse (a vacuum on
/// a nearly stress-free rubber pulls it to 1e-8 and below); above it both forms agree to
/// rounding, and the outward one, which the kernel has already computed, is kept.
const PULLED_IN_BORE: f64 = 1e-2;

/// The relaxed bladder tube before it is clamped into the sleeve (Table 2.1 columns).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BladderTube {
    /// Unstretched inner diameter `D_RI`, m.
    pub inner_diameter: f64,
    /// Unstretched wall thickness, m; `D_RO = D_RI + 2 thickness`.
    pub thickness: f64,
    /// Unstretched length `L_R0`, m; shorter than the muscle means pre-strain (Table 2.1 B, C).
    pub unstretched_length: f64,
    /// Mooney-Rivlin `C1`, Pa (eq. 2.8).
    pub mooney_c1: f64,
    /// Mooney-Rivlin `C2`, Pa (eq. 2.8).
    pub mooney_c2: f64,
}

impl BladderTube {
    /// A tube of the chapter's latex (Fig. 2.9's Mooney-Rivlin constants).
    pub fn latex(inner_diameter: f64, thickness: f64, unstretched_length: f64) -> Self {
        Self {
            inner_diameter,
            thickness,
            unstretched_length,
            mooney_c1: MOONEY_C1,
            mooney_c2: MOONEY_C2,
        }
    }
}

/// How the wall is integrated through its thickness.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Wall {
    /// The exact thick-walled tube (Rivlin's integral) by an `n`-point Gauss-Legendre quadrature
    /// through the wall (see `exact.rs`); converges geometrically in `n`.
    Exact(usize),
    /// `n` nested thin layers, each balanced by its own stress difference (eq. 2.12 with
    /// `sigma_33 = 0`); first order in `1/n` towards [`Wall::Exact`]. One layer is the exact
    /// wall's consistent thin-wall limit.
    Layers(usize),
    /// `n` nested thin layers, eq. 2.19-2.20 as the dissertation writes them (1 = its thin wall
    /// of eq. 2.6-2.17, `sigma_33 = -P`); first order in `1/n` towards
    /// [`Wall::DissertationContinuum`], not towards the exact wall.
    DissertationLayers(usize),
    /// The limit of [`Wall::DissertationLayers`] for infinitely many layers by an `n`-point
    /// Gauss-Legendre quadrature through the wall (see `continuum.rs`).
    DissertationContinuum(usize),
}

impl Wall {
    /// Layers or quadrature nodes.
    pub fn count(self) -> usize {
        match self {
            Self::Exact(n)
            | Self::Layers(n)
            | Self::DissertationLayers(n)
            | Self::DissertationContinuum(n) => n,
        }
    }
}

/// Parameter-only constants of one nested layer (eq. 2.19-2.20), precomputed once.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
struct Layer {
    /// `1 / D_0i^2`.
    inv_d0_sq: f64,
    /// `D_RO^2 - D_0i^2`: with the axial stretch it fixes the layer's diameter (incompressibility).
    excess_sq: f64,
    /// `Delta D / D_0i`, the layer's relative wall in eq. 2.19.
    wall_ratio: f64,
    /// Rubber volume of the layer, m^3 (eq. 2.6 for the layer).
    rubber_volume: f64,
}

/// A Mooney-Rivlin bladder inside a given sleeve (the helical McKibben
/// [`Sleeve`](crate::physics::gaylord::Sleeve) or a
/// [`KnittedCylinder`](crate::physics::knitted_cylinder::KnittedCylinder)), with everything that depends only on parameters precomputed (layer
/// constants, rubber volume, length limits).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Bladder<S> {
    sleeve: S,
    tube: BladderTube,
    wall: Wall,
    /// The layers of the layered walls (empty for the quadratures).
    layers: Vec<Layer>,
    /// The quadrature nodes of [`Wall::Exact`] and [`Wall::DissertationContinuum`].
    nodes: Vec<WallNode>,
    outer_diameter: f64,
    rubber_volume: f64,
    min_length: f64,
    max_length: f64,
}

impl<S: SleeveGeometry> Bladder<S> {
    /// Builds a bladder of `layers` nested thin layers as the dissertation writes them
    /// ([`Wall::DissertationLayers`]: 1 = its thin wall, eq. 2.6-2.17; more = eq. 2.19-2.20)
    /// inside `sleeve`.
    pub fn dissertation_layers(
        sleeve: S,
        tube: BladderTube,
        layers: usize,
    ) -> Result<Self, String> {
        Self::with_wall(sleeve, tube, Wall::DissertationLayers(layers))
    }

    /// Builds a bladder whose wall is integrated as `wall` says inside `sleeve`.
    pub fn with_wall(sleeve: S, tube: BladderTube, wall: Wall) -> Result<Self, String> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{name} must be positive and finite, got {v}"))
            }
        };
        positive("bladder inner_diameter (m)", tube.inner_diameter)?;
        positive("bladder thickness (m)", tube.thickness)?;
        positive("bladder unstretched_length (m)", tube.unstretched_length)?;
        if tube.thickness > tube.unstretched_length {
            return Err(format!(
                "bladder_thickness {} m exceeds bladder_length {} m: the bladder models take the \
                 tube as long against its wall (every layer stretched alike along the muscle, \
                 eq. 2.8a, its ends' own deformation neglected), and a wall thicker than the \
                 tube is long is a ring, not a tube",
                tube.thickness, tube.unstretched_length
            ));
        }
        for (name, c) in [("mooney_c1", tube.mooney_c1), ("mooney_c2", tube.mooney_c2)] {
            if !(c.is_finite() && c >= 0.0) {
                return Err(format!("{name} must be finite and >= 0 Pa, got {c}"));
            }
        }
        let count = wall.count();
        if !(1..=MAX_LAYERS).contains(&count) {
            return Err(format!(
                "bladder layers (or quadrature nodes) must be 1..={MAX_LAYERS}, got {count}"
            ));
        }
        let d_ri = tube.inner_diameter;
        let d_ro = d_ri + 2.0 * tube.thickness;
        let (layers, nodes) = match wall {
            Wall::Layers(n) | Wall::DissertationLayers(n) => (n, Vec::new()),
            Wall::Exact(n) | Wall::DissertationContinuum(n) => (0, continuum::wall_nodes(n)),
        };
        let step = (d_ro - d_ri) / layers.max(1) as f64;
        let layer_list: Vec<Layer> = (0..layers)
            .map(|i| {
                let d0 = d_ri + i as f64 * step;
                let d1 = d0 + step;
                Layer {
                    inv_d0_sq: 1.0 / (d0 * d0),
                    excess_sq: d_ro * d_ro - d0 * d0,
                    wall_ratio: step / d0,
                    rubber_volume: PI / 4.0 * (d1 * d1 - d0 * d0) * tube.unstretched_length,
                }
            })
            .collect();
        // Eq. 2.6.
        let rubber_volume = PI / 4.0 * (d_ro * d_ro - d_ri * d_ri) * tube.unstretched_length;
        let (min_length, max_length) = sleeve.fill_lengths(rubber_volume).ok_or_else(|| {
            format!(
                "the bladder's rubber volume {rubber_volume:e} m^3 does not fit in the sleeve \
                 (largest sleeve volume {:e} m^3): inner diameter of eq. 2.7 is never positive",
                sleeve.largest_volume()
            )
        })?;
        if !(rubber_volume.is_finite() && min_length.is_finite() && max_length.is_finite()) {
            return Err("bladder geometry gives non-finite rubber volume or lengths".into());
        }
        Ok(Self {
            sleeve,
            tube,
            wall,
            layers: layer_list,
            nodes,
            outer_diameter: d_ro,
            rubber_volume,
            min_length,
            max_length,
        })
    }

    pub fn sleeve(&self) -> &S {
        &self.sleeve
    }

    pub fn tube(&self) -> &BladderTube {
        &self.tube
    }

    /// Layers of a layered wall, or quadrature nodes of a quadrature.
    pub fn layer_count(&self) -> usize {
        self.layers.len() + self.nodes.len()
    }

    pub fn wall(&self) -> Wall {
        self.wall
    }

    /// Rubber volume `V_R`, m^3 (eq. 2.6); constant because rubber is incompressible.
    pub fn rubber_volume(&self) -> f64 {
        self.rubber_volume
    }

    /// Longest muscle length, m: the rubber fills the sleeve and eq. 2.7's inner diameter reaches
    /// zero, i.e. the largest root of `L (b^2 - L^2) = 4 pi n^2 V_R` for the helical sleeve. The
    /// force rises without bound towards it; at and beyond it [`Bladder::evaluate`] returns `Err`.
    /// (A knitted sleeve whose strand thickness stops it first ends at its own full extension.)
    pub fn max_length(&self) -> f64 {
        self.max_length
    }

    /// Shortest muscle length, m: the other positive root of the same cubic, where the short
    /// sleeve's volume has shrunk to the rubber volume. At and below it `evaluate` returns `Err`.
    pub fn min_length(&self) -> f64 {
        self.min_length
    }

    /// Inner diameter of the bladder in contact with the sleeve at `length` (eq. 2.7), m, or `None`
    /// outside `(min_length, max_length)`.
    pub fn contact_inner_diameter(&self, length: f64) -> Option<f64> {
        let d_in_sq = self.sleeve.diameter_sq(length) - 4.0 * self.rubber_volume / (PI * length);
        (length > 0.0 && d_in_sq > 0.0 && d_in_sq.is_finite()).then(|| d_in_sq.sqrt())
    }

    /// Threshold pressure at `length`, Pa: the gauge pressure at which the bladder, stretched
    /// axially to `length` and inflated to exactly the sleeve's inner diameter, is in equilibrium
    /// with zero contact pressure, i.e. `P_eff = 0` in eq. 2.12 / 2.19 (eq. 2.18 solved for `P` at
    /// the contact diameter). `P_eff` is proportional to `P - threshold` with a positive factor, so
    /// the bladder is in contact exactly when `P >= threshold` (the switch used by `evaluate`).
    /// It is negative near `max_length`, where the sleeve squeezes the bladder even under vacuum.
    pub fn threshold_pressure(&self, length: f64) -> Result<f64, String> {
        self.check_length(length)?;
        let (l, x) = self.contact_seed(length);
        let k = self
            .kernel(0.0, l, x)
            .ok_or_else(|| self.domain_error(length))?;
        finite_or(k.threshold, "threshold pressure", length)
    }

    /// `P_eff` (eq. 2.12 / 2.19) of the bladder held at the sleeve's diameter at `length`, Pa:
    /// [`Bladder::evaluate`] is in contact exactly where it is not negative. A positive multiple
    /// of `pressure - threshold` (see [`Bladder::threshold_pressure`]), smooth in the length.
    pub fn contact_pressure(&self, pressure: f64, length: f64) -> Result<f64, String> {
        Ok(self.contact_point(pressure, length)?.1.p_eff.v)
    }

    /// The bladder's state at gauge pressure `pressure` (Pa) and muscle length `length` (m).
    ///
    /// In contact (`P >= threshold`) the outer diameter is the sleeve's (eq. 2.7, 2.20); otherwise
    /// the bladder is free and its diameter solves eq. 2.18 (generalised to the layers) by a
    /// bracketed safeguarded Newton-bisection. At `P = threshold` both branches give the same
    /// diameter with `P_eff = 0`, so the force is continuous in pressure (its slope kinks), because
    /// the free equilibrium pressure rises monotonically with diameter (see
    /// [`Bladder::free_contact_is_stable`]): the free root is unique and meets the sleeve there.
    ///
    /// `Err` for a non-finite input, for a length outside `(min_length, max_length)` (no solution:
    /// the rubber does not fit), for a vacuum so deep that the free bladder would collapse, or if
    /// the numbers overflow right at the limits.
    pub fn evaluate(&self, pressure: f64, length: f64) -> Result<BladderState, String> {
        let (x, contact) = self.contact_point(pressure, length)?;
        if contact.p_eff.v >= 0.0 {
            let state = self.contact_state(pressure, length, &contact);
            return check_state(state, length);
        }
        // Free bladder: solve P_eff(x) = 0 for the outer diameter x below the sleeve's.
        let free = self.free_kernel(pressure, length, x.v, &contact)?;
        let state = self.free_state(pressure, length, &free, contact.threshold);
        check_state(state, length)
    }

    /// The wall's kernel at the free bladder's outer diameter (eq. 2.18), seeded in `L` and `x`;
    /// where the bore is pulled in below [`PULLED_IN_BORE`], with the axial force taken from the
    /// outside in.
    fn free_kernel(
        &self,
        pressure: f64,
        length: f64,
        x_contact: f64,
        contact: &Kernel,
    ) -> Result<Kernel, String> {
        let (x_root, at_root) = self.free_outer_diameter(pressure, length, x_contact, contact)?;
        let (l, x) = (Dual::var_l(length), Dual::var_x(x_root));
        let mut k = match at_root {
            Some(k) => k,
            None => self
                .kernel(pressure, l, x)
                .ok_or_else(|| self.domain_error(length))?,
        };
        if k.inner.l2_sq.v >= PULLED_IN_BORE {
            return Ok(k);
        }
        if let Some((elastic, innermost_volume)) = self.free_layers_elastic(pressure, l, x, &k) {
            k.elastic = elastic;
            // Only the innermost layer's `-P V_1 / L` moves with `P` at fixed `(L, x)`.
            k.elastic_dp = [Dual::constant(innermost_volume), l.recip()];
        } else {
            let at_root = match self.wall {
                Wall::DissertationContinuum(_) => self.continuum_free_elastic(l, x),
                Wall::Exact(_) => self.exact_free_elastic(l, x),
                Wall::Layers(_) | Wall::DissertationLayers(_) => None,
            };
            if let Some(elastic) = at_root {
                k.elastic = elastic;
                // The pressure enters through the root only.
                k.elastic_dp = [Dual::constant(0.0); 2];
            }
        }
        Ok(k)
    }

    fn check_length(&self, length: f64) -> Result<(), String> {
        if !length.is_finite() {
            return Err(format!("length must be finite, got {length} m"));
        }
        if length <= self.min_length || length >= self.max_length {
            return Err(self.domain_error(length));
        }
        Ok(())
    }

    fn domain_error(&self, length: f64) -> String {
        format!(
            "length {length} m is outside ({}, {}) m, where the bladder fits the sleeve \
             (eq. 2.7's inner diameter is positive only there): no solution",
            self.min_length, self.max_length
        )
    }

    /// The checked inputs' contact point: the sleeve's diameter `D(L)` as seeded by
    /// [`Self::contact_seed`] and the wall's kernel there (what every evaluation starts from).
    #[inline]
    fn contact_point(&self, pressure: f64, length: f64) -> Result<(Dual, Kernel<Dual>), String> {
        if !pressure.is_finite() {
            return Err(format!("pressure must be finite, got {pressure} Pa"));
        }
        self.check_length(length)?;
        let (l, x) = self.contact_seed(length);
        let contact = self
            .kernel(pressure, l, x)
            .ok_or_else(|| self.domain_error(length))?;
        Ok((x, contact))
    }

    /// Length seeded with d/dL = 1, and the sleeve diameter `D(L)` seeded with its total slope
    /// along the contact branch in `dl` and 1 in `dx`.
    fn contact_seed(&self, length: f64) -> (Dual, Dual) {
        let (d, slope) = self.sleeve.diameter_and_slope(length);
        (
            Dual::var_l(length),
            Dual {
                v: d,
                dl: slope,
                dx: 1.0,
            },
        )
    }

    /// The wall at muscle length `l` and bladder outer diameter `x`.
    #[inline]
    fn kernel<T: KernelScalar>(&self, pressure: f64, l: T, x: T) -> Option<Kernel<T>> {
        #[cfg(test)]
        KERNELS.with(|n| n.set(n.get() + 1));
        match self.wall {
            Wall::Exact(_) => self.exact_kernel(pressure, l, x),
            Wall::Layers(_) => self.layered_kernel(pressure, l, x, false),
            Wall::DissertationLayers(_) => self.layered_kernel(pressure, l, x, true),
            Wall::DissertationContinuum(_) => self.continuum_kernel(pressure, l, x),
        }
    }
}

/// Wall evaluations on this thread so far (tests only).
#[cfg(test)]
pub(crate) fn kernel_count() -> usize {
    KERNELS.with(|n| n.get())
}

#[cfg(test)]
thread_local! {
    /// Wall evaluations on this thread, for the tests that bound a solve's count.
    static KERNELS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

fn finite_or(v: f64, what: &str, length: f64) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!(
            "{what} overflows at length {length} m (too close to a length limit)"
        ))
    }
}

/// The innermost layer: squared hoop stretch, and the axial and hoop stresses without the
/// radial one (eq. 2.9a-b; the true stresses subtract the gauge pressure).
struct InnerLayer<T = Dual> {
    l2_sq: T,
    axial: T,
    hoop: T,
}

struct Kernel<T = Dual> {
    a: T,
    c: T,
    p_eff: T,
    threshold: f64,
    elastic: T,
    /// `d(elastic)/dP` at fixed `(L, x)` (elastic is affine in `P`) is minus the product of
    /// these two: kept as factors so that the first order multiplies their values only.
    elastic_dp: [T; 2],
    inner: InnerLayer<T>,
}

impl<T: KernelScalar> Kernel<T> {
    /// `d(elastic)/dP` at fixed `(L, x)`.
    fn elastic_dp(&self) -> T {
        self.elastic_dp[0] * self.elastic_dp[1] * -1.0
    }

    /// Its value alone.
    fn elastic_dp_value(&self) -> f64 {
        -(self.elastic_dp[0].value() * self.elastic_dp[1].value())
    }
}
