//! The robot joint through the `fmi` crate gives the trajectory that FMPy gives: the committed
//! reference `tests/data/robot_joint_ref.csv` was written by `python/actuator_fmus/robot_joint.py` (FMPy's
//! FMU2Slave), and `tests/fmpy/test_robot_joint.py` checks FMPy against the same file.

use crate::common;
#[allow(dead_code)]
#[path = "../common/robot_joint.rs"]
mod robot_joint;

use std::path::Path;

fn reference() -> Vec<Vec<f64>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/robot_joint_ref.csv");
    let text = std::fs::read_to_string(&path).expect("reference CSV");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(robot_joint::COLUMNS.join(",").as_str()));
    lines
        .filter(|l| !l.is_empty())
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect()
}

#[test]
fn fmi_crate_matches_fmpy_trajectory() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    common::fmu_path("McKibbenMuscle");
    let p = robot_joint::Parameters::load(&root.join("examples/robot_joint.json")).unwrap();
    let rows = robot_joint::simulate(&p, &root.join("target/fmu"), None).unwrap();
    let reference = reference();
    assert_eq!(rows.len(), reference.len());
    let mut worst: f64 = 0.0;
    for (row, want) in rows.iter().zip(&reference) {
        assert_eq!(row[0], want[0], "same sample times");
        worst = worst.max((row[1] - want[1]).abs());
        for (i, (a, b)) in row.iter().zip(want).enumerate() {
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                "t = {}: {} is {a}, FMPy gave {b}",
                row[0],
                robot_joint::COLUMNS[i]
            );
        }
    }
    assert!(worst <= 1e-9, "joint angle differs by {worst} rad");
}

#[test]
fn joint_actuator_fmu_gives_the_same_trajectory() {
    // McKibbenJoint computes r (F_f - F_e) from the same muscle physics with the same pressures
    // and lengths, so stepped like gazebo-fmi steps it, it reproduces the two-muscle run.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    common::fmu_path("McKibbenJoint");
    let p = robot_joint::Parameters::load(&root.join("examples/robot_joint.json")).unwrap();
    let rows = robot_joint::simulate_joint_fmu(&p, &root.join("target/fmu"), None).unwrap();
    let reference = reference();
    assert_eq!(rows.len(), reference.len());
    for (row, want) in rows.iter().zip(&reference) {
        for (i, (a, b)) in row.iter().zip(want).enumerate() {
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                "t = {}: {} is {a}, the two-muscle run gave {b}",
                row[0],
                robot_joint::COLUMNS[i]
            );
        }
    }
}

#[test]
fn joint_tracks_the_reference_and_holds_the_gravity_load() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let p = robot_joint::Parameters::load(&root.join("examples/robot_joint.json")).unwrap();
    let rows = robot_joint::simulate(&p, &root.join("target/fmu"), None).unwrap();
    // PD control with feed-forward: the angle follows the waypoints within a few degrees, and the
    // pressures stay inside their saturation limits.
    for row in &rows {
        assert!(
            (row[1] - row[3]).abs() < 3f64.to_radians(),
            "t = {}",
            row[0]
        );
        assert!((0.0..=p.max_pressure).contains(&row[4]));
        assert!((0.0..=p.max_pressure).contains(&row[5]));
    }
    // At rest at the end (q_ref = 0, zero velocity) the net torque balances gravity and damping.
    let last = rows.last().unwrap();
    let mgl = p.mass * p.gravity * p.com_distance;
    assert!(last[2].abs() < 0.05, "still moving: {} rad/s", last[2]);
    assert!(
        (last[8] - mgl * last[1].sin()).abs() < 2e-3,
        "torque {}",
        last[8]
    );
}
