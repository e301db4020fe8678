//! Festo DMSP fluidic muscles as McKibbenMuscle parameter sets, fitted by `make calibrate` to the
//! datasheet curves in `data/festo/` at 0 and 600 kPa (thin-walled bladder, eq. 2.6-2.18):
//!
//! ```text
//! make calibrate DATA=data/festo/festo_dmsp40.csv LENGTH=0.4 DIAMETER=0.04 FIT=0,600
//! make calibrate DATA=data/festo/festo_dmsp10.csv LENGTH=0.25 DIAMETER=0.01 FIT=0,600
//! ```
//! The parameters are effective, not the real tube's: the fit drives the wall thin (0.17 mm) and
//! the rubber to the stiff end of its bound (3 MPa), because only the wall's stiffness (thickness
//! times the Mooney constants) is identifiable from force curves. The force at a given contraction
//! does not depend on the nominal length ([`MuscleParams::scaled_to`]).

use crate::physics::muscle_params::MuscleParams;

/// Festo DMSP-40 at a nominal length of 400 mm.
pub const DMSP_40: MuscleParams = MuscleParams {
    nominal_length: 0.4,
    strand_length: 4.441589758962788e-1,
    turns: 1.493180401652737,
    bladder_model: 4,
    bladder_layers: 1,
    bladder_length: 4.3751546104278366e-1,
    bladder_inner_diameter: 3.987873212108272e-2,
    bladder_thickness: 1.6896226260474466e-4,
    mooney_c1: 1.8369110387253426e6,
    mooney_c2: 2.9999999999999967e6,
};

/// Festo DMSP-10 at a nominal length of 250 mm.
pub const DMSP_10: MuscleParams = MuscleParams {
    nominal_length: 0.25,
    strand_length: 2.7639908208602637e-1,
    turns: 3.4118279464330463,
    bladder_model: 4,
    bladder_layers: 1,
    bladder_length: 3.053427707883874e-1,
    bladder_inner_diameter: 1.0041469647383306e-2,
    bladder_thickness: 1.630512502967944e-4,
    mooney_c1: 1.1077181808807817e6,
    mooney_c2: 2.9999999999999967e6,
};
