"""Every FMU in the real OMSimulator, at its default settings, in Co-Simulation and Model Exchange,
against FMPy. Skipped unless OMSimulator is installed: set OMSIMULATOR to its command-line program
(`<prefix>/bin/OMSimulator`; its Python package is found under `<prefix>/lib`), or put it on PATH.
`make omsimulator` runs this file alone; docs/compatibility.md says how to build OMSimulator.

OMSimulator's defaults: Co-Simulation at a fixed 1 ms communication step; Model Exchange with CVode
(BDF up to order 5, relative tolerance 1e-4, absolute tolerance 1e-4 x each state's nominal,
initial step 1e-6 s, minimum step 1e-12 s, maximum step 1e-3 s, stability limit detection).
Any status but OK stops OMSimulator, so every run must return OK throughout."""

import json
import math
import os
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from conftest import ROOT, fmu_path
from test_motor_omsimulator_settings import tolerance

FMUS = ["McKibbenMuscle", "KnittedMuscle", "McKibbenJoint", "PulleyJoint", "MultiferroicMotor", "FreeBladder", "PassThrough"]
STEP = 1e-3  # OMSimulator's default communication step


def _python_package():
    """The directory holding OMSimulator's Python package, or None."""
    program = os.environ.get("OMSIMULATOR") or shutil.which("OMSimulator")
    if not program or not pathlib.Path(program).is_file():
        return None
    prefix = pathlib.Path(program).resolve().parents[1]
    found = sorted(prefix.glob("lib*/**/OMSimulator/capi.py"))
    return found[0].parents[1] if found else None


PACKAGE = _python_package()
pytestmark = pytest.mark.skipif(
    PACKAGE is None, reason="OMSimulator not found: set OMSIMULATOR to <prefix>/bin/OMSimulator (docs/compatibility.md)"
)


def omsimulator(runs, tmp):
    """Runs `runs` (see tools/omsimulator_run.py) in one OMSimulator process, in the directory
    `tmp` (OMSimulator writes there); one result each."""
    env = dict(os.environ, PYTHONPATH=str(PACKAGE))
    done = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "omsimulator_run.py")],
        input=json.dumps(runs), env=env, capture_output=True, text=True, timeout=600, cwd=tmp,
    )
    results = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    assert done.returncode == 0 and len(results) == len(runs), done.stdout[-3000:] + done.stderr[-3000:]
    return results


def real_outputs(md):
    return [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"]


def stop_time(md):
    return float(md.defaultExperiment.stopTime)


@pytest.mark.parametrize("name", FMUS)
def test_every_fmu_runs_in_omsimulator_in_both_interfaces(name, tmp_path):
    """Each FMU, at its default parameters and inputs and its default experiment's stop time:
    OK throughout in both interfaces, every Real output finite; Co-Simulation equals FMPy's at the
    same communication step (the same calls in the same order)."""
    path = fmu_path(name)
    md = read_model_description(path)
    outputs, stop = real_outputs(md), stop_time(md)
    cs, me = omsimulator([dict(fmu=str(path), kind=kind, stop=stop, outputs=outputs) for kind in ("cs", "me")], tmp_path)
    for kind, result in (("cs", cs), ("me", me)):
        assert result["status"] == [0, 0], (kind, result)
        bad = {k: v for k, v in result["outputs"].items() if not math.isfinite(v)}
        assert not bad, (kind, bad)
    reference = simulate_fmu(path, stop_time=stop, output_interval=STEP, output=outputs)
    assert reference["time"][-1] == pytest.approx(stop, rel=1e-12)
    for output in outputs:
        assert cs["outputs"][output] == pytest.approx(float(reference[output][-1]), rel=1e-12, abs=1e-300), output


MOTOR_RUNS = {
    "quasi-static, schedule": dict(schedule=1),
    "Gilbert, schedule": dict(schedule=1, onion_model=1),
    "Gilbert, schedule, alpha 0.01": dict(schedule=1, onion_model=1, gilbert_damping=0.01),
    "Gilbert, schedule under load": dict(schedule=1, onion_model=1, load_torque=5e-19),
    # Bounds of the declared space where Model Exchange floors the rotor's inertial time (or,
    # the thinnest fluid, where the rotor rings longest).
    "quasi-static, schedule, the lightest bar": dict(schedule=1, density=1000.0),
    "Gilbert, schedule, the lightest bar": dict(schedule=1, onion_model=1, density=1000.0),
    "quasi-static, schedule, glycerol": dict(schedule=1, fluid_viscosity=1.4),
    "Gilbert, schedule, the most viscous fluid": dict(schedule=1, onion_model=1, fluid_viscosity=1e9),
    "quasi-static, schedule, the thinnest fluid": dict(schedule=1, fluid_viscosity=5e-6),
    "Gilbert, schedule, the thinnest fluid": dict(schedule=1, onion_model=1, fluid_viscosity=5e-6),
}


def test_the_motor_runs_as_model_exchange_in_omsimulator(tmp_path):
    """The motor on its schedule for 1.2 ms as Model Exchange under OMSimulator's CVode, quasi-static
    and Gilbert onion, at defaults and at bounds of the declared space: OK throughout, the rotor
    angle at the end within the tolerance of
    tests/fmpy/test_motor_omsimulator_settings.py of FMPy's Co-Simulation at 1 us steps."""
    path = fmu_path("MultiferroicMotor")
    stop = stop_time(read_model_description(path))
    runs = [dict(fmu=str(path), kind="me", parameters=p, stop=stop, outputs=["rotor_angle"]) for p in MOTOR_RUNS.values()]
    for case, result in zip(MOTOR_RUNS, omsimulator(runs, tmp_path)):
        assert result["status"] == [0, 0], (case, result)
        cs = simulate_fmu(path, start_values=MOTOR_RUNS[case], output=["rotor_angle"], output_interval=1e-6)
        angle, reference = result["outputs"]["rotor_angle"], cs["rotor_angle"][-1]
        print(f"{case}: rotor_angle {angle!r} rad (FMPy CS {reference!r}) in {result['seconds']:.3f} s")
        assert abs(angle - reference) <= tolerance(np.abs(cs["rotor_angle"]).max()), case


def test_the_gilbert_motor_runs_as_co_simulation_in_omsimulator(tmp_path):
    """The motor on its schedule with the Gilbert onion as Co-Simulation at OMSimulator's 1 ms step:
    OK throughout, the rotor angle at the end that of FMPy's Co-Simulation at 1 us steps."""
    path = fmu_path("MultiferroicMotor")
    parameters = dict(schedule=1, onion_model=1)
    stop = stop_time(read_model_description(path))
    [result] = omsimulator([dict(fmu=str(path), kind="cs", parameters=parameters, stop=stop, outputs=["rotor_angle"])], tmp_path)
    assert result["status"] == [0, 0], result
    cs = simulate_fmu(path, start_values=parameters, output=["rotor_angle"], output_interval=1e-6)
    assert abs(result["outputs"]["rotor_angle"] - cs["rotor_angle"][-1]) <= tolerance(np.abs(cs["rotor_angle"]).max())
