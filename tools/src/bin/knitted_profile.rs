//! Radius profile of the non-cylindrical knitted sleeve (dissertation eq. 1.17-1.20) at several
//! lengths, as CSV on stdout: `length,z,radius` in metres, one row per ring. The FMU cannot
//! return a profile, so `examples/knitted_curves.py` runs this to plot it.
//!
//! Usage: `cargo run --release -p actuator-fmus-tools --bin knitted_profile [segments]
//! [length ...]`; without lengths, eight from full extension to free contraction. Defaults: the
//! section 1.4 prototype, 49 segments (one per row).

use actuator_fmus::physics::knitted::{KnittedParams, KnittedSleeve, ShapeKind};
use std::io::Write;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parse = |s: &String| {
        s.parse::<f64>()
            .map_err(|e| format!("bad number '{s}': {e}"))
    };
    let segments = match args.first() {
        Some(s) => s
            .parse::<usize>()
            .map_err(|e| format!("bad segment count '{s}': {e}"))?,
        None => 49,
    };
    let sleeve = KnittedSleeve::new(
        KnittedParams::prototype(),
        ShapeKind::NonCylindrical { segments },
    )?;
    let mut lengths = args
        .iter()
        .skip(1)
        .map(parse)
        .collect::<Result<Vec<_>, _>>()?;
    if lengths.is_empty() {
        let (top, free) = (sleeve.max_length(), sleeve.free_contraction_length());
        lengths = (0..8)
            .map(|i| top - (top - free) * i as f64 / 7.0)
            .collect();
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let io = |e: std::io::Error| e.to_string();
    writeln!(out, "length,z,radius").map_err(io)?;
    for length in lengths {
        for (z, r) in sleeve.profile(length)? {
            writeln!(out, "{length},{z},{r}").map_err(io)?;
        }
    }
    Ok(())
}
