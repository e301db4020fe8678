//! Finds MuJoCo (the pip wheel's package directory: `include/` and `libmujoco.so.*`), checks the
//! plugin's hand-written layout against its headers at compile time, compiles the C logger shim and
//! links against libmujoco.
//!
//! MUJOCO_DIR overrides the search; otherwise `$PYTHON` (default: the project's `.venv/bin/python`,
//! then `python3`) is asked where `mujoco` is installed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

#[allow(dead_code)]
mod layout {
    include!("src/layout.rs");
}

fn mujoco_dir() -> PathBuf {
    if let Ok(dir) = std::env::var("MUJOCO_DIR") {
        return PathBuf::from(dir);
    }
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join("../.venv/bin/python");
    let pythons = std::env::var("PYTHON")
        .into_iter()
        .chain([venv.display().to_string(), "python3".to_string()]);
    for python in pythons {
        let out = Command::new(&python)
            .args([
                "-c",
                "import mujoco, os; print(os.path.dirname(mujoco.__file__))",
            ])
            .output();
        if let Ok(out) = out {
            if out.status.success() {
                return PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
            }
        }
    }
    panic!(
        "MuJoCo not found: `pip install mujoco==4.0.0` (make mujoco-plugin does) or set MUJOCO_DIR"
    );
}

fn main() {
    println!("cargo:rerun-if-env-changed=MUJOCO_DIR");
    println!("cargo:rerun-if-env-changed=PYTHON");
    println!("cargo:rerun-if-changed=src/layout.rs");
    println!("cargo:rerun-if-changed=src/shim.c");
    let dir = mujoco_dir();
    let include = dir.join("include");
    assert!(
        include.join("mujoco/mjplugin.h").exists(),
        "{} has no include/mujoco/mjplugin.h",
        dir.display()
    );

    // Every hand-written number becomes a compile-time assertion against the headers.
    let mut checks = String::new();
    let mut check = |condition: String, what: &str| {
        writeln!(
            checks,
            "_Static_assert({condition}, \"layout.rs: {what}\");"
        )
        .unwrap();
    };
    check(
        format!("mjVERSION_HEADER == {}", layout::MUJOCO_VERSION),
        "MUJOCO_VERSION",
    );
    check("sizeof(mjtNum) == 8".into(), "mjtNum is double");
    check("sizeof(mjtByte) == 1".into(), "mjtByte");
    for (ty, field, offset) in layout::CHECKED_OFFSETS {
        check(
            format!("offsetof({ty}, {field}) == {offset}"),
            &format!("{ty}.{field}"),
        );
    }
    check(
        format!(
            "sizeof(mjpPlugin) == {}",
            std::mem::size_of::<layout::MjpPlugin>()
        ),
        "sizeof(mjpPlugin)",
    );
    for (field, offset) in layout::plugin_offsets() {
        check(
            format!("offsetof(mjpPlugin, {field}) == {offset}"),
            &format!("mjpPlugin.{field}"),
        );
    }
    check(
        format!("mjPLUGIN_ACTUATOR == {}", layout::PLUGIN_ACTUATOR),
        "PLUGIN_ACTUATOR",
    );
    check(
        format!("mjOBJ_ACTUATOR == {}", layout::OBJ_ACTUATOR),
        "OBJ_ACTUATOR",
    );
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    std::fs::write(out.join("layout_checks.h"), checks).unwrap();

    cc::Build::new()
        .file("src/shim.c")
        .include(&include)
        .include(&out)
        .warnings(true)
        // Unwind tables: a host whose mju_error handler throws (Python's bindings) unwinds through it.
        .flag("-fexceptions")
        .compile("actuator_fmus_mujoco_shim");

    // The wheel ships libmujoco.so.<version> only (no unversioned link name): link it verbatim.
    // In a process that already loaded MuJoCo (Python's bindings, any MuJoCo host) the dynamic
    // loader matches this name to the library in memory.
    let lib = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .find(|name| name.starts_with("libmujoco.so"))
        .unwrap_or_else(|| panic!("no libmujoco.so* in {}", dir.display()));
    println!("cargo:rustc-link-search=native={}", dir.display());
    println!("cargo:rustc-link-lib=dylib:+verbatim={lib}");
    // rust-lang/rust#91979: a cdylib unloaded while thread-local destructors are registered
    // crashes at thread exit; never unload (an ELF linker flag).
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-z,nodelete");
    }
}
