//! The integration tests in one binary: linking one release binary per `tests/*.rs` file cost
//! `make test` a link of the whole crate and its dependencies each. Each file here is the module it
//! was as a binary; they share one copy of `tests/common`. `tests/load.rs` and
//! `tests/model_exchange_states.rs` keep their own processes: their `#[global_allocator]` counts
//! every allocation the process makes, which other tests running beside them would disturb. A new `tests/*.rs` file still builds as its own binary; list it here
//! (after `git mv` into `tests/all/`) to join this one.

// The fuzz driver declares the FMI functions with the crate's types (`fmi2Status`), `common` with
// C's (`c_int`): the same C ABI, declared twice now that both are in one binary.
#![allow(clashing_extern_declarations)]

/// One copy of the shared helpers for every module (`use crate::common`).
#[path = "../common/mod.rs"]
mod common;
/// The call sequences that exercise every model, shared by the lifecycle and restore checks.
#[path = "../common/exercise.rs"]
mod exercise;

mod bad_input;
mod build_script;
mod c_abi;
mod declared_ranges;
mod fmi3_arrays;
mod fmi3_crate;
mod fmi_crate;
mod fuzz_corpus;
mod glibc_versions;
mod lifecycle_checks;
mod motor_c_abi;
mod new_model;
mod restore_validation;
mod robot_joint_runs;
mod shipped_descriptions;
mod terminals;

/// Every file in `tests/all/` is a module of this binary: a file dropped here but not listed
/// above would silently never run.
#[test]
fn every_file_in_tests_all_is_a_module() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/all");
    let this = include_str!("main.rs");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if let Some(module) = name.strip_suffix(".rs").filter(|m| *m != "main") {
            assert!(
                this.contains(&format!("\nmod {module};\n")),
                "tests/all/{name} is not declared in tests/all/main.rs"
            );
        }
    }
}
