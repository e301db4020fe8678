//! Tools around the FMU crate that the FMU binary does not need: packaging `target/fmu/<Model>.fmu`
//! (`package_fmus`), the scene files (`scenes/*.json`) that the examples and tests run, and the
//! offline calibration fit (`calibrate`).

pub mod calibration;
pub mod choices;
pub mod festo_law;
pub mod icons;
pub mod package;
pub mod scene;

/// The repository root (scenes, docs and `target/fmu` live there).
pub fn repository_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tools/ has a parent")
        .to_path_buf()
}
