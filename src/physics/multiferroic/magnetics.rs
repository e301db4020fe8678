//! Ring-bar magnetostatics from point charges (eq. 3.2-3.3) and the domain-wall magnetoelastic
//! energy (eq. 3.1, 3.4), plus the rotor's mass properties and fluid drag.
//!
//! Angles: `offset` (beta) is the onion state's angle minus the bar's. At beta = 0 the bar's
//! positive end faces the ring's negative domain wall (flux closure, the minimum of eq. 3.3).

use super::angles::turned_back;
use std::f64::consts::PI;

/// Vacuum permeability (T m / A), CODATA 2018.
pub const MU0: f64 = 1.256_637_062_12e-6;
/// Electron gyromagnetic ratio (rad / (s T)), CODATA 2018.
pub const GYROMAGNETIC_RATIO: f64 = 1.760_859_630_23e11;

/// The shortest length of the ring and the bar (m): a few atoms.
const MIN_LENGTH: f64 = 1e-9;

/// The four point charges of section 3.2.1, reduced to what eq. 3.3 needs.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RingBar {
    /// Distance from the centre to each bar charge: half the bar length (m).
    pub bar_charge_radius: f64,
    /// Distance from the centre to each domain wall: the ring's centre line (m).
    pub wall_radius: f64,
    /// `2 mu0/(4 pi) q_ring q_bar` (J m), the prefactor of eq. 3.3.
    pub coupling: f64,
}

impl RingBar {
    /// Charges `q_bar = t w_bar Ms` at the bar ends and `q_ring = 2 t w_ring Ms` at the walls on the
    /// ring's centre line (section 3.2.1). Lengths in m, `Ms` in A/m.
    pub fn new(
        ring_outer_diameter: f64,
        ring_inner_diameter: f64,
        bar_length: f64,
        bar_width: f64,
        thickness: f64,
        saturation_magnetization: f64,
    ) -> Result<Self, String> {
        // The declared ranges: 1 nm to 1 m for the lengths (below a few atoms there is no
        // continuum magnetization for eq. 3.2 to describe), up to 1e7 A/m (above any known
        // material's 2.4e6) for the magnetization.
        for (name, v) in [
            ("ring_outer_diameter", ring_outer_diameter),
            ("ring_inner_diameter", ring_inner_diameter),
            ("bar_length", bar_length),
            ("bar_width", bar_width),
            ("thickness", thickness),
        ] {
            if !(MIN_LENGTH..=1.0).contains(&v) {
                return Err(format!(
                    "{name} must be within [{MIN_LENGTH:e}, 1] m, got {v} m"
                ));
            }
        }
        let ms = saturation_magnetization;
        if !(ms > 0.0 && ms <= 1e7) {
            return Err(format!(
                "saturation_magnetization must be positive and at most 1e7 A/m, got {ms} A/m"
            ));
        }
        if ring_inner_diameter >= ring_outer_diameter {
            return Err(format!(
                "ring_inner_diameter ({ring_inner_diameter} m) must be smaller than \
                 ring_outer_diameter ({ring_outer_diameter} m)"
            ));
        }
        // The bar turns inside the ring: its corners must clear the inner edge.
        let corner = 0.5 * bar_length.hypot(bar_width);
        if corner >= 0.5 * ring_inner_diameter {
            return Err(format!(
                "the bar (bar_length {bar_length} m x bar_width {bar_width} m) does not fit \
                 inside the ring's hole (ring_inner_diameter {ring_inner_diameter} m): its \
                 corners reach {corner} m from the centre"
            ));
        }
        let ring_width = 0.5 * (ring_outer_diameter - ring_inner_diameter);
        // Eq. 3.2's charges are a thin film's (section 3.2.1): shape anisotropy holds the
        // magnetization in the plane, along the ring's edges (the onion state) and along the
        // bar's axis, so that the bar's charges sit at its ends. That needs a bar longer than
        // it is wide, and a film thinner than the bar and the ring are wide.
        if bar_width >= bar_length {
            return Err(format!(
                "bar_width ({bar_width} m) must be less than bar_length ({bar_length} m): the \
                 model's bar is magnetized along its length, which shape anisotropy holds only \
                 in a bar longer than it is wide"
            ));
        }
        if thickness > bar_width.min(ring_width) {
            return Err(format!(
                "thickness ({thickness} m) must not exceed bar_width ({bar_width} m) or the \
                 ring's width ({ring_width} m, half of ring_outer_diameter less \
                 ring_inner_diameter): the model is a thin film's, magnetized in its plane"
            ));
        }
        let q_ring = 2.0 * thickness * ring_width * saturation_magnetization;
        let q_bar = thickness * bar_width * saturation_magnetization;
        Ok(Self {
            bar_charge_radius: 0.5 * bar_length,
            wall_radius: 0.25 * (ring_outer_diameter + ring_inner_diameter),
            coupling: 2.0 * MU0 / (4.0 * PI) * q_ring * q_bar,
        })
    }

    /// Distances `A` (opposite charges, bar + to wall -) and `B` (like charges) at offset beta.
    #[inline]
    fn distances(&self, offset: f64) -> (f64, f64, f64) {
        self.distances_of_cos(turned_back(offset).cos())
    }

    /// [`Self::distances`] from the offset's cosine, for the callers that take its sine too:
    /// one `sin_cos` instead of a `cos` and a `sin_cos` of the same angle.
    #[inline]
    fn distances_of_cos(&self, cos_offset: f64) -> (f64, f64, f64) {
        let (a, r) = (self.bar_charge_radius, self.wall_radius);
        let sum = a * a + r * r;
        let cross = 2.0 * a * r * cos_offset;
        // a < r (checked), so both are positive.
        ((sum - cross).sqrt(), (sum + cross).sqrt(), a * r)
    }

    /// Eq. 3.3: the variable part of the magnetostatic energy (J), `K (1/B - 1/A)`.
    pub fn energy(&self, offset: f64) -> f64 {
        let (a, b, _) = self.distances(offset);
        self.coupling * (1.0 / b - 1.0 / a)
    }

    /// [`Self::energy`] from the cosine of the offset.
    pub fn energy_of_cos(&self, cos_offset: f64) -> f64 {
        let (a, r) = (self.bar_charge_radius, self.wall_radius);
        let sum = a * a + r * r;
        let cross = 2.0 * a * r * cos_offset;
        self.coupling * (1.0 / (sum + cross).sqrt() - 1.0 / (sum - cross).sqrt())
    }

    /// Section 3.2.2: torque on the bar (N m), `tau_bar = dU_m/d beta = K a r sin(beta)(1/A^3 + 1/B^3)`.
    /// Positive when the onion state leads the bar: it pulls the bar forward.
    pub fn torque(&self, offset: f64) -> f64 {
        let (s, c) = turned_back(offset).sin_cos();
        let (a, b, ar) = self.distances_of_cos(c);
        self.coupling * ar * s * (1.0 / (a * a * a) + 1.0 / (b * b * b))
    }

    /// [`Self::torque`] and [`Self::stiffness`] together from one `sin_cos` of the offset and one
    /// pair of distances: the quasi-static onion's Newton iteration and the rotor's Jacobian need
    /// both at every evaluation (trigonometry was 40% of a motor step with them apart).
    #[inline]
    pub fn torque_stiffness(&self, offset: f64) -> (f64, f64) {
        let (s, c) = turned_back(offset).sin_cos();
        self.torque_stiffness_of(s, c)
    }

    /// [`Self::torque_stiffness`] from the sine and cosine of the offset.
    #[inline]
    pub fn torque_stiffness_of(&self, s: f64, c: f64) -> (f64, f64) {
        let (ar, ia, ib) = self.inverse_distances(c);
        let (ia3, ib3) = (ia * ia * ia, ib * ib * ib);
        let k_ar = self.coupling * ar;
        let torque = k_ar * s * (ia3 + ib3);
        let stiffness =
            k_ar * (c * (ia3 + ib3) + 3.0 * ar * s * s * (ib3 * ib * ib - ia3 * ia * ia));
        (torque, stiffness)
    }

    /// The torque ([`Self::torque_stiffness_of`]) and the energy ([`Self::energy_of_cos`]) from
    /// one pair of distances, for a step's outputs.
    #[inline]
    pub fn torque_energy_of(&self, s: f64, c: f64) -> (f64, f64) {
        let (ar, ia, ib) = self.inverse_distances(c);
        let torque = self.coupling * ar * s * (ia * ia * ia + ib * ib * ib);
        (torque, self.coupling * (ib - ia))
    }

    /// `(a r, 1/A, 1/B)` at the offset's cosine `c`. `a < r` (checked), so both distances are
    /// positive; one division gives both reciprocals (`1/A = B/(AB)`): this runs at every
    /// evaluation of the onion's Newton iteration.
    #[inline(always)]
    fn inverse_distances(&self, c: f64) -> (f64, f64, f64) {
        let (a, r) = (self.bar_charge_radius, self.wall_radius);
        let ar = a * r;
        let sum = a * a + r * r;
        let cross = 2.0 * ar * c;
        let (dist_a, dist_b) = ((sum - cross).sqrt(), (sum + cross).sqrt());
        let inv = 1.0 / (dist_a * dist_b);
        (ar, dist_b * inv, dist_a * inv)
    }

    /// `d^2 U_m / d beta^2` (N m / rad): the ring-bar spring stiffness.
    pub fn stiffness(&self, offset: f64) -> f64 {
        let (s, c) = turned_back(offset).sin_cos();
        let (a, b, ar) = self.distances_of_cos(c);
        let (a2, b2) = (a * a, b * b);
        self.coupling
            * ar
            * (c * (1.0 / (a2 * a) + 1.0 / (b2 * b))
                + 3.0 * ar * s * s * (1.0 / (b2 * b2 * b) - 1.0 / (a2 * a2 * a)))
    }

    /// An upper bound of `|`[`Self::stiffness`]`|` at every offset (N m / rad): both distances
    /// are at least `r - a`, so `K a r (2 / (r - a)^3 + 3 a r / (r - a)^5)` (eq. 3.3).
    pub fn stiffness_bound(&self) -> f64 {
        let (a, r) = (self.bar_charge_radius, self.wall_radius);
        let ar = a * r;
        let d = r - a;
        let d3 = d * d * d;
        (self.coupling * ar).abs() * (2.0 / d3 + 3.0 * ar / (d3 * d * d))
    }

    /// `d^3 U_m / d beta^3` (N m / rad^2): the slope of [`Self::stiffness`], for the quasi-static
    /// onion's fold (where its minimum vanishes, the inflection's motion depends on it).
    pub fn stiffness_slope(&self, offset: f64) -> f64 {
        let (s, c) = turned_back(offset).sin_cos();
        let (a, b, ar) = self.distances_of_cos(c);
        let (ia, ib) = (1.0 / a, 1.0 / b);
        let (ia3, ib3) = (ia * ia * ia, ib * ib * ib);
        let (ia5, ib5) = (ia3 * ia * ia, ib3 * ib * ib);
        let (ia7, ib7) = (ia5 * ia * ia, ib5 * ib * ib);
        self.coupling
            * ar
            * (-s * (ia3 + ib3)
                + 9.0 * ar * s * c * (ib5 - ia5)
                + 15.0 * ar * ar * s * s * s * (ia7 + ib7))
    }

    /// The largest torque and the offset where it occurs (Fig. 3.3a): the root of the stiffness
    /// in (0, pi/2), found by bisection (the stiffness falls through zero once there). Eq. 3.3
    /// is odd about pi/2 (A and B swap), so the torque has the same peak again at `pi - beta`.
    pub fn max_torque(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (0.0, 0.5 * PI);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.stiffness(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-14 {
                break;
            }
        }
        let at = 0.5 * (lo + hi);
        (at, self.torque(at))
    }
}

/// Eq. 3.4's magnetoelastic term integrated over the domain walls: `U_sigma = E sin^2(theta)` with
/// `E = (3/2) lambda_s (sigma11 - sigma22) V_wall` and theta the angle between the principal
/// tension and the wall (onion) magnetization. Returns `E / sigma` (J/Pa).
pub fn magnetoelastic_coefficient(magnetostriction: f64, wall_volume: f64) -> f64 {
    1.5 * magnetostriction * wall_volume
}

/// Calibrates the domain-wall volume of eq. 3.4 so that `stress` (Pa) of tension at
/// `strain_direction` (rad, relative to the bar) leaves the onion state at `target_offset` (rad)
/// from the bar, as in Fig. 3.3b (200 MPa at -45 degrees gives 23 degrees).
///
/// Equilibrium of eq. 3.4: `tau_bar(beta) + E sin(2 (beta - gamma)) = 0`, solved for the wall
/// volume in `E`. Fails unless the result is a positive volume and the equilibrium is a stable
/// minimum (positive curvature), so a calibrated model actually settles there.
pub fn calibrate_wall_volume(
    ring_bar: &RingBar,
    magnetostriction: f64,
    stress: f64,
    strain_direction: f64,
    target_offset: f64,
) -> Result<f64, String> {
    let per_volume = 1.5 * magnetostriction * stress;
    let lever = (2.0 * (target_offset - strain_direction)).sin();
    let torque = ring_bar.torque(target_offset);
    if !(per_volume.is_finite() && per_volume != 0.0 && lever.abs() > 1e-9) {
        return Err(format!(
            "calibration needs nonzero magnetostriction and stress and a strain direction not \
             parallel or perpendicular to the target offset (lambda_s = {magnetostriction}, \
             stress = {stress} Pa, direction = {strain_direction} rad, offset = {target_offset} rad)"
        ));
    }
    let volume = -torque / (per_volume * lever);
    if !(volume.is_finite() && volume > 0.0) {
        return Err(format!(
            "no positive wall volume holds the onion state at {target_offset} rad with this \
             stress: magnetostriction pushes it the other way (volume would be {volume} m3)"
        ));
    }
    let curvature = ring_bar.stiffness(target_offset)
        + 2.0 * per_volume * volume * (2.0 * (target_offset - strain_direction)).cos();
    if curvature <= 0.0 {
        return Err(format!(
            "the calibrated equilibrium at {target_offset} rad is unstable (curvature \
             {curvature} J/rad2): the onion state would not stay there"
        ));
    }
    Ok(volume)
}

/// Mass (kg) and moment of inertia (kg m^2) of the bar as a rectangular plate turning about the
/// normal through its centre: `m = rho L w t`, `I = m (L^2 + w^2) / 12`.
pub fn bar_mass_inertia(length: f64, width: f64, thickness: f64, density: f64) -> (f64, f64) {
    let mass = density * length * width * thickness;
    (mass, mass * (length * length + width * width) / 12.0)
}

/// Rotational drag coefficient (N m s) of a rod of length `L` and diameter `d` turning about a
/// perpendicular axis through its centre in a fluid of viscosity `eta`:
/// `zeta = pi eta L^3 / (3 (ln p + delta))`, `p = L/d`, `delta = -0.662 + 0.917/p - 0.050/p^2`
/// (M. M. Tirado, C. L. Martinez, J. Garcia de la Torre, J. Chem. Phys. 81, 2047 (1984); fitted for
/// 2 <= p <= 30, extrapolated outside, with p held at 1 or more so the denominator stays positive).
pub fn rod_rotational_drag(viscosity: f64, length: f64, diameter: f64) -> f64 {
    let p = (length / diameter).max(1.0);
    let delta = -0.662 + 0.917 / p - 0.050 / (p * p);
    PI * viscosity * length.powi(3) / (3.0 * (p.ln() + delta))
}

/// Diameter of the round rod with the bar's cross-section area `w t`: `d = sqrt(4 w t / pi)`.
/// Our choice for applying the rod formula to a flat bar.
pub fn equivalent_rod_diameter(width: f64, thickness: f64) -> f64 {
    (4.0 * width * thickness / PI).sqrt()
}
