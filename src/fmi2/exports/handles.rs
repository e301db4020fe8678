//! The `fmi2Component` an importer holds is a handle, not the instance's address: a slot of a
//! fixed table and a generation number that no other instance of this process ever gets. A freed
//! instance's handle (a second `fmi2FreeInstance`, any call after the first) finds its slot
//! empty or re-used under another generation and is refused without reading freed memory; it
//! can never reach an instance allocated later at the same address, or in the same slot. A
//! handle off by a few bytes, or any other value, names no live generation and is refused too.
//!
//! The table is static (`SLOTS` instances alive at once; 16 bytes each, in pages touched only when
//! used); handles are 64-bit (the slot in the low 16 bits, the generation above).

use crate::fmi2::instance::Instance;
use crate::fmi2::types::fmi2Component;
use std::sync::atomic::{AtomicPtr, AtomicU64, Ordering};
use std::sync::Mutex;

#[cfg(not(target_pointer_width = "64"))]
compile_error!("instance handles are 64-bit: a slot in the low 16 bits, the generation above");

const SLOT_BITS: u32 = 16;
/// How many instances may be alive at once in one process.
pub(crate) const SLOTS: usize = 1 << SLOT_BITS;

struct Slot {
    /// The generation of the instance in the slot; 0 while empty.
    generation: AtomicU64,
    instance: AtomicPtr<Instance>,
}

static TABLE: [Slot; SLOTS] = [const {
    Slot {
        generation: AtomicU64::new(0),
        instance: AtomicPtr::new(std::ptr::null_mut()),
    }
}; SLOTS];

/// Generations are never re-used: at a million instances a second they last 8 years.
static NEXT_GENERATION: AtomicU64 = AtomicU64::new(1);

/// Slots never used yet start at `.0`; freed ones are in `.1`.
static FREE: Mutex<(usize, Vec<usize>)> = Mutex::new((0, Vec::new()));

fn split(c: fmi2Component) -> (usize, u64) {
    let handle = c.addr();
    (handle & (SLOTS - 1), (handle >> SLOT_BITS) as u64)
}

/// A handle for `instance`, which the table owns from now on; `None` (the instance dropped) when
/// `SLOTS` instances are alive.
pub(crate) fn register(instance: Box<Instance>) -> Option<fmi2Component> {
    let index = {
        let mut free = FREE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        match free.1.pop() {
            Some(index) => index,
            None if free.0 < SLOTS => {
                free.0 += 1;
                free.0 - 1
            }
            None => return None,
        }
    };
    let generation = NEXT_GENERATION.fetch_add(1, Ordering::Relaxed);
    let slot = &TABLE[index];
    slot.instance
        .store(Box::into_raw(instance), Ordering::Release);
    slot.generation.store(generation, Ordering::Release);
    Some(std::ptr::without_provenance_mut(
        (generation as usize) << SLOT_BITS | index,
    ))
}

/// The live instance behind handle `c`, if any.
#[inline(always)]
pub(crate) fn resolve(c: fmi2Component) -> Option<*mut Instance> {
    let (index, generation) = split(c);
    let slot = &TABLE[index];
    if generation == 0 || slot.generation.load(Ordering::Acquire) != generation {
        return None;
    }
    let ptr = slot.instance.load(Ordering::Acquire);
    (!ptr.is_null()).then_some(ptr)
}

/// Takes the instance behind `c` out of the table, once: a second call with the same handle
/// gets `None`, even from another thread at the same time.
pub(crate) fn release(c: fmi2Component) -> Option<Box<Instance>> {
    let (index, generation) = split(c);
    let slot = &TABLE[index];
    if generation == 0 {
        return None;
    }
    slot.generation
        .compare_exchange(generation, 0, Ordering::AcqRel, Ordering::Acquire)
        .ok()?;
    let ptr = slot.instance.swap(std::ptr::null_mut(), Ordering::AcqRel);
    FREE.lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
        .1
        .push(index);
    // SAFETY: the pointer came from Box::into_raw in `register`, and only the one caller that
    // emptied the slot's generation takes it.
    (!ptr.is_null()).then(|| unsafe { Box::from_raw(ptr) })
}
