//! The `fmi` crate (0.8, feature `fmi3`) imports the FMI 3.0 FMUs: the same forces as its FMI 2.0
//! import of the FMI 2.0 FMU, bit for bit, in Co-Simulation; Model Exchange's counts and states.
//!
//! fmi-schema 0.8 refuses two things FMI 3.0 allows (section 2.4.7.3 and 2.4.3): a `unit`
//! attribute on a Float64 variable and the base units `A` and `K` (it expects lower case). The
//! test hands the crate the FMU with its units removed, so that what it checks is the binary
//! through the crate's FMI 3.0 calls; `validate_fmu` checks the description as shipped.

use crate::common;

use common::mckibben::*;
use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation as _, Common as _};
use fmi::fmi3::import::Fmi3Import;
use fmi::fmi3::{CoSimulation as _, Common as _, Fmi3Model as _, GetSet as _, ModelExchange as _};
use fmi::traits::FmiImport;

/// The FMI 3.0 FMU of `model`, its description's units removed (see above), in target/tmp.
fn fmi3_path(model: &str) -> std::path::PathBuf {
    use std::io::{Read, Write};
    let fmi2 = common::fmu_path(model);
    let target = fmi2.parent().and_then(|p| p.parent()).unwrap();
    let shipped = target.join("fmu-fmi3").join(format!("{model}.fmu"));
    assert!(
        shipped.exists(),
        "{} is missing: run `make fmus`",
        shipped.display()
    );
    let dir = target.join("tmp/fmi3-crate");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!(
        "{model}-{}-{:?}.fmu",
        std::process::id(),
        std::thread::current().id()
    ));
    let mut archive = zip::ZipArchive::new(std::fs::File::open(&shipped).unwrap()).unwrap();
    let mut zip = zip::ZipWriter::new(std::fs::File::create(&out).unwrap());
    let options = zip::write::SimpleFileOptions::default();
    for i in 0..archive.len() {
        let mut entry = archive.by_index(i).unwrap();
        let name = entry.name().to_string();
        let mut data = Vec::new();
        entry.read_to_end(&mut data).unwrap();
        if name == "modelDescription.xml" {
            data = without_units(&String::from_utf8(data).unwrap()).into_bytes();
        }
        zip.start_file(name.as_str(), options).unwrap();
        zip.write_all(&data).unwrap();
    }
    zip.finish().unwrap();
    out
}

fn without_units(xml: &str) -> String {
    let start = xml.find("<UnitDefinitions>").unwrap();
    let end = xml.find("</UnitDefinitions>").unwrap() + "</UnitDefinitions>".len();
    let mut out = format!("{}{}", &xml[..start], &xml[end..]);
    while let Some(at) = out.find(" unit=\"") {
        let close = out[at + 7..].find('"').unwrap() + at + 8;
        out.replace_range(at..close, "");
    }
    out
}

/// The crate's import of `model`'s FMI 3.0 FMU (it extracts the archive, which is then removed).
fn import(model: &str) -> Fmi3Import {
    let path = fmi3_path(model);
    let import = fmi::import::from_path(&path).expect("the fmi crate loads the FMI 3.0 FMU");
    let _ = std::fs::remove_file(path);
    import
}

fn load() -> Fmi3Import {
    import("McKibbenMuscle")
}

#[test]
fn the_description_reads_back_as_fmi3() {
    let import = load();
    let md = import.model_description();
    assert_eq!(md.fmi_version, "3.0");
    assert_eq!(md.model_name, "McKibbenMuscle");
    assert_eq!(md.instantiation_token, common::guid_of("McKibbenMuscle"));
}

#[test]
fn co_simulation_gives_the_fmi2_forces_bit_for_bit() {
    let import3 = load();
    let import2: Fmi2Import = fmi::import::from_path(common::fmu_path("McKibbenMuscle")).unwrap();
    let mut cs3 = import3
        .instantiate_cs("muscle3", false, false, false, false, &[])
        .expect("instantiates");
    let mut cs2 = import2.instantiate_cs("muscle2", false, false).unwrap();
    cs3.enter_initialization_mode(None, 0.0, None).unwrap();
    cs3.exit_initialization_mode().unwrap();
    cs2.setup_experiment(None, 0.0, None).unwrap();
    cs2.enter_initialization_mode().unwrap();
    cs2.exit_initialization_mode().unwrap();
    let mut t = 0.0;
    for i in 0..11 {
        for j in 0..11 {
            let p = 6e5 * i as f64 / 10.0;
            let l = 0.04 + 0.07 * j as f64 / 10.0;
            cs3.set_float64(&[PRESSURE, LENGTH], &[p, l]).unwrap();
            cs2.set_real(&[PRESSURE, LENGTH], &[p, l]).unwrap();
            let (mut event, mut terminate, mut early, mut last) = (true, true, true, 0.0);
            cs3.do_step(
                t,
                0.01,
                true,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
            .unwrap();
            cs2.do_step(t, 0.01, true).unwrap();
            t += 0.01;
            assert!(!event && !terminate && !early);
            assert_eq!(last, t);
            let (mut f3, mut f2) = ([0.0; 2], [0.0; 2]);
            cs3.get_float64(&[FORCE, VOLUME], &mut f3).unwrap();
            cs2.get_real(&[FORCE, VOLUME], &mut f2).unwrap();
            assert_eq!(f3.map(f64::to_bits), f2.map(f64::to_bits), "P={p} L={l}");
        }
    }
}

#[test]
fn model_exchange_instantiates_and_reports_its_states() {
    let import = import("MultiferroicMotor");
    let mut me = import.instantiate_me("motor", false, false).unwrap();
    let states = me.get_number_of_continuous_states().unwrap();
    let indicators = me.get_number_of_event_indicators().unwrap();
    assert_eq!((states, indicators), (4, 1));
    me.enter_initialization_mode(None, 0.0, None).unwrap();
    me.exit_initialization_mode().unwrap();
    me.enter_continuous_time_mode().unwrap();
    let mut x = vec![0.0; states];
    me.get_continuous_states(&mut x).unwrap();
    assert!(x.iter().all(|v| v.is_finite()));
}
