//! Load through the C ABI of both packaged FMUs: 10,000 instantiate/free cycles without memory
//! growth, 100 live instances that do not interfere, and eight threads of instances whose results
//! are bit-identical to the same runs done serially.

mod common;

use common::*;
use std::sync::{Mutex, OnceLock};

/// The tests of this file run one at a time: the memory check reads the process's resident size.
static SERIAL: Mutex<()> = Mutex::new(());

/// A model, how to drive one run of it with a parameter `k`, and which outputs to compare.
struct Driver {
    model: &'static str,
    /// Sets the inputs for step `n` of run `k`.
    inputs: fn(&Instance, usize, usize),
    outputs: &'static [u32],
    step: f64,
}

mod mck {
    pub use actuator_fmus::variables::mckibben_muscle::real;
}
mod motor {
    pub use actuator_fmus::variables::multiferroic_motor::real;
}

fn mckibben_inputs(i: &Instance, k: usize, n: usize) {
    let t = n as f64 * 1e-3;
    let pressure = 5e4 * (k % 13) as f64;
    let length = 0.06 + 0.04 * (0.5 + 0.5 * (7.0 * t + k as f64).sin());
    let vrs = [mck::real::PRESSURE as u32, mck::real::LENGTH as u32];
    assert_eq!(i.set_real(&vrs, &[pressure, length]), OK);
}

fn motor_inputs(i: &Instance, k: usize, n: usize) {
    let t = n as f64 * 1e-6;
    let stress = 2e8 * (1.0 + 0.1 * (k % 7) as f64);
    let direction = 2e4 * t + 0.3 * k as f64;
    let vrs = [
        motor::real::STRESS as u32,
        motor::real::STRAIN_DIRECTION as u32,
    ];
    assert_eq!(i.set_real(&vrs, &[stress, direction]), OK);
}

const DRIVERS: [Driver; 2] = [
    Driver {
        model: "McKibbenMuscle",
        inputs: mckibben_inputs,
        outputs: &[
            mck::real::FORCE as u32,
            mck::real::VOLUME as u32,
            mck::real::FRICTION_FORCE as u32,
        ],
        step: 1e-3,
    },
    Driver {
        model: "MultiferroicMotor",
        inputs: motor_inputs,
        outputs: &[
            motor::real::TORQUE as u32,
            motor::real::ROTOR_ANGLE as u32,
            motor::real::ROTOR_SPEED as u32,
        ],
        step: 1e-6,
    },
];

fn api(model: &str) -> &'static Api {
    static APIS: OnceLock<Vec<(String, Api)>> = OnceLock::new();
    let apis = APIS.get_or_init(|| {
        DRIVERS
            .iter()
            .map(|d| (d.model.to_string(), Api::load(&extract_binary(d.model))))
            .collect()
    });
    &apis.iter().find(|(m, _)| m == model).unwrap().1
}

fn instance(d: &Driver) -> Instance<'static> {
    api(d.model)
        .instantiate("load", &guid_of(d.model))
        .unwrap_or_else(|log| panic!("{} refused: {:?}", d.model, log.lines()))
}

/// Run `k` of `d`: `steps` steps, every compared output after each, as bits.
fn run(d: &Driver, k: usize, steps: usize) -> Vec<u64> {
    let i = instance(d);
    i.initialize();
    let mut out = Vec::with_capacity(steps * d.outputs.len());
    for n in 0..steps {
        (d.inputs)(&i, k, n);
        let s = i.do_step(n as f64 * d.step, d.step);
        assert!(s <= WARNING, "{} run {k} step {n}: {s}", d.model);
        let (s, values) = i.get_real(d.outputs);
        assert_eq!(s, OK);
        assert!(values.iter().all(|x| x.is_finite()), "{values:?}");
        out.extend(values.iter().map(|x| x.to_bits()));
    }
    out
}

/// Resident memory of this process in bytes (Linux).
fn resident_bytes() -> usize {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap();
    let pages: usize = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4096
}

#[test]
fn ten_thousand_instantiate_free_cycles_do_not_grow_memory() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    for d in &DRIVERS {
        let cycle = |k: usize| {
            let i = instance(d);
            i.initialize();
            (d.inputs)(&i, k, 0);
            assert!(i.do_step(0.0, d.step) <= WARNING);
            let mut state = std::ptr::null_mut();
            // An FMU state left to fmi2FreeInstance must be freed with the instance.
            assert_eq!(unsafe { (i.api.fmi2GetFMUstate)(i.c, &mut state) }, OK);
            assert!(i.get_real(d.outputs).1.iter().all(|x| x.is_finite()));
        };
        // Warm-up: allocator pools and lazily initialized tables reach their steady size.
        (0..1000).for_each(cycle);
        let before = resident_bytes();
        (1000..10_000).for_each(cycle);
        let grown = resident_bytes().saturating_sub(before);
        println!(
            "{}: 10,000 instantiate/step/free cycles, resident memory grew by {} kB",
            d.model,
            grown / 1024
        );
        // A leaked instance (its variables and model) is at least a few hundred bytes: 9,000 of
        // them would show as megabytes.
        assert!(
            grown < 2 << 20,
            "{}: resident memory grew by {grown} bytes",
            d.model
        );
    }
}

#[test]
fn a_hundred_live_instances_do_not_interfere() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    for d in &DRIVERS {
        let steps = 20;
        let live: Vec<_> = (0..100)
            .map(|_| {
                let i = instance(d);
                i.initialize();
                i
            })
            .collect();
        // Interleaved: step n of every instance before step n + 1 of any.
        let mut interleaved = vec![Vec::new(); live.len()];
        for n in 0..steps {
            for (k, i) in live.iter().enumerate() {
                (d.inputs)(i, k, n);
                assert!(i.do_step(n as f64 * d.step, d.step) <= WARNING);
                let values = i.get_real(d.outputs).1;
                interleaved[k].extend(values.iter().map(|x| x.to_bits()));
            }
        }
        for (k, got) in interleaved.iter().enumerate() {
            assert_eq!(*got, run(d, k, steps), "{} instance {k}", d.model);
        }
    }
}

#[test]
fn eight_threads_of_instances_match_serial_runs() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let steps = 300;
    for d in &DRIVERS {
        let serial: Vec<_> = (0..8).map(|k| run(d, k, steps)).collect();
        // Each thread runs two instances of its own, interleaved, to mix the threads' work more.
        let threaded: Vec<_> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..8)
                .map(|k| s.spawn(move || (run(d, k, steps), run(d, k, steps))))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (k, (a, b)) in threaded.iter().enumerate() {
            assert_eq!(*a, serial[k], "{} thread {k}", d.model);
            assert_eq!(*b, serial[k], "{} thread {k}, second run", d.model);
        }
        // Different runs differ: the comparison is not between constants.
        assert_ne!(serial[0], serial[1], "{}", d.model);
    }
}
