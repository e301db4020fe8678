//! The continuum wall (`bladder_model` 6) and the dissertation's layers (`bladder_model` 5)
//! against the layered wall's infinite-layer limit (eq. 2.19-2.20), as the markdown rows of the
//! McKibbenMuscle page's table: Table 2.1's muscle C at 450 kPa, 41 lengths across its whole
//! stroke (to 0.5% of the fill limits), the largest force error relative to the peak force.
//!
//! The limit is found independently of the quadrature, by Richardson extrapolation of the layered
//! wall (a left Riemann sum through the wall, its error a series in `1/n`) from 256-2048 layers,
//! which the FMU does not accept (at most 64): so this runs on the physics directly.
//!
//! Usage: `cargo run --release -p actuator-fmus-tools --bin wall_limit`.

use actuator_fmus::physics::bladder::{Bladder, BladderTube, Wall};
use actuator_fmus::physics::gaylord::Sleeve;

/// Table 2.1's muscle C: bladder length, inner diameter, wall thickness, strand length, turns.
const MUSCLE_C: (f64, f64, f64, f64, f64) = (0.0541, 1.6e-3, 1.6e-3, 0.1051, 3.40);
const PRESSURE: f64 = 450e3;

fn bladder(wall: Wall) -> Result<Bladder<Sleeve>, String> {
    let (length, inner_diameter, thickness, strand_length, turns) = MUSCLE_C;
    let tube = BladderTube::latex(inner_diameter, thickness, length);
    Bladder::with_wall(Sleeve::new(strand_length, turns)?, tube, wall)
}

fn forces(wall: Wall, lengths: &[f64]) -> Result<Vec<f64>, String> {
    let bl = bladder(wall)?;
    lengths
        .iter()
        .map(|&l| bl.evaluate(PRESSURE, l).map(|s| s.force))
        .collect()
}

/// `x` as `1.2e-03`, the form of the other tables `make report` writes.
fn scientific(x: f64) -> String {
    let text = format!("{x:.1e}");
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    let sign = if exponent < 0 { '-' } else { '+' };
    format!("{mantissa}e{sign}{:02}", exponent.abs())
}

fn main() -> Result<(), String> {
    let probe = bladder(Wall::DissertationContinuum(8))?;
    let (lo, hi) = (probe.min_length(), probe.max_length());
    let lengths: Vec<f64> = (0..41)
        .map(|i| lo + (hi - lo) * (0.005 + 0.99 * i as f64 / 40.0))
        .collect();
    let f = [256, 512, 1024, 2048]
        .iter()
        .map(|&n| forces(Wall::DissertationLayers(n), &lengths))
        .collect::<Result<Vec<_>, _>>()?;
    // Cancels the 1/n, 1/n^2 and 1/n^3 terms.
    let limit: Vec<f64> = (0..lengths.len())
        .map(|j| {
            let r1: Vec<f64> = (0..3).map(|i| 2.0 * f[i + 1][j] - f[i][j]).collect();
            let r2: Vec<f64> = (0..2).map(|i| (4.0 * r1[i + 1] - r1[i]) / 3.0).collect();
            (8.0 * r2[1] - r2[0]) / 7.0
        })
        .collect();
    let peak = limit.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let error = |wall: Wall| -> Result<f64, String> {
        Ok(forces(wall, &lengths)?
            .iter()
            .zip(&limit)
            .map(|(a, b)| (a - b).abs() / peak)
            .fold(0.0, f64::max))
    };
    println!(
        "| nodes or layers | dissertation's continuum (`bladder_model` 6) | dissertation's layers (`bladder_model` 5) |"
    );
    println!("|---|---|---|");
    for n in [2, 4, 8, 16, 32, 64] {
        println!(
            "| {n} | {} | {} |",
            scientific(error(Wall::DissertationContinuum(n))?),
            scientific(error(Wall::DissertationLayers(n))?)
        );
    }
    Ok(())
}
