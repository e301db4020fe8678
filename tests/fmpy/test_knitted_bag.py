"""The figures docs/knitted-bag.md states (section 1.4's polyethylene bag), measured again
through FMPy with the functions of actuator_fmus.knitted_bag that generate it."""

import math

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import fmu_path

from actuator_fmus import knitted_bag as kb  # noqa: E402

FMU = fmu_path("KnittedMuscle")


def test_the_inextensible_bag_stops_the_stroke_where_the_sleeve_reaches_its_radius():
    # Eq. 1.4: 2 pi R = S_row - 2 m L / n with S_row = pi 153 mm, m = 22, n = 49, L_max = 514 mm.
    expected = 1.0 - 49 * (math.pi * 0.153 - math.pi * 0.085) / (2 * 22) / 0.514
    for pressure in (14e3, 100e3):
        s = kb.stroke(pressure, points=1001, bag_diameter=kb.BAG)
        assert abs(s - expected) < 0.002, (pressure, s, expected)
        assert abs(s - 0.537) < 0.002
        # With friction the bag still binds first, the same at both pressures.
        assert abs(kb.stroke(pressure, points=1001, bag_diameter=kb.BAG, friction=True) - s) < 0.002
    # Friction alone: 58.0%, pressure-independent (eq. 1.21 scales with P).
    a, b = (kb.stroke(p, points=1001, friction=True) for p in (14e3, 100e3))
    assert abs(a - 0.580) < 0.002 and abs(a - b) < 1e-3


def test_the_bags_that_would_give_the_measured_strokes():
    # The document's figures: an inextensible bag stops the ideal cylinder at 42% if it is 67.7 mm
    # across, at 51% if 80.9 mm; a 64.3 mm bag (0.42 of the 153 mm sleeve) at 39.6%. Eq. 1.4 gives the
    # same in closed form: stroke = 1 - n pi (0.153 - d) / (2 m L_max).
    def closed_form(d):
        return 1.0 - 49 * math.pi * (0.153 - d) / (2 * 22) / 0.514
    for target, diameter in ((0.42, 0.0677), (0.51, 0.0809)):
        d = kb.bag_for(target, points=1001)
        assert abs(d - diameter) < 2e-4, (target, d)
        assert abs(closed_form(d) - target) < 2e-3
    s = kb.stroke(14e3, points=1001, bag_diameter=0.42 * 0.153)
    assert abs(s - 0.396) < 0.002 and abs(s - closed_form(0.42 * 0.153)) < 0.002


def test_a_stretching_bag_lengthens_the_stroke_with_pressure():
    start = {"bag_diameter": kb.BAG, "bag_membrane_stiffness": kb.POLYETHYLENE, "friction": True}
    low, high = (kb.stroke(p, points=1001, **start) for p in (14e3, 100e3))
    assert abs(low - 0.572) < 0.002 and abs(high - 0.580) < 0.002


def test_a_fixed_resistance_fitted_to_42_percent_exceeds_the_starting_pull():
    # The document's argument: the tension at 42% contraction, 14 kPa, Cf = 0.25, is 43.4 N, more
    # than twice what the sleeve pulls at 2% contraction (the muscle would not start).
    length, force, _, hi = kb.contraction(14e3, friction=True)
    at_42 = np.interp(0.58, (length / hi)[::-1], force[::-1])
    at_2 = np.interp(0.98, (length / hi)[::-1], force[::-1])
    assert abs(at_42 - 43.4) < 0.1 and at_2 < 0.5 * at_42


@pytest.mark.parametrize("start", [{"shape_model": 2}, {"bladder_model": 1}, {"bag_membrane_stiffness": -1.0}])
def test_the_bag_is_refused_where_it_has_no_meaning(start):
    with pytest.raises(Exception):
        simulate_fmu(FMU, stop_time=1e-3, start_values={"bag_diameter": kb.BAG, **start})
