"""The linearized-muscle page's claims (actuator_fmus.linearized), on a small grid: the stiffness
read through fmi2GetDirectionalDerivative is the FMU's own `stiffness` output (friction off), it is
affine in pressure at each length while the bladder is in contact (the page's K1 (P - P0)), and the
threshold pressure is not where that stiffness vanishes."""

import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
from actuator_fmus import linearized as generate  # noqa: E402


@pytest.mark.parametrize("name", ["A", "D"])
def test_stiffness_is_affine_in_pressure_in_contact(name):
    m = generate.Muscle(generate.MUSCLES[name])
    try:
        lo, hi = m.min_length, m.max_length
        for L in np.linspace(lo + 0.3 * (hi - lo), lo + 0.9 * (hi - lo), 5):
            threshold = m.at(0.0, L)[3]
            pressures = np.linspace(max(threshold, 0.0) + 20e3, 700e3, 6)
            K = []
            for P in pressures:
                _, k, _, _ = m.at(P, L)
                own = m.fmu.getReal([m.vr["stiffness"]])[0]
                assert k == pytest.approx(own, rel=1e-9)
                K.append(k)
            K = np.array(K)
            slope, intercept = np.polyfit(pressures, K, 1)
            assert np.abs(np.polyval([slope, intercept], pressures) - K).max() <= 1e-9 * np.abs(K).max()
            assert slope > 0
            # The zero of the affine stiffness lies below the threshold: stiff already at P_th.
            assert -intercept / slope < threshold
    finally:
        m.close()
