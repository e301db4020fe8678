"""A strict master, as OMSimulator is: any status other than fmi2OK from any FMI call fails the run.
Every scene (fast variant) and every FMU's cross-check input run through it under the default
out-of-range policy; FMPy's call logger sees the status of every call."""

import fmpy
import numpy as np
import pytest
from fmpy.cross_check.validate_vendor_repo import read_csv
from fmpy.util import read_ref_opt_file

from conftest import FMU_DIR, ROOT, Slave

from actuator_fmus import scene as scenes  # noqa: E402

SCENES = sorted((ROOT / "scenes").glob("*.json"))
CROSSCHECK = ROOT / "crosscheck"
STATUSES = ("OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING")


class StrictCalls:
    """FMPy's call logger: counts the calls and keeps every one whose status is not fmi2OK."""

    def __init__(self):
        self.calls = 0
        self.failures = []

    def __call__(self, message):
        head, _, status = message.rpartition(" -> ")
        if status in STATUSES:
            self.calls += 1
            if status != "OK":
                self.failures.append(message[:300])


@pytest.fixture
def strict(monkeypatch):
    calls = StrictCalls()
    simulate = fmpy.simulate_fmu

    def strict_simulate(*args, **kwargs):
        return simulate(*args, fmi_call_logger=calls, **kwargs)

    monkeypatch.setattr(fmpy, "simulate_fmu", strict_simulate)
    yield calls
    assert calls.calls > 0, "the call logger saw no FMI call"
    assert calls.failures == [], f"{len(calls.failures)} calls did not return fmi2OK: {calls.failures[:3]}"


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_scene_under_a_strict_master(path, strict):
    runs = scenes.run_scene(scenes.load_scene(path, fast=True), progress=False)
    assert all(np.isfinite(r[n]).all() for _, r in runs for n in r.dtype.names)


@pytest.mark.parametrize("model", sorted(p.name for p in CROSSCHECK.iterdir() if p.is_dir()))
def test_crosscheck_input_under_a_strict_master(model, strict):
    d = CROSSCHECK / model
    opt = read_ref_opt_file(str(d / f"{model}_ref.opt"))
    inputs = read_csv(str(d / f"{model}_in.csv")) if (d / f"{model}_in.csv").is_file() else None
    fmpy.simulate_fmu(str(FMU_DIR / f"{model}.fmu"), start_time=opt["StartTime"], stop_time=opt["StopTime"],
                      output_interval=opt["StepSize"], input=inputs)


# The case: the thin-walled bladder at a length past where it fills the sleeve (97.3 mm) and past
# 5% strand strain beyond it (102.9 mm), which no muscle survives.
PAST_THE_SLEEVE = dict(bladder_model=1)


def test_clamped_input_is_ok_flagged_and_logged_once_per_excursion(recording_log):
    m = Slave("McKibbenMuscle", log=recording_log, **PAST_THE_SLEEVE)
    calls = StrictCalls()
    m.fmu.fmiCallLogger = calls
    assert not m.at("input_clamped", pressure=2e5, length=0.09)
    flags = []
    for length in [0.11, 0.12, 0.09, 0.11, 0.11]:
        m.step(pressure=2e5, length=length)
        clamped, force = m.get("input_clamped", "force")
        flags.append(bool(clamped))
        assert np.isfinite(force)
    m.close()
    assert flags == [True, True, False, True, True]
    assert calls.calls > 10 and calls.failures == []
    # Two excursions, two explanations, each at fmi2OK.
    notes = [r for r in recording_log.records if "until the inputs return" in r[2]]
    assert len(notes) == 2, notes
    assert all(status == 0 for status, _, _ in notes)


@pytest.mark.parametrize("policy, status", [(1, 1), (2, 2)])
def test_policy_restores_the_warning_or_asks_for_discard(policy, status):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    path = str(FMU_DIR / "McKibbenMuscle.fmu")
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="McKibbenMuscle")
    seen = []
    fmu.fmiCallLogger = lambda message: seen.append(message.rpartition(" -> ")[2])
    fmu.instantiate()
    fmu.setupExperiment(startTime=0)
    fmu.setInteger([vr["bladder_model"], vr["out_of_range_policy"]], [1, policy])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([vr["pressure"], vr["length"]], [2e5, 0.11])
    if status == 2:
        from fmpy.fmi1 import FMICallException

        with pytest.raises(FMICallException):
            fmu.doStep(currentCommunicationPoint=0, communicationStepSize=1e-3)
        assert seen[-1] == "DISCARD"
    else:
        fmu.doStep(currentCommunicationPoint=0, communicationStepSize=1e-3)
        assert seen[-1] == "WARNING"
        assert fmu.getBoolean([vr["input_clamped"]]) == [True]
    fmu.freeInstance()


def test_a_preset_overriding_user_values_is_noticed_at_fmi2ok(recording_log, strict):
    # Festo DMSP-40 (preset 6) replaces the strand length and c1 the user set: the notice is logged
    # once, at fmi2OK, and a strict master runs on. (recording_log restores FMPy's logger after.)
    records = []

    def logger(_env, _name, status, _category, message):
        records.append((status, message.decode()))

    r = fmpy.simulate_fmu(str(FMU_DIR / "McKibbenMuscle.fmu"), stop_time=0.01, output_interval=0.001,
                          start_values=dict(preset=6, strand_length=0.3, mooney_c1=2e5, length=0.38),
                          logger=logger)
    assert np.isfinite(r["force"]).all()
    notes = [rec for rec in records if "replaces the value you set" in rec[1]]
    assert len(notes) == 1 and notes[0][0] == 0, notes


def option_values():
    """(model, option, value) for every value of every option of every FMU: Booleans, and Integer
    parameters with at most eight values (the out-of-range policy aside: 1 and 2 ask for
    non-OK statuses)."""
    cases = []
    for fmu in sorted(FMU_DIR.glob("*.fmu")):
        md = fmpy.read_model_description(str(fmu))
        for v in md.modelVariables:
            if v.causality != "parameter" or v.name == "out_of_range_policy":
                continue
            if v.type == "Boolean":
                values = [True, False]
            elif v.type in ("Integer", "Enumeration") and v.min is not None and v.max is not None \
                    and int(v.max) - int(v.min) < 8:
                values = list(range(int(v.min), int(v.max) + 1))
            else:
                continue
            cases += [(fmu.stem, v.name, value) for value in values]
    return cases


@pytest.mark.parametrize("model, option, value", option_values(),
                         ids=lambda x: str(x))
def test_every_option_under_a_strict_master(model, option, value, strict):
    """Each option value alone, the rest at their defaults, through the FMU's cross-check input
    (or its default experiment): every call returns fmi2OK."""
    d = CROSSCHECK / model
    opt = read_ref_opt_file(str(d / f"{model}_ref.opt"))
    inputs = read_csv(str(d / f"{model}_in.csv")) if (d / f"{model}_in.csv").is_file() else None
    stop = min(opt["StopTime"], 200 * opt["StepSize"])
    result = fmpy.simulate_fmu(str(FMU_DIR / f"{model}.fmu"), start_time=opt["StartTime"],
                               stop_time=stop, output_interval=opt["StepSize"], input=inputs,
                               start_values={option: value})
    assert all(np.isfinite(result[n]).all() for n in result.dtype.names)
    # Checked here rather than by the fixture, so that an expected failure is the test's own.
    failures = list(strict.failures)
    strict.failures.clear()
    assert failures == [], f"{len(failures)} calls did not return fmi2OK: {failures[:3]}"
