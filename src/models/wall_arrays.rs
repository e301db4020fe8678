//! The FMI 3.0 array outputs of the models with a bladder: the wall's radius and true stresses at
//! material circles from the inner surface to the outer one ([`Bladder::wall_field`]), one array
//! per quantity, sized by the model description (`<Array name=... size=...>`).

use crate::physics::bladder::{Bladder, SleeveGeometry, WallPoint};

/// Writes the array `name` of the wall of `bladder` at gauge pressure `pressure` (Pa) and the
/// bladder's length `length` (m) into `out`.
pub(crate) fn write<S: SleeveGeometry>(
    bladder: &Bladder<S>,
    pressure: f64,
    length: f64,
    name: &str,
    out: &mut [f64],
) -> Result<(), String> {
    let quantity = quantity(name)?;
    let mut field = vec![WallPoint::default(); out.len()];
    bladder.wall_field(pressure, length, &mut field)?;
    for (o, point) in out.iter_mut().zip(&field) {
        *o = quantity(point);
    }
    Ok(())
}

/// Without a bladder there is no wall: every element is 0, as the scalar stress outputs are.
pub(crate) fn absent(name: &str, out: &mut [f64]) -> Result<(), String> {
    quantity(name)?;
    out.fill(0.0);
    Ok(())
}

fn quantity(name: &str) -> Result<fn(&WallPoint) -> f64, String> {
    Ok(match name {
        "wall_radius" => |p| p.radius,
        "wall_stress_radial" => |p| p.stress_radial,
        "wall_stress_hoop" => |p| p.stress_hoop,
        "wall_stress_axial" => |p| p.stress_axial,
        _ => return Err(format!("no array output named '{name}'")),
    })
}
