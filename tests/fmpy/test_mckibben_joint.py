"""McKibbenJoint driven the way gazebo-fmi drives an actuator FMU: every physics step it sets
actuatorInput, jointPosition and jointVelocity, calls doStep and reads jointTorque. The torque
must be r (F_flexor - F_extensor) of two McKibbenMuscle FMUs at the same pressures and lengths."""

import math

import numpy as np
import pytest

from conftest import ROOT, Slave

R, L0, PC, PMAX = 0.015, 0.09, 3.5e5, 7e5


def _pressures(u, pc=PC, pmax=PMAX):
    return min(max(pc + 0.5 * u, 0.0), pmax), min(max(pc - 0.5 * u, 0.0), pmax)


@pytest.mark.parametrize(
    "muscle",
    [
        {},
        {"preset": 4, "bladder_model": 1},
        {"preset": 1, "bladder_model": 2, "bladder_layers": 8, "friction": True, "friction_coefficient": 2e-5},
    ],
    ids=["ideal", "D-thin", "A-thick-friction"],
)
def test_torque_is_the_pulley_times_two_muscle_fmus(muscle):
    # Rest lengths inside every preset's length range; angles within +-0.3 rad (4.5 mm of stroke).
    L0f = L0e = 0.1 if muscle.get("preset") == 4 else 0.09
    joint = Slave("McKibbenJoint", moment_arm=R, flexor_rest_length=L0f, extensor_rest_length=L0e, **muscle)
    flexor = Slave("McKibbenMuscle", length=L0f, **muscle)
    extensor = Slave("McKibbenMuscle", length=L0e, **muscle)
    h = 1e-3
    worst = 0.0
    for k in range(600):
        t = k * h
        q = 0.3 * math.sin(2 * math.pi * 1.5 * t)
        dq = 0.3 * 2 * math.pi * 1.5 * math.cos(2 * math.pi * 1.5 * t)
        u = 4e5 * math.sin(2 * math.pi * 0.7 * t)
        joint.step(h, actuatorInput=u, jointPosition=q, jointVelocity=dq)
        p1, p2 = _pressures(u)
        flexor.step(h, pressure=p1, length=L0f - R * q)
        extensor.step(h, pressure=p2, length=L0e + R * q)
        f1, f2 = flexor.get("force"), extensor.get("force")
        torque = joint.get("jointTorque")
        assert joint.get("flexor_force", "extensor_force") == [f1, f2]
        assert torque == pytest.approx(R * (f1 - f2), rel=1e-12, abs=1e-12)
        worst = max(worst, abs(torque))
    # The pair really works: a 400 kPa difference gives a torque of a few tenths of a N.m.
    assert worst > 0.1
    for s in (joint, flexor, extensor):
        s.close()


def test_friction_makes_the_torque_depend_on_the_direction_of_motion():
    # Muscle D (thin wall) around 0.12 m pulls at 350 kPa; friction as in the hysteresis example.
    joint = Slave("McKibbenJoint", preset=4, bladder_model=1, friction=True, friction_coefficient=2e-5,
                  flexor_rest_length=0.12, extensor_rest_length=0.12)
    torques = {}
    for direction, path in (("up", np.linspace(-0.3, 0.3, 61)), ("down", np.linspace(0.3, -0.3, 61))):
        for q in path:
            joint.step(actuatorInput=0.0, jointPosition=q)
            if abs(q) < 1e-12:
                torques[direction] = joint.get("jointTorque", "flexor_pressure")
    joint.close()
    # Friction opposes the motion: moving up (flexor shortening, extensor lengthening) the torque at
    # q = 0 is negative, moving down positive, and the two are symmetric (equal muscles, u = 0).
    (up, p), (down, _) = torques["up"], torques["down"]
    assert up < -0.05 and down > 0.05
    assert up == pytest.approx(-down, rel=1e-9)
    # Eq. 2.4's friction is Cf P_eff per muscle, so the gap is at most 2 r (2 Cf P).
    assert down - up <= 4 * R * 2e-5 * p * 1.0000001


def test_saturation_and_ranges():
    joint = Slave("McKibbenJoint")
    b = 0.1113
    assert joint.get("max_position") == pytest.approx((b - L0) / R, rel=1e-12)
    assert joint.get("min_position") == pytest.approx(-(b - L0) / R, rel=1e-12)
    assert joint.at("flexor_pressure", "extensor_pressure", actuatorInput=5e6) == [PMAX, 0.0]
    assert joint.at("flexor_pressure", "extensor_pressure", actuatorInput=-5e6) == [0.0, PMAX]
    # Symmetric pair at q = 0 and u = 0: no torque; antisymmetric in (u, q).
    assert joint.at("jointTorque", actuatorInput=0.0, jointPosition=0.0) == pytest.approx(0.0, abs=1e-15)
    t1 = joint.at("jointTorque", actuatorInput=2e5, jointPosition=0.2)
    t2 = joint.at("jointTorque", actuatorInput=-2e5, jointPosition=-0.2)
    assert t1 == pytest.approx(-t2, rel=1e-12)
    joint.close()


def test_out_of_range_angle_warns_and_stays_finite(recording_log):
    joint = Slave("McKibbenJoint", log=recording_log, preset=1, bladder_model=2)
    lo, hi = joint.get("min_position", "max_position")
    for q in (hi + 1.0, lo - 1.0, 2 * math.pi):  # 2 pi: the declared maximum
        joint.step(actuatorInput=1e5, jointPosition=q)
        assert math.isfinite(joint.get("jointTorque"))
        assert joint.get("input_clamped")
    assert recording_log.contains("jointPosition")
    joint.close()


def test_refuses_a_common_mode_above_the_supply(recording_log):
    with pytest.raises(Exception):
        Slave("McKibbenJoint", log=recording_log, common_mode_pressure=8e5, max_pressure=7e5)
    assert recording_log.contains("common_mode_pressure")


def test_refuses_a_wall_thicker_than_the_bladder_is_long(recording_log):
    # A ring, not the long tube the bladder models assume (as McKibbenMuscle refuses it).
    with pytest.raises(Exception):
        Slave("McKibbenJoint", log=recording_log, preset=0, bladder_model=1, bladder_length=1e-3,
              bladder_thickness=2e-3)
    assert recording_log.contains("bladder_thickness 0.002 m exceeds bladder_length 0.001 m")


def test_robot_joint_with_the_joint_fmu_reproduces_the_two_muscle_trajectory():
    """The robot-joint example's pendulum with McKibbenJoint in place of two McKibbenMuscle FMUs,
    stepped like a robot simulator: the committed trajectory to 1e-9 rad."""
    from actuator_fmus import robot_joint as rj

    p = rj.load_parameters()
    joint = Slave("McKibbenJoint", moment_arm=p["moment_arm"], flexor_rest_length=p["rest_length"],
                  extensor_rest_length=p["rest_length"], common_mode_pressure=p["common_mode_pressure"],
                  max_pressure=p["max_pressure"])
    _, reference = rj.read_csv(ROOT / "tests" / "data" / "robot_joint_ref.csv")
    h, mgl = p["step"], p["mass"] * p["gravity"] * p["com_distance"]
    q, dq, rows = 0.0, 0.0, []
    n = int(round(p["stop_time"] / h))
    for k in range(n):
        q_ref, dq_ref = rj.reference(p, k * h)
        u = p["feedforward_gain"] * math.sin(q_ref) + p["kp"] * (q_ref - q) + p["kd"] * (dq_ref - dq)
        joint.step(h, actuatorInput=u, jointPosition=q, jointVelocity=dq)
        torque = joint.get("jointTorque")
        dq = dq + h * (torque - p["damping"] * dq - mgl * math.sin(q)) / p["inertia"]
        q = q + h * dq
        if (k + 1) % p["record_every"] == 0 or k + 1 == n:
            rows.append((q, torque))
    joint.close()
    assert len(rows) == len(reference)
    for (q, torque), want in zip(rows, reference):
        assert abs(q - want[1]) <= 1e-9
        assert abs(torque - want[8]) <= 1e-9


def test_strands_stretch_past_max_position_and_a_short_muscle_goes_slack():
    """Bare sleeves (b = 111.3 mm, E A = 9400 N): past max_position the extensor's strands stretch,
    F = eq. 2.3 at b + (E A / b) (L - b), continuous at max_position; the flexor, shorter than its
    free contraction b / sqrt(3), is slack with force 0; past 5% strand strain the angle is clamped."""
    joint = Slave("McKibbenJoint")
    b, n, ea = 0.1113, 3.74, 9400.0  # the start values of strand_length, turns, strand_rigidity
    k_s = ea / b
    u = 1e5
    extensor_pressure = PC - 0.5 * u
    at_b = extensor_pressure * 2 * b * b / (4 * math.pi * n * n)  # eq. 2.3 at L = b
    hi = joint.get("max_position")
    assert hi == pytest.approx((b - L0) / R, rel=1e-12)
    left = joint.at("extensor_force", actuatorInput=u, jointPosition=hi - 1e-9)
    right = joint.at("extensor_force", actuatorInput=u, jointPosition=hi + 1e-9)
    assert abs(right - left) <= 2e-9 * R * k_s * 1.01
    breaking = (1.05 * b - L0) / R
    forces = []
    for q in np.linspace(hi, breaking, 201):
        force, clamped, slack = joint.at("extensor_force", "input_clamped", "flexor_slack", actuatorInput=u,
                                         jointPosition=q)
        length = L0 + R * q
        assert not clamped
        assert force == pytest.approx(at_b + k_s * (length - b), rel=1e-9)
        # The flexor (L0 - R q) is slack below b / sqrt(3) and carries no force there.
        assert bool(slack) == (L0 - R * q < b / math.sqrt(3))
        forces.append(force)
    assert np.all(np.diff(forces) > 0)
    flexor, slack = joint.at("flexor_force", "flexor_slack", actuatorInput=u, jointPosition=1.75)
    assert slack and flexor == 0.0
    assert joint.at("input_clamped", actuatorInput=u, jointPosition=breaking + 0.01)
    joint.close()
