//! A McKibbenMuscle parameter set in the FMU's variable names: what the Festo presets
//! (`festo.rs`) hold and what the calibration (the tools crate) fits.

use crate::physics::bladder::BladderTube;
use crate::physics::gaylord::Sleeve;
use crate::physics::mckibben::{BladderModel, McKibben};

/// A McKibbenMuscle parameter set, in the FMU's variable names and SI units.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MuscleParams {
    /// `nominal_length`, m: contraction is `1 - L / nominal_length`.
    pub nominal_length: f64,
    /// `strand_length` b, m.
    pub strand_length: f64,
    /// `turns` n.
    pub turns: f64,
    /// `bladder_model` (3, the exact wall, for the Festo presets and the calibration).
    pub bladder_model: i32,
    /// `bladder_layers` (thick wall).
    pub bladder_layers: i32,
    /// `bladder_length` L_R0, m.
    pub bladder_length: f64,
    /// `bladder_inner_diameter` D_RI, m.
    pub bladder_inner_diameter: f64,
    /// `bladder_thickness`, m.
    pub bladder_thickness: f64,
    /// `mooney_c1`, Pa.
    pub mooney_c1: f64,
    /// `mooney_c2`, Pa.
    pub mooney_c2: f64,
}

impl MuscleParams {
    /// The muscle these parameters describe (no friction, rigid connector).
    pub fn muscle(&self) -> Result<McKibben, String> {
        McKibben::new(
            Sleeve::new(self.strand_length, self.turns)?,
            BladderTube {
                inner_diameter: self.bladder_inner_diameter,
                thickness: self.bladder_thickness,
                unstretched_length: self.bladder_length,
                mooney_c1: self.mooney_c1,
                mooney_c2: self.mooney_c2,
            },
            BladderModel::from_switch(self.bladder_model, self.bladder_layers)?,
            None,
            0.0,
        )
    }

    /// The same muscle at another nominal length: every length scales, so the force at a given
    /// contraction and pressure is unchanged (eq. 2.3 and the bladder's stretches depend on
    /// length ratios only; its axial force on the unchanged cross-section).
    pub fn scaled_to(&self, nominal_length: f64) -> Self {
        let k = nominal_length / self.nominal_length;
        Self {
            nominal_length,
            strand_length: self.strand_length * k,
            bladder_length: self.bladder_length * k,
            turns: self.turns * k,
            ..*self
        }
    }

    /// Braid angle at the nominal length, rad (`cos theta = L_N / b`, eq. 2.1's geometry).
    pub fn braid_angle(&self) -> f64 {
        (self.nominal_length / self.strand_length).min(1.0).acos()
    }

    /// `(name, value)` of every parameter, in the FMU's variable names.
    pub fn named_reals(&self) -> [(&'static str, f64); 8] {
        [
            ("nominal_length", self.nominal_length),
            ("strand_length", self.strand_length),
            ("turns", self.turns),
            ("bladder_length", self.bladder_length),
            ("bladder_inner_diameter", self.bladder_inner_diameter),
            ("bladder_thickness", self.bladder_thickness),
            ("mooney_c1", self.mooney_c1),
            ("mooney_c2", self.mooney_c2),
        ]
    }
}
