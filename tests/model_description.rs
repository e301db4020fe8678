//! The build script's checker refuses model descriptions that importers would reject; the shipped
//! description gets the export layer's part and the ModelStructure indices; the GUID follows every
//! change to the variables.

#[allow(dead_code)]
#[path = "../build/model_description.rs"]
mod model_description;

use model_description::{check, guid_of, ResolvedUnknown};

const SOURCE: &str = include_str!("../modelDescription/McKibbenMuscle.xml");

/// The McKibben description with `from` replaced by `to` (which must occur).
fn edited(from: &str, to: &str) -> String {
    assert!(SOURCE.contains(from), "test edit does not apply: {from}");
    SOURCE.replacen(from, to, 1)
}

fn refused(text: &str, reason: &str) {
    match check(text, "McKibbenMuscle") {
        Ok(_) => panic!("accepted a description that should fail with '{reason}'"),
        Err(e) => assert!(e.contains(reason), "error '{e}' does not say '{reason}'"),
    }
}

#[test]
fn the_shipped_description_passes() {
    check(SOURCE, "McKibbenMuscle").unwrap();
}

#[test]
fn illegal_causality_variability_initial_combinations_fail() {
    refused(
        &edited(
            r#"causality="input" variability="continuous""#,
            r#"causality="input" variability="fixed""#,
        ),
        "is not allowed",
    );
    refused(
        &edited(
            r#"causality="parameter" variability="fixed""#,
            r#"causality="parameter" variability="continuous""#,
        ),
        "is not allowed",
    );
    refused(
        &edited(
            r#"causality="input" variability="continuous""#,
            r#"causality="input" variability="continuous" initial="exact""#,
        ),
        "initial 'exact' is not allowed",
    );
    refused(
        &edited(
            r#"name="force" valueReference="2" causality="output" variability="continuous" initial="calculated""#,
            r#"name="force" valueReference="2" causality="output" variability="continuous" initial="exact""#,
        ),
        "needs a start value",
    );
    refused(
        &edited(
            r#"<Real quantity="Force" unit="N"/>"#,
            r#"<Real quantity="Force" unit="N" start="1"/>"#,
        ),
        "must not have a start value",
    );
    // Tunable parameters are legal: the export layer rebuilds the model when one changes.
    check(
        &edited(
            r#"causality="parameter" variability="fixed""#,
            r#"causality="parameter" variability="tunable""#,
        ),
        "McKibbenMuscle",
    )
    .unwrap();
}

#[test]
fn units_must_be_defined() {
    refused(
        &edited(
            r#"<Real quantity="Force" unit="N"/>"#,
            r#"<Real quantity="Force" unit="kN"/>"#,
        ),
        "unit 'kN' is not defined",
    );
    refused(
        &edited(
            r#"<Real quantity="Force" unit="N"/>"#,
            r#"<Real quantity="Force"/>"#,
        ),
        "every Real needs a unit",
    );
}

#[test]
fn value_references_are_dense_and_names_unique() {
    refused(
        &edited(
            r#"name="max_length" valueReference="6""#,
            r#"name="max_length" valueReference="9""#,
        ),
        "without gaps or repeats",
    );
    refused(
        &edited(
            r#"name="max_length" valueReference="6""#,
            r#"name="max_length" valueReference="5""#,
        ),
        "without gaps or repeats",
    );
    refused(
        &edited(r#"name="max_length""#, r#"name="turns""#),
        "is used twice",
    );
}

/// The ModelStructure source part: dependencies by name, given for `force`.
fn with_dependencies(attributes: &str) -> String {
    edited(
        "<ModelStructure/>",
        &format!("<ModelStructure><Outputs><Unknown name=\"force\" {attributes}/></Outputs></ModelStructure>"),
    )
}

#[test]
fn model_structure_indices_are_generated() {
    let m = check(SOURCE, "McKibbenMuscle").unwrap();
    let indices = |u: &[ResolvedUnknown]| u.iter().map(|u| u.index).collect::<Vec<_>>();
    // Every output in order (FMI 2.0 section 2.2.8)...
    assert_eq!(
        indices(&m.outputs),
        [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]
    );
    // ...and the outputs with initial calculated plus the calculated parameters, ascending.
    assert_eq!(
        indices(&m.initial_unknowns),
        [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 30, 31]
    );
    assert!(m.outputs.iter().all(|u| u.dependencies.is_none()));
    let xml = &m.shipped_xml;
    assert!(xml.contains(
        r#"<CoSimulation
    modelIdentifier="McKibbenMuscle""#
    ));
    assert!(xml.contains(r#"<Category name="logCalls""#));
    assert!(xml.contains(r#"<Unknown index="31"/> <!-- min_length -->"#));
    assert!(xml.contains(&format!(r#"guid="{}""#, m.guid)));
}

#[test]
fn dependencies_by_name_become_sorted_indices() {
    let m = check(
        &with_dependencies(r#"dependencies="length pressure" dependenciesKind="dependent fixed""#),
        "McKibbenMuscle",
    )
    .unwrap();
    assert_eq!(
        m.outputs[0],
        ResolvedUnknown {
            index: 3,
            dependencies: Some(vec![1, 2]),
            kinds: Some(vec!["fixed".into(), "dependent".into()]),
        }
    );
    assert!(m.shipped_xml.contains(
        r#"<Unknown index="3" dependencies="1 2" dependenciesKind="fixed dependent"/> <!-- force -->"#
    ));
    // An empty list says "depends on nothing".
    let m = check(&with_dependencies(r#"dependencies="""#), "McKibbenMuscle").unwrap();
    assert!(m
        .shipped_xml
        .contains(r#"<Unknown index="3" dependencies=""/>"#));
}

#[test]
fn bad_model_structure_entries_fail() {
    refused(
        &with_dependencies(r#"dependencies="lenght""#),
        "'lenght', not a variable",
    );
    refused(
        &with_dependencies(r#"dependencies="turns""#),
        "may depend only on an input",
    );
    refused(
        &with_dependencies(r#"dependencies="length length""#),
        "lists 'length' twice",
    );
    refused(
        &with_dependencies(r#"dependencies="length" dependenciesKind="dependent fixed""#),
        "1 dependencies but 2 dependenciesKind",
    );
    refused(
        &with_dependencies(r#"dependencies="length" dependenciesKind="sometimes""#),
        "dependenciesKind 'sometimes'",
    );
    refused(
        &with_dependencies(r#"dependenciesKind="dependent""#),
        "dependenciesKind without dependencies",
    );
    refused(
        &edited(
            "<ModelStructure/>",
            r#"<ModelStructure><Outputs><Unknown index="3"/></Outputs></ModelStructure>"#,
        ),
        "give the unknown by name",
    );
    refused(
        &edited(
            "<ModelStructure/>",
            r#"<ModelStructure><Outputs><Unknown name="turns"/></Outputs></ModelStructure>"#,
        ),
        "'turns' does not belong in this list",
    );
    refused(
        &edited(
            "<ModelStructure/>",
            r#"<ModelStructure><Outputs><Unknown name="force"/><Unknown name="force"/></Outputs></ModelStructure>"#,
        ),
        "'force' is listed twice",
    );
}

#[test]
fn the_export_layer_part_stays_out_of_the_source() {
    refused(
        &edited(
            "<UnitDefinitions>",
            "<CoSimulation modelIdentifier=\"McKibbenMuscle\"/>\n  <UnitDefinitions>",
        ),
        "<CoSimulation> belongs to the export layer",
    );
    refused(
        &edited(
            "<DefaultExperiment",
            "<LogCategories><Category name=\"logCalls\"/></LogCategories>\n  <DefaultExperiment",
        ),
        "<LogCategories> belongs to the export layer",
    );
    refused(
        &edited(
            r#"<Unit name="m"><BaseUnit m="1"/></Unit>"#,
            r#"<Unit name="m"><BaseUnit m="1"/></Unit><Unit name="m"/>"#,
        ),
        "a unit is defined twice",
    );
}

#[test]
fn identity_is_checked() {
    refused(
        &edited(r#"guid="@GUID@""#, r#"guid="{1234}""#),
        "guid must be the placeholder",
    );
    refused(
        &edited(r#"modelName="McKibbenMuscle""#, r#"modelName="Other""#),
        "modelName must equal the file name",
    );
    refused(
        &edited(r#"fmiVersion="2.0""#, r#"fmiVersion="3.0""#),
        "fmiVersion must be 2.0",
    );
}

#[test]
fn the_guid_changes_with_any_variable() {
    let original = guid_of(SOURCE);
    assert_eq!(original, guid_of(SOURCE), "deterministic");
    assert_eq!(original.len(), 38);
    assert_ne!(
        original,
        guid_of(&edited(r#"start="3.74""#, r#"start="3.75""#))
    );
    assert_ne!(
        original,
        guid_of(&edited(r#"name="volume""#, r#"name="volume_m3""#))
    );
    // The GUID build.rs ships is that of the whole shipped description.
    let shipped = check(SOURCE, "McKibbenMuscle").unwrap();
    let renamed = check(
        &edited(r#"name="volume""#, r#"name="volume_m3""#),
        "McKibbenMuscle",
    )
    .unwrap();
    assert_ne!(shipped.guid, renamed.guid);
}
