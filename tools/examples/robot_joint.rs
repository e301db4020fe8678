//! The robot joint of `python/actuator_fmus/robot_joint.py` through the `fmi` crate: two McKibbenMuscle
//! instances on a pulley, the same controller and integrator, parameters from
//! `examples/robot_joint.json`. Writes `out/robot_joint_fmi.csv`, and runs the same loop with
//! the McKibbenJoint FMU in place of the two muscles (`out/robot_joint_joint_fmu.csv`):
//! `cargo run --release -p actuator-fmus-tools --example robot_joint [-- --stop-time 2.0]`.
//! It lives in `tools/` so that `make robot-joint` compiles only the `fmi` crate beside the
//! library, not the root crate's test-only dependencies (criterion, proptest, ...).

#[path = "../../tests/common/robot_joint.rs"]
mod robot_joint;

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
    let root = &actuator_fmus_tools::repository_root();
    let p = robot_joint::Parameters::load(&root.join("examples/robot_joint.json"))
        .unwrap_or_else(|e| panic!("{e}"));
    let rows = robot_joint::simulate(&p, &root.join("target/fmu"), stop_time)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = root.join("out");
    std::fs::create_dir_all(&out).expect("create out/");
    let path = out.join("robot_joint_fmi.csv");
    std::fs::write(&path, robot_joint::to_csv(&rows)).expect("write the CSV");
    let joint = robot_joint::simulate_joint_fmu(&p, &root.join("target/fmu"), stop_time)
        .unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(
        out.join("robot_joint_joint_fmu.csv"),
        robot_joint::to_csv(&joint),
    )
    .expect("write the CSV");
    let apart = rows
        .iter()
        .zip(&joint)
        .map(|(a, b)| (a[1] - b[1]).abs())
        .fold(0.0, f64::max);
    println!("McKibbenJoint FMU: joint angle within {apart:e} rad of the two-muscle run");
    let worst = rows.iter().map(|r| (r[1] - r[3]).abs()).fold(0.0, f64::max);
    println!(
        "{} rows, largest tracking error {:.2} deg; wrote {}",
        rows.len(),
        worst.to_degrees(),
        path.display()
    );
}
