"""The mechanical flanges and icons of the FMI 3.0 FMUs (terminalsAndIcons/): valid against the FMI
3.0 schema FMPy ships, every member an existing variable of the FMU with the causality, variability
and SI unit of a Modelica flange, terminals only where the source declares a flange, the muscle and
pulley flanges pairing as the robot-joint system connects them, the force signs the Modelica
convention they claim, and every icon the file names present as PNG (and SVG) of the stated
extent."""

import pathlib
import xml.etree.ElementTree as ET
import zipfile

import fmpy
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu
from lxml import etree

from actuator_fmus.paths import FMI3_DIR, ROOT

TERMINALS = "terminalsAndIcons/terminalsAndIcons.xml"
MODELS = sorted(p.stem for p in FMI3_DIR.glob("*.fmu"))
SCHEMA = etree.XMLSchema(etree.parse(str(
    pathlib.Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3TerminalsAndIcons.xsd")))

# Member names, SI units and variableKinds of the Modelica Standard Library flange connectors
# (Translational: position s, cut force f; Rotational: angle phi, cut torque tau).
FLANGES = {
    "org.modelica.Mechanics.Translational.Interfaces.Flange": {"s": "m", "f": "N"},
    "org.modelica.Mechanics.Rotational.Interfaces.Flange": {"phi": "rad", "tau": "N.m"},
}
FLOW_MEMBERS = {"f", "tau"}


def fmu(model):
    return str(FMI3_DIR / f"{model}.fmu")


def terminals_xml(model):
    with zipfile.ZipFile(fmu(model)) as z:
        return z.read(TERMINALS)


def declares_flanges(model):
    root = ET.parse(ROOT / "modelDescription" / f"{model}.xml").getroot()
    return root.find("VendorAnnotations/Tool[@name='actuator-fmus']/Terminals/Flange") is not None


def terminals(model):
    """{terminal name: (terminalKind, {memberName: (variableName, variableKind)})}."""
    root = ET.fromstring(terminals_xml(model))
    return {
        t.get("name"): (t.get("terminalKind"),
                        {m.get("memberName"): (m.get("variableName"), m.get("variableKind"))
                         for m in t.findall("TerminalMemberVariable")})
        for t in root.findall("Terminals/Terminal")
    }


WITH_FLANGES = [m for m in MODELS if declares_flanges(m)]


def test_terminals_exactly_where_the_source_declares_flanges():
    assert MODELS, "run `make fmus` first"
    assert WITH_FLANGES and len(WITH_FLANGES) < len(MODELS)
    for model in MODELS:
        has_terminals = ET.fromstring(terminals_xml(model)).find("Terminals") is not None
        assert has_terminals == (model in WITH_FLANGES), model
    assert "PassThrough" not in WITH_FLANGES


@pytest.mark.parametrize("model", MODELS)
def test_the_terminals_are_valid_fmi3(model):
    document = etree.fromstring(terminals_xml(model))
    SCHEMA.assertValid(document)
    # The FMI 3.0 rule the schema cannot check: the same fmiVersion as the model description.
    assert document.get("fmiVersion") == read_model_description(fmu(model)).fmiVersion
    for t in document.iter("Terminal"):
        assert t.get("matchingRule") == "plug"
    # A terminalsAndIcons.xml does not disturb FMPy's validation of the FMU.
    assert validate_fmu(fmu(model)) == []


@pytest.mark.parametrize("model", WITH_FLANGES)
def test_every_member_is_a_flange_variable_of_the_fmu(model):
    variables = {v.name: v for v in read_model_description(fmu(model)).modelVariables}
    found = terminals(model)
    assert found
    for name, (kind, members) in found.items():
        assert set(members) == set(FLANGES[kind]), name
        causalities = []
        for member, (variable_name, variable_kind) in members.items():
            v = variables[variable_name]
            assert (v.type, v.variability, v.unit) == ("Float64", "continuous", FLANGES[kind][member]), \
                (name, member)
            if member in FLOW_MEMBERS:
                assert variable_kind in ("inflow", "outflow"), (name, member)
            else:
                assert variable_kind == "signal", (name, member)
            causalities.append(v.causality)
        # A causal FMU's flange imposes one of the pair and answers with the other.
        assert sorted(causalities) == ["input", "output"], name


def test_the_muscle_and_pulley_flanges_pair_as_the_robot_joint_connects_them():
    """systems/RobotJoint.ssd wires two McKibbenMuscles to a PulleyJoint variable by variable. The
    pulley's cable-end terminals, matched with the muscle's flange by member name, give the same
    connections, and the flow kinds are opposite with complementary causality: the muscle's force
    output is forwarded to the pulley's force input as it is (FMI 3.0 section 2.4.9.2.4), with no
    sign change."""
    ns = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription"}
    ssd = ET.parse(ROOT / "systems" / "RobotJoint.ssd").getroot()
    components = {c.get("name"): c.get("source").rsplit("/", 1)[-1].removesuffix(".fmu")
                  for c in ssd.iter(f"{{{ns['ssd']}}}Component")}
    wired = {(c.get("startElement"), c.get("startConnector"), c.get("endElement"), c.get("endConnector"))
             for c in ssd.iter(f"{{{ns['ssd']}}}Connection")}
    joint = next(name for name, model in components.items() if model == "PulleyJoint")
    muscles = [name for name, model in components.items() if model == "McKibbenMuscle"]
    (muscle_kind, muscle_members), = terminals("McKibbenMuscle").values()
    causality = lambda model, name: next(
        v.causality for v in read_model_description(fmu(model)).modelVariables if v.name == name)
    pulley = terminals("PulleyJoint")
    assert sorted(pulley) == sorted(muscles)
    for muscle in muscles:
        kind, members = pulley[muscle]
        assert kind == muscle_kind and set(members) == set(muscle_members)
        for member, (joint_variable, joint_flow) in members.items():
            muscle_variable, muscle_flow = muscle_members[member]
            if causality("PulleyJoint", joint_variable) == "output":
                assert (joint, joint_variable, muscle, muscle_variable) in wired, member
            else:
                assert (muscle, muscle_variable, joint, joint_variable) in wired, member
            if member == "f":
                assert {joint_flow, muscle_flow} == {"inflow", "outflow"}


def test_the_flow_signs_are_modelicas():
    """Modelica's flow convention: the cut force (torque) is what the outside applies to the model
    at the flange, along the flange axis. The muscle's inflow tension grows as the flange is pulled
    out (a spring's flange_b.f = c (s - s0)); the motor's inflow load torque accelerates the rotor
    towards +phi (an inertia's J der(w) = tau)."""
    force = [simulate_fmu(fmu("McKibbenMuscle"), stop_time=0.01, output_interval=0.01,
                          start_values={"pressure": 3e5, "length": length}, output=["force"])["force"][-1]
             for length in (0.085, 0.086)]
    assert 0 < force[0] < force[1]
    for load in (-1e-12, 1e-12):
        r = simulate_fmu(fmu("MultiferroicMotor"), stop_time=1e-9, output_interval=1e-10,
                         start_values={"load_torque": load}, output=["rotor_speed", "torque"])
        assert r["torque"][-1] == 0.0  # no strain: the load alone drives the rotor
        assert r["rotor_speed"][-1] * load > 0


def test_the_joint_torque_is_the_torque_on_the_outside():
    """McKibbenJoint's `jointTorque` is an outflow: the torque the FMU applies to the shaft towards
    +phi. By virtual work, the tensions pulling the muscles' ends together give the shaft
    -(F_flexor dL_flexor/dphi + F_extensor dL_extensor/dphi), from the FMU's own lengths and
    forces (the lengths are linear in the angle)."""
    def at(angle):
        r = simulate_fmu(fmu("McKibbenJoint"), stop_time=0.01, output_interval=0.01,
                         start_values={"actuatorInput": 1e5, "jointPosition": angle},
                         output=["jointTorque", "flexor_force", "extensor_force",
                                 "flexor_length", "extensor_length"])
        return {name: float(r[name][-1]) for name in r.dtype.names}

    step = 1e-3
    a, b = at(0.1), at(0.1 + step)
    virtual_work = -sum(a[f"{m}_force"] * (b[f"{m}_length"] - a[f"{m}_length"]) / step
                        for m in ("flexor", "extensor"))
    assert a["jointTorque"] > 0
    assert a["jointTorque"] == pytest.approx(virtual_work, rel=1e-9)


@pytest.mark.parametrize("model", MODELS)
def test_every_icon_is_there_as_png_and_svg(model):
    """The FMU icon (icon.png and icon.svg, FMI 3.0 section 2.4.9.1) over the default coordinate
    system, and each terminal's icon (iconBaseName.png and .svg) inside the FMU's archive, square
    images as their extents are."""
    from PIL import Image
    import io

    root = ET.fromstring(terminals_xml(model))
    graphics = root.find("GraphicalRepresentation")
    system = graphics.find("CoordinateSystem").attrib
    assert {k: float(v) for k, v in system.items()} == \
        {"x1": -100, "y1": -100, "x2": 100, "y2": 100, "suggestedScalingFactorTo_mm": 0.1}
    assert {k: float(v) for k, v in graphics.find("Icon").attrib.items()} == \
        {"x1": -100, "y1": -100, "x2": 100, "y2": 100}
    names = ["icon"] + [t.get("iconBaseName") for t in root.iter("TerminalGraphicalRepresentation")]
    with zipfile.ZipFile(fmu(model)) as z:
        for name in names:
            image = Image.open(io.BytesIO(z.read(f"terminalsAndIcons/{name}.png")))
            assert image.width == image.height >= 64, name
            # Not blank: more than one colour.
            assert len(image.getcolors(1 << 16)) > 1, name
            svg = etree.fromstring(z.read(f"terminalsAndIcons/{name}.svg"))
            assert svg.get("viewBox") == "-100 -100 200 200", name
    # Each terminal sits on the icon's border and the terminals do not overlap.
    boxes = [tuple(float(t.get(k)) for k in ("x1", "y1", "x2", "y2"))
             for t in root.iter("TerminalGraphicalRepresentation")]
    assert len(set(boxes)) == len(boxes)
    for x1, y1, x2, y2 in boxes:
        assert 100 in (abs((x1 + x2) / 2), abs((y1 + y2) / 2))
