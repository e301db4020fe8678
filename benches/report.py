"""Writes docs/accuracy-cost.md: for every fidelity knob, the error against a converged reference
(computed here under FMPy) beside the native time per step (criterion, benches/accuracy_cost.rs,
read from target/criterion), log-log work-precision plots, the cost under FMPy beside the
PassThrough FMU, and the performance goals. Run by `make report` after the benchmarks;
`benches/report.py --replot` redraws only the work-precision plots from docs/accuracy-cost.md;
`benches/report.py --smoke` (run by `make test`) initializes and steps every configuration the
report uses, a few times each, and writes nothing: a configuration an FMU refuses fails it.

Timings are CPU time of the measuring thread wherever the machine's load would dominate wall
time: the criterion bench measures thread CPU time (benches/cpu_clock.rs), benches/cpu_time.rs
the motor's step and the two bladder walls, the FMPy batches `time.thread_time()`, the knitted
table's initialization `time.process_time()`. Only the FMI-layer table (benches/parity.rs,
nanoseconds per call, interleaved minima) stays in wall time."""

import json
import math
import pathlib
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
from actuator_fmus import FMU_DIR, Slave  # noqa: E402
import knitted_shape_init  # noqa: E402
from knitted_shape_init import GOALS  # noqa: E402

DOCS = ROOT / "docs"
SMOKE = "--smoke" in sys.argv
# Points along each scenario; the smoke run only checks that every configuration runs.
SCENARIO_POINTS = 2 if SMOKE else 40
PLOTS = DOCS / "accuracy"


def criterion_times():
    """Median native time per step (s) by configuration id `<FMU>/<knob>/<value>`."""
    times = {}
    for bench in (ROOT / "target" / "criterion" / "accuracy_cost").glob("*/new/benchmark.json"):
        meta = json.loads(bench.read_text())
        estimates = json.loads((bench.parent / "estimates.json").read_text())
        times[meta["function_id"]] = estimates["median"]["point_estimate"] * 1e-9
    return times


def shape_table_times():
    """Criterion medians (s) of benches/knitted_shape.rs, by function name, if it has run."""
    times = {}
    for bench in (ROOT / "target" / "criterion").glob("*/*/new/benchmark.json"):
        meta = json.loads(bench.read_text())
        if meta.get("group_id", "").startswith("knitted shape table"):
            estimates = json.loads((bench.parent / "estimates.json").read_text())
            times[meta["function_id"]] = estimates["median"]["point_estimate"] * 1e-9
    return times


def cpu_figures():
    """benches/cpu_time.rs's CPU-time figures (target/cpu_time/cpu_time.json), if it has run."""
    path = ROOT / "target" / "cpu_time" / "cpu_time.json"
    if not path.exists():
        return None
    data = json.loads(path.read_text())
    data["by_case"] = {c["case"]: c for c in data["cases"]}
    return data


CPU = None
MOTOR_STEPPING = "MultiferroicMotor, stepping schedule, 1 us steps over 12 periods"
MOTOR_LOADED = "MultiferroicMotor, load torque 1e-12 N m (load-dominated), 1 us steps"
MOTOR_FAST_SLIP = "MultiferroicMotor, load torque 1e-13 N m (fast slip), 1 us steps"
WALL_LAYERS = "McKibbenMuscle, layered wall, 16 layers"
WALL_CONTINUUM = "McKibbenMuscle, continuum wall, 8 nodes"


def cpu_goal_rows():
    """The goals that benches/cpu_time.rs measures in CPU time, each beside its figure."""
    if CPU is None:
        return []
    by = CPU["by_case"]
    rows = []
    if WALL_LAYERS in by and WALL_CONTINUUM in by:
        r = CPU["walls_ratio"]
        rows.append(f"| continuum wall, 8 nodes: cost <= 16 layers, `Bladder::evaluate` in CPU time, median of the "
                    f"rounds' ratios | {r:.2f}x ({fmt_time(by[WALL_CONTINUUM]['cpu_s'])} against "
                    f"{fmt_time(by[WALL_LAYERS]['cpu_s'])}, minima) | {goal_verdict(r, 1.0)} |")
    if MOTOR_STEPPING in by:
        m = by[MOTOR_STEPPING]
        rows.append(f"| motor, 1 us step of the stepping scene <= 2 us natively, `Motor::step` in CPU time, average over "
                    f"12 periods | {fmt_time(m['cpu_s'])} ({m['substeps']:.2f} substeps per step) | "
                    f"{goal_verdict(m['cpu_s'], 2e-6)} |")
    if MOTOR_LOADED in by:
        m = by[MOTOR_LOADED]
        rows.append(f"| motor with a load torque of 1e-12 N m (5e5 times the 2.16e-18 N m peak, 3e10 rad/s): 1 us step "
                    f"stays cheap, CPU time | {fmt_time(m['cpu_s'])} | one closed-form segment and one march around the onion's cycle |")
    if MOTOR_FAST_SLIP in by:
        m = by[MOTOR_FAST_SLIP]
        rows.append(f"| motor with a load torque of 1e-13 N m (thousands of turns per 1 us step), CPU time | "
                    f"{fmt_time(m['cpu_s'])} ({m['substeps']:.0f} substeps per step) | the ring's torque averaged over the onion's cycle |")
    return rows


def parity_figures():
    """benches/parity.rs's interleaved figures (target/parity/parity.json), if it has run."""
    path = ROOT / "target" / "parity" / "parity.json"
    if not path.exists():
        return None
    data = json.loads(path.read_text())
    data["by_case"] = {c["case"]: c for c in data["cases"]}
    data["init"] = {k["segments"]: k["min_s"] for k in data.get("knitted_initialization", [])}
    data["cold_by_case"] = {c["case"]: c["median_s"] for c in data.get("cold", [])}
    data["instructions_by_case"] = {c["case"]: c["per_step"] for c in data.get("instructions", [])}
    data["calls_by_case"] = {c["case"]: c["per_call"] for c in data.get("instructions", []) if "per_call" in c}
    return data


C_CASE = "C pass-through"


def parity_table(parity):
    """The FMI layer against the C pass-through FMU, from one interleaved run."""
    c = parity["by_case"][C_CASE]
    cold = parity["cold_by_case"]
    # Instructions per step (callgrind): the same on a loaded machine as on an idle one.
    instr = parity["instructions_by_case"]
    c_instr = instr.get(C_CASE)
    calls = parity.get("calls_by_case", {})
    rows = ["| FMU (one `fmi2SetReal`, one `fmi2DoStep`, one `fmi2GetReal`) | min | median | min against C "
            "| median against C | median with cold caches | instructions (against C) "
            "| of which set / doStep / get |",
            "|---|---|---|---|---|---|---|---|"]
    for case in parity["cases"]:
        t = cold.get(case["case"])
        n = instr.get(case["case"])
        per_call = calls.get(case["case"])
        split = " / ".join(f"{per_call[f]:.0f}" for f in ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal")) \
            if per_call else ""
        rows.append(f"| {case['case']} | {fmt_time_ns(case['min_s'])} | {fmt_time_ns(case['median_s'])} | "
                    f"{case['min_s'] / c['min_s']:.2f}x | {case['median_s'] / c['median_s']:.2f}x | "
                    f"{fmt_time_ns(t) if t else ''} | "
                    f"{f'{n:.0f} ({n / c_instr:.2f}x)' if n and c_instr else ''} | {split} |")
    return rows


def fmt_time_ns(s):
    return f"{s * 1e9:.1f} ns" if s < 1e-6 else fmt_time(s)


def goal_verdict(measured, goal, why=""):
    return "met" if measured <= goal else f"missed by {measured / goal:.2f}x" + (f": {why}" if why else "")


# The FMI layer's goals: the case and its budget against the C fixture (interleaved minima).
FMI_LAYER_GOALS = (("PassThrough", 2.0), ("McKibbenMuscle, ideal", 2.5))


def fmi_layer_goal_rows(parity):
    """The FMI layer's goals beside the interleaved minima and instruction counts."""
    by = parity["by_case"]
    c = by[C_CASE]["min_s"]
    rows = []
    for name, goal in FMI_LAYER_GOALS:
        if name in by:
            r = by[name]["min_s"] / c
            n, c_n = parity["instructions_by_case"].get(name), parity["instructions_by_case"].get(C_CASE)
            count = f"; {n:.0f} against {c_n:.0f} instructions, {n / c_n:.2f}x" if n and c_n else ""
            rows.append(f"| {name} <= {goal}x the C pass-through FMU, interleaved minimum | "
                        f"{r:.2f}x ({by[name]['min_s'] * 1e9:.1f} ns against {c * 1e9:.1f} ns{count}) | "
                        f"{goal_verdict(r, goal, FMI_LAYER_WHY)} |")
    return rows


def rewrite_fmi_layer_goal_rows(parity):
    """`make parity`: the FMI layer's rows of docs/accuracy-cost.md's goal table, in place."""
    page = DOCS / "accuracy-cost.md"
    new = {row.split(" | ")[0]: row for row in fmi_layer_goal_rows(parity)}
    lines = [new.get(line.split(" | ")[0], line) for line in page.read_text().split("\n")]
    page.write_text("\n".join(lines))
    print(f"rewrote {page.relative_to(ROOT)}: the FMI layer's goal rows")


def parity_goal_rows(parity):
    """The goals that benches/parity.rs measures, each beside its figure."""
    if parity is None:
        return ["| FMI layer, continuum wall cost, motor step, knitted table | not measured: "
                "run `cargo bench --bench parity` (make report does) | open |"]
    by = parity["by_case"]
    rows = fmi_layer_goal_rows(parity)
    cont, lay = by.get("McKibbenMuscle, continuum wall, 8 nodes"), by.get("McKibbenMuscle, layered wall, 16 layers")
    if CPU is not None:
        cont = lay = motor_case = None  # the CPU-time rows (cpu_goal_rows) stand for these
    else:
        motor_case = by.get("MultiferroicMotor, 1 us step")
    if cont and lay and parity.get("walls_round_ratio"):
        r = parity["walls_round_ratio"]
        rows.append(f"| continuum wall, 8 nodes: cost <= 16 layers, median of the {parity['rounds']} rounds' ratios | "
                    f"{r:.2f}x (medians {fmt_time(cont['median_s'])} against {fmt_time(lay['median_s'])}, minima "
                    f"{fmt_time(cont['min_s'])} against {fmt_time(lay['min_s'])}) | "
                    f"{goal_verdict(r, 1.0, 'a node costs an exponential, a square root and two divisions, a layer one division')} |")
    motor = motor_case
    if motor:
        rows.append(f"| motor, per 1 us communication step <= 2 us natively, median | "
                    f"{fmt_time(motor['median_s'])} | {goal_verdict(motor['median_s'], 2e-6, EXPLANATIONS['MultiferroicMotor/tolerance/1e-6'])} |")
    # The shape table's goals come from benches/knitted_shape_init.py (CPU time through FMPy) when
    # it ran; the parity run's wall-clock figure stands in otherwise.
    for segments, goal, label in (() if SHAPE_INIT else ((49, 3e-3, "prototype (49 rows)"), (98, 10e-3, "98 segments (the most accepted)"))):
        t = parity["init"].get(segments)
        if t is not None:
            rows.append(f"| knitted shape table, {label}: `fmi2ExitInitializationMode` <= {fmt_time(goal)} "
                        f"through the FMU | {fmt_time(t)} | {goal_verdict(t, goal)} |")
    return rows


# Where the FMI layer's remaining nanoseconds go (callgrind, benches/parity.rs; docs/accuracy-cost.md, "Where the
# nanoseconds went"). Shown only beside a missed goal.
FMI_LAYER_WHY = ('the one path\'s checks (the handle\'s lookup in the instance table, the call\'s state, the range and NaN checks of every value set and got) and one dynamic call into the model per FMI call, which the C fixture does not make (see "Where the time goes" below)')


# docs/accuracy-cost.md, "The FMI layer against C": how the table is measured and where a step's
# instructions go. `make report` writes it; `make parity` rewrites only the table below it.
FMI_LAYER_TEXT = """`benches/parity.rs` (`make parity`, `make bench`, `make report`) loads every binary through the same C
ABI harness and times one set + step + get per case, {rounds} rounds interleaved in one process (each
round times every case once, in a rotating order), so the ratios hold on a loaded machine. The
yardstick is `benches/c_passthrough/passthrough.c`, a C pass-through FMU with the Reference-FMUs'
Feedthrough semantics (state mask, NULL checks, a `switch` on the value reference, a dirty flag,
the communication-point check), built with `cc -O2 -shared`. The motor's cost depends on where in
its schedule a batch falls: read its median. The cold-cache column times each step alone after
writing 4 MB, so that the step finds its code and data out of the caches, as it does under an
importer that runs an interpreter between steps. The last two columns count instructions under
callgrind (20,000 steps): per step, the harness's loop included, and per call, each call with
everything it calls. The load cannot move them.

Where the time goes: a communication step is three calls, each one path. Every call looks the
importer's handle up in the table of live instances (a freed or forged handle finds nothing
there), checks the arrays and that the call is allowed in the current state, and runs under a
panic guard, which costs nothing unless something panics. `fmi2SetReal` checks each value against
its declared range (two comparisons, which refuse NaN and infinities too) and stores it through
one dynamic call into the model's values. `fmi2DoStep` checks the step size and the communication
point, steps the model through one dynamic call (the same code for every model) and advances the
clock; a step with nothing to report allocates nothing. `fmi2GetReal` asks whether the outputs
are current (after a step they are), reads them through one dynamic call and refuses any that is
not finite. The C fixture has none of the handle table, the range checks and the dynamic calls.
For PassThrough that bookkeeping is the whole cost; the ideal McKibben adds eq. 2.3, a few
multiplications inside `fmi2DoStep`. The walls and the motor spend their time in their physics:
the bladder's equilibrium, the rotor's integration."""


def progress(text):
    print(text, file=sys.stderr, flush=True)


# ---- accuracy: the scenarios of benches/accuracy_cost.rs ----

def forces(model, pressure, lengths, **parameters):
    """The force along `lengths` at constant `pressure`, inputs set without stepping."""
    m = Slave(model, length=lengths[0], **parameters)
    f = np.array([m.at("force", pressure=pressure, length=L) for L in lengths])
    m.close()
    return f


def friction_effect(model, pressure, lengths, scale, **parameters):
    """Friction is an effect, not an approximation: its "error" is how much leaving it off
    changes the force, the largest friction force along the stepped path relative to `scale`."""
    m = Slave(model, friction=True, length=lengths[0], **parameters)
    friction = []
    for L in lengths:
        m.step(pressure=pressure, length=L)
        friction.append(m.get("friction_force"))
    m.close()
    return np.max(np.abs(friction)) / scale


def error_rows(model, pressure, lengths, reference, configurations):
    """(knob, value, largest deviation from the reference force relative to its largest value)."""
    ref = forces(model, pressure, lengths, **reference)
    scale = np.max(np.abs(ref))
    rows = [(knob, value, np.max(np.abs(forces(model, pressure, lengths, **params) - ref)) / scale)
            for knob, value, params in configurations]
    return rows, scale


def mckibben_rows():
    lengths = 0.10325 * np.linspace(0.75, 0.93, SCENARIO_POINTS)
    progress("McKibbenMuscle: reference, exact wall with 64 nodes")
    a = {"preset": 1}
    configurations = [("bladder_model", "none", {**a, "bladder_model": 0}),
                      ("bladder_model", "thin", {**a, "bladder_model": 1})]
    configurations += [("bladder_layers", str(n), {**a, "bladder_model": 2, "bladder_layers": n})
                       for n in (1, 2, 4, 8, 16, 32, 64)]
    configurations += [("bladder_exact", str(n), {**a, "bladder_model": 3, "bladder_layers": n})
                       for n in (2, 4, 8, 16)]
    configurations += [("bladder_model", "dissertation's thin", {**a, "bladder_model": 4}),
                       ("bladder_model", "dissertation's 16 layers", {**a, "bladder_model": 5, "bladder_layers": 16})]
    rows, scale = error_rows("McKibbenMuscle", 6.9e5, lengths, {**a, "bladder_model": 3, "bladder_layers": 64},
                             configurations)
    rows.append(("friction", "on (thin)",
                 friction_effect("McKibbenMuscle", 6.9e5, lengths, scale, preset=1, bladder_model=1)))
    MCKIBBEN_ERRORS.extend(rows)
    return "McKibbenMuscle", "muscle A, 690 kPa, 0.75-0.93 of its length; reference: exact wall, 64 nodes (exact to rounding)", rows


def knitted_rows():
    if not (FMU_DIR / "KnittedMuscle.fmu").exists():
        return None
    lengths = 0.514 * np.linspace(0.40, 0.95, SCENARIO_POINTS)
    progress("KnittedMuscle: reference, non-cylindrical with 98 segments (the most it accepts)")
    configurations = [("shape_model", "ideal", {"shape_model": 0}), ("shape_model", "tubular", {"shape_model": 1})]
    configurations += [("shape_segments", str(n), {"shape_model": 2, "shape_segments": n})
                       for n in (12, 24, 49)]
    rows, scale = error_rows("KnittedMuscle", 1.4e4, lengths, {"shape_model": 2, "shape_segments": 98},
                             configurations)
    rows.append(("friction", "on (ideal)", friction_effect("KnittedMuscle", 1.4e4, lengths, scale, shape_model=0)))
    return "KnittedMuscle", "section 1.4 prototype, 14 kPa, 40-95% of 514 mm; reference: non-cylindrical, 98 segments", rows


def motor_angles(parameters, steps=3 if SMOKE else 1200):
    m = Slave("MultiferroicMotor", schedule=1, **parameters)
    angles = []
    for _ in range(steps):
        m.step(h=1e-6)
        angles.append(m.get("rotor_angle"))
    m.close()
    return np.array(angles)


def motor_rows():
    progress("MultiferroicMotor: reference, tolerance 1e-10")
    ref = motor_angles({"tolerance": 1e-10})
    rows = []
    for tol in ("1e-3", "1e-4", "1e-5", "1e-6", "1e-7", "1e-8"):
        rows.append(("tolerance", tol, np.max(np.abs(motor_angles({"tolerance": float(tol)}) - ref))))
    # The Gilbert relaxation is the higher-fidelity model: quasi-static's error is the difference.
    rows.append(("onion_model", "gilbert", np.max(np.abs(motor_angles({"onion_model": 1, "tolerance": 1e-6}) - ref))))
    return "MultiferroicMotor", "stepping schedule, 12 steps of 60 degrees in 1.2 ms at 1 us communication steps; error in rotor angle (rad); reference: tolerance 1e-10", rows


# ---- cost under FMPy ----

FMPY_SCENARIOS = {
    "PassThrough": ({}, ["u"], lambda k: [k * 1e-3]),
    "McKibbenMuscle": ({}, ["pressure", "length"], lambda k: [4e5, 0.08 + 1e-5 * (k % 1000)]),
    "MultiferroicMotor": ({"schedule": 1}, ["load_torque"], lambda k: [0.0]),
    "KnittedMuscle": ({}, ["pressure", "length"], lambda k: [1.4e4, 0.3 + 1e-5 * (k % 1000)]),
}


class FmpyRun:
    """One instance under FMPy's FMU2Slave, stepped in batches: one setReal (all inputs), doStep,
    one getReal per step; its time goes on from batch to batch."""

    def __init__(self, model):
        parameters, names, self.inputs = FMPY_SCENARIOS[model]
        self.h = 1e-6 if model == "MultiferroicMotor" else 1e-3
        self.slave = Slave(model, **parameters)
        self.vrs = [self.slave.vars[n].valueReference for n in names]
        self.out = [next(v.valueReference for v in self.slave.md.modelVariables if v.causality == "output")]
        self.t, self.k = 0.0, 0

    def batch(self, steps):
        """Seconds per step over `steps` steps."""
        fmu, vrs, out, inputs, h = self.slave.fmu, self.vrs, self.out, self.inputs, self.h
        t, k = self.t, self.k
        start = time.thread_time()
        for k in range(k, k + steps):
            fmu.setReal(vrs, inputs(k))
            fmu.doStep(t, h)
            t += h
            fmu.getReal(out)
        elapsed = (time.thread_time() - start) / steps
        self.t, self.k = t, k + 1
        return elapsed


FMPY_ROUNDS, FMPY_BATCH = (1, 3) if SMOKE else (61, 500)


def fmpy_costs(models):
    """The minimum over FMPY_ROUNDS interleaved batches of FMPY_BATCH steps (each round runs every
    model once, in a rotating order), in the thread's CPU time: the machine's load then changes
    little, and the interleaving makes the ratios to PassThrough hold."""
    runs = {m: FmpyRun(m) for m in models}
    for run in runs.values():
        run.batch(FMPY_BATCH)  # warm-up
    best = {m: math.inf for m in models}
    for r in range(FMPY_ROUNDS):
        for i in range(len(models)):
            model = models[(i + r) % len(models)]
            best[model] = min(best[model], runs[model].batch(FMPY_BATCH))
    for run in runs.values():
        run.slave.close()
    return best


# ---- per-step targets ----

NATIVE_TARGETS = [
    ("McKibbenMuscle/bladder_model/none", 50e-9, "ideal McKibben"),
    ("McKibbenMuscle/bladder_model/thin", 300e-9, "thin wall"),
    ("McKibbenMuscle/bladder_layers/16", 2e-6, "thick wall, 16 layers"),
    ("KnittedMuscle/shape_segments/49", 300e-9, "knitted non-cylindrical (tabulated)"),
    ("MultiferroicMotor/tolerance/1e-6", 2e-6, "motor, per 1 us communication step, criterion median"),
]

# The native configuration each FMU runs in its FMPy measurement.
NATIVE_DEFAULT = {
    "McKibbenMuscle": "McKibbenMuscle/bladder_model/none",
    "MultiferroicMotor": "MultiferroicMotor/tolerance/1e-6",
    "KnittedMuscle": "KnittedMuscle/shape_model/ideal",
}

# The interleaved case of benches/parity.rs that stands for each FMU's default configuration.
PARITY_CASE = {
    "PassThrough": "PassThrough",
    "McKibbenMuscle": "McKibbenMuscle, ideal",
    "MultiferroicMotor": "MultiferroicMotor, 1 us step",
}

# Why a target is missed, where it is (measured causes, kept beside the numbers they explain).
EXPLANATIONS = {
    "McKibbenMuscle/bladder_model/none": "the FMI calls themselves cost about as much: behind the same calls the PassThrough FMU's step is as slow (`make bench`, group 'same FMI calls'), and eq. 2.3 adds about 1 ns",
    "McKibbenMuscle/bladder_model/thin": "the thin wall's Mooney-Rivlin stresses, the contact switch and the analytic stiffness: about 4 divisions and 2 square roots more than eq. 2.3, plus the free-bladder root below the threshold",
    "MultiferroicMotor/tolerance/1e-6": "every communication step takes at least one error-controlled substep (about two at 1 us steps: the exprb32 pair, one right-hand side and two onion settles each); a looser tolerance or longer communication steps cost less per simulated second: settled periods are advanced at once",
}


def motor_fmpy_why(parity):
    """Why the motor's FMPy ratio is what it is: its own step, warm and with cold caches."""
    base = FMPY_TIMES.get("PassThrough")
    if CPU is not None and base and MOTOR_STEPPING in CPU["by_case"]:
        own = CPU["by_case"][MOTOR_STEPPING]["cpu_s"]
        return (f"the motor's own step costs {fmt_time(own)} of CPU time natively (`Motor::step`, benches/cpu_time.rs) "
                f"against FMPy's {fmt_time(base)} per step, which predicts {1 + own / base:.2f}x warm; under FMPy the "
                f"step also finds its code and data out of the caches. The goal needs the whole added cost within "
                f"{fmt_time(0.2 * base)}")
    if not parity or not base:
        return "its own step adds to FMPy's per-step cost"
    warm = parity["by_case"].get("MultiferroicMotor, 1 us step", {}).get("median_s")
    cold = parity["cold_by_case"].get("MultiferroicMotor, 1 us step")
    cold_pt = parity["cold_by_case"].get("PassThrough", 0.0)
    if not (warm and cold):
        return "its own step adds to FMPy's per-step cost"
    return (f"the motor's own step: {fmt_time(warm)} natively in a tight loop ({fmt_time(cold)} with the caches "
            f"evicted before each step), against FMPy's {fmt_time(base)} per step; that predicts "
            f"{1 + warm / base:.2f}x-{1 + (cold - cold_pt) / base:.2f}x. The goal needs a native step of at most "
            f"{fmt_time(0.2 * base)} (0.2 of FMPy's own cost)")


KNOB_LABELS = {
    "bladder_model": "bladder_model (0 none, 1 thin wall, 4 and 5 the dissertation's)",
    "bladder_layers": "bladder_model 2: layered wall (value = layers)",
    "bladder_exact": "bladder_model 3: exact wall (value = nodes)",
    "shape_model": "shape_model (cylindrical)",
    "shape_segments": "shape_model 2: non-cylindrical (value = segments)",
    "tolerance": "tolerance (value, rad)",
    "onion_model": "onion_model 1: Gilbert onion (tolerance 1e-6 rad)",
    "friction": "friction on: size of the effect, not an error",
}


def is_number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


def _place_labels(ax, labelled):
    """Writes each (x, y, text) beside its point where it overlaps no label and no point already
    there, trying offsets ever farther out; a label set off from its point gets a thin leader."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    points = [ax.transData.transform((x, y)) for x, y, _ in labelled]
    taken = []
    rings = [(6, 4), (6, -12), (-8, 8), (-8, -14)]
    candidates = [(dx * k, dy * k) for k in (1, 2, 3, 4) for dx, dy in rings]
    for (x, y, text), own in zip(labelled, points):
        for dx, dy in candidates:
            ha = "left" if dx > 0 else "right"
            note = ax.annotate(text, (x, y), fontsize=7, xytext=(dx, dy), textcoords="offset points", ha=ha,
                               arrowprops=dict(arrowstyle="-", lw=0.4, color="0.4") if abs(dy) > 12 else None)
            box = note.get_window_extent(renderer).expanded(1.05, 1.1)
            near = box.padded(7)  # keeps a label off other markers, so that it names its own
            axes = ax.get_window_extent(renderer)
            inside = axes.contains(box.x0, box.y0) and axes.contains(box.x1, box.y1)
            clear = inside and not any(box.overlaps(t) for t in taken) and not any(
                near.contains(*p) for p in points if p is not own)
            if clear or (dx, dy) == candidates[-1]:
                taken.append(box)
                break
            note.remove()


def plot_work_precision(fmu, scenario, points, rows, times):
    """Log-log error against native time, one labelled series per knob, values beside points."""
    import textwrap

    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    fig, ax = plt.subplots(figsize=(8.0, 5.8))
    markers = iter("osD^v<>ph*")
    knobs = []
    for _, _, knob, _ in points:
        if knob not in knobs:
            knobs.append(knob)
    labelled = []
    for knob in knobs:
        series = [(t, e, v) for t, e, k, v in points if k == knob]
        numeric = all(is_number(v) for _, _, v in series)
        if numeric:
            series.sort(key=lambda p: float(p[2]))
        ts = [t * 1e9 for t, _, _ in series]
        es = [e for _, e, _ in series]
        # A line joins the values of one numeric knob; categorical ones are points alone.
        ax.loglog(ts, es, linestyle="-" if numeric and len(series) > 1 else "none",
                  marker=next(markers), label=KNOB_LABELS.get(knob, knob))
        labelled += [(t * 1e9, e, str(v)) for t, e, v in series]
    # Plain numbers at 1-2-5 steps: no minor-tick labels to collide on a short decade range.
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    unit = "rad" if fmu == "MultiferroicMotor" else "share of peak force, 1"
    ax.set_xlabel("native time per step (ns)")
    ax.set_ylabel(f"largest error against the reference ({unit})")
    title = f"{fmu}: error against native cost per step. Scenario: {scenario}."
    ax.set_title("\n".join(textwrap.wrap(title, 95)), fontsize=8)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    _place_labels(ax, labelled)
    fig.savefig(PLOTS / f"{fmu}.png", dpi=110)
    plt.close(fig)


FMPY_RATIOS = {}
FMPY_TIMES = {}
MCKIBBEN_ERRORS = []


def fmt_time(s):
    return f"{s * 1e9:.0f} ns" if s < 1e-6 else (f"{s * 1e6:.2f} us" if s < 1e-3 else f"{s * 1e3:.2f} ms")


def replot_from_page():
    """docs/accuracy/<FMU>.png again from the tables of docs/accuracy-cost.md (error, 1 or rad;
    native time per step, ns, us or ms)."""
    import re

    text = (DOCS / "accuracy-cost.md").read_text()
    per_second = {"ns": 1e-9, "us": 1e-6, "µs": 1e-6, "ms": 1e-3, "s": 1.0}
    for fmu in ("McKibbenMuscle", "KnittedMuscle", "MultiferroicMotor"):
        if f"## {fmu}\n" not in text:
            continue
        section = text.split(f"## {fmu}\n", 1)[1].split("\n## ", 1)[0]
        scenario = re.search(r"Scenario: (.*)\.\n", section).group(1)
        points = []
        for knob, value, err, t in re.findall(r"\| `(\w+)` \| ([^|]+) \| ([^|]+) \| ([^|]+) \|", section):
            number, unit = t.split()
            if unit in per_second and float(err) > 0:
                points.append((float(number) * per_second[unit], float(err), knob, value.strip()))
        plot_work_precision(fmu, scenario, points, None, None)
        print(f"wrote {PLOTS / fmu}.png")


def main():
    global CPU
    parity = parity_figures()
    if "--parity" in sys.argv:
        # `make parity`: only the FMI-layer table of docs/accuracy-cost.md, from benches/parity.rs's last run.
        if parity is None:
            sys.exit("no target/parity/parity.json: run `cargo bench --bench parity` first")
        write_docs_block("fmi-parity", parity_table(parity))
        rewrite_fmi_layer_goal_rows(parity)
        return
    if "--replot" in sys.argv:
        # Only the work-precision plots, from the numbers docs/accuracy-cost.md holds (its last
        # `make report`): a change to the plots needs no benchmark run.
        replot_from_page()
        return
    times = criterion_times()
    CPU = cpu_figures()
    if not times and not SMOKE:
        sys.exit("no criterion results: run `cargo bench --bench accuracy_cost` first (make report does)")
    if not SMOKE:
        PLOTS.mkdir(parents=True, exist_ok=True)
    shape_init()
    lines = ["# What accuracy costs in time", "",
             "Generated by `make report` (benches/accuracy_cost.rs, benches/cpu_time.rs, benches/report.py) on",
             "a 2-core machine. Native times are criterion medians, in the benchmark thread's CPU",
             "time (so that they reproduce on a loaded machine), of one set-inputs + `fmi2DoStep` + get-output",
             "through the packaged FMU's C ABI; errors are the largest deviation from a converged",
             "reference over the scenario, relative to the reference's largest force (muscles) or in rad (motor).",
             "The McKibben scenario keeps the layered and exact walls on the sleeve; the thin wall's threshold",
             "pressure for muscle A is 0.93 MPa, so below it that wall's bladder is free and each step solves",
             "its free bladder's root, which costs more (`make bench` measures muscle A at 400 kPa, mostly free).",
             ""]
    for family in (mckibben_rows(), knitted_rows(), motor_rows()):
        if family is None:
            continue
        fmu, scenario, rows = family
        lines += [f"## {fmu}", "", f"Scenario: {scenario}.", "",
                  "| knob | value | error | native time per step |", "|---|---|---|---|"]
        points = []
        for knob, value, err in rows:
            t = times.get(f"{fmu}/{knob}/{value}")
            lines.append(f"| `{knob}` | {value} | {err:.2e} | {fmt_time(t) if t else 'not measured'} |")
            if t and err > 0:
                points.append((t, err, knob, value))
        lines.append("")
        if points and not SMOKE:
            plot_work_precision(fmu, scenario, points, rows, times)
            lines += [f"![{fmu} work-precision](accuracy/{fmu}.png)", ""]

    shape = shape_table_times()
    if shape:
        lines += ["## Knitted shape table: ours against the dissertation's algorithm", "",
                  "Building the non-cylindrical volume-length table of the section 1.4 prototype (49 rows) once, at",
                  "initialization (`make bench`, benches/knitted_shape.rs):", "",
                  "| method | time to build |", "|---|---|"]
        lines += [f"| {name} | {fmt_time(t)} |" for name, t in sorted(shape.items())]
        if len(shape) == 2:
            ours = next(t for n, t in shape.items() if n.startswith("ours"))
            seed = next(t for n, t in shape.items() if n.startswith("seed"))
            lines += ["", f"Ours is {seed / ours:.0f} times faster. The two agree to 7 digits in volume from the",
                      "free contraction up to 0.356 m; nearer full extension the dissertation's exchange stalls on the",
                      "unstable uniform bulge (its stopping rule is met there) and its volume falls up to 27% short.",
                      "So it is not the same accuracy at lower cost: it is lower accuracy at far higher cost.", ""]
    progress("cost under FMPy")
    lines += ["## Cost under FMPy", "",
              f"One `setReal` + `doStep` + `getReal` through FMPy's `FMU2Slave`, in the Python thread's CPU time: the minimum",
              f"over {FMPY_ROUNDS} batches of {FMPY_BATCH} steps, interleaved (each round steps every FMU's one instance once, its time going on)",
              "beside the PassThrough FMU (y = u): the ratio is what the model adds to FMPy's own cost.", "",
              "| FMU | time per step | ratio to PassThrough | target (1.2x) |", "|---|---|---|---|"]
    models = [m for m in ("PassThrough", "McKibbenMuscle", "KnittedMuscle", "MultiferroicMotor")
              if (FMU_DIR / f"{m}.fmu").exists()]
    costs = fmpy_costs(models)
    base = costs["PassThrough"]
    for model in models:
        t = costs[model]
        ratio = t / base
        FMPY_RATIOS[model] = ratio
        FMPY_TIMES[model] = t
        native = times.get(NATIVE_DEFAULT.get(model, ""), 0.0)
        if parity and PARITY_CASE.get(model) in parity["by_case"]:
            native = parity["by_case"][PARITY_CASE[model]]["median_s"]
        why = f": its own step costs {fmt_time(native)} natively" if native else ""
        verdict = "met" if ratio <= 1.2 else f"missed by {ratio / 1.2:.2f}x{why}"
        lines.append(f"| {model} | {fmt_time(t)} | {ratio:.2f} | {verdict} |")
    lines += ["", "## Goals beside the measured figures", "",
              "| goal | measured | verdict |", "|---|---|---|"]
    # The exact wall within 1e-9 with 16 nodes.
    mck = dict(((k, v), e) for k, v, e in MCKIBBEN_ERRORS)
    if ("bladder_exact", "16") in mck:
        err = mck[("bladder_exact", "16")]
        lines.append(f"| exact wall, 16 nodes: error <= 1e-9 of peak force | {err:.1e} "
                     f"(reference: 64 nodes) | {'met' if err <= 1e-9 else 'missed'} |")
    if FMPY_RATIOS.get("MultiferroicMotor"):
        r = FMPY_RATIOS["MultiferroicMotor"]
        lines.append(f"| motor under FMPy <= 1.2x PassThrough, interleaved minima | {r:.2f}x | "
                     f"{goal_verdict(r, 1.2, motor_fmpy_why(parity))} |")
    lines += cpu_goal_rows()
    lines += parity_goal_rows(parity)
    # Goal: the shape table's build in fmi2ExitInitializationMode (benches/knitted_shape_init.py).
    if SHAPE_INIT:
        for segments, goal in GOALS.items():
            t = SHAPE_INIT[segments]
            lines.append(f"| knitted shape table: `fmi2ExitInitializationMode` at {segments:,} segments <= "
                         f"{fmt_time(goal)}, CPU time through FMPy | {fmt_time(t)} | {'met' if t <= goal else 'missed'} |")
    for key, target, label in NATIVE_TARGETS:
        t = times.get(key)
        if key == "McKibbenMuscle/bladder_model/none" and parity and "McKibbenMuscle, ideal" in parity["by_case"]:
            t = parity["by_case"]["McKibbenMuscle, ideal"]["median_s"]
            label = "ideal McKibben, interleaved median"
        if t is None:
            lines.append(f"| {label} <= {fmt_time(target)} | not measured | FMU not built |")
            continue
        verdict = "met" if t <= target else f"missed by {t / target:.1f}x: {EXPLANATIONS.get(key, 'see above')}"
        lines.append(f"| {label} <= {fmt_time(target)} | {fmt_time(t)} | {verdict} |")
    lines.append("")
    if parity:
        lines += ["## The FMI layer against C", ""] + FMI_LAYER_TEXT.format(rounds=parity["rounds"]).split("\n") + [""]
        # `make parity` rewrites this block alone.
        lines += ["<!-- report:fmi-parity -->", *parity_table(parity), "<!-- /report -->"]
        lines.append("")
    if SMOKE:
        continuum_wall_table()
        print("every configuration of make report ran (--smoke: nothing written)")
        return
    (DOCS / "accuracy-cost.md").write_text("\n".join(lines))
    print("wrote docs/accuracy-cost.md")
    write_docs_block("cost-per-step", cost_per_step_table(times))
    write_docs_block("continuum-wall", continuum_wall_table())
    if SHAPE_INIT_ROWS:
        write_docs_block("knitted-shape-init", SHAPE_INIT_ROWS)


COST_ROWS = [
    ("PassThrough/baseline/y = u", "PassThrough (y = u): the FMI layer alone"),
    ("McKibbenMuscle/bladder_model/none", "McKibbenMuscle, ideal sleeve (eq. 2.3)"),
    ("McKibbenMuscle/bladder_model/thin", "McKibbenMuscle, thin-walled bladder (muscle A, 690 kPa, below its 0.93 MPa threshold: free)"),
    ("McKibbenMuscle/bladder_layers/16", "McKibbenMuscle, layered wall, 16 layers"),
    ("McKibbenMuscle/bladder_exact/16", "McKibbenMuscle, exact wall, 16 nodes"),
    ("McKibbenMuscle/friction/on (thin)", "McKibbenMuscle, thin wall + friction"),
    ("KnittedMuscle/shape_model/ideal", "KnittedMuscle, ideal cylinder"),
    ("KnittedMuscle/shape_segments/49", "KnittedMuscle, non-cylindrical, 49 segments (tabulated)"),
    ("MultiferroicMotor/tolerance/1e-6", "MultiferroicMotor, stepping schedule, per 1 us communication step"),
]


def continuum_wall_table():
    """Muscle C at 450 kPa across its whole stroke: the continuum and layered walls against the
    layered wall's limit, extrapolated from 256-2048 layers. The FMU accepts at most 64 layers,
    so tools/src/bin/wall_limit.rs runs on the physics directly."""
    progress("continuum wall against the extrapolated layered limit")
    out = subprocess.run(["cargo", "run", "--release", "-q", "-p", "actuator-fmus-tools", "--bin", "wall_limit"],
                         cwd=ROOT, check=True, capture_output=True, text=True).stdout
    return out.strip().splitlines()


def cost_per_step_table(times):
    base = times.get("PassThrough/baseline/y = u")
    rows = ["| FMU and effects | time per step | against PassThrough in the same run |", "|---|---|---|"]
    rows += [f"| {label} | {fmt_time(times[key])} | {times[key] / base:.2f}x |" if base else
             f"| {label} | {fmt_time(times[key])} | |" for key, label in COST_ROWS if key in times]
    return rows


def shape_init():
    """fmi2ExitInitializationMode of the knitted shape table through FMPy."""
    global SHAPE_INIT_ROWS
    if (FMU_DIR / "KnittedMuscle.fmu").exists():
        progress("KnittedMuscle: shape table initialization")
        SHAPE_INIT_ROWS, times = knitted_shape_init.rows([FMU_DIR / "KnittedMuscle.fmu"],
                                                               repeats=1 if SMOKE else None)
        SHAPE_INIT.update(times)


SHAPE_INIT, SHAPE_INIT_ROWS = {}, []


def write_docs_block(name, rows):
    """Rewrites the documentation page (docs/**/*.md) that holds `<!-- report:NAME -->`, between
    that marker and `<!-- /report -->`. The README is never rewritten."""
    start, end = f"<!-- report:{name} -->", "<!-- /report -->"
    for page in sorted((ROOT / "docs").rglob("*.md")):
        text = page.read_text()
        i = text.find(start)
        j = text.find(end, i)
        if i < 0 or j < 0:
            continue
        page.write_text(text[:i + len(start)] + "\n" + "\n".join(rows) + "\n" + text[j:])
        print(f"rewrote {page.relative_to(ROOT)} block {name}")


if __name__ == "__main__":
    main()
