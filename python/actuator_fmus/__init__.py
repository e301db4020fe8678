"""actuator-fmus from Python: the packaged FMUs of McKibben and knitted muscles, their joints and the
multiferroic motor, driven through FMPy, with the project's scenes, calibration and figures.

All quantities are SI (Pa, m, N, N.m, rad, s, J) unless a name says otherwise (`_kpa`, `_mm`).

    from actuator_fmus import simulate, Slave, pressure_for_force
    r = simulate("McKibbenMuscle", start_values={"preset": "DMSP_40", "pressure": 3e5, "length": 0.36},
                 output=["force"], stop_time=0.01)
    pressure_pa, out_of_reach = pressure_for_force(2000.0, 0.36, {"preset": "DMSP_40"})

The command line is `actuator-fmus` (`actuator-fmus --help`).
"""

from .inverse import pressure_for_force
from .paths import FMU_DIR, ROOT, UsageError, fmu_path, models
from .simulation import simulate
from .slave import Slave

__all__ = ["FMU_DIR", "ROOT", "Slave", "UsageError", "fmu_path", "models", "pressure_for_force", "simulate"]
