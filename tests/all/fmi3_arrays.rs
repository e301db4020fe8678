//! The build script's check of the FMI 3.0 array outputs a model declares (`build/fmi3_arrays.rs`),
//! through the FMI 3.0 description it writes (`build/fmi3_description.rs`): the muscle's wall
//! arrays are fixed-size outputs with the dependencies of the scalar output they name, and an
//! array of no size, named like a variable or another array, depending on what is not an output,
//! or with an unknown attribute is refused with the reason.

use crate::build_script::{fmi3_description, model_description};

const SOURCE: &str = include_str!("../../modelDescription/McKibbenMuscle.xml");
const ARRAY: &str = r#"<Array name="wall_radius" size="9" unit="m" dependenciesOf="stress_hoop""#;

fn generated(text: &str) -> Result<String, String> {
    let model = model_description::check(text, "McKibbenMuscle")?;
    fmi3_description::xml(text, &model)
}

/// The McKibben description with its `wall_radius` declaration replaced by `to`.
fn refused(to: &str, reason: &str) {
    assert!(SOURCE.contains(ARRAY));
    match generated(&SOURCE.replacen(ARRAY, to, 1)) {
        Ok(_) => panic!("accepted an array that should fail with '{reason}'"),
        Err(e) => assert!(e.contains(reason), "error '{e}' does not say '{reason}'"),
    }
}

/// The `dependencies` attribute of the ModelStructure `<element>` commented `<!-- name -->`.
fn dependencies<'a>(xml: &'a str, element: &str, name: &str) -> &'a str {
    let line = xml
        .lines()
        .find(|l| {
            l.trim_start().starts_with(&format!("<{element} "))
                && l.ends_with(&format!("<!-- {name} -->"))
        })
        .unwrap_or_else(|| panic!("no {element} {name}"));
    let start = line.find("dependencies=\"").expect("dependencies") + "dependencies=\"".len();
    &line[start..start + line[start..].find('"').unwrap()]
}

#[test]
fn the_wall_arrays_are_fixed_size_outputs_with_the_hoop_stress_dependencies() {
    let xml = generated(SOURCE).unwrap();
    for name in [
        "wall_radius",
        "wall_stress_radial",
        "wall_stress_hoop",
        "wall_stress_axial",
    ] {
        let at = xml
            .find(&format!("<Float64 name=\"{name}\" "))
            .unwrap_or_else(|| panic!("no array {name}"));
        let declaration = &xml[at..at + xml[at..].find("</Float64>").unwrap()];
        assert!(declaration.contains(r#"causality="output" variability="continuous""#));
        assert!(
            declaration.contains(r#"<Dimension start="9"/>"#),
            "{declaration}"
        );
        for element in ["Output", "InitialUnknown"] {
            assert_eq!(
                dependencies(&xml, element, name),
                dependencies(&xml, element, "stress_hoop"),
                "{element} {name}"
            );
        }
    }
}

#[test]
fn bad_arrays_are_refused() {
    let array = |attributes: &str| format!(r#"<Array {attributes}"#);
    refused(
        &array(r#"name="wall_radius" size="0" unit="m" dependenciesOf="stress_hoop""#),
        "size must be at least 1",
    );
    refused(
        &array(r#"name="length" size="9" unit="m" dependenciesOf="stress_hoop""#),
        "unique among the variables",
    );
    refused(
        &array(r#"name="wall_stress_hoop" size="9" unit="m" dependenciesOf="stress_hoop""#),
        "unique among the variables",
    );
    // An input has no dependencies to lend.
    refused(
        &array(r#"name="wall_radius" size="9" unit="m" dependenciesOf="pressure""#),
        "dependenciesOf 'pressure' is not an output",
    );
    // A misspelt attribute is an error, not a silently missing one.
    refused(
        &array(r#"name="wall_radius" sise="9" unit="m" dependenciesOf="stress_hoop""#),
        "sise",
    );
}
