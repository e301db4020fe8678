"""PulleyJoint, the mechanical side of the robot joint: the pendulum settles where the muscle torque
balances gravity, swings at the small-oscillation frequency, splits long steps, and its controller
saturates as documented."""

import math

import numpy as np
import pytest

from conftest import Slave

R, MGL, INERTIA = 0.015, 0.25 * 9.81 * 0.12, 0.004


def test_settles_where_muscle_torque_balances_gravity():
    j = Slave("PulleyJoint")
    for _ in range(8000):  # 8 s at 1 ms; the damped joint settles in about 2 s
        j.step(1e-3, flexor_force=30.0, extensor_force=20.0)
    q, dq = j.get("joint_angle", "joint_velocity")
    j.close()
    # r (F_f - F_e) = m g l sin q
    assert q == pytest.approx(math.asin(R * 10.0 / MGL), rel=1e-6)
    assert abs(dq) < 1e-6


def test_undamped_swing_has_the_pendulum_frequency():
    j = Slave("PulleyJoint", damping=0.0)
    h, n = 1e-4, 40000
    q = np.empty(n)
    for k in range(n):
        j.step(h, flexor_force=20.0 + 0.2, extensor_force=20.0)  # small offset: a small swing
        q[k] = j.get("joint_angle")
    j.close()
    q_star = math.asin(R * 0.2 / MGL)
    up = np.nonzero((q[:-1] < q_star) & (q[1:] >= q_star))[0]
    period = np.mean(np.diff(up)) * h
    expected = 2 * math.pi / math.sqrt(MGL * math.cos(q_star) / INERTIA)
    assert period == pytest.approx(expected, rel=2e-3)
    # Semi-implicit Euler conserves the swing: the amplitude neither grows nor decays.
    first, last = q[: n // 4], q[-n // 4 :]
    assert np.ptp(last) == pytest.approx(np.ptp(first), rel=1e-2)


def test_a_long_step_is_split_and_lands_near_the_fine_answer():
    coarse = Slave("PulleyJoint")
    coarse.step(2.0, flexor_force=30.0, extensor_force=20.0)
    fine = Slave("PulleyJoint")
    for _ in range(2000):
        fine.step(1e-3, flexor_force=30.0, extensor_force=20.0)
    qc, qf = coarse.get("joint_angle"), fine.get("joint_angle")
    coarse.close()
    fine.close()
    assert math.isfinite(qc)
    assert qc == pytest.approx(qf, abs=2e-3)


def test_controller_saturates_and_lengths_follow_the_pulley():
    j = Slave("PulleyJoint", kp=1e11)
    # At t = 0 the reference is 0 and the joint is at rest: common-mode pressure on both.
    assert j.get("flexor_pressure", "extensor_pressure") == [350000.0, 350000.0]
    j.step(1e-3, flexor_force=0.0, extensor_force=50.0)  # pulled to q < 0: huge error, kp huge
    q = j.get("joint_angle")
    assert q < 0
    assert j.get("flexor_pressure", "extensor_pressure") == [700000.0, 0.0]
    assert j.get("flexor_length", "extensor_length") == pytest.approx([0.09 - R * q, 0.09 + R * q], rel=1e-15)
    j.close()
