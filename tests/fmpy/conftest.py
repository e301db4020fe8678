"""Shared helpers for the FMPy suite: where the packaged FMUs are, and a logger that records."""

import pathlib
from ctypes import byref

import pytest
from fmpy import calloc, free
from fmpy.fmi2 import (
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.logging import addLoggerProxy

ROOT = pathlib.Path(__file__).resolve().parents[2]
FMU_DIR = ROOT / "target" / "fmu"


def fmu_path(model: str) -> str:
    path = FMU_DIR / f"{model}.fmu"
    assert path.exists(), f"{path} is missing: run `make fmus` first"
    return str(path)


# FMPy's native logger proxy keeps ONE process-global target: whatever callbacks were passed to
# addLoggerProxy last receive every FMU's messages. Callbacks given to it must therefore never be
# garbage-collected, and FMPy's printing logger is put back after each test that records.
_KEEP_ALIVE = []


def _restore_printing_logger():
    from fmpy.fmi1 import printLogMessage

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(printLogMessage)
    addLoggerProxy(byref(callbacks))
    _KEEP_ALIVE.append(callbacks)


class RecordingLog:
    """FMI callbacks whose logger records (status, category, message), formatted by FMPy's proxy
    exactly as FMPy's own logger would see it."""

    def __init__(self):
        self.records = []

        def logger(_env, _name, status, category, message):
            self.records.append((status, category.decode(), message.decode()))

        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(self.callbacks))
        _KEEP_ALIVE.append(self)

    def messages(self):
        return [m for _, _, m in self.records]

    def contains(self, text):
        return any(text in m for m in self.messages())


@pytest.fixture
def recording_log():
    yield RecordingLog()
    _restore_printing_logger()


class Slave:
    """An initialized FMU2Slave addressed by variable names, for point-wise checks: `at(...)` sets
    inputs and reads outputs without a step (outputs follow inputs directly), `step(...)` advances
    history such as friction."""

    def __init__(self, model, log=None, **parameters):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        path = fmu_path(model)
        self.md = read_model_description(path)
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=_extracted(path),
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=model,
        )
        self.fmu.instantiate(callbacks=log.callbacks if log else None)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.set(**parameters)
        self.fmu.exitInitializationMode()
        self.time = 0.0

    def set(self, **values):
        for name, value in values.items():
            v = self.vars[name]
            if v.type == "Real":
                self.fmu.setReal([v.valueReference], [float(value)])
            elif v.type == "Integer":
                self.fmu.setInteger([v.valueReference], [int(value)])
            else:
                self.fmu.setBoolean([v.valueReference], [bool(value)])

    def get(self, *names):
        out = []
        for name in names:
            v = self.vars[name]
            getter = {"Real": self.fmu.getReal, "Integer": self.fmu.getInteger, "Boolean": self.fmu.getBoolean}[v.type]
            out.append(getter([v.valueReference])[0])
        return out[0] if len(out) == 1 else out

    def at(self, *names, **inputs):
        self.set(**inputs)
        return self.get(*names)

    def step(self, h=1e-3, **inputs):
        self.set(**inputs)
        self.fmu.doStep(self.time, h)
        self.time += h

    def close(self):
        self.fmu.terminate()
        self.fmu.fmi2FreeInstance(self.fmu.component)


_EXTRACTED = {}


def _extracted(path):
    from fmpy import extract

    if path not in _EXTRACTED:
        _EXTRACTED[path] = extract(path)
    return _EXTRACTED[path]
