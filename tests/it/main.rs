//! All integration tests but `load` and `model_description` in one binary: linking one release
//! binary per file dominated the build part of `make test`. Each file stays where it was and is a
//! module here; `load` keeps its own process because it reads the process's resident memory, and
//! `model_description` because it addresses build.rs's checker from its crate root.
//! A new `tests/<name>.rs` must be listed below (or in Cargo.toml): `every_test_file_is_built` checks.

#[path = "../bad_input.rs"]
mod bad_input;
#[path = "../declared_ranges.rs"]
mod declared_ranges;
#[path = "../c_abi.rs"]
mod c_abi;
#[path = "../fmi_crate.rs"]
mod fmi_crate;
#[path = "../motor_c_abi.rs"]
mod motor_c_abi;
#[path = "../robot_joint.rs"]
mod robot_joint_test;

/// Test files built as their own binaries (Cargo.toml).
const OWN_BINARY: &[&str] = &["load.rs", "model_description.rs"];

#[test]
fn every_test_file_is_built() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let listed = std::fs::read_to_string(root.join("tests/it/main.rs")).unwrap();
    for entry in std::fs::read_dir(root.join("tests")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name.ends_with(".rs") && !OWN_BINARY.contains(&name.as_str()) {
            assert!(
                listed.contains(&format!("#[path = \"../{name}\"]")),
                "tests/{name} is not in tests/it/main.rs, so `cargo test` would not build it"
            );
        }
    }
}
