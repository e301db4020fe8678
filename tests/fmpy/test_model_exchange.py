"""Model Exchange against Co-Simulation under FMPy: every catalogue scene of an algebraic FMU
(fast variant; first and last sweep value), with CVode and with Euler at a quarter of the
communication step, plus the McKibbenJoint under a friction cycle. FMPy records a Co-Simulation
output at t + h from the input set at t, and a Model Exchange output at t from the input at t, so
the runs are compared with that one-sample shift. The friction history is committed at every
completed integrator step, so the agreement is exact up to rounding."""

import pathlib

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from conftest import fmu_path

ROOT = pathlib.Path(__file__).resolve().parents[2]
from actuator_fmus import scene as scenes  # noqa: E402

SHIPPED = sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))
# The models without continuous states (no `derivative` attribute in their description): their
# Model Exchange runs are compared to co-simulation to 1e-9 below.
ALGEBRAIC = [
    m for m in SHIPPED
    if 'derivative="' not in (ROOT / "modelDescription" / f"{m}.xml").read_text()
]
TOLERANCE = 1e-9
CATALOGUE = {p: scenes.load_scene(p)["fmu"] for p in sorted((ROOT / "scenes").glob("*.json"))}
# Algebraic FMUs' scenes are compared to 1e-9 here, PulleyJoint's (continuous states) to first
# order in the step below; the motor's scenes (continuous states, events) in
# test_motor_model_exchange.py.
SCENES = [p for p, fmu in CATALOGUE.items() if fmu in ALGEBRAIC]
PULLEY_SCENES = [p for p, fmu in CATALOGUE.items() if fmu == "PulleyJoint"]


def test_every_catalogue_scene_is_compared():
    assert set(CATALOGUE.values()) <= set(ALGEBRAIC) | {"PulleyJoint", "MultiferroicMotor"}
    assert PULLEY_SCENES, "PulleyJoint has no catalogue scene"


EULER_SUBSTEPS = 4


def compare(model, parameters, signals, outputs, step, stop):
    """Largest difference between ME (CVode; Euler at step/4) and CS, relative to each output's
    largest magnitude, over all outputs. FMPy 0.3.x's Euler takes one step per output point
    whatever `step_size` says, so its run samples every step/4 (the inputs interpolated there and
    the friction history committed there) and every 4th row is compared."""
    kw = dict(start_values=parameters, input=signals, output=outputs, stop_time=stop)
    cs = simulate_fmu(fmu_path(model), output_interval=step, **kw)
    worst = {}
    for solver, h in [("CVode", step), ("Euler", step / EULER_SUBSTEPS)]:
        me = simulate_fmu(fmu_path(model), fmi_type="ModelExchange", solver=solver, step_size=h, output_interval=h, **kw)
        if solver == "Euler":
            # Every sampled point was one Euler step (and one completed integrator step).
            assert len(me) == EULER_SUBSTEPS * (len(cs) - 1) + 1
            assert np.allclose(np.diff(me["time"]), h)
            me = me[::EULER_SUBSTEPS]
        assert len(me) == len(cs)
        assert np.allclose(me["time"], cs["time"])
        for name in outputs:
            a, b = me[name][:-1].astype(float), cs[name][1:].astype(float)
            scale = max(np.abs(b).max(), 1e-300)
            worst[(solver, name)] = np.abs(a - b).max() / scale
    return worst


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_scene_model_exchange_matches_co_simulation(path):
    scene = scenes.load_scene(path, fast=True)
    step, stop = scene["step"], scene["stop_time"]
    n = int(round(stop / step))
    t = np.linspace(0.0, n * step, n + 1)
    sweep = scene.get("sweep")
    first_and_last = [0, len(sweep["values"]) - 1] if sweep else None
    for _, value, parameters, inputs in scenes.sweep_runs(scene, first_and_last):
        signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in inputs])
        signals["time"] = t
        for name, signal in inputs.items():
            signals[name] = scenes.signal_values(signal, t, stop, scene["_dir"])
        outputs = [o for o in scene["outputs"] if o not in inputs]
        worst = compare(scene["fmu"], parameters, signals, outputs, step, n * step)
        bad = {k: v for k, v in worst.items() if not v <= TOLERANCE}
        assert not bad, f"{path.stem} {value}: {bad}"


def test_exact_wall_model_exchange_matches_co_simulation():
    # The exact wall with friction and a connector, through contact and free inflation.
    step, stop = 0.01, 2.0
    t = np.arange(0.0, stop + step / 2, step)
    signals = np.zeros(t.size, dtype=[("time", float), ("pressure", float), ("length", float)])
    signals["time"] = t
    signals["pressure"] = 3.5e5 + 3.4e5 * np.sin(2 * np.pi * t)
    signals["length"] = 0.085 + 0.01 * np.sin(3 * np.pi * t)
    worst = compare(
        "McKibbenMuscle",
        dict(preset=1, bladder_model=3, bladder_layers=16, friction=True, connector_stiffness=5e4),
        signals,
        ["force", "effective_pressure", "stress_hoop", "friction_force"],
        step,
        stop,
    )
    assert max(worst.values()) <= TOLERANCE, worst


def test_joint_model_exchange_matches_co_simulation():
    step, stop = 0.01, 2.0
    t = np.arange(0.0, stop + step / 2, step)
    names = ["actuatorInput", "jointPosition", "jointVelocity"]
    signals = np.zeros(t.size, dtype=[("time", float)] + [(n, float) for n in names])
    signals["time"] = t
    signals["actuatorInput"] = 1e5 * np.sin(2 * np.pi * t)
    signals["jointPosition"] = 0.3 * np.sin(3 * np.pi * t)
    signals["jointVelocity"] = 0.9 * np.pi * np.cos(3 * np.pi * t)
    worst = compare(
        "McKibbenJoint",
        dict(friction=True, bladder_model=1),
        signals,
        ["jointTorque", "flexor_force", "extensor_force"],
        step,
        stop,
    )
    assert max(worst.values()) <= TOLERANCE, worst


STRAND_RUNS = {
    # The joint's muscles alternately slack and on their stretching strands (max_position 1.42 rad,
    # breaking angle 1.79 rad with the defaults), with friction.
    "McKibbenJoint": (dict(friction=True), {
        "actuatorInput": lambda t: 1e5 * np.sin(2 * np.pi * t),
        "jointPosition": lambda t: 1.75 * np.sin(np.pi * t),
        "jointVelocity": lambda t: 1.75 * np.pi * np.cos(np.pi * t),
    }, ["jointTorque", "flexor_force", "extensor_force", "flexor_slack", "extensor_slack"]),
    # The knit through its free contraction (178 mm) and on its stretching yarn (max_length 514 mm,
    # breaking length 540 mm).
    "KnittedMuscle": (dict(friction=True), {
        "pressure": lambda t: 2e4 + 1e4 * np.sin(2 * np.pi * t),
        "length": lambda t: 0.36 + 0.17 * np.sin(np.pi * t),
    }, ["force", "volume", "stiffness", "slack"]),
}


@pytest.mark.parametrize("model", STRAND_RUNS)
def test_model_exchange_matches_co_simulation_slack_and_on_the_strands(model):
    parameters, inputs, outputs = STRAND_RUNS[model]
    step, stop = 0.01, 2.0
    t = np.arange(0.0, stop + step / 2, step)
    signals = np.zeros(t.size, dtype=[("time", float)] + [(n, float) for n in inputs])
    signals["time"] = t
    for name, f in inputs.items():
        signals[name] = f(t)
    worst = compare(model, parameters, signals, outputs, step, stop)
    assert max(worst.values()) <= TOLERANCE, worst


@pytest.mark.parametrize("model,point", [
    ("McKibbenJoint", {"actuatorInput": 1e5, "jointPosition": 1.6}),
    ("McKibbenJoint", {"actuatorInput": 0.0, "jointPosition": 1.75}),  # flexor slack
    ("KnittedMuscle", {"pressure": 2e4, "length": 0.52}),
    ("KnittedMuscle", {"pressure": 2e4, "length": 0.15}),  # slack
])
def test_model_exchange_directional_derivatives_on_the_strands_and_slack(model, point):
    """Model Exchange's directional derivatives are Co-Simulation's, on the strands and slack."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Model, FMU2Slave

    path = fmu_path(model)
    md = read_model_description(path)
    where = extract(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    known = [vr[n] for n in point]
    unknown = [u.variable.valueReference for u in md.outputs if u.variable.type == "Real"]
    results = []
    for cls in (FMU2Slave, FMU2Model):
        fmu = cls(guid=md.guid, unzipDirectory=where, modelIdentifier=model, instanceName="d")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        if cls is FMU2Model:
            fmu.enterContinuousTimeMode()
        fmu.setReal(known, list(point.values()))
        results.append([list(fmu.getDirectionalDerivative(unknown, known, seed))
                        for seed in np.eye(len(known)).tolist()])
        fmu.terminate()
        fmu.freeInstance()
    assert results[0] == results[1]
    assert any(v != 0.0 for row in results[0] for v in row)


@pytest.mark.parametrize("model", SHIPPED)
def test_both_interfaces_validate_clean(model):
    assert validate_fmu(fmu_path(model)) == []
    md = read_model_description(fmu_path(model))
    assert md.coSimulation is not None and md.modelExchange is not None
    states = {"PulleyJoint": 2, "MultiferroicMotor": 4}.get(model, 0)
    indicators = {"MultiferroicMotor": 1}.get(model, 0)
    assert md.numberOfContinuousStates == states and md.numberOfEventIndicators == indicators
    assert not md.modelExchange.completedIntegratorStepNotNeeded


@pytest.mark.parametrize("model", SHIPPED)
def test_every_fmu_serves_both_interfaces(model):
    """Every shipped FMU declares both interfaces under one model identifier, and its binary
    instantiates, initializes and terminates as either (no FMU is Co-Simulation only)."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Model, FMU2Slave

    md = read_model_description(fmu_path(model))
    assert md.modelExchange is not None, f"{model} does not declare Model Exchange"
    assert md.coSimulation is not None, f"{model} does not declare Co-Simulation"
    assert md.modelExchange.modelIdentifier == md.coSimulation.modelIdentifier == model
    where = extract(fmu_path(model))
    for cls in (FMU2Model, FMU2Slave):
        fmu = cls(guid=md.guid, unzipDirectory=where, modelIdentifier=model, instanceName=cls.__name__)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.terminate()
        fmu.freeInstance()


def test_model_exchange_calls_are_checked(recording_log):
    from fmpy import extract
    from ctypes import c_double, c_int, c_void_p

    from fmpy.fmi2 import FMU2Model, FMU2Slave

    path = fmu_path("McKibbenMuscle")
    md = read_model_description(path)
    where = extract(path)
    me = FMU2Model(guid=md.guid, unzipDirectory=where, modelIdentifier="McKibbenMuscle", instanceName="me")
    me.instantiate(callbacks=recording_log.callbacks)
    me.setupExperiment(startTime=0.0)
    me.enterInitializationMode()
    me.exitInitializationMode()
    # No continuous states: a state vector of length 1 is refused with the reason.
    buffer = (c_double * 1)()
    assert me.dll.fmi2GetDerivatives(me.component, buffer, 1) == 3
    assert recording_log.contains("1 derivatives requested, but this model has none")
    # Continuous-time calls need continuous-time mode.
    assert me.dll.fmi2EnterContinuousTimeMode(me.component) == 0
    assert me.dll.fmi2EnterContinuousTimeMode(me.component) == 3
    assert recording_log.contains("fmi2EnterContinuousTimeMode: illegal call in state ContinuousTimeMode")
    me.enterEventMode()
    me.newDiscreteStates()
    me.enterContinuousTimeMode()
    me.setTime(0.5)
    assert me.completedIntegratorStep() == (False, False)
    me.terminate()
    me.freeInstance()
    # Model Exchange functions on a Co-Simulation instance are refused.
    cs = FMU2Slave(guid=md.guid, unzipDirectory=where, modelIdentifier="McKibbenMuscle", instanceName="cs")
    cs.instantiate(callbacks=recording_log.callbacks)
    cs.setupExperiment(startTime=0.0)
    cs.enterInitializationMode()
    cs.exitInitializationMode()
    enter_event_mode = cs.dll.fmi2EnterEventMode  # not bound by FMU2Slave
    enter_event_mode.argtypes, enter_event_mode.restype = [c_void_p], c_int
    assert enter_event_mode(cs.component) == 3
    assert recording_log.contains("instantiated for Co-Simulation")
    cs.terminate()
    cs.freeInstance()


def test_a_co_simulation_state_is_not_restored_into_model_exchange(recording_log):
    from fmpy import extract
    from fmpy.fmi2 import FMU2Model, FMU2Slave

    path = fmu_path("McKibbenMuscle")
    md = read_model_description(path)
    where = extract(path)

    def ready(cls, name):
        fmu = cls(guid=md.guid, unzipDirectory=where, modelIdentifier="McKibbenMuscle", instanceName=name)
        fmu.instantiate(callbacks=recording_log.callbacks)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        return fmu

    cs, me = ready(FMU2Slave, "cs"), ready(FMU2Model, "me")
    cs.doStep(0.0, 1e-3)
    serialized = cs.serializeFMUstate(cs.getFMUstate())
    state = me.deSerializeFMUstate(serialized)
    with pytest.raises(Exception):
        me.setFMUstate(state)
    assert recording_log.contains("saved mid-run in state StepComplete by a Co-Simulation instance; this one is Model Exchange")
    # Its own state round-trips.
    own = me.getFMUstate()
    me.setFMUstate(own)
    for fmu in (cs, me):
        fmu.terminate()
        fmu.freeInstance()


# PulleyJoint: continuous states (joint angle and velocity), time events at the reference's segment
# boundaries. Co-Simulation steps the ODE by semi-implicit Euler, FMPy's Euler by explicit Euler,
# CVode to 1e-10: each agrees with the others to first order in the step h, and the Richardson
# extrapolations 2 x(h/2) - x(h) agree to second order. FMPy holds each input over the output
# interval in all three (CVode's right-hand side does not re-apply inputs), so runs with the
# same h see the same forces. Every PulleyJoint catalogue scene is compared (a load lifted by
# stepped tensions), and sinusoidal forces with external pressures.
PULLEY_OUTPUTS = ["joint_angle", "joint_velocity", "flexor_pressure", "extensor_pressure",
                  "flexor_length", "extensor_length", "reference_angle", "joint_torque"]
PULLEY_STOP = 1.5  # with segment_time 0.5: time events at 0.5 and 1.0 s
PULLEY_INPUTS = ["flexor_force", "extensor_force", "flexor_pressure_command", "extensor_pressure_command"]


def sinusoidal_load(t):
    signals = np.zeros(t.size, dtype=[("time", float)] + [(n, float) for n in PULLEY_INPUTS])
    signals["time"] = t
    signals["flexor_force"], signals["extensor_force"] = 20.0 + 10.0 * np.sin(3.0 * t), 5.0
    signals["flexor_pressure_command"] = 3e5 + 1e5 * np.sin(2 * np.pi * t)
    signals["extensor_pressure_command"] = 3e5
    return signals


def pulley_run(parameters, load, stop, kind, h):
    """Outputs every 10 ms of one run: kind 'CS', or 'CVode' / 'Euler' (Model Exchange), with
    step (and output interval) h; `load(t)` gives the input signals on the run's own time grid.
    Event instants recorded twice by FMPy keep the later row."""
    t = np.arange(0.0, stop + h / 2, h)
    kw = dict(start_values=parameters, input=load(t), output=PULLEY_OUTPUTS, stop_time=stop, output_interval=h)
    if kind == "CS":
        r = simulate_fmu(fmu_path("PulleyJoint"), **kw)
    else:
        r = simulate_fmu(fmu_path("PulleyJoint"), fmi_type="ModelExchange", solver=kind,
                         step_size=h if kind == "Euler" else None, relative_tolerance=1e-10, **kw)
        r = r[np.r_[r["time"][1:] != r["time"][:-1], True]]
    every = int(round(1e-2 / h))
    assert np.allclose(r["time"][::every], np.arange(0.0, stop + 1e-9, 1e-2))
    return r[::every]


def pulley_differences(what, run, a, b, h, jumps=()):
    """Largest differences, relative to each output's largest magnitude, between kinds a and b
    (`run(kind, h)`): at the same step h/2, and between their Richardson extrapolations from h and
    h/2. Rows at the instants `jumps` where an input steps are left out: there FMPy records a
    Co-Simulation output from the input before the jump and a Model Exchange output from the one
    after (the joint torque is algebraic in the forces); the states agree there as elsewhere."""
    runs = {k: (run(k, h), run(k, h / 2)) for k in (a, b)}
    keep = ~np.isclose(runs[a][0]["time"][:, None], np.array([np.nan, *jumps])[None, :]).any(axis=1)
    same, extrapolated = {}, {}
    for name in PULLEY_OUTPUTS:
        (a1, a2), (b1, b2) = ([r[name][keep] for r in pair] for pair in (runs[a], runs[b]))
        scale = max(np.abs(b2).max(), 1e-300)
        same[name] = np.abs(a2 - b2).max() / scale
        extrapolated[name] = np.abs((2 * a2 - a1) - (2 * b2 - b1)).max() / scale
    print(f"{what} {a} vs {b}: same step {max(same.values()):.1e}, "
          f"extrapolated {max(extrapolated.values()):.1e}")
    return same, extrapolated


def step_times(inputs):
    return sorted({t for signal in inputs.values() if signal["type"] == "steps" for t in signal["times"][1:]})


def scene_load(scene, inputs):
    """The scene's input signals on a run's grid t, each step of a `steps` signal as a
    discontinuity (its time twice, the value before and after): FMPy then makes it an input event,
    at which Model Exchange restarts CVode (which otherwise integrates past an output point with
    the old inputs and fails its error test after a jump) and Co-Simulation applies the value after
    it, as the scene's own runs do."""
    jumps = step_times(inputs)

    def load(grid):
        grid = grid[~np.isclose(grid[:, None], np.array([np.nan, *jumps])[None, :]).any(axis=1)]
        t = np.sort(np.r_[grid, jumps, jumps])
        before = np.r_[np.diff(t) == 0, False]  # the first of each pair: the value before the step
        at = np.where(before, np.nextafter(t, -np.inf), t)
        signals = np.zeros(t.size, dtype=[("time", float)] + [(n, float) for n in inputs])
        signals["time"] = t
        for name, signal in inputs.items():
            signals[name] = scenes.signal_values(signal, at, scene["stop_time"], scene["_dir"])
        return signals
    return load


@pytest.mark.parametrize("path", PULLEY_SCENES, ids=lambda p: p.stem)
@pytest.mark.parametrize("solver", ["CVode", "Euler"])
def test_pulley_scene_model_exchange_matches_co_simulation(path, solver):
    # Measured on pulley_lifting_load (fast variant, 2 s): see docs/model-exchange.md, "Continuous states".
    scene = scenes.load_scene(path, fast=True)
    sweep = scene.get("sweep")
    for _, value, parameters, inputs in scenes.sweep_runs(scene, [0, len(sweep["values"]) - 1] if sweep else None):
        load = scene_load(scene, inputs)
        run = lambda kind, h: pulley_run(parameters, load, scene["stop_time"], kind, h)
        same, extrapolated = pulley_differences(f"{path.stem} {value}", run, solver, "CS", 2e-4, step_times(inputs))
        # First order in the step: at 1e-4 s, measured 1.3e-3 (CVode) and 8.8e-4 (Euler), halving
        # with the step. Richardson, second order: measured 2.1e-6 (both; Euler 8.5e-6, 2.1e-6,
        # 5.3e-7 from h = 4e-4, 2e-4, 1e-4 s): the steps' jumps in the acceleration make the
        # constants larger than under smooth forces.
        assert max(same.values()) <= 2e-3, same
        assert max(extrapolated.values()) <= 4e-6, extrapolated


def test_pulley_model_exchange_matches_co_simulation_under_varying_forces():
    # Euler against CS: both hold the forces over each step. Measured 5.6e-4, extrapolated 4.4e-7;
    # CVode against CS at 1 ms, 3.1e-3.
    parameters = {"external_pressures": True, "segment_time": 0.5}
    run = lambda kind, h: pulley_run(parameters, sinusoidal_load, PULLEY_STOP, kind, h)
    same, extrapolated = pulley_differences("sinusoidal forces, external pressures", run, "Euler", "CS", 2e-4)
    assert max(same.values()) <= 1e-3, same
    assert max(extrapolated.values()) <= 2e-6, extrapolated
    # CVode at the catalogue's usual 1 ms output interval: first order in the 1 ms hold.
    cvode, cs = (run(k, 1e-3) for k in ("CVode", "CS"))
    worst = max(np.abs(cvode[n] - cs[n]).max() / max(np.abs(cs[n]).max(), 1e-300) for n in PULLEY_OUTPUTS)
    print(f"CVode vs CS at 1 ms: {worst:.1e}")
    assert worst <= 1e-2


def test_pulley_jacobian_matches_central_differences(recording_log):
    """fmi2GetDirectionalDerivative on a Model Exchange instance: unknowns the outputs and the state
    derivatives, knowns the inputs and the states, against central differences of fmi2GetReal and
    fmi2GetDerivatives after fmi2SetReal / fmi2SetContinuousStates."""
    import ctypes

    from fmpy import extract
    from fmpy.fmi2 import FMU2Model

    path = fmu_path("PulleyJoint")
    md = read_model_description(path)
    assert md.modelExchange.providesDirectionalDerivative
    vr = {v.name: v.valueReference for v in md.modelVariables}
    states = [d.variable.derivative.name for d in md.derivatives]
    assert states == ["joint_angle", "joint_velocity"]
    derivatives = [d.variable.name for d in md.derivatives]
    inputs = ["flexor_force", "extensor_force", "flexor_pressure_command", "extensor_pressure_command"]
    outputs = [o.variable.name for o in md.outputs]
    knowns, unknowns = inputs + states, outputs + derivatives
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="PulleyJoint", instanceName="jac")
    fmu.instantiate(callbacks=recording_log.callbacks)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.newDiscreteStates()
    fmu.enterContinuousTimeMode()

    def ptr(a):
        return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def unknown_values(point):
        fmu.setReal([vr[n] for n in inputs], point[:4])
        fmu.setContinuousStates(ptr(np.array(point[4:])), 2)
        dx = np.zeros(2)
        fmu.getDerivatives(ptr(dx), 2)
        return np.r_[fmu.getReal([vr[n] for n in outputs]), dx]

    checked = 0
    for time, point in [(0.3, [120.0, 45.0, 2e5, 3e5, 0.1, 0.3]), (2.5, [30.0, 80.0, 1e5, 4e5, -0.2, -1.0])]:
        fmu.setTime(time)
        unknown_values(point)
        for j, known in enumerate(knowns):
            seed = [1.0 if k == j else 0.0 for k in range(len(knowns))]
            unknown_values(point)
            exact = fmu.getDirectionalDerivative([vr[n] for n in unknowns], [vr[n] for n in knowns], seed)
            h = 1e-6 * max(abs(point[j]), 1e-2)
            up, down = ([x + (s if k == j else 0.0) for k, x in enumerate(point)] for s in (h, -h))
            central = (unknown_values(up) - unknown_values(down)) / (2 * h)
            for name, e, c in zip(unknowns, exact, central):
                assert abs(e - c) <= 1e-6 * max(abs(e), abs(c), 1.0), f"d {name} / d {known} at t={time}: {e} vs {c}"
                checked += 1
    assert checked == 2 * len(knowns) * len(unknowns)
    fmu.terminate()
    fmu.freeInstance()


def test_pulley_state_calls_are_checked_and_states_survive_fmu_state_round_trips(recording_log):
    import ctypes

    from fmpy import extract
    from fmpy.fmi2 import FMU2Model

    path = fmu_path("PulleyJoint")
    md = read_model_description(path)
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="PulleyJoint", instanceName="states")
    fmu.instantiate(callbacks=recording_log.callbacks)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    info = fmu.newDiscreteStates()
    # The first time event is the end of the first move (segment_time 1 s).
    assert info[4] and info[5] == 1.0
    fmu.enterContinuousTimeMode()
    ptr = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    x = np.array([0.25, -0.5])
    fmu.setContinuousStates(ptr(x), 2)
    got = np.zeros(2)
    fmu.getContinuousStates(ptr(got), 2)
    assert list(got) == [0.25, -0.5]
    nominals = np.zeros(2)
    fmu.getNominalsOfContinuousStates(ptr(nominals), 2)
    assert list(nominals) == [1.0, 1.0]
    # The states are the outputs joint_angle and joint_velocity, and der(joint_angle) reads dq/dt.
    vr = {v.name: v.valueReference for v in md.modelVariables}
    assert fmu.getReal([vr["joint_angle"], vr["joint_velocity"], vr["der(joint_angle)"]]) == [0.25, -0.5, -0.5]
    # Wrong lengths and non-finite states are refused with the reason; the states are kept.
    assert fmu.dll.fmi2GetDerivatives(fmu.component, ptr(np.zeros(3)), 3) == 3
    assert recording_log.contains("3 derivatives requested, but this model has 2")
    assert fmu.dll.fmi2GetEventIndicators(fmu.component, ptr(np.zeros(1)), 1) == 3
    assert recording_log.contains("1 event indicators requested, but this model has none")
    assert fmu.dll.fmi2SetContinuousStates(fmu.component, ptr(np.array([np.nan, 0.0])), 2) == 3
    assert recording_log.contains("fmi2SetContinuousStates: state joint_angle is NaN")
    assert fmu.dll.fmi2SetContinuousStates(fmu.component, None, 2) == 3
    assert recording_log.contains("fmi2SetContinuousStates: x must not be NULL")
    fmu.getContinuousStates(ptr(got), 2)
    assert list(got) == [0.25, -0.5]
    # An FMU state saves the continuous states; serialized and back, too.
    saved = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(saved)
    fmu.setContinuousStates(ptr(np.array([1.0, 2.0])), 2)
    fmu.setFMUstate(saved)
    fmu.getContinuousStates(ptr(got), 2)
    assert list(got) == [0.25, -0.5]
    fmu.setContinuousStates(ptr(np.array([1.0, 2.0])), 2)
    fmu.setFMUstate(fmu.deSerializeFMUstate(serialized))
    fmu.getContinuousStates(ptr(got), 2)
    assert list(got) == [0.25, -0.5]
    fmu.terminate()
    fmu.freeInstance()
