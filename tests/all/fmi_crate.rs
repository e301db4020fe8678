//! A second, independent importer: the `fmi` crate loads the packaged FMU and must see eq. 2.3 and
//! working FMU states, as FMPy does.

use crate::common;

use common::gaylord_force;
use common::mckibben::*;
use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::traits::{FmiImport, FmiStatus};

const B: f64 = 0.1113;
const N: f64 = 3.74;

fn load() -> Fmi2Import {
    fmi::import::from_path(common::fmu_path("McKibbenMuscle")).expect("the fmi crate loads the FMU")
}

#[test]
fn model_description_reads_back() {
    let import = load();
    let md = import.model_description();
    assert_eq!(md.fmi_version, "2.0");
    assert_eq!(md.model_name, "McKibbenMuscle");
    assert_eq!(md.guid, common::guid_of("McKibbenMuscle"));
}

#[test]
fn force_follows_eq_2_3() {
    let import = load();
    let mut cs = import
        .instantiate_cs("muscle", false, false)
        .expect("instantiates");
    cs.setup_experiment(None, 0.0, None).unwrap();
    cs.enter_initialization_mode().unwrap();
    cs.exit_initialization_mode().unwrap();
    let mut t = 0.0;
    let mut points = 0;
    for i in 0..11 {
        for j in 0..11 {
            let p = 6e5 * i as f64 / 10.0;
            let l = 0.3 * B + 0.65 * B * j as f64 / 10.0;
            cs.set_real(&[PRESSURE, LENGTH], &[p, l]).unwrap();
            cs.do_step(t, 0.01, true).unwrap();
            t += 0.01;
            let mut out = [0.0; 2];
            cs.get_real(&[FORCE, VOLUME], &mut out).unwrap();
            // Tension only: eq. 2.3 where it pulls, 0 (slack) where it would push.
            let f = gaylord_force(p, l, B, N).max(0.0);
            assert!(
                (out[0] - f).abs() <= 1e-12 * f.abs().max(1.0),
                "P={p} L={l}: {} vs {f}",
                out[0]
            );
            points += 1;
        }
    }
    assert_eq!(points, 121);
}

#[test]
fn fmu_state_round_trips() {
    let import = load();
    let mut cs = import.instantiate_cs("muscle", false, false).unwrap();
    cs.setup_experiment(None, 0.0, None).unwrap();
    cs.enter_initialization_mode().unwrap();
    cs.exit_initialization_mode().unwrap();
    cs.set_real(&[PRESSURE, LENGTH], &[2e5, 0.08]).unwrap();
    cs.do_step(0.0, 0.5, true).unwrap();
    let state = cs.get_fmu_state().unwrap();
    let bytes = cs.serialize_fmu_state(&state).unwrap();
    cs.set_real(&[PRESSURE], &[5e5]).unwrap();
    cs.do_step(0.5, 0.5, true).unwrap();
    let restored = cs.deserialize_fmu_state(&bytes).unwrap();
    assert!(!cs.set_fmu_state(&restored).is_error());
    let mut p = [0.0];
    cs.get_real(&[PRESSURE], &mut p).unwrap();
    assert_eq!(p[0], 2e5);
    assert!(cs.last_successful_time().unwrap() == 0.5);
}
