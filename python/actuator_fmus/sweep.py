"""Design sweep on Dask: bladder pre-strain and wall thickness against net work per stroke of the
McKibbenMuscle FMU (thick-walled Mooney-Rivlin bladder, dissertation eq. 2.19-2.20).

The muscle is Table 2.1's muscle A (strand length, turns, bore, listed length 103.25 mm) with the
bladder's unstretched length L_R0 = listed / (1 + pre-strain) and its wall thickness swept. Net
work per stroke is computed as examples/mckibben_muscles.py does: the integral of
F(690 kPa) - F(0) over the stroke, from the length where the pressurized force falls to zero up
to the top of the stroke, min(listed length, 0.99 max_length) (the force grows without bound at
max_length, so the top must stay below it).

Runs go to a Dask cluster in batches: a local cluster by default (--workers processes, one thread
each), or any running scheduler given by --scheduler tcp://host:8786. The FMU travels to the
workers as bytes (scattered once), so remote workers need no shared file system, only this
script's Python packages. Writes out/sweep.csv and out/sweep.png and prints runs per second.

    actuator-fmus sweep                    # 60 x 40 = 2400 runs on a local cluster
    actuator-fmus sweep --scheduler tcp://10.0.0.5:8786 --prestrains 200 --thicknesses 100"""

import hashlib
import math
import os
import pathlib
import sys
import tempfile
import time

from .paths import fmu_path
LISTED_LENGTH = 0.10325  # Table 2.1, muscle A
PRESSURE = 6.9e5  # 690 kPa, the dissertation's work figure
MUSCLE_A = {"strand_length": 0.1113, "turns": 3.74, "bladder_inner_diameter": 0.0016}


def _fmu_dir(fmu_bytes):
    """Extracts the FMU once per machine (keyed by its hash) and returns the directory."""
    import zipfile
    import io

    digest = hashlib.sha256(fmu_bytes).hexdigest()[:16]
    d = pathlib.Path(tempfile.gettempdir()) / f"actuator_fmus_sweep_{digest}"
    if not (d / "modelDescription.xml").exists():
        tmp = pathlib.Path(tempfile.mkdtemp(prefix=d.name + "_", dir=d.parent))
        zipfile.ZipFile(io.BytesIO(fmu_bytes)).extractall(tmp)
        try:
            os.replace(tmp, d)  # atomic: concurrent workers race harmlessly
        except OSError:
            pass
    return str(d)


def net_work(fmu, vr, prestrain, thickness, layers, n_lengths):
    """Net work (J) of one muscle; NaN if the FMU refuses the parameters or the stroke is empty."""
    fmu.reset()
    fmu.enterInitializationMode(startTime=0.0)
    reals = dict(MUSCLE_A, bladder_length=LISTED_LENGTH / (1 + prestrain), bladder_thickness=thickness, length=0.08)
    fmu.setReal([vr[k] for k in reals], list(reals.values()))
    # The dissertation's layers as written (bladder_model 5), as in the README's work table.
    fmu.setInteger([vr["bladder_model"], vr["bladder_layers"]], [5, layers])
    # ... with its signed force and inextensible strands.
    fmu.setBoolean([vr["signed_force"]], [True])
    fmu.setReal([vr["strand_rigidity"]], [1e12])
    try:
        fmu.exitInitializationMode()
    except Exception:
        return math.nan
    lo, hi = fmu.getReal([vr["min_length"], vr["max_length"]])
    top = min(LISTED_LENGTH, 0.99 * hi)
    bottom = 1.01 * lo
    if not bottom < top:
        return math.nan
    inputs, force = [vr["pressure"], vr["length"]], [vr["force"]]
    h = (top - bottom) / (n_lengths - 1)
    lengths = [bottom + i * h for i in range(n_lengths)]
    net = []
    for length in lengths:
        fmu.setReal(inputs, [PRESSURE, length])
        fp = fmu.getReal(force)[0]
        fmu.setReal(inputs, [0.0, length])
        net.append((fp, fp - fmu.getReal(force)[0]))
    # Contracting from the top, the stroke ends where the pressurized force first reaches zero.
    start = 0
    for i in range(n_lengths - 1, -1, -1):
        if net[i][0] <= 0.0:
            start = i + 1
            break
    if start >= n_lengths - 1:
        return 0.0
    work = sum(0.5 * (net[i][1] + net[i + 1][1]) * h for i in range(start, n_lengths - 1))
    if start > 0:
        # The partial interval down to the zero crossing of F(690 kPa), linearly interpolated.
        (f0, n0), (f1, n1) = net[start - 1], net[start]
        w = f1 / (f1 - f0) if f1 != f0 else 0.0
        work += 0.5 * (n1 + (n1 + w * (n0 - n1))) * w * h
    return work


def run_batch(fmu_bytes, cases, layers, n_lengths):
    """One task: a batch of (prestrain, thickness) cases on one FMU instance, reset between runs."""
    from actuator_fmus.fmu import CoSimulation

    d = _fmu_dir(fmu_bytes)
    fmu = CoSimulation(d, "sweep")
    vr = {v.name: v.valueReference for v in fmu.md.modelVariables}
    fmu.instantiate()
    out = []
    try:
        for prestrain, thickness in cases:
            out.append((prestrain, thickness, net_work(fmu, vr, prestrain, thickness, layers, n_lengths)))
    finally:
        fmu.freeInstance()
    return out


def sweep(prestrains, thicknesses, scheduler=None, workers=2, batch=20, layers=8, n_lengths=200,
          progress=True):
    """Runs the grid on Dask; returns (rows, seconds). rows: (prestrain, thickness, net work)."""
    import cloudpickle
    from dask.distributed import Client, LocalCluster, as_completed

    # Workers cannot import this file by name: ship its functions by value. Distributed pickles
    # with plain pickle when it can (by reference), so the task is a local function, which only
    # cloudpickle can serialize; with the module registered, cloudpickle copies run_batch too.
    if __name__ != "__main__" and __name__ in sys.modules:
        cloudpickle.register_pickle_by_value(sys.modules[__name__])

    def task(fmu, cases, layers, n_lengths):
        return run_batch(fmu, cases, layers, n_lengths)

    fmu_bytes = pathlib.Path(fmu_path("McKibbenMuscle")).read_bytes()
    cases = [(p, t) for p in prestrains for t in thicknesses]
    batches = [cases[i:i + batch] for i in range(0, len(cases), batch)]
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
    client = Client(scheduler or cluster)
    try:
        start = time.perf_counter()
        fmu_future = client.scatter(fmu_bytes, broadcast=True)
        futures = [client.submit(task, fmu_future, b, layers, n_lengths, pure=False) for b in batches]
        rows = []
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=len(cases), unit="run", desc="sweep")
        for future in as_completed(futures):
            result = future.result()
            rows.extend(result)
            if bar is not None:
                bar.update(len(result))
        if bar is not None:
            bar.close()
        seconds = time.perf_counter() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    rows.sort()
    return rows, seconds


def linspace(a, b, n):
    """`n` evenly spaced values from `a` to `b` (their unit), as a list."""
    return [a + (b - a) * i / (n - 1) for i in range(n)] if n > 1 else [a]


def plot(rows, prestrains, thicknesses, path):
    """Writes the map of net work per stroke (J) over pre-strain (%) and wall thickness (mm) to
    `path`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    grid = {(p, t): w for p, t, w in rows}
    z = np.array([[grid[(p, t)] for p in prestrains] for t in thicknesses])
    fig, ax = plt.subplots(figsize=(7, 4.8))
    # Near the corner where the bladder barely fits the work shoots up (the stroke's top nears
    # max_length); a robust colour range keeps the rest of the map readable.
    # The contours are drawn at levels inside that range only, so that every label can be read off
    # the colour bar; the bar's arrow stands for the work above it.
    from matplotlib.ticker import MaxNLocator

    lo, hi = np.nanpercentile(z, 1), np.nanpercentile(z, 97)
    mesh = ax.pcolormesh(np.array(prestrains) * 100, np.array(thicknesses) * 1e3, z, shading="auto",
                         vmin=lo, vmax=hi)
    bar = fig.colorbar(mesh, ax=ax, extend="both", label="net work per stroke (J)")
    levels = [x for x in MaxNLocator(5).tick_values(lo, hi) if lo < x < hi]
    cs = ax.contour(np.array(prestrains) * 100, np.array(thicknesses) * 1e3, z, levels=levels, colors="w",
                    linewidths=0.6)
    ax.clabel(cs, fontsize=7, fmt="%.2f J")
    for level in levels:
        bar.ax.axhline(level, color="w", linewidth=0.8)
    ax.set_xlabel("bladder pre-strain (%)")
    ax.set_ylabel("bladder wall thickness (mm)")
    ax.set_title("McKibbenMuscle, Table 2.1 muscle A sleeve, thick-walled bladder: net work per stroke at 690 kPa\n"
                 "(blank: the bladder does not fit the sleeve; stroke top = min(listed length, 0.99 max_length);\n"
                 "colours saturate beyond the 1st and 97th percentiles, white lines: contours in J)",
                 fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def add_arguments(parser):
    """The options of `actuator-fmus sweep`."""
    parser.add_argument("--scheduler", default=None, help="address of a running Dask scheduler (default: local cluster)")
    parser.add_argument("--workers", type=int, default=2, help="local cluster worker processes")
    parser.add_argument("--prestrains", type=int, default=60, help="pre-strain points, 0 .. 90%%")
    parser.add_argument("--thicknesses", type=int, default=40, help="wall thickness points, 0.4 .. 2.4 mm")
    parser.add_argument("--layers", type=int, default=8, help="bladder_layers of the thick wall")
    parser.add_argument("--lengths", type=int, default=200, help="length samples per stroke")
    parser.add_argument("--batch", type=int, default=20, help="runs per Dask task")
    parser.add_argument("--out", default="out", help="output directory (default: out)")


def main(args):
    """Runs the sweep and writes <out>/sweep.csv (pre-strain 1, thickness m, net work J) and
    sweep.png; returns 0."""
    prestrains = linspace(0.0, 0.9, args.prestrains)
    thicknesses = linspace(0.4e-3, 2.4e-3, args.thicknesses)
    rows, seconds = sweep(prestrains, thicknesses, args.scheduler, args.workers, args.batch, args.layers,
                          args.lengths)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "sweep.csv", "w") as f:
        f.write("prestrain,thickness_m,net_work_J\n")
        for p, t, w in rows:
            f.write(f"{p!r},{t!r},{w!r}\n")
    plot(rows, prestrains, thicknesses, out / "sweep.png")
    failed = sum(1 for r in rows if math.isnan(r[2]))
    print(f"{len(rows)} runs in {seconds:.1f} s: {len(rows) / seconds:.1f} runs/s "
          f"({args.lengths} lengths x 2 pressures each, {args.layers} layers); {failed} without a stroke")
    print(f"wrote {out}/sweep.csv and {out}/sweep.png")
    return 0

