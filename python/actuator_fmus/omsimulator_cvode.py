"""FMPy's CVode configured as OMSimulator configures its own (OMSimulatorLib/SystemSC.cpp): to
check, without OMSimulator, that an FMU's Model Exchange runs under OMSimulator's default settings.
Use it by replacing `fmpy.sundials.CVodeSolver` with `OMSimulatorCVode` around `simulate_fmu`."""

from ctypes import c_int, c_void_p

from fmpy.sundials import CVodeSolver
from fmpy.sundials.cvode import sundials_cvode
from fmpy.sundials.sundials_types import sunrealtype


def _cvode_setter(name, value_type):
    f = getattr(sundials_cvode, name)
    f.argtypes = [c_void_p, value_type]
    f.restype = c_int
    return f


_SET_INIT_STEP = _cvode_setter("CVodeSetInitStep", sunrealtype)
_SET_MIN_STEP = _cvode_setter("CVodeSetMinStep", sunrealtype)
_SET_STAB_LIM_DET = _cvode_setter("CVodeSetStabLimDet", c_int)
_SET_MAX_ORD = _cvode_setter("CVodeSetMaxOrd", c_int)


class OMSimulatorCVode(CVodeSolver):
    """FMPy's CVode with OMSimulator's defaults (OMSimulatorLib/SystemSC.cpp). FMPy's CVode is BDF
    with the absolute tolerance `relativeTolerance x nominal` already; OMSimulator integrates to
    the next time event rather than to each output point, so it takes longer calls (here at most
    1000 steps between two output points)."""

    def __init__(self, *args, **kwargs):
        kwargs.update(relativeTolerance=1e-4, maxStep=1e-3, maxNumSteps=1000)
        super().__init__(*args, **kwargs)
        for setter, value in (
            (_SET_INIT_STEP, 1e-6),
            (_SET_MIN_STEP, 1e-12),
            (_SET_STAB_LIM_DET, 1),
            (_SET_MAX_ORD, 5),
        ):
            assert setter(self.cvode_mem, value) == 0, setter
