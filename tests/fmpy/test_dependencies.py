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

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from conftest import ROOT, fmu_path  # noqa: E402

# Operating points: parameter overrides (the effects on) x input points.
CONFIGS = {
    "PassThrough": ([{}], [{}, {"u": 0.7}]),
    # The first point lies just below (C2 38719.67 Pa) and just above (38679.73 Pa) the clamp at
    # 0.999 of the ballooning pressure, so that the initial input_clamped shows each parameter.
    "FreeBladder": (
        [{}, {"mooney_c2": 38719.67}, {"mooney_c2": 38679.73}],
        [{"pressure": 4.9322e4, "length": 0.1336}, {"pressure": 3e4, "length": 0.16},
         {"pressure": -5e4, "length": 0.12}],
    ),
    "McKibbenMuscle": (
        # Presets from one that differs from the defaults in nothing (1, Table 2.1's muscle A) to
        # one that does (2, muscle B; 5 to 6, the Festo DMSP-10 to the DMSP-40), with and without
        # the bladder and the pressure solver.
        [{}, {"bladder_model": 1}, {"friction": True}, {"bladder_model": 1, "friction": True},
         {"pressure_solver": True}, {"preset": 1}, {"preset": 1, "bladder_model": 1},
         {"preset": 1, "pressure_solver": True}, {"preset": 5},
         # Muscle D to the DMSP-10 (preset 4 to 5) switches the bladder model and its constants;
         # the thick wall shows its layer count.
         {"preset": 4}, {"bladder_model": 2, "bladder_layers": 8}, {"connector_stiffness": 5e4}],
        [{"pressure": 2e5, "length": 0.09, "target_force": 50.0},
         {"pressure": 4e5, "length": 0.085, "target_force": 200.0},
         {"pressure": 0.0, "length": 0.095, "target_force": 0.0},
         # Past the free contraction: slack unless signed_force.
         {"pressure": 2e5, "length": 0.06, "target_force": 0.0},
         # Taut with muscle A's bladder (max_length 97.3 mm), on the stretching strands beyond
         # it and beyond the bare sleeve's b, taut for the DMSP-10 (preset 5).
         {"pressure": 3e5, "length": 0.096, "target_force": 20.0},
         {"pressure": 2e5, "length": 0.1, "target_force": 20.0},
         {"pressure": 2e5, "length": 0.115, "target_force": 20.0},
         {"pressure": 3e5, "length": 0.26, "target_force": 20.0}],
    ),
    "KnittedMuscle": (
        [{}, {"bladder_model": 1}, {"friction": True}, {"shape_model": 1}],
        [{"pressure": 2e4, "length": 0.4}, {"pressure": 5e4, "length": 0.35},
         {"pressure": 0.0, "length": 0.42}, {"pressure": 2e4, "length": 0.15}],
    ),
    "McKibbenJoint": (
        # common_mode_pressure at max_pressure: the flexor's pressure saturates there.
        [{}, {"friction": True}, {"bladder_model": 1}, {"command_mode": 1},
         {"common_mode_pressure": 7e5},
         # Short muscles: past +-0.45 rad one goes slack (unless signed_force).
         {"flexor_rest_length": 0.07, "extensor_rest_length": 0.07}],
        [{"actuatorInput": 0.3, "jointPosition": 0.1, "jointVelocity": 0.2},
         {"actuatorInput": -0.5, "jointPosition": -0.2, "jointVelocity": -1.0},
         {"actuatorInput": 1.0, "jointPosition": 0.0, "jointVelocity": 0.0},
         {"actuatorInput": 2e4, "jointPosition": 0.6, "jointVelocity": 0.0},
         {"actuatorInput": -2e4, "jointPosition": -0.6, "jointVelocity": 0.0}],
    ),
    "PulleyJoint": (
        [{}, {"external_pressures": True}],
        [{"flexor_force": 100.0, "extensor_force": 50.0, "flexor_pressure_command": 2e5,
          "extensor_pressure_command": 1e5},
         {"flexor_force": 0.0, "extensor_force": 0.0}],
    ),
    "MultiferroicMotor": (
        [{}, {"strain_drive": True}, {"onion_model": 1}, {"schedule": 1}],
        [{"strain_direction": 0.3, "stress": 5e7, "load_torque": 1e-9, "strain": 1e-4},
         {"strain_direction": 1.2, "stress": 2e7, "load_torque": 0.0, "strain": 5e-4}],
    ),
}
MODELS = list(CONFIGS)


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


def test_every_model_has_operating_points():
    # A model missing from CONFIGS would have its declared dependencies never measured.
    shipped = {p.stem for p in (ROOT / "modelDescription").glob("*.xml")}
    assert set(CONFIGS) == shipped, f"CONFIGS lacks {sorted(shipped - set(CONFIGS))}"


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
