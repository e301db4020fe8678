"""fmi2GetDirectionalDerivative through FMPy against central differences of the FMU's own outputs,
at points across every effect of McKibbenMuscle (ideal sleeve; thin and thick wall in contact and
free; pre-strain; friction mid-presliding; connector spring) and for PassThrough."""

import pytest

from conftest import Slave

OUTPUTS = ["force", "volume", "effective_pressure", "friction_force"]
INPUTS = ["pressure", "length"]

# (parameters, points (pressure Pa, length as a fraction of the min..max range)).
CASES = {
    "ideal A": (dict(preset=1), [(3e5, 0.8), (-2e4, 0.7)]),
    "thin wall A (free, contact)": (dict(preset=1, bladder_model=1), [(5e4, 0.95), (4e5, 0.4)]),
    "thick wall A, 8 layers": (dict(preset=1, bladder_model=2, bladder_layers=8), [(4e5, 0.5), (1e5, 0.9)]),
    "pre-strained C, thin wall": (dict(preset=3, bladder_model=1), [(2e5, 0.6), (6e5, 0.8)]),
    "B, thick wall, friction": (
        dict(preset=2, bladder_model=2, bladder_layers=4, friction=True),
        [(3e5, 0.6), (5e5, 0.75)],
    ),
    "D, thin wall, connector 5e4 N/m": (
        dict(preset=4, bladder_model=1, connector_stiffness=5e4),
        [(3e5, 0.6), (5e5, 0.7)],
    ),
    "D, ideal, friction and connector": (
        dict(preset=4, friction=True, connector_stiffness=2e4),
        [(4e5, 0.7)],
    ),
}


def directional(s, unknowns, knowns, seed):
    vr = lambda names: [s.vars[n].valueReference for n in names]
    return list(s.fmu.getDirectionalDerivative(vr(unknowns), vr(knowns), seed))


@pytest.mark.parametrize("case", CASES)
def test_muscle_partials_match_central_differences(case):
    parameters, points = CASES[case]
    s = Slave("McKibbenMuscle", **parameters)
    assert s.md.coSimulation.providesDirectionalDerivative
    lo, hi = s.get("min_length", "max_length")
    try:
        for pressure, frac in points:
            length = lo + frac * (hi - lo)
            # Friction history sits 30 um behind (mid-presliding at 100 um): off the reversal kink.
            s.step(pressure=pressure, length=length - 3e-5)
            base = dict(pressure=pressure, length=length)
            for j, name in enumerate(INPUTS):
                h = 1e-6 * abs(base[name]) + (1e-3 if name == "pressure" else 0.0)
                seed = [1.0 if k == j else 0.0 for k in range(2)]
                s.set(**base)
                exact = directional(s, OUTPUTS, INPUTS, seed)
                up = s.at(*OUTPUTS, **{**base, name: base[name] + h})
                down = s.at(*OUTPUTS, **{**base, name: base[name] - h})
                for out, e, a, b in zip(OUTPUTS, exact, up, down):
                    central = (a - b) / (2 * h)
                    scale = max(abs(e), abs(central))
                    assert abs(e - central) <= 1e-5 * scale + 1e-12, (
                        f"{case} P={pressure} L={length}: d{out}/d{name} exact {e} central {central}"
                    )
    finally:
        s.close()


def test_seed_combines_linearly_and_pass_through_is_identity():
    s = Slave("McKibbenMuscle", preset=1, bladder_model=1)
    try:
        s.set(pressure=3e5, length=0.08)
        dp, dl = directional(s, ["force"], INPUTS, [1.0, 0.0])[0], directional(s, ["force"], INPUTS, [0.0, 1.0])[0]
        both = directional(s, ["force"], INPUTS, [2.0, -3.0])[0]
        assert both == pytest.approx(2 * dp - 3 * dl, rel=1e-14)
    finally:
        s.close()
    p = Slave("PassThrough")
    try:
        assert directional(p, ["y"], ["u"], [2.5]) == [2.5]
    finally:
        p.close()


def test_models_without_partials_declare_it():
    from fmpy import read_model_description

    from conftest import fmu_path

    for model in ["KnittedMuscle", "MultiferroicMotor"]:
        md = read_model_description(fmu_path(model))
        assert not md.coSimulation.providesDirectionalDerivative, model


JOINT_OUTPUTS = ["jointTorque", "flexor_force", "extensor_force", "flexor_pressure", "extensor_pressure",
                 "flexor_length", "extensor_length"]
JOINT_INPUTS = ["actuatorInput", "jointPosition", "jointVelocity"]


@pytest.mark.parametrize(
    "parameters",
    [
        dict(),
        dict(bladder_model=2, bladder_layers=8),
        dict(bladder_model=1, friction=True),
        dict(bladder_model=1, command_mode=1),
    ],
    ids=["ideal", "thick wall", "thin wall + friction", "thin wall, torque command"],
)
def test_joint_partials_match_central_differences(parameters):
    s = Slave("McKibbenJoint", **parameters)
    try:
        # Inside the pressure range (no saturation) and with friction mid-presliding.
        torque = parameters.get("command_mode") == 1
        for u, q in [(0.3, 0.05), (-0.5, -0.1)] if torque else [(1e5, 0.05), (-2e5, -0.1)]:
            s.step(actuatorInput=u, jointPosition=q + 1e-3)
            base = dict(actuatorInput=u, jointPosition=q, jointVelocity=0.0)
            s.set(**base)
            for j, name in enumerate(JOINT_INPUTS):
                h = (1e-6 if torque else 1.0) if name == "actuatorInput" else 1e-7
                seed = [1.0 if k == j else 0.0 for k in range(3)]
                s.set(**base)
                exact = directional(s, JOINT_OUTPUTS, JOINT_INPUTS, seed)
                up = s.at(*JOINT_OUTPUTS, **{**base, name: base[name] + h})
                down = s.at(*JOINT_OUTPUTS, **{**base, name: base[name] - h})
                for out, e, a, b in zip(JOINT_OUTPUTS, exact, up, down):
                    central = (a - b) / (2 * h)
                    # Absolute slack: the torque solver meets the command to rounding (1e-16 N m / h).
                    assert abs(e - central) <= 1e-5 * max(abs(e), abs(central)) + 1e-8, (
                        f"{parameters} u={u} q={q}: d{out}/d{name} exact {e} central {central}"
                    )
    finally:
        s.close()
