"""The FMI 3.0 C API of the shared library, through ctypes: bad input gets a logged error and never
a crash (the same policy as FMI 2.0, compared call for call on the same library), the declared
dependencies, and directional and adjoint derivatives against central differences."""

import ctypes
import math
import zipfile
from ctypes import POINTER, byref, c_bool, c_char_p, c_double, c_int, c_size_t, c_uint, c_void_p

import numpy as np
import pytest
from fmpy import read_model_description

from actuator_fmus.paths import FMI3_DIR

OK, WARNING, DISCARD, ERROR = 0, 1, 2, 3
LOG = ctypes.CFUNCTYPE(None, c_void_p, c_int, c_char_p, c_char_p)
MODELS = sorted(p.stem for p in FMI3_DIR.glob("*.fmu"))


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    """The x86_64-linux library of the FMI 3.0 McKibbenMuscle FMU (one library serves every model)."""
    out = tmp_path_factory.mktemp("fmi3")
    with zipfile.ZipFile(FMI3_DIR / "McKibbenMuscle.fmu") as z:
        path = z.extract("binaries/x86_64-linux/McKibbenMuscle.so", out)
    dll = ctypes.CDLL(path)
    for name in ["fmi3InstantiateCoSimulation", "fmi3InstantiateModelExchange",
                 "fmi3InstantiateScheduledExecution", "fmi2Instantiate"]:
        getattr(dll, name).restype = c_void_p
    return dll


class Instance:
    """One FMI 3.0 instance of `model` with a recording logger."""

    def __init__(self, lib, model, model_exchange=False, token=None, event_mode_used=False):
        self.lib = lib
        self.md = read_model_description(str(FMI3_DIR / f"{model}.fmu"))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.messages = []
        self.log = LOG(lambda env, status, category, message: self.messages.append((status, message.decode())))
        token = (token or self.md.instantiationToken).encode()
        if model_exchange:
            self.c = lib.fmi3InstantiateModelExchange(b"x", token, None, False, False, None, self.log)
        else:
            self.c = lib.fmi3InstantiateCoSimulation(b"x", token, None, False, False, event_mode_used, False,
                                                     None, c_size_t(0), None, self.log, None)
        self.c = c_void_p(self.c)

    def __call__(self, function, *args):
        return getattr(self.lib, function)(self.c, *args)

    def initialize(self, stop=None):
        assert self("fmi3EnterInitializationMode", False, c_double(0), c_double(0.0), stop is not None,
                    c_double(stop or 0.0)) == OK
        assert self("fmi3ExitInitializationMode") == OK

    def set(self, **values):
        vrs = (c_uint * len(values))(*[self.vr[k] for k in values])
        x = (c_double * len(values))(*values.values())
        return self("fmi3SetFloat64", vrs, c_size_t(len(values)), x, c_size_t(len(values)))

    def get(self, *names):
        vrs = (c_uint * len(names))(*[self.vr[k] for k in names])
        x = (c_double * len(names))()
        status = self("fmi3GetFloat64", vrs, c_size_t(len(names)), x, c_size_t(len(names)))
        return status, list(x)

    def last(self):
        return self.messages[-1][1] if self.messages else ""

    def free(self):
        self.lib.fmi3FreeInstance(self.c)


def test_a_wrong_token_is_refused_with_a_reason(lib):
    inst = Instance(lib, "McKibbenMuscle", token="{00000000-0000-0000-0000-000000000000}")
    assert not inst.c.value
    assert "wrong instantiationToken" in inst.last()


def test_scheduled_execution_is_refused_with_a_reason(lib):
    messages = []
    log = LOG(lambda env, status, category, message: messages.append(message.decode()))
    md = read_model_description(str(FMI3_DIR / "McKibbenMuscle.fmu"))
    c = lib.fmi3InstantiateScheduledExecution(b"x", md.instantiationToken.encode(), None, False, False, None, log,
                                              None, None, None)
    assert not c
    assert "Scheduled Execution is not supported" in messages[-1]


def test_wrong_call_order_null_pointers_and_wrong_types_are_logged_errors(lib):
    inst = Instance(lib, "McKibbenMuscle")
    flags = [c_bool() for _ in range(3)]
    last = c_double()
    # A step before initialization.
    assert inst("fmi3DoStep", c_double(0), c_double(0.1), True, *map(byref, flags), byref(last)) == ERROR
    assert "illegal call" in inst.last()
    inst.initialize()
    # NULL arrays, and more values than value references.
    assert inst("fmi3GetFloat64", None, c_size_t(1), (c_double * 1)(), c_size_t(1)) == ERROR
    assert "must not be NULL" in inst.last()
    assert inst("fmi3GetFloat64", (c_uint * 1)(0), c_size_t(1), (c_double * 2)(), c_size_t(2)) == ERROR
    assert "nValues" in inst.last()
    # NULL outputs of fmi3DoStep.
    assert inst("fmi3DoStep", c_double(0), c_double(0.1), True, None, None, None, None) == ERROR
    # A Float64 read as Int32; an Enumeration must be read as Int64, not Int32.
    assert inst("fmi3GetInt32", (c_uint * 1)(inst.vr["force"]), c_size_t(1), (ctypes.c_int32 * 1)(), c_size_t(1)) == ERROR
    preset = (c_uint * 1)(inst.vr["preset"])
    assert inst("fmi3GetInt32", preset, c_size_t(1), (ctypes.c_int32 * 1)(), c_size_t(1)) == ERROR
    value = (ctypes.c_int64 * 1)()
    assert inst("fmi3GetInt64", preset, c_size_t(1), value, c_size_t(1)) == OK
    assert value[0] == int(next(v.start for v in inst.md.modelVariables if v.name == "preset"))
    # time is the independent variable: readable, not settable.
    assert inst.get("time") == (OK, [0.0])
    assert inst.set(time=1.0) == ERROR
    # A Model Exchange call on a Co-Simulation instance.
    assert inst("fmi3SetTime", c_double(0.0)) == ERROR
    # Functions the FMU does not support say why; a getter of no variables succeeds.
    assert inst("fmi3GetClock", (c_uint * 1)(0), c_size_t(1), (c_bool * 1)()) == ERROR
    assert "not supported" in inst.last()
    assert inst("fmi3GetFloat32", None, c_size_t(0), None, c_size_t(0)) == OK
    assert inst("fmi3EnterStepMode") == ERROR
    inst.free()
    # A freed instance is refused without a crash.
    assert inst("fmi3Terminate") == ERROR


def test_nan_and_out_of_range_get_the_fmi2_status(lib):
    """The same inputs through fmi2SetReal and fmi3SetFloat64 of the same library."""
    inst = Instance(lib, "McKibbenMuscle")
    inst.initialize()
    md2_vr = inst.vr  # the Float64 value references are the FMI 2.0 Real ones
    callbacks = (c_void_p * 5)()
    fmi2 = c_void_p(lib.fmi2Instantiate(b"y", 1, inst.md.instantiationToken.encode(), None, callbacks, 0, 0))
    assert fmi2.value
    assert lib.fmi2SetupExperiment(fmi2, 0, c_double(0), c_double(0), 0, c_double(0)) == OK
    assert lib.fmi2EnterInitializationMode(fmi2) == OK
    assert lib.fmi2ExitInitializationMode(fmi2) == OK
    cases = [("pressure", math.nan), ("pressure", math.inf), ("length", -1.0), ("pressure", 1e12)]
    for name, value in cases:
        status3 = inst.set(**{name: value})
        status2 = lib.fmi2SetReal(fmi2, (c_uint * 1)(md2_vr[name]), c_size_t(1), (c_double * 1)(value))
        assert status3 == status2, (name, value)
        if status3 == ERROR:
            assert name in inst.last()
        status, (force,) = inst.get("force")
        assert status <= WARNING and math.isfinite(force)
    # The other version's handle is refused, not misused.
    assert lib.fmi3Terminate(fmi2) == ERROR
    lib.fmi2FreeInstance(fmi2)
    inst.free()


def test_a_crafted_fmu_state_is_refused(lib):
    inst = Instance(lib, "McKibbenMuscle")
    inst.initialize()
    state = c_void_p()
    assert inst("fmi3GetFMUState", byref(state)) == OK
    size = c_size_t()
    assert inst("fmi3SerializedFMUStateSize", state, byref(size)) == OK
    data = (ctypes.c_uint8 * size.value)()
    assert inst("fmi3SerializeFMUState", state, data, size) == OK
    restored = c_void_p()
    assert inst("fmi3DeserializeFMUState", data, size, byref(restored)) == OK
    assert inst("fmi3SetFMUState", restored) == OK
    data[size.value // 2] ^= 0x55
    crafted = c_void_p()
    assert inst("fmi3DeserializeFMUState", data, size, byref(crafted)) == ERROR
    assert inst("fmi3SetFMUState", c_void_p(12345)) == ERROR
    for s in (state, restored):
        assert inst("fmi3FreeFMUState", byref(s)) == OK
    inst.free()


@pytest.mark.parametrize("model", MODELS)
def test_variable_dependencies_are_the_model_structure(lib, model):
    inst = Instance(lib, model)
    unknowns = inst.md.outputs + inst.md.derivatives
    assert unknowns
    for unknown in unknowns:
        vr = unknown.variable.valueReference
        n = c_size_t()
        assert inst("fmi3GetNumberOfVariableDependencies", c_uint(vr), byref(n)) == OK
        expected = sorted(d.valueReference for d in unknown.dependencies)
        assert n.value == len(expected)
        k = n.value
        element, independents, elements, kinds = (c_size_t * k)(), (c_uint * k)(), (c_size_t * k)(), (c_int * k)()
        assert inst("fmi3GetVariableDependencies", c_uint(vr), element, independents, elements, kinds, n) == OK
        assert sorted(independents) == expected
        assert all(kind == 5 for kind in kinds)  # fmi3Dependent
    inst.free()


def test_directional_and_adjoint_derivatives_match_central_differences(lib):
    inst = Instance(lib, "McKibbenMuscle")
    inst.initialize()
    point = {"pressure": 300e3, "length": 0.95 * float(next(
        v.start for v in inst.md.modelVariables if v.name == "nominal_length"))}
    assert inst.set(**point) == OK
    knowns = ["pressure", "length"]
    unknown = (c_uint * 1)(inst.vr["force"])
    known = (c_uint * 2)(*[inst.vr[k] for k in knowns])
    jacobian = []
    for j in range(2):
        seed = (c_double * 2)(*[1.0 if i == j else 0.0 for i in range(2)])
        out = (c_double * 1)()
        assert inst("fmi3GetDirectionalDerivative", unknown, c_size_t(1), known, c_size_t(2), seed, c_size_t(2),
                    out, c_size_t(1)) == OK
        jacobian.append(out[0])
    for j, name in enumerate(knowns):
        h = 1e-6 * point[name]
        inst.set(**{name: point[name] + h})
        plus = inst.get("force")[1][0]
        inst.set(**{name: point[name] - h})
        minus = inst.get("force")[1][0]
        inst.set(**{name: point[name]})
        difference = (plus - minus) / (2 * h)
        assert jacobian[j] == pytest.approx(difference, rel=1e-5), name
    # The adjoint is the transpose: seed^T J over the same variables.
    seed = (c_double * 1)(2.5)
    out = (c_double * 2)()
    assert inst("fmi3GetAdjointDerivative", unknown, c_size_t(1), known, c_size_t(2), seed, c_size_t(1),
                out, c_size_t(2)) == OK
    assert list(out) == pytest.approx([2.5 * d for d in jacobian], rel=1e-12)
    # time has no partials.
    bad = (c_uint * 1)(inst.vr["time"])
    assert inst("fmi3GetDirectionalDerivative", unknown, c_size_t(1), bad, c_size_t(1), (c_double * 1)(1.0),
                c_size_t(1), (c_double * 1)(), c_size_t(1)) == ERROR
    # Each call's seed and sensitivity sizes are the other's swapped: either call with the
    # other's sizes, or a NULL seed of non-zero length, is an error.
    two_in, two_out = (c_double * 2)(1.0, 0.0), (c_double * 2)()
    assert inst("fmi3GetDirectionalDerivative", unknown, c_size_t(1), known, c_size_t(2), seed, c_size_t(1),
                two_out, c_size_t(2)) == ERROR
    assert inst("fmi3GetAdjointDerivative", unknown, c_size_t(1), known, c_size_t(2), two_in, c_size_t(2),
                (c_double * 1)(), c_size_t(1)) == ERROR
    assert inst("fmi3GetAdjointDerivative", unknown, c_size_t(1), known, c_size_t(2), None, c_size_t(1),
                two_out, c_size_t(2)) == ERROR
    # A refused call leaves the instance usable: the right sizes still give the adjoint.
    assert inst("fmi3GetAdjointDerivative", unknown, c_size_t(1), known, c_size_t(2), seed, c_size_t(1),
                two_out, c_size_t(2)) == OK
    assert list(two_out) == pytest.approx([2.5 * d for d in jacobian], rel=1e-12)
    inst.free()


def test_model_exchange_through_the_c_api(lib):
    """The motor's ME calls: counts, states, derivatives, event indicators, an event iteration."""
    inst = Instance(lib, "MultiferroicMotor", model_exchange=True)
    nx, nz = c_size_t(), c_size_t()
    assert inst("fmi3GetNumberOfContinuousStates", byref(nx)) == OK
    assert inst("fmi3GetNumberOfEventIndicators", byref(nz)) == OK
    assert (nx.value, nz.value) == (inst.md.numberOfContinuousStates, inst.md.numberOfEventIndicators)
    inst.initialize()
    flags = [c_bool() for _ in range(5)]
    next_time = c_double()
    assert inst("fmi3UpdateDiscreteStates", *map(byref, flags), byref(next_time)) == OK
    assert inst("fmi3EnterContinuousTimeMode") == OK
    x, dx, z = (c_double * nx.value)(), (c_double * nx.value)(), (c_double * nz.value)()
    assert inst("fmi3GetContinuousStates", x, nx) == OK
    assert inst("fmi3GetContinuousStateDerivatives", dx, nx) == OK
    assert inst("fmi3GetEventIndicators", z, nz) == OK
    assert all(math.isfinite(v) for v in list(x) + list(dx) + list(z))
    # The event indicator variable reads the same value.
    status, (indicator,) = inst.get("event_indicator[1]")
    assert status == OK and indicator == z[0]
    enter, terminate = c_bool(), c_bool()
    assert inst("fmi3SetTime", c_double(1e-9)) == OK
    assert inst("fmi3CompletedIntegratorStep", True, byref(enter), byref(terminate)) == OK
    assert inst("fmi3SetContinuousStates", None, nx) == ERROR
    nan = (c_double * nx.value)(*([math.nan] * nx.value))
    assert inst("fmi3SetContinuousStates", nan, nx) == ERROR
    assert inst("fmi3Terminate") == OK
    inst.free()
