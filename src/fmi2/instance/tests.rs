//! The state machine with a minimal model that has what no shipped model has yet: a tunable
//! parameter (FMI 2.0.4 section 2.2.7 lets it change between steps).
use super::*;
use crate::fmi2::logger::Logger;
use crate::fmi2::runtime::{Bindings, ModelFactory, Values};
use crate::models::{Model, Refusal};
use crate::variables::{Causality, Initial, Interface, Start, Variability};
use serde::{Deserialize, Serialize};

/// y = gain * u, with a tunable gain.
#[derive(Clone, Serialize, Deserialize)]
struct Gain {
    gain: f64,
}

const fn var(
    name: &'static str,
    vr: u32,
    causality: Causality,
    variability: Variability,
    initial: Initial,
    start: Start,
) -> Variable {
    Variable {
        name,
        kind: VarType::Real,
        vr,
        causality,
        variability,
        initial,
        start,
        min: None,
        max: None,
        unit: "",
        description: "",
    }
}

static VARIABLES: [Variable; 3] = [
    var(
        "gain",
        0,
        Causality::Parameter,
        Variability::Tunable,
        Initial::Exact,
        Start::Real(1.0),
    ),
    var(
        "u",
        1,
        Causality::Input,
        Variability::Continuous,
        Initial::None,
        Start::Real(0.0),
    ),
    var(
        "y",
        2,
        Causality::Output,
        Variability::Continuous,
        Initial::Calculated,
        Start::None,
    ),
];

static INFO: ModelInfo = ModelInfo {
    name: "Gain",
    guid: "{gain}",
    description: "",
    model_description_xml: "",
    variables: &VARIABLES,
    counts: [3, 0, 0, 0],
    log_categories: &[],
};

/// What build.rs would generate for the three variables above.
struct GainVariables;

/// The gain, starting at 1 as the description says.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct GainParameters {
    gain: f64,
}

impl Default for GainParameters {
    fn default() -> Self {
        Self { gain: 1.0 }
    }
}

impl Interface for GainVariables {
    type Parameters = GainParameters;
    type Inputs = f64;
    type Outputs = f64;
    type CalculatedParameters = ();
    type States = ();
    const EVENT_INDICATORS: usize = 0;
    const INFO: &'static ModelInfo = &INFO;
}
impl Bindings for GainVariables {
    fn real(v: &Values<Self>, vr: usize) -> f64 {
        [v.parameters.gain, v.inputs, v.outputs]
            .get(vr)
            .copied()
            .unwrap_or_default()
    }
    fn set_real(v: &mut Values<Self>, vr: usize, x: f64) {
        match vr {
            0 => v.parameters.gain = x,
            1 => v.inputs = x,
            2 => v.outputs = x,
            _ => {}
        }
    }
    fn integer(_: &Values<Self>, _: usize) -> i32 {
        0
    }
    fn set_integer(_: &mut Values<Self>, _: usize, _: i32) {}
    fn boolean(_: &Values<Self>, _: usize) -> bool {
        false
    }
    fn set_boolean(_: &mut Values<Self>, _: usize, _: bool) {}
    fn string(_: &Values<Self>, _: usize) -> &str {
        ""
    }
    fn set_string(_: &mut Values<Self>, _: usize, _: &str) {}
    fn set_input_clamped(_: &mut Values<Self>, _: bool) {}
}

impl Model for Gain {
    type Variables = GainVariables;
    const DOCUMENTATION: &'static str = "";
    fn new(p: &GainParameters, _: &f64) -> Result<Self, Refusal> {
        match p.gain {
            0.0 => Err("gain must not be zero".into()),
            gain => Ok(Self { gain }),
        }
    }
    fn evaluate(&mut self, u: &f64, y: &mut f64, _: &mut Report) {
        *y = self.gain * u;
    }
    fn step(&mut self, u: &f64, y: &mut f64, _: f64, _: f64, report: &mut Report) {
        self.evaluate(u, y, report);
    }
}

static FACTORY: ModelFactory<Gain> = ModelFactory::NEW;

fn y(inst: &mut Instance) -> (fmi2Status, f64) {
    let mut out = [f64::NAN];
    let s = inst.get("fmi2GetReal", VarType::Real, &[2], &mut out, |v, i| {
        v.real(i)
    });
    (s, out[0])
}

#[test]
fn a_tunable_parameter_set_between_steps_takes_effect() {
    let mut inst = Instance::new(&FACTORY, Logger::new(None, std::ptr::null_mut(), "t"));
    assert_eq!(inst.setup_experiment(None, 0.0, None), fmi2Status::OK);
    assert_eq!(inst.enter_initialization_mode(), fmi2Status::OK);
    assert_eq!(inst.exit_initialization_mode(), fmi2Status::OK);
    assert_eq!(inst.set("fmi2SetReal", &[1], &[2.0]), fmi2Status::OK);
    assert_eq!(y(&mut inst), (fmi2Status::OK, 2.0));
    assert_eq!(inst.set("fmi2SetReal", &[0], &[3.0]), fmi2Status::OK);
    assert_eq!(
        y(&mut inst),
        (fmi2Status::OK, 6.0),
        "outputs follow the new gain"
    );
    assert_eq!(inst.do_step(0.0, 0.1), fmi2Status::OK);
    assert_eq!(y(&mut inst), (fmi2Status::OK, 6.0), "and so does the step");
    assert_eq!(inst.set("fmi2SetReal", &[0], &[-1.0]), fmi2Status::OK);
    assert_eq!(inst.do_step(0.1, 0.1), fmi2Status::OK);
    assert_eq!(y(&mut inst), (fmi2Status::OK, -2.0));
    // A gain the model refuses: the whole call is undone, the model keeps running.
    assert_eq!(
        inst.set("fmi2SetReal", &[1, 0], &[5.0, 0.0]),
        fmi2Status::Error
    );
    assert_eq!(y(&mut inst), (fmi2Status::OK, -2.0));
    assert_eq!([inst.runtime.real(0), inst.runtime.real(1)], [-1.0, 2.0]);
    assert_eq!(inst.do_step(0.2, 0.1), fmi2Status::OK);
    assert_eq!(y(&mut inst), (fmi2Status::OK, -2.0));
}

#[test]
fn a_non_finite_output_is_refused_with_a_logged_reason_never_handed_out() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static ERRORS: AtomicUsize = AtomicUsize::new(0);
    unsafe extern "C" fn count(
        _: *mut std::ffi::c_void,
        _: crate::fmi2::types::fmi2String,
        status: std::ffi::c_int,
        _: crate::fmi2::types::fmi2String,
        _: crate::fmi2::types::fmi2String,
    ) {
        if status == fmi2Status::Error as std::ffi::c_int {
            ERRORS.fetch_add(1, Ordering::Relaxed);
        }
    }
    // SAFETY: called with exactly these five arguments, as the logger is (see the fuzz driver).
    let logger = unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(
                *mut std::ffi::c_void,
                crate::fmi2::types::fmi2String,
                std::ffi::c_int,
                crate::fmi2::types::fmi2String,
                crate::fmi2::types::fmi2String,
            ),
            crate::fmi2::types::fmi2CallbackLogger,
        >(count)
    };
    let mut inst = Instance::new(
        &FACTORY,
        Logger::new(Some(logger), std::ptr::null_mut(), "t"),
    );
    assert_eq!(inst.setup_experiment(None, 0.0, None), fmi2Status::OK);
    assert_eq!(inst.enter_initialization_mode(), fmi2Status::OK);
    assert_eq!(inst.exit_initialization_mode(), fmi2Status::OK);
    // Both finite and legal; their product overflows to +inf.
    assert_eq!(
        inst.set("fmi2SetReal", &[0, 1], &[1e300, 1e300]),
        fmi2Status::OK
    );
    assert_eq!(inst.do_step(0.0, 0.1), fmi2Status::OK);
    let before = ERRORS.load(Ordering::Relaxed);
    let mut out = [7.0, 7.0];
    let s = inst.get("fmi2GetReal", VarType::Real, &[1, 2], &mut out, |v, i| {
        v.real(i)
    });
    assert_eq!(s, fmi2Status::Error);
    assert_eq!(out[1], 7.0, "the infinity was written out");
    assert!(out.iter().all(|x| x.is_finite()));
    assert_eq!(
        ERRORS.load(Ordering::Relaxed),
        before + 1,
        "refused without a reason"
    );
    // Back in range, the same instance hands out finite outputs again.
    assert_eq!(inst.set("fmi2SetReal", &[1], &[2.0]), fmi2Status::OK);
    assert_eq!(y(&mut inst), (fmi2Status::OK, 2e300));
}
