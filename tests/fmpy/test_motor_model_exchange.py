"""MultiferroicMotor: exact directional derivatives through FMPy against central differences of the
FMU's own outputs (Co-Simulation: outputs by inputs, the quasi-static onion settled for the present
inputs from its stored branch)."""

import math

import pytest

from conftest import Slave

OUTPUTS = [
    "torque",
    "onion_angle",
    "offset_angle",
    "magnetostatic_energy",
    "magnetoelastic_energy",
    "applied_strain_direction",
    "rotor_angle",
    "rotor_speed",
]

# (parameters, inputs before the point, point inputs, the inputs to differentiate by and their steps)
CASES = {
    "locked, tension at -45 deg": (
        dict(rotor_locked=True),
        dict(strain_direction=-math.pi / 4, stress=150e6, load_torque=0.0),
        dict(strain_direction=-math.pi / 4, stress=200e6, load_torque=0.0),
        {"strain_direction": 1e-6, "stress": 1e2, "load_torque": 1e-24},
    ),
    "free rotor mid-turn under load": (
        dict(),
        dict(strain_direction=-math.pi / 4, stress=200e6, load_torque=-5e-19),
        dict(strain_direction=-0.6, stress=250e6, load_torque=-5e-19),
        {"strain_direction": 1e-6, "stress": 1e2, "load_torque": 1e-24},
    ),
    "strain drive": (
        dict(strain_drive=True, rotor_locked=True),
        dict(strain_direction=-math.pi / 4, strain=5e-4),
        dict(strain_direction=-0.7, strain=1e-3),
        {"strain": 1e-9, "stress": 1e2, "strain_direction": 1e-6},
    ),
    "schedule (direction and stress are not inputs)": (
        dict(schedule=1, step_period=1e-4, stress_amplitude=200e6),
        dict(load_torque=2e-19),
        dict(load_torque=2e-19, strain_direction=0.3, stress=1e6),
        {"strain_direction": 1e-6, "stress": 1e2, "load_torque": 1e-24},
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_motor_partials_match_central_differences(case):
    parameters, before, point, steps = CASES[case]
    s = Slave("MultiferroicMotor", **parameters)
    assert s.md.coSimulation.providesDirectionalDerivative
    try:
        s.step(h=3e-6, **before)
        vr = lambda names: [s.vars[n].valueReference for n in names]
        for name, h in steps.items():
            s.set(**point)
            exact = list(s.fmu.getDirectionalDerivative(vr(OUTPUTS), vr([name]), [1.0]))
            up = s.at(*OUTPUTS, **{**point, name: point.get(name, 0.0) + h})
            down = s.at(*OUTPUTS, **{**point, name: point.get(name, 0.0) - h})
            for out, e, a, b in zip(OUTPUTS, exact, up, down):
                central = (a - b) / (2 * h)
                scale = max(abs(e), abs(central))
                floor = 1e-9 * max(abs(x) for x in exact + [central]) + 1e-300
                assert abs(e - central) <= 2e-5 * scale + floor, (case, out, name, e, central)
    finally:
        s.close()


def test_motor_torque_sensitivity_is_nonzero_where_the_physics_says():
    # Locked rotor at -45 degrees: more stress pulls the onion further and raises the torque
    # (below the peak, Fig. 3.3a); the load torque does not enter the torque output.
    s = Slave("MultiferroicMotor", rotor_locked=True)
    try:
        s.set(strain_direction=-math.pi / 4, stress=100e6)
        vr = lambda names: [s.vars[n].valueReference for n in names]
        (d_stress,) = s.fmu.getDirectionalDerivative(vr(["torque"]), vr(["stress"]), [1.0])
        assert d_stress > 0
        (d_load,) = s.fmu.getDirectionalDerivative(vr(["torque"]), vr(["load_torque"]), [1.0])
        assert d_load == 0.0
    finally:
        s.close()


# --- Model Exchange against Co-Simulation on the motor's catalogue scenes --------------------------

import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from fmpy import read_model_description, simulate_fmu  # noqa: E402

from conftest import fmu_path  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
from actuator_fmus import scene as scenes  # noqa: E402

MOTOR_SCENES = [p for p in sorted((ROOT / "scenes").glob("*.json")) if scenes.load_scene(p)["fmu"] == "MultiferroicMotor"]
ANGLE_TOLERANCE = np.radians(0.1)
# Explicit Euler is stable below twice the rotor's inertial time I/c (2.2 ns for Table 3.1): 2 ns
# steps (FMPy's Euler steps at each output point, so the output interval is the step).
EULER_STEP = 2e-9
# That is 50 000 steps per 100 us period under FMPy's Python loop (about 5 s here): Euler runs the
# scheduled scene's first two periods, CVode all of it.
EULER_PERIODS = 2


def at(result, times, name):
    """The value at each time: the last sample at or before it (events record two samples)."""
    idx = np.searchsorted(result["time"], np.asarray(times) * (1 + 1e-12), side="right") - 1
    return result[name][idx]


def scene_signals(scene, stop):
    step = scene["step"]
    n = int(round(stop / step))
    t = np.linspace(0.0, n * step, n + 1)
    inputs = scene.get("inputs", {})
    if not inputs:
        return None, t
    signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in inputs])
    signals["time"] = t
    for name, signal in inputs.items():
        signals[name] = scenes.signal_values(signal, t, scene["stop_time"], scene["_dir"])
    return signals, t


def test_the_motor_serves_model_exchange_with_states_and_an_event_indicator():
    md = read_model_description(fmu_path("MultiferroicMotor"))
    assert md.modelExchange is not None and md.modelExchange.providesDirectionalDerivative
    assert md.numberOfContinuousStates == 4
    assert md.numberOfEventIndicators == 1


@pytest.mark.parametrize("path", MOTOR_SCENES, ids=lambda p: p.stem)
def test_motor_scene_model_exchange_matches_co_simulation(path):
    scene = scenes.load_scene(path, fast=True)
    parameters = scene.get("parameters", {})
    scheduled = parameters.get("schedule", 0) == 1
    period = parameters.get("step_period", 1e-4)
    outputs = [o for o in scene["outputs"] if o not in scene.get("inputs", {})]
    outputs = sorted(set(outputs) | {"rotor_angle", "offset_angle", "torque"})
    for solver, h, stop in [
        ("CVode", None, scene["stop_time"]),
        ("Euler", EULER_STEP if scheduled else scene["step"] / 4, EULER_PERIODS * period if scheduled else scene["stop_time"]),
    ]:
        signals, t = scene_signals(scene, stop)
        kw = dict(start_values=parameters, input=signals, output=outputs, stop_time=t[-1])
        cs = simulate_fmu(fmu_path("MultiferroicMotor"), output_interval=scene["step"], **kw)
        me = simulate_fmu(
            fmu_path("MultiferroicMotor"), fmi_type="ModelExchange", solver=solver, step_size=h, output_interval=h or scene["step"], **kw
        )
        if scheduled:
            # The rotor angle at the end of each period of the schedule.
            ends = np.arange(1, int(round(t[-1] / period)) + 1) * period
            worst = np.abs(at(me, ends, "rotor_angle") - at(cs, ends, "rotor_angle")).max()
            assert worst <= ANGLE_TOLERANCE, (solver, np.degrees(worst))
            assert at(cs, ends, "rotor_angle")[-1] > 0.9 * len(ends) * np.radians(60)
        else:
            # Locked rotor: the outputs are algebraic in the inputs and the onion's branch. FMPy
            # records a Co-Simulation output at t + h from the input at t, a Model Exchange one
            # at t from the input at t.
            for name in outputs:
                a = at(me, t[:-1], name)
                b = cs[name][1:]
                scale = max(np.abs(b).max(), 1e-300)
                assert np.abs(a - b).max() <= 1e-9 * scale, (solver, name, np.abs(a - b).max() / scale)


@pytest.mark.parametrize("parameters", [dict(), dict(onion_model=1), dict(schedule=1)], ids=["quasi-static", "gilbert", "schedule"])
def test_motor_model_exchange_jacobian_matches_central_differences(parameters):
    """fmi2GetDirectionalDerivative in Model Exchange: the state derivatives and outputs by the
    states and the inputs, against central differences of fmi2GetDerivatives and fmi2GetReal."""
    from ctypes import c_double

    from fmpy import extract
    from fmpy.fmi2 import FMU2Model

    path = fmu_path("MultiferroicMotor")
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables if v.type == "Real"}
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="MultiferroicMotor", instanceName="me")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for name, value in parameters.items():
        fmu.setInteger([next(v.valueReference for v in md.modelVariables if v.name == name)], [value])
    fmu.setReal([vr["strain_direction"], vr["stress"], vr["load_torque"]], [-0.6, 2.2e8, -3e-19])
    fmu.exitInitializationMode()
    fmu.newDiscreteStates()
    fmu.enterContinuousTimeMode()
    fmu.setTime(2e-6)
    onion = 0.5 if parameters.get("onion_model") else 0.0
    x0 = [0.2, 1.5e3, onion, 1e-3 if parameters.get("onion_model") else 0.0]
    states = ["rotor_angle", "rotor_speed", "onion_state_angle", "onion_tilt"]
    derivatives = [f"der({s})" for s in states]
    outputs = ["torque", "onion_angle", "offset_angle", "magnetostatic_energy", "magnetoelastic_energy"]
    inputs = {"strain_direction": -0.6, "stress": 2.2e8, "load_torque": -3e-19}
    steps = {"rotor_angle": 1e-6, "rotor_speed": 1e-1, "onion_state_angle": 1e-6, "onion_tilt": 1e-7,
             "strain_direction": 1e-6, "stress": 1e2, "load_torque": 1e-24}

    def values(x, u):
        fmu.setContinuousStates((c_double * 4)(*x), 4)
        fmu.setReal([vr[k] for k in u], list(u.values()))
        dx = (c_double * 4)()
        fmu.getDerivatives(dx, 4)
        return list(dx) + list(fmu.getReal([vr[o] for o in outputs]))

    try:
        for known, h in steps.items():
            values(x0, inputs)
            exact = list(fmu.getDirectionalDerivative([vr[n] for n in derivatives + outputs], [vr[known]], [1.0]))
            if known in states:
                k = states.index(known)
                up = values([xi + (h if i == k else 0) for i, xi in enumerate(x0)], inputs)
                down = values([xi - (h if i == k else 0) for i, xi in enumerate(x0)], inputs)
            else:
                up = values(x0, {**inputs, known: inputs[known] + h})
                down = values(x0, {**inputs, known: inputs[known] - h})
            for name, e, a, b in zip(derivatives + outputs, exact, up, down):
                central = (a - b) / (2 * h)
                scale = max(abs(e), abs(central))
                floor = 1e-7 * max(abs(v) for v in exact) + 1e-300
                assert abs(e - central) <= 2e-5 * scale + floor, (parameters, name, known, e, central)
    finally:
        fmu.terminate()
        fmu.freeInstance()


# --- Model Exchange under FMPy's defaults (no solver options), against Co-Simulation ------------

# Every configuration a user may start from, at the FMU's default experiment (1.2 ms, output every
# 2 us): the Gilbert onion rings for some nanoseconds after every jump of its drive, which CVode
# resolved in more steps than FMPy allows between two output points until the FMU announced its
# ringing windows as time events (Motor::me_ringing).
DEFAULT_RUNS = {
    "quasi-static, schedule": dict(schedule=1),
    "quasi-static, schedule 25 us": dict(schedule=1, step_period=25e-6),
    "quasi-static, tension at -40 deg": dict(stress=2e8, strain_direction=-0.7),
    "Gilbert, schedule": dict(onion_model=1, schedule=1),
    "Gilbert, schedule 25 us": dict(onion_model=1, schedule=1, step_period=25e-6),
    "Gilbert, schedule under load": dict(onion_model=1, schedule=1, load_torque=5e-19),
    "Gilbert, schedule, alpha 0.01": dict(onion_model=1, schedule=1, gilbert_damping=0.01),
    "Gilbert, tension at -40 deg": dict(onion_model=1, stress=2e8, strain_direction=-0.7),
    "Gilbert, onion 1 rad off": dict(onion_model=1, initial_onion_offset=1.0),
    # The onion's rate floored (Motor::me_llg_rate); with a light bar, to a tenth of the rotor's
    # floored inertial time (at the plain 0.1 ns floor this run exceeds CVode's step budget).
    "Gilbert, schedule at 5e8 Pa": dict(onion_model=1, schedule=1, stress_amplitude=5e8),
    "Gilbert, schedule, a light bar": dict(onion_model=1, schedule=1, density=1000.0),
}
# The largest rotor-angle difference allowed at any output point (rad): the transients after the
# switches differ by up to 2e-4 rad between CVode at its default tolerance and Co-Simulation.
DEFAULT_RUN_TOLERANCE = 1e-3


@pytest.mark.parametrize("case", DEFAULT_RUNS)
def test_motor_model_exchange_runs_under_fmpy_defaults(case):
    parameters = DEFAULT_RUNS[case]
    path = fmu_path("MultiferroicMotor")
    me = simulate_fmu(path, fmi_type="ModelExchange", start_values=parameters, output=["rotor_angle"])
    cs = simulate_fmu(path, start_values=parameters, output=["rotor_angle"], output_interval=1e-6)
    stop = read_model_description(path).defaultExperiment.stopTime
    assert me["time"][-1] == pytest.approx(float(stop), rel=1e-12)
    idx = np.clip(np.searchsorted(cs["time"], me["time"] - 1e-12), 0, len(cs) - 1)
    common = np.abs(cs["time"][idx] - me["time"]) < 1e-12
    assert common.sum() >= 500
    worst = np.abs(me["rotor_angle"][common] - cs["rotor_angle"][idx[common]]).max()
    assert worst <= DEFAULT_RUN_TOLERANCE, (case, worst)
    if parameters.get("schedule"):
        # It steps: 60 degrees per period.
        periods = 1.2e-3 / parameters.get("step_period", 1e-4)
        assert me["rotor_angle"][-1] > 0.9 * periods * np.radians(60)


def test_motor_model_exchange_below_the_default_bdf_damping_says_why(recording_log):
    """Below gilbert_damping 0.005 FMPy's default CVode (BDF up to order 5) cannot follow the
    Gilbert onion's precession: the FMU says why at its first event, before the solver stops.
    (`recording_log` puts FMPy's process-global logger back afterwards: the callbacks
    simulate_fmu builds for `logger` do not outlive it.)"""
    messages = []

    def logger(_env, _name, _status, _category, message):
        messages.append(message.decode())

    path = fmu_path("MultiferroicMotor")
    parameters = dict(onion_model=1, schedule=1, gilbert_damping=0.002)
    try:
        simulate_fmu(path, fmi_type="ModelExchange", start_values=parameters, logger=logger)
    except Exception:
        pass  # CVode's own failure, after the warning
    assert any("gilbert_damping = 0.002 is below 0.005" in m for m in messages), messages
    assert any("limit the solver's order to 2" in m for m in messages)


@pytest.mark.parametrize("onion", [0, 1])
def test_motor_model_exchange_refuses_a_schedule_below_its_shortest_period(onion, recording_log):
    """Below step_period 1e-7 s every switch is a time event that restarts the importer's
    integrator (0.9 to 7 ms each through FMPy): Model Exchange refuses at its first event with the
    parameter and the limit named. At the limit it runs, fmi2OK throughout."""
    messages, statuses = [], []

    def logger(_env, _name, _status, _category, message):
        messages.append(message.decode())

    def calls(message):
        if message.rpartition(" -> ")[2] in ("WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"):
            statuses.append(message[:160])

    path = fmu_path("MultiferroicMotor")
    with pytest.raises(Exception):
        simulate_fmu(path, fmi_type="ModelExchange", stop_time=1e-7,
                     start_values=dict(onion_model=onion, schedule=1, step_period=1e-9),
                     logger=logger)
    assert any("step_period = 1e-9 s is below 1e-7 s" in m for m in messages), messages
    me = simulate_fmu(path, fmi_type="ModelExchange", stop_time=2e-6, output=["rotor_angle"],
                      start_values=dict(onion_model=onion, schedule=1, step_period=1e-7), fmi_call_logger=calls)
    assert me["time"][-1] == pytest.approx(2e-6, rel=1e-12)
    assert statuses == []
    assert np.isfinite(me["rotor_angle"]).all()
