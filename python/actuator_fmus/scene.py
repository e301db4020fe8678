"""Runs a scene file (scenes/*.json, format: scenes/schema/scene.schema.json) under FMPy: writes <out>/<scene>.csv and
<out>/<scene>.png, prints the dissertation's numbers beside ours, exits 1 if a check fails.

    actuator-fmus scene scenes/fig2_3_ideal_mckibben.json [--fast] [--out out]

Before anything runs, the scene's FMU, parameter, input and output names and its values are
checked against the FMU's model description: a mistake is one line naming the valid choices.
Every number in a scene and in the results is in the variable's SI unit.
"""

import json
import math
import pathlib
import re
import sys
import time as clock

import numpy as np

from . import names as checks
from .paths import ROOT, UsageError, fmu_path

LONG_RUN_STEPS = 1000  # runs with more communication steps than this show a progress bar
SCHEMA = ROOT / "scenes" / "schema" / "scene.schema.json"


class SceneError(UsageError):
    """A scene file that does not follow scenes/schema/scene.schema.json."""


def _dotted(path):
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".") or "(top level)"


def _innermost(error):
    """Descends into oneOf/anyOf: the branch whose `type`/`kind` tag matched, else the branch
    that failed least, so that the message names the field, not the whole signal or check."""
    while error.context:
        branches = {}
        for sub in error.context:
            branches.setdefault(sub.relative_schema_path[0], []).append(sub)
        tagged = [errs for errs in branches.values()
                  if not any(e.validator in ("const", "enum") for e in errs)]
        if not tagged:  # an unknown `type` or `kind`: list the known ones
            tags = [e for errs in branches.values() for e in errs if e.validator == "const"]
            if tags:
                tags[0].message = (f"{tags[0].instance!r} is not one of "
                                   + ", ".join(repr(e.validator_value) for e in tags))
                return tags[0]
        errors = tagged[0] if len(tagged) == 1 else min(branches.values(), key=len)
        error = max(errors, key=lambda e: len(e.absolute_path))
    return error


def schema_errors(scene):
    """One line per problem, each naming the field's path, e.g. `inputs.pressure.valu: unknown field`."""
    import jsonschema

    validator = jsonschema.Draft202012Validator(json.loads(SCHEMA.read_text()))
    lines = []
    for error in sorted(validator.iter_errors(scene), key=lambda e: list(map(str, e.absolute_path))):
        error = _innermost(error)
        path = list(error.absolute_path)
        if error.validator in ("additionalProperties", "unevaluatedProperties"):
            known = set(error.schema.get("properties", {}))
            for name in sorted(set(error.instance) - known):
                lines.append(f"{_dotted(path + [name])}: unknown field")
            continue
        lines.append(f"{_dotted(path)}: {error.message}")
    return lines


def load_scene(path, fast=False):
    """The scene file at `path`, checked against the schema (SceneError otherwise); `fast`: its short
    variant. Numbers in SI units."""
    path = pathlib.Path(path)
    scene = json.loads(path.read_text())
    errors = schema_errors(scene)
    if errors:
        raise SceneError(f"{path}: not a valid scene (scenes/schema/scene.schema.json): " + "; ".join(errors))
    scene["_name"] = path.stem
    scene["_dir"] = path.parent
    if fast and scene.get("fast"):
        f = scene["fast"]
        scene["step"] = f.get("step", scene["step"])
        scene["stop_time"] = f.get("stop_time", scene["stop_time"])
        if scene.get("sweep") and "sweep_values" in f:
            sweep = scene["sweep"]
            keep = [sweep["values"].index(v) for v in f["sweep_values"]]
            also = {name: [column[i] for i in keep] for name, column in sweep.get("also", {}).items()}
            scene["sweep"] = dict(sweep, values=f["sweep_values"], also=also)
    return scene


def check_scene(scene):
    """Checks the scene against its FMU's model description before it runs: the FMU exists; the
    parameters, the swept variable and its `also` columns are parameters or inputs with values in
    their declared ranges; the inputs are inputs whose signals stay in range; the outputs, the
    plotted and the checked variables exist. Raises SceneError (one line, valid choices named)."""
    model = scene["fmu"]
    where = f"{scene['_dir'] / scene['_name']}.json"
    try:
        fmu_path(model)
        checks.check_start_values(model, scene.get("parameters", {}))
        checks.check_input_names(model, scene.get("inputs", {}))
        checks.check_output_names(model, scene["outputs"])
        plot = scene.get("plot") or {}
        recorded = set(scene["outputs"]) | {"time"}
        for name in [plot.get("x")] + list(plot.get("y", [])) + [
                n for c in scene.get("checks", []) for n in (c.get("output"), c.get("x"))]:
            if name is not None and name not in recorded:
                raise UsageError(f"{model}: {name!r} is plotted or checked but not in the scene's outputs; "
                                 f"outputs: {', '.join(checks.nearest_first(name, sorted(recorded)))}")
        sweep = scene.get("sweep")
        if sweep:
            checks.check_name(model, sweep["variable"], checks.SETTABLE, "parameter or input")
        step, stop = scene["step"], scene["stop_time"]
        n = int(round(stop / step))
        t = np.linspace(0.0, n * step, n + 1)
        for _, _, parameters, inputs in sweep_runs(scene):
            checks.check_start_values(model, parameters)
            for name, signal in inputs.items():
                checks.check_input_values(model, name, signal_values(signal, t, stop, scene["_dir"]), t)
    except UsageError as e:
        raise SceneError(f"{where}: {e}") from None


def signal_values(signal, t, stop_time, directory):
    """The input `signal` of a scene sampled at times `t` (s), in its variable's SI unit."""
    kind = signal["type"]
    if kind == "constant":
        return np.full_like(t, signal["value"])
    if kind == "ramp":
        return signal["from"] + (signal["to"] - signal["from"]) * np.clip(t / stop_time, 0.0, 1.0)
    if kind == "cycle":
        phase = np.mod(t / signal["period"], 1.0)
        up = np.where(phase < 0.5, 2 * phase, 2 - 2 * phase)
        return signal["min"] + (signal["max"] - signal["min"]) * up
    if kind == "steps":
        idx = np.clip(np.searchsorted(signal["times"], t, side="right") - 1, 0, None)
        return np.asarray(signal["values"], dtype=float)[idx]
    if kind == "csv":
        data = np.genfromtxt(directory / signal["file"], delimiter=",", names=True)
        return np.interp(t, data["time"], data[signal["column"]])
    raise ValueError(f"unknown signal type {kind}")


class Progress:
    """A progress bar on stderr for long runs: redrawn in place on a terminal, in quarters in a log."""

    def __init__(self, label, total):
        self.label, self.total, self.shown, self.start = label, total, -1, clock.time()
        self.tty = sys.stderr.isatty()

    def update(self, done):
        percent = int(100 * done / self.total) if self.total else 100
        quantum = 1 if self.tty else 25
        if percent // quantum != self.shown:
            self.shown = percent // quantum
            bar = "#" * (percent // 4)
            end = "" if self.tty else "\n"
            print(f"\r{self.label} [{bar:<25}] {percent:3d}%", end=end, file=sys.stderr, flush=True)

    def close(self):
        print(f"{'' if self.tty else self.label} done in {clock.time() - self.start:.1f} s", file=sys.stderr, flush=True)


def sweep_runs(scene, indices=None):
    """(k, swept value, parameters, inputs) for each run of the scene's sweep (one run without a
    sweep): a swept input becomes a constant, a swept parameter and its `also` columns are set."""
    sweep = scene.get("sweep")
    values = sweep["values"] if sweep else [None]
    for k in range(len(values)) if indices is None else indices:
        parameters = dict(scene.get("parameters", {}))
        inputs = dict(scene.get("inputs", {}))
        if sweep:
            if sweep["variable"] in inputs:
                inputs[sweep["variable"]] = {"type": "constant", "value": values[k]}
            else:
                parameters[sweep["variable"]] = values[k]
            for name, column in sweep.get("also", {}).items():
                parameters[name] = column[k]
        yield k, values[k], parameters, inputs


def run_scene(scene, progress=True, fmu=None, fmi_type=None):
    """Returns a list of (sweep value or None, structured result array). `fmu`: the path of another
    .fmu of the scene's model (e.g. its FMI 3.0 FMU); `fmi_type`: "CoSimulation" (FMPy's default) or
    "ModelExchange"."""
    from fmpy import simulate_fmu

    check_scene(scene)
    fmu = fmu or fmu_path(scene["fmu"])
    sweep = scene.get("sweep")
    values = sweep["values"] if sweep else [None]
    step, stop = scene["step"], scene["stop_time"]
    n = int(round(stop / step))
    t = np.linspace(0.0, n * step, n + 1)
    runs = []
    for k, value, parameters, inputs in sweep_runs(scene):
        signals = None
        if inputs:
            # FMPy warns for every input without a column: the scene's other inputs are held at
            # their start values (the scene's parameters, else the declared ones), as they would
            # be without any input signal.
            held = {name: float(parameters.get(name, v.start))
                    for name, v in checks.variables(scene["fmu"]).items()
                    if v.causality == "input" and name not in inputs and checks.fmi2_type(v) == "Real"}
            signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in [*inputs, *held]])
            signals["time"] = t
            for name, signal in inputs.items():
                signals[name] = signal_values(signal, t, stop, scene["_dir"])
            for name, start in held.items():
                signals[name] = start
        label = f"{scene['_name']} {k + 1}/{len(values)}"
        bar = Progress(label, n) if progress and n >= LONG_RUN_STEPS else None

        def step_finished(time, _recorder):
            if bar:
                bar.update(round(time / step))
            return True

        result = simulate_fmu(
            fmu,
            start_values=checks.check_start_values(scene["fmu"], parameters),
            input=signals,
            output=scene["outputs"],
            stop_time=n * step,
            output_interval=step,
            step_finished=step_finished,
            fmi_type=fmi_type,
        )
        if bar:
            bar.close()
        runs.append((value, result))
    return runs


def zero_crossing(x, y):
    """The x where y first crosses zero, linearly interpolated (units of x); NaN if it never does."""
    sign = np.sign(y)
    idx = np.nonzero(sign[:-1] * sign[1:] <= 0)[0]
    if idx.size == 0:
        return math.nan
    i = idx[0]
    if y[i + 1] == y[i]:
        return float(x[i])
    return float(x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i]))


def units(scene):
    """Unit of every variable of the scene's FMU, from its model description."""
    from fmpy import read_model_description

    md = read_model_description(fmu_path(scene["fmu"]))
    return {v.name: v.unit or (v.declaredType.unit if v.declaredType else "") or "" for v in md.modelVariables}


# SI unit -> (display unit, factor from SI): what a person reads at a glance.
DISPLAY = {"Pa": ("kPa", 1e-3), "m": ("mm", 1e3), "rad": ("degrees", 180 / math.pi), "N.m": ("N m", 1.0),
           "m3": ("cm³", 1e6)}


def quantity(value, unit):
    """`value` (SI) in the unit a person reads: 172000 Pa -> "172 kPa", 0.7854 rad -> "45 degrees"."""
    if unit == "s":
        for name, factor in (("s", 1.0), ("ms", 1e3), ("µs", 1e6), ("ns", 1e9)):
            if value == 0 or abs(value) * factor >= 1:
                return f"{value * factor:.4g} {name}"
        return f"{value:.4g} s"
    if unit in ("", "1"):
        return f"{value:.4g}"
    name, factor = DISPLAY.get(unit, (unit.replace(".", " "), 1.0))
    return f"{value * factor:.4g} {name}"


def run_label(scene, value, unit_of):
    """"<swept variable> = <value in display units>" for a sweep run, "" without a sweep."""
    if value is None:
        return ""
    variable = scene["sweep"]["variable"]
    return f"{variable} = {quantity(value, unit_of.get(variable, ''))}"


def evaluate_checks(scene, runs):
    """Returns a list of (passed, text) for the scene's checks; numbers in SI units."""
    unit_of = units(scene) if scene.get("sweep") else {}
    results = []
    for check in scene.get("checks", []):
        kind, out = check["kind"], check["output"]
        if kind == "max":
            got = max(float(np.max(r[out])) for _, r in runs)
            ok = abs(got - check["expect"]) <= check["rel_tol"] * abs(check["expect"])
            results.append((ok, f"max {out} = {got:.6g}, dissertation {check['expect']:.6g} ({check['source']})"))
        elif kind == "zero_crossing":
            for value, r in runs:
                got = zero_crossing(r[check["x"]], r[out])
                ok = abs(got - check["expect"]) <= check["rel_tol"] * abs(check["expect"])
                run = run_label(scene, value, unit_of)
                results.append((ok, f"{out} = 0 at {check['x']} = {got:.6g}, dissertation {check['expect']:.6g} "
                                    f"({run + '; ' if run else ''}{check['source']})"))
        elif kind == "final":
            for value, r in runs:
                got = float(r[out][-1])
                ok = abs(got - check["expect"]) <= check["abs_tol"]
                run = run_label(scene, value, unit_of)
                results.append((ok, f"final {out} = {got:.6g}, dissertation {check['expect']:.6g} "
                                    f"({run + '; ' if run else ''}{check['source']})"))
        else:
            results.append((False, f"unknown check kind {kind}"))
    return results


def title_of(scene, width=80):
    """The figure number and the description's first sentence, wrapped, never cut."""
    import textwrap

    figure, _, said = scene["description"].partition(": ")
    first_sentence = re.split(r"\.\s+(?=[A-Z])", said)[0].rstrip(".")
    return textwrap.fill(f"{figure}: {first_sentence}", width=width)


def branches(x):
    """Index ranges where x rises and where it falls: [(slice, rising)], for cycle inputs."""
    dx = np.diff(x)
    if x.size < 3 or np.all(dx >= 0) or np.all(dx <= 0):
        return [(slice(0, x.size), None)]
    rising = dx >= 0
    out, start = [], 0
    for k in range(1, rising.size):
        if rising[k] != rising[k - 1]:
            out.append((slice(start, k + 1), bool(rising[k - 1])))
            start = k
    out.append((slice(start, x.size), bool(rising[-1])))
    return out


def write_outputs(scene, runs, out):
    """Writes <out>/<scene>.csv (SI units) and, if the scene has a plot, <out>/<scene>.png."""
    out.mkdir(parents=True, exist_ok=True)
    sweep = scene.get("sweep")
    names = list(runs[0][1].dtype.names)
    with open(out / f"{scene['_name']}.csv", "w") as f:
        header = ([sweep["variable"]] if sweep else []) + names
        f.write(",".join(header) + "\n")
        for value, r in runs:
            for row in r:
                f.write(",".join(([f"{value:.9g}"] if sweep else []) + [f"{row[n]:.9g}" for n in names]) + "\n")
    plot = scene.get("plot")
    if not plot:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    unit_of = units(scene)
    x_name = plot["x"]
    fig, ax = plt.subplots(figsize=(7.5, 5))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    handles, directions = [], set()
    curves = [(value, y) for value, _ in runs for y in plot["y"]]
    for k, ((value, y), r) in enumerate(zip(curves, [r for _, r in runs for _ in plot["y"]])):
        colour = colours[k % len(colours)]
        xs = r[x_name] * plot.get("x_scale", 1.0)
        ys = r[y] * plot.get("y_scale", 1.0)
        for part, rising in branches(xs):
            ax.plot(xs[part], ys[part], color=colour, linestyle="--" if rising is False else "-")
            if rising is not None:
                directions.add(rising)
        label = ", ".join(s for s in [run_label(scene, value, unit_of),
                                      y.replace("_", " ") if len(plot["y"]) > 1 else ""] if s)
        if label:
            handles.append(Line2D([], [], color=colour, label=label))
    if directions == {True, False}:
        what = x_name.replace("_", " ")
        rise, fall = (("extension (length rising)", "contraction (length falling)") if x_name == "length"
                      else (f"{what} rising", f"{what} falling"))
        handles += [Line2D([], [], color="0.3", linestyle="-", label=rise),
                    Line2D([], [], color="0.3", linestyle="--", label=fall)]
    ax.set_xlabel(plot["x_label"])
    ax.set_ylabel(plot["y_label"])
    if plot.get("y_limits"):
        ax.set_ylim(*plot["y_limits"])
    ax.set_title(title_of(scene), fontsize=9)
    ax.grid(alpha=0.3)
    if handles:
        ax.legend(handles=handles, fontsize=8)
    fig.tight_layout()
    fig.savefig(out / f"{scene['_name']}.png", dpi=110)
    plt.close(fig)


def add_arguments(parser):
    """The options of `actuator-fmus scene`."""
    parser.add_argument("scene", nargs="+", help="scene files (scenes/*.json)")
    parser.add_argument("--fast", action="store_true", help="the scene's short variant (as in make test)")
    parser.add_argument("--out", default="out", help="output directory (default: out)")


def main(args):
    """Runs each scene of `args.scene`; exits 1 if a check fails. Raises UsageError on a mistake."""
    scenes = [load_scene(path, fast=args.fast) for path in args.scene]
    for scene in scenes:
        check_scene(scene)
    failed = 0
    for scene in scenes:
        runs = run_scene(scene)
        write_outputs(scene, runs, pathlib.Path(args.out))
        for ok, text in evaluate_checks(scene, runs):
            print(f"  {'ok  ' if ok else 'FAIL'} {text}")
            failed += not ok
        print(f"wrote {args.out}/{scene['_name']}.csv" + (" and .png" if scene.get("plot") else ""))
    return 1 if failed else 0
