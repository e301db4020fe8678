//! Every catalogue scene, in its fast variant, through the `fmi` crate: it runs, its outputs are
//! finite and the dissertation's numbers it names hold (the FMPy runner checks the same in pytest).

#[allow(dead_code)]
#[path = "common/scene_runner.rs"]
mod scene_runner;

use actuator_fmus_tools::scene::Scene;

#[test]
fn catalogue_scenes_run_and_match_the_dissertation() {
    let root = &actuator_fmus_tools::repository_root();
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

#[test]
fn csv_input_signal_through_the_fmi_crate() {
    let root = &actuator_fmus_tools::repository_root();
    let dir = std::env::temp_dir().join(format!("scene-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("u.csv"), "time,u\n0,0\n0.5,1\n1,0\n").unwrap();
    let scene = Scene::from_json(
        r#"{"fmu": "PassThrough", "description": "echo", "step": 0.125, "stop_time": 1.0,
            "inputs": {"u": {"type": "csv", "file": "u.csv", "column": "u"}}, "outputs": ["y"]}"#,
    )
    .unwrap();
    let runs = scene_runner::run(&scene, &dir, &root.join("target/fmu")).unwrap();
    let y = runs[0].column("y");
    // The row at t + h holds the input applied at t: 0, 0, 0.25, 0.5, 0.75, 1, 0.75, 0.5, 0.25.
    let expected = [0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 0.75, 0.5, 0.25];
    assert_eq!(y.len(), expected.len());
    for (got, want) in y.iter().zip(expected) {
        assert!((got - want).abs() < 1e-12, "{y:?}");
    }
}
