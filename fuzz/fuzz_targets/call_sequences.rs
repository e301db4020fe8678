//! libFuzzer entry point: the logic is in `tests/fuzz_driver/call_sequences.rs`, which
//! `tests/all/fuzz_corpus.rs` also runs over the committed corpus in `make test`.
#![no_main]

#[path = "../../tests/fuzz_driver/call_sequences.rs"]
mod driver;

use libfuzzer_sys::fuzz_target;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Total calls made, for the report of a `make fuzz` run.
static CALLS: AtomicUsize = AtomicUsize::new(0);

fuzz_target!(|data: &[u8]| {
    let calls = driver::run(data);
    let total = CALLS.fetch_add(calls, Ordering::Relaxed) + calls;
    if total / 1_000_000 != (total - calls) / 1_000_000 {
        eprintln!("call_sequences: {total} FMI calls so far");
    }
});
