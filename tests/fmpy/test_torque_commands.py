"""Commands in the units a controller has: McKibbenJoint's torque mode (command_mode 1),
McKibbenMuscle's pressure for a force (pressure_solver), and PulleyJoint's external pressures.
Every answer is checked against the forward model it inverts."""

import math

import pytest

from conftest import Slave

R, L0, PC, PMAX = 0.015, 0.09, 3.5e5, 7e5

# Every bladder model (0 ideal, 1 thin wall, 2 thick wall), and friction.
MUSCLES = {
    "ideal": ({}, 0.09),
    "D-thin": ({"preset": 4, "bladder_model": 1}, 0.12),
    "A-thick": ({"preset": 1, "bladder_model": 2, "bladder_layers": 8}, 0.09),
    "A-thick-friction": ({"preset": 1, "bladder_model": 2, "bladder_layers": 8, "friction": True,
                          "friction_coefficient": 2e-5}, 0.09),
}


def reachable_range(muscle, rest, q):
    """The torques of the extreme pressure pairs (mode 0) at angle q: the reachable range."""
    j = Slave("McKibbenJoint", moment_arm=R, flexor_rest_length=rest, extensor_rest_length=rest, **muscle)
    lo = j.at("jointTorque", actuatorInput=-2 * PMAX, jointPosition=q)
    hi = j.at("jointTorque", actuatorInput=2 * PMAX, jointPosition=q)
    j.close()
    return lo, hi


@pytest.mark.parametrize("name", list(MUSCLES))
def test_torque_mode_meets_reachable_commands_with_every_bladder_model(name):
    muscle, rest = MUSCLES[name]
    joint = Slave("McKibbenJoint", command_mode=1, moment_arm=R, flexor_rest_length=rest,
                  extensor_rest_length=rest, **muscle)
    check = Slave("McKibbenJoint", moment_arm=R, flexor_rest_length=rest, extensor_rest_length=rest, **muscle)
    h = 1e-3
    for k in range(200):
        q = 0.2 * math.sin(2 * math.pi * 2 * k * h)
        # The reachable range from this joint's own friction history: the saturated ends.
        lo = joint.at("jointTorque", actuatorInput=-1e9, jointPosition=q)
        hi = joint.at("jointTorque", actuatorInput=1e9, jointPosition=q)
        assert hi - lo > 0.1
        command = lo + (hi - lo) * (0.5 + 0.45 * math.sin(2 * math.pi * 3 * k * h))
        joint.step(h, actuatorInput=command, jointPosition=q)
        torque, saturated, pf, pe = joint.get("jointTorque", "torque_saturated", "flexor_pressure",
                                              "extensor_pressure")
        assert not saturated
        assert torque == pytest.approx(command, rel=1e-6, abs=1e-9 * (hi - lo)), (q, command)
        # Around the common mode, inside 0 .. max_pressure.
        assert 0 <= pf <= PMAX and 0 <= pe <= PMAX
        assert pf - PC == pytest.approx(PC - pe, abs=1e-6) or min(pf, pe) == 0 or max(pf, pe) == PMAX
        # The pressures it chose give that torque in pressure mode too (same physics).
        check.step(h, actuatorInput=pf - pe, jointPosition=q)
        assert check.get("jointTorque") == pytest.approx(torque, rel=1e-9, abs=1e-12)
    joint.close()
    check.close()


@pytest.mark.parametrize("name", ["ideal", "D-thin"])
def test_torque_mode_reports_saturation_and_delivers_the_nearest_torque(name):
    muscle, rest = MUSCLES[name]
    lo, hi = reachable_range(muscle, rest, 0.1)
    joint = Slave("McKibbenJoint", command_mode=1, moment_arm=R, flexor_rest_length=rest,
                  extensor_rest_length=rest, jointPosition=0.1, **muscle)
    for command, expected in [(hi + 5.0, hi), (lo - 5.0, lo)]:
        torque, saturated = joint.at("jointTorque", "torque_saturated", actuatorInput=command, jointPosition=0.1)
        assert saturated
        assert torque == pytest.approx(expected, rel=1e-12)
    _, saturated = joint.at("jointTorque", "torque_saturated", actuatorInput=0.5 * (lo + hi), jointPosition=0.1)
    assert not saturated
    joint.close()


def test_pressure_mode_is_unchanged_and_never_saturates():
    joint = Slave("McKibbenJoint")
    torque, saturated = joint.at("jointTorque", "torque_saturated", actuatorInput=1e7, jointPosition=0.0)
    assert not saturated and torque > 0
    joint.close()


@pytest.mark.parametrize("name", ["ideal", "D-thin", "A-thick"])
def test_pressure_for_force_is_inverted_through_the_same_physics(name):
    muscle, length = MUSCLES[name]
    m = Slave("McKibbenMuscle", pressure_solver=True, max_pressure=PMAX, length=length, **muscle)
    top = m.at("force", pressure=PMAX, length=length)
    for fraction in (0.2, 0.5, 0.9):
        p, saturated = m.at("target_pressure", "target_force_saturated", target_force=fraction * top, length=length)
        assert not saturated and 0 < p < PMAX
        assert m.at("force", pressure=p, length=length) == pytest.approx(fraction * top, rel=1e-6)
    p, saturated = m.at("target_pressure", "target_force_saturated", target_force=2 * top, length=length)
    assert saturated and p == PMAX
    m.close()


def test_pressure_for_force_with_the_solver_off_leaves_zero():
    m = Slave("McKibbenMuscle", length=0.09)
    assert m.at("target_pressure", target_force=10.0) == 0.0
    m.close()


def test_pulley_joint_takes_external_pressures_and_bypasses_its_controller():
    j = Slave("PulleyJoint", external_pressures=True, max_pressure=6e5)
    for k, (pf, pe) in enumerate([(1e5, 2e5), (5e5, 0.0), (9e5, -1e4)]):
        j.step(1e-3, flexor_pressure_command=pf, extensor_pressure_command=pe, flexor_force=20.0,
               extensor_force=20.0)
        assert j.get("flexor_pressure", "extensor_pressure") == [min(pf, 6e5), max(pe, 0.0)]
    # Outputs follow the inputs directly (no step needed), as an importer's loop expects.
    assert j.at("flexor_pressure", flexor_pressure_command=2.5e5) == 2.5e5
    j.close()
    # Without the option the controller decides: the commands are ignored.
    j = Slave("PulleyJoint")
    j.step(1e-3, flexor_pressure_command=6e5, extensor_pressure_command=6e5, flexor_force=20.0, extensor_force=20.0)
    pf, pe = j.get("flexor_pressure", "extensor_pressure")
    assert pf + pe == pytest.approx(2 * j.get("common_mode_pressure"), rel=1e-12)
    j.close()


def test_festo_preset_in_the_joint_meets_torque_commands_and_matches_the_muscle_fmu():
    # A DMSP-40 pair (nominal length 0.4 m) on a 30 mm pulley, rest lengths at 5% contraction.
    rest, r = 0.38, 0.03
    joint = Slave("McKibbenJoint", preset=6, command_mode=1, moment_arm=r, flexor_rest_length=rest,
                  extensor_rest_length=rest, max_pressure=6e5, common_mode_pressure=3e5)
    lo = joint.at("jointTorque", actuatorInput=-1e9, jointPosition=0.2)
    hi = joint.at("jointTorque", actuatorInput=1e9, jointPosition=0.2)
    torque, saturated, pf, pe = joint.at("jointTorque", "torque_saturated", "flexor_pressure", "extensor_pressure",
                                         actuatorInput=0.3 * hi + 0.7 * lo, jointPosition=0.2)
    assert not saturated and torque == pytest.approx(0.3 * hi + 0.7 * lo, rel=1e-6)
    joint.close()
    # The same muscles as McKibbenMuscle's preset 6 at those pressures and lengths.
    flexor = Slave("McKibbenMuscle", preset=6, length=rest - r * 0.2)
    extensor = Slave("McKibbenMuscle", preset=6, length=rest + r * 0.2)
    f = flexor.at("force", pressure=pf, length=rest - r * 0.2)
    e = extensor.at("force", pressure=pe, length=rest + r * 0.2)
    assert torque == pytest.approx(r * (f - e), rel=1e-9)
    flexor.close()
    extensor.close()
