"""FreeBladder, the McKibben muscle's latex tube without its sleeve, under FMPy: its diameter holds
the pressure by radial equilibrium through the thick wall (Rivlin's integral, checked against an
independent quadrature and bisection here), at zero pressure it is the uniaxial Mooney-Rivlin curve
of Fig. 2.9, and it balloons at 2 (C1/lambda_1 + C2 lambda_1) ln(D_RO / D_RI), where the FMU flags
the clamped input and logs it once."""

import math

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import Slave, fmu_path

# Table 2.1 muscle D's tube and the latex of Fig. 2.9 (the FMU's defaults).
L_R0, D_RI, T, C1, C2 = 0.1336, 3.8e-3, 0.25e-3, 161e3, 39e3
D_RO = D_RI + 2 * T


def held_pressure(l1, l2):
    """int (sigma_22 - sigma_33) dr / r through the wall (eq. 2.9b, radial equilibrium) for an inner
    hoop stretch l2 at axial stretch l1, by Simpson's rule in ln r."""
    r_in = l2 * D_RI / 2
    r_out = math.sqrt(r_in**2 + ((D_RO / 2) ** 2 - (D_RI / 2) ** 2) / l1)  # incompressibility
    t = np.linspace(math.log(r_in), math.log(r_out), 4001)
    r = np.exp(t)
    big_r = np.sqrt((D_RO / 2) ** 2 - l1 * (r_out**2 - r**2))
    lt, lr = r / big_r, big_r / (l1 * r)
    h = 2 * C1 * (lt**2 - lr**2) - 2 * C2 * (1 / lt**2 - 1 / lr**2)
    step = t[1] - t[0]
    return step / 3 * (h[0] + h[-1] + 4 * h[1:-1:2].sum() + 2 * h[2:-1:2].sum())


def hoop_stretch(p, l1):
    """The inner hoop stretch that holds p, by bisection (the held pressure rises with it)."""
    lo, hi = 1e-2, 1e2
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        if held_pressure(l1, mid) < p:
            lo = mid
        else:
            hi = mid
    return math.sqrt(lo * hi)


@pytest.mark.parametrize("pressure, stretch", [(3e4, 1.0), (4e4, 1.3), (-5e4, 0.9), (1.5e4, 2.5)])
def test_diameter_holds_the_pressure_through_the_thick_wall(pressure, stretch):
    s = Slave("FreeBladder")
    d_in, l1, l2, l3, clamped = s.at("inner_diameter", "stretch_axial", "stretch_hoop", "stretch_radial",
                                     "input_clamped", pressure=pressure, length=stretch * L_R0)
    s.close()
    assert not clamped
    assert l1 == pytest.approx(stretch, rel=1e-14)
    assert l2 == pytest.approx(hoop_stretch(pressure, stretch), rel=1e-9)
    assert d_in == pytest.approx(l2 * D_RI, rel=1e-14)
    assert l1 * l2 * l3 == pytest.approx(1.0, rel=1e-14)


def test_unpressurized_tube_is_the_uniaxial_mooney_rivlin_curve_of_fig_2_9():
    s = Slave("FreeBladder")
    a0 = math.pi / 4 * (D_RO**2 - D_RI**2)
    for lam in [0.8, 1.0, 2.0, 4.0]:
        force, hoop = s.at("force", "stress_hoop", pressure=0.0, length=lam * L_R0)
        nominal = 2 * (C1 + C2 / lam) * (lam - 1 / lam**2)
        assert force == pytest.approx(nominal * a0, rel=1e-12, abs=1e-12)
        assert abs(hoop) < 1e-6
    s.close()


def test_inflation_is_monotonic_up_to_the_ballooning_pressure(recording_log):
    s = Slave("FreeBladder", log=recording_log)
    limit = s.at("ballooning_pressure", pressure=0.0, length=L_R0)
    assert limit == pytest.approx(2 * (C1 + C2) * math.log(D_RO / D_RI), rel=1e-14)
    assert limit == pytest.approx(49_445.58, rel=1e-6)
    pressures = np.linspace(-101325.0, 0.99 * limit, 200)
    volumes = np.array([s.at("volume", pressure=p) for p in pressures])
    compliance = np.array([s.at("compliance", pressure=p) for p in pressures])
    assert np.all(np.diff(volumes) > 0) and np.all(compliance > 0)
    # The compliance is dV/dP: it integrates back to the volume change (trapezoids, fine grid).
    fine = np.linspace(0.0, 0.5 * limit, 2001)
    c = np.array([s.at("compliance", pressure=p) for p in fine])
    v0, v1 = s.at("volume", pressure=fine[0]), s.at("volume", pressure=fine[-1])
    assert np.sum(0.5 * (c[1:] + c[:-1]) * np.diff(fine)) == pytest.approx(v1 - v0, rel=1e-5)
    # Above the ballooning pressure the tube has no equilibrium: evaluated just below it, flagged, and
    # logged once for the whole excursion.
    before = len(recording_log.records)
    for p in [1.2 * limit, 2 * limit, 1e6]:
        s.step(0.01, pressure=p)
        assert s.get("input_clamped")
        assert math.isfinite(s.get("volume"))
    assert len(recording_log.records) - before == 1
    assert recording_log.contains("ballooning pressure")
    s.step(0.01, pressure=0.5 * limit)
    assert not s.get("input_clamped")
    s.close()


def test_simulate_fmu_co_simulation_and_model_exchange_agree():
    t = np.linspace(0.0, 1.0, 11)
    signals = np.array(list(zip(t, 4e4 * t, np.full_like(t, L_R0))),
                       dtype=[("time", float), ("pressure", float), ("length", float)])
    kw = dict(input=signals, output=["volume", "force"], stop_time=1.0, output_interval=0.1)
    cs = simulate_fmu(fmu_path("FreeBladder"), **kw)
    me = simulate_fmu(fmu_path("FreeBladder"), fmi_type="ModelExchange", **kw)
    # Co-Simulation records the output from the input at the previous communication point.
    assert np.allclose(me["volume"][:-1], cs["volume"][1:], rtol=1e-9)
    assert np.all(np.diff(cs["volume"][1:]) > 0)
