//! `package_fmi3 <FMI 2.0 FMU dir> <output dir>`: writes `<output dir>/<Model>.fmu`, the FMI 3.0
//! FMU of every model, from the FMI 2.0 FMU that `package_fmus` wrote: the same binaries (one
//! library exports both APIs) under FMI 3.0's platform tuples, its documentation page naming FMI 3.0, the
//! FMI 3.0 model description generated from the same source, and `terminalsAndIcons/`: the
//! model's icon and mechanical flanges (`terminalsAndIcons.xml`), with the icon and each flange's
//! icon as SVG and PNG (`actuator_fmus_tools::icons`).

use actuator_fmus_tools::icons;
use std::io::{Read, Write};
use std::path::Path;

/// FMI 2.0 platform folders and their FMI 3.0 tuples (FMI 3.0 section 2.5.1.1).
const PLATFORMS: [(&str, &str); 3] = [
    ("binaries/linux64/", "binaries/x86_64-linux/"),
    ("binaries/win64/", "binaries/x86_64-windows/"),
    ("binaries/aarch64-linux/", "binaries/aarch64-linux/"),
];

fn repackage(
    model: &str,
    fmi2: &Path,
    out: &Path,
    description: &str,
    documentation: &str,
    terminals: Option<&str>,
) -> Result<(), String> {
    let file =
        std::fs::File::open(fmi2).map_err(|e| format!("cannot read {}: {e}", fmi2.display()))?;
    let mut archive = zip::ZipArchive::new(file).map_err(|e| format!("{}: {e}", fmi2.display()))?;
    let partial = out.with_extension(format!("fmu.{}.partial", std::process::id()));
    let target = std::fs::File::create(&partial)
        .map_err(|e| format!("cannot create {}: {e}", partial.display()))?;
    let mut zip = zip::ZipWriter::new(target);
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)
        .map_err(|e| e.to_string())?;
    zip.write_all(description.as_bytes())
        .map_err(|e| e.to_string())?;
    zip.start_file("documentation/index.html", options)
        .map_err(|e| e.to_string())?;
    zip.write_all(documentation.as_bytes())
        .map_err(|e| e.to_string())?;
    if let Some(terminals) = terminals {
        let mut files = vec![(
            "terminalsAndIcons.xml".to_string(),
            terminals.as_bytes().to_vec(),
        )];
        let (svg, png) = icons::fmu_icon(model)?;
        files.push(("icon.svg".into(), svg.into_bytes()));
        files.push(("icon.png".into(), png));
        for name in ["translational_flange", "rotational_flange"] {
            if terminals.contains(&format!("iconBaseName=\"{name}\"")) {
                let (svg, png) = icons::flange_icon(name)?;
                files.push((format!("{name}.svg"), svg.into_bytes()));
                files.push((format!("{name}.png"), png));
            }
        }
        for (name, data) in files {
            zip.start_file(format!("terminalsAndIcons/{name}"), options)
                .map_err(|e| e.to_string())?;
            zip.write_all(&data).map_err(|e| e.to_string())?;
        }
    }
    for i in 0..archive.len() {
        let mut entry = archive.by_index(i).map_err(|e| e.to_string())?;
        let name = entry.name().to_string();
        if name == "modelDescription.xml" || name == "documentation/index.html" || entry.is_dir() {
            continue;
        }
        let renamed = PLATFORMS
            .iter()
            .find_map(|(from, to)| name.strip_prefix(from).map(|rest| format!("{to}{rest}")))
            .unwrap_or(name);
        let mut data = Vec::new();
        entry.read_to_end(&mut data).map_err(|e| e.to_string())?;
        zip.start_file(renamed.as_str(), options)
            .map_err(|e| e.to_string())?;
        zip.write_all(&data).map_err(|e| e.to_string())?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    std::fs::rename(&partial, out).map_err(|e| format!("cannot write {}: {e}", out.display()))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, fmi2_dir, out_dir] = &args[..] else {
        eprintln!("usage: package_fmi3 <directory of the FMI 2.0 FMUs> <output directory>");
        std::process::exit(2);
    };
    if let Err(e) = std::fs::create_dir_all(out_dir) {
        eprintln!("package_fmi3: cannot create {out_dir}: {e}");
        std::process::exit(1);
    }
    for model in actuator_fmus::fmi3::FMI3_MODELS {
        let fmi2 = Path::new(fmi2_dir).join(format!("{}.fmu", model.name));
        let out = Path::new(out_dir).join(format!("{}.fmu", model.name));
        let terminals = actuator_fmus::terminals::terminals_and_icons(model.name);
        let Some(factory) = actuator_fmus::export::REGISTRY
            .iter()
            .find(|f| f.info().name == model.name)
        else {
            eprintln!("package_fmi3: {} is not in the registry", model.name);
            std::process::exit(1);
        };
        let page = actuator_fmus_tools::package::documentation_page(*factory, "3.0");
        match repackage(
            model.name,
            &fmi2,
            &out,
            model.model_description_xml,
            &page,
            terminals,
        ) {
            Ok(()) => println!("wrote {}", out.display()),
            Err(e) => {
                eprintln!("package_fmi3: {e}");
                std::process::exit(1);
            }
        }
    }
}
