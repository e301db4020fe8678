//! `calibrate`: fits McKibbenMuscle's physical parameters to a datasheet of force-contraction
//! curves with the FMU's own physics (see `actuator_fmus_tools::calibration`).
//!
//! ```text
//! calibrate --data festo_dmsp40.csv --length 0.4 --diameter 0.04 --fit 0,600 --out out/dmsp40
//!           [--model 3] [--layers 16] [--fix NAME=VALUE,...|none] [--starts 24] [--iterations 200]
//! ```
//! `--model`/`--layers`: `bladder_model` and `bladder_layers` (default the exact wall, 16 nodes).
//! `--fix`: parameters held instead of fitted, replacing the default (bladder unstretched at the
//! nominal length, `mooney_c1` 30 kPa, `mooney_c2` 600 kPa, braid on the wall); `none`
//! fits all seven; `sleeve_diameter=on_wall` puts the braid on the wall.
//! The CSV has columns `pressure_kpa,contraction,force_n` (`#` lines are comments). Writes
//! `OUT/params.json` (FMPy `start_values` for McKibbenMuscle.fmu), `OUT/params.ssv` (SSP parameter
//! values), `OUT/fit.csv` (every datum with the model's force) and `OUT/fit.json` (errors per
//! pressure, fit time). `python/actuator_fmus/calibration.py` adds the report and its plot.

use actuator_fmus_tools::calibration::{
    curves, errors, fit, model_force, parameter_report, Curve, Datum, FitConfig, MuscleParams,
    AT_BOUND, PARAMS,
};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

struct Args {
    data: PathBuf,
    out: PathBuf,
    fit_kpa: Vec<f64>,
    cfg: FitConfig,
}

const USAGE: &str =
    "usage: calibrate --data CSV --length M --diameter M --fit KPA[,KPA...] --out DIR \
                     [--model BLADDER_MODEL (3)] [--layers N (16)] [--fix NAME=VALUE,...|none] \
                     [--starts N] [--iterations N]";

fn parse_args() -> Result<Args, String> {
    let mut get = std::collections::HashMap::new();
    let mut it = std::env::args().skip(1);
    while let Some(key) = it.next() {
        let key = key
            .strip_prefix("--")
            .ok_or_else(|| format!("unexpected argument '{key}'\n{USAGE}"))?
            .to_string();
        let value = it.next().ok_or_else(|| format!("--{key} needs a value"))?;
        get.insert(key, value);
    }
    let text = |k: &str| {
        get.get(k)
            .cloned()
            .ok_or_else(|| format!("missing --{k}\n{USAGE}"))
    };
    let number = |k: &str, default: Option<f64>| -> Result<f64, String> {
        match (get.get(k), default) {
            (Some(v), _) => v
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or_else(|| format!("--{k} must be a positive number, got '{v}'")),
            (None, Some(d)) => Ok(d),
            (None, None) => Err(format!("missing --{k}\n{USAGE}")),
        }
    };
    let fit_kpa = text("fit")?
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| format!("--fit: '{s}' is not a pressure in kPa"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut cfg = FitConfig::exact_wall(number("length", None)?, number("diameter", None)?);
    cfg.model = (
        get.get("model").map_or(Ok(cfg.model.0), |v| {
            v.parse::<i32>()
                .map_err(|_| format!("--model must be a bladder_model (1-6), got '{v}'"))
        })?,
        number("layers", Some(cfg.model.1 as f64))? as i32,
    );
    cfg.starts = number("starts", Some(24.0))? as usize;
    cfg.iterations = number("iterations", Some(200.0))? as usize;
    if let Some(fix) = get.get("fix") {
        cfg.fixed.clear();
        cfg.sleeve_on_wall = false;
        for item in fix.split(',').filter(|s| *s != "none" && !s.is_empty()) {
            let (name, value) = item
                .split_once('=')
                .ok_or_else(|| format!("--fix: write NAME=VALUE, got '{item}'"))?;
            if name.trim() == "sleeve_diameter" && value.trim() == "on_wall" {
                cfg.sleeve_on_wall = true;
                continue;
            }
            let param = PARAMS
                .into_iter()
                .find(|p| p.name() == name.trim())
                .ok_or_else(|| {
                    let names: Vec<_> = PARAMS.iter().map(|p| p.name()).collect();
                    format!("--fix: '{name}' is none of {}", names.join(", "))
                })?;
            let value = value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| format!("--fix {name}: '{value}' is not a positive number"))?;
            cfg.fixed.push((param, value));
        }
    }
    Ok(Args {
        data: text("data")?.into(),
        out: text("out")?.into(),
        fit_kpa,
        cfg,
    })
}

fn read_csv(path: &PathBuf) -> Result<Vec<Datum>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut data = Vec::new();
    let mut header_seen = false;
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if !header_seen {
            if line.replace(' ', "") != "pressure_kpa,contraction,force_n" {
                return Err(format!(
                    "{}:{}: expected the header pressure_kpa,contraction,force_n, got '{line}'",
                    path.display(),
                    i + 1
                ));
            }
            header_seen = true;
            continue;
        }
        let fields: Vec<f64> = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{}:{}: {e}", path.display(), i + 1))?;
        match fields[..] {
            [p, c, f] if p.is_finite() && c.is_finite() && f.is_finite() => data.push(Datum {
                pressure: p * 1e3,
                contraction: c,
                force: f,
            }),
            _ => return Err(format!("{}:{}: need three numbers", path.display(), i + 1)),
        }
    }
    if data.is_empty() {
        return Err(format!("{}: no data", path.display()));
    }
    Ok(data)
}

fn params_json(p: &MuscleParams) -> String {
    let mut s = String::from("{\n  \"preset\": 0,\n");
    let _ = writeln!(s, "  \"bladder_model\": {},", p.bladder_model);
    let _ = writeln!(s, "  \"bladder_layers\": {},", p.bladder_layers);
    let reals = p.named_reals();
    for (i, (name, v)) in reals.iter().enumerate() {
        let sep = if i + 1 < reals.len() { "," } else { "" };
        let _ = writeln!(s, "  \"{name}\": {v:e}{sep}");
    }
    s + "}\n"
}

fn unit_of(name: &str) -> &'static str {
    match name {
        "turns" => "1",
        "mooney_c1" | "mooney_c2" => "Pa",
        _ => "m",
    }
}

/// SSP 1.0 parameter values (SystemStructureParameterValues) with their units.
fn params_ssv(p: &MuscleParams, name: &str) -> String {
    let mut s = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <ssv:ParameterSet xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\" \
         xmlns:ssc=\"http://ssp-standard.org/SSP1/SystemStructureCommon\" version=\"1.0\" name=\"{name}\">\n  <ssv:Parameters>\n"
    );
    for (n, v) in [
        ("preset", 0),
        ("bladder_model", p.bladder_model),
        ("bladder_layers", p.bladder_layers),
    ] {
        let _ = writeln!(
            s,
            "    <ssv:Parameter name=\"{n}\"><ssv:Integer value=\"{v}\"/></ssv:Parameter>"
        );
    }
    for (n, v) in p.named_reals() {
        let _ = writeln!(
            s,
            "    <ssv:Parameter name=\"{n}\"><ssv:Real value=\"{v:e}\" unit=\"{}\"/></ssv:Parameter>",
            unit_of(n)
        );
    }
    s += "  </ssv:Parameters>\n  <ssv:Units>\n    <ssc:Unit name=\"1\"><ssc:BaseUnit/></ssc:Unit>\n    \
          <ssc:Unit name=\"m\"><ssc:BaseUnit m=\"1\"/></ssc:Unit>\n    \
          <ssc:Unit name=\"Pa\"><ssc:BaseUnit kg=\"1\" m=\"-1\" s=\"-2\"/></ssc:Unit>\n  </ssv:Units>\n</ssv:ParameterSet>\n";
    s
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let data = read_csv(&args.data)?;
    let all = curves(&data);
    let fitted: Vec<Curve> = all
        .iter()
        .filter(|c| {
            args.fit_kpa
                .iter()
                .any(|k| (k * 1e3 - c.pressure).abs() < 1e-6)
        })
        .cloned()
        .collect();
    if fitted.len() != args.fit_kpa.len() {
        let have: Vec<String> = all
            .iter()
            .map(|c| format!("{}", c.pressure / 1e3))
            .collect();
        return Err(format!(
            "--fit {:?} kPa: the data has curves at {} kPa only",
            args.fit_kpa,
            have.join(", ")
        ));
    }
    let cfg = &args.cfg;
    eprintln!(
        "calibrate: {} points in {} curves; fitting {} curves ({} points), bladder_model {} \
         ({} layers or nodes), {} starts",
        data.len(),
        all.len(),
        fitted.len(),
        fitted.iter().map(|c| c.points.len()).sum::<usize>(),
        cfg.model.0,
        cfg.model.1,
        cfg.starts
    );
    let t0 = Instant::now();
    let best = fit(cfg, &fitted, |k, n, b| {
        let worst = errors(&b.params, &fitted)
            .iter()
            .map(|e| e.rms)
            .fold(0.0, f64::max);
        eprintln!(
            "  start {k:>3}/{n}: best worst-curve RMS {:.2}% ({:.1} s)",
            100.0 * worst,
            t0.elapsed().as_secs_f64()
        );
    })?;
    let seconds = t0.elapsed().as_secs_f64();
    let p = best.params;
    let errs = errors(&p, &all);

    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let write = |name: &str, text: String| {
        let path = args.out.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))
    };
    write("params.json", params_json(&p))?;
    let stem = args
        .data
        .file_stem()
        .map_or("muscle".into(), |s| s.to_string_lossy().into_owned());
    write("params.ssv", params_ssv(&p, &stem))?;

    let muscle = p.muscle()?;
    let mut csv = String::from("pressure_kpa,contraction,force_n,model_force_n,fitted\n");
    for c in &all {
        let is_fit = fitted.iter().any(|f| f.pressure == c.pressure);
        for d in &c.points {
            let f = model_force(&muscle, p.nominal_length, d).unwrap_or(f64::NAN);
            let _ = writeln!(
                csv,
                "{},{},{},{},{}",
                d.pressure / 1e3,
                d.contraction,
                d.force,
                f,
                is_fit as u8
            );
        }
    }
    write("fit.csv", csv)?;

    let rows: Vec<serde_json::Value> = errs
        .iter()
        .map(|e| {
            serde_json::json!({
                "pressure_kpa": e.pressure / 1e3,
                "fitted": fitted.iter().any(|f| f.pressure == e.pressure),
                "rms": e.rms, "max": e.max, "infeasible": e.infeasible,
            })
        })
        .collect();
    let report = parameter_report(cfg, &p);
    let parameters: Vec<serde_json::Value> = report
        .iter()
        .map(|r| {
            serde_json::json!({
                "name": r.name, "unit": r.unit, "value": r.value, "lower": r.lower,
                "upper": r.upper, "fixed": r.fixed, "position": r.position,
            })
        })
        .collect();
    let summary = serde_json::json!({
        "data": args.data.display().to_string(),
        "nominal_length": cfg.nominal_length,
        "diameter": cfg.diameter,
        "fit_kpa": args.fit_kpa,
        "bladder_model": cfg.model.0,
        "bladder_layers": cfg.model.1,
        "parameters": parameters,
        "starts": cfg.starts,
        "seconds": seconds,
        "cost": best.cost,
        "braid_angle_deg": p.braid_angle().to_degrees(),
        "max_length": muscle.max_length(),
        "min_length": muscle.min_length(),
        "errors": rows,
    });
    write(
        "fit.json",
        serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())? + "\n",
    )?;

    println!(
        "fitted in {seconds:.1} s: braid angle {:.2} deg at the nominal length",
        p.braid_angle().to_degrees()
    );
    println!("pressure_kpa  fitted  rms_%   max_%");
    for e in &errs {
        let is_fit = fitted.iter().any(|f| f.pressure == e.pressure);
        println!(
            "{:>12}  {:>6}  {:>5.2}  {:>6.2}{}",
            e.pressure / 1e3,
            if is_fit { "yes" } else { "no" },
            100.0 * e.rms,
            100.0 * e.max,
            if e.infeasible > 0 {
                format!(
                    "  ({} points outside the model's length range)",
                    e.infeasible
                )
            } else {
                String::new()
            }
        );
    }
    println!("parameter               value        lower        upper      fitted");
    for r in &report {
        let at_bound = !r.fixed && (r.position < AT_BOUND || r.position > 1.0 - AT_BOUND);
        println!(
            "{:<22} {:>11.4e}  {:>11.4e}  {:>11.4e}  {}{}",
            r.name,
            r.value,
            r.lower,
            r.upper,
            match (r.fixed, r.name) {
                (false, _) => "yes",
                (true, "sleeve_diameter") if cfg.sleeve_on_wall => "bore + 2 wall",
                (true, _) => "fixed",
            },
            if at_bound { "  AT A BOUND" } else { "" }
        );
    }
    println!("wrote {}", args.out.display());
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("calibrate: {e}");
        std::process::exit(1);
    }
}
