"""Which pressure makes a Festo DMSP-40 pull 2000 N at 10% contraction? One call, then checked by
simulating the muscle at that pressure.  Run after `make fmus`:
    .venv/bin/python recipes/pressure_for_force_datasheet.py
"""

from actuator_fmus import pressure_for_force, simulate

DMSP_40 = {"preset": "DMSP_40"}  # fitted to the datasheet, nominal length 0.4 m
NOMINAL = 0.4  # m

length = NOMINAL * (1 - 0.10)
p, saturated = pressure_for_force(2000.0, length, DMSP_40)  # Pa, and whether out of reach
print(f"DMSP-40 at 10% contraction pulls 2000 N at {p / 1e3:.2f} kPa (out of reach: {saturated})")

# Check: the forward model at that pressure.
r = simulate("McKibbenMuscle", start_values={**DMSP_40, "pressure": p, "length": length}, stop_time=0.001,
             output=["force"])
print(f"forward check: force at {p / 1e3:.2f} kPa = {r['force'][-1]:.6f} N")
assert not saturated and abs(r["force"][-1] - 2000.0) < 1e-6 * 2000.0

# A whole stroke at once, and a force out of reach (more than 600 kPa can give).
lengths = [NOMINAL * (1 - c) for c in (0.0, 0.05, 0.10, 0.15, 0.25)]
pressures, flags = pressure_for_force([1500.0] * len(lengths), lengths, DMSP_40, max_pressure=6e5)
for c, p, s in zip((0, 5, 10, 15, 25), pressures, flags):
    print(f"  1500 N at {c:2d}% contraction: {p / 1e3:7.2f} kPa{'  (out of reach: nearest force)' if s else ''}")
assert all(b >= a for a, b in zip(pressures, pressures[1:])), "a shorter muscle needs more pressure"
assert flags[-1] and not flags[0]
