"""Two more masters, pinned in requirements.txt: libcosim (libcosimpy) and ecos (ecospy; Debian's
libtbb12) run every FMU at its start values for STEPS steps of its default step size; every Real output matches FMPy driven at the same communication points (libcosim
keeps time in whole nanoseconds, ecos adds step sizes up: compare at matched times)."""

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from conftest import FMU_DIR, ROOT

FMUS = sorted(p.stem for p in FMU_DIR.glob("*.fmu"))
STEPS = 50
RTOL = 1e-12


def inputs(model):
    """Non-trivial constant inputs: the middle row of the FMU's cross-check input."""
    path = ROOT / "crosscheck" / model / f"{model}_in.csv"
    if not path.is_file():
        return {}
    data = np.genfromtxt(path, delimiter=",", names=True)
    row = data[len(data) // 2]
    return {name: float(row[name]) for name in data.dtype.names[1:]}


def outputs(model):
    md = read_model_description(str(FMU_DIR / f"{model}.fmu"))
    return md, [v for v in md.modelVariables if v.type == "Real" and v.causality == "output"]


def fmpy_run(model, times):
    """FMPy stepping through the communication points `times`; the outputs after each step."""
    md, outs = outputs(model)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(FMU_DIR / f"{model}.fmu")),
                    modelIdentifier=model, instanceName="fmpy")
    fmu.instantiate()
    fmu.setupExperiment(startTime=times[0])
    fmu.enterInitializationMode()
    by_name = {v.name: v.valueReference for v in md.modelVariables}
    for name, value in inputs(model).items():
        fmu.setReal([by_name[name]], [value])
    fmu.exitInitializationMode()
    rows = []
    for t0, t1 in zip(times[:-1], times[1:]):
        fmu.doStep(t0, t1 - t0)
        rows.append(fmu.getReal([v.valueReference for v in outs]))
    fmu.terminate()
    fmu.freeInstance()
    return np.array(rows)


def step_of(model):
    md, _ = outputs(model)
    return md.defaultExperiment.stepSize and float(md.defaultExperiment.stepSize)


@pytest.mark.parametrize("model", FMUS)
def test_libcosim_matches_fmpy(model):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    _, outs = outputs(model)
    step_ns = int(round(step_of(model) * 1e9))
    execution = CosimExecution.from_step_size(step_ns)
    index = execution.add_local_slave(CosimLocalSlave(str(FMU_DIR / f"{model}.fmu"), "m"))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    by_name = {v.name: v.valueReference for v in outputs(model)[0].modelVariables}
    for name, value in inputs(model).items():
        assert execution.real_initial_value(index, by_name[name], value)
    rows = []
    for _ in range(STEPS):
        assert execution.step()
        rows.append(observer.last_real_values(index, [v.valueReference for v in outs]))
    times = [k * step_ns * 1e-9 for k in range(STEPS + 1)]
    assert np.any(np.array(rows) != 0)
    np.testing.assert_allclose(np.array(rows), fmpy_run(model, times), rtol=RTOL, atol=0)


@pytest.mark.parametrize("model", FMUS)
def test_ecos_matches_fmpy(model):
    from ecospy.EcosSimulation import EcosSimulation
    from ecospy.EcosSimulationStructure import EcosSimulationStructure

    _, outs = outputs(model)
    h = step_of(model)
    structure = EcosSimulationStructure()
    structure.add_model("m", str(FMU_DIR / f"{model}.fmu"))
    rows, times = [], [0.0]
    with EcosSimulation(structure=structure, step_size=h) as sim:
        sim.init()
        for name, value in inputs(model).items():
            sim.set_real(f"m::{name}", value)
        for _ in range(STEPS):
            times.append(sim.step())
            rows.append([sim.get_real(f"m::{v.name}") for v in outs])
        sim.terminate()
    assert np.any(np.array(rows) != 0)
    np.testing.assert_allclose(np.array(rows), fmpy_run(model, times), rtol=RTOL, atol=0)

