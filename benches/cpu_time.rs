//! Native costs in thread CPU time, so that the figures reproduce on a loaded machine (wall time
//! there measures the other processes), for `make report` (`target/cpu_time/cpu_time.json`).
//!
//! - The motor's Co-Simulation step: each scenario from a fresh state, several rounds, the
//!   minimum CPU time per communication step with the substeps per step.
//! - The bladder walls (the continuum wall at 8 nodes against 16 layers), one
//!   `Bladder::evaluate` per call along the same stroke, interleaved round by round.
//!
//! Motor scenarios: the `motor_stepping` scene (section 3.2.2, 60 degree steps every 100 us at
//! 200 MPa, 12 periods at 1 us communication steps, the FMU's defaults), and a rotor slipping
//! under a large load torque (1e-12 N m, 5e5 times the 2.16e-18 N m peak of Fig. 3.3a, the bar
//! below its burst speed within 20 us), and under 1e-13 N m.
//!
//! `cargo bench --bench cpu_time -- profile` loops the stepping scene for `perf record`;
//! `-- walls` the two walls.

use actuator_fmus::physics::bladder::{Bladder, Wall};
use actuator_fmus::physics::gaylord::Sleeve;
use actuator_fmus::physics::mckibben::MuscleGeometry;
use actuator_fmus::physics::multiferroic::{
    Motor, MotorInputs, MotorParams, MotorState, ScheduleSwitch, SteppingSchedule,
    CALIBRATION_STRESS,
};
use std::hint::black_box;

#[path = "cpu_clock.rs"]
mod cpu_clock;
use cpu_clock::thread_cpu;

struct Scenario {
    name: &'static str,
    inputs: MotorInputs,
    steps: usize,
    h: f64,
    rounds: usize,
}

fn scenarios() -> Vec<Scenario> {
    let schedule =
        SteppingSchedule::new(0.0, 60f64.to_radians(), 1e-4, CALIBRATION_STRESS).unwrap();
    vec![
        Scenario {
            name: "stepping schedule, 1 us steps over 12 periods",
            inputs: MotorInputs {
                schedule: ScheduleSwitch::on(schedule),
                ..MotorInputs::fixed(0.0, 0.0)
            },
            steps: 1200,
            h: 1e-6,
            rounds: 25,
        },
        Scenario {
            name: "load torque 1e-12 N m (load-dominated), 1 us steps",
            inputs: MotorInputs {
                load_torque: 1e-12,
                ..MotorInputs::fixed(0.0, CALIBRATION_STRESS)
            },
            steps: 20,
            h: 1e-6,
            rounds: 5,
        },
        // Thousands of turns per step, the ring's torque averaged over the onion's cycle.
        Scenario {
            name: "load torque 1e-13 N m (fast slip), 1 us steps",
            inputs: MotorInputs {
                load_torque: 1e-13,
                ..MotorInputs::fixed(0.0, CALIBRATION_STRESS)
            },
            steps: 3,
            h: 1e-6,
            rounds: 1,
        },
    ]
}

/// (minimum CPU seconds per step over the rounds, substeps per step).
fn measure(motor: &Motor, s: &Scenario) -> (f64, f64) {
    let mut best = f64::INFINITY;
    let mut substeps = 0u64;
    for _ in 0..s.rounds {
        let mut state = MotorState::aligned(0.0);
        substeps = 0;
        let start = thread_cpu();
        for _ in 0..s.steps {
            let r = motor.step(&mut state, &s.inputs, s.h).unwrap();
            substeps += u64::from(r.substeps);
            black_box(r);
        }
        best = best.min((thread_cpu() - start) / s.steps as f64);
    }
    (best, substeps as f64 / s.steps as f64)
}

/// The parity bench's wall scenario: Table 2.1's muscle A at 690 kPa over 0.75-0.93 of its
/// length (bladder on the sleeve), 200 lengths.
fn wall_round(bladder: &Bladder<Sleeve>) -> f64 {
    let start = thread_cpu();
    for k in 0..200 {
        let length = 0.10325 * (0.75 + 0.18 * k as f64 / 200.0);
        black_box(bladder.evaluate(6.9e5, black_box(length)).unwrap());
    }
    (thread_cpu() - start) / 200.0
}

/// (minimum CPU seconds per evaluation of each wall, median of the rounds' ratios).
fn walls(rounds: usize) -> Vec<(&'static str, f64)> {
    let a = MuscleGeometry::muscle_a();
    let walls = [
        // The dissertation's walls (bladder_model 5 and 6), under their benchmark names.
        (
            "McKibbenMuscle, layered wall, 16 layers",
            Wall::DissertationLayers(16),
        ),
        (
            "McKibbenMuscle, continuum wall, 8 nodes",
            Wall::DissertationContinuum(8),
        ),
        ("McKibbenMuscle, exact wall, 16 nodes", Wall::Exact(16)),
    ];
    let bladders: Vec<Bladder<Sleeve>> = walls
        .iter()
        .map(|(_, w)| Bladder::with_wall(a.sleeve().unwrap(), a.tube(), *w).unwrap())
        .collect();
    let mut best = [f64::INFINITY; 3];
    // Ratios to the 16-layer wall: continuum, exact.
    let mut ratios = [vec![], vec![]];
    for round in 0..rounds {
        let mut t = [0.0; 3];
        for i in 0..3 {
            let which = (i + round) % 3;
            t[which] = wall_round(&bladders[which]);
            best[which] = best[which].min(t[which]);
        }
        ratios[0].push(t[1] / t[0]);
        ratios[1].push(t[2] / t[0]);
    }
    for r in &mut ratios {
        r.sort_by(f64::total_cmp);
    }
    vec![
        (walls[0].0, best[0]),
        (walls[1].0, best[1]),
        (walls[2].0, best[2]),
        (
            "continuum 8 nodes / layered 16, median of round ratios",
            ratios[0][rounds / 2],
        ),
        (
            "exact 16 nodes / layered 16, median of round ratios",
            ratios[1][rounds / 2],
        ),
    ]
}

fn main() {
    let motor = Motor::new(MotorParams::table_3_1()).unwrap();
    let all = scenarios();
    if std::env::args().any(|a| a == "profile") {
        let s = Scenario {
            rounds: 400,
            ..scenarios().swap_remove(0)
        };
        let (cpu, _) = measure(&motor, &s);
        eprintln!("{}: {:.3} us CPU per step", s.name, 1e6 * cpu);
        return;
    }
    if std::env::args().any(|a| a == "walls") {
        for (name, v) in walls(2000) {
            eprintln!("{name}: {v:.4e}");
        }
        return;
    }
    let mut rows = vec![];
    for s in &all {
        let (cpu, substeps) = measure(&motor, s);
        println!(
            "MultiferroicMotor, {}: {:.3} us CPU per step (minimum of {} rounds), {:.2} substeps per step",
            s.name,
            cpu * 1e6,
            s.rounds,
            substeps
        );
        rows.push(format!(
            "{{\"case\": \"MultiferroicMotor, {}\", \"cpu_s\": {cpu:e}, \"substeps\": {substeps}}}",
            s.name
        ));
    }
    let wall_rows = walls(201);
    for (name, v) in &wall_rows[..3] {
        println!(
            "{name}: {:.1} ns CPU per evaluation (minimum of 201 rounds)",
            v * 1e9
        );
        rows.push(format!("{{\"case\": \"{name}\", \"cpu_s\": {v:e}}}"));
    }
    for (name, ratio) in &wall_rows[3..] {
        println!("{name}: {ratio:.2}x");
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/cpu_time");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("cpu_time.json"),
        format!(
            "{{\"cases\": [{}], \"walls_ratio\": {}, \"exact_wall_ratio\": {}}}\n",
            rows.join(", "),
            wall_rows[3].1,
            wall_rows[4].1
        ),
    )
    .unwrap();
}
