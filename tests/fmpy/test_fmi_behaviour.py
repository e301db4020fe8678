"""The FMI 2.0 contract under FMPy: GUID and call-order checks with logged reasons, FMU states,
repeated load/unload, and instances in threads."""

import os
import threading

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from conftest import RecordingLog, fmu_path

FMU = fmu_path("McKibbenMuscle")
MD = read_model_description(FMU)
VR = {v.name: v.valueReference for v in MD.modelVariables}
UNZIPPED = extract(FMU)


def slave(guid=MD.guid, name="muscle"):
    return FMU2Slave(guid=guid, unzipDirectory=UNZIPPED, modelIdentifier="McKibbenMuscle", instanceName=name)


def started(log=None):
    fmu = slave()
    fmu.instantiate(callbacks=log.callbacks if log else None)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu


def test_wrong_guid_is_refused_with_a_logged_reason(recording_log):
    fmu = slave(guid="{01234567-89ab-cdef-0123-456789abcdef}")
    with pytest.raises(Exception, match="Failed to instantiate"):
        fmu.instantiate(callbacks=recording_log.callbacks)
    assert recording_log.records[0][:2] == (3, "logStatusError")
    assert "wrong GUID {01234567-89ab-cdef-0123-456789abcdef}" in recording_log.records[0][2]
    assert MD.guid in recording_log.records[0][2], "the message names the GUID the binary expects"
    fmu.freeLibrary()


def test_illegal_call_order_is_refused_with_a_logged_reason(recording_log):
    fmu = slave()
    fmu.instantiate(callbacks=recording_log.callbacks)
    with pytest.raises(FMICallException, match="fmi2DoStep failed with status 3"):
        fmu.doStep(0.0, 0.1)
    assert recording_log.contains("fmi2DoStep: illegal call in state Instantiated")
    with pytest.raises(FMICallException):
        fmu.exitInitializationMode()
    assert recording_log.contains("fmi2ExitInitializationMode: illegal call in state Instantiated")
    # The refused calls changed nothing: the normal sequence still works.
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.doStep(0.0, 0.1)
    fmu.terminate()
    fmu.freeInstance()


def test_percent_signs_reach_fmpy_as_written(recording_log):
    # FMPy's logger proxy formats the message: the FMU must escape '%' so that it prints as '%'.
    fmu = slave(guid="{100%-sure-%s}")
    with pytest.raises(Exception):
        fmu.instantiate(callbacks=recording_log.callbacks)
    assert "{100%-sure-%s}" in recording_log.records[0][2]
    fmu.freeLibrary()


def test_nan_input_is_refused_and_the_old_value_kept(recording_log):
    fmu = started(recording_log)
    fmu.setReal([VR["pressure"]], [2e5])
    with pytest.raises(FMICallException):
        fmu.setReal([VR["pressure"]], [float("nan")])
    assert fmu.getReal([VR["pressure"]]) == [2e5]
    assert recording_log.contains("pressure = NaN is not finite; the value is kept")
    fmu.freeInstance()


def trajectory(fmu, steps=50, t0=0.0):
    out = []
    for k in range(steps):
        t = t0 + k * 0.01
        fmu.setReal([VR["pressure"], VR["length"]], [3e5 + 1e3 * k, 0.08 + 0.02 * np.sin(0.1 * k)])
        fmu.doStep(t, 0.01)
        out.append(fmu.getReal([VR["force"], VR["volume"]]))
    return np.array(out)


def test_fmu_state_get_step_set_step_is_identical():
    fmu = started()
    trajectory(fmu, steps=10)
    state = fmu.getFMUstate()
    first = trajectory(fmu, t0=0.1)
    fmu.setFMUstate(state)
    again = trajectory(fmu, t0=0.1)
    assert np.array_equal(first, again)

    serialized = fmu.serializeFMUstate(state)
    assert serialized[:8] == b"AFMUSTAT", "versioned format: magic, then the format version"
    restored = fmu.deSerializeFMUstate(serialized)
    fmu.setFMUstate(restored)
    assert np.array_equal(trajectory(fmu, t0=0.1), first)
    fmu.freeFMUstate(state)
    fmu.freeFMUstate(restored)
    fmu.terminate()
    fmu.freeInstance()


# Under valgrind (`make memcheck`) each load reads the library's debug information: a few
# cycles there, the full 2,000 in `make test`.
LOAD_CYCLES = int(os.environ.get("FMI_BEHAVIOUR_LOAD_CYCLES", "2000"))


def test_two_thousand_load_simulate_unload_cycles():
    for cycle in range(LOAD_CYCLES):
        fmu = slave(name=f"cycle{cycle}")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.setReal([VR["pressure"], VR["length"]], [4e5, 0.1])
        fmu.doStep(0.0, 0.01)
        fmu.doStep(0.01, 0.01)
        assert fmu.getReal([VR["force"]])[0] > 0
        fmu.terminate()
        fmu.freeInstance()  # frees the instance and unloads the library


def test_four_instances_in_four_threads_match_serial_runs():
    def run(k, results):
        fmu = started()
        results[k] = trajectory(fmu, steps=400)
        fmu.terminate()
        fmu.fmi2FreeInstance(fmu.component)  # keep the library loaded while other threads use it

    serial = {}
    for k in range(4):
        run(k, serial)
    threaded = {}
    threads = [threading.Thread(target=run, args=(k, threaded)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for k in range(4):
        assert np.array_equal(serial[k], threaded[k])


def test_threads_that_outlive_the_unloaded_library_exit_cleanly():
    # rust-lang/rust#91979: a thread that ran the FMU's code and exits after dlclose must not
    # jump into unmapped thread-local destructors (the binary is linked with -z nodelete).
    def worker(k):
        fmu = slave(name=f"thread{k}")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        trajectory(fmu, steps=20)
        fmu.terminate()
        fmu.freeInstance()  # dlclose while this thread is still alive

    for round_ in range(25):
        threads = [threading.Thread(target=worker, args=(4 * round_ + k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
