"""The robot joint under FMPy's FMU2Slave (`actuator-fmus robot-joint`) reproduces the committed
trajectory tests/data/robot_joint_ref.csv, which tests/all/robot_joint_runs.rs checks the `fmi` crate
against: both importers give the same trajectory."""

import math

from conftest import ROOT


def _example():
    from actuator_fmus import robot_joint

    return robot_joint


def test_fmpy_matches_the_reference_trajectory():
    rj = _example()
    rows = rj.simulate(rj.load_parameters())
    header, reference = rj.read_csv(ROOT / "tests" / "data" / "robot_joint_ref.csv")
    assert header == rj.COLUMNS
    assert len(rows) == len(reference)
    for row, want in zip(rows, reference):
        assert row[0] == want[0]
        assert abs(row[1] - want[1]) <= 1e-9, f"t = {row[0]}: q {row[1]} vs {want[1]}"
        for name, a, b in zip(rj.COLUMNS, row, want):
            assert abs(a - b) <= 1e-9 * max(abs(b), 1.0), f"t = {row[0]}: {name} {a} vs {b}"


def test_torque_is_the_pulley_times_the_force_difference():
    rj = _example()
    p = dict(rj.load_parameters(), record_every=1)
    rows = rj.simulate(p, stop_time=0.5)
    r, L0, b, n = p["moment_arm"], p["rest_length"], 0.1113, 3.74
    q_before = 0.0  # each step's forces are at the lengths of the angle at its start
    for t, q, dq, q_ref, p1, p2, f1, f2, torque in rows:
        assert torque == r * (f1 - f2)
        # Eq. 2.3 for the ideal muscle at the length the pulley gives each muscle.
        for pressure, length, force in ((p1, L0 - r * q_before, f1), (p2, L0 + r * q_before, f2)):
            assert math.isclose(force, pressure * (3 * length**2 - b**2) / (4 * math.pi * n**2), rel_tol=1e-9)
        q_before = q
