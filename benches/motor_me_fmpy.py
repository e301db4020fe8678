"""Wall time of the motor's stepping scene (section 3.2.2: 60 degree steps every 100 us at
200 MPa, 12 periods) under FMPy: Co-Simulation against Model Exchange with CVode, and Euler at
2 ns over the first two periods, with the rotor angle's largest difference at the period ends.
Run from the repository root after `make fmus`: `.venv/bin/python benches/motor_me_fmpy.py`."""

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


def main():
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
