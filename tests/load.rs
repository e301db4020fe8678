//! Load through the C ABI of all six FMUs: 10,000 instantiate/step/state/free
//! cycles each whose heap does not grow (counted by this binary's global allocator, exact to the
//! byte), 100 live instances that do not interfere, and eight threads stepping in lockstep whose
//! results are bit-identical to the same runs done serially.

mod common;
#[path = "common/exercise.rs"]
mod exercise;

use actuator_fmus::variables::ModelInfo;
use common::*;
use exercise::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::ptr::null_mut;
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

fn packaged(info: &ModelInfo) -> &'static Api {
    static APIS: OnceLock<Vec<(&'static str, Api)>> = OnceLock::new();
    let apis = APIS.get_or_init(|| {
        models()
            .into_iter()
            .map(|i| (i.name, Api::load(&extract_binary(i.name))))
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

/// One cycle: instantiate (all effects on every hundredth cycle: their builds and steps cost most),
/// initialize, step, a serialized state restored
/// and freed, a state left for fmi2FreeInstance, every Real read, free.
fn cycle(api: &Api, info: &ModelInfo, k: usize) {
    let i = ready(api, info, k.is_multiple_of(100));
    step_and_read(&i, info, k, 0);
    let bytes = serialized_state(&i);
    unsafe {
        let mut s = null_mut();
        assert_eq!(
            (api.fmi2DeSerializeFMUstate)(i.c, bytes.as_ptr(), bytes.len(), &mut s),
            OK
        );
        assert_eq!((api.fmi2SetFMUstate)(i.c, s), OK);
        assert_eq!((api.fmi2FreeFMUstate)(i.c, &mut s), OK);
        // An FMU state left to fmi2FreeInstance must be freed with the instance.
        let mut kept = null_mut();
        assert_eq!((api.fmi2GetFMUstate)(i.c, &mut kept), OK);
    }
    step_and_read(&i, info, k, 1);
}

// Minutes of CPU (the motor's steps dominate): `make load`, not `make test`.
#[test]
#[ignore]
fn ten_thousand_cycles_of_every_fmu_do_not_grow_the_heap() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let api = Api::linked();
    const WARM_UP: usize = 1000;
    const CYCLES: usize = 10_000;
    for info in models() {
        // Warm-up: lazily initialized tables and the log's buffers reach their steady size.
        (0..WARM_UP).for_each(|k| cycle(&api, info, k));
        let before = HELD.load(Ordering::SeqCst);
        (WARM_UP..CYCLES).for_each(|k| cycle(&api, info, k));
        let grown = HELD.load(Ordering::SeqCst) - before;
        let per_cycle = grown as f64 / (CYCLES - WARM_UP) as f64;
        println!(
            "{}: {CYCLES} cycles, heap grew by {grown} bytes over the last {} ({per_cycle:.3} bytes per cycle)",
            info.name,
            CYCLES - WARM_UP
        );
        // A leak of 32 bytes per cycle (less than any Box this FMU allocates) would be 288,000.
        assert!(
            per_cycle < 32.0,
            "{}: the heap grew by {grown} bytes ({per_cycle} per cycle)",
            info.name
        );
    }
}

#[test]
fn a_hundred_live_instances_do_not_interfere() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    for info in models() {
        let api = packaged(info);
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
        let api = packaged(info);
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
