"""Shared helpers for the FMPy suite: the package's FMU paths and `Slave`, and a logger that records."""

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

# The package's helpers, under the names the tests use.
from actuator_fmus.paths import FMU_DIR, ROOT, fmu_path  # noqa: E402,F401
from actuator_fmus.slave import Slave as CheckedSlave  # noqa: E402


class Slave(CheckedSlave):
    """The package's Slave without its range checks: the suite also feeds the FMUs values outside
    their declared ranges to test the FMUs' own refusals (tests/fmpy/test_names.py tests the checks)."""

    check_values = False


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
