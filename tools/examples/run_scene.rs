//! Runs scene files through the `fmi` crate (the Rust-side importer) and writes
//! `<out>/<scene>_fmi.csv`: `cargo run --release -p actuator-fmus-tools --example run_scene -- scenes/<scene>.json [--fast]`.
//! `--schema` prints the JSON Schema of scene files instead (`scenes/schema/scene.schema.json`).

#[allow(dead_code)]
#[path = "../tests/common/scene_runner.rs"]
mod scene_runner;

use actuator_fmus_tools::scene::{json_schema, Scene};
use std::path::{Path, PathBuf};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let fast = args.iter().any(|a| a == "--fast");
    if args.iter().any(|a| a == "--schema") {
        print!("{}", json_schema());
        return;
    }
    let root = &actuator_fmus_tools::repository_root();
    let mut failed = 0;
    for path in args
        .iter()
        .filter(|a| !a.starts_with("--"))
        .map(PathBuf::from)
    {
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let scene = match Scene::from_json(&text) {
            Ok(scene) => scene,
            Err(e) => {
                eprintln!("{}: {e}", path.display());
                std::process::exit(2);
            }
        };
        let scene = if fast { scene.fast() } else { scene };
        let dir = path.parent().unwrap_or(Path::new("."));
        let runs = scene_runner::run(&scene, dir, &root.join("target/fmu"))
            .unwrap_or_else(|e| panic!("{e}"));
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
        let out = root.join("out");
        std::fs::create_dir_all(&out).expect("create out/");
        let mut csv = String::new();
        let sweep = scene.sweep.as_ref().map(|s| s.variable.clone());
        csv.push_str(
            &sweep
                .iter()
                .cloned()
                .chain(runs[0].columns.iter().cloned())
                .collect::<Vec<_>>()
                .join(","),
        );
        csv.push('\n');
        for run in &runs {
            for row in &run.rows {
                let cells: Vec<String> = run
                    .sweep_value
                    .iter()
                    .chain(row.iter())
                    .map(|x| format!("{x:.9e}"))
                    .collect();
                csv.push_str(&cells.join(","));
                csv.push('\n');
            }
        }
        let file = out.join(format!("{stem}_fmi.csv"));
        std::fs::write(&file, csv).expect("write CSV");
        for (ok, text) in scene_runner::checks(&scene, &runs) {
            println!("  {} {text}", if ok { "ok  " } else { "FAIL" });
            failed += usize::from(!ok);
        }
        println!("wrote {}", file.display());
    }
    std::process::exit(i32::from(failed > 0));
}
