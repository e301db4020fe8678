"""The FMI 3.0 array outputs (the bladder wall's field: McKibbenMuscle, KnittedMuscle, FreeBladder) under FMPy: declared with a
fixed Dimension and their dependencies, read with `getFloat64(..., nValues)`, equal to the thick
tube solved independently here (scipy's adaptive quadrature in the deformed radius), meeting the
tube's boundary conditions and the equilibrium of a half tube, refused with a reason for a wrong
`nValues`, kept by the FMU state, and absent from the FMI 2.0 FMU."""

import math

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu
from scipy.integrate import quad

from actuator_fmus.paths import FMI2_DIR, FMI3_DIR

FMU = str(FMI3_DIR / "McKibbenMuscle.fmu")
ARRAYS = ["wall_radius", "wall_stress_radial", "wall_stress_hoop", "wall_stress_axial"]
EXACT = 3


@pytest.fixture(scope="module")
def md():
    return read_model_description(FMU)


@pytest.fixture(scope="module")
def unzipped():
    return extract(FMU)


class Muscle:
    def __init__(self, md, unzipped, log, **parameters):
        self.vr = {v.name: v for v in md.modelVariables}
        self.fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipped,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName="arrays")
        self.fmu.instantiate(logMessage=lambda *args: log.append(args[-1].decode()))
        self.fmu.enterInitializationMode()
        for name, value in parameters.items():
            v = self.vr[name]
            {"Enumeration": self.fmu.setInt64, "Int32": self.fmu.setInt32, "Float64": self.fmu.setFloat64,
             "Boolean": self.fmu.setBoolean}[v.type]([v.valueReference], [value])
        self.fmu.exitInitializationMode()
        self.size = {name: int(self.vr[name].dimensions[0].start) for name in ARRAYS}

    def get(self, *names):
        return self.fmu.getFloat64([self.vr[n].valueReference for n in names])

    def arrays(self):
        """{name: numpy array} of the four arrays, read in one call."""
        flat = self.fmu.getFloat64([self.vr[n].valueReference for n in ARRAYS],
                                   nValues=sum(self.size.values()))
        out, at = {}, 0
        for name in ARRAYS:
            out[name] = np.array(flat[at:at + self.size[name]])
            at += self.size[name]
        return out

    def set(self, pressure, length):
        self.fmu.setFloat64([self.vr["pressure"].valueReference, self.vr["length"].valueReference],
                            [pressure, length])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def thick_tube(m, pressure, names=("effective_bladder_inner_diameter", "effective_bladder_thickness",
                                     "effective_mooney_c1", "effective_mooney_c2")):
    """The exact thick Mooney-Rivlin tube at the muscle's deformation (its axial stretch and
    inner hoop stretch as the FMU reports them): the radius of each sampled material circle and
    the stress functions of the deformed radius r, by eq. 2.8-2.9 and radial equilibrium
    d sigma_rr / dr = (sigma_tt - sigma_rr) / r from sigma_rr = -P at the inner wall. `names`:
    the tube's inner diameter, thickness, C1 and C2 among the FMU's variables."""
    d_ri, t, c1, c2, lam1, lam2_in = m.get(*names, "stretch_axial", "stretch_hoop")
    d_ro = d_ri + 2 * t
    r_in = lam2_in * d_ri / 2
    # Incompressibility: the annulus between two material circles keeps its area times length.
    r_out = math.sqrt(r_in ** 2 + (d_ro ** 2 - d_ri ** 2) / (4 * lam1))

    def material_diameter(r):
        return math.sqrt(d_ri ** 2 + 4 * lam1 * (r ** 2 - r_in ** 2))

    def differences(r):
        lam2 = 2 * r / material_diameter(r)
        lam3 = 1 / (lam1 * lam2)
        hoop = 2 * c1 * (lam2 ** 2 - lam3 ** 2) - 2 * c2 * (1 / lam2 ** 2 - 1 / lam3 ** 2)
        axial = 2 * c1 * (lam1 ** 2 - lam3 ** 2) - 2 * c2 * (1 / lam1 ** 2 - 1 / lam3 ** 2)
        return hoop, axial

    def radial(r):
        return -pressure + quad(lambda q: differences(q)[0] / q, r_in, r, epsabs=0, epsrel=1e-13)[0]

    def stresses(r):
        hoop, axial = differences(r)
        s = radial(r)
        return s, s + hoop, s + axial

    n = m.size["wall_radius"]
    radii = [math.sqrt(r_in ** 2 + ((d_ri + k / (n - 1) * (d_ro - d_ri)) ** 2 - d_ri ** 2) / (4 * lam1))
             for k in range(n)]
    return np.array(radii), stresses, r_in, r_out


def test_the_description_declares_the_arrays(md):
    assert validate_fmu(FMU) == []
    by_name = {v.name: v for v in md.modelVariables}
    outputs = {u.variable.name: u for u in md.outputs}
    initial = {u.variable.name: u for u in md.initialUnknowns}
    for name in ARRAYS:
        v = by_name[name]
        assert (v.type, v.causality, v.variability) == ("Float64", "output", "continuous")
        assert [int(d.start) for d in v.dimensions] == [9] and v.unit == ("m" if name == "wall_radius" else "Pa")
        # The dependencies of the innermost layer's stress, as an output and initially.
        hoop = by_name["stress_hoop"].name
        assert outputs[name].dependencies == outputs[hoop].dependencies
        assert initial[name].dependencies == initial[hoop].dependencies
    # FMI 2.0 has no arrays: its FMU has none of these variables.
    md2 = read_model_description(str(FMI2_DIR / "McKibbenMuscle.fmu"))
    assert not {v.name for v in md2.modelVariables} & set(ARRAYS)
    assert len(md2.modelVariables) == len(md.modelVariables) - 1 - len(ARRAYS)  # time


@pytest.mark.parametrize("pressure, length", [(300e3, 0.09), (690e3, 0.095), (50e3, 0.085)])
def test_the_exact_wall_is_the_thick_tube(md, unzipped, pressure, length):
    log = []
    m = Muscle(md, unzipped, log, bladder_model=EXACT, bladder_layers=24)
    m.set(pressure, length)
    a = m.arrays()
    p_eff, = m.get("effective_pressure")
    radii, stresses, r_in, r_out = thick_tube(m, pressure)
    assert np.allclose(a["wall_radius"], radii, rtol=1e-12, atol=0)
    assert a["wall_radius"][0] == pytest.approx(r_in, rel=1e-12)
    assert a["wall_radius"][-1] == pytest.approx(r_out, rel=1e-12)
    scale = max(pressure, 1e3)
    for k, r in enumerate(radii):
        radial, hoop, axial = stresses(r)
        assert a["wall_stress_radial"][k] == pytest.approx(radial, abs=1e-9 * scale)
        assert a["wall_stress_hoop"][k] == pytest.approx(hoop, abs=1e-9 * scale)
        assert a["wall_stress_axial"][k] == pytest.approx(axial, abs=1e-9 * scale)
    # Boundary conditions: the gas pressure inside, the sleeve's contact pressure outside (the
    # FMU's own solve for the scalar output).
    assert a["wall_stress_radial"][0] == -pressure
    assert a["wall_stress_radial"][-1] == pytest.approx(-p_eff, abs=1e-9 * scale)
    # A half tube cut along its axis: its hoop force balances the pressures on its faces.
    hoop_force = quad(lambda r: stresses(r)[1], r_in, r_out, epsrel=1e-12)[0]
    assert hoop_force == pytest.approx(pressure * r_in - p_eff * r_out, abs=1e-9 * scale * r_out)
    # The innermost element is the scalar output of the innermost layer.
    assert a["wall_stress_hoop"][0] == pytest.approx(m.get("stress_hoop")[0], abs=1e-6 * scale)
    assert not log
    m.close()


def test_a_free_bladder_has_a_free_outer_surface(md, unzipped):
    m = Muscle(md, unzipped, [], bladder_model=EXACT, bladder_layers=24)
    for length in np.linspace(0.06, 0.095, 15):
        m.set(0.0, length)
        threshold = m.get("threshold_pressure")[0]
        if threshold > 20e3:
            break
    else:
        pytest.fail("no length with a threshold pressure above 20 kPa")
    pressure = 0.5 * threshold
    m.set(pressure, length)
    assert m.fmu.getBoolean([m.vr["bladder_contact"].valueReference]) == [False]
    a = m.arrays()
    assert a["wall_stress_radial"][0] == -pressure
    assert abs(a["wall_stress_radial"][-1]) < 1e-9 * pressure
    m.close()


def test_no_bladder_no_wall(md, unzipped):
    m = Muscle(md, unzipped, [], bladder_model=0)
    m.set(300e3, 0.09)
    assert all((x == 0).all() for x in m.arrays().values())
    m.close()


def test_a_wrong_count_is_an_error_that_says_why(md, unzipped):
    from fmpy.fmi1 import FMICallException

    log = []
    m = Muscle(md, unzipped, log, bladder_model=EXACT)
    vr = m.vr["wall_stress_hoop"].valueReference
    for n in (1, 8, 10):
        with pytest.raises(FMICallException):
            m.fmu.getFloat64([vr], nValues=n)
    assert any("nValues (8) must be 9" in line and "wall_stress_hoop has 9" in line for line in log), log
    # Scalars and an array in one call: 1 + 9 values.
    values = m.fmu.getFloat64([m.vr["force"].valueReference, vr], nValues=10)
    assert values[1:] == m.fmu.getFloat64([vr], nValues=9)
    m.close()


def test_the_fmu_state_keeps_the_arrays(md, unzipped):
    m = Muscle(md, unzipped, [], bladder_model=EXACT, friction=True)
    m.set(300e3, 0.09)
    m.fmu.doStep(0.0, 0.01)
    before = m.arrays()
    state = m.fmu.getFMUState()
    serialized = m.fmu.serializeFMUState(state)
    m.set(500e3, 0.085)
    m.fmu.doStep(0.01, 0.01)
    assert not np.array_equal(m.arrays()["wall_stress_hoop"], before["wall_stress_hoop"])
    m.fmu.setFMUState(state)
    for name, values in m.arrays().items():
        assert np.array_equal(values, before[name]), name
    m.set(500e3, 0.085)
    m.fmu.setFMUState(m.fmu.deserializeFMUState(serialized))
    for name, values in m.arrays().items():
        assert np.array_equal(values, before[name]), name
    m.fmu.freeFMUState(state)
    m.close()


def test_the_knitted_muscle_has_the_same_wall():
    """KnittedMuscle's bladder is the same wall in the knitted cylinder (section 1.3.6): its
    boundary conditions, and no wall without a bladder."""
    path = str(FMI3_DIR / "KnittedMuscle.fmu")
    md = read_model_description(path)
    vr = {v.name: v for v in md.modelVariables}
    assert [int(d.start) for d in vr["wall_stress_radial"].dimensions] == [9]
    for bladder_model in (EXACT, 0):
        fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="KnittedMuscle")
        fmu.instantiate()
        fmu.enterInitializationMode()
        fmu.setInt64([vr["preset"].valueReference], [1])  # the section 1.4 prototype
        fmu.setInt64([vr["bladder_model"].valueReference], [bladder_model])
        fmu.exitInitializationMode()
        lo, hi = fmu.getFloat64([vr["min_length"].valueReference, vr["max_length"].valueReference])
        pressure = 100e3
        fmu.setFloat64([vr["pressure"].valueReference, vr["length"].valueReference],
                       [pressure, lo + 0.7 * (hi - lo)])
        radial = fmu.getFloat64([vr["wall_stress_radial"].valueReference], nValues=9)
        p_eff = fmu.getFloat64([vr["effective_pressure"].valueReference])[0]
        if bladder_model:
            assert radial[0] == -pressure
            assert radial[-1] == pytest.approx(-p_eff, abs=1e-9 * pressure)
            assert 0 < p_eff < pressure
        else:
            assert radial == [0.0] * 9
        fmu.terminate()
        fmu.freeInstance()


def test_the_free_tube_is_the_thick_tube_with_nothing_outside():
    """FreeBladder's closed form against the thick tube solved here, and its free outer surface."""
    path = str(FMI3_DIR / "FreeBladder.fmu")
    md = read_model_description(path)
    log = []
    m = Muscle(md, extract(path), log)
    names = ("bladder_inner_diameter", "bladder_thickness", "mooney_c1", "mooney_c2")
    for stretch, fraction in [(0.8, 0.5), (1.0, 0.9), (1.3, 0.3)]:
        length = stretch * m.get("bladder_length")[0]
        m.set(0.0, length)
        pressure = fraction * m.get("ballooning_pressure")[0]
        m.set(pressure, length)
        a = m.arrays()
        radii, stresses, r_in, r_out = thick_tube(m, pressure, names)
        assert np.allclose(a["wall_radius"], radii, rtol=1e-12, atol=0)
        for k, r in enumerate(radii):
            for name, value in zip(ARRAYS[1:], stresses(r)):
                assert a[name][k] == pytest.approx(value, abs=1e-9 * pressure), (name, k)
        assert a["wall_stress_radial"][0] == -pressure
        assert abs(a["wall_stress_radial"][-1]) < 1e-9 * pressure
        hoop_force = quad(lambda r: stresses(r)[1], r_in, r_out, epsrel=1e-12)[0]
        assert hoop_force == pytest.approx(pressure * r_in, rel=1e-9)
        assert a["wall_stress_hoop"][0] == pytest.approx(m.get("stress_hoop")[0], abs=1e-9 * pressure)
    assert not log
    m.close()
