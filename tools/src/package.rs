//! Writes `<Model>.fmu` archives: model description, binary, and generated documentation.

use actuator_fmus::export::runtime::Factory;
use actuator_fmus::variables::{ModelInfo, Start, Variable};
use std::io::Write;
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;

/// Packs one FMU per registered model into `out_dir`, each with a copy of the shared library
/// `binary` (one library serves every model; `fmi2Instantiate` picks the model by GUID).
pub fn package_all(binary: &Path, out_dir: &Path) -> Result<Vec<PathBuf>, String> {
    package_all_platforms(&[("linux64".into(), binary.to_path_buf())], out_dir)
}

/// As [`package_all`], with one binary per platform folder: `linux64` (x86_64 Linux), `win64`
/// (`.dll`), `aarch64-linux` (FMI 2.0.4 section 2.3 names other platforms as FMI 3.0 does).
pub fn package_all_platforms(
    binaries: &[(String, PathBuf)],
    out_dir: &Path,
) -> Result<Vec<PathBuf>, String> {
    let binaries = binaries
        .iter()
        .map(|(platform, path)| {
            let data =
                std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            let extension = if platform.starts_with("win") || platform.ends_with("-windows") {
                "dll"
            } else {
                "so"
            };
            Ok((platform.clone(), extension, data))
        })
        .collect::<Result<Vec<_>, String>>()?;
    std::fs::create_dir_all(out_dir)
        .map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    actuator_fmus::export::REGISTRY
        .iter()
        .map(|f| package(*f, &binaries, out_dir))
        .collect()
}

/// The cross-check run's plot of model `name` (python/actuator_fmus/crosscheck.py), shipped in the
/// FMU's documentation when present.
fn plot_path(name: &str) -> PathBuf {
    crate::repository_root()
        .join("docs/fmu")
        .join(format!("{name}.png"))
}

/// `documentation/index.html` of `factory`'s model as an FMI `fmi_version` FMU ("2.0" or "3.0"):
/// the same page in both, but for the interfaces it names.
pub fn documentation_page(factory: &dyn Factory, fmi_version: &str) -> String {
    let info = factory.info();
    let mut equations = factory.documentation().to_string();
    if plot_path(info.name).exists() {
        equations.push_str(&format!(
            "\n<h2>Plot</h2>\n<p>The cross-check run (default experiment, inputs from \
             <code>{name}_in.csv</code>):</p>\n<p><img src=\"plot.png\" alt=\"{name} cross-check run\" \
             style=\"max-width:100%\"></p>\n",
            name = info.name
        ));
    }
    equations.insert_str(0, &choices_html(factory, info));
    documentation(info, factory.model_exchange(), fmi_version, &equations)
}

fn package(
    factory: &dyn Factory,
    binaries: &[(String, &str, Vec<u8>)],
    out_dir: &Path,
) -> Result<PathBuf, String> {
    let info = factory.info();
    let path = out_dir.join(format!("{}.fmu", info.name));
    // Written beside and renamed over the FMU whole: a reader of the previous FMU (a test running
    // beside `make calibrate`, which repackages, under `make -j`) keeps reading it intact.
    let partial = out_dir.join(format!(".{}.fmu.{}.partial", info.name, std::process::id()));
    let file = std::fs::File::create(&partial)
        .map_err(|e| format!("cannot create {}: {e}", partial.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    // A plot of the model's cross-check run (python/actuator_fmus/crosscheck.py), shipped when present.
    let plot = std::fs::read(plot_path(info.name)).ok();
    let doc = documentation_page(factory, "2.0");
    let mut entries: Vec<(String, &[u8])> = vec![
        (
            "modelDescription.xml".into(),
            info.model_description_xml.as_bytes(),
        ),
        ("documentation/index.html".into(), doc.as_bytes()),
    ];
    for (platform, extension, data) in binaries {
        entries.push((
            format!("binaries/{platform}/{}.{extension}", info.name),
            data,
        ));
    }
    if let Some(png) = &plot {
        entries.push(("documentation/plot.png".into(), png));
    }
    for (name, data) in entries {
        zip.start_file(name.as_str(), options)
            .map_err(|e| e.to_string())?;
        zip.write_all(data).map_err(|e| e.to_string())?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    std::fs::rename(&partial, &path).map_err(|e| {
        format!(
            "cannot move {} to {}: {e}",
            partial.display(),
            path.display()
        )
    })?;
    Ok(path)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn start_text(v: &Variable) -> String {
    match v.start {
        Start::None => String::new(),
        Start::Real(x) => number(x),
        Start::Integer(x) => format!("{x}"),
        Start::Boolean(x) => format!("{x}"),
        Start::String(x) => escape(x),
    }
}

/// A number as a person reads it: plain between 0.001 and 1e6 with at most 6 significant digits
/// (0.1113, 161000), otherwise 4 significant digits with an exponent (3.043e-22, 1e-12, 1e+12).
/// The model description keeps the full value.
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs();
    if (1e-3..1e6).contains(&magnitude) {
        let decimals = (5 - magnitude.log10().floor() as i32).max(0) as usize;
        let text = format!("{x:.decimals$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        let text = format!("{x:.3e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let mantissa = if mantissa.contains('.') {
            mantissa.trim_end_matches('0').trim_end_matches('.')
        } else {
            mantissa
        };
        let exponent: i32 = exponent.parse().unwrap_or(0);
        format!(
            "{mantissa}e{}{exponent}",
            if exponent > 0 { "+" } else { "" }
        )
    }
}

/// A unit as printed: `m3` as m³, `kg.m2` as kg m², `N.m.s` as N m s.
fn unit_text(unit: &str) -> String {
    escape(unit)
        .replace('.', "\u{2009}")
        .replace('2', "\u{b2}")
        .replace('3', "\u{b3}")
}

/// The page's named choices: a table per Enumeration type, and the values each preset gives.
fn choices_html(factory: &dyn Factory, info: &ModelInfo) -> String {
    let xml = info.model_description_xml;
    let used_by = crate::choices::enumeration_variables(xml);
    let mut html = String::new();
    let enumerations = crate::choices::enumerations(xml);
    if !enumerations.is_empty() {
        html.push_str(
            "<h2>Named choices</h2>\n<p>Enumeration types: an importer shows the names; the values \
             travel as FMI Integers (fmi2SetInteger, FMPy start values by value or name).</p>\n",
        );
    }
    for e in &enumerations {
        let users: Vec<String> = used_by
            .iter()
            .filter(|(_, t)| *t == e.name)
            .map(|(v, _)| format!("<code>{v}</code>"))
            .collect();
        html.push_str(&format!(
            "<h3>{}</h3>\n<p>Used by {}.</p>\n<table><tr><th>value</th><th>name</th><th>meaning</th></tr>\n",
            e.name,
            users.join(", ")
        ));
        for (value, name, description) in &e.items {
            html.push_str(&format!(
                "<tr><td class=\"n\">{value}</td><td><code>{name}</code></td><td>{description}</td></tr>\n"
            ));
        }
        html.push_str("</table>\n");
    }
    if let Some((parameters, presets)) = crate::choices::preset_values(factory, info) {
        // One column per preset, one row per calculated parameter: the table stays narrow.
        html.push_str(
            "<h2>Presets</h2>\n<p>The calculated parameters with each <code>preset</code> and every \
             other parameter at its start value, read from the model (SI units).</p>\n\
             <table><tr><th>calculated parameter</th><th>unit</th>",
        );
        for (preset, _) in &presets {
            html.push_str(&format!("<th><code>{preset}</code></th>"));
        }
        html.push_str("</tr>\n");
        for (k, (name, unit)) in parameters.iter().enumerate() {
            html.push_str(&format!(
                "<tr><td><code>{name}</code></td><td>{}</td>",
                unit_text(unit)
            ));
            for (_, values) in &presets {
                let value = values.get(k).or(values.first()).map_or("", String::as_str);
                html.push_str(&format!("<td class=\"n\">{}</td>", escape(value)));
            }
            html.push_str("</tr>\n");
        }
        html.push_str("</table>\n");
    }
    html
}

/// `documentation/index.html`: what the model is, its interfaces and variables, the equations it
/// implements.
pub fn documentation(
    info: &ModelInfo,
    model_exchange: bool,
    fmi_version: &str,
    equations: &str,
) -> String {
    let enumeration_of = crate::choices::enumeration_variables(info.model_description_xml);
    let mut rows = String::new();
    for v in info.variables {
        let kind = enumeration_of
            .iter()
            .find(|(name, _)| name == v.name)
            .map_or(format!("{:?}", v.kind), |(_, t)| {
                format!("Enumeration ({t})")
            });
        let range = match (v.min, v.max) {
            (None, None) => String::new(),
            (min, max) => format!(
                "{}&nbsp;..&nbsp;{}",
                min.map_or("".into(), number),
                max.map_or("".into(), number)
            ),
        };
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{:?}</td><td>{:?}</td><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>\n",
            v.name,
            v.causality,
            v.variability,
            kind,
            unit_text(v.unit),
            start_text(v),
            range,
            escape(v.description)
        ));
    }
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title>\
         <style>body{{font-family:sans-serif;max-width:72em;margin:2em auto;padding:0 1em}}\
         table{{border-collapse:collapse;width:100%}}\
         td,th{{border:1px solid #ccc;padding:0.2em 0.4em;vertical-align:top;text-align:left}}\
         td:first-child,td.n{{white-space:nowrap}}\
         img{{max-width:100%}}</style></head><body>\n\
         <h1>{name}</h1>\n<p>{description}</p>\n<p>{interfaces}, GUID <code>{guid}</code>.</p>\n\
         <h2>Variables</h2>\n<p>Values in SI units; the model description holds them to full precision.</p>\n\
         <table><tr><th>name</th><th>causality</th><th>variability</th><th>type</th>\
         <th>unit</th><th>start</th><th>range</th><th>description</th></tr>\n{rows}</table>\n{equations}\n\
         <h2>Source</h2>\n<p>Equation, figure, section and table numbers refer to E. Ball, \
         <i>Novel Methods in Meso-Scale and Nano-Scale Actuation</i>, M.S. thesis, Cornell University, \
         2014, available from Cornell's eCommons repository \
         (<a href=\"https://ecommons.cornell.edu\">ecommons.cornell.edu</a>; search for the title).</p>\n\
         </body></html>\n",
        name = info.name,
        description = escape(info.description),
        guid = info.guid,
        interfaces = if model_exchange {
            format!("FMI {fmi_version} Co-Simulation and Model Exchange (one binary serves both)")
        } else {
            format!("FMI {fmi_version} Co-Simulation")
        },
    )
}

#[cfg(test)]
mod tests {
    use super::number;

    #[test]
    fn numbers_read_at_a_glance() {
        assert_eq!(number(3.043293741141106e-22), "3.043e-22");
        assert_eq!(number(1e-12), "1e-12");
        assert_eq!(number(1e12), "1e+12");
        assert_eq!(number(-1e12), "-1e+12");
        assert_eq!(number(0.1113), "0.1113");
        assert_eq!(number(161000.0), "161000");
        assert_eq!(number(-101325.0), "-101325");
        assert_eq!(number(1.0471975511965976), "1.0472");
        assert_eq!(number(0.0), "0");
        assert_eq!(number(1.0), "1");
        assert_eq!(number(4096.0), "4096");
        assert_eq!(number(0.0010016), "0.0010016");
        assert_eq!(number(2e8), "2e+8");
    }
}
