//! The FMI 3.0 `terminalsAndIcons/terminalsAndIcons.xml` of a model (FMI 3.0 section 2.4.9,
//! "Terminals and Icons"), from the mechanical flanges its source declares in
//! `<VendorAnnotations><Tool name="actuator-fmus"><Terminals>`:
//!
//! ```xml
//! <Flange name="flange" kind="translational" position="length" force="force" flow="inflow"/>
//! <Flange name="rotor" kind="rotational" angle="rotor_angle" torque="load_torque" flow="inflow"/>
//! ```
//!
//! Each flange becomes a `plug` terminal whose members carry the names of the Modelica Standard
//! Library connector's variables (`s`, `f` translational; `phi`, `tau` rotational), so that a
//! Modelica tool matches them by name. The position (angle) is a `signal`; the force (torque) is
//! `inflow` when the variable is the force that the outside applies to the model at the flange,
//! positive along the flange axis (Modelica's flow convention), and `outflow` when it is the force
//! the model applies to the outside. The check refuses a member that does not exist, is not a
//! continuous Float64 in the connector's SI unit, or a flange that is not one input and one
//! output (a causal FMU's flange imposes one of the pair and answers with the other).
//!
//! Every model's file also carries its `<GraphicalRepresentation>`: FMI 3.0's default coordinate
//! system and the FMU icon over all of it (`icon.png`, `icon.svg`, which the packager draws,
//! `tools/src/icons.rs`), and each flange's icon (`translational_flange` or `rotational_flange`)
//! on the icon's border: the first flange right, then left, bottom, top.

use super::model_description::description::Flange;
use super::model_description::Model;
use std::fmt::Write as _;

/// What a flange kind is made of: the connector, and per member (source attribute, Modelica
/// member name, SI unit).
struct Kind {
    terminal_kind: &'static str,
    /// The flange icon's `iconBaseName`.
    icon: &'static str,
    across: (&'static str, &'static str, &'static str),
    through: (&'static str, &'static str, &'static str),
}

const TRANSLATIONAL: Kind = Kind {
    terminal_kind: "org.modelica.Mechanics.Translational.Interfaces.Flange",
    icon: "translational_flange",
    across: ("position", "s", "m"),
    through: ("force", "f", "N"),
};

const ROTATIONAL: Kind = Kind {
    terminal_kind: "org.modelica.Mechanics.Rotational.Interfaces.Flange",
    icon: "rotational_flange",
    across: ("angle", "phi", "rad"),
    through: ("torque", "tau", "N.m"),
};

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The checked flange members: (variable, member name, variableKind) for the across and the
/// through variable.
fn members<'a>(
    flange: &'a Flange,
    model: &Model,
) -> Result<[(&'a str, &'static str, &'a str); 2], String> {
    let (kind, across, through, unused) = match flange.kind.as_str() {
        "translational" => (
            &TRANSLATIONAL,
            &flange.position,
            &flange.force,
            [("angle", &flange.angle), ("torque", &flange.torque)],
        ),
        "rotational" => (
            &ROTATIONAL,
            &flange.angle,
            &flange.torque,
            [("position", &flange.position), ("force", &flange.force)],
        ),
        other => {
            return Err(format!(
                "kind must be translational or rotational, found '{other}'"
            ))
        }
    };
    if let Some((attribute, _)) = unused.iter().find(|(_, v)| v.is_some()) {
        return Err(format!("a {} flange has no '{attribute}'", flange.kind));
    }
    if flange.flow != "inflow" && flange.flow != "outflow" {
        return Err(format!(
            "flow must be inflow or outflow, found '{}'",
            flange.flow
        ));
    }
    let mut causalities = Vec::new();
    let mut checked = Vec::new();
    for ((attribute, member, unit), name, variable_kind) in [
        (kind.across, across, "signal"),
        (kind.through, through, flange.flow.as_str()),
    ] {
        let name = name
            .as_deref()
            .ok_or_else(|| format!("a {} flange needs '{attribute}'", flange.kind))?;
        let v = model
            .variables
            .iter()
            .find(|v| v.name == name)
            .ok_or_else(|| format!("{attribute} '{name}' is not a variable"))?;
        if v.type_index != 0 || v.variability != "continuous" {
            return Err(format!("{attribute} '{name}' must be a continuous Real"));
        }
        if v.unit.as_deref() != Some(unit) {
            return Err(format!(
                "{attribute} '{name}' must have unit=\"{unit}\", found {:?}",
                v.unit
            ));
        }
        causalities.push(v.causality.as_str());
        checked.push((name, member, variable_kind));
    }
    causalities.sort_unstable();
    if causalities != ["input", "output"] {
        return Err(format!(
            "one of the {} and the {} must be an input and the other an output",
            kind.across.0, kind.through.0
        ));
    }
    Ok([checked[0], checked[1]])
}

/// Centres of the flange icons on the FMU icon's border, in declaration order, and their half
/// side (FMI 3.0's default coordinate system, -100..100).
const FLANGE_PLACES: [(i32, i32); 4] = [(100, 0), (-100, 0), (0, -100), (0, 100)];
const FLANGE_HALF_SIDE: i32 = 10;

/// The terminalsAndIcons.xml of `model` (checked): the graphical representation, and the
/// terminals of the flanges its source declares (none: no `<Terminals>`).
pub fn xml(model: &Model) -> Result<String, String> {
    let flanges: Vec<&Flange> = model.source.flanges().collect();
    let mut x = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Generated by build.rs from modelDescription/{}.xml. -->\n<fmiTerminalsAndIcons fmiVersion=\"3.0\">\n  <GraphicalRepresentation>\n    <CoordinateSystem x1=\"-100\" y1=\"-100\" x2=\"100\" y2=\"100\" suggestedScalingFactorTo_mm=\"0.1\"/>\n    <Icon x1=\"-100\" y1=\"-100\" x2=\"100\" y2=\"100\"/>\n  </GraphicalRepresentation>\n",
        model.name
    );
    if flanges.is_empty() {
        x.push_str("</fmiTerminalsAndIcons>\n");
        return Ok(x);
    }
    if flanges.len() > FLANGE_PLACES.len() {
        return Err(format!(
            "Terminals: at most {} flanges have a place on the icon",
            FLANGE_PLACES.len()
        ));
    }
    x.push_str("  <Terminals>\n");
    let mut names = std::collections::BTreeSet::new();
    for (flange, (cx, cy)) in flanges.into_iter().zip(FLANGE_PLACES) {
        let context = |e: String| format!("Terminals: flange '{}': {e}", flange.name);
        if flange.name.trim().is_empty() || !names.insert(flange.name.as_str()) {
            return Err(context("the name must be non-empty and unique".into()));
        }
        let members = members(flange, model).map_err(context)?;
        let kind = if flange.kind == "translational" {
            &TRANSLATIONAL
        } else {
            &ROTATIONAL
        };
        let description = flange
            .description
            .as_deref()
            .map(|d| format!(" description=\"{}\"", escape(d)))
            .unwrap_or_default();
        let _ = writeln!(
            x,
            "    <Terminal name=\"{}\" matchingRule=\"plug\" terminalKind=\"{}\"{description}>",
            escape(&flange.name),
            kind.terminal_kind
        );
        for (variable, member, variable_kind) in members {
            let _ = writeln!(
                x,
                "      <TerminalMemberVariable variableName=\"{}\" memberName=\"{member}\" variableKind=\"{variable_kind}\"/>",
                escape(variable)
            );
        }
        let h = FLANGE_HALF_SIDE;
        let _ = writeln!(
            x,
            "      <TerminalGraphicalRepresentation iconBaseName=\"{}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>",
            kind.icon,
            cx - h,
            cy - h,
            cx + h,
            cy + h
        );
        x.push_str("    </Terminal>\n");
    }
    x.push_str("  </Terminals>\n</fmiTerminalsAndIcons>\n");
    Ok(x)
}
