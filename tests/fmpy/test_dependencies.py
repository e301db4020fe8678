"""Declared `dependencies` against measured ones. For every FMU, at several operating
points with the effects on, each input is perturbed alone (relative 1e-3, absolute where zero) and
the outputs are re-read WITHOUT stepping (fmi2GetReal after fmi2SetReal recomputes the direct
feedthrough): an output that changes must declare the input, and each declared input must change
its output at one tested point at least. Discrete outputs (flags) change only where an input
crosses a threshold: for them each input is also swept across its declared range. Initial unknowns: each input and parameter is perturbed
before initialization and the initial unknowns compared after fmi2ExitInitializationMode.

The Jacobian: each model writes its partials through row types generated from its
`<ModelStructure>` (one field per declared known), so its structure is the declared one. On a
Model Exchange instance at every operating point, every declared (output or state derivative,
Real input or state) pair must show a nonzero fmi2GetDirectionalDerivative at one point at least,
and no undeclared known may move an unknown when it is perturbed (fmi2SetReal,
fmi2SetContinuousStates): the finite difference is the independent truth.

`python tests/fmpy/test_dependencies.py` prints the measured lists."""

import ctypes
import random
import shutil
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model, FMU2Slave

from conftest import ROOT, fmu_path  # noqa: E402

def parse_values(text):
    """`name=value ...` from a model description's test data: {name: bool or float}."""
    values = {}
    for item in text.split():
        name, value = item.split("=")
        values[name] = value == "true" if value in ("true", "false") else float(value)
    return values


def option_values(v):
    """Every setting of an option parameter: each item of an Enumeration, both Booleans, an
    Integer's bounds and start; None for a Real."""
    if v.type == "Boolean":
        return [False, True]
    if v.type == "Enumeration":
        return [int(item.value) for item in v.declaredType.items]
    if v.type == "Integer":
        return sorted({int(v.min), int(v.start), int(v.max)})
    return None


SAMPLED_COMBINATIONS = 6
# Options that set only the status of a call, never a value (test_strict_master.py runs them):
# the Discard they may ask for would end the measurement at an out-of-range point.
STATUS_ONLY = {"out_of_range_policy"}


def initializes(md, where, config):
    """Whether the model of description `md`, extracted at `where`, initializes with parameters
    `config` at its start inputs."""
    s = FMU2Slave(guid=md.guid, unzipDirectory=where, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="sample")
    s.instantiate()
    try:
        s.setupExperiment(startTime=0.0)
        for name, value in config.items():
            v = next(v for v in md.modelVariables if v.name == name)
            if v.type == "Boolean":
                s.setBoolean([v.valueReference], [bool(value)])
            elif v.type == "Real":
                s.setReal([v.valueReference], [float(value)])
            else:
                s.setInteger([v.valueReference], [int(value)])
        s.enterInitializationMode()
        s.exitInitializationMode()
        s.terminate()
        return True
    except Exception:
        return False
    finally:
        s.freeInstance()


def configurations(model, given):
    """The defaults, the description's Parameters sets, every option setting alone, and twice
    SAMPLED_COMBINATIONS random combinations of the options, alone and on the sets that switch
    a Real effect on (seeded by the model's name)."""
    md = read_model_description(fmu_path(model))
    options = [v for v in md.modelVariables
               if v.causality == "parameter" and v.name not in STATUS_ONLY and option_values(v)]
    settings = {v.name: option_values(v) for v in options}
    # Each setting alone; the start value is the defaults'.
    alone = [{v.name: value} for v in options for value in settings[v.name]
             if str(value).lower() != str(v.start).lower()]
    # The description's sets that set a Real (a connector spring, a bag) are the bases of half
    # the combinations on them: the options override the rest of such a set.
    switches = [{}] + [config for config in given if set(config) - set(settings)]
    switches += [{}] * (len(switches) - 1)
    where = extract(fmu_path(model))

    def combinations(rng, bases):
        sampled = []
        for _ in range(50 * SAMPLED_COMBINATIONS if settings else 0):
            if len(sampled) == SAMPLED_COMBINATIONS:
                break
            base = rng.choice(bases) if bases else {}
            combination = dict(base, **{name: rng.choice(values) for name, values in settings.items()})
            # A combination the model refuses, saying why, is no sample.
            if initializes(md, where, combination):
                sampled.append(combination)
        return sampled

    try:
        sampled = combinations(random.Random(model), []) + combinations(random.Random(model), switches)
    finally:
        shutil.rmtree(where, ignore_errors=True)
    unique = []
    for config in [{}] + given + alone + sampled:
        if config not in unique:
            unique.append(config)
    return unique


def operating_points(model):
    """The configurations ([`configurations`]) and the Inputs points the model's description gives
    for its tests (VendorAnnotations; the start values if none)."""
    root = ET.parse(ROOT / "modelDescription" / f"{model}.xml").getroot()
    tests = root.find("VendorAnnotations/Tool[@name='actuator-fmus']/Tests")
    given = lambda tag: [parse_values(e.get("values")) for e in tests.iter(tag)] if tests is not None else []
    return configurations(model, given("Parameters")), given("Inputs") or [{}]


MODELS = sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))
CONFIGS = {}


def configs(model):
    """([configurations], [Inputs points]) of `model`, built once."""
    if model not in CONFIGS:
        CONFIGS[model] = operating_points(model)
    return CONFIGS[model]


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
    params, points = configs(model.name)
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
    params, points = configs(model.name)
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


def jacobian_pairs(model):
    """{unknown: {known: declared}} of the Jacobian: Real outputs and state derivatives by Real
    inputs and continuous states."""
    knowns = [v for v in model.inputs if v.type == "Real"] + [d.variable.derivative for d in model.md.derivatives]
    unknowns = [u for u in model.md.outputs if u.variable.type == "Real"] + list(model.md.derivatives)
    names = {k.name for k in knowns}
    declared = {u.variable.name: {d.name for d in (u.dependencies or []) if d.name in names} for u in unknowns}
    return knowns, [u.variable for u in unknowns], declared


def as_doubles(values):
    array = np.ascontiguousarray(values, dtype=float)
    return array, array.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def measure_jacobian(model):
    """({unknown: {knowns with a nonzero partial}}, {unknown: {knowns that moved it}}) over every
    operating point of a Model Exchange instance in continuous-time mode, and the points."""
    knowns, unknowns, _ = jacobian_pairs(model)
    n = len(model.md.derivatives)
    inputs = [k for k in knowns if k.causality == "input"]
    outputs = [u for u in unknowns if u.causality == "output"]
    nonzero = {u.name: set() for u in unknowns}
    moved = {u.name: set() for u in unknowns}
    params, points = configs(model.name)
    sampled = 0
    for config in params:
        m = FMU2Model(guid=model.md.guid, unzipDirectory=model.dir,
                      modelIdentifier=model.md.modelExchange.modelIdentifier, instanceName="jacobian")
        m.instantiate()
        try:
            m.setupExperiment(startTime=0.0)
            model.set(m, config)
            m.enterInitializationMode()
            m.exitInitializationMode()
            while m.newDiscreteStates()[0]:
                pass
            m.enterContinuousTimeMode()
            x, x_ptr = as_doubles(np.zeros(n))
            if n:
                m.getContinuousStates(x_ptr, n)

            def values(states):
                _, ptr = as_doubles(states)
                if n:
                    m.setContinuousStates(ptr, n)
                dx, dx_ptr = as_doubles(np.zeros(n))
                if n:
                    m.getDerivatives(dx_ptr, n)
                return list(m.getReal([o.valueReference for o in outputs])) + list(dx)

            for point in points:
                model.set(m, point)
                state = x.copy()
                base = values(state)
                current = dict(zip((i.name for i in inputs), m.getReal([i.valueReference for i in inputs])))
                for j, k in enumerate(knowns):
                    column = m.getDirectionalDerivative([u.valueReference for u in unknowns],
                                                        [k.valueReference], [1.0])
                    for u, d in zip(unknowns, column):
                        if d != 0.0:
                            nonzero[u.name].add(k.name)
                    if k.causality == "input":
                        model.set(m, {k.name: perturbed(k, current[k.name])})
                        after = values(state)
                        model.set(m, {k.name: current[k.name]})
                    else:
                        shifted = state.copy()
                        shifted[j - len(inputs)] = perturbed(k, state[j - len(inputs)])
                        after = values(shifted)
                    for u, a, b in zip(unknowns, after, base):
                        if a != b:
                            moved[u.name].add(k.name)
                    assert values(state) == base, f"{model.name} {config} {point}: {k.name} not restored"
                sampled += 1
        finally:
            m.terminate()
            m.freeInstance()
    return nonzero, moved, sampled


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
    params, points = configs(name)
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
def test_the_jacobian_is_the_declared_dependencies(name):
    model = Model(name)
    try:
        _, _, declared = jacobian_pairs(model)
        nonzero, moved, sampled = measure_jacobian(model)
    finally:
        model.close()
    undeclared = [(u, sorted(nonzero[u] - declared[u])) for u in declared if nonzero[u] - declared[u]]
    assert not undeclared, f"{name}: partials by undeclared knowns {undeclared}"
    moving = [(u, sorted(moved[u] - declared[u])) for u in declared if moved[u] - declared[u]]
    assert not moving, f"{name}: undeclared knowns that move an unknown {moving}"
    unshown = [(u, sorted(declared[u] - nonzero[u])) for u in declared if declared[u] - nonzero[u]]
    assert not unshown, f"{name}: declared dependencies whose partial is 0 at every point {unshown}"
    pairs = sum(len(d) for d in declared.values())
    print(f"{name}: {pairs} declared (unknown, known) pairs nonzero, {sampled} Model Exchange points")


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
