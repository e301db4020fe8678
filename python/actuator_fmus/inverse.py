"""The gauge pressure that gives a force: one call, any McKibbenMuscle configuration.

    from actuator_fmus import pressure_for_force
    pressure_pa, out_of_reach = pressure_for_force(2000.0, 0.36, {"preset": "DMSP_40"})
    # 356670 Pa (356.67 kPa): a DMSP-40 at 10% contraction pulls 2000 N

It asks McKibbenMuscle.fmu itself (`pressure_solver` on): the FMU inverts its own force model with
the solver of McKibbenJoint's torque mode, so the answer holds for every bladder model, preset and
parameter set the FMU accepts. Forces and lengths may be sequences.
"""

from typing import NamedTuple

from . import names as checks
from .slave import Slave

MODEL = "McKibbenMuscle"


class PressureForForce(NamedTuple):
    pressure_pa: float  # gauge pressure, Pa
    out_of_reach: bool  # True: no pressure in 0 .. max_pressure gives the force; the nearest one's pressure


def pressure_for_force(force, length, start_values=None, max_pressure=8e5):
    """Gauge pressure in Pa (within 0 .. `max_pressure` Pa) at which McKibbenMuscle with
    `start_values` (SI units, checked) pulls with `force` (N) at `length` (m), and whether the
    force is out of reach (then the pressure of the nearest reachable force).

    Returns a PressureForForce (pressure_pa, out_of_reach); with sequences of forces or lengths,
    (list of pressures in Pa, list of flags)."""
    many = hasattr(force, "__len__") or hasattr(length, "__len__")
    n = len(force) if hasattr(force, "__len__") else len(length) if hasattr(length, "__len__") else 1
    forces = list(force) if hasattr(force, "__len__") else [force] * n
    lengths = list(length) if hasattr(length, "__len__") else [length] * n
    for f in forces:
        checks.check_value(MODEL, checks.variables(MODEL)["target_force"], f)
    muscle = Slave(MODEL, **{**(start_values or {}), "pressure_solver": True, "max_pressure": max_pressure,
                             "length": lengths[0]})
    try:
        out = [PressureForForce(*muscle.at("target_pressure", "target_force_saturated",
                                           target_force=f, length=length_))
               for f, length_ in zip(forces, lengths)]
    finally:
        muscle.close()
    out = [PressureForForce(float(p), bool(s)) for p, s in out]
    if many:
        return [p for p, _ in out], [s for _, s in out]
    return out[0]
