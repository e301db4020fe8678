//! The FMI layer against C, and the performance goals that are ratios of two step costs, measured
//! interleaved in one process: every round times each case once (in a rotating order), and each
//! case's figure is the minimum and the median over the rounds. On a machine shared with other jobs
//! a ratio of two figures taken minutes apart means little; taken round by round, it holds.
//!
//! Every case is one communication step as a master makes it, through the C ABI of a binary loaded
//! with `libloading`: `fmi2SetReal` of one input, `fmi2DoStep`, `fmi2GetReal` of one output. The
//! yardstick is `benches/c_passthrough/passthrough.c`, a C pass-through FMU with the Reference-FMUs'
//! Feedthrough semantics, compiled by `make bench` (`cc -O2 -shared`; this bench compiles it itself
//! when run alone).
//!
//! Time on a shared machine moves with the load; instructions do not. When `valgrind` is on the
//! PATH, the bench also runs itself under callgrind for each FMI-layer case (`PARITY_COUNT=<case>`:
//! that case alone, its steps inside `counted_steps`) and reports instructions per step (counted
//! inside `counted_steps`) and per call (inside each of the three exported functions) beside
//! the times. (`perf stat` would count them too, but these
//! virtual machines expose no hardware counters.)
//!
//! Writes `target/parity/parity.json` for `benches/report.py`. `PARITY_ROUNDS` sets the rounds;
//! `PARITY_ONLY=<text>[,<text>...]` keeps the C fixture and the cases whose name contains a text;
//! `PARITY_INSTRUCTIONS=0` skips the instruction counts; `PARITY_AB=<path to another build of
//! libactuator_fmus.so>` adds its PassThrough and ideal McKibben cases to the same rounds.

#[path = "../tests/common/mod.rs"]
mod common;

use actuator_fmus::export::REGISTRY;
use actuator_fmus::variables::{ModelInfo, VarType};
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const C_SOURCE: &str = "benches/c_passthrough/passthrough.c";
const C_GUID: &str = "{c-passthrough-bench-fixture}";
const C_CASE: &str = "C pass-through";
const IDEAL_CASE: &str = "McKibbenMuscle, ideal";
/// The cases of the FMI-layer goals, whose instructions per step are counted.
const COUNTED: [&str; 3] = [C_CASE, "PassThrough", IDEAL_CASE];

/// The C fixture's binary: `make bench` builds it; built here if it is missing or older.
fn c_fixture() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let so = root.join("target/c_passthrough/PassThroughC.so");
    let source = root.join(C_SOURCE);
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    if modified(&so) < modified(&source) {
        std::fs::create_dir_all(so.parent().unwrap()).unwrap();
        let status = std::process::Command::new("cc")
            .args(["-O2", "-shared", "-fPIC", "-o"])
            .arg(&so)
            .arg(&source)
            .arg("-lm")
            .status()
            .expect("cc (a C compiler) is needed for the C pass-through fixture");
        assert!(status.success(), "compiling {C_SOURCE} failed");
    }
    so
}

fn info(model: &str) -> &'static ModelInfo {
    REGISTRY
        .iter()
        .find(|f| f.info().name == model)
        .unwrap_or_else(|| panic!("no FMU {model} in this build"))
        .info()
}

fn vr(info: &ModelInfo, name: &str) -> u32 {
    info.by_name(name)
        .unwrap_or_else(|| panic!("{}: no variable {name}", info.name))
        .vr
}

/// One timed case: runs `n` steps and returns their total time; `evict` (when not null) is written
/// over before each step and only the step is timed, as an importer's own work between steps
/// (FMPy's interpreter) leaves the caches and branch predictors cold.
struct Case {
    name: &'static str,
    run: Box<Steps>,
}

/// `run(n, evict)`: see [`Case`].
type Steps = dyn FnMut(u64, &mut [u8]) -> Duration;

/// Bytes written between cold steps: past the L2 cache of these machines.
const EVICT_BYTES: usize = 4 << 20;

/// An instance stepped by `set(input) + doStep(h) + get(output)`, the input from `input(k)`.
/// The loop is monomorphized per case: no dynamic call inside the timed region but the FMU's own.
fn case(
    name: &'static str,
    api: &'static common::Api,
    inst: common::Component,
    (vin, vout): (u32, u32),
    h: f64,
    input: impl Fn(u64) -> f64 + 'static,
) -> Case {
    let (mut t, mut k) = (0.0, 0u64);
    let run = move |n: u64, evict: &mut [u8]| {
        let mut out = 0.0;
        let mut cold = Duration::ZERO;
        // Statuses worse than fmi2Warning: a failing step is fast and would time nothing.
        let mut failed = 0u32;
        let start = Instant::now();
        for _ in 0..n {
            k += 1;
            let x = input(k);
            let step_start = if evict.is_empty() {
                None
            } else {
                for byte in evict.iter_mut().step_by(64) {
                    *byte = byte.wrapping_add(1);
                }
                black_box(&evict);
                Some(Instant::now())
            };
            unsafe {
                let s1 = (api.fmi2SetReal)(inst, &vin, 1, &x);
                let s2 = (api.fmi2DoStep)(inst, t, h, 1);
                t += h;
                let s3 = (api.fmi2GetReal)(inst, &vout, 1, &mut out);
                failed += ((s1 | s2 | s3) > common::WARNING) as u32;
                black_box(out);
            }
            if let Some(s) = step_start {
                cold += s.elapsed();
            }
        }
        let elapsed = start.elapsed();
        assert_eq!(failed, 0, "{name}: {failed} of {n} steps failed");
        if evict.is_empty() {
            elapsed
        } else {
            cold
        }
    };
    Case {
        name,
        run: Box::new(run),
    }
}

/// Instantiates `model` (leaked: lives for the whole bench), sets its parameters by name and
/// initializes it.
fn instance(
    api: &'static common::Api,
    guid: &str,
    model: Option<&ModelInfo>,
    parameters: &[(&str, f64)],
) -> common::Component {
    let inst = api
        .instantiate("parity", guid)
        .unwrap_or_else(|log| panic!("instantiate: {:?}", log.lines()));
    for (name, value) in parameters {
        let var = model.expect("a model").by_name(name).expect("parameter");
        let status = unsafe {
            match var.kind {
                VarType::Real => (api.fmi2SetReal)(inst.c, &var.vr, 1, value),
                VarType::Integer => (api.fmi2SetInteger)(inst.c, &var.vr, 1, &(*value as i32)),
                _ => (api.fmi2SetBoolean)(inst.c, &var.vr, 1, &(*value as i32)),
            }
        };
        assert_eq!(status, common::OK, "{name}: {:?}", inst.log.lines());
    }
    inst.initialize();
    let c = inst.c;
    std::mem::forget(inst);
    c
}

fn leak(api: common::Api) -> &'static common::Api {
    Box::leak(Box::new(api))
}

/// The cases whose name `keep` accepts (the C fixture is always first).
fn cases(keep: &dyn Fn(&str) -> bool) -> Vec<Case> {
    let c_api = leak(common::Api::load(&c_fixture()));
    let c_inst = instance(c_api, C_GUID, None, &[]);
    let mut cases = vec![case(C_CASE, c_api, c_inst, (0, 1), 1e-3, |k| {
        0.5 + 1e-6 * (k % 1000) as f64
    })];
    if !keep("PassThrough") {
        return cases;
    }

    let pt = info("PassThrough");
    let pt_api = leak(common::Api::load(&common::extract_binary("PassThrough")));
    let inst = instance(pt_api, pt.guid, Some(pt), &[]);
    cases.push(case(
        "PassThrough",
        pt_api,
        inst,
        (vr(pt, "u"), vr(pt, "y")),
        1e-3,
        |k| 0.5 + 1e-6 * (k % 1000) as f64,
    ));

    if !keep(IDEAL_CASE) {
        return cases;
    }
    let mck = info("McKibbenMuscle");
    let mck_api = leak(common::Api::load(&common::extract_binary("McKibbenMuscle")));
    let io = (vr(mck, "length"), vr(mck, "force"));
    // The ideal sleeve (eq. 2.3) at 400 kPa, the length sweeping 90-91 mm of muscle A.
    let ideal = instance(mck_api, mck.guid, Some(mck), &[("pressure", 4e5)]);
    cases.push(case(IDEAL_CASE, mck_api, ideal, io, 1e-3, |k| {
        0.09 + 1e-6 * (k % 1000) as f64
    }));
    // Another build of the library (`PARITY_AB=path/to/libactuator_fmus.so`) beside this one, in
    // the same rounds: how a change to the FMI layer measures without the load in between.
    if let Some(other) = std::env::var_os("PARITY_AB").filter(|_| keep("walls and motor")) {
        let api = leak(common::Api::load(Path::new(&other)));
        let inst = instance(api, pt.guid, Some(pt), &[]);
        cases.push(case(
            "PassThrough, PARITY_AB",
            api,
            inst,
            (vr(pt, "u"), vr(pt, "y")),
            1e-3,
            |k| 0.5 + 1e-6 * (k % 1000) as f64,
        ));
        let ideal = instance(api, mck.guid, Some(mck), &[("pressure", 4e5)]);
        cases.push(case(
            "McKibbenMuscle, ideal, PARITY_AB",
            api,
            ideal,
            io,
            1e-3,
            |k| 0.09 + 1e-6 * (k % 1000) as f64,
        ));
    }
    if !keep("walls and motor") {
        return cases;
    }
    // The walls of the continuum goal: muscle A at 690 kPa over 0.75-0.93 of its length (on
    // the sleeve), the scenario of docs/accuracy-cost.md.
    let walls = [
        // The dissertation's walls (bladder_model 5 and 6) and the exact wall (3).
        ("McKibbenMuscle, layered wall, 16 layers", 5.0, 16.0),
        ("McKibbenMuscle, continuum wall, 8 nodes", 6.0, 8.0),
        ("McKibbenMuscle, exact wall, 16 nodes", 3.0, 16.0),
    ];
    for (name, model, n) in walls {
        let p = [
            ("preset", 1.0),
            ("bladder_model", model),
            ("bladder_layers", n),
            ("pressure", 6.9e5),
            ("length", 0.10325 * 0.75),
        ];
        let inst = instance(mck_api, mck.guid, Some(mck), &p);
        cases.push(case(name, mck_api, inst, io, 1e-3, |k| {
            0.10325 * (0.75 + 0.18 * (k % 200) as f64 / 200.0)
        }));
    }

    let motor = info("MultiferroicMotor");
    let motor_api = leak(common::Api::load(&common::extract_binary(
        "MultiferroicMotor",
    )));
    let inst = instance(motor_api, motor.guid, Some(motor), &[("schedule", 1.0)]);
    cases.push(case(
        "MultiferroicMotor, 1 us step",
        motor_api,
        inst,
        (vr(motor, "load_torque"), vr(motor, "rotor_angle")),
        1e-6,
        |_| 0.0,
    ));
    cases
}

/// Seconds that `fmi2ExitInitializationMode` takes for the section 1.4 prototype with the
/// non-cylindrical shape (`shape_model` 2) of `segments` rows: the table is built there. The
/// minimum over `repeats` fresh instances (fewer when one takes over a second).
fn knitted_initialization(api: &'static common::Api, segments: i32, repeats: usize) -> f64 {
    let knitted = info("KnittedMuscle");
    let mut best = f64::INFINITY;
    for _ in 0..repeats {
        let inst = api
            .instantiate("parity", knitted.guid)
            .unwrap_or_else(|log| panic!("instantiate: {:?}", log.lines()));
        let vrs = [vr(knitted, "shape_model"), vr(knitted, "shape_segments")];
        let status =
            unsafe { (api.fmi2SetInteger)(inst.c, vrs.as_ptr(), 2, [2, segments].as_ptr()) };
        assert_eq!(status, common::OK, "{:?}", inst.log.lines());
        assert_eq!(inst.setup(), common::OK);
        assert_eq!(inst.enter(), common::OK);
        let start = Instant::now();
        let status = inst.exit();
        let elapsed = start.elapsed().as_secs_f64();
        assert!(status <= common::WARNING, "{:?}", inst.log.lines());
        best = best.min(elapsed);
        if elapsed > 1.0 {
            break;
        }
    }
    best
}

/// A performance goal beside its measured figure.
fn verdict(measured: f64, goal: f64) -> String {
    if measured <= goal {
        "met".into()
    } else {
        format!("missed by {:.2}x", measured / goal)
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Steps counted under callgrind: `--toggle-collect` names this function.
#[inline(never)]
fn counted_steps(case: &mut Case, n: u64) {
    (case.run)(n, &mut []);
}

/// Steps each `PARITY_COUNT` run counts; the loop's entry and exit are amortized over them.
const COUNTED_STEPS: u64 = 20_000;
/// Steps before them (lazy binding, first-call work), counted only in the per-call figures.
const WARMUP_STEPS: u64 = 1000;
/// The three calls of a step, counted one by one.
const CALLS: [&str; 3] = ["fmi2SetReal", "fmi2DoStep", "fmi2GetReal"];

/// `PARITY_COUNT=<case>`: that case alone, [`WARMUP_STEPS`] steps, then [`COUNTED_STEPS`] steps
/// inside [`counted_steps`].
fn count_mode(name: &str) {
    // `cases` builds its cases in the order of COUNTED: up to this one.
    let last = COUNTED
        .iter()
        .position(|c| *c == name)
        .unwrap_or_else(|| panic!("{name} is not one of {COUNTED:?}"));
    let mut cases = cases(&|case| COUNTED[..=last].contains(&case));
    let case = cases
        .iter_mut()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no case {name}"));
    (case.run)(WARMUP_STEPS, &mut []);
    counted_steps(case, COUNTED_STEPS);
}

/// One case's instructions by callgrind: per step (the harness's loop included) and per call
/// of [`CALLS`] (the call and everything it calls).
struct Instructions {
    case: &'static str,
    per_step: f64,
    per_call: [f64; 3],
}

/// The instructions callgrind collects inside `function` (and what it calls) when this binary
/// runs `case` in `PARITY_COUNT` mode.
fn collected(exe: &Path, case: &str, function: &str) -> Option<f64> {
    let output = std::process::Command::new("valgrind")
        .args(["--tool=callgrind", "--callgrind-out-file=/dev/null"])
        .arg(format!("--toggle-collect={function}"))
        .arg(exe)
        .env("PARITY_COUNT", case)
        .output()
        .ok()?;
    let log = String::from_utf8_lossy(&output.stderr);
    // "==pid== Collected : 1234567"
    let collected = log
        .lines()
        .find_map(|l| l.split("Collected :").nth(1))
        .and_then(|n| n.trim().parse::<f64>().ok());
    if !output.status.success() || collected.is_none() {
        eprintln!("callgrind on {case} ({function}) failed:\n{log}");
    }
    collected.filter(|_| output.status.success())
}

/// Instructions of each case in [`COUNTED`], by callgrind (this binary run again in
/// `PARITY_COUNT` mode); `None` when valgrind is missing or `PARITY_INSTRUCTIONS=0`.
fn instructions() -> Option<Vec<Instructions>> {
    if std::env::var("PARITY_INSTRUCTIONS").is_ok_and(|v| v == "0") {
        return None;
    }
    let exe = std::env::current_exe().ok()?;
    let calls = (WARMUP_STEPS + COUNTED_STEPS) as f64;
    let mut counts = Vec::new();
    for case in COUNTED {
        let per_step = collected(&exe, case, "*counted_steps*")? / COUNTED_STEPS as f64;
        let mut per_call = [0.0; 3];
        for (n, function) in per_call.iter_mut().zip(CALLS) {
            *n = collected(&exe, case, function)? / calls;
        }
        counts.push(Instructions {
            case,
            per_step,
            per_call,
        });
    }
    Some(counts)
}

fn main() {
    // `cargo bench` passes `--bench`; a filter or `--list` from the harness protocol is ignored.
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let rounds: usize = std::env::var("PARITY_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(201);
    if let Ok(name) = std::env::var("PARITY_COUNT") {
        return count_mode(&name);
    }
    let mut cases = cases(&|_| true);
    // For profiling one case (`PARITY_ONLY=PassThrough perf record ...`): the yardstick stays first.
    if let Ok(only) = std::env::var("PARITY_ONLY") {
        let mut i = 0;
        cases.retain(|c| {
            i += 1;
            i == 1 || only.split(',').any(|part| c.name.contains(part))
        });
    }
    // Batches of about 0.5 ms: long enough for the clock, short enough that on a loaded machine
    // many of them run without being preempted (the minimum over rounds is such a batch).
    let batches: Vec<u64> = cases
        .iter_mut()
        .map(|c| {
            (c.run)(2000, &mut []);
            let probe = (c.run)(2000, &mut []).as_secs_f64() / 2000.0;
            ((5e-4 / probe) as u64).clamp(20, 100_000)
        })
        .collect();
    let mut samples = vec![Vec::with_capacity(rounds); cases.len()];
    for round in 0..rounds {
        for j in 0..cases.len() {
            let i = (j + round) % cases.len();
            let n = batches[i];
            samples[i].push((cases[i].run)(n, &mut []).as_secs_f64() / n as f64);
        }
    }
    let c_min = samples[0].iter().copied().fold(f64::INFINITY, f64::min);
    let c_median = median(samples[0].clone());
    println!(
        "FMI parity: one set + fmi2DoStep + get through the C ABI, {rounds} interleaved rounds"
    );
    println!(
        "{:<42} {:>10} {:>10} {:>9} {:>9}",
        "case", "min (ns)", "median", "min/C", "median/C"
    );
    let mut json = Vec::new();
    let mut json_init: Vec<(i32, f64)> = Vec::new();
    for (case, s) in cases.iter().zip(&samples) {
        let min = s.iter().copied().fold(f64::INFINITY, f64::min);
        let med = median(s.clone());
        println!(
            "{:<42} {:>10.1} {:>10.1} {:>8.2}x {:>8.2}x",
            case.name,
            min * 1e9,
            med * 1e9,
            min / c_min,
            med / c_median
        );
        json.push(format!(
            "  {{\"case\": \"{}\", \"min_s\": {:e}, \"median_s\": {:e}, \"samples_s\": [{}]}}",
            case.name,
            min,
            med,
            s.iter()
                .map(|x| format!("{x:e}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    // The same steps with the caches evicted before each (one step timed at a time): what a step
    // costs when the importer's own work runs between steps, as FMPy's interpreter does.
    let mut evict = vec![0u8; EVICT_BYTES];
    println!(
        "\nCold steps ({} MB written between steps; median of 31 batches of 64):",
        EVICT_BYTES >> 20
    );
    let mut cold = Vec::new();
    for case in cases.iter_mut() {
        let batches: Vec<f64> = (0..31)
            .map(|_| (case.run)(64, &mut evict).as_secs_f64() / 64.0)
            .collect();
        let med = median(batches);
        println!("{:<42} {:>10.1} ns", case.name, med * 1e9);
        cold.push(format!(
            "  {{\"case\": \"{}\", \"median_s\": {med:e}}}",
            case.name
        ));
    }

    let figure = |name: &str| {
        let i = cases.iter().position(|c| c.name == name)?;
        let s = &samples[i];
        Some((
            s.iter().copied().fold(f64::INFINITY, f64::min),
            median(s.clone()),
        ))
    };

    // The knitted shape table is built once, at initialization: time that call through the FMU.
    let knitted_api = leak(common::Api::load(&common::extract_binary("KnittedMuscle")));
    let mut init = Vec::new();
    for (segments, repeats) in [(49, 9), (98, 5)] {
        let t = knitted_initialization(knitted_api, segments, repeats);
        init.push(format!("  {{\"segments\": {segments}, \"min_s\": {t:e}}}"));
        json_init.push((segments, t));
    }

    println!(
        "\nPerformance goals (ratios within this run; the motor FMPy goal is in `make report`):"
    );
    let goal = |text: &str, measured: Option<f64>, target: f64, shown: &dyn Fn(f64) -> String| {
        match measured {
            Some(m) => println!("  {text:<62} {:>12}  {}", shown(m), verdict(m, target)),
            None => println!("  {text:<62} {:>12}  not measured", "-"),
        }
    };
    let ratio = |name: &str| figure(name).map(|(min, _)| min / c_min);
    let x = |r: f64| format!("{r:.2}x");
    goal(
        "PassThrough <= 2x the C pass-through (min)",
        ratio("PassThrough"),
        2.0,
        &x,
    );
    goal(
        "ideal McKibben <= 2.5x the C pass-through (min)",
        ratio(IDEAL_CASE),
        2.5,
        &x,
    );
    // Round by round the two walls ran within a millisecond of each other: the median of those
    // ratios is the figure least moved by the machine's load.
    let position = |name: &str| cases.iter().position(|c| c.name == name);
    let walls = position("McKibbenMuscle, continuum wall, 8 nodes")
        .zip(position("McKibbenMuscle, layered wall, 16 layers"))
        .map(|(c, l)| {
            median(
                samples[c]
                    .iter()
                    .zip(&samples[l])
                    .map(|(a, b)| a / b)
                    .collect(),
            )
        });
    goal(
        "continuum wall, 8 nodes <= 16 layers (median of round ratios)",
        walls,
        1.0,
        &x,
    );
    let us = |t: f64| format!("{:.2} us", t * 1e6);
    let motor = figure("MultiferroicMotor, 1 us step").map(|(_, med)| med);
    goal(
        "motor, 1 us communication step <= 2 us natively (median)",
        motor,
        2e-6,
        &us,
    );
    let ms = |t: f64| format!("{:.2} ms", t * 1e3);
    let init_of = |n: i32| json_init.iter().find(|(s, _)| *s == n).map(|(_, t)| *t);
    goal(
        "knitted prototype (49 rows) initialization <= 3 ms",
        init_of(49),
        3e-3,
        &ms,
    );
    goal(
        "knitted table, 98 segments (the most accepted), initialization <= 10 ms",
        init_of(98),
        10e-3,
        &ms,
    );

    let instructions = instructions();
    match &instructions {
        Some(counts) => {
            println!("\nInstructions (callgrind, {COUNTED_STEPS} steps; independent of the load):");
            println!(
                "{:<42} {:>10} {:>9} {:>12} {:>11} {:>12}",
                "case", "per step", "against C", CALLS[0], CALLS[1], CALLS[2]
            );
            let c = counts[0].per_step;
            for n in counts {
                println!(
                    "{:<42} {:>10.1} {:>8.2}x {:>12.1} {:>11.1} {:>12.1}",
                    n.case,
                    n.per_step,
                    n.per_step / c,
                    n.per_call[0],
                    n.per_call[1],
                    n.per_call[2]
                );
            }
        }
        None => {
            println!("\nInstructions: not counted (no valgrind, or PARITY_INSTRUCTIONS=0)")
        }
    }
    let instructions_json = instructions.map_or("[]".to_string(), |counts| {
        let rows: Vec<String> = counts
            .iter()
            .map(|n| {
                let calls: Vec<String> = CALLS
                    .iter()
                    .zip(n.per_call)
                    .map(|(f, x)| format!("\"{f}\": {x}"))
                    .collect();
                format!(
                    "  {{\"case\": \"{}\", \"per_step\": {}, \"per_call\": {{{}}}}}",
                    n.case,
                    n.per_step,
                    calls.join(", ")
                )
            })
            .collect();
        format!("[\n{}\n]", rows.join(",\n"))
    });

    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/parity");
    std::fs::create_dir_all(&dir).unwrap();
    let body = format!(
        "{{\"rounds\": {rounds}, \"walls_round_ratio\": {}, \"cases\": [\n{}\n], \"cold\": [\n{}\n], \"knitted_initialization\": [\n{}\n], \"instructions\": {instructions_json}}}\n",
        walls.map_or("null".to_string(), |r| format!("{r:e}")),
        json.join(",\n"),
        cold.join(",\n"),
        init.join(",\n")
    );
    std::fs::write(dir.join("parity.json"), body).unwrap();
    println!("wrote target/parity/parity.json");
}
