//! The packaged MultiferroicMotor binary driven through its C ABI: the chapter 3 numbers through the
//! FMU, FMU state round trips with the motor's history, and finiteness over communication steps
//! from 1e-12 s to 1 s.

use crate::common;

use actuator_fmus::variables::multiferroic_motor::{boolean, integer, real};
use common::*;
use std::ffi::{c_char, c_int, c_void};
use std::sync::OnceLock;

const MODEL: &str = "MultiferroicMotor";

fn vr(index: usize) -> u32 {
    index as u32
}

const OUTPUTS: [usize; 8] = [
    real::TORQUE,
    real::ROTOR_ANGLE,
    real::ROTOR_SPEED,
    real::ONION_ANGLE,
    real::OFFSET_ANGLE,
    real::MAGNETOSTATIC_ENERGY,
    real::MAGNETOELASTIC_ENERGY,
    real::APPLIED_STRAIN_DIRECTION,
];

fn api() -> &'static Api {
    static API: OnceLock<Api> = OnceLock::new();
    API.get_or_init(|| Api::load(&extract_binary(MODEL)))
}

fn instance() -> Instance<'static> {
    api()
        .instantiate("motor", &guid_of(MODEL))
        .unwrap_or_else(|log| panic!("refused: {:?}", log.lines()))
}

fn set_integer(i: &Instance, index: usize, value: c_int) -> c_int {
    unsafe { (api().fmi2SetInteger)(i.c, &vr(index), 1, &value) }
}

fn set_boolean(i: &Instance, index: usize, value: bool) -> c_int {
    let v = c_int::from(value);
    unsafe { (api().fmi2SetBoolean)(i.c, &vr(index), 1, &v) }
}

fn set(i: &Instance, index: usize, value: f64) {
    assert_eq!(
        i.set_real(&[vr(index)], &[value]),
        OK,
        "{:?}",
        i.log.lines()
    );
}

fn get(i: &Instance, index: usize) -> f64 {
    i.real(vr(index))
}

fn outputs(i: &Instance) -> Vec<f64> {
    let refs: Vec<u32> = OUTPUTS.iter().map(|&k| vr(k)).collect();
    let (status, values) = i.get_real(&refs);
    assert_eq!(status, OK, "{:?}", i.log.lines());
    values
}

/// Initialized with the rotor locked (static torque) or free with the stepping schedule.
fn locked() -> Instance<'static> {
    let i = instance();
    assert_eq!(set_boolean(&i, boolean::ROTOR_LOCKED, true), OK);
    i.initialize();
    i
}

fn stepping() -> Instance<'static> {
    let i = instance();
    assert_eq!(set_integer(&i, integer::SCHEDULE, 1), OK);
    i.initialize();
    i
}

#[test]
fn locked_rotor_torque_peaks_at_2_1e_18() {
    // Section 3.2.2: "a maximum torque value of about 2.1e-18 Nm" (Fig. 3.3a). Stress raised at
    // -45 degrees, one step per stress value.
    let i = locked();
    set(&i, real::STRAIN_DIRECTION, (-45f64).to_radians());
    let (mut best, mut best_stress, mut t) = (0.0f64, 0.0, 0.0);
    for k in 1..=200 {
        let stress = 1e9 * k as f64 / 200.0;
        set(&i, real::STRESS, stress);
        assert_eq!(i.do_step(t, 1e-6), OK);
        t += 1e-6;
        let torque = get(&i, real::TORQUE);
        assert_eq!(get(&i, real::ROTOR_ANGLE), 0.0, "the rotor is locked");
        if torque > best {
            (best, best_stress) = (torque, stress);
        }
    }
    assert!((best / 2.1e-18 - 1.0).abs() < 0.05, "{best:e}");
    assert!(
        best_stress > 100e6 && best_stress < 250e6,
        "{best_stress:e}"
    );
    // At 1 GPa the onion swings out of alignment and the torque has fallen.
    assert!(get(&i, real::TORQUE) < 0.9 * best);
    assert!(get(&i, real::OFFSET_ANGLE).to_degrees() > 35.0);
}

#[test]
fn fig_3_3b_offset_of_23_degrees() {
    // Fig. 3.3b: 200 MPa tension at -45 degrees holds the onion state 23 degrees from the bar.
    let i = locked();
    set(&i, real::STRAIN_DIRECTION, (-45f64).to_radians());
    set(&i, real::STRESS, 200e6);
    let before = get(&i, real::OFFSET_ANGLE).to_degrees();
    assert!((before - 23.0).abs() < 1.0, "{before}");
    assert_eq!(i.do_step(0.0, 1e-3), OK);
    let after = get(&i, real::OFFSET_ANGLE).to_degrees();
    assert!((after - 23.0).abs() < 1.0, "{after}");
    // The torque is the slope of the magnetostatic energy: positive towards the onion state.
    assert!(get(&i, real::TORQUE) > 1.9e-18);
    assert!(
        get(&i, real::MAGNETOELASTIC_ENERGY) < 0.0,
        "tension on nickel"
    );
}

#[test]
fn calculated_parameters_of_table_3_1() {
    let i = locked();
    // A 350 x 100 x 20 nm nickel bar (8908 kg/m3): 6.24e-18 kg, I = m (L^2 + w^2) / 12.
    let mass = 350e-9 * 100e-9 * 20e-9 * 8908.0;
    assert!((get(&i, real::BAR_MASS) / mass - 1.0).abs() < 1e-12);
    let inertia = mass * (350e-9f64.powi(2) + 100e-9f64.powi(2)) / 12.0;
    assert!((get(&i, real::INERTIA) / inertia - 1.0).abs() < 1e-12);
    let w0 = get(&i, real::UNDAMPED_FREQUENCY);
    assert!(
        (w0 / (2.0 * std::f64::consts::PI) - 1.95e6).abs() < 0.02e6,
        "{w0}"
    );
    assert!((get(&i, real::RELAXATION_TIME) - 3.1e-6).abs() < 0.05e-6);
    assert!(get(&i, real::DRAG) > 3.0e-23 && get(&i, real::DRAG) < 3.4e-23);
}

#[test]
fn fmu_state_round_trip_replays_the_motor() {
    let i = stepping();
    let h = 2e-6;
    let mut t = 0.0;
    for _ in 0..10 {
        assert_eq!(i.do_step(t, h), OK);
        t += h;
    }
    // Mid-step of the rotor: angle and speed both matter.
    assert!(get(&i, real::ROTOR_SPEED) > 1e3);
    let mut state: *mut c_void = std::ptr::null_mut();
    assert_eq!(unsafe { (api().fmi2GetFMUstate)(i.c, &mut state) }, OK);
    let t_saved = t;
    let run = |t0: f64| {
        let mut t = t0;
        let mut trace = vec![];
        for _ in 0..30 {
            assert_eq!(i.do_step(t, h), OK);
            t += h;
            trace.extend(outputs(&i));
        }
        trace
    };
    let first = run(t_saved);
    assert_eq!(unsafe { (api().fmi2SetFMUstate)(i.c, state) }, OK);
    let again = run(t_saved);
    assert_eq!(first, again, "restored state replays bit for bit");

    // Serialized into another instance, it replays there too.
    let mut size = 0usize;
    assert_eq!(
        unsafe { (api().fmi2SerializedFMUstateSize)(i.c, state, &mut size) },
        OK
    );
    let mut bytes = vec![0 as c_char; size];
    assert_eq!(
        unsafe { (api().fmi2SerializeFMUstate)(i.c, state, bytes.as_mut_ptr(), size) },
        OK
    );
    let other = stepping();
    let mut copy: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        unsafe { (api().fmi2DeSerializeFMUstate)(other.c, bytes.as_ptr(), size, &mut copy) },
        OK
    );
    assert_eq!(unsafe { (api().fmi2SetFMUstate)(other.c, copy) }, OK);
    let mut t = t_saved;
    let mut elsewhere = vec![];
    for _ in 0..30 {
        assert_eq!(other.do_step(t, h), OK);
        t += h;
        elsewhere.extend(outputs(&other));
    }
    assert_eq!(first, elsewhere);
    assert_eq!(unsafe { (api().fmi2FreeFMUstate)(other.c, &mut copy) }, OK);
    assert_eq!(unsafe { (api().fmi2FreeFMUstate)(i.c, &mut state) }, OK);
}

#[test]
fn no_nan_from_1e_12_to_1_s_steps() {
    for h in [1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2, 1.0] {
        let i = stepping();
        set(&i, real::LOAD_TORQUE, -5e-19);
        let mut t = 0.0;
        for _ in 0..3 {
            let status = i.do_step(t, h);
            assert!(status == OK || status == WARNING, "h = {h}: {status}");
            t += h;
            for (k, x) in outputs(&i).iter().enumerate() {
                assert!(x.is_finite(), "h = {h}: output {k} = {x}");
            }
        }
        // After a long step the rotor has followed the schedule: the onion is at most a step
        // ahead of it, never somewhere random.
        if h >= 1e-2 {
            assert!(get(&i, real::OFFSET_ANGLE).abs() < 70f64.to_radians());
            assert!(get(&i, real::ROTOR_ANGLE) > 1.0);
        }
    }
}

#[test]
fn a_refused_step_is_discarded_with_the_state_kept() {
    let i = stepping();
    assert_eq!(i.do_step(0.0, 1e-5), OK);
    let before = outputs(&i);
    // The physics refuses steps longer than 1000 s.
    assert_eq!(i.do_step(1e-5, 2e3), DISCARD);
    assert!(i.log.contains("communication step"), "{:?}", i.log.lines());
    assert_eq!(outputs(&i), before);
}

#[test]
fn a_bar_that_does_not_fit_fails_initialization_with_a_reason() {
    let i = instance();
    set(&i, real::BAR_LENGTH, 600e-9);
    assert_eq!(i.setup(), OK);
    assert_eq!(i.enter(), OK);
    assert_eq!(i.exit(), ERROR);
    assert!(
        i.log.contains("does not fit inside the ring"),
        "{:?}",
        i.log.lines()
    );
    // Out-of-range values are refused at fmi2SetReal/fmi2SetInteger.
    let j = instance();
    assert_eq!(j.set_real(&[vr(real::THICKNESS)], &[-1e-9]), ERROR);
    assert_eq!(set_integer(&j, integer::ONION_MODEL, 2), ERROR);
    assert_eq!(set_integer(&j, integer::MAX_SUBSTEPS, 0), ERROR);
}

#[test]
fn a_diverged_long_step_is_never_returned_as_a_result() {
    // A 1 s step spans 10 000 switches of the 100 us schedule with a budget of 20 000 substeps.
    // Whatever the integrator does, a returned rotor angle must respect the drag's speed limit,
    // (largest torque) / drag ~ 6.7e4 rad/s for Table 3.1; otherwise the step is discarded.
    let i = stepping();
    let limit = 2.2e-18 / get(&i, real::DRAG);
    let status = i.do_step(0.0, 1.0);
    let angle = get(&i, real::ROTOR_ANGLE);
    assert!(angle.is_finite());
    match status {
        OK | WARNING => assert!(angle.abs() <= 1.5 * limit, "{angle}"),
        DISCARD => {
            assert!(
                i.log.contains("integration diverged"),
                "{:?}",
                i.log.lines()
            );
            assert_eq!(angle, 0.0, "the state before the step is kept");
        }
        other => panic!("status {other}: {:?}", i.log.lines()),
    }
}
