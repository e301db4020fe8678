"""MultiferroicMotor: exact directional derivatives through FMPy against central differences of the
FMU's own outputs (Co-Simulation: outputs by inputs, the quasi-static onion settled for the present
inputs from its stored branch)."""

import math

import pytest

from conftest import Slave

OUTPUTS = [
    "torque",
    "onion_angle",
    "offset_angle",
    "magnetostatic_energy",
    "magnetoelastic_energy",
    "applied_strain_direction",
    "rotor_angle",
    "rotor_speed",
]

# (parameters, inputs before the point, point inputs, the inputs to differentiate by and their steps)
CASES = {
    "locked, tension at -45 deg": (
        dict(rotor_locked=True),
        dict(strain_direction=-math.pi / 4, stress=150e6, load_torque=0.0),
        dict(strain_direction=-math.pi / 4, stress=200e6, load_torque=0.0),
        {"strain_direction": 1e-6, "stress": 1e2, "load_torque": 1e-24},
    ),
    "free rotor mid-turn under load": (
        dict(),
        dict(strain_direction=-math.pi / 4, stress=200e6, load_torque=-5e-19),
        dict(strain_direction=-0.6, stress=250e6, load_torque=-5e-19),
        {"strain_direction": 1e-6, "stress": 1e2, "load_torque": 1e-24},
    ),
    "strain drive": (
        dict(strain_drive=True, rotor_locked=True),
        dict(strain_direction=-math.pi / 4, strain=5e-4),
        dict(strain_direction=-0.7, strain=1e-3),
        {"strain": 1e-9, "stress": 1e2, "strain_direction": 1e-6},
    ),
    "schedule (direction and stress are not inputs)": (
        dict(schedule=1, step_period=1e-4, stress_amplitude=200e6),
        dict(load_torque=2e-19),
        dict(load_torque=2e-19, strain_direction=0.3, stress=1e6),
        {"strain_direction": 1e-6, "stress": 1e2, "load_torque": 1e-24},
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_motor_partials_match_central_differences(case):
    parameters, before, point, steps = CASES[case]
    s = Slave("MultiferroicMotor", **parameters)
    assert s.md.coSimulation.providesDirectionalDerivative
    try:
        s.step(h=3e-6, **before)
        vr = lambda names: [s.vars[n].valueReference for n in names]
        for name, h in steps.items():
            s.set(**point)
            exact = list(s.fmu.getDirectionalDerivative(vr(OUTPUTS), vr([name]), [1.0]))
            up = s.at(*OUTPUTS, **{**point, name: point.get(name, 0.0) + h})
            down = s.at(*OUTPUTS, **{**point, name: point.get(name, 0.0) - h})
            for out, e, a, b in zip(OUTPUTS, exact, up, down):
                central = (a - b) / (2 * h)
                scale = max(abs(e), abs(central))
                floor = 1e-9 * max(abs(x) for x in exact + [central]) + 1e-300
                assert abs(e - central) <= 2e-5 * scale + floor, (case, out, name, e, central)
    finally:
        s.close()


def test_motor_torque_sensitivity_is_nonzero_where_the_physics_says():
    # Locked rotor at -45 degrees: more stress pulls the onion further and raises the torque
    # (below the peak, Fig. 3.3a); the load torque does not enter the torque output.
    s = Slave("MultiferroicMotor", rotor_locked=True)
    try:
        s.set(strain_direction=-math.pi / 4, stress=100e6)
        vr = lambda names: [s.vars[n].valueReference for n in names]
        (d_stress,) = s.fmu.getDirectionalDerivative(vr(["torque"]), vr(["stress"]), [1.0])
        assert d_stress > 0
        (d_load,) = s.fmu.getDirectionalDerivative(vr(["torque"]), vr(["load_torque"]), [1.0])
        assert d_load == 0.0
    finally:
        s.close()
