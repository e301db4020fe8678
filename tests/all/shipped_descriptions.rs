//! The build script's checker refuses model descriptions that importers would reject; the shipped
//! description gets the export layer's part and the ModelStructure indices; the GUID follows every
//! change to the variables.

use crate::build_script::{codegen, model_description};

use model_description::{check, guid_of, ResolvedUnknown};

const SOURCE: &str = include_str!("../../modelDescription/McKibbenMuscle.xml");

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

/// Every `modelDescription/<Model>.xml`: the model's name and source.
fn sources() -> Vec<(String, String)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription");
    let mut sources: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .map(|p| {
            let name = p.file_stem().unwrap().to_str().unwrap().to_string();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    sources.sort();
    assert!(
        sources.len() > 1,
        "no model descriptions in {}",
        dir.display()
    );
    sources
}

/// The source with `force`'s Outputs entry given `attributes` instead of its own.
fn with_dependencies(attributes: &str) -> String {
    edited(FORCE, &format!("<Unknown name=\"force\" {attributes}/>"))
}

/// The source's declaration of `force` among the Outputs (its first Unknown).
const FORCE: &str = r#"<Unknown name="force" dependencies="pressure length" dependenciesKind="dependent dependent"/>"#;

#[test]
fn model_structure_indices_are_generated() {
    let m = check(SOURCE, "McKibbenMuscle").unwrap();
    let indices = |u: &[ResolvedUnknown]| u.iter().map(|u| u.index).collect::<Vec<_>>();
    // Every output in order (FMI 2.0 section 2.2.8)...
    assert_eq!(
        indices(&m.outputs),
        [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 33, 47, 48, 50, 53]
    );
    // ...and the outputs with initial calculated plus the calculated parameters, ascending.
    assert_eq!(
        indices(&m.initial_unknowns),
        [
            3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 30, 31, 33, 34, 35, 36, 37, 38, 39, 40,
            41, 42, 43, 47, 48, 50, 53
        ]
    );
    assert!(m.outputs.iter().all(|u| u.dependencies.is_some()));
    let xml = &m.shipped_xml;
    assert!(xml.contains(
        r#"<CoSimulation
    modelIdentifier="McKibbenMuscle""#
    ));
    assert!(xml.contains(r#"<Category name="logCalls""#));
    assert!(xml.contains(r#"<Unknown index="31" dependencies=""#));
    assert!(xml.contains(r#"<!-- min_length -->"#));
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
        &edited("<Outputs>", r#"<Outputs><Unknown index="3"/>"#),
        "give the unknown by name",
    );
    refused(
        &edited(
            "<Outputs>",
            r#"<Outputs><Unknown name="turns" dependencies=""/>"#,
        ),
        "'turns' does not belong in this list",
    );
    refused(
        &edited(
            "<Outputs>",
            r#"<Outputs><Unknown name="force" dependencies=""/>"#,
        ),
        "'force' is listed twice",
    );
}

#[test]
fn every_output_and_initial_unknown_declares_its_dependencies() {
    // An output left out, or listed without a dependency list, is refused...
    refused(&edited(FORCE, ""), "'force' declares no dependencies");
    refused(&with_dependencies(""), "'force' declares no dependencies");
    // ...and so is an initial unknown (a calculated parameter here).
    let min_length = SOURCE
        .lines()
        .find(|l| l.contains(r#"<Unknown name="min_length""#))
        .expect("min_length is declared among the InitialUnknowns")
        .trim();
    refused(
        &edited(min_length, ""),
        "'min_length' declares no dependencies",
    );
    // Every shipped description declares them all.
    for (name, text) in sources() {
        let m = check(&text, &name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(m
            .outputs
            .iter()
            .chain(&m.initial_unknowns)
            .all(|u| u.dependencies.is_some() && u.kinds.is_some()));
    }
}

/// Enumerations: named items with consecutive values, a variable names its type, and its start,
/// min and max are item values; the generator sees an Integer with the items' range.
#[test]
fn enumerations_are_checked_and_travel_as_integers() {
    let m = check(SOURCE, "McKibbenMuscle").unwrap();
    let preset = m.variables.iter().find(|v| v.name == "preset").unwrap();
    assert_eq!(model_description::TYPES[preset.type_index], "Integer");
    assert_eq!(
        (preset.min.as_deref(), preset.max.as_deref()),
        (Some("0"), Some("8"))
    );
    // Without min and max the items give them.
    let effective = m
        .variables
        .iter()
        .find(|v| v.name == "effective_bladder_model")
        .unwrap();
    assert_eq!(
        (effective.min.as_deref(), effective.max.as_deref()),
        (Some("0"), Some("6"))
    );
    let policy = r#"<Enumeration declaredType="OutOfRangePolicy" min="0" max="2" start="0"/>"#;
    refused(
        &edited(policy, r#"<Enumeration min="0" max="2" start="0"/>"#),
        "an Enumeration needs a declaredType",
    );
    refused(
        &edited(policy, r#"<Enumeration declaredType="Policy" start="0"/>"#),
        "declaredType 'Policy' is not an Enumeration in TypeDefinitions",
    );
    refused(
        &edited(
            policy,
            r#"<Enumeration declaredType="OutOfRangePolicy" start="3"/>"#,
        ),
        "start '3' is not an item value (0 .. 2)",
    );
    refused(
        &edited(
            r#"<Item name="warning" value="1""#,
            r#"<Item name="warning" value="5""#,
        ),
        "item 'warning' has value 5, expected 1",
    );
    refused(
        &edited(
            r#"<Item name="warning" value="1""#,
            r#"<Item name="ok" value="1""#,
        ),
        "item 'ok' appears twice",
    );
    refused(
        &edited(
            r#"<Integer min="1" max="64" start="16"/>"#,
            r#"<Integer declaredType="OutOfRangePolicy" min="1" max="64" start="16"/>"#,
        ),
        "declaredType is supported for Enumerations only",
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
        &SOURCE.replace(r#"name="volume""#, r#"name="volume_m3""#),
        "McKibbenMuscle",
    )
    .unwrap();
    assert_ne!(shipped.guid, renamed.guid);
}

/// The rules of `build/rules.rs` (FMI 2.0 chapter 2, after the INTO-CPS VDMCheck inventory),
/// which build.rs runs on the source and again on the shipped description: each one refuses a
/// shipped description that breaks it.
mod rules {
    use super::model_description::rules;
    use super::{check, SOURCE};

    fn shipped() -> String {
        check(SOURCE, "McKibbenMuscle").unwrap().shipped_xml
    }

    /// The shipped McKibbenMuscle description with `from` replaced by `to` must fail with `reason`.
    fn broken(from: &str, to: &str, reason: &str) {
        let xml = shipped();
        assert!(xml.contains(from), "test edit does not apply: {from}");
        match rules::check(&xml.replacen(from, to, 1)) {
            Ok(()) => panic!("accepted a description that should fail with '{reason}'"),
            Err(e) => assert!(e.contains(reason), "error '{e}' does not say '{reason}'"),
        }
    }

    #[test]
    fn the_shipped_descriptions_pass_every_rule() {
        rules::check(&shipped()).unwrap();
        assert_eq!(rules::RULES.len(), 15);
    }

    #[test]
    fn duplicate_unit_type_and_category_names_are_refused() {
        let unit = r#"<Unit name="m"><BaseUnit m="1"/></Unit>"#;
        broken(unit, &format!("{unit}{unit}"), "unit 'm' is defined twice");
        broken(
            "<TypeDefinitions>",
            "<TypeDefinitions><SimpleType name=\"T\"><Real/></SimpleType>\
             <SimpleType name=\"T\"><Real/></SimpleType>",
            "type 'T' is defined twice",
        );
        broken(
            "<LogCategories>",
            "<LogCategories><Category name=\"logCalls\"/>",
            "log category 'logCalls' is declared twice",
        );
    }

    #[test]
    fn base_units_need_integer_exponents_and_a_factor() {
        broken(
            r#"<BaseUnit m="1"/></Unit>"#,
            r#"<BaseUnit m="1.5"/></Unit>"#,
            "must be an integer",
        );
        broken(
            r#"<BaseUnit m="1"/></Unit>"#,
            r#"<BaseUnit m="1" factor="0"/></Unit>"#,
            "factor must not be zero",
        );
    }

    #[test]
    fn default_experiment_must_be_runnable() {
        let experiment = r#"<DefaultExperiment startTime="0" stopTime="1" stepSize="0.001"/>"#;
        broken(
            experiment,
            r#"<DefaultExperiment startTime="2" stopTime="1" stepSize="0.001"/>"#,
            "must be after startTime",
        );
        broken(
            experiment,
            r#"<DefaultExperiment startTime="0" stopTime="1" stepSize="0"/>"#,
            "stepSize 0 must be positive",
        );
        broken(
            experiment,
            r#"<DefaultExperiment startTime="0" stopTime="1" tolerance="-1"/>"#,
            "tolerance -1 must be positive",
        );
    }

    #[test]
    fn start_must_lie_within_min_and_max() {
        let turns = r#"min="1e-3" max="1e4" start="3.74""#;
        broken(
            turns,
            r#"min="1e-3" max="1" start="3.74""#,
            "start 3.74 is outside",
        );
        broken(
            turns,
            r#"min="10" max="1" start="3.74""#,
            "min 10 is above max 1",
        );
        broken(
            r#"<Integer min="1" max="64" start="16"/>"#,
            r#"<Integer min="20" max="64" start="16"/>"#,
            "start 16 is outside",
        );
        broken(
            r#"<Enumeration declaredType="BladderModel" min="0" max="6" start="0"/>"#,
            r#"<Enumeration declaredType="BladderModel" min="1" max="6" start="0"/>"#,
            "start 0 is outside",
        );
        broken(
            turns,
            r#"min="1e-3" max="1e4" nominal="0" start="3.74""#,
            "nominal 0 must be positive",
        );
    }

    /// FMI 2.0's schema gives a `<Tool>` one child element at most; the source's `<Terminals>`
    /// (the FMI 3.0 flanges) and `<Arrays>` (the FMI 3.0 array outputs) beside its `<Tests>` do
    /// not ship.
    #[test]
    fn a_tool_holds_one_element() {
        let tests = "<Tests>";
        broken(
            tests,
            "<Extra/><Tests>",
            "Tool 'actuator-fmus' holds 2 elements; FMI 2.0 allows at most one",
        );
        broken(
            tests,
            "<Terminals/><Tests>",
            "Tool 'actuator-fmus' holds 2 elements",
        );
        assert!(SOURCE.contains("<Terminals>") && !shipped().contains("<Terminals>"));
        assert!(SOURCE.contains("<Arrays>") && !shipped().contains("<Arrays>"));
        super::refused(
            &SOURCE.replacen(tests, "<Extra/><Tests>", 1),
            "holds 2 elements",
        );
        let source = super::model_description::description::parse(SOURCE).unwrap();
        rules::check_description(&source, rules::Form::Source).unwrap();
        // Terminals, Arrays and Tests.
        assert!(rules::check_description(&source, rules::Form::Shipped)
            .unwrap_err()
            .contains("holds 3 elements"));
    }

    #[test]
    fn booleans_carry_no_numeric_attributes() {
        broken(
            r#"<Boolean start="false"/>"#,
            r#"<Boolean min="0" start="false"/>"#,
            "a Boolean has no attribute min",
        );
    }

    #[test]
    fn boolean_attributes_are_true_or_false() {
        broken(
            r#"canHandleVariableCommunicationStepSize="true""#,
            r#"canHandleVariableCommunicationStepSize="yes""#,
            "must be 'true' or 'false'",
        );
    }

    #[test]
    fn structured_names_follow_the_grammar() {
        broken(
            r#"name="force""#,
            r#"name="force (N)""#,
            "structured naming convention",
        );
        broken(
            r#"name="force""#,
            r#"name="1force""#,
            "structured naming convention",
        );
        // Legal structured names pass.
        rules::check(&shipped().replacen(r#"name="force""#, r#"name="muscle.force[1]""#, 1))
            .unwrap();
        rules::check(&shipped().replacen(r#"name="force""#, r#"name="der(muscle.'x y', 2)""#, 1))
            .unwrap();
    }

    #[test]
    fn unknowns_refer_to_variables_once() {
        broken(
            r#"<Unknown index="3" dependencies="1 2""#,
            r#"<Unknown index="99" dependencies="1 2""#,
            "Unknown index 99 is not a variable",
        );
        broken(
            r#"<Unknown index="4" dependencies="1 2""#,
            r#"<Unknown index="3" dependencies="1 2""#,
            "Unknown index 3 is listed twice",
        );
    }

    #[test]
    fn every_unknown_declares_its_dependencies() {
        broken(
            r#"<Unknown index="3" dependencies="1 2" dependenciesKind="dependent dependent"/>"#,
            r#"<Unknown index="3"/>"#,
            "Unknown 3 declares no dependencies",
        );
    }

    #[test]
    fn dependencies_are_sorted_inputs_with_one_kind_each() {
        let force =
            r#"<Unknown index="3" dependencies="1 2" dependenciesKind="dependent dependent"/>"#;
        broken(
            force,
            r#"<Unknown index="3" dependencies="2 1"/>"#,
            "must be ascending and unique",
        );
        broken(
            force,
            r#"<Unknown index="3" dependencies="1 4"/>"#,
            "may not depend on 'volume'",
        );
        broken(
            force,
            r#"<Unknown index="3" dependencies="1 2" dependenciesKind="dependent"/>"#,
            "1 dependenciesKind for 2 dependencies",
        );
        broken(
            force,
            r#"<Unknown index="3" dependencies="1" dependenciesKind="linear"/>"#,
            "dependenciesKind 'linear' is not one of",
        );
        broken(
            force,
            r#"<Unknown index="3" dependenciesKind="dependent"/>"#,
            "dependenciesKind without dependencies",
        );
        broken(
            force,
            r#"<Unknown index="3" dependencies="1 x"/>"#,
            "dependencies must be indices",
        );
    }
}

/// Continuous states for Model Exchange: a source declares each by a derivative variable that
/// names it (`derivative="joint_angle"`); build.rs numbers the states, writes the index and the
/// `<Derivatives>` list, and refuses every inconsistent declaration.
mod continuous_states {
    use super::check;
    use super::model_description::rules;

    const PULLEY: &str = include_str!("../../modelDescription/PulleyJoint.xml");

    fn edited(from: &str, to: &str) -> String {
        assert!(PULLEY.contains(from), "test edit does not apply: {from}");
        PULLEY.replacen(from, to, 1)
    }

    fn refused(text: &str, reason: &str) {
        match check(text, "PulleyJoint") {
            Ok(_) => panic!("accepted a description that should fail with '{reason}'"),
            Err(e) => assert!(e.contains(reason), "error '{e}' does not say '{reason}'"),
        }
    }

    #[test]
    fn states_are_numbered_in_derivative_order_and_indexed_in_the_shipped_description() {
        let m = check(PULLEY, "PulleyJoint").unwrap();
        let names: Vec<(&str, &str)> = m
            .states
            .iter()
            .map(|&(s, d)| (m.variables[s].name.as_str(), m.variables[d].name.as_str()))
            .collect();
        assert_eq!(
            names,
            [
                ("joint_angle", "der(joint_angle)"),
                ("joint_velocity", "der(joint_velocity)")
            ]
        );
        // joint_angle is variable 7, joint_velocity 8 (1-based).
        assert!(m.shipped_xml.contains(r#"unit="rad/s" derivative="7"/>"#));
        assert!(m.shipped_xml.contains(r#"derivative="8"/>"#));
        assert_eq!(m.derivatives.len(), 2);
        assert_eq!(m.derivatives[1].dependencies, Some(vec![1, 2, 7, 8]));
        assert_eq!(m.event_indicators, 0);
        rules::check(&m.shipped_xml).unwrap();
    }

    #[test]
    fn inconsistent_state_declarations_are_refused() {
        refused(
            &edited(r#"derivative="joint_angle""#, r#"derivative="nothing""#),
            "derivative=\"nothing\" is not a variable",
        );
        refused(
            &edited(r#"derivative="joint_angle""#, r#"derivative="7""#),
            "name the state",
        );
        // A parameter cannot be a state.
        refused(
            &edited(r#"derivative="joint_angle""#, r#"derivative="inertia""#),
            "must be a continuous Real output or local",
        );
        // A state's start comes from the model (initial calculated), not from a start value.
        refused(
            &edited(
                r#"name="joint_angle" valueReference="6" causality="output" variability="continuous" initial="calculated""#,
                r#"name="joint_angle" valueReference="6" causality="output" variability="continuous" initial="exact""#,
            )
            .replacen(r#"<Real quantity="Angle" unit="rad"/>"#, r#"<Real quantity="Angle" unit="rad" start="0"/>"#, 1),
            "must have initial 'calculated'",
        );
        // Two derivatives of one state.
        refused(
            &edited(
                r#"derivative="joint_velocity""#,
                r#"derivative="joint_angle""#,
            ),
            "already has the derivative",
        );
        // A derivative must be a calculated local.
        refused(
            &edited(
                r#"name="der(joint_angle)" valueReference="29" causality="local""#,
                r#"name="der(joint_angle)" valueReference="29" causality="output""#,
            ),
            "a derivative must be a local",
        );
        // A local that is neither a state nor a derivative has no typed group.
        refused(
            &edited(r#" derivative="joint_angle""#, ""),
            "a local must be a continuous state or a state derivative",
        );
        // Every derivative declares its dependencies, on knowns only.
        refused(
            &edited(
                r#"<Unknown name="der(joint_angle)" dependencies="joint_velocity" dependenciesKind="dependent"/>"#,
                "",
            ),
            "'der(joint_angle)' declares no dependencies",
        );
        refused(
            &edited(
                r#"<Unknown name="der(joint_angle)" dependencies="joint_velocity""#,
                r#"<Unknown name="der(joint_angle)" dependencies="inertia""#,
            ),
            "may depend only on an input or a continuous state",
        );
        // An output may depend on a state, not on another output.
        refused(
            &edited(
                r#"<Unknown name="flexor_length" dependencies="joint_angle""#,
                r#"<Unknown name="flexor_length" dependencies="reference_angle""#,
            ),
            "may depend only on an input or a continuous state",
        );
        refused(
            &PULLEY.replace(
                r#"numberOfEventIndicators="0""#,
                r#"numberOfEventIndicators="-1""#,
            ),
            "numberOfEventIndicators must be a non-negative integer",
        );
    }

    #[test]
    fn a_local_state_is_generated_into_the_state_mirror_and_its_derivative_into_the_derivatives() {
        // joint_velocity made a local (not an output): the export layer reads it from the
        // model's states, copied into `values.states`.
        let text = edited(
            r#"name="joint_velocity" valueReference="7" causality="output""#,
            r#"name="joint_velocity" valueReference="7" causality="local""#,
        )
        .replacen(
            r#"      <Unknown name="joint_velocity" dependencies="joint_velocity" dependenciesKind="dependent"/>
"#,
            "",
            1,
        );
        let m = check(&text, "PulleyJoint").unwrap_or_else(|e| panic!("{e}"));
        let (mut tables, mut bindings) = (String::new(), String::new());
        super::codegen::tables(&m, "PulleyJoint.xml", &mut tables).unwrap();
        super::codegen::bindings(&m, &mut bindings).unwrap();
        assert!(tables.contains("pub struct States {"));
        assert!(tables.contains("const COUNT: usize = 2;"));
        assert!(tables.contains(r#"const DERIVATIVE_NAMES: &'static [&'static str] = &["der(joint_angle)", "der(joint_velocity)"];"#));
        assert!(tables.contains("pub const DER_JOINT_VELOCITY: usize = 30;"));
        // Reals by value reference: the rows of the table of field offsets.
        let offsets: Vec<&str> = bindings
            .lines()
            .skip_while(|l| !l.starts_with("const REAL_OFFSETS_PULLEY_JOINT"))
            .skip(1)
            .take_while(|l| !l.starts_with("];"))
            .collect();
        let field = |vr: usize| {
            offsets[vr]
                .trim()
                .trim_end_matches("),")
                .rsplit(", ")
                .next()
        };
        assert_eq!(field(7), Some("states.joint_velocity"));
        assert_eq!(field(6), Some("outputs.joint_angle"));
        assert_eq!(field(29), Some("derivatives.joint_angle"));
        assert_eq!(field(30), Some("derivatives.joint_velocity"));
    }

    #[test]
    fn the_rules_check_the_shipped_derivative_indices() {
        let shipped = check(PULLEY, "PulleyJoint").unwrap().shipped_xml;
        let broken = |from: &str, to: &str, reason: &str| {
            assert!(shipped.contains(from), "test edit does not apply: {from}");
            match rules::check(&shipped.replacen(from, to, 1)) {
                Ok(()) => panic!("accepted a description that should fail with '{reason}'"),
                Err(e) => assert!(e.contains(reason), "error '{e}' does not say '{reason}'"),
            }
        };
        // external_pressures (variable 28) is a Boolean; flexor_pressure_command (29) an input.
        for not_a_state in ["28", "29"] {
            broken(
                r#"derivative="7""#,
                &format!(r#"derivative="{not_a_state}""#),
                "is not the index of a continuous Real output or local",
            );
        }
        broken(
            r#"derivative="8""#,
            r#"derivative="7""#,
            "is the state of two derivatives",
        );
        broken(
            r#"<Unknown index="31" dependencies="8""#,
            r#"<Unknown index="30" dependencies="8""#,
            "is not a variable with a derivative attribute",
        );
        // An output may depend on a state (7), not on a parameter (11).
        broken(
            r#"<Unknown index="3" dependencies="7""#,
            r#"<Unknown index="3" dependencies="11""#,
            "may not depend on 'moment_arm'",
        );
    }
}

/// The shipped description numbers each variable once, with its index: a number written into the
/// source would be doubled, and go stale when a variable is added above it.
#[test]
fn each_shipped_variable_carries_its_own_index_once() {
    for (name, source) in sources() {
        let xml = check(&source, &name).unwrap().shipped_xml;
        let parts: Vec<&str> = xml.split("<ScalarVariable").collect();
        for (i, before) in parts[..parts.len() - 1].iter().enumerate() {
            let line = before.rsplit('\n').next().unwrap_or_default().trim();
            assert_eq!(
                line,
                format!("<!-- {} -->", i + 1),
                "{name}: variable {} must be preceded on its line by its index alone",
                i + 1
            );
        }
    }
}
