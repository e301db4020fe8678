"""The robot joint as a system, from the packaged FMUs in target/fmu:

- out/systems/RobotJoint.ssp: systems/RobotJoint.ssd with the McKibbenMuscle and PulleyJoint FMUs
  under resources/, for fmpy.ssp.simulation.simulate_ssp;
- out/systems/RobotJoint.fmu: a container FMU built by fmu-manipulation-toolbox from
  systems/RobotJoint.container.json (two McKibbenMuscle instances and PulleyJoint, 1 ms step).

With --run both are simulated for 4 s and out/systems/robot_joint_systems.png compares them with
the two-FMU co-simulation of `actuator-fmus robot-joint`. Usage: actuator-fmus systems [--run]"""

import logging
import shutil
import zipfile

from .paths import FMU_DIR, ROOT

OUT = ROOT / "out" / "systems"
HERE = ROOT / "systems"
STEP = 1e-3


def build_ssp(out=OUT):
    """Writes <out>/RobotJoint.ssp (systems/RobotJoint.ssd and the two FMUs); returns its path."""
    out.mkdir(parents=True, exist_ok=True)
    path = out / "RobotJoint.ssp"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(HERE / "RobotJoint.ssd", "SystemStructure.ssd")
        for model in ("McKibbenMuscle", "PulleyJoint"):
            z.write(FMU_DIR / f"{model}.fmu", f"resources/{model}.fmu")
    return path


def build_container(out=OUT):
    """fmu-manipulation-toolbox's Assembly, as its `fmucontainer -container <json>` CLI runs it."""
    from fmu_manipulation_toolbox.assembly import Assembly

    out.mkdir(parents=True, exist_ok=True)
    for model in ("McKibbenMuscle", "PulleyJoint"):
        shutil.copy(FMU_DIR / f"{model}.fmu", out / f"{model}.fmu")
    shutil.copy(HERE / "RobotJoint.container.json", out / "RobotJoint.json")
    unconnected = _UnconnectedOutputs()
    toolbox_log = logging.getLogger("fmu_manipulation_toolbox")
    toolbox_log.addFilter(unconnected)
    try:
        assembly = Assembly("RobotJoint.json", fmu_directory=out, default_step_size=STEP)
        assembly.make_fmu()
    finally:
        toolbox_log.removeFilter(unconnected)
    print(f"container: {unconnected.count} muscle outputs left unconnected (the joint reads only "
          f"each muscle's force)")
    return out / "RobotJoint.fmu"


def run_ssp(path, stop_time=4.0):
    """Simulates the SSP for `stop_time` s with FMPy's simulate_ssp at 1 ms steps; returns its result
    (SI units)."""
    from fmpy.ssp.simulation import simulate_ssp

    return simulate_ssp(str(path), stop_time=stop_time, step_size=STEP)


# fmu-manipulation-toolbox 2.0's container runtime (its container.so, not our FMUs) reports its
# start-up with FMI status warning or error although nothing failed. These lines are shown as
# notes; every other message keeps its status.
CONTAINER_START_UP = ("FMUContainer 'V", "Solver configure", "Container use ")
_KEEP_ALIVE = []  # FMPy's logger proxy has one process-global target: never free a callback


def _container_logger(_env, _name, status, _category, message):
    from fmpy.fmi2 import printLogMessage

    text = message.decode("utf-8", "replace")
    if status in (1, 3) and text.startswith(CONTAINER_START_UP):
        print(f"[note] container runtime start-up: {text}")
    else:
        printLogMessage(_env, _name, status, _category, message)


def _callbacks(logger):
    from ctypes import byref

    from fmpy.fmi2 import (calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                           fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)
    from fmpy.logging import addLoggerProxy

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    addLoggerProxy(byref(callbacks))
    _KEEP_ALIVE.append(callbacks)
    return callbacks


def run_container(path, stop_time=4.0):
    """Simulates the container FMU for `stop_time` s; returns the result (SI units)."""
    from fmpy import extract, read_model_description, simulate_fmu
    from fmpy.fmi2 import FMU2Slave, printLogMessage

    md = read_model_description(str(path))
    unzipdir = extract(str(path))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="RobotJoint")
    fmu.instantiate(callbacks=_callbacks(_container_logger))
    try:
        return simulate_fmu(str(path), stop_time=stop_time, output_interval=STEP,
                            output=["joint_angle", "reference_angle", "joint_torque"],
                            model_description=md, fmu_instance=fmu)
    finally:
        fmu.freeInstance()
        _callbacks(printLogMessage)  # later FMUs print as FMPy's default logger does
        shutil.rmtree(unzipdir, ignore_errors=True)


class _UnconnectedOutputs(logging.Filter):
    """Counts fmu-manipulation-toolbox's "Output ... is not connected" lines (the joint reads only
    each muscle's force) and lets every other message through."""

    def __init__(self):
        super().__init__()
        self.count = 0

    def filter(self, record):
        if record.getMessage().endswith("is not connected"):
            self.count += 1
            return False
        return True


def add_arguments(parser):
    """The options of `actuator-fmus systems`."""
    parser.add_argument("--run", action="store_true", help="simulate both for 4 s and plot them against the two-FMU run")


def main(args):
    """Builds the SSP and the container FMU and, with --run, simulates and plots both; returns 0."""
    ssp = build_ssp()
    container = build_container()
    print(f"wrote {ssp} and {container}")
    if not args.run:
        return 0
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from . import robot_joint

    reference = np.array(robot_joint.read_csv(ROOT / "tests" / "data" / "robot_joint_ref.csv")[1])
    s = run_ssp(ssp)
    c = run_container(container)
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(reference[:, 0], np.degrees(reference[:, 3]), "k--", label="reference angle")
    ax.plot(reference[:, 0], np.degrees(reference[:, 1]), label="two FMUs, FMPy FMU2Slave (Gauss-Seidel)")
    ax.plot(s["time"] + STEP, np.degrees(s["joint.joint_angle"]), ":", label="SSP, fmpy simulate_ssp (Jacobi)")
    ax.plot(c["time"], np.degrees(c["joint_angle"]), "-.", label="container FMU (fmu-manipulation-toolbox)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("joint angle (deg)")
    ax.set_title("Robot joint (two McKibbenMuscle FMUs and PulleyJoint): the same joint co-simulated,\n"
                 "as an SSP and as a container FMU, 1 ms communication step", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "robot_joint_systems.png", dpi=100)
    print(f"wrote {OUT}/robot_joint_systems.png")
    return 0

