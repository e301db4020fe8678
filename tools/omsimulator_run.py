"""Runs FMUs in OMSimulator through its Python API, at OMSimulator's default settings, and prints
one JSON line per run. Started by tests/fmpy/test_omsimulator.py with OMSimulator's Python package
on PYTHONPATH; reads the runs as a JSON list on stdin, each
{"fmu": path, "kind": "cs" | "me", "parameters": {name: value}, "stop": s, "outputs": [names]}
(a JSON bool sets a Boolean, an int an Integer, a float a Real; a refused value stops the run). Prints for each
{"status": [initialize, simulate], "outputs": {name: value at the end}, "seconds": wall time}."""

import json
import sys
import tempfile
import time

from OMSimulator.capi import Capi as oms

SETTERS = {bool: oms.setBoolean, int: oms.setInteger, float: oms.setReal}


def run(index, fmu, kind, parameters, stop, outputs, results):
    model = f"run{index}"
    oms.newModel(model)
    # oms_system_wc (1): Co-Simulation FMUs; oms_system_sc (2): Model Exchange FMUs, CVode.
    oms.addSystem(f"{model}.root", 2 if kind == "me" else 1)
    oms.addSubModel(f"{model}.root.fmu", fmu)
    oms.setResultFile(model, f"{results}/{model}.csv")
    oms.setStopTime(model, stop)
    prefix = f"{model}.root.fmu."
    oms.instantiate(model)
    for name, value in parameters.items():
        # A setter of the wrong type (an int for a Real) returns an error status and leaves the
        # start value in place: stop rather than run the wrong scene.
        status = SETTERS[type(value)](prefix + name, value)
        if status.value != 0:
            raise ValueError(f"OMSimulator refused {name} = {value!r} ({type(value).__name__}): status {status}")
    status = [oms.initialize(model).value]
    start = time.perf_counter()
    if status[0] == 0:
        status.append(oms.simulate(model).value)
    seconds = time.perf_counter() - start
    values = {name: oms.getReal(prefix + name)[0] for name in outputs}
    oms.terminate(model)
    oms.delete(model)
    return {"status": status, "outputs": values, "seconds": seconds}


def main():
    runs = json.load(sys.stdin)
    with tempfile.TemporaryDirectory() as results:
        oms.setTempDirectory(results)
        for i, r in enumerate(runs):
            out = run(i, r["fmu"], r["kind"], r.get("parameters", {}), r["stop"], r["outputs"], results)
            print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
