"""KnittedMuscle under FMPy: the knitted-sleeve muscle of dissertation ch. 1 against what the
model must show. Each test names the equation or figure it checks."""

import math

import numpy as np
import pytest

from conftest import Slave

MODEL = "KnittedMuscle"
IDEAL, TUBULAR, NON_CYLINDRICAL = 0, 1, 2
# Section 1.4 prototype: m = 22, n = 49, S_row = pi 153 mm; t from its 514 mm stretched length.
M, N, S = 22.0, 49.0, math.pi * 0.153
T = (S - 0.514 * 2 * M / N) / (4 * M)


def knitted(log=None, **parameters):
    parameters.setdefault("length", 0.4)
    # The dissertation's signed force: the tests check its equations, negative below the free
    # contraction.
    parameters.setdefault("signed_force", True)
    return Slave(MODEL, log=log, **parameters)


def eq_1_8(p, L, m, n, s):
    """Eq. 1.8: F = -P (12 m^2 L^2 - 8 m n S L + n^2 S^2) / (4 pi n^2)."""
    return -p / (4 * math.pi * n * n) * (12 * m * m * L * L - 8 * m * n * s * L + n * n * s * s)


def eq_1_14(p, L, m, n, s):
    """Eq. 1.14: F = -P ((12 m^2 - 3) L^2 - 8 S m n L + n^2 S^2) / (4 pi n^2)."""
    return -p / (4 * math.pi * n * n) * ((12 * m * m - 3) * L * L - 8 * s * m * n * L + n * n * s * s)


def sweep(m, pressure, lengths, *names):
    return np.array([m.at(*names, pressure=pressure, length=L) for L in lengths])


def test_ideal_free_contraction_at_one_third_peak_at_two_thirds_and_eq_1_8():
    m = knitted(strand_thickness=0.0)
    top, free = m.get("max_length", "free_contraction_length")
    assert top == pytest.approx(N * S / (2 * M), rel=1e-14)  # eq. 1.10
    assert free == pytest.approx(top / 3, rel=1e-14)  # eq. 1.9: 67% stroke
    p = 14e3
    lengths = np.linspace(free, top, 301)
    f = sweep(m, p, lengths, "force")
    peak = p * S * S / (12 * math.pi)
    assert abs(f[0]) < 1e-9 * peak and abs(f[-1]) < 1e-9 * peak
    assert lengths[np.argmax(f)] == pytest.approx(2 * top / 3, abs=top / 300)
    assert m.at("force", pressure=p, length=2 * top / 3) == pytest.approx(peak, rel=1e-12)
    assert abs(m.at("stiffness", pressure=p, length=2 * top / 3)) < 1e-9 * peak / top
    for L in np.linspace(0.0, top, 41):
        force, volume, radius = m.at("force", "volume", "max_radius", pressure=p, length=L)
        assert force == pytest.approx(eq_1_8(p, L, M, N, S), rel=1e-12, abs=1e-12 * peak)
        assert volume == pytest.approx(L * (S - 2 * M * L / N) ** 2 / (4 * math.pi), rel=1e-12, abs=1e-18)  # eq. 1.5
        assert radius == pytest.approx((S - 2 * M * L / N) / (2 * math.pi), rel=1e-12, abs=1e-15)
    m.close()


def test_tubular_is_eq_1_14_and_its_correction_shrinks_with_m():
    corrections, losses = [], []
    for stitches in (4, 8, 16, 22):
        m = knitted(shape_model=TUBULAR, stitches_per_row=stitches, strand_thickness=0.0)
        top, free = m.get("max_length", "free_contraction_length")
        assert top == pytest.approx(N * S / (2 * stitches + 1), rel=1e-12)  # C = 0 on the spiral
        p = 14e3
        for L in np.linspace(0.0, top, 25):
            assert m.at("force", pressure=p, length=L) == pytest.approx(
                eq_1_14(p, L, stitches, N, S), rel=1e-12, abs=1e-12 * p * S * S)
        # Correction at the tubular full extension relative to the ideal peak P S^2 / (12 pi):
        # F_tub - F_ideal = 3 P L^2 / (4 pi n^2), i.e. 9 / (2m + 1)^2.
        correction = (m.at("force", pressure=p, length=top) - eq_1_8(p, top, stitches, N, S)) / (p * S * S / (12 * math.pi))
        assert correction == pytest.approx(9 / (2 * stitches + 1) ** 2, rel=1e-9)
        assert abs(m.at("force", pressure=p, length=free)) < 1e-9 * p * S * S
        corrections.append(correction)
        losses.append(2 / 3 - (1 - free / top))
        m.close()
    print("tubular correction at m = 4, 8, 16, 22: force", np.round(corrections, 5), "stroke loss", np.round(losses, 5))
    assert np.all(np.diff(corrections) < 0) and np.all(np.diff(losses) < 0)
    assert losses[-1] < 0.01  # section 1.4.3: below 1% of length for the prototype


def test_thick_strand_stops_at_the_minimum_radius_with_the_larger_initial_force():
    # Eq. 1.15-1.16 and Fig. 1.11, prototype (t = 0.217 mm).
    thick = knitted(preset=1)
    thin = knitted(strand_thickness=0.0)
    r_min = 4 * M * T / (2 * math.pi)
    top = thick.get("max_length")
    assert top == pytest.approx(0.514, rel=1e-12)
    assert thick.get("min_length") == pytest.approx(2 * N * T, rel=1e-12)
    p = 14e3
    f0, radius = thick.at("force", "max_radius", pressure=p, length=top)
    assert radius == pytest.approx(r_min, rel=1e-9)
    assert f0 == pytest.approx(p * (r_min * S - 3 * math.pi * r_min**2), rel=1e-9)
    thin_top = thin.get("max_length")
    assert abs(thin.at("force", pressure=p, length=thin_top)) < 1e-9 * f0
    # Same volume law (eq. 1.15 gives eq. 1.6), so the thick curve is the thin one cut off where
    # the radius reaches r_min: it starts with a positive force where the thin one starts at zero.
    assert thin.at("force", pressure=p, length=top) == pytest.approx(f0, rel=1e-12)
    assert f0 > 0.15 * p * S * S / (12 * math.pi)
    print(f"thick strand: stroke ends at {top:.4f} m (r_min {r_min * 1e3:.3f} mm) with {f0:.2f} N at 14 kPa")
    thick.close()
    thin.close()


def peak_force(m, p, samples=1201):
    lo, hi = m.get("min_length", "max_length")
    lengths = np.linspace(lo, hi, samples)
    f = sweep(m, p, lengths, "force")
    return f.max(), lengths[np.argmax(f)]


def test_non_cylindrical_shorter_stroke_faster_rise_lower_peak_fig_1_14():
    p = 14e3
    nc = knitted(shape_model=NON_CYLINDRICAL, shape_segments=49)
    cyl = knitted(shape_model=IDEAL)
    assert nc.get("max_length") == pytest.approx(cyl.get("max_length"), rel=1e-12)
    # Both start with every row at r_min: same force at full extension.
    assert nc.at("force", pressure=p, length=0.514) == pytest.approx(cyl.at("force", pressure=p, length=0.514), rel=1e-9)
    rise_nc = nc.at("force", pressure=p, length=0.49)
    rise_cyl = cyl.at("force", pressure=p, length=0.49)
    (peak_nc, at_nc), (peak_cyl, at_cyl) = peak_force(nc, p), peak_force(cyl, p)
    free_nc, free_cyl = nc.get("free_contraction_length"), cyl.get("free_contraction_length")
    print(f"14 kPa: F(0.49 m) {rise_nc:.2f} vs {rise_cyl:.2f} N; peak {peak_nc:.2f} N at {at_nc:.4f} m vs "
          f"{peak_cyl:.2f} N at {at_cyl:.4f} m; stroke {1 - free_nc / 0.514:.4f} vs {1 - free_cyl / 0.514:.4f}")
    assert rise_nc > 1.3 * rise_cyl
    assert peak_nc < 0.85 * peak_cyl
    assert free_nc > free_cyl + 0.005
    assert abs(nc.at("force", pressure=p, length=free_nc)) < 1e-6 * peak_nc
    # The pocket: the largest radius exceeds the cylinder's early in the stroke.
    assert nc.at("max_radius", pressure=p, length=0.49) > cyl.at("max_radius", pressure=p, length=0.49)
    # Force is -P dV/dL of the table: check against a central difference of the volume output.
    for L in (0.25, 0.35, 0.45, 0.5):
        d = 1e-6
        dv = (nc.at("volume", pressure=p, length=L + d) - nc.at("volume", pressure=p, length=L - d)) / (2 * d)
        assert nc.at("force", pressure=p, length=L) == pytest.approx(-p * dv, rel=1e-5)
    nc.close()
    cyl.close()


def test_non_cylindrical_converges_as_shape_segments_grow():
    p = 14e3
    peaks, frees = [], []
    for segments in (12, 24, 49, 98):
        m = knitted(shape_model=NON_CYLINDRICAL, shape_segments=segments)
        peaks.append(peak_force(m, p, samples=601)[0])
        frees.append(m.get("free_contraction_length"))
        m.close()
    print("segments 12..98: peak", np.round(peaks, 4), "free contraction", np.round(frees, 6))
    peak_changes, free_changes = np.abs(np.diff(peaks)), np.abs(np.diff(frees))
    assert np.all(np.diff(peak_changes) < 0) and np.all(np.diff(free_changes) < 0)
    assert peak_changes[-1] < 1e-3 * peaks[-1]


def test_friction_cf_0_25_contraction_below_extension_fig_1_18():
    # Eq. 1.21 on the non-cylindrical prototype at 14 kPa: a full contraction then extension.
    cf, p = 0.25, 14e3
    m = knitted(shape_model=NON_CYLINDRICAL, friction=True, friction_coefficient=cf, presliding_length=1e-4,
                length=0.514)
    frictionless = knitted(shape_model=NON_CYLINDRICAL, length=0.514)
    lo, top = m.get("min_length", "max_length")
    lengths = np.linspace(top, lo, 300)
    down, up = [], []
    for L in lengths:
        m.step(pressure=p, length=L)
        down.append(m.get("force", "friction_force", "volume"))
    for L in lengths[::-1]:
        m.step(pressure=p, length=L)
        up.append(m.get("force", "friction_force", "volume"))
    down, up = np.array(down), np.array(up)[::-1]
    f0 = sweep(frictionless, p, lengths, "force")
    inner = slice(5, -5)  # away from the reversals' presliding zones
    assert np.all(up[inner, 0] > f0[inner]) and np.all(f0[inner] > down[inner, 0])
    # Saturated friction: |friction| = sqrt(2) Cf (F + P V / L) with F the total tension.
    tension = down[inner, 0] + p * down[inner, 2] / lengths[inner]
    slack = tension <= 0
    assert np.allclose(-down[inner, 1][~slack], math.sqrt(2) * cf * tension[~slack], rtol=1e-9)
    assert np.all(down[inner, 1][slack] == 0)
    tension_up = up[inner, 0] + p * up[inner, 2] / lengths[inner]
    assert np.allclose(up[inner, 1], math.sqrt(2) * cf * tension_up, rtol=1e-9)
    # Contraction stops short of the frictionless free contraction (zero force comes earlier).
    stop = lengths[np.nonzero(down[:, 0] <= 0)[0][0]]
    free = frictionless.get("free_contraction_length")
    print(f"Cf = 0.25: contraction reaches zero force at {stop:.4f} m (stroke {1 - stop / top:.3f}), "
          f"frictionless at {free:.4f} m (stroke {1 - free / top:.3f})")
    assert stop > free + 0.02
    # Holding still changes nothing; the friction state survives get/set FMU state.
    held = m.get("force")
    for _ in range(50):
        m.step(pressure=p, length=top)
    assert m.get("force") == held
    state, time = m.fmu.getFMUstate(), m.time
    first = [m.step(pressure=p, length=L) or m.get("force") for L in lengths[:40]]
    m.fmu.setFMUstate(state)
    m.time = time
    assert first == [m.step(pressure=p, length=L) or m.get("force") for L in lengths[:40]]
    m.close()
    frictionless.close()


def simpson(f, a, b, steps=400):
    x = np.linspace(a, b, 2 * steps + 1)
    y = np.array([f(v) for v in x])
    h = (b - a) / (2 * steps)
    return h / 3 * (y[0] + y[-1] + 4 * y[1:-1:2].sum() + 2 * y[2:-1:2].sum())


def test_knitted_against_mckibben_section_1_3_6():
    # 110 mm stretched, 14.6 mm diameter at free contraction, 550 kPa, ideal geometry.
    p, b, d = 550e3, 0.110, 0.0146
    k = knitted(preset=2, strand_thickness=0.0, length=0.08)
    top, free = k.get("max_length", "free_contraction_length")
    assert top == pytest.approx(b, rel=1e-12)
    assert 2 * k.at("max_radius", pressure=p, length=free) == pytest.approx(d, rel=1e-12)
    stroke_k = 1 - free / top
    # McKibben with zero initial braid angle: L_max = strand length b; free contraction at
    # b / sqrt(3) with D = b sqrt(2/3) / (turns pi) = 14.6 mm gives the turns.
    turns = b * math.sqrt(2 / 3) / (math.pi * d)
    mk = Slave("McKibbenMuscle", signed_force=True, strand_rigidity=1e12, preset=0, bladder_model=0, strand_length=b, turns=turns, length=0.08)
    free_mk = b / math.sqrt(3)
    assert abs(mk.at("force", pressure=p, length=free_mk)) < 1e-9
    stroke_mk = 1 - free_mk / b
    # Ideal work per stroke = P V(L_free) for both (V = 0 at full extension).
    work_k = simpson(lambda L: k.at("force", pressure=p, length=L), free, top)
    work_mk = simpson(lambda L: mk.at("force", pressure=p, length=L), free_mk, b)
    v_k = k.at("volume", pressure=p, length=free)
    v_mk = mk.at("volume", pressure=p, length=free_mk)
    assert work_k == pytest.approx(p * v_k, rel=1e-9)
    assert work_mk == pytest.approx(p * v_mk, rel=1e-9)
    peak_k = k.at("force", pressure=p, length=2 * top / 3)
    peak_mk = mk.at("force", pressure=p, length=b)
    print(f"110 mm, 14.6 mm, 550 kPa, ideal: stroke knitted {stroke_k:.4f} vs McKibben {stroke_mk:.4f}; "
          f"work {work_k:.3f} J vs {work_mk:.3f} J; peak {peak_k:.2f} N vs {peak_mk:.2f} N "
          f"(ratio {peak_mk / peak_k:.3f}; the dissertation, with bladders: ratio about 2, work 2.6 J knitted vs 2.3 J McKibben)")
    assert stroke_k == pytest.approx(2 / 3, rel=1e-12)
    assert stroke_mk == pytest.approx(1 - 1 / math.sqrt(3), rel=1e-12)  # 42%
    # Ideal, the McKibben peak is P b^2 / (2 pi turns^2) and the knitted one P S^2 / (12 pi).
    assert peak_k == pytest.approx(p * (1.5 * math.pi * d) ** 2 / (12 * math.pi), rel=1e-12)
    assert peak_mk == pytest.approx(p * b * b / (2 * math.pi * turns**2), rel=1e-9)
    k.close()
    mk.close()


@pytest.mark.parametrize("shape", [IDEAL, TUBULAR, NON_CYLINDRICAL])
@pytest.mark.parametrize("friction", [False, True])
def test_dense_grid_never_gives_nan(shape, friction, recording_log):
    m = knitted(log=recording_log, shape_model=shape, friction=friction)
    names = ["force", "volume", "effective_pressure", "friction_force", "max_radius", "stiffness"]
    for p in np.linspace(-101325, 1e6, 12):
        for L in np.linspace(0.0, 1.0, 26):
            m.step(pressure=p, length=L)
            values = m.get(*names)
            assert all(math.isfinite(v) for v in values), (p, L, values)
    assert recording_log.contains("until the inputs return"), "out-of-range points are logged"
    m.close()


def test_out_of_range_length_is_the_nearest_limit_and_logged_once(recording_log):
    m = knitted(log=recording_log, shape_model=NON_CYLINDRICAL)
    lo, top = m.get("min_length", "max_length")
    # The yarn stretches up to 5% of the full extension past max_length; beyond, the breaking
    # length is evaluated.
    breaking = top + 0.05 * top
    at_break = m.at("force", "volume", pressure=14e3, length=breaking)
    for L in (top * 1.06, top * 1.5, 5.0):
        assert m.at("force", "volume", pressure=14e3, length=L) == at_break
    m.at("force", pressure=14e3, length=0.4)
    assert m.at("force", pressure=14e3, length=0.0) == m.at("force", pressure=14e3, length=lo)
    warnings = [x for x in recording_log.messages() if "until the inputs return" in x]
    assert len(warnings) == 2, warnings  # one per excursion (above, then below)
    m.close()


@pytest.mark.parametrize("parameters", [
    {"shape_model": NON_CYLINDRICAL, "strand_thickness": 0.0},  # no clamped radius for the pocket
    {"strand_thickness": 0.01},  # too thick: no stroke
    {"friction": True, "friction_coefficient": 0.7071},  # above the declared max 0.7: sqrt(2) Cf -> 1 locks the sleeve
])
def test_bad_parameters_fail_initialization(parameters):
    with pytest.raises(Exception):
        knitted(**parameters)


# Section 1.3.6 bladder: the same latex tube in both muscles of the 110 mm / 14.6 mm / 550 kPa
# comparison. A 1/4 in (6.4 mm) bore with a 0.8 mm wall (OD 8.0 mm) slides into either sleeve at
# free contraction (14.6 mm), and must inflate to a hoop stretch of 14.6/6.4 = 2.3 there, within
# the stretches for which chapter 2's Mooney-Rivlin latex is used; its 110 mm unstretched length is
# the muscles' nominal length ("no pre-strain", as the dissertation's green curves). Rubber volume
# 1.99 cm^3: 32% of the knitted sleeve's largest volume, 19% of the McKibben's. The dissertation's
# thick-walled model as written, 16 layers (Fig. 2.8; bladder_model 5). The dissertation's knitted curve also has a 0.2 mm strand. Caveat: the rubber fills
# the knitted sleeve at 82 mm, so there the 110 mm tube is always axially compressed (lambda_1 <=
# 0.75), which the model takes as Mooney-Rivlin compression without buckling.
BLADDER = dict(bladder_model=5, bladder_layers=16, bladder_length=0.110,
               bladder_inner_diameter=6.4e-3, bladder_thickness=0.8e-3)


def bisect(f, a, b, iterations=60):
    """Root of f in [a, b] where f changes sign."""
    fa = f(a)
    assert fa * f(b) <= 0, (a, b)
    for _ in range(iterations):
        mid = 0.5 * (a + b)
        if (f(mid) > 0) == (fa > 0):
            a = mid
        else:
            b = mid
    return 0.5 * (a + b)


def test_a_wall_thicker_than_the_bladder_is_long_is_refused_with_its_reason(recording_log):
    # A 1 mm wall on a bladder 0.5 mm long is a ring, not the long tube eq. 2.8a stretches alike
    # along the muscle: refused at initialization, naming both parameters.
    with pytest.raises(Exception):
        knitted(log=recording_log, preset=2, strand_thickness=0.2e-3, length=0.08,
                **dict(BLADDER, bladder_length=5e-4, bladder_thickness=1e-3))
    assert recording_log.contains("bladder_thickness 0.001 m exceeds bladder_length 0.0005 m")


def test_bladder_off_is_unchanged():
    # bladder_model 0 ignores every bladder parameter: bit-identical outputs.
    plain = knitted(strand_thickness=0.0)
    off = knitted(strand_thickness=0.0, bladder_model=0, bladder_thickness=5e-3, bladder_length=0.01, mooney_c1=1.0)
    names = ["force", "volume", "effective_pressure", "max_radius", "stiffness"]
    assert plain.get("max_length", "min_length") == off.get("max_length", "min_length")
    for p in (-5e4, 0.0, 14e3):
        for L in np.linspace(0.0, 0.6, 13):
            assert plain.at(*names, pressure=p, length=L) == off.at(*names, pressure=p, length=L)
    plain.close()
    off.close()


@pytest.mark.parametrize("shape,eq", [(IDEAL, eq_1_8), (TUBULAR, eq_1_14)])
def test_vanishing_bladder_is_eq_1_8_and_eq_1_14(shape, eq):
    # A 0.1 um wall with zero moduli: V_R -> 0 and P_eff -> P, so eq. 2.16-2.17 become -P dV/dL.
    m = knitted(preset=2, strand_thickness=0.0, shape_model=shape, bladder_model=1, bladder_thickness=1e-7,
                bladder_inner_diameter=1e-3, mooney_c1=0.0, mooney_c2=0.0, length=0.08)
    lo, top = m.get("min_length", "max_length")
    m_, s = 8.0, 1.5 * math.pi * 0.0146
    n = m_ * 2 * 0.110 / s
    p = 550e3
    peak = p * s * s / (12 * math.pi)
    for L in np.linspace(lo, top, 41)[1:-1]:
        force, p_eff = m.at("force", "effective_pressure", pressure=p, length=L)
        # P_eff = P (1 + lambda_3 t / D_in) of the thin wall (eq. 2.12 with zero moduli): t / D order.
        assert p_eff == pytest.approx(p, rel=1e-3)
        assert force == pytest.approx(eq(p, L, m_, n, s), abs=1e-4 * peak)
    m.close()


@pytest.mark.parametrize("shape", [IDEAL, TUBULAR])
def test_bladder_force_is_continuous_across_contact(shape):
    # Eq. 2.18 meets eq. 2.7 at the threshold: bisect the pressure where P_eff leaves zero and
    # compare the forces either side (no jump above 1e-6 of the ideal peak force at 550 kPa).
    m = knitted(preset=2, strand_thickness=0.2e-3, shape_model=shape, length=0.08, **BLADDER)
    lo, top = m.get("min_length", "max_length")
    scale = 550e3 * (1.5 * math.pi * 0.0146) ** 2 / (12 * math.pi)
    found = 0
    for L in np.linspace(lo, top, 12)[2:-2]:
        def contact(p):
            return 1.0 if m.at("effective_pressure", pressure=p, length=L) > 0 else -1.0
        if contact(0.0) > 0 or contact(1e6) < 0:
            continue
        th = bisect(contact, 0.0, 1e6, iterations=80)
        dp = 1e-7 * th
        below, above = m.at("force", pressure=th - dp, length=L), m.at("force", pressure=th + dp, length=L)
        assert abs(above - below) < 1e-6 * scale, (L, th, above - below)
        found += 1
    assert found >= 3
    m.close()


def stroke_with_bladder(m, p):
    """(rest length, zero-force length at p, peak force, work) of the pressurized contraction.
    The stroke starts at the rest length, where the unpressurized muscle pulls with zero force:
    the longest length it reaches unloaded (the bladder's force grows without bound towards
    max_length, where the rubber fills the sleeve, so longer lengths need an external pull)."""
    lo, top = m.get("min_length", "max_length")
    grid = np.linspace(lo + 0.01 * (top - lo), top - 0.002 * (top - lo), 400)
    f0 = np.array([m.at("force", pressure=0.0, length=L) for L in grid])
    # Last crossing from compression to tension of the unpressurized force.
    up = [i for i in range(len(grid) - 1) if f0[i] < 0 <= f0[i + 1]]
    assert up, "the unpressurized muscle has a rest length"
    rest = bisect(lambda L: m.at("force", pressure=0.0, length=L), grid[up[-1]], grid[up[-1] + 1])
    fp = np.array([m.at("force", pressure=p, length=L) for L in grid if L < rest])
    sub = grid[grid < rest]
    zeros = [i for i in range(len(sub) - 1) if fp[i] < 0 <= fp[i + 1]]
    assert len(zeros) == 1, "one zero-force length under pressure"
    free = bisect(lambda L: m.at("force", pressure=p, length=L), sub[zeros[0]], sub[zeros[0] + 1])
    lengths = np.linspace(free, rest, 801)
    forces = [m.at("force", pressure=p, length=L) for L in lengths]
    work = simpson(lambda L: m.at("force", pressure=p, length=L), free, rest, steps=400)
    return rest, free, max(forces), work


def test_knitted_against_mckibben_with_bladder_section_1_3_6():
    p, b, d = 550e3, 0.110, 0.0146
    turns = b * math.sqrt(2 / 3) / (math.pi * d)
    rows = []
    # Ideal (the geometry of test_knitted_against_mckibben_section_1_3_6).
    k = knitted(preset=2, strand_thickness=0.0, length=0.08)
    mk = Slave("McKibbenMuscle", signed_force=True, strand_rigidity=1e12, preset=0, bladder_model=0, strand_length=b, turns=turns, length=0.08)
    top_k, free_k = k.get("max_length", "free_contraction_length")
    free_mk = b / math.sqrt(3)
    ideal = {
        "knitted": (top_k, free_k, k.at("force", pressure=p, length=2 * top_k / 3),
                    simpson(lambda L: k.at("force", pressure=p, length=L), free_k, top_k)),
        "McKibben": (b, free_mk, mk.at("force", pressure=p, length=b),
                     simpson(lambda L: mk.at("force", pressure=p, length=L), free_mk, b)),
    }
    k.close()
    mk.close()
    # With the same bladder in both.
    kb = knitted(preset=2, strand_thickness=0.2e-3, length=0.08, **BLADDER)
    mkb = Slave("McKibbenMuscle", signed_force=True, strand_rigidity=1e12, preset=0, strand_length=b, turns=turns, length=0.08, **BLADDER)
    bladder = {"knitted": stroke_with_bladder(kb, p), "McKibben": stroke_with_bladder(mkb, p)}
    reach = {"knitted": kb.get("max_length"), "McKibben": mkb.get("max_length")}
    kb.close()
    mkb.close()
    print("\nSection 1.3.6 at 110 mm, 14.6 mm, 550 kPa. Bladder: latex 6.4 mm bore, 0.8 mm wall, 110 mm "
          "unstretched, 16 layers; knitted strand 0.2 mm")
    print(f"{'':22s}{'start mm':>9s}{'F=0 mm':>9s}{'stroke':>8s}{'peak N':>9s}{'work J':>8s}")
    for name in ("knitted", "McKibben"):
        for label, (start, end, peak, work) in (("ideal", ideal[name]), ("bladder", bladder[name])):
            rows.append((name, label, start, end, peak, work))
            print(f"{name + ' ' + label:22s}{start * 1e3:9.2f}{end * 1e3:9.2f}{1 - end / start:8.1%}"
                  f"{peak:9.1f}{work:8.3f}")
    print(f"reach with bladder (rubber fills the sleeve): knitted {reach['knitted'] * 1e3:.2f} mm, "
          f"McKibben {reach['McKibben'] * 1e3:.2f} mm")
    print(f"peak ratio McKibben/knitted: ideal {ideal['McKibben'][2] / ideal['knitted'][2]:.2f}, "
          f"bladder {bladder['McKibben'][2] / bladder['knitted'][2]:.2f} (dissertation: about 2); work knitted vs McKibben: "
          f"ideal {ideal['knitted'][3]:.2f} J vs {ideal['McKibben'][3]:.2f} J, bladder {bladder['knitted'][3]:.2f} J "
          f"vs {bladder['McKibben'][3]:.2f} J (dissertation, with bladders: 2.6 J vs 2.3 J)")
    # Ideal: peak ratio 6 b^2 / (turns^2 S^2) = 4 exactly for this geometry; work = P V(L_free).
    assert ideal["McKibben"][2] / ideal["knitted"][2] == pytest.approx(4.0, rel=1e-9)
    assert ideal["knitted"][3] == pytest.approx(3.376, rel=1e-3)
    assert ideal["McKibben"][3] == pytest.approx(5.848, rel=1e-3)
    # With the bladder (computed; regression): rest length, zero-force length, peak, work.
    for got, want in ((bladder["knitted"], (0.06368, 0.04593, 98.71, 0.8773)),
                      (bladder["McKibben"], (0.09715, 0.06688, 239.8, 2.906))):
        assert got == pytest.approx(want, rel=2e-3)
    for name in ("knitted", "McKibben"):
        # Section 1.3.6: "reduced free contraction", less work than ideal.
        assert bladder[name][1] > ideal[name][1]
        assert bladder[name][3] < 0.6 * ideal[name][3]
    # "Higher initial force": the knitted peak with the bladder exceeds the ideal one, and the
    # McKibben/knitted peak ratio falls from 4 towards the dissertation's "about twice" (computed 2.43).
    assert bladder["knitted"][2] > ideal["knitted"][2]
    assert 2.0 < bladder["McKibben"][2] / bladder["knitted"][2] < 3.0
    # Disagreement with the dissertation: it has the knitted muscle doing MORE work with its bladder
    # (2.6 J) than the McKibben (2.3 J). With the same tube in both we compute the opposite
    # (0.88 J vs 2.91 J): the knitted sleeve's volume falls like (L_max - L)^2 near full
    # extension (eq. 1.6) against (b - L) for the McKibben (eq. 2.2), so the rubber fills it much
    # earlier and its stroke starts far shorter (63.7 mm against 97.2 mm). The dissertation's knitted
    # figure is 77% of our ideal 3.38 J, its McKibben one 39% of 5.85 J: its two bladders cannot
    # have been the same tube. Less rubber narrows the gap but never reverses it:
    print("same bore/wall in both (knitted work vs McKibben work):")
    for wall, bore in ((0.4e-3, 6.4e-3), (0.2e-3, 3.2e-3)):
        tube = dict(BLADDER, bladder_thickness=wall, bladder_inner_diameter=bore)
        kb = knitted(preset=2, strand_thickness=0.2e-3, length=0.08, **tube)
        mkb = Slave("McKibbenMuscle", signed_force=True, strand_rigidity=1e12, preset=0, strand_length=b, turns=turns, length=0.08, **tube)
        wk, wm = stroke_with_bladder(kb, p)[3], stroke_with_bladder(mkb, p)[3]
        print(f"  {bore * 1e3:.1f} mm bore, {wall * 1e3:.1f} mm wall: {wk:.3f} J vs {wm:.3f} J")
        assert bladder["knitted"][3] < wk < wm
        kb.close()
        mkb.close()


@pytest.mark.parametrize("shape", [IDEAL, TUBULAR])
@pytest.mark.parametrize("friction", [False, True])
@pytest.mark.parametrize("model", [1, 2, 3, 5])
def test_bladder_dense_grid_never_gives_nan(shape, friction, model, recording_log):
    m = knitted(log=recording_log, preset=2, strand_thickness=0.2e-3, shape_model=shape, friction=friction,
                length=0.08, **dict(BLADDER, bladder_model=model))
    names = ["force", "volume", "effective_pressure", "friction_force", "max_radius", "stiffness"]
    for p in np.linspace(-101325, 1e6, 12):
        for L in np.linspace(0.0, 0.15, 31):
            m.step(pressure=p, length=L)
            values = m.get(*names)
            assert all(math.isfinite(v) for v in values), (p, L, values)
            assert values[2] >= 0
    assert recording_log.contains("until the inputs return"), "out-of-range points are logged"
    m.close()


def test_bladder_with_the_non_cylindrical_shape_fails_initialization():
    with pytest.raises(Exception):
        knitted(shape_model=NON_CYLINDRICAL, bladder_model=1)


@pytest.mark.parametrize("parameters", [dict(), dict(shape_model=TUBULAR), dict(preset=2, bladder_model=1)],
                         ids=["ideal", "tubular", "Fig. 1.16 thin wall"])
def test_yarn_stretches_past_max_length(parameters):
    """Fully extended, each row's yarn lies along the axis as 2 m legs of L_max / n: the yarn is a
    spring of k_s = 2 m E A / L_max (E A = 6300 N, the Spectra line). The force is continuous at
    max_length, rises by exactly k_s past it, is finite and monotone up to the breaking length
    (5% of L_max past max_length), and is clamped beyond."""
    s = Slave(MODEL, **parameters)
    m = 8.0 if parameters.get("preset") == 2 else M
    hi = s.get("max_length")
    # The sleeve's own full extension: max_length without a bladder.
    bare = {k: v for k, v in parameters.items() if k != "bladder_model"}
    sleeve_max = Slave(MODEL, **bare).get("max_length")
    k_s = 2 * m * 6300.0 / sleeve_max
    p = 2e4
    left = s.at("force", pressure=p, length=hi - 1e-9)
    right = s.at("force", pressure=p, length=hi + 1e-9)
    assert abs(right - left) <= 2e-9 * k_s * 1.01 + 1e-9 * abs(left)
    breaking = hi + 0.05 * sleeve_max
    lengths = np.linspace(hi + 1e-6, breaking, 101)
    rows = sweep(s, p, lengths, "force", "stiffness", "input_clamped", "slack")
    assert np.all(np.isfinite(rows[:, 0])) and np.all(np.diff(rows[:, 0]) > 0)
    assert np.allclose(np.diff(rows[:, 0]) / np.diff(lengths), k_s, rtol=1e-6)
    assert np.allclose(rows[:, 1], k_s, rtol=1e-12)
    assert not rows[:, 2].any() and not rows[:, 3].any()
    beyond = s.at("force", "input_clamped", pressure=p, length=breaking + 0.01)
    assert beyond[1] and beyond[0] == pytest.approx(rows[-1, 0], rel=1e-12)
    s.close()


def test_tension_only_below_the_free_contraction():
    """By default the knit cannot push: below its free contraction force and stiffness are 0,
    `slack` is set and the directional derivatives of force are 0; signed_force gives eq. 1.8."""
    s = Slave(MODEL)
    free = s.get("free_contraction_length")
    length = 0.8 * free
    force, stiffness, slack = s.at("force", "stiffness", "slack", pressure=2e4, length=length)
    assert slack and force == 0.0 and stiffness == 0.0
    vr = [s.vars[n].valueReference for n in ("pressure", "length")]
    d = s.fmu.getDirectionalDerivative([s.vars["force"].valueReference], vr[:1], [1.0])
    d += s.fmu.getDirectionalDerivative([s.vars["force"].valueReference], vr[1:], [1.0])
    assert list(d) == [0.0, 0.0]
    signed = knitted(length=length)
    assert signed.at("force", pressure=2e4, length=length) < 0.0
    s.close()
    signed.close()
