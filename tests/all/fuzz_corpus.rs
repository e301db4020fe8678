//! The committed fuzz corpus (`fuzz/corpus/call_sequences/`, kept small with `make fuzz-cmin`)
//! and the inputs that once were findings (`fuzz/regressions/call_sequences/`, kept out of the
//! corpus so that `cmin` cannot drop them) replayed through the fuzz harness's own logic, without
//! libFuzzer or a nightly toolchain: no input makes any FMU return fmi2Fatal, crash, refuse
//! without a logged reason or hand out a NaN. `make fuzz` writes new findings to
//! `fuzz/artifacts/`.

#[path = "../fuzz_driver/call_sequences.rs"]
mod driver;

use std::path::Path;

#[test]
fn the_fuzz_corpus_finds_nothing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut inputs: Vec<_> = ["corpus", "regressions"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(root.join(dir).join("call_sequences")).unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    inputs.sort();
    assert!(
        inputs
            .iter()
            .any(|p| p.to_string_lossy().contains("regressions")),
        "the regression inputs are missing"
    );
    let mut calls = 0;
    for path in &inputs {
        let data = std::fs::read(path).unwrap();
        // The driver panics on a finding, naming it; say which input it was.
        let result = std::panic::catch_unwind(|| driver::run(&data));
        match result {
            Ok(n) => calls += n,
            Err(_) => panic!("{} is a finding (see the panic above)", path.display()),
        }
    }
    println!("{} inputs, {calls} FMI calls", inputs.len());
    assert!(
        inputs.len() >= 50 && calls > 1000,
        "{} inputs, {calls} calls",
        inputs.len()
    );
}

/// The harness names models by a stable id (`MODEL_IDS`), not by registry position: each id must
/// name a model of the registry (the harness panics otherwise, but only when an input picks that
/// id), and every other model is reached through the reserved id.
#[test]
fn every_model_is_reached_by_a_stable_fuzz_id() {
    use actuator_fmus::fmi2::REGISTRY;
    for name in driver::MODEL_IDS.iter().flatten() {
        assert!(
            REGISTRY.iter().any(|f| f.info().name == *name),
            "MODEL_IDS names {name}, which the registry lacks"
        );
    }
    let later = driver::later_models();
    assert_eq!(
        driver::MODEL_IDS.iter().flatten().count() + later.len(),
        REGISTRY.len()
    );
    assert!(driver::MODEL_IDS.contains(&None), "the reserved id is gone");
}

/// The harness reads the Model Exchange sizes from the shipped model description, as an
/// importer does; the right sizes are what let its calls pass the size checks.
#[test]
fn the_harness_reads_the_model_exchange_sizes() {
    use actuator_fmus::fmi2::REGISTRY;
    let sizes = |name: &str| {
        let info = REGISTRY
            .iter()
            .find(|f| f.info().name == name)
            .unwrap()
            .info();
        driver::me_sizes(info)
    };
    assert_eq!(sizes("PulleyJoint"), (2, 0)); // joint angle and velocity
    assert_eq!(sizes("MultiferroicMotor"), (4, 1)); // rotor and onion angles; the fold
    assert_eq!(sizes("McKibbenMuscle"), (0, 0));
}
