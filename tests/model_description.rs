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
    // Drop the last output, then the last initial unknown (both input_clamped).
    refused(
        &edited("<Unknown index=\"33\"/>\n    </Outputs>", "</Outputs>"),
        "ModelStructure/Outputs must list indices [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 33]",
    );
    refused(
        &edited(
            "<Unknown index=\"33\"/>\n    </InitialUnknowns>",
            "</InitialUnknowns>",
        ),
        "InitialUnknowns must list indices [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 30, 31, 33]",
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

/// The rules of `build/rules.rs` (FMI 2.0 chapter 2, after the INTO-CPS VDMCheck inventory):
/// each one refuses a description that breaks it.
mod rules {
    use super::{edited, refused};

    #[test]
    fn duplicate_unit_type_and_category_names_are_refused() {
        refused(
            &edited(
                r#"<Unit name="m"><BaseUnit m="1"/></Unit>"#,
                r#"<Unit name="m"><BaseUnit m="1"/></Unit><Unit name="m"><BaseUnit m="1"/></Unit>"#,
            ),
            "unit 'm' is defined twice",
        );
        refused(
            &edited(
                "  <LogCategories>",
                "  <TypeDefinitions><SimpleType name=\"T\"><Real/></SimpleType>\
                 <SimpleType name=\"T\"><Real/></SimpleType></TypeDefinitions>\n  <LogCategories>",
            ),
            "type 'T' is defined twice",
        );
        refused(
            &edited(
                r#"<Category name="logStatusFatal""#,
                r#"<Category name="logCalls"/><Category name="logStatusFatal""#,
            ),
            "log category 'logCalls' is declared twice",
        );
    }

    #[test]
    fn base_units_need_integer_exponents_and_a_factor() {
        refused(
            &edited(
                r#"<BaseUnit m="1"/></Unit>"#,
                r#"<BaseUnit m="1.5"/></Unit>"#,
            ),
            "must be an integer",
        );
        refused(
            &edited(
                r#"<BaseUnit m="1"/></Unit>"#,
                r#"<BaseUnit m="1" factor="0"/></Unit>"#,
            ),
            "factor must not be zero",
        );
    }

    #[test]
    fn default_experiment_must_be_runnable() {
        let experiment = r#"<DefaultExperiment startTime="0" stopTime="1" stepSize="0.001"/>"#;
        refused(
            &edited(
                experiment,
                r#"<DefaultExperiment startTime="2" stopTime="1" stepSize="0.001"/>"#,
            ),
            "must be after startTime",
        );
        refused(
            &edited(
                experiment,
                r#"<DefaultExperiment startTime="0" stopTime="1" stepSize="0"/>"#,
            ),
            "stepSize 0 must be positive",
        );
        refused(
            &edited(
                experiment,
                r#"<DefaultExperiment startTime="0" stopTime="1" tolerance="-1"/>"#,
            ),
            "tolerance -1 must be positive",
        );
    }

    #[test]
    fn start_must_lie_within_min_and_max() {
        refused(
            &edited(
                r#"min="1e-3" max="1e4" start="3.74""#,
                r#"min="1e-3" max="1" start="3.74""#,
            ),
            "start 3.74 is outside",
        );
        refused(
            &edited(
                r#"min="1e-3" max="1e4" start="3.74""#,
                r#"min="10" max="1" start="3.74""#,
            ),
            "min 10 is above max 1",
        );
        refused(
            &edited(
                r#"<Integer min="0" max="2" start="0"/>"#,
                r#"<Integer min="1" max="2" start="0"/>"#,
            ),
            "start 0 is outside",
        );
        refused(
            &edited(
                r#"min="1e-3" max="1e4" start="3.74""#,
                r#"min="1e-3" max="1e4" nominal="0" start="3.74""#,
            ),
            "nominal 0 must be positive",
        );
    }

    #[test]
    fn booleans_carry_no_numeric_attributes() {
        refused(
            &edited(
                r#"<Boolean start="false"/>"#,
                r#"<Boolean min="0" start="false"/>"#,
            ),
            "a Boolean has no attribute min",
        );
    }

    #[test]
    fn boolean_attributes_are_true_or_false() {
        refused(
            &edited(
                r#"canHandleVariableCommunicationStepSize="true""#,
                r#"canHandleVariableCommunicationStepSize="yes""#,
            ),
            "must be 'true' or 'false'",
        );
    }

    #[test]
    fn structured_names_follow_the_grammar() {
        refused(
            &edited(r#"name="force""#, r#"name="force (N)""#),
            "structured naming convention",
        );
        refused(
            &edited(r#"name="force""#, r#"name="1force""#),
            "structured naming convention",
        );
        // Legal structured names pass this rule (and fail nothing else).
        crate::model_description::check(
            &edited(r#"name="force""#, r#"name="muscle.force[1]""#),
            "McKibbenMuscle",
        )
        .unwrap();
    }

    #[test]
    fn unknowns_refer_to_variables_once() {
        refused(
            &edited(r#"<Unknown index="3"/>"#, r#"<Unknown index="99"/>"#),
            "Unknown index 99 is not a variable",
        );
        refused(
            &edited(r#"<Unknown index="4"/>"#, r#"<Unknown index="3"/>"#),
            "Unknown index 3 is listed twice",
        );
    }

    #[test]
    fn dependencies_are_sorted_inputs_with_one_kind_each() {
        let force = r#"<Unknown index="3"/>"#;
        refused(
            &edited(force, r#"<Unknown index="3" dependencies="2 1"/>"#),
            "must be ascending and unique",
        );
        refused(
            &edited(force, r#"<Unknown index="3" dependencies="1 4"/>"#),
            "may not depend on 'volume'",
        );
        refused(
            &edited(
                force,
                r#"<Unknown index="3" dependencies="1 2" dependenciesKind="dependent"/>"#,
            ),
            "1 dependenciesKind for 2 dependencies",
        );
        refused(
            &edited(
                force,
                r#"<Unknown index="3" dependencies="1" dependenciesKind="linear"/>"#,
            ),
            "dependenciesKind 'linear' is not one of",
        );
        refused(
            &edited(
                force,
                r#"<Unknown index="3" dependenciesKind="dependent"/>"#,
            ),
            "dependenciesKind without dependencies",
        );
        refused(
            &edited(force, r#"<Unknown index="3" dependencies="1 x"/>"#),
            "dependencies must be indices",
        );
    }
}
