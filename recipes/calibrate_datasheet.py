"""Calibrate McKibbenMuscle to a Festo DMSP-40 datasheet and use the result.  Run after `make fmus`
(and `cargo build --release -p actuator-fmus-tools --bin calibrate`, which `make fmus` also builds):
    .venv/bin/python recipes/calibrate_datasheet.py

Fits at 0 and 600 kPa only, predicts the other pressures, checks the fitted parameters through the
FMU, and writes out/recipes/calibrate_dmsp40/{params.json,params.ssv,report.md,fit.png}.
"""

import json

from actuator_fmus import ROOT, simulate
from actuator_fmus.calibration import calibrate

out = ROOT / "out" / "recipes" / "calibrate_dmsp40"
summary = calibrate(ROOT / "data" / "festo" / "festo_dmsp40.csv", length=0.4, diameter=0.04,
                    fit_kpa=[0, 600], out=out)
print(f"\nfit time {summary['seconds']:.2f} s; error as a share of each curve's largest force:")
for e in summary["errors"]:
    role = "fitted   " if e["fitted"] else "predicted"
    print(f"  {e['pressure_kpa']:5g} kPa  {role}  RMS {100 * e['rms']:5.2f}%  max {100 * e['max']:5.2f}%")
assert all(e["rms"] < 0.02 for e in summary["errors"]), "goal: within 2% RMS at every pressure"
assert summary["fmu_max_force_difference_n"] < 1e-9, "the FMU must reproduce the fit exactly"

# The fitted parameters are FMPy start values as they are: the force at 300 kPa and 10% contraction.
params = json.loads((out / "params.json").read_text())
r = simulate("McKibbenMuscle", start_values={**params, "pressure": 3e5, "length": 0.4 * 0.9}, stop_time=0.001,
             output=["force", "contraction"])
print(f"McKibbenMuscle with params.json at 300 kPa, {100 * r['contraction'][-1]:.0f}% contraction: "
      f"{r['force'][-1]:.0f} N (datasheet, 300 kPa: 2084 N at 6%, 1000 N at 16%)")
print(f"report: {out / 'report.md'}")
