//! The robot joint of `examples/robot_joint.py` through the `fmi` crate: two McKibbenMuscle
//! instances on a pulley, the same controller and integrator, parameters from
//! `examples/robot_joint.json`. Writes `out/robot_joint_fmi.csv`:
//! `cargo run --release --example robot_joint [-- --stop-time 2.0]`.

#[path = "../tests/common/robot_joint.rs"]
mod robot_joint;

use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let stop_time = args
        .iter()
        .position(|a| a == "--stop-time")
        .and_then(|i| args.get(i + 1))
        .map(|s| {
            s.parse::<f64>()
                .expect("--stop-time takes a number of seconds")
        });
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let p = robot_joint::Parameters::load(&root.join("examples/robot_joint.json"))
        .unwrap_or_else(|e| panic!("{e}"));
    let rows = robot_joint::simulate(&p, &root.join("target/fmu"), stop_time)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = root.join("out");
    std::fs::create_dir_all(&out).expect("create out/");
    let path = out.join("robot_joint_fmi.csv");
    std::fs::write(&path, robot_joint::to_csv(&rows)).expect("write the CSV");
    let worst = rows.iter().map(|r| (r[1] - r[3]).abs()).fold(0.0, f64::max);
    println!(
        "{} rows, largest tracking error {:.2} deg; wrote {}",
        rows.len(),
        worst.to_degrees(),
        path.display()
    );
}
