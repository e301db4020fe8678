//! What the call sequence and restored FMU states may not do, on every FMU through its C ABI:
//! a step whose end overflows, a second fmi2FreeInstance, a resealed state whose machine state,
//! clocks or outputs no run produces.

use crate::common;
use crate::exercise;

use common::*;
use exercise::*;
use std::ffi::c_char;
use std::ptr::null_mut;

/// A step from the largest clock a double holds: its end overflows to +inf, refused with the
/// reason; the last successful time stays finite.
#[test]
fn a_step_whose_end_overflows_is_refused() {
    for info in models() {
        let api = Api::load(&extract_binary(info.name));
        let i = api
            .instantiate("overflow", info.guid)
            .unwrap_or_else(|log| panic!("{:?}", log.lines()));
        let t0 = 1e308;
        unsafe {
            assert_eq!((api.fmi2SetupExperiment)(i.c, 0, 0.0, t0, 0, 0.0), OK);
        }
        assert_eq!(i.enter(), OK);
        assert_eq!(i.exit(), OK, "{}: {:?}", info.name, i.log.lines());
        i.log.clear();
        assert_eq!(i.do_step(t0, 1e308), ERROR, "{}", info.name);
        assert!(
            i.log.contains("overflows to inf"),
            "{}: {:?}",
            info.name,
            i.log.lines()
        );
        let mut last = 0.0;
        unsafe { (api.fmi2GetRealStatus)(i.c, 2, &mut last) };
        assert_eq!(last, t0, "{}", info.name);
    }
}

/// A second fmi2FreeInstance of a handle whose slot another instance took meanwhile frees
/// nothing: the new instance runs on.
#[test]
fn a_double_free_never_frees_the_next_instance() {
    let info = info_of("McKibbenMuscle");
    let api = Api::load(&extract_binary(info.name));
    let first = api
        .instantiate("first", info.guid)
        .unwrap_or_else(|log| panic!("{:?}", log.lines()));
    let stale = first.c;
    drop(first);
    let second = api
        .instantiate("second", info.guid)
        .unwrap_or_else(|log| panic!("{:?}", log.lines()));
    for _ in 0..3 {
        unsafe { (api.fmi2FreeInstance)(stale) };
        assert_eq!(unsafe { (api.fmi2Reset)(stale) }, ERROR);
    }
    second.initialize();
    assert_eq!(second.do_step(0.0, 1e-3), OK);
    assert!(second.real(2).is_finite());
}

/// Where the fields after the GUID start in a serialized state: the time, the start time, the
/// stop time (an option) and the machine state (postcard: a varint index).
fn clock_offset(bytes: &[c_char], guid: &str) -> usize {
    let bytes: Vec<u8> = bytes.iter().map(|&b| b as u8).collect();
    let at = bytes
        .windows(guid.len())
        .position(|w| w == guid.as_bytes())
        .expect("the GUID is in the state");
    at + guid.len()
}

fn write_f64(bytes: &mut [c_char], at: usize, x: f64) {
    for (j, b) in x.to_le_bytes().iter().enumerate() {
        bytes[at + j] = *b as c_char;
    }
}

fn deserialize(i: &Instance, bytes: &[c_char]) -> (i32, *mut std::ffi::c_void) {
    let mut s = null_mut();
    let st = unsafe { (i.api.fmi2DeSerializeFMUstate)(i.c, bytes.as_ptr(), bytes.len(), &mut s) };
    (st, s)
}

/// The machine state Fatal and clocks out of order (time before the start, after the stop, a
/// stop before the start), resealed, are refused with the reason.
#[test]
fn impossible_machine_states_and_clocks_are_refused() {
    for info in models() {
        let api = Api::load(&extract_binary(info.name));
        let i = ready(&api, info, false);
        for n in 0..2 {
            step_and_read(&i, info, 0, n);
        }
        let good = serialized_state(&i);
        let at = clock_offset(&good, info.guid);
        let time = f64::from_le_bytes(std::array::from_fn(|j| good[at + j] as u8));
        assert!(
            time > 0.0,
            "{}: the time field is not where it should be",
            info.name
        );
        // No stop time was set up: the option's tag is 0, the machine state follows it.
        assert_eq!(good[at + 16], 0, "{}", info.name);
        let machine = at + 17;
        let cases: Vec<(&str, Vec<c_char>, &str)> = vec![
            (
                "Fatal",
                {
                    let mut b = good.clone();
                    b[machine] = 6;
                    b
                },
                "machine state Fatal",
            ),
            (
                "time before start",
                {
                    let mut b = good.clone();
                    write_f64(&mut b, at, -1.0);
                    b
                },
                "startTime <= time",
            ),
            (
                "start after time",
                {
                    let mut b = good.clone();
                    write_f64(&mut b, at + 8, 2.0 * time);
                    b
                },
                "startTime <= time",
            ),
        ];
        for (what, mut bytes, reason) in cases {
            reseal(&mut bytes);
            i.log.clear();
            let (st, s) = deserialize(&i, &bytes);
            assert_eq!(st, ERROR, "{}: {what} accepted", info.name);
            assert!(s.is_null());
            assert!(
                i.log.contains(reason),
                "{}: {what}: {:?}",
                info.name,
                i.log.lines()
            );
        }
        let (st, mut s) = deserialize(&i, &{
            let mut b = good.clone();
            reseal(&mut b);
            b
        });
        assert_eq!(st, OK, "{}: {:?}", info.name, i.log.lines());
        unsafe { (api.fmi2FreeFMUstate)(i.c, &mut s) };
    }
}

/// Every Real output whose value occurs once in a serialized state, replaced there by 1.2345e300
/// and resealed: the restored instance hands out the output its inputs and history give, bit for
/// bit the one saved, never the forged number.
#[test]
fn restored_outputs_are_recomputed_not_trusted() {
    let forged = 1.2345e300;
    let mut checked = 0;
    for info in models() {
        let api = Api::load(&extract_binary(info.name));
        let i = ready(&api, info, true);
        for n in 0..3 {
            step_and_read(&i, info, 1, n);
        }
        let outputs: Vec<u32> = info
            .variables
            .iter()
            .filter(|v| {
                v.causality == actuator_fmus::variables::Causality::Output
                    && v.kind == actuator_fmus::variables::VarType::Real
            })
            .map(|v| v.vr)
            .collect();
        let (st, before) = i.get_real(&outputs);
        assert!(st <= WARNING);
        let good = serialized_state(&i);
        for (&vr, &x) in outputs.iter().zip(&before) {
            let pattern = x.to_le_bytes().map(|b| b as c_char);
            let hits: Vec<usize> = (0..good.len() - 8)
                .filter(|&k| good[k..k + 8] == pattern)
                .collect();
            if hits.len() != 1 || x == 0.0 {
                continue;
            }
            let mut bytes = good.clone();
            write_f64(&mut bytes, hits[0], forged);
            reseal(&mut bytes);
            i.log.clear();
            let (st, mut s) = deserialize(&i, &bytes);
            if st != OK {
                // A copy the model also keeps as history and checks: refused with a reason.
                assert!(i.log.contains("fmi2DeSerializeFMUstate"), "{}", info.name);
                continue;
            }
            unsafe {
                assert_eq!((api.fmi2SetFMUstate)(i.c, s), OK, "{}", info.name);
                (api.fmi2FreeFMUstate)(i.c, &mut s);
            }
            let (st, after) = i.get_real(&outputs);
            assert!(st <= WARNING, "{}: {:?}", info.name, i.log.lines());
            for ((&vr2, &b), &a) in outputs.iter().zip(&before).zip(&after) {
                assert_eq!(
                    b.to_bits(),
                    a.to_bits(),
                    "{}: output {vr2} after forging output {vr}: {b} saved, {a} restored",
                    info.name
                );
            }
            checked += 1;
        }
    }
    println!("{checked} forged outputs recomputed");
    assert!(checked >= 7, "only {checked} outputs could be forged");
}
