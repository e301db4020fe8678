//! `package_fmus <shared library> <output dir>`: writes `<output dir>/<Model>.fmu` for every model.

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, binary, out_dir] = &args[..] else {
        eprintln!("usage: package_fmus <path to libactuator_fmus.so> <output directory>");
        std::process::exit(2);
    };
    match actuator_fmus_tools::package::package_all(binary.as_ref(), out_dir.as_ref()) {
        Ok(paths) => paths.iter().for_each(|p| println!("wrote {}", p.display())),
        Err(e) => {
            eprintln!("package_fmus: {e}");
            std::process::exit(1);
        }
    }
}
