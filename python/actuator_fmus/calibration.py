"""Calibrate McKibbenMuscle to a datasheet: one Python function around the native fitter.

    from actuator_fmus.calibration import calibrate
    summary = calibrate("data/festo/festo_dmsp40.csv", length=0.4, diameter=0.04, fit_kpa=[0, 600],
                        out="out/calibrate/dmsp40")

runs `target/release/calibrate` (the fit, with the FMU's own physics), then checks the fitted
parameters through the packaged McKibbenMuscle.fmu under FMPy and writes `OUT/report.md` with the
error table and `OUT/fit.png` (data against model at every pressure). Also a command line:

    actuator-fmus calibrate DATA --length 0.4 --diameter 0.04 --fit-kpa 0,600 --out OUT [--starts 24]

Units: lengths and diameters in m, forces in N, pressures in Pa except where a name ends in
`_kpa` (the datasheet's column and the fit pressures are in kPa, as datasheets give them).
"""

import csv
import json
import pathlib
import subprocess
import textwrap

from .paths import RELEASE, UsageError
from .slave import Slave

BINARY = RELEASE / "calibrate"
MODEL = "McKibbenMuscle"


def fmu_forces(params, points):
    """McKibbenMuscle.fmu's force (N) at each (gauge pressure Pa, length m), with `params` (SI
    start values, e.g. params.json) set; one 1 ms step per point, in order."""
    p0, l0 = points[0]
    # The fitter's muscle: the signed force of the datasheets, inextensible strands.
    model = {"signed_force": True, "strand_rigidity": 1e12, **params}
    muscle = Slave(MODEL, **{**model, "pressure": p0, "length": l0})
    try:
        forces = []
        for p, length in points:
            muscle.step(1e-3, pressure=p, length=length)
            forces.append(muscle.get("force"))
    finally:
        muscle.close()
    return forces


def _errors(rows, force_key):
    """{pressure_kpa: (rms, max)} as fractions of each curve's largest measured force."""
    out = {}
    for kpa in sorted({r["pressure_kpa"] for r in rows}):
        curve = [r for r in rows if r["pressure_kpa"] == kpa]
        scale = max(abs(r["force_n"]) for r in curve)
        e = [abs(r[force_key] - r["force_n"]) / scale for r in curve]
        out[kpa] = ((sum(x * x for x in e) / len(e)) ** 0.5, max(e))
    return out


def _plot(rows, summary, path, title, dense=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5))
    pressures = sorted({r["pressure_kpa"] for r in rows})
    colors = plt.cm.viridis([i / max(1, len(pressures) - 1) for i in range(len(pressures))])
    fitted = set(summary["fit_kpa"])
    for kpa, color in zip(pressures, colors):
        curve = sorted((r for r in rows if r["pressure_kpa"] == kpa), key=lambda r: r["contraction"])
        c = [100 * r["contraction"] for r in curve]
        role = "fitted" if kpa in fitted else "predicted"
        ax.plot(c, [r["force_n"] for r in curve], "o", color=color, ms=4,
                label=f"datasheet, {kpa:g} kPa")
        if dense:  # the FMU sampled finely over the curve's range
            c, f = dense[kpa]
            c = [100 * x for x in c]
        else:
            f = [r["model_force_n"] for r in curve]
        ax.plot(c, f, "-", color=color, label=f"model, {kpa:g} kPa ({role})")
    ax.set_xlabel("contraction 1 - L / L_N (%)")
    ax.set_ylabel("force (N)")
    ax.set_title("\n".join(textwrap.wrap(title, 70)))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def calibrate(data, length, diameter, fit_kpa, out, starts=24, verify=True):
    """Fits McKibbenMuscle to the curves of `data` (CSV `pressure_kpa,contraction,force_n`) at the
    pressures `fit_kpa` for a muscle of nominal length `length` (m) and inner diameter `diameter`
    (m). Writes OUT/params.json, params.ssv, fit.csv, fit.json, report.md and fit.png; returns the
    summary (fit.json) with, if `verify`, the errors recomputed through the FMU."""
    out = pathlib.Path(out)
    if not BINARY.exists():
        raise UsageError(f"{BINARY} is missing: run `make fmus` (it builds the fitter too)")
    if not pathlib.Path(data).is_file():
        raise UsageError(f"no datasheet at {data}: give a CSV with columns pressure_kpa,contraction,force_n")
    cmd = [str(BINARY), "--data", str(data), "--length", repr(float(length)),
           "--diameter", repr(float(diameter)), "--fit", ",".join(f"{k:g}" for k in fit_kpa),
           "--out", str(out), "--starts", str(starts)]
    subprocess.run(cmd, check=True)
    summary = json.loads((out / "fit.json").read_text())
    params = json.loads((out / "params.json").read_text())
    with open(out / "fit.csv") as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    native = _errors(rows, "model_force_n")
    if verify:
        points = [(1e3 * r["pressure_kpa"], length * (1 - r["contraction"])) for r in rows]
        for r, f in zip(rows, fmu_forces(params, points)):
            r["fmu_force_n"] = f
        through_fmu = _errors(rows, "fmu_force_n")
        summary["fmu_max_force_difference_n"] = max(abs(r["fmu_force_n"] - r["model_force_n"]) for r in rows)
        summary["fmu_errors"] = {f"{k:g}": {"rms": v[0], "max": v[1]} for k, v in through_fmu.items()}
    dense = None
    if verify:
        # Smooth model curves for the plot: 60 contractions per pressure, through the FMU.
        dense, grid = {}, []
        for kpa in sorted({r["pressure_kpa"] for r in rows}):
            cs = [r["contraction"] for r in rows if r["pressure_kpa"] == kpa]
            c = [min(cs) + (max(cs) - min(cs)) * i / 59 for i in range(60)]
            dense[kpa] = (c, None)
            grid += [(1e3 * kpa, length * (1 - x)) for x in c]
        forces = fmu_forces(params, grid)
        for i, kpa in enumerate(dense):
            dense[kpa] = (dense[kpa][0], forces[60 * i: 60 * (i + 1)])
    name = pathlib.Path(data).stem
    title = (f"{name}: datasheet force against McKibbenMuscle fitted at "
             f"{' + '.join(f'{k:g}' for k in fit_kpa)} kPa (nominal length {length:g} m, "
             f"bladder_model {summary['bladder_model']}, the exact wall)")
    _plot(rows, summary, out / "fit.png", title, dense)
    lines = [f"# Calibration of McKibbenMuscle to `{name}`", "",
             f"Fitted at {', '.join(f'{k:g}' for k in fit_kpa)} kPa in {summary['seconds']:.2f} s "
             f"({starts} starts); nominal length {length:g} m, nominal inner diameter {diameter:g} m; "
             f"braid angle at the nominal length {summary['braid_angle_deg']:.2f} deg; valid lengths "
             f"{summary['min_length']:.4g} .. {summary['max_length']:.4g} m.", "",
             "Errors as a fraction of each curve's largest force:", "",
             "| pressure (kPa) | role | RMS | max |" + (" RMS through the FMU | max through the FMU |" if verify else ""),
             "|---|---|---|---|" + ("---|---|" if verify else "")]
    for kpa, (rms, mx) in native.items():
        role = "fitted" if kpa in set(fit_kpa) else "predicted"
        row = f"| {kpa:g} | {role} | {100 * rms:.2f}% | {100 * mx:.2f}% |"
        if verify:
            e = summary["fmu_errors"][f"{kpa:g}"]
            row += f" {100 * e['rms']:.2f}% | {100 * e['max']:.2f}% |"
        lines.append(row)
    if verify:
        lines += ["", f"Largest difference between the fitter's and the FMU's force at the data points: "
                  f"{summary['fmu_max_force_difference_n']:.3g} N."]
    lines += ["", "Every parameter beside the search's bounds (fixed: not identifiable from force curves, "
              "set from the datasheet or physics; see docs/calibration.md):", "",
              "| parameter | value | lower bound | upper bound | fitted | position in the bounds |",
              "|---|---|---|---|---|---|"]
    for p in summary["parameters"]:
        role = "fixed" if p["fixed"] else "fitted"
        if p["name"] == "sleeve_diameter" and p["fixed"]:
            role = "bore + 2 wall"
        position = "" if p["fixed"] else f"{p['position']:.3f}"
        lines.append(f"| `{p['name']}` ({p['unit']}) | {p['value']:.6g} | {p['lower']:.4g} | {p['upper']:.4g} | "
                     f"{role} | {position} |")
    lines += ["", "![datasheet against model](fit.png)", "", "Parameters (`params.json`, FMPy `start_values`):",
              "", "```json", (out / "params.json").read_text().strip(), "```", ""]
    (out / "report.md").write_text("\n".join(lines))
    print(f"wrote {out / 'report.md'}")
    return summary


def add_arguments(parser):
    """The options of `actuator-fmus calibrate` (lengths in m, pressures in kPa as datasheets give
    them)."""
    parser.add_argument("data", help="datasheet CSV with columns pressure_kpa,contraction,force_n")
    parser.add_argument("--length", type=float, required=True, help="nominal length of the muscle, m")
    parser.add_argument("--diameter", type=float, required=True, help="nominal inner diameter, m")
    parser.add_argument("--fit-kpa", default="0,600", help="pressures to fit at, kPa, comma-separated (default 0,600)")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--starts", type=int, default=24, help="starting points of the search (default 24)")


def main(args):
    """Runs the fit of `args`; returns 0."""
    try:
        fit_kpa = [float(k) for k in args.fit_kpa.split(",")]
    except ValueError:
        raise UsageError(f"--fit-kpa {args.fit_kpa!r}: give pressures in kPa separated by commas, e.g. 0,600") from None
    calibrate(args.data, args.length, args.diameter, fit_kpa, args.out, starts=args.starts)
    return 0
