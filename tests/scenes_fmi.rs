//! Every catalogue scene, in its fast variant, through the `fmi` crate: it runs, its outputs are
//! finite and the seed's numbers it names hold (the FMPy runner checks the same in pytest).

mod common;
#[allow(dead_code)]
#[path = "common/scene_runner.rs"]
mod scene_runner;

use actuator_fmus::scene::Scene;
use std::path::Path;

#[test]
fn catalogue_scenes_run_and_match_the_seed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scenes: Vec<_> = std::fs::read_dir(root.join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    scenes.sort();
    let mut checked = 0;
    for path in &scenes {
        let scene = Scene::from_json(&std::fs::read_to_string(path).unwrap())
            .unwrap()
            .fast();
        let runs = scene_runner::run(&scene, &root.join("scenes"), &root.join("target/fmu"))
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for run in &runs {
            assert!(
                run.rows.iter().flatten().all(|x| x.is_finite()),
                "{}: non-finite output",
                path.display()
            );
        }
        for (ok, text) in scene_runner::checks(&scene, &runs) {
            assert!(ok, "{}: {text}", path.display());
            checked += 1;
        }
    }
    assert!(
        scenes.len() >= 10 && checked >= 5,
        "{} scenes, {checked} checks",
        scenes.len()
    );
}
