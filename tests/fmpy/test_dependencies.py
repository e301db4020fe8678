"""Declared `dependencies` against measured ones. For every FMU, at several operating
points with the effects on, each input is perturbed alone (relative 1e-3, absolute where zero) and
the outputs are re-read WITHOUT stepping (fmi2GetReal after fmi2SetReal recomputes the direct
feedthrough): an output that changes must declare the input, and each declared input must change
its output at one tested point at least. Discrete outputs (flags) change only where an input
crosses a threshold: for them each input is also swept across its declared range. Initial unknowns: each input and parameter is perturbed
before initialization and the initial unknowns compared after fmi2ExitInitializationMode.

`python tests/fmpy/test_dependencies.py` prints the measured lists."""

import shutil
import sys
import tempfile
import xml.etree.ElementTree as ET

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from conftest import ROOT, fmu_path  # noqa: E402

def parse_values(text):
    """`name=value ...` from a model description's test data: {name: bool or float}."""
    values = {}
    for item in text.split():
        name, value = item.split("=")
        values[name] = value == "true" if value in ("true", "false") else float(value)
    return values


def operating_points(model):
    """The operating points a model's description gives for its tests (VendorAnnotations): the
    defaults and each Parameters set (the effects on), and the Inputs points (the start values if
    none)."""
    root = ET.parse(ROOT / "modelDescription" / f"{model}.xml").getroot()
    tests = root.find("VendorAnnotations/Tool[@name='actuator-fmus']/Tests")
    given = lambda tag: [parse_values(e.get("values")) for e in tests.iter(tag)] if tests is not None else []
    return [{}] + given("Parameters"), given("Inputs") or [{}]


MODELS = sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))
CONFIGS = {m: operating_points(m) for m in MODELS}


class Model:
    def __init__(self, name):
        self.name = name
        self.md = read_model_description(fmu_path(name))
        self.dir = extract(fmu_path(name))
        self.vars = self.md.modelVariables
        self.by_name = {v.name: v for v in self.vars}
        self.inputs = [v for v in self.vars if v.causality == "input"]
        self.outputs = [u.variable for u in self.md.outputs]
        self.initial = [u.variable for u in self.md.initialUnknowns]

    def declared(self, unknowns):
        """The declared inputs and parameters; continuous states (Model Exchange's other knowns)
        cannot be perturbed through Co-Simulation and are checked by the derivative tests."""
        return {u.variable.name: {d.name for d in (u.dependencies or []) if d.causality in ("input", "parameter")}
                for u in unknowns}

    def slave(self):
        s = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                      modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="deps")
        s.instantiate()
        return s

    def set(self, s, values):
        for name, value in values.items():
            v = self.by_name[name]
            if v.type == "Real":
                s.setReal([v.valueReference], [float(value)])
            elif v.type == "Boolean":
                s.setBoolean([v.valueReference], [bool(value)])
            else:
                s.setInteger([v.valueReference], [int(value)])

    def get(self, s, variables):
        out = {}
        for v in variables:
            if v.type == "Real":
                out[v.name] = s.getReal([v.valueReference])[0]
            elif v.type == "Boolean":
                out[v.name] = s.getBoolean([v.valueReference])[0]
            else:
                out[v.name] = s.getInteger([v.valueReference])[0]
        return out

    def close(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def perturbed(v, value):
    """The value moved by 1e-3 relative (1e-3 of the range scale where zero), kept in range."""
    if v.type == "Boolean":
        return not value
    if v.type != "Real":
        up = int(value) + 1
        return up if v.max is None or up <= float(v.max) else int(value) - 1
    value = float(value)
    step = 1e-3 * abs(value) if value != 0 else 1e-3 * min(1.0, float(v.max or 1.0))
    if v.max is not None and value + step > float(v.max):
        return value - step
    return value + step


def sweep(v, value):
    """Values of a Real input across its declared range: multiples of the operating point and
    fractions of the range."""
    lo, hi = float(v.min), float(v.max)
    values = [value * f for f in (-1.0, 0.0, 0.5, 0.9, 1.1, 2.0, 5.0, 10.0, 100.0)]
    values += [lo + f * (hi - lo) for f in (0.0, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0)]
    return [x for x in values if lo <= x <= hi]


def measure_outputs(model):
    """{output: {inputs that changed it}} over every operating point."""
    seen = {o.name: set() for o in model.outputs}
    params, points = CONFIGS[model.name]
    for config in params:
        s = model.slave()
        try:
            s.setupExperiment(startTime=0.0)
            model.set(s, config)
            s.enterInitializationMode()
            s.exitInitializationMode()
            t = 0.0
            for point in points:
                model.set(s, point)
                s.doStep(t, 1e-3)
                t += 1e-3
                model.set(s, point)
                base = model.get(s, model.outputs)
                current = {i.name: model.get(s, [i])[i.name] for i in model.inputs}
                for i in model.inputs:
                    model.set(s, {i.name: perturbed(i, current[i.name])})
                    after = model.get(s, model.outputs)
                    model.set(s, {i.name: current[i.name]})
                    for o in model.outputs:
                        if after[o.name] != base[o.name]:
                            seen[o.name].add(i.name)
                    assert model.get(s, model.outputs) == base, f"{i.name}: not restored"
                # A discrete output moves only where its input crosses a threshold: each input is
                # swept over its range instead, still without stepping.
                discrete = [o for o in model.outputs if o.type != "Real"]
                for i in model.inputs if discrete else []:
                    for value in sweep(i, current[i.name]):
                        model.set(s, {i.name: value})
                        after = model.get(s, discrete)
                        for o in discrete:
                            if after[o.name] != base[o.name]:
                                seen[o.name].add(i.name)
                    model.set(s, {i.name: current[i.name]})
                    assert model.get(s, model.outputs) == base, f"{i.name}: not restored"
        finally:
            s.terminate()
            s.freeInstance()
    return seen


def initial_values(model, values):
    s = model.slave()
    try:
        s.setupExperiment(startTime=0.0)
        model.set(s, values)
        s.enterInitializationMode()
        s.exitInitializationMode()
        return model.get(s, model.initial)
    except Exception:
        return None
    finally:
        try:
            s.terminate()
        except Exception:
            pass
        s.freeInstance()


def measure_initial(model):
    """{initial unknown: {inputs and parameters that changed it}} over every configuration."""
    seen = {u.name: set() for u in model.initial}
    candidates = [v for v in model.vars if v.causality in ("input", "parameter")]
    params, points = CONFIGS[model.name]
    for config, point in ((c, p) for c in params for p in points):
        values = dict(config, **point)
        base = initial_values(model, values)
        assert base is not None, f"{model.name} {values}: initialization failed"
        for c in candidates:
            start = values.get(c.name, c.start)
            if start is None:
                continue
            start = {"true": True, "false": False}.get(str(start).lower(), start)
            after = initial_values(model, dict(values, **{c.name: perturbed(c, start)}))
            if after is None:
                continue
            for u in model.initial:
                if after[u.name] != base[u.name]:
                    seen[u.name].add(c.name)
        # Discrete initial unknowns (flags): each input swept across its declared range.
        discrete = [u for u in model.initial if u.type != "Real"]
        for i in model.inputs if discrete else []:
            for value in sweep(i, float(values.get(i.name, i.start))):
                after = initial_values(model, dict(values, **{i.name: value}))
                for u in discrete if after is not None else []:
                    if after[u.name] != base[u.name]:
                        seen[u.name].add(i.name)
    return seen


def compare(declared, measured, what):
    undeclared = [(o, sorted(measured[o] - declared[o])) for o in declared if measured[o] - declared[o]]
    unshown = [(o, sorted(declared[o] - measured[o])) for o in declared if declared[o] - measured[o]]
    assert not undeclared, f"{what}: undeclared dependencies {undeclared}"
    assert not unshown, f"{what}: declared dependencies that never showed {unshown}"
    return sum(len(d) for d in declared.values())


@pytest.mark.parametrize("name", MODELS)
def test_the_operating_points_name_the_models_variables(name):
    # A renamed variable must not leave an operating point that sets nothing.
    causality = {v.name: v.causality for v in read_model_description(fmu_path(name)).modelVariables}
    params, points = CONFIGS[name]
    for values, kind in [(p, "parameter") for p in params] + [(p, "input") for p in points]:
        for variable in values:
            assert causality.get(variable) == kind, f"{name}: {variable} is not a {kind}"


@pytest.mark.parametrize("name", MODELS)
def test_output_dependencies(name):
    model = Model(name)
    try:
        pairs = compare(model.declared(model.md.outputs), measure_outputs(model), f"{name} Outputs")
    finally:
        model.close()
    print(f"{name}: {pairs} (output, input) pairs verified")


@pytest.mark.parametrize("name", MODELS)
def test_initial_unknown_dependencies(name):
    model = Model(name)
    try:
        pairs = compare(model.declared(model.md.initialUnknowns), measure_initial(model),
                        f"{name} InitialUnknowns")
    finally:
        model.close()
    print(f"{name}: {pairs} (initial unknown, input or parameter) pairs verified")


if __name__ == "__main__":
    for name in sys.argv[1:] or MODELS:
        model = Model(name)
        order = {v.name: k for k, v in enumerate(model.vars)}
        for list_name, measured in (("Outputs", measure_outputs(model)),
                                    ("InitialUnknowns", measure_initial(model))):
            print(f"== {name} {list_name}")
            for o, deps in measured.items():
                deps = sorted(deps, key=order.get)
                print(f'      <Unknown name="{o}" dependencies="{" ".join(deps)}" '
                      f'dependenciesKind="{" ".join(["dependent"] * len(deps))}"/>')
        model.close()
