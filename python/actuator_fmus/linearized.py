"""The linearized McKibben muscle: stiffness dF/dL and pressure gain dF/dP over the stroke of Table
2.1's muscles A-D (thick-walled bladder, 16 layers), computed through the FMU's
fmi2GetDirectionalDerivative, and a test of chapter 2's proposal to treat a finished muscle as a
spring whose stiffness is proportional to the applied pressure minus the threshold pressure.

    actuator-fmus linearized     (or: make linearized)

Writes docs/linearized-muscle.md and docs/linearized/*.png; exits 1 if its own checks fail.
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import extract, read_model_description  # noqa: E402

from .fmu import CoSimulation  # noqa: E402
from .paths import FMU_DIR, ROOT, fmu_path  # noqa: E402

FMU = FMU_DIR / "McKibbenMuscle.fmu"
OUT = ROOT / "docs" / "linearized"
PAGE = ROOT / "docs" / "linearized-muscle.md"
MUSCLES = {"A": 1, "B": 2, "C": 3, "D": 4}
PRESSURES = np.arange(0.0, 700e3 + 1, 25e3)  # Pa
CURVE_PRESSURES = [100e3, 300e3, 500e3, 700e3]
LENGTHS = 48
FAIL = 0.2  # a linear spring "fails" where it misses the model's stiffness by more than 20%


class Muscle:
    """One initialized McKibbenMuscle instance; `at(P, L)` gives the outputs and the partials."""

    def __init__(self, preset):
        md = read_model_description(str(FMU))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = CoSimulation(extract(str(FMU)), "linearized", md)
        self.fmu.instantiate()
        self.fmu.enterInitializationMode(startTime=0.0)
        self.fmu.setInteger([self.vr["preset"], self.vr["bladder_model"]], [preset, 5])
        # The dissertation's muscle: signed force, inextensible strands.
        self.fmu.setBoolean([self.vr["signed_force"]], [True])
        self.fmu.setReal([self.vr["strand_rigidity"]], [1e12])
        self.fmu.exitInitializationMode()
        self.min_length, self.max_length = self.fmu.getReal([self.vr["min_length"], self.vr["max_length"]])

    def at(self, pressure, length):
        v = self.vr
        self.fmu.setReal([v["pressure"], v["length"]], [pressure, length])
        force, threshold = self.fmu.getReal([v["force"], v["threshold_pressure"]])
        knowns = [v["pressure"], v["length"]]
        gain = self.fmu.getDirectionalDerivative([v["force"]], knowns, [1.0, 0.0])[0]
        stiffness = self.fmu.getDirectionalDerivative([v["force"]], knowns, [0.0, 1.0])[0]
        return force, stiffness, gain, threshold

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def sweep(name, preset):
    """Stiffness dF/dL (N/m), pressure gain dF/dP (m2) and threshold pressure (Pa) of Table 2.1
    muscle `name` (`preset`) over its stroke (lengths in m) and PRESSURES (Pa)."""
    m = Muscle(preset)
    lo, hi = m.min_length, m.max_length
    # The stroke: from where the muscle at the highest pressure pulls nothing (F = 0) up to 2% of
    # the range short of the fill limit, where the stiffness diverges.
    grid = np.linspace(lo + 0.02 * (hi - lo), hi - 0.02 * (hi - lo), 400)
    f_top = np.array([m.at(PRESSURES[-1], L)[0] for L in grid])
    start = grid[np.argmax(f_top >= 0.0)]
    lengths = np.linspace(start, grid[-1], LENGTHS)
    shape = (len(lengths), len(PRESSURES))
    F, K, G, TH = (np.zeros(shape) for _ in range(4))
    for i, L in enumerate(lengths):
        for j, P in enumerate(PRESSURES):
            F[i, j], K[i, j], G[i, j], TH[i, j] = m.at(P, L)
    m.close()
    return dict(name=name, lengths=lengths, F=F, K=K, G=G, threshold=TH[:, 0], max_length=hi)


def analyse(s):
    """Fit K = k (P - P_th(L)) over the stroke in contact (P >= P_th): one slope k per muscle.
    Per length, K is affine in P in contact (the layer pressures of eq. 2.12/2.19 are affine in P at
    a fixed diameter), K = K1 (P - P0): the proposal holds where P0 = P_th and K1 does not vary."""
    P = PRESSURES[None, :]
    th = s["threshold"][:, None]
    contact = P >= th
    x = (P - th)[contact]
    y = s["K"][contact]
    # Least squares on the relative error: the stiffness diverges at the fill limit and would
    # otherwise decide the slope alone.
    k = float(np.sum(x / y) / np.sum((x / y) ** 2))
    fit = k * np.clip(P - th, 0.0, None)
    rel = np.abs(fit - s["K"]) / np.maximum(np.abs(s["K"]), 1e-12)
    per_length = []
    for i in range(len(s["lengths"])):
        c = contact[i]
        if c.sum() >= 2:
            slope, intercept = np.polyfit(PRESSURES[c], s["K"][i, c], 1)
            per_length.append((slope, -intercept / slope))
        else:
            per_length.append((np.nan, np.nan))
    per_length = np.array(per_length)
    rms = float(np.sqrt(np.mean(rel[contact] ** 2)))
    failing = contact & (rel > FAIL)
    return dict(k=k, fit=fit, rel=rel, contact=contact, rms=rms, per_length=per_length, failing=failing)


def plot(s, a):
    """Writes docs/linearized/muscle_<name>.png from `sweep`'s and `analyse`'s results (plotted in
    kN/m, N/MPa, kPa, mm); returns its path."""
    from matplotlib.lines import Line2D

    L = s["lengths"] * 1e3
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.4))
    colours = {P: f"C{k}" for k, P in enumerate(CURVE_PRESSURES)}
    gains = {}
    for P in CURVE_PRESSURES:
        j = int(np.argmin(np.abs(PRESSURES - P)))
        axes[0].plot(L, s["K"][:, j] / 1e3, color=colours[P])
        axes[0].plot(L, a["fit"][:, j] / 1e3, "--", color=colours[P])
        gains[P] = s["G"][:, j] * 1e6
    # Once the bladder touches the sleeve the gain does not depend on the pressure: curves that
    # coincide are drawn once, labelled with every pressure they stand for.
    drawn = []
    for P, g in gains.items():
        same = next((d for d in drawn if np.allclose(d[1], g, rtol=1e-3, atol=0.5)), None)
        if same:
            same[0].append(P)
        else:
            drawn.append(([P], g))
    for k, (ps, g) in enumerate(drawn):
        axes[1].plot(L, g, color=colours[ps[0]], lw=4 - 0.8 * k, alpha=0.85,
                     label="P = " + ", ".join(f"{P / 1e3:.0f}" for P in ps) + " kPa"
                     + (" (the same curve)" if len(ps) > 1 else ""))
    top = 1.5 * np.nanmax(a["fit"]) / 1e3
    axes[0].set(xlabel="muscle length L (mm)", ylabel="stiffness dF/dL (kN/m)",
                ylim=(min(0.0, np.nanmin(s["K"]) / 1e3), top))
    axes[0].set_title(f"stiffness dF/dL; linear spring k = {a['k']:.3g} N/m per Pa", fontsize=10)
    axes[0].legend(handles=[Line2D([], [], color=colours[P], label=f"P = {P / 1e3:.0f} kPa") for P in CURVE_PRESSURES]
                   + [Line2D([], [], color="0.3", label="model (diverges at the fill limit)"),
                      Line2D([], [], color="0.3", ls="--", label="linear spring k (P - P_th)")], fontsize=7)
    axes[1].set(xlabel="muscle length L (mm)", ylabel="pressure gain dF/dP (N/MPa)")
    axes[1].set_title("pressure gain dF/dP over the stroke", fontsize=10)
    axes[1].legend(fontsize=7, title="in contact the gain does not depend on P", title_fontsize=7)
    slope, p0 = a["per_length"].T
    axes[2].plot(L, s["threshold"] / 1e3, label="threshold pressure P_th (model)")
    axes[2].plot(L, p0 / 1e3, "--", label="pressure of zero stiffness P0 (fit per length)")
    axes[2].set(xlabel="muscle length L (mm)", ylabel="pressure (kPa)")
    axes[2].set_title("where K = K1 (P - P0) meets zero, against P_th", fontsize=10)
    axes[2].legend(fontsize=7)
    fig.suptitle(f"Table 2.1 muscle {s['name']} (thick-walled bladder, 16 layers), linearized through "
                 "fmi2GetDirectionalDerivative", fontsize=12)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    path = OUT / f"muscle_{s['name']}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(args=None):
    """Writes docs/linearized-muscle.md and its plots; returns 1 if its own checks fail, else 0."""
    fmu_path("McKibbenMuscle")
    rows, images, failures = [], [], []
    for name, preset in MUSCLES.items():
        s = sweep(name, preset)
        a = analyse(s)
        images.append(plot(s, a))
        slope, p0 = a["per_length"].T
        ok = np.isfinite(slope)
        frac_fail = a["failing"].sum() / a["contact"].sum()
        where = s["lengths"][a["failing"].any(axis=1)]
        rows.append(
            f"| {name} | {a['k']:.4g} | {a['rms']:.1%} | {np.nanmin(slope[ok]):.3g} .. {np.nanmax(slope[ok]):.3g} | "
            f"{np.nanmax(np.abs(p0[ok] - s['threshold'][ok])) / 1e3:.0f} | {frac_fail:.0%} | "
            + (f"{where.min() * 1e3:.1f} .. {where.max() * 1e3:.1f}" if where.size else "none")
            + f" (stroke {s['lengths'][0] * 1e3:.1f} .. {s['lengths'][-1] * 1e3:.1f}) |"
        )
        # Checks: the stiffness grows with pressure in contact (positive slope) at every length.
        if not (slope[ok] > 0).all():
            failures.append(f"muscle {name}: stiffness does not grow with pressure everywhere")
        if not np.isfinite(s["K"]).all() or not np.isfinite(s["G"]).all():
            failures.append(f"muscle {name}: non-finite partials")
    text = f"""# The linearized McKibben muscle

Generated by `make linearized` (`python/actuator_fmus/linearized.py`) from the McKibbenMuscle FMU; do not
edit by hand.

Chapter 2's introduction proposes that, once a muscle is designed, a controls engineer can treat it
as a spring whose stiffness is proportional to the applied pressure minus the threshold pressure.
This page checks that against the full model. For Table 2.1's muscles A-D with the thick-walled
bladder (`bladder_model` 5, the dissertation's 16 layers as written, the chapter's latex), the stiffness `dF/dL` and the pressure
gain `dF/dP` are read through `fmi2GetDirectionalDerivative` (exact partials, no finite differences)
on a grid of {LENGTHS} lengths over the stroke (from the length where the muscle at 700 kPa pulls
nothing, to 2% of the length range short of the fill limit where the stiffness diverges) and
pressures 0 .. 700 kPa in 25 kPa steps. The threshold pressure `P_th(L)` is the FMU's
`threshold_pressure` output.

The proposal is fitted as `K = k (P - P_th(L))` over all grid points in contact (`P >= P_th`): one
slope `k` per muscle, by least squares on the relative error (the stiffness diverges at the fill
limit and would otherwise set the slope alone). Because every layer pressure of eq. 2.12 / 2.19 is affine in `P` at a fixed
diameter, the model's stiffness in contact is exactly affine in `P` at each length,
`K = K1(L) (P - P0(L))`: the proposal holds where `P0 = P_th` and `K1` is constant over the stroke.

| muscle | fitted k (N/m per Pa) | RMS relative error | K1 over the stroke (N/m per Pa) | max abs(P0 - P_th) (kPa) | contact points off by > {FAIL:.0%} | lengths where it fails (mm) |
|---|---|---|---|---|---|---|
""" + "\n".join(rows) + """

Where the proportionality fails:

- **Across the stroke.** `K1`, the stiffness per unit pressure, is not a constant: it grows from the
  short end of the stroke towards the long end (eq. 2.3 alone gives `dF/dL = 6 P L / (4 pi n^2)`,
  proportional to `L`, and the bladder's elastic force stiffens further towards the fill limit). A
  single slope is right at one operating length only; the table's failing lengths are the ends of
  the stroke.
- **The zero of the stiffness is not the threshold pressure.** At `P = P_th` the contact pressure is
  zero but the rubber's own axial elasticity and the end-cap force `-P A` still have a length
  slope, so the model's stiffness at threshold is not zero: `P0` differs from `P_th` (third plot).
- **Below the threshold** the bladder is free of the sleeve and the linear spring predicts zero
  stiffness, while the model keeps the bladder's elastic stiffness.

For a controller designed at one operating length, the linear spring is a fair local model; over
the whole stroke, use `K1(L)` and `P0(L)` from the FMU's directional derivatives instead.

""" + "\n\n".join(f"![Muscle {n}: stiffness, pressure gain and zero-stiffness pressure](linearized/{p.name})" for n, p in zip(MUSCLES, images)) + "\n"
    PAGE.write_text(text)
    print(text)
    if failures:
        print("\n".join(failures), file=sys.stderr)
        return 1
    return 0
