"""Recipe: the robot joint as an SSP (two McKibbenMuscle FMUs and PulleyJoint, systems/RobotJoint.ssd)
run by three co-simulation masters: FMPy's simulate_ssp, libcosim (libcosimpy) and ecos (ecospy).

All three read the same .ssp file; the script prints the joint angle every 0.5 s from each and
checks that they agree at the times where each master stopped: libcosim keeps time in whole
nanoseconds, ecos adds the steps up in floating point and may stop one step off. All three pass
every output to the inputs at the same instant, so they lag a sequential co-simulation
(`actuator-fmus robot-joint`) by one 1 ms step. Run after `make fmus`:
.venv/bin/python recipes/importers_ssp_libcosim_ecos.py
"""
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
STEP = 1e-3  # s
STOP = 4.0  # s
SAMPLES = np.arange(0.5, STOP + 1e-9, 0.5)

from actuator_fmus import systems  # noqa: E402


def with_fmpy(ssp):
    """The joint angle as a function of time (linear between the 1 ms steps)."""
    from fmpy.ssp.simulation import simulate_ssp

    r = simulate_ssp(str(ssp), stop_time=STOP, step_size=STEP)
    # simulate_ssp records each row at the start of its step with the values at its end.
    return lambda t: np.interp(t, r["time"] + STEP, r["joint.joint_angle"])


def with_libcosim(ssp):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.WARNING)

    execution = CosimExecution.from_ssp_file(str(ssp), step_size=int(STEP * 1e9))  # nanoseconds
    joint = execution.slave_index_from_instance_name("joint")
    vr = next(v.reference for v in execution.slave_variables(joint) if v.name == b"joint_angle")
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    angles = []
    for t in SAMPLES:
        execution.simulate_until(int(round(t * 1e9)))
        angles.append(observer.last_real_values(joint, [vr])[0])
    return SAMPLES, np.array(angles)  # libcosim keeps time in whole nanoseconds: exact


def with_ecos(ssp):
    from ecospy import EcosLib
    from ecospy.EcosSimulation import EcosSimulation

    EcosLib.set_log_level("warn")
    sim = EcosSimulation(ssp_path=str(ssp), step_size=STEP)
    sim.init()
    times, angles = [], []
    for t in SAMPLES:
        sim.step_until(t)
        # ecos adds the steps up in floating point, so it may stop one step before or after t.
        times.append(sim.get_time())
        angles.append(sim.get_real("joint::joint_angle"))
    sim.terminate()
    return np.array(times), np.array(angles)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        ssp = systems.build_ssp(Path(tmp))
        fmpy_angle = with_fmpy(ssp)
        masters = {"libcosim": with_libcosim(ssp), "ecos": with_ecos(ssp)}
    print(f"robot joint SSP, {STEP * 1e3:g} ms step: joint angle [degrees] (time [s] where the master stopped)")
    print(f"{'time [s]':>8}  {'FMPy simulate_ssp':>17}  " + "  ".join(f"{name:>24}" for name in masters))
    for i, t in enumerate(SAMPLES):
        row = "  ".join(f"{np.degrees(a[i]):13.6f} ({ts[i]:8.6f})" for ts, a in masters.values())
        print(f"{t:8.1f}  {np.degrees(fmpy_angle(t)):17.6f}  {row}")
    for name, (ts, a) in masters.items():
        # Compare at the master's own times: FMPy's result is exact at every 1 ms step.
        diff = np.max(np.abs(a - fmpy_angle(ts)))
        print(f"{name}: largest difference from FMPy at the same times {diff:.2e} rad")
        assert diff < 1e-9, (name, diff)
    assert np.max(np.abs(fmpy_angle(SAMPLES))) > 0.2, "the joint did not move"


if __name__ == "__main__":
    sys.exit(main())
