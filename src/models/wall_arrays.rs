//! The FMI 3.0 array outputs of the models with a bladder: the wall's radius and true stresses at
//! material circles from the inner surface to the outer one ([`Bladder::wall_field`],
//! [`FreeBladder::wall_field`]), one array per quantity, sized by the model description
//! (`<Array name=... size=...>`). Each model maps its generated `ArrayOutput` onto a
//! [`WallQuantity`].
//!
//! [`Bladder::wall_field`]: crate::physics::bladder::Bladder::wall_field
//! [`FreeBladder::wall_field`]: crate::physics::free_bladder::FreeBladder::wall_field

use crate::physics::bladder::WallPoint;

/// What an array of the wall holds at each of its material circles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum WallQuantity {
    /// The deformed radius (m).
    Radius,
    /// The radial true stress sigma_33 (Pa).
    StressRadial,
    /// The hoop true stress sigma_22 (Pa).
    StressHoop,
    /// The axial true stress sigma_11 (Pa).
    StressAxial,
}

/// The [`WallQuantity`] of the calling model's generated `ArrayOutput`: every model with a bladder
/// declares the same four arrays, so one mapping serves them all (a renamed array does not
/// compile).
macro_rules! wall_quantity_of {
    ($array:expr) => {
        match $array {
            ArrayOutput::WallRadius => WallQuantity::Radius,
            ArrayOutput::WallStressRadial => WallQuantity::StressRadial,
            ArrayOutput::WallStressHoop => WallQuantity::StressHoop,
            ArrayOutput::WallStressAxial => WallQuantity::StressAxial,
        }
    };
}
pub(crate) use wall_quantity_of;

impl WallQuantity {
    fn of(self, point: &WallPoint) -> f64 {
        match self {
            Self::Radius => point.radius,
            Self::StressRadial => point.stress_radial,
            Self::StressHoop => point.stress_hoop,
            Self::StressAxial => point.stress_axial,
        }
    }
}

/// Writes `quantity` of the wall that `field` computes (as many points as `out` holds) into `out`.
pub(crate) fn write(
    quantity: WallQuantity,
    out: &mut [f64],
    field: impl FnOnce(&mut [WallPoint]) -> Result<(), String>,
) -> Result<(), String> {
    let mut points = vec![WallPoint::default(); out.len()];
    field(&mut points)?;
    for (o, point) in out.iter_mut().zip(&points) {
        *o = quantity.of(point);
    }
    Ok(())
}

/// Without a bladder there is no wall: every element is 0, as the scalar stress outputs are.
pub(crate) fn absent(out: &mut [f64]) -> Result<(), String> {
    out.fill(0.0);
    Ok(())
}
