"""fmi2GetDirectionalDerivative in Initialization Mode through FMPy: with respect to every Real known
(parameter or input) that an initial unknown declares among its dependencies, against central
differences taken here through fmi2SetReal and fmi2GetReal in the same mode (the FMU rebuilds the
model from the changed value at each get)."""

import math

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from conftest import fmu_path

_EXTRACTED = {}


def _extracted(path):
    if path not in _EXTRACTED:
        _EXTRACTED[path] = extract(path)
    return _EXTRACTED[path]

# (model, parameters set before the derivatives are taken).
# Pressurized, and with a connector spring: away from the kinks at zero pressure and at the
# switches that zero stands for ("no connector", "no bag").
CASES = [
    ("McKibbenMuscle", {"pressure": 3e5, "connector_stiffness": 5e4}),
    ("McKibbenMuscle", {"preset": 1, "bladder_model": 1, "pressure": 4e5, "length": 0.08}),
    ("McKibbenMuscle", {"preset": 2, "bladder_model": 2, "bladder_layers": 4, "pressure": 3e5,
                        "length": 0.09}),
    ("McKibbenJoint", {}),
    ("KnittedMuscle", {"pressure": 2e5}),
    ("KnittedMuscle", {"shape_model": 1, "bladder_model": 1, "pressure": 2e5}),
    ("KnittedMuscle", {"bag_diameter": 0.085, "pressure": 1e4}),
    ("FreeBladder", {"pressure": 3e4}),
    ("PulleyJoint", {"flexor_pressure_command": 3e5, "extensor_pressure_command": 2e5}),
    ("MultiferroicMotor", {"stress": 2e8, "strain_direction": 0.3, "initial_onion_offset": 0.2}),
    ("PassThrough", {}),
]
# Relative step of the differences here: not the FMU's (its is the cube root of epsilon).
STEP = 1e-5
RTOL = 2e-4


def in_initialization(model, parameters):
    path = fmu_path(model)
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=_extracted(path),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName=model)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    by_name = {v.name: v for v in md.modelVariables}
    for name, value in parameters.items():
        v = by_name[name]
        {"Real": fmu.setReal, "Integer": fmu.setInteger, "Enumeration": fmu.setInteger,
         "Boolean": fmu.setBoolean}[v.type](
            [v.valueReference], [value])
    return md, fmu


def central_difference(fmu, unknown, known):
    """d unknown / d known by central differences, one-sided at a declared bound."""
    x = fmu.getReal([known.valueReference])[0]
    lo = float(known.min) if known.min is not None else -math.inf
    hi = float(known.max) if known.max is not None else math.inf
    h = STEP * (abs(x) if x != 0 else min(1.0, 0.5 * (hi - lo)))
    up, down = (x + h, x - h)
    if up > hi:
        up = x
    if down < lo:
        down = x
    values = []
    for point in (up, down):
        fmu.setReal([known.valueReference], [point])
        values.append(fmu.getReal([unknown.valueReference])[0])
    fmu.setReal([known.valueReference], [x])
    return (values[0] - values[1]) / (up - down), max(abs(v) for v in values), up - down


@pytest.mark.parametrize("model,parameters", CASES, ids=[f"{m}{p}" for m, p in CASES])
def test_initial_unknowns_by_their_declared_knowns_match_central_differences(model, parameters):
    md, fmu = in_initialization(model, parameters)
    if not md.coSimulation.providesDirectionalDerivative:
        pytest.skip(f"{model} provides no directional derivatives")
    pairs, failures, found = 0, [], []
    try:
        for u in md.initialUnknowns:
            unknown = u.variable
            if unknown.type != "Real":
                continue
            for known in u.dependencies or []:
                if known.type != "Real" or known.causality not in ("parameter", "input"):
                    continue
                x = fmu.getReal([known.valueReference])[0]
                # At a declared bound a value often switches an effect off (0: no connector, no
                # bag): no derivative there.
                if x in (known.min and float(known.min), known.max and float(known.max)):
                    continue
                exact = fmu.getDirectionalDerivative(
                    [unknown.valueReference], [known.valueReference], [1.0])[0]
                fd, magnitude, width = central_difference(fmu, unknown, known)
                found.append((unknown.name, known.name, exact, fd, magnitude, width))
                pairs += 1
    finally:
        fmu.freeInstance()
    # The unknown's own scale, the largest magnitude it took in any difference of this case: a
    # partial is zero where the difference is within its accuracy there (the models' iterations
    # converge to about 1e-10 relative), tenfold.
    scale = {}
    for name, _, _, _, magnitude, _ in found:
        scale[name] = max(scale.get(name, 0.0), magnitude)
    for name, known, exact, fd, _, width in found:
        floor = 1e-9 * scale[name] / width
        if not math.isclose(exact, fd, rel_tol=RTOL, abs_tol=floor):
            failures.append(f"d{name}/d{known}: {exact!r} against {fd!r}")
    print(f"{model} {parameters}: {pairs} pairs")
    assert pairs > 0 or model == "PassThrough"
    assert not failures, "\n".join(failures)
