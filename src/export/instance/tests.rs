//! The state machine with a minimal model that has what no shipped model has yet: a tunable
//! parameter (FMI 2.0.4 section 2.2.7 lets it change between steps).
use super::*;
use crate::export::logger::{Logger, Sink};
use crate::export::runtime::{Bindings, ModelFactory, Values};
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
    type Known = ();
    type Unknown = ();
    type ArrayOutput = std::convert::Infallible;
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

static API: Api = Api {
    version: "FMI 2.0",
    step_state: "StepComplete",
    get_fmu_state: "fmi2GetFMUstate",
    serialize_fmu_state: "fmi2SerializeFMUstate",
};

/// A logger that drops every message.
struct Silent;

impl Sink for Silent {
    fn send(&self, _: Status, _: &str, _: &str) {}
}

fn y(inst: &mut Instance) -> (Status, f64) {
    let mut out = [f64::NAN];
    let s = inst.get("fmi2GetReal", VarType::Real, &[2], &mut out, |v, i| {
        v.real(i)
    });
    (s, out[0])
}

#[test]
fn a_tunable_parameter_set_between_steps_takes_effect() {
    let mut inst = Instance::new(&FACTORY, &API, Logger::new(Silent));
    assert_eq!(
        inst.setup_experiment("fmi2SetupExperiment", None, 0.0, None),
        Status::OK
    );
    assert_eq!(
        inst.enter_initialization_mode("fmi2EnterInitializationMode"),
        Status::OK
    );
    assert_eq!(
        inst.exit_initialization_mode("fmi2ExitInitializationMode"),
        Status::OK
    );
    assert_eq!(inst.set("fmi2SetReal", &[1], &[2.0]), Status::OK);
    assert_eq!(y(&mut inst), (Status::OK, 2.0));
    assert_eq!(inst.set("fmi2SetReal", &[0], &[3.0]), Status::OK);
    assert_eq!(
        y(&mut inst),
        (Status::OK, 6.0),
        "outputs follow the new gain"
    );
    assert_eq!(inst.do_step("fmi2DoStep", 0.0, 0.1), Status::OK);
    assert_eq!(y(&mut inst), (Status::OK, 6.0), "and so does the step");
    assert_eq!(inst.set("fmi2SetReal", &[0], &[-1.0]), Status::OK);
    assert_eq!(inst.do_step("fmi2DoStep", 0.1, 0.1), Status::OK);
    assert_eq!(y(&mut inst), (Status::OK, -2.0));
    // A gain the model refuses: the whole call is undone, the model keeps running.
    assert_eq!(inst.set("fmi2SetReal", &[1, 0], &[5.0, 0.0]), Status::Error);
    assert_eq!(y(&mut inst), (Status::OK, -2.0));
    assert_eq!([inst.runtime.real(0), inst.runtime.real(1)], [-1.0, 2.0]);
    assert_eq!(inst.do_step("fmi2DoStep", 0.2, 0.1), Status::OK);
    assert_eq!(y(&mut inst), (Status::OK, -2.0));
}

#[test]
fn a_non_finite_output_is_refused_with_a_logged_reason_never_handed_out() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static ERRORS: AtomicUsize = AtomicUsize::new(0);
    struct CountErrors;
    impl Sink for CountErrors {
        fn send(&self, status: Status, _: &str, _: &str) {
            if status == Status::Error {
                ERRORS.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
    let mut inst = Instance::new(&FACTORY, &API, Logger::new(CountErrors));
    assert_eq!(
        inst.setup_experiment("fmi2SetupExperiment", None, 0.0, None),
        Status::OK
    );
    assert_eq!(
        inst.enter_initialization_mode("fmi2EnterInitializationMode"),
        Status::OK
    );
    assert_eq!(
        inst.exit_initialization_mode("fmi2ExitInitializationMode"),
        Status::OK
    );
    // Both finite and legal; their product overflows to +inf.
    assert_eq!(
        inst.set("fmi2SetReal", &[0, 1], &[1e300, 1e300]),
        Status::OK
    );
    assert_eq!(inst.do_step("fmi2DoStep", 0.0, 0.1), Status::OK);
    let before = ERRORS.load(Ordering::Relaxed);
    let mut out = [7.0, 7.0];
    let s = inst.get("fmi2GetReal", VarType::Real, &[1, 2], &mut out, |v, i| {
        v.real(i)
    });
    assert_eq!(s, Status::Error);
    assert_eq!(out[1], 7.0, "the infinity was written out");
    assert!(out.iter().all(|x| x.is_finite()));
    assert_eq!(
        ERRORS.load(Ordering::Relaxed),
        before + 1,
        "refused without a reason"
    );
    // Back in range, the same instance hands out finite outputs again.
    assert_eq!(inst.set("fmi2SetReal", &[1], &[2.0]), Status::OK);
    assert_eq!(y(&mut inst), (Status::OK, 2e300));
}
