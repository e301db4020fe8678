"""MultiferroicMotor under FMPy: what the motor must show (dissertation chapter 3)."""

import math

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from conftest import fmu_path

FMU = fmu_path("MultiferroicMotor")
OUTPUTS = [
    "torque",
    "rotor_angle",
    "rotor_speed",
    "onion_angle",
    "offset_angle",
    "magnetostatic_energy",
    "magnetoelastic_energy",
    "applied_strain_direction",
]
START = {
    v.name: float(v.start) for v in read_model_description(FMU).modelVariables if v.type == "Real" and v.start is not None
}


def locked_sweep(direction_deg, max_stress, points=400):
    """Rotor locked, stress ramped 0 -> max_stress at a fixed direction, one step per point."""
    t = np.linspace(0.0, 1.0, points + 1)
    signals = np.zeros(t.size, dtype=[("time", float), ("stress", float)])
    signals["time"] = t
    signals["stress"] = max_stress * t
    return simulate_fmu(
        FMU,
        input=signals,
        start_values={"rotor_locked": True, "strain_direction": math.radians(direction_deg)},
        output=["stress"] + OUTPUTS,
        stop_time=1.0,
        output_interval=1.0 / points,
    )


def stepping(period, stop_time, step, **start):
    return simulate_fmu(
        FMU,
        start_values={"schedule": 1, "step_period": period, **start},
        output=OUTPUTS,
        stop_time=stop_time,
        output_interval=step,
    )


def test_locked_rotor_stress_sweep_of_fig_3_3a():
    r = locked_sweep(-45.0, 2e9)
    assert np.all(r["rotor_angle"] == 0.0) and np.all(r["rotor_speed"] == 0.0)
    best = np.argmax(r["torque"])
    # Section 3.2.2: "a maximum torque value of about 2.1e-18 Nm", within 5%.
    assert abs(r["torque"][best] / 2.1e-18 - 1.0) < 0.05
    assert 100e6 < r["stress"][best] < 250e6
    # High stress: the onion state swings towards 45 degrees and the torque falls.
    assert math.degrees(r["offset_angle"][-1]) > 40.0
    assert r["torque"][-1] < 0.85 * r["torque"][best]


def test_torque_proportional_to_small_stress():
    # Near alignment the onion barely turns, so the torque balances the magnetoelastic torque at
    # psi = 0 (eq. 3.4): tau = -(3/2) lambda_s V sigma sin(2 * 45 deg) = -(3/2) lambda_s V sigma.
    r = locked_sweep(-45.0, 20e6, points=20)
    # FMPy records each row after the step that used it: the first two rows hold zero stress.
    loaded = r["stress"] > 0
    assert loaded.sum() >= 18
    stress, torque = r["stress"][loaded], r["torque"][loaded]
    per_pa = torque / stress
    expected = -1.5 * START["magnetostriction"] * START["wall_volume"]
    assert np.allclose(per_pa, expected, rtol=5e-3)
    # Proportional: doubling the stress doubles the torque.
    assert abs(per_pa[-1] / per_pa[0] - 1.0) < 5e-3


def test_fig_3_3b_offset_of_23_degrees():
    r = simulate_fmu(
        FMU,
        start_values={"rotor_locked": True, "strain_direction": math.radians(-45), "stress": 200e6},
        output=OUTPUTS,
        stop_time=1e-5,
        output_interval=1e-6,
    )
    assert np.all(np.abs(np.degrees(r["offset_angle"]) - 23.0) < 1.0)


def test_twelve_steps_of_sixty_degrees():
    # Section 3.2.2: the strain direction steps by 60 degrees every 100 us (the default scene);
    # the free rotor follows one step per period.
    period = START["step_period"]
    r = stepping(period, 12 * period, 1e-6)
    assert abs(math.degrees(r["rotor_angle"][-1]) - 720.0) < 10.0
    for k in range(1, 13):
        i = np.argmin(np.abs(r["time"] - k * period))
        assert abs(math.degrees(r["rotor_angle"][i]) - 60.0 * k) < 1.0
    # The applied direction is the schedule's: -30 degrees plus 60 per period.
    middle = np.argmin(np.abs(r["time"] - 5.5 * period))
    assert math.degrees(r["applied_strain_direction"][middle]) == pytest.approx(-30 + 5 * 60)
    assert np.all(np.isfinite(r["torque"]))


def speeds_after_first_period(period):
    r = stepping(period, 12 * period, period / 50)
    speed = r["rotor_speed"][r["time"] > period]
    return speed.min() / speed.max(), r


def test_fast_schedule_turns_continuously_slow_one_in_steps():
    # A 60-degree step takes about 20 us (relaxation time 3.1 us): a 25 us period keeps the rotor
    # moving, a 200 us one lets it stop between steps.
    fast, r_fast = speeds_after_first_period(25e-6)
    slow, r_slow = speeds_after_first_period(200e-6)
    assert fast > 0.1, fast
    assert slow < 1e-3, slow
    for r in (r_fast, r_slow):
        assert abs(math.degrees(r["rotor_angle"][-1]) - 720.0) < 10.0


def common_points(r, times):
    idx = [int(np.argmin(np.abs(r["time"] - t))) for t in times]
    assert np.allclose(r["time"][idx], times, rtol=1e-9, atol=1e-15)
    return r[idx]


# Stated tolerance: angles agree within 1e-5 rad at common time points (the integrator's local
# tolerance is 1e-6 rad per substep).
ANGLE_TOLERANCE = 1e-5


def test_communication_step_size_does_not_change_the_answer():
    period = 100e-6
    # 1e-9 s vs 1e-6 s over the first step's transient, compared every microsecond.
    fine = stepping(period, 10e-6, 1e-9)
    mid = stepping(period, 3e-3, 1e-6)
    coarse = stepping(period, 3e-3, 1e-3)
    for r in (fine, mid, coarse):
        for name in OUTPUTS:
            assert np.all(np.isfinite(r[name])), name
    early = np.arange(1, 11) * 1e-6
    a, b = common_points(fine, early), common_points(mid, early)
    assert np.max(np.abs(a["rotor_angle"] - b["rotor_angle"])) < ANGLE_TOLERANCE
    assert np.max(np.abs(a["onion_angle"] - b["onion_angle"])) < ANGLE_TOLERANCE
    assert b["rotor_angle"][-1] > 0.5, "the rotor is moving during the comparison"
    # 1e-6 s vs 1e-3 s over 30 schedule steps, compared every millisecond.
    late = np.array([1e-3, 2e-3, 3e-3])
    b, c = common_points(mid, late), common_points(coarse, late)
    assert np.max(np.abs(b["rotor_angle"] - c["rotor_angle"])) < ANGLE_TOLERANCE
    assert np.max(np.abs(b["onion_angle"] - c["onion_angle"])) < ANGLE_TOLERANCE
    assert abs(math.degrees(c["rotor_angle"][-1]) - 1800.0) < 0.1


def test_bad_geometry_fails_initialization():
    # A 600 nm bar does not fit inside the 500 nm hole of the ring.
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        simulate_fmu(FMU, start_values={"bar_length": 600e-9}, stop_time=1e-6)
