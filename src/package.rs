//! Writes `<Model>.fmu` archives: model description, binary, and generated documentation.

use crate::fmi2::runtime::Factory;
use crate::variables::{ModelInfo, Start, Variable};
use std::io::Write;
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;

/// Packs one FMU per registered model into `out_dir`, each with a copy of the shared library
/// `binary` (one library serves every model; `fmi2Instantiate` picks the model by GUID).
pub fn package_all(binary: &Path, out_dir: &Path) -> Result<Vec<PathBuf>, String> {
    let so = std::fs::read(binary).map_err(|e| format!("cannot read {}: {e}", binary.display()))?;
    std::fs::create_dir_all(out_dir)
        .map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    crate::fmi2::REGISTRY
        .iter()
        .map(|f| package(*f, &so, out_dir))
        .collect()
}

fn package(factory: &dyn Factory, so: &[u8], out_dir: &Path) -> Result<PathBuf, String> {
    let info = factory.info();
    let path = out_dir.join(format!("{}.fmu", info.name));
    let file = std::fs::File::create(&path)
        .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    // A plot of the model's cross-check run (crosscheck/generate.py), shipped when present.
    let plot_path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/fmu")
        .join(format!("{}.png", info.name));
    let plot = std::fs::read(&plot_path).ok();
    let mut equations = factory.documentation().to_string();
    if plot.is_some() {
        equations.push_str(&format!(
            "\n<h2>Plot</h2>\n<p>The cross-check run (default experiment, inputs from \
             <code>{name}_in.csv</code>):</p>\n<p><img src=\"plot.png\" alt=\"{name} cross-check run\" \
             style=\"max-width:100%\"></p>\n",
            name = info.name
        ));
    }
    let doc = documentation(info, &equations);
    let mut entries: Vec<(String, &[u8])> = vec![
        (
            "modelDescription.xml".into(),
            info.model_description_xml.as_bytes(),
        ),
        (format!("binaries/linux64/{}.so", info.name), so),
        ("documentation/index.html".into(), doc.as_bytes()),
    ];
    if let Some(png) = &plot {
        entries.push(("documentation/plot.png".into(), png));
    }
    for (name, data) in entries {
        zip.start_file(name.as_str(), options)
            .map_err(|e| e.to_string())?;
        zip.write_all(data).map_err(|e| e.to_string())?;
    }
    zip.finish().map_err(|e| e.to_string())?;
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
        Start::Real(x) => format!("{x}"),
        Start::Integer(x) => format!("{x}"),
        Start::Boolean(x) => format!("{x}"),
        Start::String(x) => escape(x),
    }
}

/// `documentation/index.html`: what the model is, its variables, the equations it implements.
pub fn documentation(info: &ModelInfo, equations: &str) -> String {
    let mut rows = String::new();
    for v in info.variables {
        let range = match (v.min, v.max) {
            (None, None) => String::new(),
            (min, max) => format!(
                "{} .. {}",
                min.map_or("".into(), |x| x.to_string()),
                max.map_or("".into(), |x| x.to_string())
            ),
        };
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{:?}</td><td>{:?}</td><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            v.name,
            v.causality,
            v.variability,
            v.kind,
            escape(v.unit),
            start_text(v),
            range,
            escape(v.description)
        ));
    }
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title>\
         <style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}table{{border-collapse:collapse}}\
         td,th{{border:1px solid #ccc;padding:0.2em 0.5em}}</style></head><body>\n\
         <h1>{name}</h1>\n<p>{description}</p>\n<p>FMI 2.0 Co-Simulation, GUID <code>{guid}</code>.</p>\n\
         <h2>Variables</h2>\n<table><tr><th>name</th><th>causality</th><th>variability</th><th>type</th>\
         <th>unit</th><th>start</th><th>range</th><th>description</th></tr>\n{rows}</table>\n{equations}\n\
         <p>Source: the dissertation the project is built on; equation numbers refer to it.</p>\n</body></html>\n",
        name = info.name,
        description = escape(info.description),
        guid = info.guid,
    )
}
