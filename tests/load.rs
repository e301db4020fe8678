//! Load through the C ABI of every FMU, in both interfaces: 10,000 cycles each (a Co-Simulation
//! instance, then a Model Exchange one with its continuous states, events and directional
//! derivatives) whose heap does not grow (counted by this binary's global allocator, exact to the
//! byte), 100 live instances that do not interfere, and eight threads stepping in lockstep, in
//! both interfaces, whose results are bit-identical to the same runs done serially.

mod common;
#[path = "common/exercise.rs"]
mod exercise;
#[path = "common/model_exchange.rs"]
mod model_exchange;

use actuator_fmus::variables::ModelInfo;
use common::*;
use exercise::*;
use model_exchange::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicIsize, Ordering};
use std::sync::{Barrier, Mutex, OnceLock};

/// Bytes this process holds on the heap through Rust's allocator: allocated minus freed. The
/// crate is linked into this test ([`Api::linked`]), so the FMUs' allocations are counted too.
struct Counting;

static HELD: AtomicIsize = AtomicIsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if !p.is_null() {
            HELD.fetch_add(layout.size() as isize, Ordering::Relaxed);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        if !p.is_null() {
            HELD.fetch_add(layout.size() as isize, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        System.dealloc(p, layout);
        HELD.fetch_sub(layout.size() as isize, Ordering::Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let q = System.realloc(p, layout, new_size);
        if !q.is_null() {
            HELD.fetch_add(
                new_size as isize - layout.size() as isize,
                Ordering::Relaxed,
            );
        }
        q
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The tests of this file run one at a time: the heap count is process-wide.
static SERIAL: Mutex<()> = Mutex::new(());

fn packaged(info: &ModelInfo) -> &'static (Api, MeApi) {
    static APIS: OnceLock<Vec<(&'static str, (Api, MeApi))>> = OnceLock::new();
    let apis = APIS.get_or_init(|| {
        models()
            .into_iter()
            .map(|i| {
                let path = extract_binary(i.name);
                (i.name, (Api::load(&path), MeApi::load(&path)))
            })
            .collect()
    });
    &apis.iter().find(|(m, _)| *m == info.name).unwrap().1
}

/// Run `k` of `info` on `api`: `steps` steps, every Real after each, as bits.
fn run(api: &Api, info: &ModelInfo, k: usize, steps: usize) -> Vec<u64> {
    let i = ready(api, info, true);
    (0..steps)
        .flat_map(|n| step_and_read(&i, info, k, n))
        .collect()
}

/// Steps of the Model Exchange instance of each cycle: with [`me_run`]'s schedule they cover a
/// time event (step 2), an FMU state round trip (step 1) and directional derivatives (steps 1, 3).
const ME_CYCLE_STEPS: usize = 4;

/// One cycle (all effects on every hundredth cycle: their builds and steps cost most):
/// - Co-Simulation: instantiate, initialize, step, a serialized state restored and freed, a
///   state left for fmi2FreeInstance, every Real read, directional derivatives, free;
/// - Model Exchange: [`me_run`] over [`ME_CYCLE_STEPS`] steps, free.
fn cycle(api: &Api, me: &MeApi, info: &ModelInfo, k: usize) {
    let effects = k.is_multiple_of(100);
    {
        let i = ready(api, info, effects);
        step_and_read(&i, info, k, 0);
        fmu_state_round_trip(&i, info);
        step_and_read(&i, info, k, 1);
        directional_derivatives(&i, info, None);
    }
    me_run(api, me, info, effects, k, ME_CYCLE_STEPS);
}

/// The heap's growth over `cycles` of `info`, and how many cycles did not free all they
/// allocated. `leak_every`: the positive control, 64 bytes leaked by every n-th cycle.
fn heap_growth(
    api: &Api,
    me: &MeApi,
    info: &ModelInfo,
    cycles: std::ops::Range<usize>,
    leak_every: Option<usize>,
) -> (isize, usize) {
    let before = HELD.load(Ordering::SeqCst);
    let mut unbalanced = 0;
    for k in cycles {
        let held = HELD.load(Ordering::SeqCst);
        cycle(api, me, info, k);
        if leak_every.is_some_and(|n| k.is_multiple_of(n)) {
            std::hint::black_box(Box::leak(Box::new([0u8; 64])));
        }
        unbalanced += usize::from(HELD.load(Ordering::SeqCst) != held);
    }
    (HELD.load(Ordering::SeqCst) - before, unbalanced)
}

/// Less than one 64-byte block over the 9,000 measured cycles: a 64-byte leak in any kind of
/// cycle (the all-effects ones are one in a hundred) fails, and so does a cache that keeps
/// growing after the warm-up.
const GROWTH_LIMIT: isize = 64;

// Minutes of CPU (the motor's Co-Simulation steps dominate): `make load`, not `make test`.
#[test]
#[ignore]
fn ten_thousand_cycles_of_every_fmu_do_not_grow_the_heap() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let (api, me) = (Api::linked(), MeApi::linked());
    const WARM_UP: usize = 1000;
    const CYCLES: usize = 10_000;
    // The positive control: the count sees a 64-byte leak in one cycle in a hundred.
    let pass_through = info_of("PassThrough");
    (0..WARM_UP).for_each(|k| cycle(&api, &me, pass_through, k));
    let (leaked, _) = heap_growth(&api, &me, pass_through, 1000..2000, Some(100));
    assert_eq!(leaked, 10 * 64, "the counter missed a deliberate leak");
    assert!(leaked >= GROWTH_LIMIT);
    for info in models() {
        let t0 = std::time::Instant::now();
        // Warm-up: lazily initialized tables and the log's buffers reach their steady size.
        (0..WARM_UP).for_each(|k| cycle(&api, &me, info, k));
        let (grown, unbalanced) = heap_growth(&api, &me, info, WARM_UP..CYCLES, None);
        let per_cycle = grown as f64 / (CYCLES - WARM_UP) as f64;
        println!(
            "{}: {CYCLES} cycles (CS + ME) in {:.1?}, heap grew by {grown} bytes over the last {} \
             ({per_cycle:.3} bytes per cycle); {unbalanced} of them did not free all they allocated",
            info.name,
            t0.elapsed(),
            CYCLES - WARM_UP
        );
        assert!(
            grown < GROWTH_LIMIT,
            "{}: the heap grew by {grown} bytes ({per_cycle} per cycle)",
            info.name
        );
    }
}

#[test]
fn a_hundred_live_instances_do_not_interfere() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    for info in models() {
        let (api, _) = packaged(info);
        let steps = 10;
        let live: Vec<_> = (0..100).map(|_| ready(api, info, true)).collect();
        // Interleaved: step n of every instance before step n + 1 of any.
        let mut interleaved = vec![Vec::new(); live.len()];
        for n in 0..steps {
            for (k, i) in live.iter().enumerate() {
                interleaved[k].extend(step_and_read(i, info, k, n));
            }
        }
        for (k, got) in interleaved.iter().enumerate().step_by(7) {
            assert_eq!(*got, run(api, info, k, steps), "{} instance {k}", info.name);
        }
    }
}

#[test]
fn eight_threads_in_lockstep_match_serial_runs() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    const THREADS: usize = 8;
    let steps = 100;
    for info in models() {
        let (api, _) = packaged(info);
        let serial: Vec<_> = (0..THREADS).map(|k| run(api, info, k, steps)).collect();
        // Every thread steps its own instance; a barrier before each step makes the eight
        // threads run step n at the same time, so the runs truly interleave.
        let barrier = Barrier::new(THREADS);
        let threaded: Vec<_> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..THREADS)
                .map(|k| {
                    let barrier = &barrier;
                    s.spawn(move || {
                        let i = ready(api, info, true);
                        (0..steps)
                            .flat_map(|n| {
                                barrier.wait();
                                step_and_read(&i, info, k, n)
                            })
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (k, got) in threaded.iter().enumerate() {
            assert_eq!(*got, serial[k], "{} thread {k}", info.name);
        }
        // Different runs differ: the comparison is not between constants.
        assert_ne!(serial[0], serial[1], "{}", info.name);
    }
}

/// As above through Model Exchange: states, events, directional derivatives and FMU states.
#[test]
fn eight_threads_in_lockstep_through_model_exchange_match_serial_runs() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    const THREADS: usize = 8;
    let steps = 40;
    for info in models() {
        let (api, me) = packaged(info);
        let serial: Vec<_> = (0..THREADS)
            .map(|k| me_run(api, me, info, true, k, steps).values)
            .collect();
        let barrier = Barrier::new(THREADS);
        let threaded: Vec<_> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..THREADS)
                .map(|k| {
                    let barrier = &barrier;
                    s.spawn(move || {
                        me_run_with(api, me, info, true, k, steps, &|_| {
                            barrier.wait();
                        })
                        .values
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (k, got) in threaded.iter().enumerate() {
            assert_eq!(*got, serial[k], "{} thread {k}", info.name);
        }
        assert_ne!(serial[0], serial[1], "{}", info.name);
    }
}
