"""Recipe: step the MultiferroicMotor (the dissertation's chapter 3, Table 3.1) by 60 degrees.

Two ways, which must agree:

1. the built-in schedule (`schedule` = 1, `stepping_schedule`): every `step_period` the strain direction turns by
   `step_angle` at `stress_amplitude`, starting from `schedule_initial_direction` (-30 degrees);
2. your own schedule through the inputs (`schedule` = 0, `inputs`): `strain_direction` and `stress` as a
   piecewise-constant input signal, here the same -30, 30, 90, ... degrees at 200 MPa.

Uniaxial stress has 180-degree symmetry, so a 60-degree step makes the next energy minimum unique
(+60, not -120): 12 steps turn the rotor two full turns. Run after `make fmus`:
.venv/bin/python recipes/motor_stepping_schedule.py
"""
import numpy as np

from actuator_fmus import simulate  # FMPy's simulate_fmu with names and ranges checked first

FMU = "MultiferroicMotor"
PERIOD = 100e-6  # s
STEPS = 12
STRESS = 200e6  # Pa
FIRST = np.radians(-30.0)
STEP = np.radians(60.0)


def ends_of_periods(result):
    """Rotor angle (degrees) at the end of each period."""
    idx = [int(np.argmin(abs(result["time"] - (k + 1) * PERIOD))) for k in range(STEPS)]
    return np.degrees(result["rotor_angle"][idx])


built_in = simulate(FMU, start_values={"schedule": "stepping_schedule", "step_period": PERIOD,
                                       "step_angle": STEP, "stress_amplitude": STRESS,
                                       "schedule_initial_direction": FIRST},
                    stop_time=STEPS * PERIOD, output_interval=PERIOD / 50,
                    output=["rotor_angle", "applied_strain_direction"])

# FMPy interpolates continuous inputs linearly between rows; a repeated time stamp is a jump.
switches = np.arange(1, STEPS) * PERIOD
times = np.concatenate([[0.0], np.repeat(switches, 2), [STEPS * PERIOD]])
level = np.concatenate([[0], np.repeat(np.arange(STEPS - 1), 2) + np.tile([0, 1], STEPS - 1), [STEPS - 1]])
signal = np.zeros(len(times), dtype=[("time", float), ("strain_direction", float), ("stress", float),
                                     ("load_torque", float)])
signal["time"] = times
signal["strain_direction"] = FIRST + STEP * level
signal["stress"] = STRESS
# Inputs without a column (here `strain`) are held at their start values.
own = simulate(FMU, start_values={"schedule": "inputs"}, input=signal, stop_time=STEPS * PERIOD,
               output_interval=PERIOD / 50, output=["rotor_angle", "applied_strain_direction"])

a, b = ends_of_periods(built_in), ends_of_periods(own)
print(f"MultiferroicMotor, {STEPS} steps of 60 degrees every {PERIOD * 1e6:g} us at {STRESS / 1e6:g} MPa")
print("step  strain direction [deg]  rotor, built-in schedule [deg]  rotor, own inputs [deg]")
for k in range(STEPS):
    direction = np.degrees(FIRST + STEP * k)
    print(f"{k + 1:4d}  {direction:22.1f}  {a[k]:30.3f}  {b[k]:23.3f}")
assert abs(a[-1] - 720.0) < 0.01, a[-1]
assert np.allclose(a, b, atol=0.01), (a, b)
assert np.allclose(np.diff(np.concatenate([[0.0], a])), 60.0, atol=1.0)
print(f"two turns: {a[-1]:.4f} degrees built-in, {b[-1]:.4f} degrees from the inputs")
