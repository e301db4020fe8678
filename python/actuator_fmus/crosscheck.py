"""Writes the FMI cross-check files of every packaged FMU (modelica/fmi-cross-check rules):

    crosscheck/<Model>/<Model>_in.csv   inputs (time first), linearly interpolated by the importer
    crosscheck/<Model>/<Model>_ref.csv  reference outputs at every communication point
    crosscheck/<Model>/<Model>_ref.opt  StartTime, StopTime, StepSize, RelTol

and docs/fmu/<Model>.png, the plot the packager puts into the FMU's documentation/.

The run is each model's default experiment with its default parameters (the rules allow no other
settings), StepSize = the default experiment's step as the communication step, and the inputs
below. An FMU not listed here gets no _in.csv (its inputs keep their start values) and its first
eight Real outputs. Usage: actuator-fmus crosscheck [Model ...]"""

import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu

from .paths import FMU_DIR, ROOT, UsageError, fmu_path, models

OUT = ROOT / "crosscheck"
PLOTS = ROOT / "docs" / "fmu"
REL_TOL = 1e-6


def _mckibben(t):
    # Pressure ramps 0 -> 600 kPa; length swings between 0.07 and 0.10 m (ideal muscle, b = 0.1113 m).
    return {"pressure": 6e5 * t, "length": 0.085 + 0.015 * np.sin(2 * np.pi * 2 * t)}


def _joint(t):
    # Like a robot simulator: a pressure-difference command and a swinging joint.
    w = 2 * np.pi * 1.5
    return {
        "actuatorInput": 4e5 * np.sin(2 * np.pi * 0.7 * t),
        "jointPosition": 0.3 * np.sin(w * t),
        "jointVelocity": 0.3 * w * np.cos(w * t),
    }


def _motor(t):
    # 200 MPa with the strain direction turning two full turns in 1.2 ms (continuous rotation).
    return {"strain_direction": 4 * np.pi * t / 1.2e-3, "stress": np.full_like(t, 2e8), "load_torque": np.zeros_like(t)}


def _pulley(t):
    # Muscle forces of a few newtons either way around 24 N: the joint swings against gravity.
    swing = 5 * np.sin(2 * np.pi * 0.5 * t)
    return {"flexor_force": 24 + swing, "extensor_force": 24 - swing}


def _knitted(t):
    # The section 1.4 prototype at 14 kPa, its length sweeping 0.25-0.50 m and back (ideal sleeve).
    return {"pressure": np.full_like(t, 1.4e4), "length": 0.375 - 0.125 * np.cos(2 * np.pi * t)}


def _free_bladder(t):
    # Muscle D's tube inflated to 40 kPa and vented while stretched 30% and back (its ballooning
    # pressure is 45.9 kPa at 1.3 times its length).
    return {"pressure": 4e4 * np.sin(np.pi * t) ** 2, "length": 0.1336 * (1 + 0.3 * np.sin(np.pi * t))}


def _pass_through(t):
    return {"u": np.sin(2 * np.pi * t)}


SPEC = {
    "McKibbenMuscle": (_mckibben, ["force", "volume", "effective_pressure", "stiffness"]),
    "KnittedMuscle": (_knitted, ["force", "volume", "max_radius", "stiffness"]),
    "McKibbenJoint": (_joint, ["jointTorque", "flexor_force", "extensor_force", "flexor_pressure", "extensor_pressure"]),
    "MultiferroicMotor": (_motor, ["torque", "rotor_angle", "rotor_speed", "onion_angle", "offset_angle"]),
    "PassThrough": (_pass_through, ["y"]),
    "FreeBladder": (_free_bladder, ["inner_diameter", "volume", "force", "stress_hoop"]),
    "PulleyJoint": (_pulley, ["joint_angle", "joint_velocity", "joint_torque", "flexor_pressure", "extensor_pressure"]),
}


def experiment(md):
    """(start, stop, step) of the model description's default experiment, in s."""
    de = md.defaultExperiment
    start = float(de.startTime or 0.0) if de else 0.0
    stop = float(de.stopTime or 1.0) if de else 1.0
    step = float(de.stepSize) if de and de.stepSize else (stop - start) / 1000
    return start, stop, step


def write_csv(path, names, columns):
    """Writes `columns` (SI units, time in s first) under the header `names` to `path`."""
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in zip(*columns):
            f.write(",".join(repr(float(x)) for x in row) + "\n")


def generate(model):
    """Writes crosscheck/<model>/ (inputs, reference outputs in SI units, options) and
    docs/fmu/<model>.png."""
    fmu = str(FMU_DIR / f"{model}.fmu")
    md = read_model_description(fmu)
    start, stop, step = experiment(md)
    inputs_of, outputs = SPEC.get(model, (None, None))
    if outputs is None:
        outputs = [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"][:8]
    d = OUT / model
    d.mkdir(parents=True, exist_ok=True)
    signals = None
    if inputs_of is not None:
        # Inputs at 201 points: the importer interpolates linearly between them.
        t = np.linspace(start, stop, 201)
        values = inputs_of(t)
        names = ["time"] + list(values)
        write_csv(d / f"{model}_in.csv", names, [t] + [values[n] for n in values])
        signals = np.array(list(zip(t, *values.values())), dtype=[(n, np.float64) for n in names])
    with open(d / f"{model}_ref.opt", "w") as f:
        f.write(f"StartTime, {start!r}\nStopTime, {stop!r}\nStepSize, {step!r}\nRelTol, {REL_TOL!r}\n")
    result = simulate_fmu(fmu, start_time=start, stop_time=stop, output_interval=step, input=signals, output=outputs)
    write_csv(d / f"{model}_ref.csv", ["time"] + outputs, [result[n] for n in ["time"] + outputs])
    plot(model, md, signals, result, outputs)
    print(f"{model}: {len(result)} rows, {start} .. {stop} s every {step} s -> {d}", file=sys.stderr)


PREFIXES = [(1e-18, "a"), (1e-15, "f"), (1e-12, "p"), (1e-9, "n"), (1e-6, "µ"), (1e-3, "m"), (1.0, ""),
            (1e3, "k"), (1e6, "M"), (1e9, "G")]


def display_unit(unit, values):
    """(label, factor): the unit a person reads, with an SI prefix that puts the largest value
    between 1 and 1000 (torque 2.2e-18 N m -> aN m), degrees for radians."""
    largest = float(np.max(np.abs(values))) if len(values) else 0.0
    if unit == "rad":
        return "degrees", 180.0 / np.pi
    if unit in ("", "1"):
        return "", 1.0
    if unit == "m3":
        for label, factor in (("cm³", 1e6), ("mm³", 1e9), ("µm³", 1e18)):
            if largest * factor >= 1:
                return label, factor
        return "m³", 1.0
    prefix_of = [(scale, p) for scale, p in PREFIXES if largest >= scale]
    scale, prefix = prefix_of[-1] if prefix_of and largest > 0 else (1.0, "")
    pretty = unit.replace(".", " ").replace("2", "²")
    if prefix and (" " in pretty or "/" in pretty):
        first, _, rest = pretty.partition(" " if " " in pretty else "/")
        pretty = f"{prefix}{first}{' ' if ' ' in unit.replace('.', ' ') else '/'}{rest}"
    else:
        pretty = prefix + pretty
    return pretty, 1.0 / scale


def plot(model, md, signals, result, outputs):
    """One panel per unit, inputs first, every curve in physical units."""
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    units = {v.name: v.unit or (v.declaredType.unit if v.declaredType else "") or "" for v in md.modelVariables}
    panels = []  # (title, source, names)
    for title, source, names in ((["input"], signals, list(signals.dtype.names[1:]) if signals is not None else []),
                                 (["output"], result, outputs)):
        by_unit = {}
        for n in names:
            by_unit.setdefault(units.get(n, ""), []).append(n)
        panels += [(title[0], source, group) for group in by_unit.values()]
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 1.9 * len(panels) + 0.8), sharex=True, squeeze=False)
    time_label, time_factor = display_unit("s", result["time"])
    for ax, (kind, source, names) in zip(axes[:, 0], panels):
        values = np.concatenate([np.asarray(source[n], dtype=float) for n in names])
        label, factor = display_unit(units.get(names[0], ""), values)
        for n in names:
            ax.plot(source["time"] * time_factor, np.asarray(source[n], dtype=float) * factor,
                    label=f"{n.replace('_', ' ')}" + (f" ({label})" if label else ""))
        ylabel = f"{kind}s" + (f" ({label})" if label else "")
        ax.set_ylabel(textwrap.fill(ylabel, 16), fontsize=8)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(f"time ({time_label})")
    fig.suptitle(f"{model}: cross-check run (default experiment, inputs from {model}_in.csv)", fontsize=10)
    fig.tight_layout()
    PLOTS.mkdir(parents=True, exist_ok=True)
    fig.savefig(PLOTS / f"{model}.png", dpi=80)
    plt.close(fig)


def add_arguments(parser):
    """The options of `actuator-fmus crosscheck`."""
    parser.add_argument("model", nargs="*", help="FMU names (default: every packaged FMU)")


def main(args):
    """Writes the cross-check files of `args.model` (all packaged FMUs if none); returns 0."""
    chosen = args.model or models()
    if not chosen:
        raise UsageError(f"no FMUs in {FMU_DIR}: run `make fmus` first")
    for model in chosen:
        fmu_path(model)  # a misspelt name fails before any run
    for model in chosen:
        generate(model)
    return 0
