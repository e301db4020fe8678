//! The motor's native Co-Simulation step in thread CPU time, so that the figures reproduce on a
//! loaded machine (wall time there measures the other processes). Each scenario is run from a
//! fresh state several times; the minimum CPU time per communication step is reported with the
//! substeps per step. Writes `target/motor_steps/motor_steps.json` for `make report`.
//!
//! Scenarios: the `motor_stepping` scene (section 3.2.2, 60 degree steps every 100 us at
//! 200 MPa, 12 periods at 1 us communication steps, the FMU's defaults), and a rotor slipping
//! under a large legal load torque (1e-6 N m, far beyond the 2.16e-18 N m peak of Fig. 3.3a).
//!
//! `cargo bench --bench motor_steps -- profile` loops the stepping scene for `perf record`.

use actuator_fmus::physics::multiferroic::{
    Motor, MotorInputs, MotorParams, MotorState, ScheduleSwitch, SteppingSchedule,
    CALIBRATION_STRESS,
};
use std::hint::black_box;

#[repr(C)]
struct Timespec {
    sec: i64,
    nsec: i64,
}

extern "C" {
    fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
}

/// CLOCK_THREAD_CPUTIME_ID on Linux.
const THREAD_CPU: i32 = 3;

/// CPU seconds this thread has used.
fn thread_cpu() -> f64 {
    let mut ts = Timespec { sec: 0, nsec: 0 };
    // SAFETY: a valid pointer to a timespec; clock_gettime only writes it.
    let rc = unsafe { clock_gettime(THREAD_CPU, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime");
    ts.sec as f64 + 1e-9 * ts.nsec as f64
}

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
            name: "load torque 1e-6 N m (load-dominated), 1 us steps",
            inputs: MotorInputs {
                load_torque: 1e-6,
                ..MotorInputs::fixed(0.0, CALIBRATION_STRESS)
            },
            steps: 20,
            h: 1e-6,
            rounds: 5,
        },
        // Between the resolved slip and the load-dominated shortcut: thousands of turns per
        // step whose ring torque does not average out within the tolerance; still budget-bound.
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
            "{{\"case\": \"{}\", \"cpu_s\": {cpu:e}, \"substeps\": {substeps}}}",
            s.name
        ));
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/motor_steps");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("motor_steps.json"),
        format!("{{\"cases\": [{}]}}\n", rows.join(", ")),
    )
    .unwrap();
}
