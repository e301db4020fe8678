//! No NaN anywhere in the declared ranges: through the C ABI of EVERY packaged FMU, every parameter
//! and input is drawn from the whole range its modelDescription.xml declares (log-uniform where the
//! range spans decades, the bounds themselves often). Each instance must either refuse
//! initialization with a logged reason, or give finite Real outputs and calculated parameters after
//! initialization and after every step (a step may be discarded, with a logged reason, keeping
//! finite outputs). Every value inside the declared range must be accepted by the setters, and
//! each declared bound alone (every other value at its start) must initialize and step, or be
//! refused for its combination with another variable, which the reason names.
//! Prints how many cases ran (docs/compatibility.md quotes the count).

use crate::common;
#[path = "../common/rng.rs"]
mod rng;
use rng::Rng;

use common::*;
use std::collections::BTreeMap;
use std::ffi::c_int;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Real,
    Integer,
    Boolean,
}

#[derive(Clone, Debug)]
struct Var {
    name: String,
    vr: u32,
    kind: Kind,
    causality: String,
    min: Option<f64>,
    max: Option<f64>,
    start: f64,
}

struct Description {
    guid: String,
    step: f64,
    vars: Vec<Var>,
}

fn parse(xml: &str) -> Description {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut d = Description {
        guid: String::new(),
        step: 1e-3,
        vars: Vec::new(),
    };
    let mut current: Option<(String, u32, String)> = None;
    loop {
        let e = match reader
            .read_event()
            .expect("well-formed modelDescription.xml")
        {
            Event::Start(e) | Event::Empty(e) => e,
            Event::Eof => break,
            _ => continue,
        };
        let attr = |k: &str| {
            e.attributes()
                .flatten()
                .find(|a| a.key.as_ref() == k.as_bytes())
                .map(|a| a.unescape_value().unwrap().into_owned())
        };
        let num = |k: &str| {
            attr(k).map(|v| match v.as_str() {
                "true" => 1.0,
                "false" => 0.0,
                _ => v.parse::<f64>().unwrap(),
            })
        };
        match e.name().as_ref() {
            b"fmiModelDescription" => d.guid = attr("guid").unwrap(),
            b"DefaultExperiment" => d.step = num("stepSize").unwrap_or(1e-3),
            b"ScalarVariable" => {
                current = Some((
                    attr("name").unwrap(),
                    attr("valueReference").unwrap().parse().unwrap(),
                    attr("causality").unwrap_or_else(|| "local".into()),
                ))
            }
            tag @ (b"Real" | b"Integer" | b"Enumeration" | b"Boolean") => {
                if let Some((name, vr, causality)) = current.take() {
                    d.vars.push(Var {
                        name,
                        vr,
                        kind: match tag {
                            b"Real" => Kind::Real,
                            b"Integer" | b"Enumeration" => Kind::Integer,
                            _ => Kind::Boolean,
                        },
                        causality,
                        min: num("min"),
                        max: num("max"),
                        start: num("start").unwrap_or(0.0),
                    })
                }
            }
            _ => {}
        }
    }
    d
}

/// Smallest magnitude drawn from a range that reaches zero: magnitudes are log-uniform over
/// `DECADES` decades below the largest bound.
const DECADES: f64 = 15.0;

/// Knobs that buy accuracy with time (table nodes, wall layers, substep budget): random cases draw
/// them log-uniformly up to these caps; their declared maxima run in the bound-alone cases.
const WORK_CAPS: [(&str, f64); 3] = [
    ("shape_segments", 500.0),
    ("bladder_layers", 256.0),
    ("max_substeps", 1e5),
];

/// A value of `v` in its declared range: a bound (one in five), log-uniform where the range spans
/// decades, uniform otherwise. Undeclared bounds stand for the largest finite values.
fn draw(rng: &mut Rng, v: &Var) -> f64 {
    let (lo, hi) = match v.kind {
        Kind::Boolean => return (rng.next() & 1) as f64,
        Kind::Integer => {
            let cap = WORK_CAPS.iter().find(|(n, _)| *n == v.name).map(|c| c.1);
            let max = v.max.unwrap_or(i32::MAX as f64);
            (
                v.min.unwrap_or(i32::MIN as f64),
                cap.map_or(max, |c| c.min(max)),
            )
        }
        Kind::Real => (v.min.unwrap_or(-f64::MAX), v.max.unwrap_or(f64::MAX)),
    };
    let x = if rng.chance(0.2) {
        if rng.chance(0.5) {
            lo
        } else {
            hi
        }
    } else if lo > 0.0 && hi / lo > 100.0 {
        rng.log_uniform(lo, hi)
    } else if v.kind == Kind::Integer && lo > 0.0 {
        rng.log_uniform(lo, hi + 0.5)
    } else if v.kind == Kind::Integer && hi - lo <= 100.0 {
        (lo + rng.uniform() * (hi - lo + 1.0)).floor()
    } else if lo <= 0.0 && hi > 0.0 {
        // From or through zero: zero sometimes, else a side (either, if both) and a log-uniform
        // magnitude over DECADES decades below that bound.
        let negative = lo < 0.0 && rng.chance(0.5);
        let top = if negative { -lo } else { hi };
        if rng.chance(0.05) {
            0.0
        } else {
            let m = rng.log_uniform(top * 10f64.powf(-DECADES), top);
            if negative {
                -m
            } else {
                m
            }
        }
    } else {
        lo + rng.uniform() * (hi - lo)
    };
    match v.kind {
        Kind::Integer => x.round().clamp(lo, hi),
        _ => x,
    }
}

#[derive(Default, Debug)]
struct Tally {
    cases: usize,
    refused: usize,
    steps: usize,
    discarded: usize,
    /// The log of the last refused initialization.
    last_refusal: String,
}

/// Steps per case (random cases draw fresh inputs for each), of this fraction of the default step size (the
/// motor's extreme inputs spin the rotor through many substeps per default step).
const STEPS: usize = 4;
const MIN_RANDOM_CASES: usize = 40;
const STEP_FRACTION: f64 = 0.1;

/// One case: returns a failure description, or None.
fn run_case(
    api: &Api,
    d: &Description,
    values: &BTreeMap<String, f64>,
    mut rng: Option<&mut Rng>,
    tally: &mut Tally,
) -> Option<String> {
    let i = api
        .instantiate("ranges", &d.guid)
        .unwrap_or_else(|log| panic!("refused: {:?}", log.lines()));
    assert_eq!(i.setup(), OK);
    assert_eq!(i.enter(), OK);
    let set = |v: &Var, x: f64| -> c_int {
        unsafe {
            match v.kind {
                Kind::Real => (i.api.fmi2SetReal)(i.c, &v.vr, 1, &x),
                Kind::Integer => (i.api.fmi2SetInteger)(i.c, &v.vr, 1, &(x as c_int)),
                Kind::Boolean => (i.api.fmi2SetBoolean)(i.c, &v.vr, 1, &(x as c_int)),
            }
        }
    };
    let settable = |v: &&Var| v.causality == "parameter" || v.causality == "input";
    for v in d.vars.iter().filter(settable) {
        let x = values[&v.name];
        if set(v, x) != OK {
            return Some(format!(
                "{} = {x} (inside its declared range) was refused: {:?}",
                v.name,
                i.log.lines()
            ));
        }
    }
    tally.cases += 1;
    let exit = i.exit();
    // fmi2Warning: a clamped input under out_of_range_policy 1 or 2 (the outputs must be finite).
    if exit != OK && exit != WARNING {
        tally.refused += 1;
        tally.last_refusal = i.log.lines().join(" | ");
        return (exit != ERROR || i.log.lines().is_empty())
            .then(|| format!("initialization returned {exit} without a reason"));
    }
    let watched: Vec<&Var> = d
        .vars
        .iter()
        .filter(|v| {
            v.kind == Kind::Real && matches!(v.causality.as_str(), "output" | "calculatedParameter")
        })
        .collect();
    let non_finite = |when: &str| -> Option<String> {
        let vrs: Vec<u32> = watched.iter().map(|v| v.vr).collect();
        let (s, out) = i.get_real(&vrs);
        if s > WARNING {
            return Some(format!(
                "{when}: fmi2GetReal returned {s}: {:?}",
                i.log.lines()
            ));
        }
        let bad: Vec<String> = watched
            .iter()
            .zip(&out)
            .filter(|(_, x)| !x.is_finite())
            .map(|(v, x)| format!("{} = {x}", v.name))
            .collect();
        (!bad.is_empty()).then(|| format!("{when}: {}", bad.join(", ")))
    };
    if let Some(f) = non_finite("after initialization") {
        return Some(f);
    }
    let inputs: Vec<&Var> = d.vars.iter().filter(|v| v.causality == "input").collect();
    let mut t = 0.0;
    for k in 0..STEPS {
        if let (true, Some(rng)) = (k > 0, rng.as_deref_mut()) {
            for v in &inputs {
                let x = draw(rng, v);
                if set(v, x) != OK {
                    return Some(format!("input {} = {x} was refused", v.name));
                }
            }
        }
        let s = i.do_step(t, d.step * STEP_FRACTION);
        tally.steps += 1;
        match s {
            OK | WARNING => t += d.step * STEP_FRACTION,
            DISCARD if !i.log.lines().is_empty() => {
                tally.discarded += 1;
                return non_finite("after a discarded step");
            }
            _ => return Some(format!("step {k} returned {s}: {:?}", i.log.lines())),
        }
        if let Some(f) = non_finite(&format!("after step {k}")) {
            return Some(f);
        }
    }
    None
}

#[test]
fn every_value_in_the_declared_ranges_gives_finite_outputs_or_a_reason() {
    let cases_per_model: usize = std::env::var("RANGE_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(400);
    // Seconds of random cases per model: the motor's extreme inputs cost up to a second a case.
    let budget: f64 = std::env::var("RANGE_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(25.0);
    let mut models: Vec<String> = std::fs::read_dir(fmu_path("McKibbenMuscle").parent().unwrap())
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "fmu").then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    models.sort();
    if let Ok(only) = std::env::var("RANGE_MODELS") {
        models.retain(|m| only.split(',').any(|o| o == m));
    }
    let mut failures = Vec::new();
    let mut total = Tally::default();
    for model in &models {
        let xml = String::from_utf8(read_entry(&fmu_path(model), "modelDescription.xml")).unwrap();
        let d = parse(&xml);
        let api = Api::load(&extract_binary(model));
        let mut rng = Rng(0x5eed ^ model.len() as u64);
        let settable: Vec<&Var> = d
            .vars
            .iter()
            .filter(|v| v.causality == "parameter" || v.causality == "input")
            .collect();
        let start: BTreeMap<String, f64> =
            settable.iter().map(|v| (v.name.clone(), v.start)).collect();
        // Each bound alone (the rest at their start values), then random points of the whole box.
        let mut plans: Vec<(String, BTreeMap<String, f64>)> = Vec::new();
        for v in &settable {
            for bound in [v.min, v.max].into_iter().flatten() {
                let mut values = start.clone();
                values.insert(v.name.clone(), bound);
                plans.push((format!("{} = {bound}", v.name), values));
            }
        }
        for n in 0..cases_per_model {
            let values = settable
                .iter()
                .map(|v| (v.name.clone(), draw(&mut rng, v)))
                .collect();
            plans.push((format!("random case {n}"), values));
        }
        let mut tally = Tally::default();
        let begun_model = std::time::Instant::now();
        let mut random_cases = 0;
        for (label, values) in &plans {
            // Random cases stop at the time budget, after at least MIN_RANDOM_CASES (the
            // bound-alone cases always run).
            if label.starts_with("random") {
                if random_cases >= MIN_RANDOM_CASES && begun_model.elapsed().as_secs_f64() > budget
                {
                    break;
                }
                random_cases += 1;
            }
            // Random cases draw new inputs every step; a bound alone keeps the start inputs (a
            // substep budget of 1e8 with extreme inputs would run for hours, as asked).
            let redraw = label.starts_with("random").then_some(&mut rng);
            let refused_before = tally.refused;
            let mut failure = run_case(&api, &d, values, redraw, &mut tally);
            // A bound alone (every other value at its start) is a point of the declared space
            // that must run: a bound the model cannot meet is declared wrongly. A bound refused
            // for its combination with another variable (the bar must fit inside the ring)
            // names that variable: that is a reason, not a wrong range.
            let bound_of = label.split(' ').next().unwrap_or_default();
            let names_another = settable.iter().any(|v| {
                v.name != bound_of
                    && tally
                        .last_refusal
                        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .any(|word| word == v.name)
            });
            if failure.is_none()
                && !label.starts_with("random")
                && tally.refused > refused_before
                && !names_another
            {
                failure = Some(format!(
                    "a declared bound alone was refused for a reason that names no other \
                     variable: {}",
                    tally.last_refusal
                ));
            }
            if let Some(f) = failure {
                failures.push(format!("{model} {label} {values:?}: {f}"));
            }
        }
        println!("{model}: {tally:?}");
        total.cases += tally.cases;
        total.refused += tally.refused;
        total.steps += tally.steps;
        total.discarded += tally.discarded;
    }
    println!(
        "declared-range cases: {} instances ({} refused initialization with a reason), {} steps ({} discarded with a reason), {} failures",
        total.cases,
        total.refused,
        total.steps,
        total.discarded,
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} failing cases, first ones:\n{}",
        failures.len(),
        failures
            .iter()
            .take(20)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}
