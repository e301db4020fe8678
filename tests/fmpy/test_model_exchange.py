"""Model Exchange against Co-Simulation under FMPy: every catalogue scene of an algebraic FMU
(fast variant; first and last sweep value), with CVode and with Euler at a quarter of the
communication step, plus the McKibbenJoint under a friction cycle. FMPy records a Co-Simulation
output at t + h from the input set at t, and a Model Exchange output at t from the input at t, so
the runs are compared with that one-sample shift. The friction history is committed at every
completed integrator step, so the agreement is exact up to rounding."""

import pathlib
import sys

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from conftest import fmu_path

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scenes"))
import run as scenes  # noqa: E402

MODEL_EXCHANGE = ["FreeBladder", "KnittedMuscle", "McKibbenJoint", "McKibbenMuscle", "PassThrough"]
CO_SIMULATION_ONLY = ["MultiferroicMotor", "PulleyJoint"]
TOLERANCE = 1e-9
SCENES = [
    p for p in sorted((ROOT / "scenes").glob("*.json")) if scenes.load_scene(p)["fmu"] in MODEL_EXCHANGE
]


def compare(model, parameters, signals, outputs, step, stop):
    """Largest difference between ME (CVode; Euler at step/4) and CS, relative to each output's
    largest magnitude, over all outputs."""
    kw = dict(start_values=parameters, input=signals, output=outputs, stop_time=stop, output_interval=step)
    cs = simulate_fmu(fmu_path(model), **kw)
    worst = {}
    for solver, h in [("CVode", None), ("Euler", step / 4)]:
        me = simulate_fmu(fmu_path(model), fmi_type="ModelExchange", solver=solver, step_size=h, **kw)
        assert len(me) == len(cs)
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


def test_every_model_is_in_one_list():
    shipped = sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))
    assert sorted(MODEL_EXCHANGE + CO_SIMULATION_ONLY) == shipped


@pytest.mark.parametrize("model", MODEL_EXCHANGE + CO_SIMULATION_ONLY)
def test_both_interfaces_validate_clean(model):
    assert validate_fmu(fmu_path(model)) == []
    md = read_model_description(fmu_path(model))
    assert md.coSimulation is not None
    assert (md.modelExchange is not None) == (model in MODEL_EXCHANGE)
    if md.modelExchange:
        assert md.numberOfContinuousStates == 0 and md.numberOfEventIndicators == 0
        assert not md.modelExchange.completedIntegratorStepNotNeeded


def test_co_simulation_only_models_refuse_model_exchange():
    from fmpy.fmi2 import FMU2Model
    from fmpy import extract

    md = read_model_description(fmu_path("PulleyJoint"))
    fmu = FMU2Model(
        guid=md.guid,
        unzipDirectory=extract(fmu_path("PulleyJoint")),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="pulley",
    )
    with pytest.raises(Exception, match="Failed to instantiate"):
        fmu.instantiate()
    fmu.freeLibrary()


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
    assert recording_log.contains("saved in state StepComplete, which this Model Exchange instance has not")
    # Its own state round-trips.
    own = me.getFMUstate()
    me.setFMUstate(own)
    for fmu in (cs, me):
        fmu.terminate()
        fmu.freeInstance()
