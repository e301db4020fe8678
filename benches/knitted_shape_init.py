"""Time of `fmi2ExitInitializationMode` of KnittedMuscle with the non-cylindrical shape (the
table is built there), through FMPy, for the section 1.4 prototype at 49 and 98 segments
(the goals: 3 ms and 10 ms; shape_segments is declared at most 98). Each figure is the best of `repeats` fresh instances, in
CPU time of this process (the FMU runs in it) and in wall time.

    .venv/bin/python benches/knitted_shape_init.py [--docs] [OTHER.fmu]

With another KnittedMuscle.fmu (for example one packaged from an older commit), the two are
timed interleaved, so that a loaded machine slows both alike, and their ratio is printed.
Prints a Markdown table over 49 and 98 segments."""

import os
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
from actuator_fmus import FMU_DIR  # noqa: E402

GOALS = {49: 3e-3, 98: 10e-3}


def instance(path):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(path))
    directory = extract(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}

    def exit_time(segments):
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=directory,
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="k")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setInteger([vr["shape_model"], vr["shape_segments"]], [2, segments])
        start, cpu = time.perf_counter(), time.process_time()
        fmu.exitInitializationMode()
        elapsed = (time.process_time() - cpu, time.perf_counter() - start)
        fmu.terminate()
        fmu.freeInstance()
        return elapsed

    return exit_time


def measure(paths, segments, repeats):
    """Best (CPU, wall) time per FMU (s), instances interleaved. The build is single-threaded, so
    on an idle machine the two agree; on a shared one the wall time adds the waits for a core."""
    timers = [instance(p) for p in paths]
    best = [(float("inf"), float("inf"))] * len(paths)
    for _ in range(repeats):
        for k, timer in enumerate(timers):
            cpu, wall = timer(segments)
            best[k] = (min(best[k][0], cpu), min(best[k][1], wall))
    return best


SEGMENTS = (49, 98)


def rows(paths, repeats=None):
    """Markdown rows over SEGMENTS, and the best CPU times of the first FMU by segments (over
    `repeats` builds each, by default 20 below 200 segments and 5 from there)."""
    header = "| segments | CPU time | wall time | goal (CPU) |"
    if len(paths) > 1:
        header += " other FMU, CPU | ratio |"
    out = [header, "|---" * (header.count("|") - 1) + "|"]
    times = {}
    for segments in SEGMENTS:
        best = measure(paths, segments, repeats or (20 if segments < 200 else 5))
        (cpu, wall) = best[0]
        times[segments] = cpu
        goal = GOALS.get(segments)
        verdict = f"<= {goal * 1e3:.0f} ms: {'met' if cpu <= goal else 'missed'}" if goal else ""
        line = f"| {segments:,} | {cpu * 1e3:.2f} ms | {wall * 1e3:.2f} ms | {verdict} |"
        if len(best) > 1:
            line += f" {best[1][0] * 1e3:.2f} ms | {best[1][0] / cpu:.1f}x |"
        out.append(line)
    return out, times


def main():
    """`--docs` writes the table into the `knitted-shape-init` block of docs/performance.md (as `make report`
    does); a path is another KnittedMuscle.fmu to time interleaved."""
    args = [a for a in sys.argv[1:] if a != "--docs"]
    paths = [FMU_DIR / "KnittedMuscle.fmu"] + [pathlib.Path(p) for p in args[:1]]
    table = rows(paths)[0]
    print("\n".join(table))
    if "--docs" in sys.argv:
        from report import write_docs_block
        write_docs_block("knitted-shape-init", table)
    print(f"load average during the run: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
