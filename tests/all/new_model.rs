//! A model is declared once: docs/adding-a-model.md's trivial model (y = 2u, Co-Simulation and
//! Model Exchange, with its directional derivative) added to a scratch copy of the repository as
//! its model description, its model file and one line in `src/models/mod.rs`, nothing else, then
//! built, packaged and put through the Rust suites that iterate over every model.
//!
//! The full walk is ignored in `cargo test` (it builds the crate a second time: minutes); run it
//! with `make test-new-model`. The scratch copy builds in `target/new-model/`, which keeps the
//! dependencies between runs. The cheap half (the page's three files pass the build checks) runs
//! in every `cargo test`.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::build_script::{codegen, model_description};

fn documented_files() -> Vec<(String, String)> {
    let doc = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/adding-a-model.md");
    walk_through(&std::fs::read_to_string(doc).unwrap())
}

/// The cheap half, in every `cargo test`: the page writes three files, its model description
/// passes the build script's checks and generates code, and its model file names no other model.
#[test]
fn the_walk_through_writes_three_files_that_pass_the_build_checks() {
    let files = documented_files();
    let paths: Vec<&str> = files.iter().map(|(p, _)| p.as_str()).collect();
    assert_eq!(
        paths,
        [
            "modelDescription/Doubler.xml",
            "src/models/doubler.rs",
            "src/models/mod.rs"
        ]
    );
    let model = model_description::check(&files[0].1, "Doubler").unwrap_or_else(|e| panic!("{e}"));
    assert!(model.shipped_xml.contains("<ModelExchange"));
    assert!(model
        .shipped_xml
        .contains(r#"providesDirectionalDerivative="true""#));
    let mut code = String::new();
    codegen::tables(&model, "Doubler.xml", &mut code).unwrap();
    assert!(
        code.contains("pub mod doubler"),
        "no `variables::doubler` generated"
    );
    assert!(files[1].1.contains("use crate::variables::doubler::"));
    assert_eq!(files[2].1, "pub mod doubler;\n");
}

/// The files docs/adding-a-model.md writes: each fenced block preceded by a
/// `<!-- new-model: <path> -->` line, with the block's text.
fn walk_through(doc: &str) -> Vec<(String, String)> {
    let mut files = Vec::new();
    let mut lines = doc.lines();
    while let Some(line) = lines.next() {
        let Some(path) = line
            .trim()
            .strip_prefix("<!-- new-model: ")
            .and_then(|rest| rest.strip_suffix(" -->"))
        else {
            continue;
        };
        let fence = lines.next().expect("a fenced block after the marker");
        assert!(
            fence.starts_with("```"),
            "{path}: no fenced block after the marker"
        );
        let text: Vec<&str> = lines.by_ref().take_while(|l| *l != "```").collect();
        files.push((path.to_string(), text.join("\n") + "\n"));
    }
    files
}

/// Copies the repository's working tree (tracked and untracked files, not the ignored ones) to
/// `to`.
fn copy_repository(from: &Path, to: &Path) {
    let listing = Command::new("git")
        .args([
            "ls-files",
            "-z",
            "--cached",
            "--others",
            "--exclude-standard",
        ])
        .current_dir(from)
        .output()
        .expect("git runs");
    assert!(listing.status.success(), "git ls-files failed");
    for name in listing.stdout.split(|&b| b == 0).filter(|n| !n.is_empty()) {
        let name = std::str::from_utf8(name).unwrap();
        let source = from.join(name);
        if !source.is_file() {
            continue; // deleted in the working tree
        }
        let target = to.join(name);
        std::fs::create_dir_all(target.parent().unwrap()).unwrap();
        std::fs::copy(&source, &target).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

fn run(dir: &Path, target_dir: &Path, program: &str, args: &[&str]) {
    eprintln!("new model: {program} {}", args.join(" "));
    let status = Command::new(program)
        .args(args)
        .current_dir(dir)
        .env("CARGO_TARGET_DIR", target_dir)
        .status()
        .unwrap_or_else(|e| panic!("{program}: {e}"));
    assert!(
        status.success(),
        "{program} {args:?} failed in {}",
        dir.display()
    );
}

#[test]
#[ignore = "builds the crate again (minutes): make test-new-model"]
fn a_new_model_takes_its_description_its_file_and_one_line() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files = documented_files();

    let scratch: PathBuf =
        std::env::temp_dir().join(format!("actuator-fmus-new-model-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&scratch);
    copy_repository(repo, &scratch);
    for (path, text) in &files {
        let target = scratch.join(path);
        if path == "src/models/mod.rs" {
            // The one line elsewhere: the module, among the others in name order.
            let line = text.trim();
            let modules = std::fs::read_to_string(&target).unwrap();
            assert!(!modules.contains(line), "{line} is in mod.rs already");
            let at = modules
                .match_indices("\npub mod ")
                .find(|(i, _)| modules[i + 1..].lines().next().unwrap() > line)
                .map_or_else(|| modules.find("\npub mod ").unwrap(), |(i, _)| i);
            let edited = format!("{}\n{line}{}", &modules[..at], &modules[at..]);
            assert_eq!(edited.lines().count(), modules.lines().count() + 1);
            std::fs::write(&target, edited).unwrap();
        } else {
            assert!(!target.exists(), "{path} exists already");
            std::fs::write(&target, text).unwrap();
        }
    }

    let target_dir = repo.join("target/new-model");
    let target_str = target_dir.to_str().unwrap();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    run(
        &scratch,
        &target_dir,
        &cargo,
        &["build", "--release", "--lib", "-p", "actuator-fmus"],
    );
    run(
        &scratch,
        &target_dir,
        &cargo,
        &[
            "build",
            "--release",
            "-p",
            "actuator-fmus-tools",
            "--bin",
            "package_fmus",
        ],
    );
    run(
        &scratch,
        &target_dir,
        &format!("{target_str}/release/package_fmus"),
        &[
            &format!("{target_str}/release/libactuator_fmus.so"),
            scratch.join("target/fmu").to_str().unwrap(),
        ],
    );
    assert!(
        scratch.join("target/fmu/Doubler.fmu").is_file(),
        "Doubler.fmu was not packaged"
    );
    // The crate's own tests (the registry's capabilities check, the export layer on every model)
    // and the FMU-level suites that iterate over every model.
    run(
        &scratch,
        &target_dir,
        &cargo,
        &["test", "--release", "-p", "actuator-fmus", "--lib"],
    );
    run(
        &scratch,
        &target_dir,
        &cargo,
        &[
            "test",
            "--release",
            "-p",
            "actuator-fmus",
            "--test",
            "all",
            "--",
            "--skip",
            "new_model",
            "bad_input",
            "declared_ranges",
            "fuzz_corpus",
            "restore_validation",
            "shipped_descriptions",
        ],
    );
    std::fs::remove_dir_all(&scratch).unwrap();
}
