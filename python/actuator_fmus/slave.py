"""`Slave`: one initialized FMU instance addressed by variable names, for point-wise work.

Values are in the model description's SI units (Pa, m, N, N.m, rad, s); an Enumeration takes an
item's name or its integer. Names and values are checked before they reach the FMU.
"""

import functools

from . import names as checks
from .fmu import CoSimulation
from .paths import fmu_path


@functools.lru_cache(maxsize=None)
def extracted(path):
    """The directory FMPy extracted `path` (an .fmu) to, once per process."""
    from fmpy import extract

    return extract(path)


class Slave:
    """An initialized FMU (FMI 2.0 or 3.0, see `fmu.CoSimulation`) addressed by variable names: `at(...)` sets inputs and reads outputs
    without a step (outputs follow inputs directly), `step(...)` advances history such as friction.

        m = Slave("McKibbenMuscle", preset="DMSP_40", length=0.36)
        force_n = m.at("force", pressure=3e5)   # Pa in, N out
    """

    # False: values go to the FMU as given (a test of the FMU's own refusals); names are still checked.
    check_values = True

    def __init__(self, model, log=None, **parameters):
        """`model`: FMU name; `log`: an object with FMI 2.0 `callbacks` or an FMI 3.0 `log_message`
        (FMPy's printing logger if None); `parameters`: start values set in initialization mode, SI
        units."""
        path = fmu_path(model)
        self.model = model
        self.md = checks.model_description(model)
        self.vars = {v.name: v for v in self.md.modelVariables}
        if self.check_values:
            parameters = checks.check_start_values(model, parameters)
        self.fmu = CoSimulation(extracted(path), model, self.md)
        self.fmu.instantiate(log)
        self.fmu.enterInitializationMode(startTime=0.0)
        self.set(**parameters)
        self.fmu.exitInitializationMode()
        self.time = 0.0  # s

    def set(self, **values):
        """Sets variables by name (SI units; Enumeration: item name or integer)."""
        for name, value in values.items():
            v = checks.check_name(self.model, name, checks.SETTABLE, "parameter or input")
            if self.check_values or isinstance(value, str):
                value = checks.check_value(self.model, v, value)
            kind = checks.fmi2_type(v)
            if kind == "Real":
                self.fmu.setReal([v.valueReference], [float(value)])
            elif kind in ("Integer", checks.ENUMERATION):
                self.fmu.setInteger([v.valueReference], [int(value)])
            else:
                self.fmu.setBoolean([v.valueReference], [bool(value)])

    def get(self, *names):
        """The values of `names` (SI units; Enumerations as integers): one value or a list."""
        checks.check_output_names(self.model, names)
        out = []
        for name in names:
            v = self.vars[name]
            getter = {"Real": self.fmu.getReal, "Integer": self.fmu.getInteger,
                      checks.ENUMERATION: self.fmu.getInteger, "Boolean": self.fmu.getBoolean}[checks.fmi2_type(v)]
            out.append(getter([v.valueReference])[0])
        return out[0] if len(out) == 1 else out

    def at(self, *names, **inputs):
        """Sets `inputs`, then returns `get(*names)`, without a step."""
        self.set(**inputs)
        return self.get(*names)

    def step(self, h=1e-3, **inputs):
        """Sets `inputs`, then advances the FMU by `h` seconds."""
        self.set(**inputs)
        self.fmu.doStep(self.time, h)
        self.time += h

    def close(self):
        """Terminates and frees the instance."""
        self.fmu.terminate()
        self.fmu.freeInstance()
