"""The pressure that gives a force: one call, any McKibbenMuscle configuration.

    from calibration.inverse import pressure_for_force
    p, saturated = pressure_for_force(2000.0, 0.36, {"preset": 6})   # DMSP-40, 10% contraction

It asks McKibbenMuscle.fmu itself (`pressure_solver` on): the FMU inverts its own force model with
the solver of McKibbenJoint's torque mode (src/physics/inverse.rs), so the answer holds for every
bladder model, preset and parameter set the FMU accepts. Forces and lengths may be sequences.
"""

import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
FMU = ROOT / "target" / "fmu" / "McKibbenMuscle.fmu"


def pressure_for_force(force, length, start_values=None, max_pressure=8e5, fmu=FMU):
    """Gauge pressure (Pa, within 0 .. max_pressure) at which McKibbenMuscle with `start_values`
    pulls with `force` (N) at `length` (m), and whether the force is out of reach (then the
    pressure of the nearest force). With sequences, lists of both."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    many = hasattr(force, "__len__") or hasattr(length, "__len__")
    n = len(force) if hasattr(force, "__len__") else len(length) if hasattr(length, "__len__") else 1
    forces = list(force) if hasattr(force, "__len__") else [force] * n
    lengths = list(length) if hasattr(length, "__len__") else [length] * n

    md = read_model_description(str(fmu))
    var = {v.name: v for v in md.modelVariables}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="pressure_for_force")
    slave.instantiate()
    try:
        setters = {"Real": slave.setReal, "Integer": slave.setInteger, "Boolean": slave.setBoolean}
        values = {**(start_values or {}), "pressure_solver": True, "max_pressure": max_pressure,
                  "length": lengths[0]}
        for name, value in values.items():
            setters[var[name].type]([var[name].valueReference], [value])
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        vr = {k: var[k].valueReference for k in ("target_force", "length", "target_pressure",
                                                  "target_force_saturated")}
        out = []
        for f, length_ in zip(forces, lengths):
            slave.setReal([vr["target_force"], vr["length"]], [f, length_])
            out.append((slave.getReal([vr["target_pressure"]])[0],
                        bool(slave.getBoolean([vr["target_force_saturated"]])[0])))
        slave.terminate()
    finally:
        slave.freeInstance()
    if many:
        return [p for p, _ in out], [s for _, s in out]
    return out[0]
