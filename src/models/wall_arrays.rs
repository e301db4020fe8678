//! The FMI 3.0 array outputs of the models with a bladder: the wall's radius and true stresses at
//! material circles from the inner surface to the outer one ([`Bladder::wall_field`],
//! [`FreeBladder::wall_field`]), one array per quantity, sized by the model description
//! (`<Array name=... size=...>`).
//!
//! [`Bladder::wall_field`]: crate::physics::bladder::Bladder::wall_field
//! [`FreeBladder::wall_field`]: crate::physics::free_bladder::FreeBladder::wall_field

use crate::physics::bladder::WallPoint;

/// Writes the array `name` of the wall that `field` computes (as many points as `out` holds)
/// into `out`.
pub(crate) fn write(
    name: &str,
    out: &mut [f64],
    field: impl FnOnce(&mut [WallPoint]) -> Result<(), String>,
) -> Result<(), String> {
    let quantity = quantity(name)?;
    let mut points = vec![WallPoint::default(); out.len()];
    field(&mut points)?;
    for (o, point) in out.iter_mut().zip(&points) {
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
