//! `package_fmus <shared library> <output dir> [<platform>=<binary> ...]`: writes
//! `<output dir>/<Model>.fmu` for every model, with the library in `binaries/linux64` and each
//! further binary in `binaries/<platform>` (e.g. `win64=actuator_fmus.dll`).

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, binary, out_dir, more @ ..] = &args[..] else {
        eprintln!(
            "usage: package_fmus <path to libactuator_fmus.so> <output directory> [<platform>=<binary> ...]"
        );
        std::process::exit(2);
    };
    let mut binaries = vec![("linux64".to_string(), std::path::PathBuf::from(binary))];
    for extra in more {
        let Some((platform, path)) = extra.split_once('=') else {
            eprintln!("package_fmus: expected <platform>=<binary>, got {extra}");
            std::process::exit(2);
        };
        binaries.push((platform.to_string(), path.into()));
    }
    match actuator_fmus_tools::package::package_all_platforms(&binaries, out_dir.as_ref()) {
        Ok(paths) => paths.iter().for_each(|p| println!("wrote {}", p.display())),
        Err(e) => {
            eprintln!("package_fmus: {e}");
            std::process::exit(1);
        }
    }
}
