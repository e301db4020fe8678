"""`simulate`: FMPy's `simulate_fmu` for a packaged FMU, with every name and value checked first."""

from . import names as checks
from .paths import fmu_path


def simulate(model, start_values=None, input=None, output=None, **options):
    """Simulates the packaged `<model>.fmu` with FMPy's `simulate_fmu` and returns its structured
    result array (column "time" in s, every other column in its variable's SI unit).

    `start_values`: {name: value} of parameters and inputs, SI units (an Enumeration also takes an
    item's name, e.g. {"preset": "DMSP_40"}); `input`: FMPy's structured input array, column
    "time" (s) then inputs in SI units; `output`: names to record. Names, ranges and input samples
    are checked before the FMU is loaded: a mistake raises UsageError naming the valid choices.
    `options` go to `simulate_fmu` unchanged (stop_time in s, output_interval in s, ...)."""
    from fmpy import simulate_fmu

    path = fmu_path(model)
    start_values = checks.check_start_values(model, start_values)
    if input is not None:
        for name in input.dtype.names[1:]:
            checks.check_input_values(model, name, input[name], input["time"])
        input = _with_held_inputs(model, input, start_values)
    if output is not None:
        checks.check_output_names(model, output)
    return simulate_fmu(path, start_values=start_values, input=input, output=output, **options)


def _with_held_inputs(model, signals, start_values):
    """`signals` with a constant column for every Real input it lacks, at the start value given
    in `start_values` or else the declared one, so that FMPy does not warn about them (they are
    held at that value either way)."""
    import numpy as np

    held = {name: float(start_values.get(name, v.start)) for name, v in checks.variables(model).items()
            if v.causality == "input" and checks.fmi2_type(v) == "Real" and name not in signals.dtype.names}
    if not held:
        return signals
    out = np.zeros(signals.size, dtype=signals.dtype.descr + [(name, float) for name in held])
    for name in signals.dtype.names:
        out[name] = signals[name]
    for name, value in held.items():
        out[name] = value
    return out
