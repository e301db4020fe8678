"""MultiferroicMotor as Model Exchange under OMSimulator's CVode settings (through FMPy, see
actuator_fmus.omsimulator_cvode) at every declared bound of every parameter alone, both onion
models, the stepping schedule on; each run compared with Co-Simulation (1 us steps).

    .venv/bin/python tools/motor_omsimulator_bounds.py [--timeout S] [NAME ...]
    .venv/bin/python tools/motor_omsimulator_bounds.py --options
    .venv/bin/python tools/motor_omsimulator_bounds.py --fmpy-defaults [NAME ...]

Prints one line per run as it finishes: OK or the reason CVode stopped, wall time, the final
rotor angles of both interfaces and their largest difference at common output points. With
`--options`: every combination of the options (onion model, schedule, rotor_locked,
strain_drive) at the defaults and at the bounds of density and fluid_viscosity, Model Exchange
only, OK only where every FMI call returned fmi2OK. With `--fmpy-defaults`: FMPy's own CVode
settings (relative tolerance 1e-5, at most 500 steps between output points) instead of
OMSimulator's."""

import itertools

import argparse
import multiprocessing as mp
import sys
import time

import numpy as np


def run(path, start_values, queue, fmpy_defaults=False):
    import fmpy.sundials
    from fmpy import simulate_fmu

    from actuator_fmus.omsimulator_cvode import OMSimulatorCVode

    if not fmpy_defaults:
        fmpy.sundials.CVodeSolver = OMSimulatorCVode
    try:
        t0 = time.perf_counter()
        me = simulate_fmu(path, fmi_type="ModelExchange", solver="CVode", start_values=start_values, output=["rotor_angle"])
        wall = time.perf_counter() - t0
        cs = simulate_fmu(path, start_values=start_values, output=["rotor_angle"], output_interval=1e-6)
        idx = np.clip(np.searchsorted(cs["time"], me["time"] - 1e-12), 0, len(cs) - 1)
        common = np.abs(cs["time"][idx] - me["time"]) < 1e-12
        worst = float(np.abs(me["rotor_angle"][common] - cs["rotor_angle"][idx[common]]).max())
        queue.put(("OK", wall, float(me["time"][-1]), float(me["rotor_angle"][-1]), float(cs["rotor_angle"][-1]), worst))
    except Exception as e:  # the reason CVode or the FMU stopped
        queue.put(("STOP", time.perf_counter() - t0, str(e).splitlines()[0][:160]))


def run_strict(path, start_values, queue):
    """Model Exchange only; "OK" only if every FMI call returned fmi2OK."""
    import fmpy.sundials
    from fmpy import simulate_fmu

    from actuator_fmus.omsimulator_cvode import OMSimulatorCVode

    fmpy.sundials.CVodeSolver = OMSimulatorCVode
    bad = []

    def calls(message):
        if message.rpartition(" -> ")[2] in ("WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"):
            bad.append(message[:160])

    t0 = time.perf_counter()
    try:
        simulate_fmu(path, fmi_type="ModelExchange", solver="CVode", start_values=start_values, output=["rotor_angle"], fmi_call_logger=calls)
        queue.put(("OK", time.perf_counter() - t0, "") if not bad else ("NOT OK", time.perf_counter() - t0, bad[0]))
    except Exception as e:
        queue.put(("STOP", time.perf_counter() - t0, str(e).splitlines()[0][:160]))


def options(path, timeout):
    extremes = [{}, dict(density=1000.0), dict(density=1e5), dict(fluid_viscosity=5e-6), dict(fluid_viscosity=1e9)]
    combos = list(itertools.product((0, 1), (0, 1), (False, True), (False, True), extremes))
    ok = 0
    for k, (onion, schedule, locked, strain, extra) in enumerate(combos, 1):
        start = dict(onion_model=onion, schedule=schedule, rotor_locked=locked, strain_drive=strain, **extra)
        queue = mp.Queue()
        p = mp.Process(target=run_strict, args=(path, start, queue))
        p.start()
        p.join(timeout)
        if p.is_alive():
            p.terminate()
            p.join()
            result = ("TIMEOUT", timeout, "")
        else:
            result = queue.get() if not queue.empty() else ("CRASH", 0.0, f"exit code {p.exitcode}")
        ok += result[0] == "OK"
        print(f"[{k}/{len(combos)}] {start}: {result[0]} {result[1]:.2f} s {result[2]}", flush=True)
    print(f"{ok} of {len(combos)} runs fmi2OK throughout")


def cases(path, names):
    from fmpy import read_model_description

    md = read_model_description(path)
    for v in md.modelVariables:
        if v.causality != "parameter" or (names and v.name not in names):
            continue
        if v.name in ("schedule", "onion_model"):
            continue
        bounds = [True, False] if v.type == "Boolean" else [b for b in (v.min, v.max) if b is not None]
        for b in bounds:
            value = b if v.type == "Boolean" else (int(b) if v.type in ("Integer", "Enumeration") else float(b))
            yield v.name, value


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("names", nargs="*", help="parameters to vary (all if none)")
    parser.add_argument("--timeout", type=float, default=300.0, help="wall time per run (s)")
    parser.add_argument("--onion", type=int, choices=(0, 1), action="append", help="onion model(s)")
    parser.add_argument("--options", action="store_true", help="every combination of the options instead")
    parser.add_argument("--fmu", help="the FMU (default: the packaged MultiferroicMotor.fmu)")
    parser.add_argument("--set", action="append", default=[], help="NAME=VALUE for every run")
    parser.add_argument("--fmpy-defaults", action="store_true", help="FMPy's CVode settings instead of OMSimulator's")
    args = parser.parse_args()
    from actuator_fmus.paths import fmu_path

    path = args.fmu or fmu_path("MultiferroicMotor")
    common = {k: float(v) for k, v in (s.split("=") for s in args.set)}
    if args.options:
        return options(path, args.timeout)
    onions = args.onion or [0, 1]
    todo = [(n, v, o) for n, v in cases(path, args.names) for o in onions]
    for k, (name, value, onion) in enumerate(todo, 1):
        start = {"schedule": 1, "onion_model": onion, **common, name: value}
        queue = mp.Queue()
        p = mp.Process(target=run, args=(path, start, queue, args.fmpy_defaults))
        p.start()
        p.join(args.timeout)
        if p.is_alive():
            p.terminate()
            p.join()
            result = ("TIMEOUT", args.timeout, "")
        else:
            result = queue.get() if not queue.empty() else ("CRASH", 0.0, f"exit code {p.exitcode}")
        label = f"[{k}/{len(todo)}] onion {onion} {name}={value!r}"
        if result[0] == "OK":
            _, wall, t_end, me_end, cs_end, worst = result
            print(f"{label}: OK {wall:.2f} s, ME {me_end:.4f} rad, CS {cs_end:.4f} rad, largest difference {worst:.2e} rad", flush=True)
        else:
            print(f"{label}: {result[0]} after {result[1]:.2f} s: {result[2]}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
