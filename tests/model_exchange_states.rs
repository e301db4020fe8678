//! Model Exchange with continuous states through the C ABI of the crate linked into this test:
//! the integrator's hot path (`fmi2SetTime`, `fmi2SetContinuousStates`, `fmi2GetDerivatives`)
//! allocates nothing (counted by this binary's global allocator), and an explicit Euler
//! integration of PulleyJoint's states through it follows the joint's ODE.

mod common;

use common::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::c_int;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Counts allocation calls (not bytes) on the thread that switched counting on: the hot path must
/// make none. Other threads (the test harness's own) allocate when they like, so they are not
/// counted.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    // `try_with`: the allocator also runs while thread-locals are torn down.
    if COUNTING.try_with(Cell::get).unwrap_or(false) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        unsafe { System.dealloc(p, layout) }
    }
    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// `fmi2EventInfo`.
#[repr(C)]
#[derive(Default, Debug)]
struct EventInfo {
    new_discrete_states_needed: c_int,
    terminate_simulation: c_int,
    nominals_changed: c_int,
    values_changed: c_int,
    next_event_time_defined: c_int,
    next_event_time: f64,
}

// The Model Exchange functions of the crate linked into this test.
extern "C" {
    fn fmi2NewDiscreteStates(c: Component, info: *mut EventInfo) -> c_int;
    fn fmi2EnterContinuousTimeMode(c: Component) -> c_int;
    fn fmi2SetTime(c: Component, time: f64) -> c_int;
    fn fmi2SetContinuousStates(c: Component, x: *const f64, nx: usize) -> c_int;
    fn fmi2GetContinuousStates(c: Component, x: *mut f64, nx: usize) -> c_int;
    fn fmi2GetDerivatives(c: Component, dx: *mut f64, nx: usize) -> c_int;
    fn fmi2CompletedIntegratorStep(
        c: Component,
        no_set_prior: c_int,
        enter_event_mode: *mut c_int,
        terminate: *mut c_int,
    ) -> c_int;
}

#[test]
fn the_integrators_hot_path_allocates_nothing_and_integrates_the_joint_ode() {
    use actuator_fmus::variables::pulley_joint::{real, INFO};
    let api = Api::linked();
    let i = api
        .instantiate_as("me", INFO.guid, 0)
        .unwrap_or_else(|log| panic!("{:?}", log.lines()));
    i.initialize();
    // Constant forces: 10 N flexor, 5 N extensor (torque 0.075 N m against the gravity load).
    assert_eq!(
        i.set_real(
            &[real::FLEXOR_FORCE as u32, real::EXTENSOR_FORCE as u32],
            &[10.0, 5.0]
        ),
        OK
    );
    let mut info = EventInfo::default();
    unsafe {
        assert_eq!(fmi2NewDiscreteStates(i.c, &mut info), OK);
        assert_eq!(fmi2EnterContinuousTimeMode(i.c), OK);
    }
    assert_eq!(
        (info.next_event_time_defined, info.next_event_time),
        (1, 1.0)
    );
    let (mut x, mut dx) = ([0.0; 2], [0.0; 2]);
    let (h, steps) = (1e-4, 5000);
    // Warm-up: the first calls may size the log's buffers.
    unsafe {
        assert_eq!(fmi2GetDerivatives(i.c, dx.as_mut_ptr(), 2), OK);
    }
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    COUNTING.with(|c| c.set(true));
    let (mut q, mut dq) = (0.0f64, 0.0f64);
    for n in 0..steps {
        unsafe {
            assert_eq!(fmi2SetTime(i.c, n as f64 * h), OK);
            assert_eq!(fmi2SetContinuousStates(i.c, x.as_ptr(), 2), OK);
            assert_eq!(fmi2GetDerivatives(i.c, dx.as_mut_ptr(), 2), OK);
        }
        x[0] += h * dx[0];
        x[1] += h * dx[1];
        // The ODE by hand, with PulleyJoint's default parameters (r 0.015 m, I 0.004 kg m2,
        // c 0.05 N m s, m g l = 0.25 x 9.81 x 0.12 N m).
        let ddq = (0.015 * 5.0 - 0.05 * dq - 0.25 * 9.81 * 0.12 * q.sin()) / 0.004;
        q += h * dq;
        dq += h * ddq;
    }
    COUNTING.with(|c| c.set(false));
    let allocations = ALLOCATIONS.load(Ordering::SeqCst) - before;
    assert_eq!(
        allocations, 0,
        "{allocations} allocations in {steps} right-hand sides"
    );
    assert!(
        (x[0] - q).abs() <= 1e-12 && (x[1] - dq).abs() <= 1e-12,
        "{x:?} vs {q}, {dq}"
    );
    // The joint has swung towards its equilibrium sin q = 0.075 / (m g l) = 0.255.
    assert!(x[0] > 0.1, "{x:?}");
    let mut back = [0.0; 2];
    let (mut enter, mut terminate) = (1, 1);
    unsafe {
        assert_eq!(fmi2GetContinuousStates(i.c, back.as_mut_ptr(), 2), OK);
        assert_eq!(
            fmi2CompletedIntegratorStep(i.c, 1, &mut enter, &mut terminate),
            OK
        );
    }
    assert_eq!((enter, terminate), (0, 0));
    // The states the importer set last (x before its final update), and the outputs follow them.
    assert_eq!(back[1], x[1] - h * dx[1]);
    assert_eq!(i.real(real::JOINT_VELOCITY as u32), back[1]);
}
