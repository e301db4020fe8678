"""McKibbenMuscle under FMPy: the ideal Gaylord force, eq. 2.3 (dissertation section 2.2.1)."""

import math

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from conftest import fmu_path

FMU = fmu_path("McKibbenMuscle")
B, N = 0.1113, 3.74  # Table 2.1, muscle A: the model's start values


def gaylord(p, length):
    """Eq. 2.3, F = P (3 L^2 - b^2) / (4 pi n^2)."""
    return p * (3 * length**2 - B**2) / (4 * math.pi * N**2)


def ramps(stop=1.0):
    """Pressure ramps 0 -> 600 kPa while length saw-tooths five times over 0.3 b .. 0.99 b."""
    t = np.linspace(0.0, stop, 501)
    frac = (5 * t / stop) % 1.0
    signals = np.zeros(t.size, dtype=[("time", float), ("pressure", float), ("length", float)])
    signals["time"] = t
    signals["pressure"] = 6e5 * t / stop
    signals["length"] = B * (0.3 + 0.69 * frac)
    return signals


def run(**kwargs):
    return simulate_fmu(FMU, output=["pressure", "length", "force", "volume"], **kwargs)


def test_defaults_are_muscle_a():
    md = read_model_description(FMU)
    start = {v.name: float(v.start) for v in md.modelVariables if v.type == "Real" and v.start is not None}
    assert start["strand_length"] == B and start["turns"] == N


def test_force_follows_eq_2_3_along_input_ramps():
    # signed_force: eq. 2.3 as written, negative below b / sqrt(3).
    r = run(input=ramps(), stop_time=1.0, output_interval=0.002, start_values={"signed_force": True})
    assert len(r) > 100
    pairs = {(p, length) for p, length in zip(r["pressure"], r["length"])}
    assert len(pairs) >= 100, "the ramps must visit 100+ distinct (P, L) points"
    expected = gaylord(r["pressure"], r["length"])
    scale = np.maximum(np.abs(expected), 1e-9 * 6e5 * B**2)
    assert np.all(np.abs(r["force"] - expected) <= 1e-9 * scale)
    volume = (B**2 * r["length"] - r["length"] ** 3) / (4 * math.pi * N**2)  # eq. 2.2
    assert np.allclose(r["volume"], volume, rtol=1e-12, atol=0)


def test_by_default_the_muscle_cannot_push():
    # Tension only: eq. 2.3 where it is positive; 0 and slack (a Boolean output, read through
    # fmi2GetBoolean) below b / sqrt(3), where eq. 2.3 would push.
    r = simulate_fmu(FMU, output=["pressure", "length", "force", "slack"], input=ramps(),
                     stop_time=1.0, output_interval=0.002)
    expected = gaylord(r["pressure"], r["length"])
    pushing = expected < 0
    assert pushing.sum() > 50 and (~pushing).sum() > 50
    assert np.array_equal(r["slack"].astype(bool), pushing)
    assert np.all(r["force"][pushing] == 0.0)
    taut = ~pushing
    scale = np.maximum(np.abs(expected[taut]), 1e-9 * 6e5 * B**2)
    assert np.all(np.abs(r["force"][taut] - expected[taut]) <= 1e-9 * scale)


@pytest.mark.parametrize("pressure", [1e5, 3.45e5, 6.9e5])
def test_zero_force_at_largest_volume(pressure):
    # Section 2.2.1: the tension vanishes at L = b / sqrt(3), 57.7 % of the strand length.
    r = run(start_values={"pressure": pressure, "length": B / math.sqrt(3)}, stop_time=0.01)
    full_scale = pressure * 2 * B**2 / (4 * math.pi * N**2)
    assert np.all(np.abs(r["force"]) < 1e-12 * full_scale)
    assert r["force"][0] != gaylord(pressure, 0.99 * B / math.sqrt(3))


def test_force_is_linear_in_pressure():
    lengths = np.linspace(0.3 * B, 0.99 * B, 12)
    forces = {}
    for p in (1e5, 2e5, 6e5):
        forces[p] = np.array(
            [run(start_values={"pressure": p, "length": L, "signed_force": True}, stop_time=0.001)["force"][-1]
             for L in lengths]
        )
    assert np.allclose(forces[2e5], 2 * forces[1e5], rtol=1e-12)
    assert np.allclose(forces[6e5], 6 * forces[1e5], rtol=1e-12)
    assert np.all(np.diff(forces[6e5]) > 0), "force rises with length (Fig. 2.3)"


def test_calculated_max_length_is_the_strand_length():
    r = simulate_fmu(FMU, output=["max_length"], stop_time=0.001)
    assert r["max_length"][-1] == B


STRAND_RIGIDITY = 9400.0  # N, the start value of strand_rigidity
BREAKING = B * (1.0 + 0.05)  # 5% strand strain past b: no muscle survives


@pytest.mark.parametrize("stretch", [1.001, 1.02, 1.049])
def test_strands_stretch_past_b(stretch):
    # Past b the straight strands stretch: F(b) + (E A / b) (L - b), not clamped.
    r = simulate_fmu(FMU, output=["force", "stiffness", "input_clamped"], stop_time=0.001,
                     start_values={"pressure": 4e5, "length": stretch * B})
    k_s = STRAND_RIGIDITY / B
    assert r["force"][-1] == pytest.approx(gaylord(4e5, B) + k_s * (stretch - 1.0) * B, rel=1e-9)
    assert r["stiffness"][-1] == pytest.approx(k_s, rel=1e-12)
    assert not r["input_clamped"][-1]


def test_length_beyond_the_sleeve_is_clamped_and_logged(recording_log):
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(FMU)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(FMU), modelIdentifier="McKibbenMuscle", instanceName="m")
    fmu.instantiate(callbacks=recording_log.callbacks)
    fmu.setupExperiment(startTime=0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([vr["pressure"], vr["length"]], [4e5, 1.2 * B])
    fmu.doStep(0.0, 0.1)  # fmi2OK under the default out-of-range policy, flagged and logged
    force, volume = fmu.getReal([vr["force"], vr["volume"]])
    # Evaluated at the breaking length, 5% strand strain past b.
    at_break = gaylord(4e5, B) + STRAND_RIGIDITY / B * (BREAKING - B)
    assert force == pytest.approx(at_break, rel=1e-9) and volume == 0.0
    where = f"evaluating at pressure 400000 Pa and length {BREAKING!r} m"
    warnings = [(s, c) for s, c, m in recording_log.records if where in m]
    assert warnings == [(0, "logStatusWarning")]
    assert fmu.getBoolean([vr["input_clamped"]]) == [True]
    fmu.terminate()
    fmu.freeInstance()
