"""Wall time of the motor's stepping scene (section 3.2.2: 60 degree steps every 100 us at
200 MPa, 12 periods) under FMPy: Co-Simulation against Model Exchange with CVode, and Euler at
2 ns over the first two periods, with the rotor angle's largest difference at the period ends.
Run from the repository root after `make fmus`: `.venv/bin/python benches/motor_me_fmpy.py`; with
`--defaults`, every configuration of DEFAULT_RUNS as Model Exchange under FMPy's default settings;
with `--nominals`, what rotor_speed's nominal does under FMPy's and OMSimulator's CVode settings."""

import pathlib
import time

import numpy as np
from fmpy import simulate_fmu

FMU = str(pathlib.Path(__file__).resolve().parents[1] / "target" / "fmu" / "MultiferroicMotor.fmu")
PARAMETERS = dict(schedule=1, step_period=1e-4, stress_amplitude=2e8)


def at(result, times):
    idx = np.searchsorted(result["time"], np.asarray(times) * (1 + 1e-12), side="right") - 1
    return result["rotor_angle"][idx]


def timed(**kw):
    start = time.perf_counter()
    # FMPy's Euler steps at each output point, so its output interval is its step.
    kw.setdefault("output_interval", kw.get("step_size") or 1e-6)
    result = simulate_fmu(FMU, start_values=PARAMETERS, output=["rotor_angle"], **kw)
    return result, time.perf_counter() - start


# Configurations run under FMPy's defaults (simulate_fmu with fmi_type="ModelExchange" and no
# solver options: CVode, relative tolerance 1e-5, at most 500 steps between output points).
DEFAULT_RUNS = {
    "quasi-static, schedule": dict(schedule=1),
    "quasi-static, schedule 25 us": dict(schedule=1, step_period=25e-6),
    "Gilbert, schedule": dict(onion_model=1, schedule=1),
    "Gilbert, schedule 25 us": dict(onion_model=1, schedule=1, step_period=25e-6),
    "Gilbert, schedule, alpha 0.01": dict(onion_model=1, schedule=1, gilbert_damping=0.01),
    "Gilbert, tension at -40 deg": dict(onion_model=1, stress=2e8, strain_direction=-0.7),
}


def defaults():
    """Model Exchange at FMPy's defaults against Co-Simulation at 1 us: right-hand sides,
    events, wall time and the largest rotor-angle difference at the common output points."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Model

    md = read_model_description(FMU)
    unzipped = extract(FMU)
    print("| configuration | right-hand sides | events | wall time | largest rotor-angle difference vs CS |")
    print("|---|---|---|---|---|")
    for label, parameters in DEFAULT_RUNS.items():
        fmu = FMU2Model(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="MultiferroicMotor", instanceName="me")
        counts = dict(rhs=0, events=0)
        get_derivatives, new_discrete_states = fmu.getDerivatives, fmu.newDiscreteStates

        def counted_derivatives(*a):
            counts["rhs"] += 1
            return get_derivatives(*a)

        def counted_events(*a):
            counts["events"] += 1
            return new_discrete_states(*a)

        fmu.getDerivatives, fmu.newDiscreteStates = counted_derivatives, counted_events
        fmu.instantiate()
        start = time.perf_counter()
        me = simulate_fmu(FMU, fmi_type="ModelExchange", start_values=parameters, output=["rotor_angle"], record_events=False,
                          fmu_instance=fmu, model_description=md)
        wall = time.perf_counter() - start
        fmu.freeInstance()
        cs = simulate_fmu(FMU, start_values=parameters, output=["rotor_angle"], output_interval=1e-6)
        idx = np.clip(np.searchsorted(cs["time"], me["time"] - 1e-12), 0, len(cs) - 1)
        common = np.abs(cs["time"][idx] - me["time"]) < 1e-12
        worst = np.abs(me["rotor_angle"][common] - cs["rotor_angle"][idx[common]]).max()
        print(f"| {label} | {counts['rhs']} | {counts['events']} | {wall:.2f} s | {worst:.1e} rad |")


def with_speed_nominal(solver, nominal):
    """`solver` (a CVode class of FMPy's) with rotor_speed's nominal replaced by `nominal`."""

    class Replaced(solver):
        def __init__(self, *args, **kwargs):
            get_nominals = kwargs["get_nominals"]

            def replaced(x, nx):
                get_nominals(x, nx)
                x[1] = nominal

            kwargs["get_nominals"] = replaced
            super().__init__(*args, **kwargs)

    return Replaced


NOMINAL_RUNS = [("fluid_viscosity", v) for v in (5e-6, 1e-4, 1e-3, 1e-2, 0.1, 1, 4, 1e3, 1e9)] + [("density", d) for d in (1e3, 1e5)]


def nominals():
    """For rotor_speed nominals from 1e2 rad/s to the description's: the largest rotor-angle
    difference at the period ends under FMPy's default CVode, and which parameter sets run (on the
    schedule, 1.2 ms) under OMSimulator's CVode settings (tests/fmpy/test_motor_omsimulator_settings.py)."""
    import fmpy.sundials

    from actuator_fmus.omsimulator_cvode import OMSimulatorCVode

    default_solver = fmpy.sundials.CVodeSolver
    cs = simulate_fmu(FMU, start_values=PARAMETERS, output=["rotor_angle"], output_interval=1e-6)
    ends = np.arange(1, 13) * 1e-4
    print("| rotor_speed nominal | period ends vs CS, FMPy defaults | " + " | ".join(f"{k} {v:g}" for k, v in NOMINAL_RUNS) + " |")
    print("|---" * (2 + len(NOMINAL_RUNS)) + "|")
    try:
        for nominal in (1e2, 1e3, 1e4, 6.7e4):
            fmpy.sundials.CVodeSolver = with_speed_nominal(default_solver, nominal)
            me = simulate_fmu(FMU, fmi_type="ModelExchange", start_values=PARAMETERS, output=["rotor_angle"])
            row = [f"{nominal:g} rad/s", f"{np.abs(at(me, ends) - at(cs, ends)).max():.1e} rad"]
            fmpy.sundials.CVodeSolver = with_speed_nominal(OMSimulatorCVode, nominal)
            for name, value in NOMINAL_RUNS:
                try:
                    simulate_fmu(FMU, fmi_type="ModelExchange", start_values={**PARAMETERS, name: value}, output=["rotor_angle"])
                    row.append("runs")
                except Exception:
                    row.append("stops")
            print("| " + " | ".join(row) + " |", flush=True)
    finally:
        fmpy.sundials.CVodeSolver = default_solver


def main():
    import sys

    if "--defaults" in sys.argv:
        return defaults()
    if "--nominals" in sys.argv:
        return nominals()
    print("| run | simulated | wall time | largest rotor-angle difference at period ends |")
    print("|---|---|---|---|")
    for label, stop, kw in [
        ("Model Exchange, CVode", 12e-4, dict(fmi_type="ModelExchange", solver="CVode")),
        ("Model Exchange, CVode, rtol 1e-8", 12e-4, dict(fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-8)),
        ("Model Exchange, Euler 2 ns", 2e-4, dict(fmi_type="ModelExchange", solver="Euler", step_size=2e-9)),
    ]:
        cs, cs_time = timed(stop_time=stop)
        me, me_time = timed(stop_time=stop, **kw)
        ends = np.arange(1, int(round(stop / 1e-4)) + 1) * 1e-4
        worst = np.degrees(np.abs(at(me, ends) - at(cs, ends)).max())
        print(f"| Co-Simulation, 1 us steps | {stop * 1e6:.0f} us | {cs_time:.2f} s | |")
        print(f"| {label} | {stop * 1e6:.0f} us | {me_time:.2f} s | {worst:.2e} degrees |")


if __name__ == "__main__":
    main()
