//! The cost of a step anywhere in each FMU's declared space (`make worst-case`, not part of
//! `make test`): through the packaged linux64 binary's C ABI, every settable variable at each of
//! its declared bounds alone, every combination of the options (Integer parameters with at most
//! eight values, Booleans), the cases the random points do not meet ([`named_cases`]), then
//! `WORST_CASE_POINTS` (10,000) random points of the whole box that initialize (drawn
//! log-uniform across decades until that many do; the refused draws' initializations count too).
//! Each case initializes (timed from fmi2EnterInitializationMode to
//! fmi2ExitInitializationMode, the parameters set in between) and takes `STEPS` steps of the
//! FMU's default step size (each timed in thread CPU time, so that a loaded machine does not
//! inflate the figures, less the clock's own cost). The cases whose step or initialization lands
//! in the slowest 0.1% are run again and keep their minimum (see [`RETIMES`]). Prints per FMU the
//! median, p99 and maximum step and initialization cost, how many cases were refused at
//! initialization and at a step, and the slowest cases. A refused step ends its case; it counts
//! towards the maximum but not the median and p99, which describe the steps that run.
//!
//! `WORST_CASE_MODELS=A,B` restricts the FMUs; `WORST_CASE_POINTS=n` the random points;
//! `WORST_CASE_REPORT_ABOVE=s` lists every case whose step or initialization takes longer than
//! `s` seconds (default 1), as measured on its first run; `WORST_CASE_REPORT_STEPS_ABOVE=s` lists
//! after the re-timing every case one of whose steps takes longer than `s` seconds, with each
//! step's cost and the variables set away from their start values. `WORST_CASE_CASES=i,j` runs
//! only the random draws `random i`, `random j` (the same draws as a full run), each five times,
//! printing every value at full precision and each run's step costs. `WORST_CASE_BY=a,b` groups
//! each FMU's random points by the values of variables `a` and `b` together (an option's value,
//! a Real's decade) and prints the step median, p99 and maximum of each group.

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "cpu_clock.rs"]
mod cpu_clock;
#[path = "../tests/common/rng.rs"]
mod rng;

use actuator_fmus::export::REGISTRY;
use actuator_fmus::variables::{Causality, ModelInfo, Start, VarType};
use common::*;
use cpu_clock::thread_cpu;
use rng::Rng;
use std::ffi::c_int;
use std::time::Instant;

const STEPS: usize = 3;
/// A refused random draw whose initialization takes longer than this (s) is kept as a case.
const SLOW_REFUSAL: f64 = 1e-4;
/// The most random draws per point to initialize (see `main`).
const MAX_DRAWS_PER_POINT: usize = 200;
const DECADES: f64 = 15.0;

/// A settable variable: (value reference, type, lower and upper bound, start).
#[derive(Clone, Copy)]
struct Knob {
    name: &'static str,
    vr: u32,
    kind: VarType,
    lo: f64,
    hi: f64,
    start: f64,
}

fn knobs(info: &ModelInfo) -> Vec<Knob> {
    info.variables
        .iter()
        .filter(|v| matches!(v.causality, Causality::Parameter | Causality::Input))
        .filter(|v| v.kind != VarType::String)
        .map(|v| {
            let (lo, hi) = match v.kind {
                VarType::Boolean => (0.0, 1.0),
                VarType::Integer => (
                    v.min.unwrap_or(i32::MIN as f64),
                    v.max.unwrap_or(i32::MAX as f64),
                ),
                _ => (v.min.unwrap_or(-f64::MAX), v.max.unwrap_or(f64::MAX)),
            };
            let start = match v.start {
                Start::Real(x) => x,
                Start::Integer(i) => i as f64,
                Start::Boolean(b) => b as i32 as f64,
                _ => 0.0,
            };
            Knob {
                name: v.name,
                vr: v.vr,
                kind: v.kind,
                lo,
                hi,
                start,
            }
        })
        .collect()
}

/// Log-uniform across decades where the range allows, through zero by magnitude.
fn draw(rng: &mut Rng, k: &Knob) -> f64 {
    let x = match k.kind {
        VarType::Boolean => (rng.next() & 1) as f64,
        // A Real whose range starts at 0 is often an effect switched off there (no bag, no
        // connector): a quarter of the draws take it.
        VarType::Real if k.lo == 0.0 && k.hi > 0.0 && rng.chance(0.25) => 0.0,
        _ if k.lo > 0.0 && k.hi / k.lo > 10.0 => rng.log_uniform(
            k.lo,
            k.hi + 0.5 * (k.kind == VarType::Integer) as i32 as f64,
        ),
        _ if k.lo <= 0.0 && k.hi > 0.0 && k.hi - k.lo > 100.0 => {
            let negative = k.lo < 0.0 && rng.chance(0.5);
            let top = if negative { -k.lo } else { k.hi };
            let m = rng.log_uniform(top * 10f64.powf(-DECADES), top);
            if negative {
                -m
            } else {
                m
            }
        }
        _ => k.lo + rng.uniform() * (k.hi - k.lo + (k.kind == VarType::Integer) as i32 as f64),
    };
    match k.kind {
        VarType::Real => x,
        _ => x.floor().clamp(k.lo, k.hi),
    }
}

/// Every combination of the options: Integer parameters with at most 8 values and Booleans.
fn option_combinations(knobs: &[Knob]) -> Vec<Vec<(usize, f64)>> {
    let options: Vec<(usize, Vec<f64>)> = knobs
        .iter()
        .enumerate()
        .filter(|(_, k)| k.kind != VarType::Real && k.hi - k.lo < 8.0)
        .map(|(i, k)| (i, (k.lo as i64..=k.hi as i64).map(|x| x as f64).collect()))
        .collect();
    let mut combos = vec![Vec::new()];
    for (i, values) in &options {
        combos = combos
            .iter()
            .flat_map(|c| {
                values.iter().map(move |&x| {
                    let mut c = c.clone();
                    c.push((*i, x));
                    c
                })
            })
            .collect();
    }
    combos
}

/// Cases the random points do not meet, set on the start values by name: Table 2.1's muscle D
/// with an almost stress-free rubber (`mooney_c1` 0.28 Pa) of the dissertation's continuum wall
/// under a 36 kPa vacuum through a connector, at lengths 0.093-0.115 m, where the connector's
/// solutions jump between branches from one length to the next; with 1 node (refused) and 2.
fn named_cases(model: &str) -> Vec<(String, Vec<(&'static str, f64)>)> {
    if model != "McKibbenMuscle" {
        return Vec::new();
    }
    let mut cases = Vec::new();
    for nodes in [1.0, 2.0] {
        for i in 0..=22 {
            let length = 0.093 + 0.001 * f64::from(i);
            cases.push((
                format!(
                    "muscle D, 0.28 Pa rubber, {nodes} nodes, vacuum, connector, {length:.3} m"
                ),
                vec![
                    ("preset", 4.0),
                    ("bladder_model", 6.0),
                    ("bladder_layers", nodes),
                    ("mooney_c1", 0.2847),
                    ("mooney_c2", 3.127e-3),
                    ("connector_stiffness", 16553.48),
                    ("pressure", -36058.86),
                    ("length", length),
                ],
            ));
        }
    }
    cases
}

fn step_size(info: &ModelInfo) -> f64 {
    let xml = info.model_description_xml;
    xml.find("stepSize=\"")
        .and_then(|at| {
            let rest = &xml[at + 10..];
            rest[..rest.find('"')?].parse().ok()
        })
        .unwrap_or(1e-3)
}

struct Case {
    label: String,
    values: Vec<f64>,
    init: f64,
    steps: Vec<f64>,
    refused: bool,
    /// The last of `steps` was refused (worse than fmi2Warning): it counts towards the maximum,
    /// not the median and p99, which describe the steps that run (a refusal is mostly quick).
    step_refused: bool,
}

/// Repeats of a case whose step or initialization lands in the top [`RETIME_SHARE`] of its FMU:
/// the minimum over the first run and these is that case's cost, so that a preemption or page
/// fault during one run does not stand in for the FMU's own worst case.
const RETIMES: usize = 4;
const RETIME_SHARE: f64 = 0.001;

/// Re-times the slowest cases (see [`RETIMES`]); returns how many were re-timed.
/// Replays the random draws up to the last chosen one and runs only the chosen ones.
fn run_chosen(
    api: &Api,
    info: &ModelInfo,
    knobs: &[Knob],
    rng: &mut Rng,
    chosen: &[usize],
    h: f64,
    overhead: f64,
) {
    let last = chosen.iter().copied().max().unwrap_or(0);
    for drawn in 0..=last {
        let values: Vec<f64> = knobs.iter().map(|k| draw(rng, k)).collect();
        if !chosen.contains(&drawn) {
            continue;
        }
        println!("{}: random {drawn}:", info.name);
        for (k, x) in knobs.iter().zip(&values) {
            println!("  {} = {x:e}", k.name);
        }
        for _ in 0..5 {
            let (init, steps, refused, step_refused) = run(api, info, knobs, &values, h, overhead);
            let steps: Vec<String> = steps.iter().map(|s| format!("{:.1}", s * 1e6)).collect();
            println!(
                "  init {:.1} us{}, steps [{}] us{}",
                init * 1e6,
                if refused { " (refused)" } else { "" },
                steps.join(", "),
                if step_refused { " (last refused)" } else { "" }
            );
        }
    }
}

fn retime_slowest(
    api: &Api,
    info: &ModelInfo,
    knobs: &[Knob],
    cases: &mut [Case],
    h: f64,
    overhead: f64,
) -> usize {
    let sorted = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v
    };
    let steps = sorted(cases.iter().flat_map(|c| c.steps.clone()).collect());
    let inits = sorted(cases.iter().map(|c| c.init).collect());
    let step_cut = quantile(&steps, 1.0 - RETIME_SHARE);
    let init_cut = quantile(&inits, 1.0 - RETIME_SHARE);
    let mut retimed = 0;
    for case in cases.iter_mut() {
        let slow_step = case.steps.iter().any(|&s| s >= step_cut);
        if !(slow_step || case.init >= init_cut) {
            continue;
        }
        retimed += 1;
        for _ in 0..RETIMES {
            let (init, steps, ..) = run(api, info, knobs, &case.values, h, overhead);
            case.init = case.init.min(init);
            for (kept, again) in case.steps.iter_mut().zip(steps) {
                *kept = kept.min(again);
            }
        }
    }
    retimed
}

/// The cost of reading the thread CPU clock, subtracted from each timing.
fn clock_cost() -> f64 {
    let mut d: Vec<f64> = (0..1001)
        .map(|_| {
            let a = thread_cpu();
            thread_cpu() - a
        })
        .collect();
    d.sort_by(f64::total_cmp);
    d[500]
}

fn run(
    api: &Api,
    info: &ModelInfo,
    knobs: &[Knob],
    values: &[f64],
    h: f64,
    overhead: f64,
) -> (f64, Vec<f64>, bool, bool) {
    let i = api
        .instantiate("worst", info.guid)
        .unwrap_or_else(|log| panic!("{}: {:?}", info.name, log.lines()));
    assert_eq!(i.setup(), OK);
    let begun = thread_cpu();
    assert_eq!(i.enter(), OK);
    for (k, &x) in knobs.iter().zip(values) {
        unsafe {
            match k.kind {
                VarType::Real => (api.fmi2SetReal)(i.c, &k.vr, 1, &x),
                VarType::Integer => (api.fmi2SetInteger)(i.c, &k.vr, 1, &(x as c_int)),
                _ => (api.fmi2SetBoolean)(i.c, &k.vr, 1, &(x as c_int)),
            };
        }
    }
    let exit = i.exit();
    let init = (thread_cpu() - begun - overhead).max(0.0);
    if exit > WARNING {
        return (init, Vec::new(), true, false);
    }
    let mut steps = Vec::with_capacity(STEPS);
    let mut t = 0.0;
    for _ in 0..STEPS {
        let begun = thread_cpu();
        let s = i.do_step(t, h);
        steps.push((thread_cpu() - begun - overhead).max(0.0));
        if s > WARNING {
            return (init, steps, false, true);
        }
        t += h;
    }
    (init, steps, false, false)
}

/// `max / median`, or "-" where the median is below the clock's resolution (0.1 us).
fn ratio(max: f64, median: f64) -> String {
    if median >= 1e-7 {
        format!("{:.0}x", max / median)
    } else {
        "-".into()
    }
}

/// The random points' step costs grouped by the values of `split` (knobs with their indices):
/// an option's value, a Real's decade (its sign apart where its range crosses 0).
fn print_split(split: &[(Knob, usize)], cases: &[Case]) {
    let key_of = |knob: &Knob, x: f64| match knob.kind {
        VarType::Real if x == 0.0 => (0, i64::MIN),
        VarType::Real => (x.signum() as i64, x.abs().log10().floor() as i64),
        _ => (x as i64, 0),
    };
    let label_of = |knob: &Knob, (sign, decade): (i64, i64)| match knob.kind {
        VarType::Real if decade == i64::MIN => "0".to_string(),
        VarType::Real => {
            let minus = if sign < 0 { "-" } else { "" };
            format!("{minus}[1e{decade}, 1e{})", decade + 1)
        }
        _ => sign.to_string(),
    };
    let mut groups: std::collections::BTreeMap<Vec<(i64, i64)>, Vec<f64>> = Default::default();
    for c in cases
        .iter()
        .filter(|c| c.label.starts_with("random") && !c.refused)
    {
        let key = split
            .iter()
            .map(|(k, at)| key_of(k, c.values[*at]))
            .collect();
        let ran = c.steps.len() - usize::from(c.step_refused);
        groups.entry(key).or_default().extend(&c.steps[..ran]);
    }
    let names: Vec<&str> = split.iter().map(|(k, _)| k.name).collect();
    println!(
        "\n| {} | steps | step median | step p99 | step max |",
        names.join(" | ")
    );
    println!("|{}---|---|---|---|", "---|".repeat(names.len()));
    for (key, mut steps) in groups {
        steps.sort_by(f64::total_cmp);
        let labels: Vec<String> = split
            .iter()
            .zip(key)
            .map(|((k, _), x)| label_of(k, x))
            .collect();
        let us = |q: f64| format!("{:.1} us", quantile(&steps, q) * 1e6);
        println!(
            "| {} | {} | {} | {} | {} |",
            labels.join(" | "),
            steps.len(),
            us(0.5),
            us(0.99),
            us(1.0)
        );
    }
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

fn main() {
    let points: usize = std::env::var("WORST_CASE_POINTS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let only = std::env::var("WORST_CASE_MODELS").ok();
    let chosen: Option<Vec<usize>> = std::env::var("WORST_CASE_CASES")
        .ok()
        .map(|s| s.split(',').filter_map(|i| i.trim().parse().ok()).collect());
    let report_above: f64 = std::env::var("WORST_CASE_REPORT_ABOVE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let report_steps_above: f64 = std::env::var("WORST_CASE_REPORT_STEPS_ABOVE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(f64::INFINITY);
    let by: Option<Vec<String>> = std::env::var("WORST_CASE_BY")
        .ok()
        .map(|s| s.split(',').map(|n| n.trim().to_string()).collect());
    let overhead = clock_cost();
    println!(
        "(thread CPU time; the clock's own {:.0} ns subtracted)\n",
        overhead * 1e9
    );
    println!(
        "| FMU | cases | refused at init | refused at a step | random points initialized | step median | step p99 | step max | max / median | init median | init p99 | init max |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut slowest_all = Vec::new();
    for factory in REGISTRY {
        let info = factory.info();
        if only
            .as_ref()
            .is_some_and(|o| !o.split(',').any(|m| m == info.name))
        {
            continue;
        }
        let api = Api::load(&extract_binary(info.name));
        let knobs = knobs(info);
        let start: Vec<f64> = knobs.iter().map(|k| k.start).collect();
        let h = step_size(info);
        let mut plans: Vec<(String, Vec<f64>)> = Vec::new();
        for (i, k) in knobs.iter().enumerate() {
            for bound in [k.lo, k.hi] {
                let mut v = start.clone();
                v[i] = bound;
                plans.push((format!("{} = {bound:e}", k.name), v));
            }
        }
        for combo in option_combinations(&knobs) {
            let mut v = start.clone();
            let label: Vec<String> = combo
                .iter()
                .map(|&(i, x)| {
                    v[i] = x;
                    format!("{}={x}", knobs[i].name)
                })
                .collect();
            plans.push((format!("options {}", label.join(" ")), v));
        }
        for (label, set) in named_cases(info.name) {
            let mut v = start.clone();
            for (name, x) in set {
                let at = knobs.iter().position(|k| k.name == name);
                v[at.unwrap_or_else(|| panic!("{}: no {name}", info.name))] = x;
            }
            plans.push((label, v));
        }
        let mut rng = Rng(0x5eed ^ info.name.len() as u64);
        if let Some(chosen) = &chosen {
            run_chosen(&api, info, &knobs, &mut rng, chosen, h, overhead);
            continue;
        }
        let mut cases = Vec::with_capacity(plans.len() + points);
        // Initializations refused at the random points: their cost counts, their labels are not
        // kept (a model refusing most of its box draws hundreds of thousands of them).
        let mut refused_inits = Vec::new();
        let begun = Instant::now();
        let mut measure = |label: String, values: Vec<f64>, cases: &mut Vec<Case>| {
            let (init, steps, refused, step_refused) =
                run(&api, info, &knobs, &values, h, overhead);
            let slow = steps.iter().copied().fold(init, f64::max);
            let describe = |only_changed: bool| -> Vec<String> {
                knobs
                    .iter()
                    .zip(&values)
                    .filter(|(k, x)| !only_changed || **x != k.start)
                    .map(|(k, x)| format!("{}={x:.3e}", k.name))
                    .collect()
            };
            if slow > report_above {
                eprintln!(
                    "{}: {label}: {:.1} us [{}]",
                    info.name,
                    slow * 1e6,
                    describe(true).join(" ")
                );
            }
            let random = label.starts_with("random");
            // A refusal is normally quick; a slow one is kept as a case, to be re-timed and listed.
            if refused && random && init < SLOW_REFUSAL {
                refused_inits.push(init);
                return false;
            }
            let label = if random {
                format!("{label} [{}]", describe(false).join(" "))
            } else {
                label
            };
            cases.push(Case {
                label,
                values,
                init,
                steps,
                refused,
                step_refused,
            });
            !refused
        };
        for (label, values) in plans {
            measure(label, values, &mut cases);
        }
        // Random points are drawn until `points` of them initialize (at most MAX_DRAWS_PER_POINT
        // draws each): the declared box is mostly combinations a model refuses at once.
        let (mut drawn, mut initialized) = (0, 0);
        while initialized < points && drawn < MAX_DRAWS_PER_POINT * points {
            let values = knobs.iter().map(|k| draw(&mut rng, k)).collect();
            initialized += usize::from(measure(format!("random {drawn}"), values, &mut cases));
            drawn += 1;
            if drawn % 20_000 == 0 {
                eprintln!(
                    "{}: {initialized}/{points} random points initialized of {drawn} drawn, {:.0} s",
                    info.name,
                    begun.elapsed().as_secs_f64()
                );
            }
        }
        let retimed = retime_slowest(&api, info, &knobs, &mut cases, h, overhead);
        eprintln!(
            "{}: {retimed} slowest cases re-timed {RETIMES} more times, their minima kept",
            info.name
        );
        for c in &cases {
            if c.steps.iter().any(|&s| s > report_steps_above) {
                let steps: Vec<String> =
                    c.steps.iter().map(|s| format!("{:.1}", s * 1e6)).collect();
                let changed: Vec<String> = knobs
                    .iter()
                    .zip(&c.values)
                    .filter(|(k, x)| **x != k.start)
                    .map(|(k, x)| format!("{}={x:.3e}", k.name))
                    .collect();
                let label = c.label.split(" [").next().unwrap_or(&c.label);
                eprintln!(
                    "{}: slow step: {label}: steps [{}] us{} [{}]",
                    info.name,
                    steps.join(", "),
                    if c.step_refused {
                        " (last refused)"
                    } else {
                        ""
                    },
                    changed.join(" ")
                );
            }
        }
        let ran = |c: &Case| c.steps.len() - usize::from(c.step_refused);
        let mut steps: Vec<f64> = cases
            .iter()
            .flat_map(|c| c.steps[..ran(c)].to_vec())
            .collect();
        steps.sort_by(f64::total_cmp);
        let slowest = cases
            .iter()
            .flat_map(|c| c.steps.iter().copied())
            .fold(0.0, f64::max);
        let mut inits: Vec<f64> = cases.iter().map(|c| c.init).collect();
        inits.extend(&refused_inits);
        inits.sort_by(f64::total_cmp);
        let us = |x: f64| format!("{:.1} us", x * 1e6);
        println!(
            "| {} | {} | {} | {} | {initialized} of {drawn} | {} | {} | {} | {} | {} | {} | {} |",
            info.name,
            cases.len() + refused_inits.len(),
            cases.iter().filter(|c| c.refused).count() + refused_inits.len(),
            cases.iter().filter(|c| c.step_refused).count(),
            us(quantile(&steps, 0.5)),
            us(quantile(&steps, 0.99)),
            us(slowest),
            ratio(slowest, quantile(&steps, 0.5)),
            us(quantile(&inits, 0.5)),
            us(quantile(&inits, 0.99)),
            us(quantile(&inits, 1.0)),
        );
        if let Some(by) = &by {
            let split: Vec<(Knob, usize)> = by
                .iter()
                .filter_map(|name| knobs.iter().position(|k| k.name == name))
                .map(|at| (knobs[at], at))
                .collect();
            if !split.is_empty() {
                print_split(&split, &cases);
            }
        }
        cases.sort_by(|a, b| {
            let worst = |c: &Case| c.steps.iter().copied().fold(c.init, f64::max);
            worst(b).total_cmp(&worst(a))
        });
        for c in cases.iter().take(3) {
            let worst_step = c.steps.iter().copied().fold(0.0, f64::max);
            slowest_all.push(format!(
                "{}: step {} init {}: {}",
                info.name,
                us(worst_step),
                us(c.init),
                c.label
            ));
        }
    }
    println!("\nSlowest cases:");
    for line in slowest_all {
        println!("- {line}");
    }
}
