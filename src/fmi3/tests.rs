//! The FMI 3.0 view of each model against the FMI 2.0 one it is generated beside.

use super::FMI3_MODELS;
use crate::export::REGISTRY;

#[test]
fn every_model_has_an_fmi3_description_with_the_same_token() {
    assert_eq!(FMI3_MODELS.len(), REGISTRY.len());
    for (model, factory) in FMI3_MODELS.iter().zip(REGISTRY) {
        let info = factory.info();
        assert_eq!(model.name, info.name);
        let token = format!("instantiationToken=\"{}\"", info.guid);
        assert!(
            model.model_description_xml.contains(&token),
            "{}",
            model.name
        );
        assert!(model.model_description_xml.contains("fmiVersion=\"3.0\""));
    }
}

#[test]
fn value_references_are_unique_and_the_float64_ones_are_the_fmi2_reals() {
    for (model, factory) in FMI3_MODELS.iter().zip(REGISTRY) {
        let info = factory.info();
        let xml = model.model_description_xml;
        let mut seen = std::collections::BTreeSet::new();
        for (at, key) in xml.match_indices("valueReference=\"") {
            let piece = &xml[at + key.len()..];
            let line_start = xml[..at].rfind('<').unwrap();
            let element = &xml[line_start + 1..];
            let element = &element[..element.find(' ').unwrap()];
            let vr: u32 = piece[..piece.find('"').unwrap()].parse().unwrap();
            if !matches!(element, "Float64" | "Int32" | "Enumeration" | "Boolean") {
                continue; // ModelStructure entries name variables, they declare none
            }
            assert!(
                seen.insert(vr),
                "{}: value reference {vr} twice",
                model.name
            );
            if element == "Float64" && vr < model.time {
                let name_at = xml[line_start..].find("name=\"").unwrap() + line_start + 6;
                let name = &xml[name_at..name_at + xml[name_at..].find('"').unwrap()];
                assert_eq!(info.by_name(name).map(|v| v.vr), Some(vr), "{name}");
            }
        }
        let [reals, integers, booleans, _] = info.counts;
        let indicators = (model.integers - model.event_indicators) as usize;
        assert_eq!(model.time as usize, reals);
        assert_eq!(
            seen.len(),
            reals + 1 + indicators + integers + booleans + model.arrays.len()
        );
        // The array outputs follow the Booleans, one value reference each.
        for (k, array) in model.arrays.iter().enumerate() {
            assert_eq!(
                array.value_reference,
                model.booleans + (booleans + k) as u32
            );
            assert!(array.size >= 1);
        }
    }
}

#[test]
fn every_declared_array_is_served_by_its_model() {
    use crate::export::runtime::Runtime;
    for (model, factory) in FMI3_MODELS.iter().zip(REGISTRY) {
        let mut runtime: Box<dyn Runtime> = factory.create();
        runtime.build().unwrap();
        for (k, array) in model.arrays.iter().enumerate() {
            let mut out = vec![f64::NAN; array.size];
            runtime.array(k, &mut out).unwrap();
            assert!(out.iter().all(|x| x.is_finite()), "{}", array.name);
        }
        let mut out = [0.0];
        assert!(runtime.array(model.arrays.len(), &mut out).is_err());
    }
}
