//! Festo DMSP fluidic muscles as McKibbenMuscle parameter sets: every size from its catalogue
//! numbers by a scaling law derived from the DMSP-10 and DMSP-40 fits.
//!
//! The fits (`make calibrate-festo`, exact wall, `bladder_model` 3) are [`FIT_DMSP_10`] and
//! [`FIT_DMSP_40`], each made at 0 and 600 kPa of its datasheet (`data/festo/`). The law
//! ([`ScalingLaw`]) turns a size's inner diameter `D`, nominal length `L_N` and largest
//! contraction `eps` into parameters through six coefficients, each a power of `D` through the two
//! fits (a constant if derived from one):
//!
//! - the contraction factor `k_eps = eps / eps_0(theta)`, with `eps_0 = 1 - 1 / (sqrt 3 cos
//!   theta)` the bare sleeve's free contraction (eq. 2.3 vanishes at `3 L^2 = b^2`, `L_N = b cos
//!   theta`), gives the braid angle at the nominal length;
//! - the bore per diameter `D_RI / D` and the wall thickness `t` (m); the braid lies on the wall,
//!   so the sleeve's diameter at `L_N` is `D_RI + 2 t` (`n = b sin theta / (pi (D_RI + 2 t))`);
//! - the bladder's length per nominal length `L_R0 / L_N` and the rubber's `C1`, `C2`.
//!
//! The catalogue's largest force at 6 bar sizes the strands' rigidity (McKibbenMuscle's
//! `strand_rigidity`), not the geometry: the figures are quoted at different points of the
//! curves (DMSP-10's 630 N at 2% stretch, DMSP-40's 6000 N at 0.6% contraction), and a bore sized
//! by them carries that 33% difference into every size without curves (docs/calibration.md).
//!
//! A size's preset is the law at its catalogue numbers ([`preset`]); for DMSP-10 and DMSP-40 the
//! law gives back their fits. The force at a given contraction does not depend on the nominal
//! length ([`MuscleParams::scaled_to`]).

use crate::physics::muscle_params::MuscleParams;

/// A DMSP size's catalogue numbers (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Catalogue {
    pub name: &'static str,
    /// Inner diameter `D` (the size's number), m.
    pub inner_diameter: f64,
    /// The preset's nominal length `L_N`, m (any length the size is sold in; force at a given
    /// contraction does not depend on it).
    pub nominal_length: f64,
    /// Largest (theoretical) force at 600 kPa, N.
    pub max_force: f64,
    /// Largest contraction, fraction of the nominal length.
    pub max_contraction: f64,
}

/// Festo DMSP-5 (catalogue: 140 N at 6 bar, 20% contraction).
pub const DMSP_5: Catalogue = Catalogue {
    name: "DMSP-5",
    inner_diameter: 0.005,
    nominal_length: 0.1,
    max_force: 140.0,
    max_contraction: 0.20,
};
/// Festo DMSP-10 (catalogue: 630 N at 6 bar, 25% contraction).
pub const DMSP_10: Catalogue = Catalogue {
    name: "DMSP-10",
    inner_diameter: 0.010,
    nominal_length: 0.25,
    max_force: 630.0,
    max_contraction: 0.25,
};
/// Festo DMSP-20 (catalogue: 1500 N at 6 bar, 25% contraction); no curves are shipped.
pub const DMSP_20: Catalogue = Catalogue {
    name: "DMSP-20",
    inner_diameter: 0.020,
    nominal_length: 0.3,
    max_force: 1500.0,
    max_contraction: 0.25,
};
/// Festo DMSP-40 (catalogue: 6000 N at 6 bar, 25% contraction).
pub const DMSP_40: Catalogue = Catalogue {
    name: "DMSP-40",
    inner_diameter: 0.040,
    nominal_length: 0.4,
    max_force: 6000.0,
    max_contraction: 0.25,
};

/// The fit of DMSP-10 at 0 + 600 kPa (`make calibrate-festo`).
pub const FIT_DMSP_10: MuscleParams = MuscleParams {
    nominal_length: 0.25,
    strand_length: 2.8879279125843643e-1,
    turns: 3.2220939233461077,
    bladder_model: 3,
    bladder_layers: 16,
    bladder_length: 0.25,
    bladder_inner_diameter: 1.0548530499080857e-2,
    bladder_thickness: 1.866887763628523e-3,
    mooney_c1: 3e4,
    mooney_c2: 6e5,
};

/// The fit of DMSP-40 at 0 + 600 kPa (`make calibrate-festo`).
pub const FIT_DMSP_40: MuscleParams = MuscleParams {
    nominal_length: 0.4,
    strand_length: 4.495360460399648e-1,
    turns: 1.4719701800955933,
    bladder_model: 3,
    bladder_layers: 16,
    bladder_length: 0.4,
    bladder_inner_diameter: 4.1049844628720036e-2,
    bladder_thickness: 1.6556472640102812e-3,
    mooney_c1: 3e4,
    mooney_c2: 6e5,
};

/// The preset values of McKibbenMuscle's and McKibbenJoint's `preset` for the DMSP sizes, with
/// their catalogue numbers.
pub const PRESETS: [(i32, Catalogue); 4] = [(7, DMSP_5), (5, DMSP_10), (8, DMSP_20), (6, DMSP_40)];

/// The law's coefficients, in order.
pub const COEFFICIENTS: [&str; 6] = [
    "contraction factor k_eps",
    "bore per diameter D_RI / D",
    "wall thickness t (m)",
    "bladder length per nominal length L_R0 / L_N",
    "mooney_c1 (Pa)",
    "mooney_c2 (Pa)",
];

/// `value (D / D_ref)^exponent`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Power {
    pub value: f64,
    pub exponent: f64,
}

/// The scaling law: each coefficient a power of the inner diameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScalingLaw {
    /// `D_ref`, m.
    pub reference_diameter: f64,
    pub coefficients: [Power; 6],
}

/// The bare sleeve's free contraction at braid angle `theta` (rad) at the nominal length.
fn free_contraction(theta: f64) -> f64 {
    1.0 - 1.0 / (3f64.sqrt() * theta.cos())
}

/// The law's six coefficients of muscle `p` with catalogue numbers `c`.
pub fn coefficients(c: &Catalogue, p: &MuscleParams) -> [f64; 6] {
    [
        c.max_contraction / free_contraction(p.braid_angle()),
        p.bladder_inner_diameter / c.inner_diameter,
        p.bladder_thickness,
        p.bladder_length / p.nominal_length,
        p.mooney_c1,
        p.mooney_c2,
    ]
}

impl ScalingLaw {
    /// The law through the fits `(catalogue, fitted parameters)`: with one fit every coefficient
    /// is constant, with two each is the power of `D` through both (more are not supported).
    pub fn derive(fits: &[(Catalogue, MuscleParams)]) -> Result<Self, String> {
        match fits {
            [(c, p)] => Ok(Self {
                reference_diameter: c.inner_diameter,
                coefficients: coefficients(c, p).map(|value| Power {
                    value,
                    exponent: 0.0,
                }),
            }),
            [(a, pa), (b, pb)] if a.inner_diameter != b.inner_diameter => {
                let (ka, kb) = (coefficients(a, pa), coefficients(b, pb));
                let span = (b.inner_diameter / a.inner_diameter).ln();
                Ok(Self {
                    reference_diameter: a.inner_diameter,
                    coefficients: std::array::from_fn(|i| Power {
                        value: ka[i],
                        exponent: (kb[i] / ka[i]).ln() / span,
                    }),
                })
            }
            _ => Err("the scaling law needs one fit or two of different diameters".into()),
        }
    }

    /// The law derived from the DMSP-10 and DMSP-40 fits.
    pub fn festo() -> Self {
        Self::derive(&[(DMSP_10, FIT_DMSP_10), (DMSP_40, FIT_DMSP_40)])
            .unwrap_or_else(|_| unreachable!("the two fits have different diameters"))
    }

    /// The coefficients at inner diameter `d`, m.
    pub fn at(&self, d: f64) -> [f64; 6] {
        self.coefficients
            .map(|k| k.value * (d / self.reference_diameter).powf(k.exponent))
    }

    /// The muscle of catalogue numbers `c` (exact wall, 16 nodes). `Err` if the numbers
    /// describe no muscle (no braid angle gives the contraction).
    pub fn params(&self, c: &Catalogue) -> Result<MuscleParams, String> {
        let [k_eps, bore, thickness, length, c1, c2] = self.at(c.inner_diameter);
        // eps_0 = eps / k_eps, cos theta = 1 / (sqrt 3 (1 - eps_0)).
        let cos = 1.0 / (3f64.sqrt() * (1.0 - c.max_contraction / k_eps));
        if !(cos > 1.0 / 3f64.sqrt() && cos < 1.0) {
            return Err(format!(
                "{}: no braid angle contracts by {}",
                c.name, c.max_contraction
            ));
        }
        let (b, bore) = (c.nominal_length / cos, bore * c.inner_diameter);
        Ok(MuscleParams {
            nominal_length: c.nominal_length,
            strand_length: b,
            turns: b * cos.acos().sin() / (std::f64::consts::PI * (bore + 2.0 * thickness)),
            bladder_model: 3,
            bladder_layers: 16,
            bladder_length: length * c.nominal_length,
            bladder_inner_diameter: bore,
            bladder_thickness: thickness,
            mooney_c1: c1,
            mooney_c2: c2,
        })
    }
}

/// The DMSP preset `preset` of McKibbenMuscle and McKibbenJoint (5 DMSP-10, 6 DMSP-40, 7 DMSP-5,
/// 8 DMSP-20) with its catalogue numbers, `None` for any other value.
pub fn preset(preset: i32) -> Option<(MuscleParams, Catalogue)> {
    let (_, c) = PRESETS.iter().find(|(k, _)| *k == preset)?;
    ScalingLaw::festo().params(c).ok().map(|p| (p, *c))
}

/// The catalogue's largest force of the DMSP preset `preset`, N (it sizes the aramid strands),
/// `None` for any other value.
pub fn largest_force(preset: i32) -> Option<f64> {
    PRESETS
        .iter()
        .find(|(k, _)| *k == preset)
        .map(|(_, c)| c.max_force)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
    }

    #[test]
    fn the_law_gives_back_the_two_fits_it_was_derived_from() {
        for (k, fit) in [(5, FIT_DMSP_10), (6, FIT_DMSP_40)] {
            let (p, _) = preset(k).unwrap();
            for ((name, a), (_, b)) in p.named_reals().iter().zip(fit.named_reals()) {
                assert!(close(*a, b), "preset {k} {name}: {a} vs {b}");
            }
            assert_eq!((p.bladder_model, p.bladder_layers), (3, 16));
        }
    }

    #[test]
    fn every_size_is_a_muscle_with_a_bore_of_its_size_and_an_unstretched_bladder() {
        // Measured: bore / D 1.069 (DMSP-5), 1.055, 1.040, 1.026 (DMSP-40); walls 1.66-1.98 mm;
        // braid angles 38.8 deg (DMSP-5, 20% contraction), 30.0, 28.7, 27.2 deg.
        for (k, c) in PRESETS {
            let (p, _) = preset(k).unwrap();
            p.muscle().unwrap();
            let bore = p.bladder_inner_diameter / c.inner_diameter;
            assert!((1.0..1.1).contains(&bore), "{}: bore {bore} D", c.name);
            assert!((1.5e-3..2e-3).contains(&p.bladder_thickness), "{}", c.name);
            assert!(p.bladder_length <= p.nominal_length, "{}", c.name);
            let theta = p.braid_angle().to_degrees();
            assert!((25.0..40.0).contains(&theta), "{}: {theta} deg", c.name);
        }
        assert!(preset(0).is_none() && preset(4).is_none() && preset(9).is_none());
    }

    #[test]
    fn a_law_from_one_fit_is_that_fit_at_its_own_size() {
        let law = ScalingLaw::derive(&[(DMSP_40, FIT_DMSP_40)]).unwrap();
        let p = law.params(&DMSP_40).unwrap();
        assert!(close(p.strand_length, FIT_DMSP_40.strand_length));
        assert!(close(
            p.bladder_inner_diameter,
            FIT_DMSP_40.bladder_inner_diameter
        ));
        assert!(ScalingLaw::derive(&[]).is_err());
        assert!(ScalingLaw::derive(&[(DMSP_40, FIT_DMSP_40), (DMSP_40, FIT_DMSP_40)]).is_err());
    }
}
