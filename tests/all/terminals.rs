//! The build script's check of the mechanical flanges a model declares (`build/terminals.rs`):
//! every model's source passes, and a flange naming a missing variable, the wrong unit or
//! causality, or an unknown attribute is refused with the reason.

use crate::build_script::model_description;
use crate::build_script::terminals as flanges;

const SOURCE: &str = include_str!("../../modelDescription/McKibbenMuscle.xml");
const FLANGE: &str =
    r#"<Flange name="flange" kind="translational" position="length" force="force" flow="inflow""#;

fn generated(text: &str) -> Result<String, String> {
    let model = model_description::check(text, "McKibbenMuscle")?;
    flanges::xml(&model)
}

/// The McKibben description with its flange declaration replaced by `to`.
fn refused(to: &str, reason: &str) {
    assert!(SOURCE.contains(FLANGE));
    match generated(&SOURCE.replacen(FLANGE, to, 1)) {
        Ok(_) => panic!("accepted a flange that should fail with '{reason}'"),
        Err(e) => assert!(e.contains(reason), "error '{e}' does not say '{reason}'"),
    }
}

#[test]
fn every_source_passes_and_only_passthrough_has_no_flange() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription");
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_str().unwrap().to_string();
        let text = std::fs::read_to_string(&path).unwrap();
        let model = model_description::check(&text, &stem).unwrap();
        let xml = flanges::xml(&model).unwrap();
        // Every model has its icon; only PassThrough has no terminal.
        assert!(xml.contains(r#"<Icon x1="-100" y1="-100" x2="100" y2="100"/>"#));
        assert_eq!(
            !xml.contains("<Terminals>"),
            stem == "PassThrough",
            "{stem}"
        );
    }
}

#[test]
fn the_muscle_flange_is_length_and_tension() {
    let xml = generated(SOURCE).unwrap();
    assert!(xml.contains(r#"<Terminal name="flange" matchingRule="plug" terminalKind="org.modelica.Mechanics.Translational.Interfaces.Flange""#));
    assert!(xml.contains(
        r#"<TerminalMemberVariable variableName="length" memberName="s" variableKind="signal"/>"#
    ));
    assert!(xml.contains(
        r#"<TerminalMemberVariable variableName="force" memberName="f" variableKind="inflow"/>"#
    ));
    // Its icon on the right border of the FMU icon.
    assert!(xml.contains(
        r#"<TerminalGraphicalRepresentation iconBaseName="translational_flange" x1="90" y1="-10" x2="110" y2="10"/>"#
    ));
}

#[test]
fn bad_flanges_are_refused() {
    let flange = |attributes: &str| format!(r#"<Flange name="flange" {attributes}"#);
    refused(
        &flange(r#"kind="translational" position="stroke" force="force" flow="inflow""#),
        "position 'stroke' is not a variable",
    );
    // volume is in m3, not m.
    refused(
        &flange(r#"kind="translational" position="volume" force="force" flow="inflow""#),
        "must have unit=\"m\"",
    );
    // Two inputs: the flange would impose both position and force.
    refused(
        &flange(r#"kind="translational" position="length" force="target_force" flow="inflow""#),
        "must be an input and the other an output",
    );
    // A parameter is no flange position.
    refused(
        &flange(r#"kind="translational" position="nominal_length" force="force" flow="inflow""#),
        "must be a continuous Real",
    );
    refused(
        &flange(r#"kind="translational" position="length" force="force" flow="through""#),
        "flow must be inflow or outflow",
    );
    refused(
        &flange(r#"kind="hydraulic" position="length" force="force" flow="inflow""#),
        "kind must be translational or rotational",
    );
    refused(
        &flange(r#"kind="rotational" position="length" force="force" flow="inflow""#),
        "a rotational flange has no 'position'",
    );
    refused(
        &flange(r#"kind="translational" force="force" flow="inflow""#),
        "needs 'position'",
    );
    // A misspelt attribute is an error, not a silently missing member.
    refused(
        &flange(r#"kind="translational" postion="length" force="force" flow="inflow""#),
        "postion",
    );
    refused(
        &format!(
            r#"{FLANGE}/><Flange name="flange" kind="translational" position="length" force="force" flow="inflow""#
        ),
        "unique",
    );
}

#[test]
fn the_fmi2_description_ships_without_the_flanges() {
    // FMI 2.0's schema allows a VendorAnnotations Tool one element: the Tests stay, the
    // Terminals (FMI 3.0 only) go, with their comment.
    let shipped = model_description::check(SOURCE, "McKibbenMuscle")
        .unwrap()
        .shipped_xml;
    assert!(!shipped.contains("Terminals") && !shipped.contains("<Flange"));
    assert!(shipped.contains("<Tool name=\"actuator-fmus\">\n      <Tests>"));
}
