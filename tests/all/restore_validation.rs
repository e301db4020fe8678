//! A restored FMU state is a valid model or a refusal with a logged reason: bytes changed and
//! then resealed (a valid checksum) must never reach the physics as an impossible model.
//!
//! Regression: a KnittedMuscle state whose cached `min_length` was made larger than its
//! `max_length` and resealed used to deserialize, and the next `fmi2DoStep` panicked in
//! `f64::clamp` and returned fmi2Fatal (found by `make fuzz SANITIZER=none`).

use crate::common;
use crate::exercise;

use common::*;
use exercise::*;
use std::ffi::c_char;
use std::ptr::null_mut;

/// Deserializes `bytes` into `i`; if accepted, restores, steps and reads every Real. Returns the
/// deserialization status. Never fmi2Fatal; a refusal is logged; an accepted state gives finite
/// outputs whenever a call returns OK or Warning.
fn restore_and_step(
    i: &Instance,
    info: &actuator_fmus::variables::ModelInfo,
    bytes: &[c_char],
) -> i32 {
    let api = i.api;
    i.log.clear();
    let mut s = null_mut();
    let st = unsafe { (api.fmi2DeSerializeFMUstate)(i.c, bytes.as_ptr(), bytes.len(), &mut s) };
    assert!(
        st == OK || st == ERROR,
        "{}: deserialize returned {st}",
        info.name
    );
    if st != OK {
        assert!(s.is_null());
        assert!(
            i.log.contains("fmi2DeSerializeFMUstate"),
            "{}: refused without a reason: {:?}",
            info.name,
            i.log.lines()
        );
        return st;
    }
    unsafe {
        let set = (api.fmi2SetFMUstate)(i.c, s);
        assert_ne!(set, FATAL, "{}: {:?}", info.name, i.log.lines());
        let mut t = 0.0;
        (api.fmi2GetRealStatus)(i.c, 2, &mut t);
        let step = i.do_step(t, step_of(info));
        assert_ne!(step, FATAL, "{}: {:?}", info.name, i.log.lines());
        let (got, values) = i.get_real(&all_reals(info));
        assert_ne!(got, FATAL);
        if got <= WARNING {
            assert!(
                values.iter().all(|x| x.is_finite()),
                "{}: {values:?}",
                info.name
            );
        }
        assert_eq!((api.fmi2FreeFMUstate)(i.c, &mut s), OK);
        // An Error ends the instance's run: back to a fresh one for the next trial.
        if set >= ERROR || step >= ERROR || got >= ERROR {
            assert_eq!((api.fmi2Reset)(i.c), OK);
            i.initialize();
        }
    }
    st
}

#[test]
fn knitted_min_length_above_max_length_resealed_is_refused() {
    let info = info_of("KnittedMuscle");
    let api = Api::load(&extract_binary(info.name));
    let i = ready(&api, info, true);
    for n in 0..3 {
        step_and_read(&i, info, 0, n);
    }
    let vr = |name: &str| info.variables.iter().find(|v| v.name == name).unwrap().vr;
    let (min, max) = (i.real(vr("min_length")), i.real(vr("max_length")));
    let good = serialized_state(&i);
    let replace_all = |from: f64, to: f64| {
        let mut b = good.clone();
        let (from, to) = (from.to_le_bytes().map(|x| x as c_char), to.to_le_bytes());
        let mut count = 0;
        for k in 0..b.len() - 7 {
            if b[k..k + 8] == from {
                for (j, x) in to.iter().enumerate() {
                    b[k + j] = *x as c_char;
                }
                count += 1;
            }
        }
        assert!(count >= 2, "min_length occurs {count} times");
        reseal(&mut b);
        b
    };
    // Every copy (the calculated parameter and the model's caches): the parameters no longer
    // give the stored value, refused.
    let crafted = replace_all(min, 2.0 * max);
    assert_eq!(restore_and_step(&i, info, &crafted), ERROR);
    assert!(
        i.log
            .contains("corrupt model state: its calculated parameters"),
        "{:?}",
        i.log.lines()
    );
    // The uncorrupted state still restores.
    assert_eq!(restore_and_step(&i, info, &good), OK);
}

/// Every FMU with all effects on: at every byte offset of its serialized state, one of a NaN, an
/// infinity, a huge, a negative or a small number written there and resealed is refused with a reason or
/// gives a model that steps without fmi2Fatal and with finite outputs.
#[test]
fn resealed_corruptions_of_every_fmu_are_refused_or_valid() {
    for info in models() {
        let api = Api::load(&extract_binary(info.name));
        let i = ready(&api, info, true);
        for n in 0..3 {
            step_and_read(&i, info, 1, n);
        }
        let good = serialized_state(&i);
        let (mut refused, mut accepted) = (0, 0);
        // Past the 10-byte header, before the checksum; every byte offset (postcard packs the
        // fields without alignment).
        for at in 10..good.len() - 16 {
            // One value per offset, in turn: each field is hit by each kind of value through
            // the offsets that overlap it.
            {
                let x = [f64::NAN, f64::INFINITY, -1e300, 1e300, -1.0, 2.5e-3][at % 6];
                let mut b = good.clone();
                for (j, byte) in x.to_le_bytes().iter().enumerate() {
                    b[at + j] = *byte as c_char;
                }
                reseal(&mut b);
                if restore_and_step(&i, info, &b) == OK {
                    accepted += 1;
                } else {
                    refused += 1;
                }
            }
        }
        println!(
            "{}: {} bytes, {refused} crafted states refused, {accepted} accepted and valid",
            info.name,
            good.len()
        );
        assert!(refused > 0 && accepted > 0, "{}", info.name);
    }
}
