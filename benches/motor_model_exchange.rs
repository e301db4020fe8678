//! Cost of the motor's Model Exchange calls against a Co-Simulation step, in the physics (no C
//! ABI): a 1 us `Motor::step` of the stepping schedule (section 3.2.2, 100 us periods at 200 MPa,
//! the `motor_stepping` scene's communication step), one right-hand side with outputs and the fold
//! indicator (`me_evaluate`, what `fmi2GetDerivatives` costs), and the full set of exact partials
//! of the derivatives and outputs by every state and input (`me_partials`, what one or more
//! `fmi2GetDirectionalDerivative` calls cost).

use actuator_fmus::physics::multiferroic::{
    Motor, MotorInputs, MotorParams, MotorState, ScheduleSwitch, SteppingSchedule,
    CALIBRATION_STRESS,
};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Duration;

fn cost(c: &mut Criterion) {
    let motor = Motor::new(MotorParams::table_3_1()).unwrap();
    let schedule =
        SteppingSchedule::new(0.0, 60f64.to_radians(), 1e-4, CALIBRATION_STRESS).unwrap();
    let inputs = MotorInputs {
        schedule: ScheduleSwitch::on(schedule),
        ..MotorInputs::fixed(0.0, 0.0)
    };
    // Mid-period of the second step, the rotor turning.
    let mut state = MotorState::aligned(0.0);
    motor.step(&mut state, &inputs, 1.05e-4).unwrap();
    let mut group = c.benchmark_group("MultiferroicMotor");
    group.bench_function("Co-Simulation step of 1 us (Motor::step)", |b| {
        b.iter(|| {
            let mut s = state;
            black_box(motor.step(&mut s, &inputs, 1e-6).unwrap())
        })
    });
    let t = state.time;
    group.bench_function(
        "right-hand side, outputs and fold indicator (me_evaluate)",
        |b| b.iter(|| black_box(motor.me_evaluate(black_box(&state), &inputs, t).unwrap())),
    );
    group.bench_function(
        "all exact partials by states and inputs (me_partials)",
        |b| b.iter(|| black_box(motor.me_partials(black_box(&state), &inputs, t).unwrap())),
    );
    group.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30)
}

criterion_group! { name = benches; config = config(); targets = cost }
criterion_main!(benches);
