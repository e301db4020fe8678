//! Bad input through the C ABI of EVERY packaged FMU in `target/fmu`, driven generically from each
//! FMU's own modelDescription.xml (docs/reliability.md, "Bad input policy"): non-finite and out-of-range values,
//! wrong value references, variables that may not be set, NULL pointers for every pointer argument,
//! wrong GUIDs, every illegal call order of FMI 2.0.4 section 4.2.4, bad step sizes and
//! communication points. Each refusal must return the expected non-OK status AND log a reason, and
//! the instance must then come back through `fmi2Reset`: a normal run afterwards gives exactly the
//! outputs of a fresh instance. One test runs everything and lists every failing case at once;
//! it prints how many cases were tried (docs/reliability.md quotes the count).

use crate::common;

use common::*;
use std::ffi::{c_char, c_int, c_void, CString};
use std::ptr::{null, null_mut};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Real,
    Integer,
    Boolean,
    String,
}

const KINDS: [Kind; 4] = [Kind::Real, Kind::Integer, Kind::Boolean, Kind::String];

#[derive(Clone, Debug)]
struct Var {
    name: String,
    vr: u32,
    kind: Kind,
    causality: String,
    variability: String,
    initial: String,
    min: Option<f64>,
    max: Option<f64>,
    start: Option<f64>,
}

/// FMI 2.0.4 section 4.2.4 states this FMU can reach (no asynchronous steps, so no StepCanceled
/// or StepInProgress). Bits of a mask, in the order of [`STATES`].
#[derive(Clone, Copy, Debug, PartialEq)]
enum State {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
}

const STATES: [State; 6] = [
    State::Instantiated,
    State::InitializationMode,
    State::StepComplete,
    State::StepFailed,
    State::Terminated,
    State::Error,
];

const fn bit(s: State) -> u32 {
    1 << s as u32
}

impl Var {
    /// FMI 2.0.4 section 2.2.7 (table of `fmi2SetXXX` per state), written out from the spec, not
    /// from the crate, so that the two are checked against each other.
    fn settable_in(&self) -> u32 {
        use State::*;
        if self.variability == "constant" {
            return 0;
        }
        match self.causality.as_str() {
            "input" => bit(Instantiated) | bit(InitializationMode) | bit(StepComplete),
            "parameter" if self.variability == "tunable" => {
                bit(Instantiated) | bit(InitializationMode) | bit(StepComplete)
            }
            "parameter" => bit(Instantiated) | bit(InitializationMode),
            _ if self.initial == "approx" => bit(Instantiated),
            _ => 0,
        }
    }
}

/// The modelDescription.xml of a packaged FMU.
/// The model name, GUID and variables of a model description, and the parameter set its test data
/// gives as describing no physical actuator (`<Impossible values="name=value ...">` in the
/// project's VendorAnnotations), if any.
fn parse(xml: &str) -> (String, String, Vec<Var>, Option<String>) {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(xml);
    let (mut model, mut guid, mut vars) = (String::new(), String::new(), Vec::<Var>::new());
    let mut impossible = None;
    let mut in_variable = false;
    loop {
        let event = reader
            .read_event()
            .expect("well-formed modelDescription.xml");
        let (e, empty) = match event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(e) if e.name().as_ref() == b"ScalarVariable" => {
                in_variable = false;
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let attrs: Vec<(String, String)> = e
            .attributes()
            .map(|a| {
                let a = a.unwrap();
                (
                    String::from_utf8_lossy(a.key.as_ref()).into_owned(),
                    a.unescape_value().unwrap().into_owned(),
                )
            })
            .collect();
        let get = |k: &str| {
            attrs
                .iter()
                .find(|(key, _)| key == k)
                .map(|(_, v)| v.clone())
        };
        let num = |k: &str| get(k).map(|v| v.parse::<f64>().unwrap());
        match e.name().as_ref() {
            b"fmiModelDescription" => {
                model = get("modelName").unwrap();
                guid = get("guid").unwrap();
            }
            b"ScalarVariable" => {
                in_variable = !empty;
                let causality = get("causality").unwrap_or_else(|| "local".into());
                let default_initial = match causality.as_str() {
                    "parameter" => "exact",
                    "input" | "independent" => "",
                    _ => "calculated",
                };
                vars.push(Var {
                    name: get("name").unwrap(),
                    vr: get("valueReference").unwrap().parse().unwrap(),
                    kind: Kind::Real,
                    variability: get("variability").unwrap_or_else(|| "continuous".into()),
                    initial: get("initial").unwrap_or_else(|| default_initial.into()),
                    causality,
                    min: None,
                    max: None,
                    start: None,
                });
            }
            kind @ (b"Real" | b"Integer" | b"Enumeration" | b"Boolean" | b"String")
                if in_variable =>
            {
                let v = vars.last_mut().unwrap();
                v.kind = match kind {
                    b"Real" => Kind::Real,
                    // An Enumeration travels as an Integer.
                    b"Integer" | b"Enumeration" => Kind::Integer,
                    b"Boolean" => Kind::Boolean,
                    _ => Kind::String,
                };
                v.min = num("min");
                v.max = num("max");
                v.start = match v.kind {
                    Kind::Boolean => get("start").map(|s| f64::from(u8::from(s == "true"))),
                    Kind::String => None,
                    _ => num("start"),
                };
            }
            b"Impossible" => impossible = get("values"),
            _ => {}
        }
    }
    (model, guid, vars, impossible)
}

/// A parameter value to set by name.
#[derive(Clone, Copy, Debug)]
enum Value {
    R(f64),
    I(c_int),
}

/// Communication step of the normal run and of the bad-step cases.
const H: f64 = 1e-6;

struct Fmu {
    model: String,
    guid: String,
    vars: Vec<Var>,
    api: Api,
    /// The outputs of a normal run on a fresh instance.
    reference: Vec<u64>,
    /// The parameter set the model description gives as impossible (`name=value ...`), if any.
    listed_impossible: Option<String>,
    /// Parameters that make initialization fail, if any were found.
    impossible: Option<Vec<(String, Value)>>,
    /// A step size that the model discards (StepFailed), if any.
    discarded_step: Option<f64>,
}

impl Fmu {
    fn load(path: &std::path::Path) -> Fmu {
        let xml = read_entry(path, "modelDescription.xml");
        let (model, guid, vars, impossible) = parse(&String::from_utf8(xml).unwrap());
        let stem = path.file_stem().unwrap().to_str().unwrap();
        assert_eq!(stem, model, "{}", path.display());
        let mut fmu = Fmu {
            api: Api::load(&extract_binary(&model)),
            model,
            guid,
            vars,
            reference: Vec::new(),
            listed_impossible: impossible,
            impossible: None,
            discarded_step: None,
        };
        let (reference, impossible, discarded_step) = {
            let i = fmu.instance();
            let reference = fmu
                .normal_run(&i)
                .unwrap_or_else(|e| panic!("{}: normal run failed: {e}", fmu.model));
            (
                reference,
                fmu.find_impossible(&i),
                fmu.find_discarded_step(&i),
            )
        };
        fmu.reference = reference;
        fmu.impossible = impossible;
        fmu.discarded_step = discarded_step;
        fmu
    }

    fn instance(&self) -> Instance<'_> {
        self.api
            .instantiate("bad-input", &self.guid)
            .unwrap_or_else(|log| panic!("{} refused: {:?}", self.model, log.lines()))
    }

    fn of(&self, kind: Kind) -> impl Iterator<Item = &Var> {
        self.vars.iter().filter(move |v| v.kind == kind)
    }

    fn count(&self, kind: Kind) -> u32 {
        self.of(kind).count() as u32
    }

    fn var(&self, name: &str) -> &Var {
        self.vars.iter().find(|v| v.name == name).unwrap()
    }

    fn set(&self, i: &Instance, name: &str, value: Value) -> c_int {
        let vr = self.var(name).vr;
        unsafe {
            match value {
                Value::R(x) => (self.api.fmi2SetReal)(i.c, &vr, 1, &x),
                Value::I(k) => match self.var(name).kind {
                    Kind::Boolean => (self.api.fmi2SetBoolean)(i.c, &vr, 1, &k),
                    _ => (self.api.fmi2SetInteger)(i.c, &vr, 1, &k),
                },
            }
        }
    }

    /// Every Real, Integer and Boolean value, as bits (so that a NaN would compare too).
    fn snapshot(&self, i: &Instance) -> Result<Vec<u64>, String> {
        let mut out = Vec::new();
        for v in &self.vars {
            let s = unsafe {
                match v.kind {
                    Kind::Real => {
                        let mut x = f64::NAN;
                        let s = (self.api.fmi2GetReal)(i.c, &v.vr, 1, &mut x);
                        if !x.is_finite() {
                            return Err(format!("{} = {x}", v.name));
                        }
                        out.push(x.to_bits());
                        s
                    }
                    Kind::Integer | Kind::Boolean => {
                        let mut k: c_int = -7;
                        let f = if v.kind == Kind::Integer {
                            self.api.fmi2GetInteger
                        } else {
                            self.api.fmi2GetBoolean
                        };
                        let s = f(i.c, &v.vr, 1, &mut k);
                        out.push(k as u64);
                        s
                    }
                    Kind::String => OK,
                }
            };
            if s > WARNING {
                return Err(format!("get {} returned {s}", v.name));
            }
        }
        Ok(out)
    }

    /// Setup, initialization with start values, three steps of `H`, then every value.
    fn normal_run(&self, i: &Instance) -> Result<Vec<u64>, String> {
        for (what, s) in [
            ("setup", i.setup()),
            ("enter", i.enter()),
            ("exit", i.exit()),
        ] {
            if s != OK {
                return Err(format!("{what} returned {s}: {:?}", i.log.lines()));
            }
        }
        for k in 0..3 {
            let s = i.do_step(k as f64 * H, H);
            if s > WARNING {
                return Err(format!("step {k} returned {s}: {:?}", i.log.lines()));
            }
        }
        self.snapshot(i)
    }

    fn reset(&self, i: &Instance) -> c_int {
        unsafe { (self.api.fmi2Reset)(i.c) }
    }

    fn try_impossible(&self, i: &Instance, set: &[(String, Value)]) -> bool {
        if self.reset(i) != OK {
            return false;
        }
        let all_set = set.iter().all(|(n, v)| self.set(i, n, *v) == OK);
        i.log.clear();
        all_set
            && i.setup() == OK
            && i.enter() == OK
            && i.exit() == ERROR
            && i.log
                .contains("fmi2ExitInitializationMode: parameters rejected: ")
    }

    /// The impossible set the model description gives, or a search over single parameters at
    /// extreme in-range values, each with every small-range Integer parameter at each of its values.
    fn find_impossible(&self, i: &Instance) -> Option<Vec<(String, Value)>> {
        let listed: Vec<(String, Value)> = self
            .listed_impossible
            .iter()
            .flat_map(|values| values.split_whitespace())
            .map(|item| {
                let (name, value) = item.split_once('=').expect("name=value");
                let value = match (self.var(name).kind, value) {
                    (Kind::Real, x) => Value::R(x.parse().expect("a number")),
                    (_, "true") => Value::I(1),
                    (_, "false") => Value::I(0),
                    (_, k) => Value::I(k.parse().expect("an integer")),
                };
                (name.to_string(), value)
            })
            .collect();
        if !listed.is_empty() {
            assert!(
                self.try_impossible(i, &listed),
                "{}: {listed:?} no longer fails initialization: {:?}",
                self.model,
                i.log.lines()
            );
            return Some(listed);
        }
        let params: Vec<&Var> = self
            .vars
            .iter()
            .filter(|v| v.causality == "parameter")
            .collect();
        let mut switches: Vec<Option<(String, Value)>> = vec![None];
        for p in params.iter().filter(|p| p.kind != Kind::Real) {
            let (lo, hi) = (p.min.unwrap_or(0.0) as c_int, p.max.unwrap_or(1.0) as c_int);
            if hi - lo <= 4 {
                switches.extend((lo..=hi).map(|k| Some((p.name.clone(), Value::I(k)))));
            }
        }
        for switch in &switches {
            for p in params.iter().filter(|p| p.kind == Kind::Real) {
                let start = p.start.unwrap_or(1.0);
                for x in [p.min, p.max, Some(start * 1e4), Some(start * 1e-4)]
                    .into_iter()
                    .flatten()
                {
                    let mut set: Vec<_> = switch.iter().cloned().collect();
                    set.push((p.name.clone(), Value::R(x)));
                    if self.try_impossible(i, &set) {
                        return Some(set);
                    }
                }
            }
        }
        None
    }

    /// A step size the model discards from a normal initialization, if any.
    fn find_discarded_step(&self, i: &Instance) -> Option<f64> {
        [2e3, 1e6, 1e12].into_iter().find(|&h| {
            self.reset(i);
            i.initialize();
            i.do_step(0.0, h) == DISCARD
        })
    }

    /// Resets `i` and drives it into `state`; false if the FMU cannot reach it.
    fn drive(&self, i: &Instance, state: State) -> bool {
        assert_eq!(self.reset(i), OK, "{}: {:?}", self.model, i.log.lines());
        let ok = match state {
            State::Instantiated => true,
            State::InitializationMode => i.setup() == OK && i.enter() == OK,
            State::StepComplete => i.setup() == OK && i.enter() == OK && i.exit() == OK,
            State::StepFailed => match self.discarded_step {
                Some(h) => {
                    i.setup() == OK
                        && i.enter() == OK
                        && i.exit() == OK
                        && i.do_step(0.0, h) == DISCARD
                }
                None => false,
            },
            State::Terminated => {
                i.setup() == OK
                    && i.enter() == OK
                    && i.exit() == OK
                    && unsafe { (self.api.fmi2Terminate)(i.c) } == OK
            }
            State::Error => match &self.impossible {
                Some(set) => self.try_impossible(i, set),
                None => false,
            },
        };
        i.log.clear();
        ok
    }
}

fn fmus() -> Vec<Fmu> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/fmu");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}; run `make fmus` first", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "fmu"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no FMU in {}", dir.display());
    paths.iter().map(|p| Fmu::load(p)).collect()
}

/// Counts and checks the cases.
#[derive(Default)]
struct Tally {
    refused: usize,
    accepted: usize,
    no_instance: usize,
    failures: Vec<String>,
}

impl Tally {
    /// One bad call on `i` (already driven into its state): it must return `expected` and log a
    /// line of that status containing `reason` (parts separated by `*`, in any order); `extra` may report a further failure (such as a
    /// value that changed). Then `fmi2Reset` and a normal run must match a fresh instance.
    fn refused(
        &mut self,
        fmu: &Fmu,
        i: &Instance,
        what: &str,
        expected: c_int,
        reason: &str,
        call: impl FnOnce() -> (c_int, Option<String>),
    ) {
        self.refused += 1;
        i.log.clear();
        let (status, extra) = call();
        let lines = i.log.lines();
        let prefix = format!("{expected} ");
        let tag = format!("{} / {what}", fmu.model);
        if status != expected {
            self.failures.push(format!(
                "{tag}: status {status}, expected {expected}; log {lines:?}"
            ));
        } else if !lines
            .iter()
            .any(|l| l.starts_with(&prefix) && reason.split('*').all(|part| l.contains(part)))
        {
            self.failures
                .push(format!("{tag}: no logged reason '{reason}' in {lines:?}"));
        }
        if let Some(e) = extra {
            self.failures.push(format!("{tag}: {e}"));
        }
        self.recovers(fmu, i, &tag);
    }

    fn recovers(&mut self, fmu: &Fmu, i: &Instance, tag: &str) {
        if fmu.reset(i) != OK {
            self.failures
                .push(format!("{tag}: fmi2Reset refused: {:?}", i.log.lines()));
            return;
        }
        match fmu.normal_run(i) {
            Ok(values) if values == fmu.reference => {}
            Ok(values) => self.failures.push(format!(
                "{tag}: after fmi2Reset the run differs from a fresh one: {values:?} vs {:?}",
                fmu.reference
            )),
            Err(e) => self
                .failures
                .push(format!("{tag}: after fmi2Reset the normal run failed: {e}")),
        }
    }

    /// A call that is legal but extreme: any status up to Discard, never a NaN afterwards.
    fn accepted(&mut self, fmu: &Fmu, i: &Instance, what: &str, call: impl FnOnce() -> c_int) {
        self.accepted += 1;
        let tag = format!("{} / {what}", fmu.model);
        let status = call();
        if status > DISCARD {
            self.failures
                .push(format!("{tag}: status {status}: {:?}", i.log.lines()));
        } else if status <= WARNING {
            if let Err(e) = fmu.snapshot(i) {
                self.failures.push(format!("{tag}: {e}"));
            }
        }
        self.recovers(fmu, i, &tag);
    }
}

/// A getter's value array: NULL when the case asks for one, else the buffer.
fn out_ptr<T>(buf: &mut [T], null: bool) -> *mut T {
    if null {
        null_mut()
    } else {
        buf.as_mut_ptr()
    }
}

/// A setter's value array: NULL when the case asks for one, else the buffer.
fn in_ptr<T>(buf: &[T], null: bool) -> *const T {
    if null {
        std::ptr::null()
    } else {
        buf.as_ptr()
    }
}

fn values_beyond(v: &Var) -> Vec<(f64, &'static str)> {
    let mut out = Vec::new();
    let int = v.kind == Kind::Integer;
    if let Some(min) = v.min {
        let step = if int { 1.0 } else { min.abs().max(1.0) };
        out.push((min - step, "is below its minimum"));
        if !int {
            out.push((next_down(min), "is below its minimum"));
            out.push((-f64::MAX, "is below its minimum"));
        }
    }
    if let Some(max) = v.max {
        let step = if int { 1.0 } else { max.abs().max(1.0) };
        out.push((max + step, "is above its maximum"));
        if !int {
            out.push((next_up(max), "is above its maximum"));
            out.push((f64::MAX, "is above its maximum"));
        }
    }
    if int {
        // Only what a C int can carry.
        out.retain(|(x, _)| *x >= c_int::MIN as f64 && *x <= c_int::MAX as f64);
    }
    out
}

fn next_up(x: f64) -> f64 {
    if x == 0.0 {
        return f64::from_bits(1);
    }
    f64::from_bits(if x > 0.0 {
        x.to_bits() + 1
    } else {
        x.to_bits() - 1
    })
}

fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

/// Calls a setter of `kind` with one value reference and one valid-typed value.
unsafe fn set_one(fmu: &Fmu, i: &Instance, kind: Kind, vr: u32, x: f64) -> c_int {
    let api = &fmu.api;
    let text = CString::new("x").unwrap();
    match kind {
        Kind::Real => (api.fmi2SetReal)(i.c, &vr, 1, &x),
        Kind::Integer => (api.fmi2SetInteger)(i.c, &vr, 1, &(x as c_int)),
        Kind::Boolean => (api.fmi2SetBoolean)(i.c, &vr, 1, &(x as c_int)),
        Kind::String => (api.fmi2SetString)(i.c, &vr, 1, &text.as_ptr()),
    }
}

unsafe fn get_one(fmu: &Fmu, i: &Instance, kind: Kind, vr: u32) -> c_int {
    let api = &fmu.api;
    let (mut x, mut k, mut s) = (0.0, 0, null::<c_char>());
    match kind {
        Kind::Real => (api.fmi2GetReal)(i.c, &vr, 1, &mut x),
        Kind::Integer => (api.fmi2GetInteger)(i.c, &vr, 1, &mut k),
        Kind::Boolean => (api.fmi2GetBoolean)(i.c, &vr, 1, &mut k),
        Kind::String => (api.fmi2GetString)(i.c, &vr, 1, &mut s),
    }
}

/// Getters and setters with raw arrays, for the NULL cases: `(name, call(c, vr, n, value))`.
type RawCall<'a> = (String, Box<dyn Fn(*const u32, usize, bool) -> c_int + 'a>);

fn raw_array_calls<'a>(fmu: &'a Fmu, i: &'a Instance) -> Vec<RawCall<'a>> {
    let api = &fmu.api;
    let c = i.c;
    let mut calls: Vec<RawCall> = Vec::new();
    // `value_null` chooses a NULL value array; otherwise a valid buffer of 4 elements.
    calls.push((
        "fmi2SetReal".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let buf = [0.0f64; 4];
            (api.fmi2SetReal)(c, vr, n, in_ptr(&buf, value_null))
        }),
    ));
    calls.push((
        "fmi2SetInteger".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let buf = [0 as c_int; 4];
            (api.fmi2SetInteger)(c, vr, n, in_ptr(&buf, value_null))
        }),
    ));
    calls.push((
        "fmi2SetBoolean".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let buf = [0 as c_int; 4];
            (api.fmi2SetBoolean)(c, vr, n, in_ptr(&buf, value_null))
        }),
    ));
    calls.push((
        "fmi2SetString".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let s = CString::new("x").unwrap();
            let buf = [s.as_ptr(); 4];
            (api.fmi2SetString)(c, vr, n, in_ptr(&buf, value_null))
        }),
    ));
    calls.push((
        "fmi2GetReal".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let mut buf = [0.0f64; 4];
            (api.fmi2GetReal)(c, vr, n, out_ptr(&mut buf, value_null))
        }),
    ));
    calls.push((
        "fmi2GetInteger".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let mut buf = [0 as c_int; 4];
            (api.fmi2GetInteger)(c, vr, n, out_ptr(&mut buf, value_null))
        }),
    ));
    calls.push((
        "fmi2GetBoolean".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let mut buf = [0 as c_int; 4];
            (api.fmi2GetBoolean)(c, vr, n, out_ptr(&mut buf, value_null))
        }),
    ));
    calls.push((
        "fmi2GetString".into(),
        Box::new(move |vr, n, value_null| unsafe {
            let mut buf = [null::<c_char>(); 4];
            (api.fmi2GetString)(c, vr, n, out_ptr(&mut buf, value_null))
        }),
    ));
    calls
}

/// A call with valid arguments to every function whose legality depends on the state, and the
/// states FMI 2.0.4 section 4.2.4 allows it in. Functions allowed in every reachable state
/// (fmi2Reset, fmi2SetDebugLogging, the FMU-state functions) have no illegal state to test.
type OrderCall<'a> = (&'static str, u32, Box<dyn Fn(&Instance) -> c_int + 'a>);

fn order_calls(fmu: &Fmu) -> Vec<OrderCall<'_>> {
    use State::*;
    let api = &fmu.api;
    let setup_only = bit(Instantiated);
    let get = bit(InitializationMode)
        | bit(StepComplete)
        | bit(StepFailed)
        | bit(Terminated)
        | bit(Error);
    let set = bit(Instantiated) | bit(InitializationMode) | bit(StepComplete);
    let status = bit(StepComplete) | bit(StepFailed) | bit(Terminated);
    let mut calls: Vec<OrderCall> = vec![
        (
            "fmi2SetupExperiment",
            setup_only,
            Box::new(|i: &Instance| i.setup()),
        ),
        (
            "fmi2EnterInitializationMode",
            setup_only,
            Box::new(|i: &Instance| i.enter()),
        ),
        (
            "fmi2ExitInitializationMode",
            bit(InitializationMode),
            Box::new(|i: &Instance| i.exit()),
        ),
        (
            "fmi2Terminate",
            bit(StepComplete) | bit(StepFailed),
            Box::new(move |i: &Instance| unsafe { (api.fmi2Terminate)(i.c) }),
        ),
        (
            "fmi2DoStep",
            bit(StepComplete),
            Box::new(|i: &Instance| i.do_step(0.0, H)),
        ),
        (
            "fmi2GetStatus",
            status,
            Box::new(move |i: &Instance| unsafe { (api.fmi2GetStatus)(i.c, 0, &mut 0) }),
        ),
        (
            "fmi2GetRealStatus",
            status,
            Box::new(move |i: &Instance| unsafe { (api.fmi2GetRealStatus)(i.c, 2, &mut 0.0) }),
        ),
        (
            "fmi2GetIntegerStatus",
            status,
            Box::new(move |i: &Instance| unsafe { (api.fmi2GetIntegerStatus)(i.c, 0, &mut 0) }),
        ),
        (
            "fmi2GetBooleanStatus",
            status,
            Box::new(move |i: &Instance| unsafe { (api.fmi2GetBooleanStatus)(i.c, 3, &mut 0) }),
        ),
        (
            "fmi2GetStringStatus",
            status,
            Box::new(move |i: &Instance| unsafe { (api.fmi2GetStringStatus)(i.c, 0, &mut null()) }),
        ),
    ];
    for kind in KINDS {
        // A real variable of the kind where there is one; an empty call otherwise (the state is
        // checked before the arguments).
        let first = fmu.of(kind).next().map(|v| v.vr);
        let input = fmu
            .of(kind)
            .find(|v| v.causality == "input")
            .map(|v| (v.vr, v.start.unwrap_or(0.0)));
        let (get_name, set_name) = match kind {
            Kind::Real => ("fmi2GetReal", "fmi2SetReal"),
            Kind::Integer => ("fmi2GetInteger", "fmi2SetInteger"),
            Kind::Boolean => ("fmi2GetBoolean", "fmi2SetBoolean"),
            Kind::String => ("fmi2GetString", "fmi2SetString"),
        };
        calls.push((
            get_name,
            get,
            Box::new(move |i: &Instance| unsafe {
                match first {
                    Some(vr) => get_one(fmu, i, kind, vr),
                    None => get_empty(fmu, i, kind),
                }
            }),
        ));
        calls.push((
            set_name,
            set,
            Box::new(move |i: &Instance| unsafe {
                match input {
                    Some((vr, x)) => set_one(fmu, i, kind, vr, x),
                    None => set_empty(fmu, i, kind),
                }
            }),
        ));
    }
    calls
}

unsafe fn get_empty(fmu: &Fmu, i: &Instance, kind: Kind) -> c_int {
    let api = &fmu.api;
    match kind {
        Kind::Real => (api.fmi2GetReal)(i.c, null(), 0, null_mut()),
        Kind::Integer => (api.fmi2GetInteger)(i.c, null(), 0, null_mut()),
        Kind::Boolean => (api.fmi2GetBoolean)(i.c, null(), 0, null_mut()),
        Kind::String => (api.fmi2GetString)(i.c, null(), 0, null_mut()),
    }
}

unsafe fn set_empty(fmu: &Fmu, i: &Instance, kind: Kind) -> c_int {
    let api = &fmu.api;
    match kind {
        Kind::Real => (api.fmi2SetReal)(i.c, null(), 0, null()),
        Kind::Integer => (api.fmi2SetInteger)(i.c, null(), 0, null()),
        Kind::Boolean => (api.fmi2SetBoolean)(i.c, null(), 0, null()),
        Kind::String => (api.fmi2SetString)(i.c, null(), 0, null()),
    }
}

fn kind_setter(kind: Kind) -> &'static str {
    match kind {
        Kind::Real => "fmi2SetReal",
        Kind::Integer => "fmi2SetInteger",
        Kind::Boolean => "fmi2SetBoolean",
        Kind::String => "fmi2SetString",
    }
}

fn kind_getter(kind: Kind) -> &'static str {
    match kind {
        Kind::Real => "fmi2GetReal",
        Kind::Integer => "fmi2GetInteger",
        Kind::Boolean => "fmi2GetBoolean",
        Kind::String => "fmi2GetString",
    }
}

fn values(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    for v in fmu.vars.clone() {
        let settable = v.settable_in();
        for state in [
            State::Instantiated,
            State::InitializationMode,
            State::StepComplete,
        ] {
            if !fmu.drive(i, state) {
                continue;
            }
            if settable & bit(state) == 0 {
                // Outputs, calculated parameters, fixed parameters after initialization.
                let x = v.start.unwrap_or(0.0);
                t.refused(
                    fmu,
                    i,
                    &format!("{state:?}: set {} ({})", v.name, v.causality),
                    ERROR,
                    &format!(
                        "{}: {}*cannot be set in state {state:?}",
                        kind_setter(v.kind),
                        v.name
                    ),
                    || (unsafe { set_one(fmu, i, v.kind, v.vr, x) }, None),
                );
                fmu.drive(i, state);
                continue;
            }
            let mut bad: Vec<(f64, &str)> = values_beyond(&v);
            if v.kind == Kind::Real {
                bad.extend([
                    (f64::NAN, "is not finite"),
                    (f64::INFINITY, "is not finite"),
                    (f64::NEG_INFINITY, "is not finite"),
                    (-f64::NAN, "is not finite"),
                ]);
            }
            for (x, reason) in bad {
                // In StepComplete an input's old value must be kept; a good value set in the
                // same call must not be applied either (all or nothing).
                let check_kept = state == State::StepComplete && v.kind == Kind::Real;
                t.refused(
                    fmu,
                    i,
                    &format!("{state:?}: set {} = {x}", v.name),
                    ERROR,
                    &format!("{}: {} = *{reason}", kind_setter(v.kind), v.name),
                    || {
                        let before = check_kept.then(|| i.get_real(&[v.vr]).1[0]);
                        let s = unsafe { set_one(fmu, i, v.kind, v.vr, x) };
                        let extra = before.and_then(|b| {
                            let first = fmu.of(Kind::Real).find(|o| o.settable_in() & bit(state) != 0)?;
                            let old_first = i.get_real(&[first.vr]).1[0];
                            let s2 = i.set_real(&[first.vr, v.vr], &[old_first + 1.0, x]);
                            let (after, first_after) =
                                (i.get_real(&[v.vr]).1[0], i.get_real(&[first.vr]).1[0]);
                            (s2 != ERROR
                                || after.to_bits() != b.to_bits()
                                || first_after.to_bits() != old_first.to_bits())
                            .then(|| {
                                format!(
                                    "refused value changed something: {b} -> {after}, {} {old_first} -> {first_after}",
                                    first.name
                                )
                            })
                        });
                        (s, extra)
                    },
                );
                fmu.drive(i, state);
            }
        }
    }

    // Extreme but valid values of inputs, then a step: finite outputs, no error.
    for v in fmu.of(Kind::Real).filter(|v| v.causality == "input") {
        let mut xs: Vec<f64> = vec![v.min.unwrap_or(-1e300), v.max.unwrap_or(1e300), 0.0];
        xs.extend([-1e-300, 1e-300]);
        xs.retain(|x| v.min.is_none_or(|m| *x >= m) && v.max.is_none_or(|m| *x <= m));
        for x in xs {
            fmu.drive(i, State::StepComplete);
            t.accepted(fmu, i, &format!("input {} = {x:e}, step", v.name), || {
                let s = i.set_real(&[v.vr], &[x]);
                if s != OK {
                    return ERROR;
                }
                i.do_step(0.0, H)
            });
        }
    }
}

fn references(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    for kind in KINDS {
        let n = fmu.count(kind);
        for vr in [n, n + 1, n + 1000, u32::MAX] {
            for state in [State::Instantiated, State::StepComplete] {
                fmu.drive(i, state);
                t.refused(
                    fmu,
                    i,
                    &format!("{state:?}: {} vr {vr}", kind_setter(kind)),
                    ERROR,
                    &format!("{vr} is not the value reference of a {kind:?} variable"),
                    || (unsafe { set_one(fmu, i, kind, vr, 0.0) }, None),
                );
            }
            fmu.drive(i, State::StepComplete);
            t.refused(
                fmu,
                i,
                &format!("{} vr {vr}", kind_getter(kind)),
                ERROR,
                &format!("{vr} is not the value reference of a {kind:?} variable"),
                || (unsafe { get_one(fmu, i, kind, vr) }, None),
            );
        }
    }
}

fn null_pointers(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    let api = &fmu.api;
    let c = i.c;
    // Arrays: NULL with n > 0 is refused, NULL with n = 0 is an empty call.
    for (name, call) in raw_array_calls(fmu, i) {
        let vr0 = [0u32; 4];
        for (what, vr_null, value_null, n) in [
            ("vr NULL", true, false, 1),
            ("value NULL", false, true, 1),
            ("both NULL", true, true, 1),
            ("both NULL, n = 4", true, true, 4),
            ("both NULL, n = usize::MAX", true, true, usize::MAX),
        ] {
            fmu.drive(i, State::StepComplete);
            let vr = if vr_null { null() } else { vr0.as_ptr() };
            t.refused(
                fmu,
                i,
                &format!("{name}: {what}"),
                ERROR,
                &format!("{name}: vr and value must not be NULL"),
                || (call(vr, n, value_null), None),
            );
        }
        fmu.drive(i, State::StepComplete);
        t.accepted(fmu, i, &format!("{name}: n = 0 with NULL arrays"), || {
            call(null(), 0, true)
        });
    }
    let logcalls = CString::new("logCalls").unwrap();
    let bogus = CString::new("logNothingAtAll").unwrap();
    type Case<'a> = (&'static str, &'static str, Box<dyn Fn() -> c_int + 'a>);
    let cases: Vec<Case> = vec![
        (
            "fmi2SetString: a NULL string",
            "fmi2SetString: a string value must not be NULL",
            Box::new(|| unsafe { (api.fmi2SetString)(c, [0u32].as_ptr(), 1, [null()].as_ptr()) }),
        ),
        (
            "fmi2SetDebugLogging: categories NULL",
            "fmi2SetDebugLogging: categories must not be NULL",
            Box::new(|| unsafe { (api.fmi2SetDebugLogging)(c, 1, 1, null()) }),
        ),
        (
            "fmi2SetDebugLogging: a NULL category",
            "fmi2SetDebugLogging: a category name must not be NULL",
            Box::new(|| unsafe {
                (api.fmi2SetDebugLogging)(c, 1, 2, [logcalls.as_ptr(), null()].as_ptr())
            }),
        ),
        (
            "fmi2SetDebugLogging: unknown category",
            "unknown log category 'logNothingAtAll'",
            Box::new(|| unsafe { (api.fmi2SetDebugLogging)(c, 1, 1, [bogus.as_ptr()].as_ptr()) }),
        ),
        (
            "fmi2GetFMUstate: NULL",
            "fmi2GetFMUstate: FMUstate must not be NULL",
            Box::new(|| unsafe { (api.fmi2GetFMUstate)(c, null_mut()) }),
        ),
        (
            "fmi2SetFMUstate: NULL",
            "fmi2SetFMUstate: unknown FMU state",
            Box::new(|| unsafe { (api.fmi2SetFMUstate)(c, null_mut()) }),
        ),
        (
            "fmi2FreeFMUstate: NULL",
            "fmi2FreeFMUstate: FMUstate must not be NULL",
            Box::new(|| unsafe { (api.fmi2FreeFMUstate)(c, null_mut()) }),
        ),
        (
            "fmi2SerializedFMUstateSize: state NULL",
            "fmi2SerializedFMUstateSize: unknown FMU state",
            Box::new(|| unsafe { (api.fmi2SerializedFMUstateSize)(c, null_mut(), &mut 0) }),
        ),
        (
            "fmi2SerializedFMUstateSize: size NULL",
            "fmi2SerializedFMUstateSize: size must not be NULL",
            Box::new(|| unsafe {
                with_state(api, c, |s| {
                    (api.fmi2SerializedFMUstateSize)(c, s, null_mut())
                })
            }),
        ),
        (
            "fmi2SerializeFMUstate: state NULL",
            "fmi2SerializeFMUstate: unknown FMU state",
            Box::new(|| unsafe {
                let mut buf = [0 as c_char; 64];
                (api.fmi2SerializeFMUstate)(c, null_mut(), buf.as_mut_ptr(), buf.len())
            }),
        ),
        (
            "fmi2SerializeFMUstate: bytes NULL",
            "fmi2SerializeFMUstate: serializedState must not be NULL",
            Box::new(|| unsafe {
                with_state(api, c, |s| {
                    (api.fmi2SerializeFMUstate)(c, s, null_mut(), 64)
                })
            }),
        ),
        (
            "fmi2SerializeFMUstate: too small",
            "is too small, the state needs",
            Box::new(|| unsafe {
                with_state(api, c, |s| {
                    let mut buf = [0 as c_char; 4];
                    (api.fmi2SerializeFMUstate)(c, s, buf.as_mut_ptr(), buf.len())
                })
            }),
        ),
        (
            "fmi2DeSerializeFMUstate: bytes NULL",
            "fmi2DeSerializeFMUstate: serializedState and FMUstate must not be NULL",
            Box::new(|| unsafe { (api.fmi2DeSerializeFMUstate)(c, null(), 16, &mut null_mut()) }),
        ),
        (
            "fmi2DeSerializeFMUstate: state NULL",
            "fmi2DeSerializeFMUstate: serializedState and FMUstate must not be NULL",
            Box::new(|| unsafe {
                (api.fmi2DeSerializeFMUstate)(c, [0 as c_char; 16].as_ptr(), 16, null_mut())
            }),
        ),
        (
            "fmi2DeSerializeFMUstate: junk",
            "not a serialized FMU state of this FMU",
            Box::new(|| unsafe {
                let mut s = null_mut();
                (api.fmi2DeSerializeFMUstate)(c, [7 as c_char; 16].as_ptr(), 16, &mut s)
            }),
        ),
        (
            "fmi2DeSerializeFMUstate: truncated",
            "fmi2DeSerializeFMUstate: corrupt state",
            Box::new(|| unsafe {
                with_state(api, c, |s| {
                    let bytes = serialize(api, c, s);
                    let mut out = null_mut();
                    (api.fmi2DeSerializeFMUstate)(c, bytes.as_ptr(), bytes.len() / 2, &mut out)
                })
            }),
        ),
        (
            "fmi2SetFMUstate: a freed state",
            "fmi2SetFMUstate: unknown FMU state",
            Box::new(|| unsafe {
                let mut s = null_mut();
                (api.fmi2GetFMUstate)(c, &mut s);
                // Our own pointer, freed: the FMU must recognize it without dereferencing it.
                let freed = s;
                (api.fmi2FreeFMUstate)(c, &mut s);
                (api.fmi2SetFMUstate)(c, freed)
            }),
        ),
        (
            "fmi2GetStatus: value NULL",
            "fmi2GetStatus: value must not be NULL",
            Box::new(|| unsafe { (api.fmi2GetStatus)(c, 0, null_mut()) }),
        ),
        (
            "fmi2GetRealStatus: value NULL",
            "fmi2GetRealStatus: value must not be NULL",
            Box::new(|| unsafe { (api.fmi2GetRealStatus)(c, 2, null_mut()) }),
        ),
        (
            "fmi2GetIntegerStatus: value NULL",
            "fmi2GetIntegerStatus: value must not be NULL",
            Box::new(|| unsafe { (api.fmi2GetIntegerStatus)(c, 0, null_mut()) }),
        ),
        (
            "fmi2GetBooleanStatus: value NULL",
            "fmi2GetBooleanStatus: value must not be NULL",
            Box::new(|| unsafe { (api.fmi2GetBooleanStatus)(c, 3, null_mut()) }),
        ),
        (
            "fmi2GetStringStatus: value NULL",
            "fmi2GetStringStatus: value must not be NULL",
            Box::new(|| unsafe { (api.fmi2GetStringStatus)(c, 0, null_mut()) }),
        ),
        (
            "fmi2GetDirectionalDerivative: all NULL",
            "fmi2GetDirectionalDerivative: vUnknown_ref, vKnown_ref, dvKnown or dvUnknown must not be NULL",
            Box::new(|| unsafe {
                (api.fmi2GetDirectionalDerivative)(c, null(), 1, null(), 1, null(), null_mut())
            }),
        ),
        (
            "fmi2SetRealInputDerivatives: all NULL",
            "fmi2SetRealInputDerivatives: not supported",
            Box::new(|| unsafe { (api.fmi2SetRealInputDerivatives)(c, null(), 1, null(), null()) }),
        ),
        (
            "fmi2GetRealOutputDerivatives: all NULL",
            "fmi2GetRealOutputDerivatives: not supported",
            Box::new(|| unsafe {
                (api.fmi2GetRealOutputDerivatives)(c, null(), 1, null(), null_mut())
            }),
        ),
        (
            "fmi2CancelStep",
            "fmi2CancelStep: not supported",
            Box::new(|| unsafe { (api.fmi2CancelStep)(c) }),
        ),
    ];
    for (what, reason, call) in &cases {
        fmu.drive(i, State::StepComplete);
        t.refused(fmu, i, what, ERROR, reason, || (call(), None));
    }
    // Status kinds the FMU cannot report: Discard, with a reason (FMI 2.0.4 section 4.2.3).
    for kind in [0, 1, 3, 99, -1] {
        fmu.drive(i, State::StepComplete);
        t.refused(
            fmu,
            i,
            &format!("fmi2GetRealStatus kind {kind}"),
            DISCARD,
            &format!("status kind {kind} is not available"),
            || (unsafe { (api.fmi2GetRealStatus)(c, kind, &mut 0.0) }, None),
        );
    }
    // Freeing a NULL FMU state is a no-op (FMI 2.0.4 section 2.1.8).
    fmu.drive(i, State::StepComplete);
    t.accepted(fmu, i, "fmi2FreeFMUstate of a NULL state", || unsafe {
        (api.fmi2FreeFMUstate)(c, &mut null_mut())
    });
}

/// Runs `f` on a fresh FMU state of `c` and frees it.
unsafe fn with_state(api: &Api, c: Component, f: impl FnOnce(*mut c_void) -> c_int) -> c_int {
    let mut s = null_mut();
    assert_eq!((api.fmi2GetFMUstate)(c, &mut s), OK);
    let status = f(s);
    assert_eq!((api.fmi2FreeFMUstate)(c, &mut s), OK);
    status
}

unsafe fn serialize(api: &Api, c: Component, s: *mut c_void) -> Vec<c_char> {
    let mut size = 0;
    assert_eq!((api.fmi2SerializedFMUstateSize)(c, s, &mut size), OK);
    let mut bytes = vec![0 as c_char; size];
    assert_eq!(
        (api.fmi2SerializeFMUstate)(c, s, bytes.as_mut_ptr(), size),
        OK
    );
    bytes
}

/// Serialized states whose clock fields are corrupt (FMI leaves the byte format to the FMU; ours
/// is magic, format version, then postcard: GUID string, time, start time, optional stop time).
fn corrupt_clocks(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    let api = &fmu.api;
    let time_at = 10 + 1 + fmu.guid.len();
    assert!(fmu.guid.len() < 128, "one-byte length prefix");
    for (what, offset, value) in [
        ("time NaN", time_at, f64::NAN),
        ("startTime NaN", time_at + 8, f64::NAN),
        ("startTime inf", time_at + 8, f64::INFINITY),
        ("stopTime NaN", time_at + 17, f64::NAN),
        ("stopTime -inf", time_at + 17, f64::NEG_INFINITY),
        ("stopTime before startTime", time_at + 17, -1.0),
    ] {
        fmu.drive(i, State::Instantiated);
        assert_eq!(
            unsafe { (api.fmi2SetupExperiment)(i.c, 0, 0.0, 0.0, 1, 1.0) },
            OK
        );
        let mut data = unsafe {
            let mut s = null_mut();
            (api.fmi2GetFMUstate)(i.c, &mut s);
            let data = serialize(api, i.c, s);
            (api.fmi2FreeFMUstate)(i.c, &mut s);
            data
        };
        assert_eq!(data[time_at + 16], 1, "stop time present");
        for (k, b) in value.to_le_bytes().iter().enumerate() {
            data[offset + k] = *b as c_char;
        }
        reseal(&mut data);
        t.refused(
            fmu,
            i,
            &format!("fmi2DeSerializeFMUstate with {what}"),
            ERROR,
            "fmi2DeSerializeFMUstate: corrupt state",
            || unsafe {
                let mut s = null_mut();
                let status = (api.fmi2DeSerializeFMUstate)(i.c, data.as_ptr(), data.len(), &mut s);
                (status, (!s.is_null()).then(|| "a state was created".into()))
            },
        );
    }
}

/// Recomputes the trailing FNV-1a checksum of a serialized state after an edit, so that the
/// checks behind it (a state crafted with a valid checksum) are reached.
fn reseal(data: &mut [c_char]) {
    let n = data.len() - 8;
    let sum = data[..n].iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b as u8)).wrapping_mul(0x100_0000_01b3)
    });
    for (k, b) in sum.to_le_bytes().iter().enumerate() {
        data[n + k] = *b as c_char;
    }
}

/// Any byte changed without resealing: refused by the checksum.
fn unsealed_edits(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    let api = &fmu.api;
    fmu.drive(i, State::StepComplete);
    let data = unsafe {
        let mut s = null_mut();
        (api.fmi2GetFMUstate)(i.c, &mut s);
        let b = serialize(api, i.c, s);
        (api.fmi2FreeFMUstate)(i.c, &mut s);
        b
    };
    // Past the header: every 16th byte, each checksum byte, and the last payload byte.
    let positions: Vec<usize> = (10..data.len())
        .step_by(16)
        .chain(data.len() - 9..data.len())
        .collect();
    for at in positions {
        let mut corrupt = data.clone();
        corrupt[at] ^= 0x20;
        fmu.drive(i, State::StepComplete);
        t.refused(
            fmu,
            i,
            &format!("fmi2DeSerializeFMUstate with byte {at} changed"),
            ERROR,
            "fmi2DeSerializeFMUstate: corrupt state: checksum mismatch",
            || unsafe {
                let mut s = null_mut();
                let status =
                    (api.fmi2DeSerializeFMUstate)(i.c, corrupt.as_ptr(), corrupt.len(), &mut s);
                (status, (!s.is_null()).then(|| "a state was created".into()))
            },
        );
    }
}

/// A serialized state in which one Real variable's bytes became NaN or infinite, or an Integer
/// parameter left its range: values `fmi2SetXXX` would refuse must not come in through a state.
fn corrupt_values(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    let api = &fmu.api;
    fmu.drive(i, State::StepComplete);
    let bytes: Vec<u8> = unsafe {
        let mut s = null_mut();
        (api.fmi2GetFMUstate)(i.c, &mut s);
        let b = serialize(api, i.c, s);
        (api.fmi2FreeFMUstate)(i.c, &mut s);
        b.iter().map(|&c| c as u8).collect()
    };
    // Variables whose current value occurs exactly once in the bytes can be located there.
    let located: Vec<(&Var, usize)> = fmu
        .of(Kind::Real)
        .filter_map(|v| {
            let x = i.real(v.vr).to_le_bytes();
            let at: Vec<usize> = (0..bytes.len().saturating_sub(7))
                .filter(|&k| bytes[k..k + 8] == x)
                .collect();
            (at.len() == 1).then(|| (v, at[0]))
        })
        .collect();
    if located.is_empty() {
        // PassThrough's y always equals u: no Real occurs once, so none can be located.
        println!(
            "{}: no Real value occurs once in the state; value corruption untested",
            fmu.model
        );
        return;
    }
    for (v, at) in located.iter().take(4) {
        for bad in [f64::NAN, f64::INFINITY] {
            let mut corrupt = bytes.clone();
            corrupt[*at..at + 8].copy_from_slice(&bad.to_le_bytes());
            let mut corrupt: Vec<c_char> = corrupt.iter().map(|&b| b as c_char).collect();
            reseal(&mut corrupt);
            fmu.drive(i, State::StepComplete);
            t.refused(
                fmu,
                i,
                &format!("fmi2DeSerializeFMUstate with {} = {bad}", v.name),
                ERROR,
                &format!("fmi2DeSerializeFMUstate: corrupt state: {} = {bad}", v.name),
                || unsafe {
                    let mut s = null_mut();
                    let status =
                        (api.fmi2DeSerializeFMUstate)(i.c, corrupt.as_ptr(), corrupt.len(), &mut s);
                    (status, (!s.is_null()).then(|| "a state was created".into()))
                },
            );
        }
    }
}

/// A state of every other FMU is refused by this one.
fn foreign_states(fmus: &[Fmu], t: &mut Tally) {
    for fmu in fmus {
        let i = fmu.instance();
        for other in fmus.iter().filter(|o| o.model != fmu.model) {
            let j = other.instance();
            j.initialize();
            let data = unsafe {
                let mut s = null_mut();
                (other.api.fmi2GetFMUstate)(j.c, &mut s);
                let data = serialize(&other.api, j.c, s);
                (other.api.fmi2FreeFMUstate)(j.c, &mut s);
                data
            };
            fmu.drive(&i, State::StepComplete);
            t.refused(
                fmu,
                &i,
                &format!("fmi2DeSerializeFMUstate of a {} state", other.model),
                ERROR,
                &format!("the state is of GUID {}", other.guid),
                || unsafe {
                    let mut s = null_mut();
                    let status =
                        (fmu.api.fmi2DeSerializeFMUstate)(i.c, data.as_ptr(), data.len(), &mut s);
                    (status, (!s.is_null()).then(|| "a state was created".into()))
                },
            );
        }
        // A state of another instance of the same FMU.
        let k = fmu.instance();
        k.initialize();
        let mut theirs = null_mut();
        unsafe { (fmu.api.fmi2GetFMUstate)(k.c, &mut theirs) };
        fmu.drive(&i, State::StepComplete);
        t.refused(
            fmu,
            &i,
            "fmi2SetFMUstate with another instance's state",
            ERROR,
            "fmi2SetFMUstate: unknown FMU state",
            || (unsafe { (fmu.api.fmi2SetFMUstate)(i.c, theirs) }, None),
        );
        fmu.drive(&i, State::StepComplete);
        t.refused(
            fmu,
            &i,
            "fmi2FreeFMUstate with another instance's state",
            ERROR,
            "fmi2FreeFMUstate: unknown FMU state",
            || {
                (
                    unsafe { (fmu.api.fmi2FreeFMUstate)(i.c, &mut theirs) },
                    None,
                )
            },
        );
        unsafe { assert_eq!((fmu.api.fmi2FreeFMUstate)(k.c, &mut theirs), OK) };
    }
}

fn instantiation(fmu: &Fmu, t: &mut Tally) {
    let mut wrong = fmu.guid.clone();
    let last = wrong.pop().unwrap();
    wrong.insert(wrong.len() - 1, if last == '0' { '1' } else { '0' });
    let guids = [
        String::new(),
        "{00000000-0000-0000-0000-000000000000}".to_string(),
        format!("{} ", fmu.guid),
        fmu.guid.to_lowercase().replace('a', "A").replace('{', "{ "),
        wrong,
        "%s%n%x".repeat(50),
    ];
    for guid in guids.iter().filter(|g| **g != fmu.guid) {
        t.refused += 1;
        match fmu.api.instantiate("bad", guid) {
            Ok(_) => t
                .failures
                .push(format!("{}: GUID '{guid}' accepted", fmu.model)),
            Err(log)
                if !log
                    .lines()
                    .iter()
                    .any(|l| l.starts_with("3 ") && l.contains("wrong GUID")) =>
            {
                t.failures
                    .push(format!("{}: GUID '{guid}': {:?}", fmu.model, log.lines()))
            }
            Err(_) => {}
        }
    }
    // fmuType 0 (Model Exchange) is accepted or refused per model: tests/fmpy/test_model_exchange.py.
    for fmu_type in [2, -1, 99] {
        t.refused += 1;
        match fmu.api.instantiate_as("bad", &fmu.guid, fmu_type) {
            Ok(_) => t
                .failures
                .push(format!("{}: fmuType {fmu_type} accepted", fmu.model)),
            Err(log) if !log.contains(&format!("fmuType {fmu_type} is not supported")) => {
                t.failures.push(format!(
                    "{}: fmuType {fmu_type}: {:?}",
                    fmu.model,
                    log.lines()
                ))
            }
            Err(_) => {}
        }
    }
    t.refused += 1;
    match fmu.api.instantiate("", &fmu.guid) {
        Ok(_) => t
            .failures
            .push(format!("{}: empty name accepted", fmu.model)),
        Err(log) if !log.contains("instanceName must be a non-empty string") => t
            .failures
            .push(format!("{}: empty name: {:?}", fmu.model, log.lines())),
        Err(_) => {}
    }
    // NULL name, GUID and callbacks; a NULL logger with a bad GUID (nowhere to log: NULL only).
    let log = Box::new(Log::default());
    let callbacks = recording_callbacks(&log);
    let name = CString::new("n").unwrap();
    let guid = CString::new(fmu.guid.clone()).unwrap();
    let bad_guid = CString::new("{bad}").unwrap();
    // fmi2CallbackFunctions with every member NULL: no logger, no environment.
    let silent = [0usize; 5];
    let cases: [(
        &str,
        *const c_char,
        *const c_char,
        *const c_void,
        Option<&str>,
    ); 4] = [
        (
            "NULL instanceName",
            null(),
            guid.as_ptr(),
            callbacks,
            Some("instanceName must be a non-empty string"),
        ),
        (
            "NULL fmuGUID",
            name.as_ptr(),
            null(),
            callbacks,
            Some("fmuGUID must not be NULL"),
        ),
        ("NULL functions", name.as_ptr(), guid.as_ptr(), null(), None),
        (
            "NULL logger, wrong GUID",
            name.as_ptr(),
            bad_guid.as_ptr(),
            silent.as_ptr() as *const c_void,
            None,
        ),
    ];
    for (what, n, g, cb, reason) in cases {
        log.clear();
        t.refused += 1;
        let c = unsafe { (fmu.api.fmi2Instantiate)(n, 1, g, null(), cb as *const Callbacks, 0, 0) };
        if !c.is_null() {
            unsafe { (fmu.api.fmi2FreeInstance)(c) };
            t.failures
                .push(format!("{}: {what}: instantiated", fmu.model));
        } else if let Some(reason) = reason {
            if !log.contains(reason) {
                t.failures
                    .push(format!("{}: {what}: {:?}", fmu.model, log.lines()));
            }
        }
    }
    drop(log);
    // Every function with a NULL instance: Error, nothing to log to, no crash.
    let api = &fmu.api;
    let z = null_mut();
    let results = unsafe {
        (api.fmi2FreeInstance)(z);
        [
            (api.fmi2SetDebugLogging)(z, 0, 0, null()),
            (api.fmi2SetupExperiment)(z, 0, 0.0, 0.0, 0, 0.0),
            (api.fmi2EnterInitializationMode)(z),
            (api.fmi2ExitInitializationMode)(z),
            (api.fmi2Terminate)(z),
            (api.fmi2Reset)(z),
            (api.fmi2GetReal)(z, null(), 0, null_mut()),
            (api.fmi2GetInteger)(z, null(), 0, null_mut()),
            (api.fmi2GetBoolean)(z, null(), 0, null_mut()),
            (api.fmi2GetString)(z, null(), 0, null_mut()),
            (api.fmi2SetReal)(z, null(), 0, null()),
            (api.fmi2SetInteger)(z, null(), 0, null()),
            (api.fmi2SetBoolean)(z, null(), 0, null()),
            (api.fmi2SetString)(z, null(), 0, null()),
            (api.fmi2GetFMUstate)(z, &mut null_mut()),
            (api.fmi2SetFMUstate)(z, null_mut()),
            (api.fmi2FreeFMUstate)(z, &mut null_mut()),
            (api.fmi2SerializedFMUstateSize)(z, null_mut(), &mut 0),
            (api.fmi2SerializeFMUstate)(z, null_mut(), null_mut(), 0),
            (api.fmi2DeSerializeFMUstate)(z, null(), 0, &mut null_mut()),
            (api.fmi2GetDirectionalDerivative)(z, null(), 0, null(), 0, null(), null_mut()),
            (api.fmi2SetRealInputDerivatives)(z, null(), 0, null(), null()),
            (api.fmi2GetRealOutputDerivatives)(z, null(), 0, null(), null_mut()),
            (api.fmi2DoStep)(z, 0.0, 1.0, 0),
            (api.fmi2CancelStep)(z),
            (api.fmi2GetStatus)(z, 0, &mut 0),
            (api.fmi2GetRealStatus)(z, 2, &mut 0.0),
            (api.fmi2GetIntegerStatus)(z, 0, &mut 0),
            (api.fmi2GetBooleanStatus)(z, 3, &mut 0),
            (api.fmi2GetStringStatus)(z, 0, &mut null()),
        ]
    };
    t.no_instance += results.len() + 1;
    for (k, s) in results.iter().enumerate() {
        if *s != ERROR {
            t.failures.push(format!(
                "{}: function {k} with a NULL instance returned {s}",
                fmu.model
            ));
        }
    }
}

/// Callbacks whose logger records into `log` (the harness's, rebuilt for raw fmi2Instantiate).
fn recording_callbacks(log: &Log) -> *const c_void {
    // The harness keeps its callbacks private; this is the same `fmi2CallbackFunctions` layout,
    // leaked so that it outlives every call (a handful per test run).
    #[repr(C)]
    struct Raw {
        logger:
            unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char),
        allocate: *const c_void,
        free: *const c_void,
        step_finished: *const c_void,
        environment: *const c_void,
    }
    unsafe extern "C" fn record(
        env: *mut c_void,
        _: *const c_char,
        status: c_int,
        category: *const c_char,
        message: *const c_char,
    ) {
        let log = &*(env as *const Log);
        let text = |p: *const c_char| std::ffi::CStr::from_ptr(p).to_string_lossy().into_owned();
        log.0
            .lock()
            .unwrap()
            .push(format!("{status} {}: {}", text(category), text(message)));
    }
    Box::leak(Box::new(Raw {
        logger: record,
        allocate: null(),
        free: null(),
        step_finished: null(),
        environment: log as *const Log as *const c_void,
    })) as *const Raw as *const c_void
}

fn call_order(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    for state in STATES {
        if !fmu.drive(i, state) {
            println!(
                "{}: state {state:?} is not reachable; its illegal calls are untested",
                fmu.model
            );
            continue;
        }
        for (name, allowed, call) in order_calls(fmu) {
            if allowed & bit(state) != 0 {
                continue;
            }
            fmu.drive(i, state);
            t.refused(
                fmu,
                i,
                &format!("{name} in {state:?}"),
                ERROR,
                &format!("{name}: illegal call in state {state:?}"),
                || (call(i), None),
            );
        }
    }
}

fn steps(fmu: &Fmu, t: &mut Tally, i: &Instance) {
    let bad_sizes = [
        0.0,
        -0.0,
        -H,
        -1.0,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        -f64::from_bits(1),
    ];
    for h in bad_sizes {
        fmu.drive(i, State::StepComplete);
        t.refused(
            fmu,
            i,
            &format!("fmi2DoStep step {h}"),
            ERROR,
            "must be positive and finite",
            || (i.do_step(0.0, h), None),
        );
    }
    for time in [H, -H, 1.0, -1.0, f64::NAN, f64::INFINITY, 1e300] {
        fmu.drive(i, State::StepComplete);
        t.refused(
            fmu,
            i,
            &format!("fmi2DoStep at t = {time}"),
            ERROR,
            "fmi2DoStep: expected currentCommunicationPoint",
            || (i.do_step(time, H), None),
        );
    }
    // A long step must not widen the rounding allowance on the communication point.
    for (time, h) in [(H, 1e10), (1.0, 1e17)] {
        fmu.drive(i, State::StepComplete);
        t.refused(
            fmu,
            i,
            &format!("fmi2DoStep at t = {time} by {h}"),
            ERROR,
            "fmi2DoStep: expected currentCommunicationPoint",
            || (i.do_step(time, h), None),
        );
    }
    // After a step: the old point again, a point in the future.
    for time in [0.0, 3.0 * H] {
        fmu.drive(i, State::StepComplete);
        t.refused(
            fmu,
            i,
            &format!("fmi2DoStep at t = {time} after one step"),
            ERROR,
            "fmi2DoStep: expected currentCommunicationPoint",
            || {
                let first = i.do_step(0.0, H);
                (
                    i.do_step(time, H),
                    (first != OK).then(|| format!("first step {first}")),
                )
            },
        );
    }
    // Past the stop time.
    for h in [2.0 * H, 1.0, 1e300] {
        fmu.drive(i, State::Instantiated);
        t.refused(
            fmu,
            i,
            &format!("step {h} past stopTime {H}"),
            ERROR,
            "would pass the stop time",
            || {
                let s = unsafe { (fmu.api.fmi2SetupExperiment)(i.c, 0, 0.0, 0.0, 1, H) };
                let ok = s == OK && i.enter() == OK && i.exit() == OK;
                (i.do_step(0.0, h), (!ok).then(|| "setup failed".into()))
            },
        );
    }
    // Bad experiments.
    for (what, tol_def, tol, start, stop_def, stop, reason) in [
        ("start NaN", 0, 0.0, f64::NAN, 0, 0.0, "must be finite"),
        ("start inf", 0, 0.0, f64::INFINITY, 0, 0.0, "must be finite"),
        (
            "start -inf",
            0,
            0.0,
            f64::NEG_INFINITY,
            0,
            0.0,
            "must be finite",
        ),
        ("stop NaN", 0, 0.0, 0.0, 1, f64::NAN, "must be finite"),
        ("stop inf", 0, 0.0, 0.0, 1, f64::INFINITY, "must be finite"),
        (
            "stop before start",
            0,
            0.0,
            1.0,
            1,
            0.5,
            "is before startTime",
        ),
        ("tolerance 0", 1, 0.0, 0.0, 0, 0.0, "tolerance positive"),
        ("tolerance -1", 1, -1.0, 0.0, 0, 0.0, "tolerance positive"),
        (
            "tolerance NaN",
            1,
            f64::NAN,
            0.0,
            0,
            0.0,
            "tolerance positive",
        ),
        (
            "tolerance inf",
            1,
            f64::INFINITY,
            0.0,
            0,
            0.0,
            "tolerance positive",
        ),
    ] {
        fmu.drive(i, State::Instantiated);
        t.refused(
            fmu,
            i,
            &format!("fmi2SetupExperiment {what}"),
            ERROR,
            reason,
            || {
                (
                    unsafe {
                        (fmu.api.fmi2SetupExperiment)(i.c, tol_def, tol, start, stop_def, stop)
                    },
                    None,
                )
            },
        );
    }
    // Tiny but valid steps.
    for h in [f64::from_bits(1), 1e-300, 1e-15] {
        fmu.drive(i, State::StepComplete);
        t.accepted(fmu, i, &format!("fmi2DoStep step {h:e}"), || {
            i.do_step(0.0, h)
        });
    }
}

#[test]
fn every_bad_input_is_refused_with_a_reason_and_reset_recovers() {
    let start = std::time::Instant::now();
    let fmus = fmus();
    let mut t = Tally::default();
    for fmu in &fmus {
        assert!(
            fmu.impossible.is_some()
                || !["McKibbenMuscle", "MultiferroicMotor"].contains(&fmu.model.as_str()),
            "{}: no parameter set reaches the Error state",
            fmu.model
        );
        match &fmu.impossible {
            Some(set) => println!("{}: Error state through {set:?}", fmu.model),
            None => println!(
                "{}: no impossible parameter set found; Error state untested",
                fmu.model
            ),
        }
        match fmu.discarded_step {
            Some(h) => println!("{}: StepFailed through a {h} s step", fmu.model),
            None => println!(
                "{}: no step is discarded; StepFailed unreachable",
                fmu.model
            ),
        }
        let i = fmu.instance();
        values(fmu, &mut t, &i);
        references(fmu, &mut t, &i);
        null_pointers(fmu, &mut t, &i);
        call_order(fmu, &mut t, &i);
        steps(fmu, &mut t, &i);
        corrupt_clocks(fmu, &mut t, &i);
        corrupt_values(fmu, &mut t, &i);
        unsealed_edits(fmu, &mut t, &i);
        instantiation(fmu, &mut t);
    }
    foreign_states(&fmus, &mut t);
    println!(
        "bad input: {} FMUs, {} refused calls with logged reasons, {} extreme valid calls, {} calls on a NULL instance, all followed by fmi2Reset and a normal run; {} failures; {:.1} s",
        fmus.len(),
        t.refused,
        t.accepted,
        t.no_instance,
        t.failures.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(
        t.failures.is_empty(),
        "{} of {} cases failed:\n{}",
        t.failures.len(),
        t.refused + t.accepted,
        t.failures.join("\n")
    );
}
