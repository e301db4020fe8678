//! The build script's checker refuses model descriptions that importers would reject; the GUID
//! follows every change to the variables.

#[allow(dead_code)]
#[path = "../build/model_description.rs"]
mod model_description;

use model_description::{check, guid_of};

const SOURCE: &str = include_str!("../modelDescription/McKibbenMuscle.xml");

/// The McKibben description with `from` replaced by `to` (which must occur).
fn edited(from: &str, to: &str) -> String {
    assert!(SOURCE.contains(from), "test edit does not apply: {from}");
    SOURCE.replacen(from, to, 1)
}

fn refused(text: &str, reason: &str) {
    match check(text, "McKibbenMuscle") {
        Ok(()) => panic!("accepted a description that should fail with '{reason}'"),
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
    refused(
        &edited(
            r#"causality="parameter" variability="fixed""#,
            r#"causality="parameter" variability="tunable""#,
        ),
        "tunable parameters are not supported",
    );
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

#[test]
fn model_structure_must_match_the_variables() {
    // Drop the last output, then the last initial unknown (target_force_saturated both times).
    refused(
        &edited("<Unknown index=\"48\"/>\n    </Outputs>", "</Outputs>"),
        "ModelStructure/Outputs must list indices [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 33, 47, 48]",
    );
    refused(
        &edited(
            "<Unknown index=\"48\"/>\n    </InitialUnknowns>",
            "</InitialUnknowns>",
        ),
        "InitialUnknowns must list indices [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 30, 31, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 47, 48]",
    );
}

#[test]
fn identity_is_checked() {
    refused(
        &edited(r#"guid="@GUID@""#, r#"guid="{1234}""#),
        "guid must be the placeholder",
    );
    refused(
        &edited(
            r#"modelIdentifier="McKibbenMuscle""#,
            r#"modelIdentifier="Other""#,
        ),
        "must both equal the file name",
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
}
