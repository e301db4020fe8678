//! The packaged McKibbenMuscle binary driven through its C ABI: call order, bad arguments, logging,
//! FMU state, threads. Every refusal must come with a logged reason and a non-OK status.

use crate::common;
use approx::assert_relative_eq;

use common::mckibben::*;
use common::*;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::OnceLock;

const MODEL: &str = "McKibbenMuscle";
/// Table 2.1, muscle A: the start values of the model description.
const B: f64 = 0.1113;
const N: f64 = 3.74;

fn api() -> &'static Api {
    static API: OnceLock<Api> = OnceLock::new();
    API.get_or_init(|| Api::load(&extract_binary(MODEL)))
}

fn instance() -> Instance<'static> {
    api()
        .instantiate("muscle", &guid_of(MODEL))
        .unwrap_or_else(|log| panic!("refused: {:?}", log.lines()))
}

fn ready() -> Instance<'static> {
    let i = instance();
    i.initialize();
    i
}

#[test]
fn platform_and_version() {
    unsafe {
        assert_eq!(
            CStr::from_ptr((api().fmi2GetTypesPlatform)()).to_str(),
            Ok("default")
        );
        assert_eq!(CStr::from_ptr((api().fmi2GetVersion)()).to_str(), Ok("2.0"));
    }
}

#[test]
fn wrong_guid_is_refused_with_a_reason() {
    let log = api()
        .instantiate("m", "{00000000-0000-0000-0000-000000000000}")
        .err()
        .expect("must refuse");
    assert!(
        log.contains("wrong GUID {00000000-0000-0000-0000-000000000000}"),
        "{:?}",
        log.lines()
    );
    assert!(
        log.lines()[0].starts_with("3 logStatusError"),
        "{:?}",
        log.lines()
    );
}

#[test]
fn percent_signs_never_reach_the_logger_as_directives() {
    // The message is the logger's format string: every '%' must come doubled.
    let log = api()
        .instantiate("m", "{%s%n%d}")
        .err()
        .expect("must refuse");
    let line = &log.lines()[0];
    assert!(line.contains("{%%s%%n%%d}"), "{line}");
}

#[test]
fn bad_instantiate_arguments_return_null() {
    let guid = CString::new(guid_of(MODEL)).unwrap();
    let name = CString::new("m").unwrap();
    unsafe {
        // No callbacks: nowhere to log, still no crash.
        let c = (api().fmi2Instantiate)(
            name.as_ptr(),
            1,
            guid.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
            0,
            0,
        );
        assert!(c.is_null());
    }
    let log = api()
        .instantiate("", &guid_of(MODEL))
        .err()
        .expect("empty name refused");
    assert!(log.contains("instanceName must be a non-empty string"));
}

#[test]
fn model_exchange_is_accepted_and_other_types_refused() {
    assert!(api().instantiate_as("m", &guid_of(MODEL), 0).is_ok());
    let log = api()
        .instantiate_as("m", &guid_of(MODEL), 2)
        .err()
        .expect("not an fmi2Type");
    assert!(
        log.contains("fmuType 2 is not supported: not an fmi2Type"),
        "{:?}",
        log.lines()
    );
}

#[test]
fn illegal_call_order_is_refused_and_logged() {
    let i = instance();
    assert_eq!(i.do_step(0.0, 0.1), ERROR);
    assert!(
        i.log
            .contains("fmi2DoStep: illegal call in state Instantiated"),
        "{:?}",
        i.log.lines()
    );
    assert_eq!(i.exit(), ERROR);
    assert!(i
        .log
        .contains("fmi2ExitInitializationMode: illegal call in state Instantiated"));
    assert_eq!(i.get_real(&[FORCE]).0, ERROR);
    assert!(i
        .log
        .contains("fmi2GetReal: illegal call in state Instantiated"));
    assert_eq!(unsafe { (api().fmi2Terminate)(i.c) }, ERROR);
    i.initialize();
    assert_eq!(i.enter(), ERROR);
    assert!(i
        .log
        .contains("fmi2EnterInitializationMode: illegal call in state StepComplete"));
    assert_eq!(i.setup(), ERROR);
    // Still usable after refused calls.
    assert_eq!(i.do_step(0.0, 0.1), OK);
    assert_eq!(unsafe { (api().fmi2Terminate)(i.c) }, OK);
    assert_eq!(i.do_step(0.1, 0.1), ERROR);
    assert!(i
        .log
        .contains("fmi2DoStep: illegal call in state Terminated"));
    assert_eq!(unsafe { (api().fmi2Reset)(i.c) }, OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, 0.1), OK);
}

#[test]
fn variables_are_settable_only_when_fmi_allows() {
    let i = instance();
    assert_eq!(
        i.set_real(&[FORCE], &[1.0]),
        ERROR,
        "an output is never set"
    );
    assert!(i
        .log
        .contains("force (Output, Continuous) cannot be set in state Instantiated"));
    assert_eq!(
        i.set_real(&[MAX_LENGTH], &[1.0]),
        ERROR,
        "a calculated parameter is never set"
    );
    assert_eq!(i.set_real(&[STRAND_LENGTH], &[0.12]), OK);
    i.initialize();
    assert_eq!(
        i.set_real(&[STRAND_LENGTH], &[0.13]),
        ERROR,
        "fixed parameters are fixed after initialization"
    );
    assert!(i
        .log
        .contains("strand_length (Parameter, Fixed) cannot be set in state StepComplete"));
    assert_eq!(i.real(STRAND_LENGTH), 0.12);
    assert_eq!(i.real(MAX_LENGTH), 0.12, "ideal sleeve reaches L = b");
    assert_eq!(
        i.set_real(&[PRESSURE], &[1e5]),
        OK,
        "inputs are set between steps"
    );
}

#[test]
fn unknown_value_references_and_null_arrays_are_refused() {
    let i = ready();
    assert_eq!(i.get_real(&[99]).0, ERROR);
    assert!(i
        .log
        .contains("99 is not the value reference of a Real variable of McKibbenMuscle"));
    assert_eq!(i.set_real(&[7], &[0.0]), ERROR);
    unsafe {
        assert_eq!(
            (api().fmi2GetReal)(i.c, std::ptr::null(), 1, std::ptr::null_mut()),
            ERROR
        );
        assert!(i.log.contains("fmi2GetReal: vr and value must not be NULL"));
        assert_eq!(
            (api().fmi2SetReal)(i.c, std::ptr::null(), 2, std::ptr::null()),
            ERROR
        );
        // Zero-length arrays may be NULL.
        assert_eq!(
            (api().fmi2GetReal)(i.c, std::ptr::null(), 0, std::ptr::null_mut()),
            OK
        );
        let mut x = 0;
        assert_eq!(
            (api().fmi2GetInteger)(i.c, [99u32].as_ptr(), 1, &mut x),
            ERROR,
            "no Integer variable 99"
        );
        // A NULL instance cannot be logged about, but must not crash.
        assert_eq!((api().fmi2DoStep)(std::ptr::null_mut(), 0.0, 1.0, 0), ERROR);
        assert_eq!(
            (api().fmi2GetReal)(std::ptr::null_mut(), [0u32].as_ptr(), 1, [0.0].as_mut_ptr()),
            ERROR
        );
        (api().fmi2FreeInstance)(std::ptr::null_mut());
        let mut fake = [0u64; 64];
        assert_eq!(
            (api().fmi2Terminate)(fake.as_mut_ptr() as *mut c_void),
            ERROR,
            "not an instance of ours"
        );
    }
}

#[test]
fn non_finite_and_out_of_range_inputs_keep_the_old_value() {
    let i = ready();
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[2e5, 0.1]), OK);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(i.set_real(&[PRESSURE], &[bad]), ERROR);
        assert_eq!(i.real(PRESSURE), 2e5);
    }
    assert!(
        i.log
            .contains("fmi2SetReal: pressure = NaN is not finite; the value is kept"),
        "{:?}",
        i.log.lines()
    );
    // Below absolute vacuum.
    assert_eq!(i.set_real(&[PRESSURE], &[-2e5]), ERROR);
    assert!(i
        .log
        .contains("pressure = -200000 Pa is below its minimum -101325 Pa"));
    // All or nothing: a bad value anywhere leaves every value as it was.
    assert_eq!(i.set_real(&[LENGTH, PRESSURE], &[0.09, f64::NAN]), ERROR);
    assert_eq!(i.real(LENGTH), 0.1);
    assert_eq!(i.set_real(&[LENGTH], &[-0.01]), ERROR);
    assert!(i.real(FORCE).is_finite());
}

#[test]
fn force_follows_eq_2_3_through_the_c_abi() {
    let i = ready();
    let mut t = 0.0;
    for k in 0..20 {
        let l = 0.2 * B + 0.8 * B * k as f64 / 20.0;
        for p in [0.0, 1e5, 3.45e5, 6.9e5] {
            assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[p, l]), OK);
            assert_eq!(i.do_step(t, 1e-3), OK);
            t += 1e-3;
            let f = i.real(FORCE);
            let expected = gaylord_force(p, l, B, N);
            assert!(
                (f - expected).abs() <= 1e-12 * expected.abs().max(1e-3),
                "L={l} P={p}: {f} vs {expected}"
            );
            let v = (B * B * l - l * l * l) / (4.0 * std::f64::consts::PI * N * N);
            assert!((i.real(VOLUME) - v).abs() <= 1e-15, "eq. 2.2");
        }
    }
}

#[test]
fn outputs_follow_inputs_before_the_step() {
    // Direct feedthrough: a get after a set reflects the new inputs without a step.
    let i = ready();
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[5e5, 0.1]), OK);
    // Eq. 2.3, to rounding (the FMU groups its products differently).
    assert_relative_eq!(
        i.real(FORCE),
        gaylord_force(5e5, 0.1, B, N),
        max_relative = 1e-14
    );
}

#[test]
fn vacuum_leaves_the_sleeve_unloaded() {
    let i = ready();
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[-5e4, 0.1]), OK);
    assert_eq!(i.real(FORCE), 0.0);
}

#[test]
fn length_beyond_the_sleeve_is_clamped_flagged_and_logged_once_per_excursion() {
    let i = ready();
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[4e5, 0.2]), OK);
    let mut t = 0.0;
    for _ in 0..5 {
        // The default out-of-range policy: strict masters see fmi2OK.
        assert_eq!(i.do_step(t, 0.01), OK);
        t += 0.01;
        assert_relative_eq!(
            i.real(FORCE),
            gaylord_force(4e5, B, B, N),
            max_relative = 1e-14
        );
        assert_eq!(i.real(VOLUME), 0.0);
        assert!(i.boolean(INPUT_CLAMPED));
    }
    let explained = |i: &Instance| {
        i.log
            .lines()
            .iter()
            .filter(|l| l.contains("until the inputs return"))
            .count()
    };
    assert_eq!(explained(&i), 1, "{:?}", i.log.lines());
    assert_eq!(i.set_real(&[LENGTH], &[0.1]), OK);
    assert_eq!(i.do_step(t, 0.01), OK);
    assert!(!i.boolean(INPUT_CLAMPED));
    assert_eq!(i.set_real(&[LENGTH], &[0.3]), OK);
    assert_eq!(i.do_step(t + 0.01, 0.01), OK, "a new excursion");
    assert_eq!(explained(&i), 2);
}

#[test]
fn out_of_range_policy_restores_the_warning_or_discards_the_step() {
    for (policy, expected) in [(0, OK), (1, WARNING), (2, DISCARD)] {
        let i = instance();
        assert_eq!(i.setup(), OK);
        assert_eq!(i.enter(), OK);
        assert_eq!(i.set_integer(&[OUT_OF_RANGE_POLICY], &[policy]), OK);
        assert_eq!(i.exit(), OK);
        assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[4e5, 0.2]), OK);
        // Outside fmi2DoStep a discard means nothing: the getter warns instead.
        let (status, _) = i.get_real(&[FORCE]);
        assert_eq!(status, expected.min(WARNING), "policy {policy}");
        assert!(i.boolean(INPUT_CLAMPED));
        // The excursion was explained when it began, in the getter; the step's status other
        // than OK still comes with its reason (a fuzzed sequence found a bare fmi2Discard).
        let before = i.log.lines().len();
        assert_eq!(i.do_step(0.0, 0.01), expected, "policy {policy}");
        let after = i.log.lines();
        if expected != OK {
            assert!(
                after[before..]
                    .iter()
                    .any(|l| l.contains("fmi2DoStep") && l.contains("outside")),
                "policy {policy}: {after:?}"
            );
        }
    }
}

#[test]
fn bad_parameters_are_refused_and_reset_restores_start_values() {
    let i = instance();
    assert_eq!(i.set_real(&[TURNS], &[0.0]), ERROR);
    assert!(
        i.log.contains("turns = 0 is below its minimum 0.001"),
        "{:?}",
        i.log.lines()
    );
    assert_eq!(i.set_real(&[STRAND_LENGTH], &[0.2]), OK);
    i.initialize();
    assert_eq!(i.real(MAX_LENGTH), 0.2);
    assert_eq!(unsafe { (api().fmi2Reset)(i.c) }, OK);
    i.initialize();
    assert_eq!(i.real(MAX_LENGTH), B);
    assert_eq!(i.real(FORCE), gaylord_force(0.0, 0.09, B, N));
}

#[test]
fn communication_point_and_step_size_are_checked() {
    let i = ready();
    assert_eq!(i.do_step(0.0, 0.0), ERROR);
    assert!(i
        .log
        .contains("communicationStepSize = 0 must be positive and finite"));
    assert_eq!(i.do_step(0.0, -1.0), ERROR);
    assert_eq!(i.do_step(0.0, f64::NAN), ERROR);
    assert_eq!(i.do_step(0.5, 0.1), ERROR);
    assert!(i.log.contains("expected currentCommunicationPoint = 0.0000000000000000e0 but was 5.0000000000000000e-1"), "{:?}", i.log.lines());
    // A master that accumulates time by multiplication differs by rounding only: accepted.
    let mut t = 0.0;
    for k in 0..1000 {
        assert_eq!(i.do_step(t, 0.1), OK, "step {k}");
        t = (k + 1) as f64 * 0.1;
    }
    let mut last = 0.0;
    assert_eq!(unsafe { (api().fmi2GetRealStatus)(i.c, 2, &mut last) }, OK);
    assert!((last - 100.0).abs() < 1e-9);
    let mut terminated = 1;
    assert_eq!(
        unsafe { (api().fmi2GetBooleanStatus)(i.c, 3, &mut terminated) },
        OK
    );
    assert_eq!(terminated, 0);
    let mut x = 0;
    assert_eq!(
        unsafe { (api().fmi2GetStatus)(i.c, 0, &mut x) },
        DISCARD,
        "no asynchronous step to report on"
    );
}

#[test]
fn steps_may_not_pass_the_stop_time() {
    let i = instance();
    assert_eq!(
        unsafe { (api().fmi2SetupExperiment)(i.c, 0, 0.0, 0.0, 1, 1.0) },
        OK
    );
    assert_eq!(i.enter(), OK);
    assert_eq!(i.exit(), OK);
    assert_eq!(i.do_step(0.0, 0.75), OK);
    assert_eq!(i.do_step(0.75, 0.5), ERROR);
    assert!(i.log.contains("would pass the stop time"));
    assert_eq!(i.do_step(0.75, 0.25), OK);
}

/// A step takes our own clock (-0 for 0 too); a step whose end overflows is taken, after which
/// every step is refused.
#[test]
fn the_clock_is_ours_to_the_bit_and_never_overflows() {
    let i = ready();
    assert_eq!(i.do_step(-0.0, 0.5), OK);
    // 0.5 + MAX rounds to MAX: a finite end.
    assert_eq!(i.do_step(0.5, f64::MAX), OK);
    // MAX + MAX overflows: refused, the clock stays finite.
    assert_eq!(i.do_step(f64::MAX, f64::MAX), ERROR, "{:?}", i.log.lines());
    assert!(i.log.contains("overflows to inf"), "{:?}", i.log.lines());
    assert_eq!(i.do_step(f64::INFINITY, 1.0), ERROR);
    assert!(i.log.contains("expected currentCommunicationPoint"));
    assert_eq!(i.do_step(f64::MAX, 1.0), OK, "{:?}", i.log.lines());
}

#[test]
fn unsupported_functions_say_why() {
    let i = ready();
    unsafe {
        use std::ptr::{null, null_mut};
        assert_eq!(
            (api().fmi2SetRealInputDerivatives)(i.c, null(), 0, null(), null()),
            ERROR
        );
        assert_eq!(
            (api().fmi2GetRealOutputDerivatives)(i.c, null(), 0, null(), null_mut()),
            ERROR
        );
        assert_eq!((api().fmi2CancelStep)(i.c), ERROR);
    }
    assert!(i.log.contains("fmi2CancelStep: not supported"));
}

/// `fmi2GetDirectionalDerivative` over (pressure, length) -> (force, volume).
fn directional(i: &Instance, unknown: &[u32], known: &[u32], seed: &[f64]) -> (c_int, Vec<f64>) {
    let mut out = vec![f64::NAN; unknown.len()];
    let status = unsafe {
        (api().fmi2GetDirectionalDerivative)(
            i.c,
            unknown.as_ptr(),
            unknown.len(),
            known.as_ptr(),
            known.len(),
            seed.as_ptr(),
            out.as_mut_ptr(),
        )
    };
    (status, out)
}

#[test]
fn directional_derivatives_are_eq_2_3_differentiated() {
    let i = ready();
    let (p, l) = (3e5, 0.09);
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[p, l]), OK);
    // Eq. 2.3: dF/dP = (3 L^2 - b^2)/(4 pi n^2), dF/dL = 6 P L/(4 pi n^2); eq. 2.2: dV/dL.
    let k = 1.0 / (4.0 * std::f64::consts::PI * N * N);
    let (status, d) = directional(&i, &[FORCE, VOLUME], &[PRESSURE, LENGTH], &[1.0, 0.0]);
    assert_eq!(status, OK);
    assert!((d[0] - (3.0 * l * l - B * B) * k).abs() < 1e-15, "{d:?}");
    assert_eq!(d[1], 0.0);
    let (status, d) = directional(&i, &[FORCE, VOLUME], &[PRESSURE, LENGTH], &[0.0, 1.0]);
    assert_eq!(status, OK);
    assert!((d[0] - 6.0 * p * l * k).abs() < 1e-9 * d[0], "{d:?}");
    assert!((d[1] - (B * B - 3.0 * l * l) * k).abs() < 1e-15, "{d:?}");
    // A seed over both inputs is the sum (linearity); the order of the knowns does not matter.
    let (_, both) = directional(&i, &[FORCE], &[LENGTH, PRESSURE], &[2.0, 1e-3]);
    let expected = 2.0 * 6.0 * p * l * k + 1e-3 * (3.0 * l * l - B * B) * k;
    assert!(
        (both[0] - expected).abs() < 1e-12 * expected.abs(),
        "{both:?}"
    );
    // The stiffness 6 P L / (4 pi n^2) (eq. 2.3 differentiated in L) is bilinear in P and L.
    let (status, d) = directional(&i, &[STIFFNESS], &[PRESSURE, LENGTH], &[1.0, 0.0]);
    assert_eq!(status, OK);
    assert!((d[0] - 6.0 * l * k).abs() < 1e-12 * d[0], "{d:?}");
    let (status, d) = directional(&i, &[STIFFNESS], &[PRESSURE, LENGTH], &[0.0, 1.0]);
    assert_eq!(status, OK);
    assert!((d[0] - 6.0 * p * k).abs() < 1e-12 * d[0], "{d:?}");
}

#[test]
fn directional_derivatives_refuse_what_they_cannot_give() {
    let i = ready();
    // An output as a known, an input as an unknown, an unprovided output: each refused, logged.
    let (status, _) = directional(&i, &[FORCE], &[FORCE], &[1.0]);
    assert_eq!(status, ERROR);
    assert!(i
        .log
        .contains("force (value reference 2) is not an input of McKibbenMuscle"));
    let (status, _) = directional(&i, &[LENGTH], &[PRESSURE], &[1.0]);
    assert_eq!(status, ERROR);
    assert!(i.log.contains("is not an output"));
    let (status, _) = directional(&i, &[FORCE], &[PRESSURE], &[f64::NAN]);
    assert_eq!(status, ERROR);
    assert!(i.log.contains("dvKnown must be finite"));
    let (status, _) = directional(&i, &[999], &[PRESSURE], &[1.0]);
    assert_eq!(status, ERROR);
}

#[test]
fn debug_logging_traces_calls_and_checks_categories() {
    let i = ready();
    let calls = CString::new("logCalls").unwrap();
    let bogus = CString::new("logEverything").unwrap();
    unsafe {
        assert_eq!(
            (api().fmi2SetDebugLogging)(i.c, 1, 1, [bogus.as_ptr()].as_ptr()),
            ERROR
        );
        assert!(i.log.contains("unknown log category 'logEverything'"));
        assert_eq!(
            (api().fmi2SetDebugLogging)(i.c, 1, 1, [calls.as_ptr()].as_ptr()),
            OK
        );
    }
    assert_eq!(i.do_step(0.0, 0.1), OK);
    // One value per set and get, as a master calls them every step.
    assert_eq!(i.set_real(&[LENGTH], &[0.09]), OK);
    assert!(i.real(FORCE).is_finite());
    for call in ["fmi2DoStep", "fmi2SetReal", "fmi2GetReal"] {
        assert!(
            i.log
                .contains(&format!("0 logCalls: {call} in state StepComplete")),
            "{call}: {:?}",
            i.log.lines()
        );
    }
    unsafe { assert_eq!((api().fmi2SetDebugLogging)(i.c, 0, 0, std::ptr::null()), OK) };
    i.log.clear();
    assert_eq!(i.do_step(0.1, 0.1), OK);
    assert_eq!(i.set_real(&[LENGTH], &[0.08]), OK);
    assert!(i.real(FORCE).is_finite());
    assert!(i.log.lines().is_empty());
}

#[test]
fn fmu_state_restores_and_serializes() {
    let i = ready();
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[3e5, 0.09]), OK);
    assert_eq!(i.do_step(0.0, 0.1), OK);
    let mut state: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (api().fmi2GetFMUstate)(i.c, &mut state) }, OK);
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[6e5, 0.1]), OK);
    assert_eq!(i.do_step(0.1, 0.1), OK);
    let after = i.get_real(&[FORCE, VOLUME, PRESSURE]).1;

    assert_eq!(unsafe { (api().fmi2SetFMUstate)(i.c, state) }, OK);
    assert_eq!(i.real(PRESSURE), 3e5, "inputs are part of the state");
    assert_eq!(
        i.do_step(0.2, 0.1),
        ERROR,
        "time went back to 0.1 with the state"
    );
    assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[6e5, 0.1]), OK);
    assert_eq!(i.do_step(0.1, 0.1), OK);
    assert_eq!(
        i.get_real(&[FORCE, VOLUME, PRESSURE]).1,
        after,
        "same outputs after restoring"
    );

    // Serialize, deserialize into a new state, restore from it.
    let mut size = 0usize;
    assert_eq!(
        unsafe { (api().fmi2SerializedFMUstateSize)(i.c, state, &mut size) },
        OK
    );
    let mut bytes = vec![0 as c_char; size];
    assert_eq!(
        unsafe { (api().fmi2SerializeFMUstate)(i.c, state, bytes.as_mut_ptr(), size - 1) },
        ERROR,
        "too small"
    );
    assert_eq!(
        unsafe { (api().fmi2SerializeFMUstate)(i.c, state, bytes.as_mut_ptr(), size) },
        OK
    );
    let other = ready();
    let mut copy: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        unsafe { (api().fmi2DeSerializeFMUstate)(other.c, bytes.as_ptr(), size, &mut copy) },
        OK
    );
    assert_eq!(unsafe { (api().fmi2SetFMUstate)(other.c, copy) }, OK);
    assert_eq!(other.real(PRESSURE), 3e5);
    assert_eq!(other.set_real(&[PRESSURE, LENGTH], &[6e5, 0.1]), OK);
    assert_eq!(other.do_step(0.1, 0.1), OK);
    assert_eq!(
        other.get_real(&[FORCE, VOLUME, PRESSURE]).1,
        after,
        "same outputs in another instance"
    );

    // Corrupt bytes and foreign pointers are refused.
    let mut junk: *mut c_void = std::ptr::null_mut();
    bytes[12] ^= 0x55;
    bytes.truncate(size / 2);
    assert_eq!(
        unsafe { (api().fmi2DeSerializeFMUstate)(other.c, bytes.as_ptr(), bytes.len(), &mut junk) },
        ERROR
    );
    assert!(other.log.contains("fmi2DeSerializeFMUstate"));
    assert_eq!(
        unsafe {
            (api().fmi2DeSerializeFMUstate)(other.c, [0 as c_char; 3].as_ptr(), 3, &mut junk)
        },
        ERROR
    );
    assert!(other.log.contains("not a serialized FMU state of this FMU"));
    assert_eq!(
        unsafe { (api().fmi2SetFMUstate)(other.c, state) },
        ERROR,
        "a state of another instance"
    );
    assert!(other.log.contains("fmi2SetFMUstate: unknown FMU state"));
    assert_eq!(unsafe { (api().fmi2FreeFMUstate)(other.c, &mut copy) }, OK);
    assert!(copy.is_null());
    assert_eq!(unsafe { (api().fmi2FreeFMUstate)(i.c, &mut state) }, OK);
    // Freeing an instance frees the states it still holds.
    let mut left: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (api().fmi2GetFMUstate)(i.c, &mut left) }, OK);
}

#[test]
fn instances_in_threads_match_serial_runs() {
    fn run(pressure: f64) -> Vec<f64> {
        let i = ready();
        let mut out = Vec::new();
        for k in 0..2000 {
            let t = k as f64 * 1e-3;
            let l = 0.06 + 0.04 * (0.5 + 0.5 * (7.0 * t).sin());
            assert_eq!(i.set_real(&[PRESSURE, LENGTH], &[pressure, l]), OK);
            assert_eq!(i.do_step(t, 1e-3), OK);
            out.push(i.real(FORCE));
        }
        out
    }
    let pressures = [1e5, 2e5, 4e5, 6e5];
    let serial: Vec<_> = pressures.iter().map(|&p| run(p)).collect();
    let threaded: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> = pressures.iter().map(|&p| s.spawn(move || run(p))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(serial, threaded);
}

#[test]
fn many_instances_live_at_once() {
    let instances: Vec<_> = (0..100).map(|_| ready()).collect();
    for (k, i) in instances.iter().enumerate() {
        assert_eq!(i.set_real(&[PRESSURE], &[1e3 * k as f64]), OK);
    }
    for (k, i) in instances.iter().enumerate() {
        assert_eq!(i.real(PRESSURE), 1e3 * k as f64);
    }
}

#[test]
fn string_status_and_strings() {
    let i = ready();
    let mut s: *const c_char = std::ptr::null();
    assert_eq!(
        unsafe { (api().fmi2GetStringStatus)(i.c, 1, &mut s) },
        DISCARD
    );
    assert_eq!(
        unsafe { (api().fmi2GetString)(i.c, [0u32].as_ptr(), 1, &mut s) },
        ERROR,
        "no String variables"
    );
}
