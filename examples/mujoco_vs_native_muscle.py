"""The McKibbenMuscle FMU in MuJoCo (actuator_fmus.fmu plugin) against MuJoCo's own <muscle>
fitted to the FMU's force-length curve at one pressure, on the arm of examples/mujoco/arm.xml:
static curves over pressure, the same arm task, a slow pressure cycle, and the cost per step.

    .venv/bin/python examples/mujoco_vs_native_muscle.py --out docs/img \
        --report docs/mujoco-comparison.md                                   (make mujoco-docs)

The <muscle> gets activation = pressure / 600 kPa (its activation is capped at 1), no passive force
to speak of (fpmax = 1e-9, as MuJoCo wants it positive: a McKibben muscle's cable goes slack
instead) and MuJoCo's default force-velocity curve. Its force-length curve (range, force, lmin;
lmax fixed) is fitted by least squares to the FMU's tension at 600 kPa over the arm's stroke."""

import argparse
import pathlib
import re
import time

import numpy as np

import mujoco_arm as arm  # noqa: E402  (beside this script: Python finds it there)

P_FIT = 600e3  # Pa: the pressure the <muscle> is fitted at (activation 1)
LMAX = 1.6  # the <muscle>'s lmax, fixed: the stroke lies on the ascending limb
# m, the flexor's lengths over elbow angles -0.6 .. 0.6 rad (the tasks stay inside)
STROKE = (arm.HANG - arm.PULLEY_RADIUS * 0.6, arm.HANG + arm.PULLEY_RADIUS * 0.6)


def tendon(length):
    """Tendon length (what a native actuator sees) of a muscle length."""
    return length - arm.LENGTH_OFFSET


def fmu_tension(lengths, pressure):
    """The FMU's force (friction off) through the plugin in MuJoCo, as a cable transmits it."""
    import mujoco

    model = arm.arm_model()
    data = mujoco.MjData(model)
    out = []
    for length in lengths:
        data.qpos[0] = (arm.HANG - length) / arm.PULLEY_RADIUS  # the flexor at this length
        data.ctrl[:] = (pressure, 0.0)
        mujoco.mj_forward(model, data)
        out.append(-data.actuator_force[0])
    return np.array(out)


def fit_native():
    """(prm, lengthrange, rms N): the <muscle> parameters fitted at P_FIT."""
    import mujoco
    from scipy.optimize import least_squares

    lengths = np.linspace(*STROKE, 49)
    target = fmu_tension(lengths, P_FIT)
    lengthrange = np.array([tendon(STROKE[0]), tendon(STROKE[1])])

    def model(x):
        r0, r1, force, lmin = x
        prm = np.array([r0, r1, force, 1.0, lmin, LMAX, 1.5, 0.0, 1.2])
        return np.array([-mujoco.mju_muscleGain(tendon(L), 0.0, lengthrange, 0.0, prm)
                         for L in lengths]), prm

    fit = least_squares(lambda x: model(x)[0] - target, x0=[0.6, 1.0, target.max(), 0.4],
                        bounds=([0.3, 0.7, 1.0, 0.1], [1.0, 1.5, 1e5, 0.95]))
    predicted, prm = model(fit.x)
    rms = float(np.sqrt(np.mean((predicted - target) ** 2)))
    return prm, lengthrange, rms


def native_xml(prm, lengthrange, timeconst=0.005):
    """arm.xml with the two plugin actuators replaced by fitted <muscle> actuators."""
    xml = arm.ARM_XML.read_text()
    for name in ("flexor", "extensor"):
        block = re.search(rf'<plugin name="{name}".*?</plugin>', xml, re.S).group(0)
        muscle = (f'<muscle name="{name}" tendon="{name}" ctrlrange="0 1" '
                  f'lengthrange="{lengthrange[0]:.17g} {lengthrange[1]:.17g}" '
                  f'range="{prm[0]:.17g} {prm[1]:.17g}" force="{prm[2]:.17g}" lmin="{prm[4]:.17g}" '
                  f'lmax="{prm[5]:.17g}" vmax="{prm[6]:.17g}" fpmax="1e-9" fvmax="{prm[8]:.17g}" '
                  f'timeconst="{timeconst} {timeconst}"/>')
        xml = xml.replace(block, muscle)
    return re.sub(r"<extension>.*?</extension>", "", xml, flags=re.S)


def linear_xml(pressures):
    """arm.xml with each muscle replaced by MuJoCo's cheapest actuator, a spring linearized about
    the plugin's equilibrium at `pressures` (force and `stiffness` of the FMU there): the same
    motion at MuJoCo's own cost."""
    import mujoco

    model = arm.arm_model()
    data = mujoco.MjData(model)
    data.ctrl[:] = pressures
    for _ in range(3000):
        mujoco.mj_step(model, data)
    from actuator_fmus import Slave

    fmu = Slave("McKibbenMuscle", preset=5, nominal_length=0.25)
    xml = arm.ARM_XML.read_text()
    for i, name in enumerate(("flexor", "extensor")):
        tendon_length = data.actuator_length[i]
        k = fmu.at("stiffness", length=tendon_length + arm.LENGTH_OFFSET, pressure=pressures[i])
        force = -data.actuator_force[i]  # tension
        bias = f"{-force + k * tendon_length:.17g} {-k:.17g} 0"
        block = re.search(rf'<plugin name="{name}".*?</plugin>', xml, re.S).group(0)
        xml = xml.replace(block, f'<general name="{name}" tendon="{name}" gainprm="0" '
                                 f'biastype="affine" biasprm="{bias}"/>')
    return re.sub(r"<extension>.*?</extension>", "", xml, flags=re.S)


def native_tension(model, lengths, activation):
    import mujoco

    data = mujoco.MjData(model)
    out = []
    for length in lengths:
        data.qpos[0] = (arm.HANG - length) / arm.PULLEY_RADIUS
        data.act[:] = (activation, 0.0)
        mujoco.mj_forward(model, data)
        out.append(-data.actuator_force[0])
    return np.array(out)


def run_task(model, native, duration=6.5):
    """The arm task of examples/mujoco_arm.py; `native`: controls are pressure / P_FIT."""
    import mujoco

    data = mujoco.MjData(model)
    controller = arm.Controller()
    rows = []
    for k in range(int(round(duration / model.opt.timestep))):
        q_ref, (pf, pe), torque = controller(data.time, data.qpos[0], data.qvel[0],
                                             model.opt.timestep)
        data.ctrl[:] = (pf / P_FIT, pe / P_FIT) if native else (pf, pe)
        data.qfrc_applied[0] = torque
        mujoco.mj_step(model, data)
        if k % 10 == 0:
            rows.append((data.time, data.qpos[0], q_ref, pf, pe, -data.actuator_force[0],
                         -data.actuator_force[1]))
    return np.array(rows)


def pressure_cycle(model, native, seconds=32.0, settle=2.0):
    """Flexor 250 -> 500 -> 250 kPa, extensor 350 kPa, after `settle` s at the start:
    (p_flexor, q) every 10 steps."""
    import mujoco

    data = mujoco.MjData(model)
    data.ctrl[:] = (2.5e5 / P_FIT, 3.5e5 / P_FIT) if native else (2.5e5, 3.5e5)
    for _ in range(int(settle / model.opt.timestep)):
        mujoco.mj_step(model, data)
    steps = int(seconds / model.opt.timestep)
    rows = []
    for k in range(steps):
        s = k / steps
        pf = 2.5e5 + 2.5e5 * (1 - abs(2 * s - 1))
        data.ctrl[:] = (pf / P_FIT, 3.5e5 / P_FIT) if native else (pf, 3.5e5)
        mujoco.mj_step(model, data)
        if k % 10 == 0:
            rows.append((pf, data.qpos[0]))
    return np.array(rows)


def steps_per_second(model, scale, nstep=5000, repeats=9):
    """mj_step rate over `nstep` steps in C (mujoco.rollout, one thread), best of `repeats`:
    5 s from q = 0 with the pressures swinging in antiphase, 350 +- 100 kPa at 1 Hz (controls
    times `scale`: 1 for pressures in Pa, 1 / P_FIT for the <muscle>), so that the muscles'
    inputs change every step."""
    import mujoco
    from mujoco import rollout

    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty((1, mujoco.mj_stateSize(model, spec)))
    mujoco.mj_getState(model, data, state[0], spec)
    t = np.arange(nstep) * model.opt.timestep
    swing = 1e5 * np.sin(2 * np.pi * t)
    control = (scale * np.stack([3.5e5 + swing, 3.5e5 - swing], axis=1))[None]
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        rollout.rollout(model, data, state, control)
        best = min(best, time.perf_counter() - start)
    return nstep / best


def main():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import mujoco

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="out/mujoco")
    parser.add_argument("--report", default="out/mujoco/comparison.md")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = pathlib.Path(args.report)
    report.parent.mkdir(parents=True, exist_ok=True)
    image_path = lambda name: out / f"mujoco_{name}.png"  # noqa: E731

    print("fitting <muscle> to the FMU at 600 kPa ...")
    prm, lengthrange, fit_rms = fit_native()
    native = mujoco.MjModel.from_xml_string(native_xml(prm, lengthrange))
    plugin = arm.arm_model()
    plugin_friction = arm.arm_model(arm.DMSP10 + " friction=true")

    # 1. Static force-length curves and isometric force over pressure.
    lengths = np.linspace(*STROKE, 61)
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.8))
    errors = {}
    for pressure, colour in zip((150e3, 300e3, 450e3, 600e3), ("C0", "C1", "C2", "C3")):
        f_fmu = fmu_tension(lengths, pressure)
        f_nat = native_tension(native, lengths, pressure / P_FIT)
        errors[pressure] = (np.sqrt(np.mean((f_nat - f_fmu) ** 2)), np.abs(f_fmu).max())
        ax[0].plot(lengths * 1e3, f_fmu, "-", color=colour,
                   label=f"FMU, {pressure / 1e3:.0f} kPa (N)")
        ax[0].plot(lengths * 1e3, f_nat, "--", color=colour,
                   label=f"<muscle>, activation {pressure / P_FIT:.2f} (N)")
    ax[0].set_xlabel("muscle length (mm)")
    ax[0].set_ylabel("cable tension (N)")
    ax[0].set_title("Force-length: <muscle> fitted at 600 kPa")
    ax[0].legend(fontsize=7)
    pressures = np.linspace(0, 600e3, 121)
    thresholds = {}
    for length, colour in zip((0.225, arm.HANG, 0.25), ("C4", "C5", "C6")):
        f_fmu = [fmu_tension([length], p)[0] for p in pressures]
        f_nat = [native_tension(native, [length], p / P_FIT)[0] for p in pressures]
        contraction = 1 - length / arm.NOMINAL_LENGTH
        pulling = [p for p, f in zip(pressures, f_fmu) if f > 0]
        thresholds[contraction] = pulling[0] if pulling else np.nan
        ax[1].plot(pressures / 1e3, f_fmu, "-", color=colour,
                   label=f"FMU, {contraction:.0%} contraction (N)")
        ax[1].plot(pressures / 1e3, f_nat, "--", color=colour,
                   label=f"<muscle>, {contraction:.0%} contraction (N)")
    ax[1].set_xlabel("gauge pressure (kPa)")
    ax[1].set_ylabel("cable tension (N)")
    ax[1].set_title("Isometric tension over pressure")
    ax[1].legend(fontsize=7)
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("McKibbenMuscle FMU (Festo DMSP-10) against MuJoCo's <muscle>, static")
    fig.tight_layout()
    fig.savefig(image_path("static"), dpi=110)
    plt.close(fig)

    # 2. The same arm task.
    print("running the arm task with both ...")
    task_fmu = run_task(plugin, native=False)
    task_nat = run_task(native, native=True)
    fig, ax = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    ax[0].plot(task_fmu[:, 0], task_fmu[:, 2], "k--", label="reference (rad)")
    ax[0].plot(task_fmu[:, 0], task_fmu[:, 1], label="FMU muscles (rad)")
    ax[0].plot(task_nat[:, 0], task_nat[:, 1], label="<muscle> (rad)")
    ax[0].set_ylabel("elbow angle (rad)")
    ax[1].plot(task_fmu[:, 0], task_fmu[:, 3] / 1e3, "C0-", label="FMU: flexor pressure (kPa)")
    ax[1].plot(task_fmu[:, 0], task_fmu[:, 4] / 1e3, "C0:", label="FMU: extensor pressure (kPa)")
    ax[1].plot(task_nat[:, 0], task_nat[:, 3] / 1e3, "C1-", label="<muscle>: flexor (kPa)")
    ax[1].plot(task_nat[:, 0], task_nat[:, 4] / 1e3, "C1:", label="<muscle>: extensor (kPa)")
    ax[1].set_ylabel("commanded pressure (kPa)")
    ax[1].set_xlabel("time (s)")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle("The same task and controller: move to 0.3 rad, 0.3 N m pulses,\n"
                 "co-contraction 250 -> 450 kPa")
    fig.tight_layout()
    fig.savefig(image_path("task"), dpi=110)
    plt.close(fig)

    def pulse_deflection(task):
        t, q = task[:, 0], task[:, 1]
        return [q[(t > a - 0.1) & (t < a)].mean() - q[(t > b - 0.1) & (t < b)].mean()
                for a, b in arm.PULSES]

    # 3. Slow pressure cycle.
    print("slow pressure cycles ...")
    cycles = {"FMU, friction on": pressure_cycle(plugin_friction, False),
              "FMU, friction off": pressure_cycle(plugin, False),
              "<muscle>": pressure_cycle(native, True)}
    fig, ax = plt.subplots(figsize=(7, 5))
    for label, rows in cycles.items():
        ax.plot(rows[:, 0] / 1e3, rows[:, 1], label=f"{label} (rad)")
    ax.set_xlabel("flexor pressure (kPa), extensor at 350 kPa")
    ax.set_ylabel("elbow angle (rad)")
    ax.set_title("Slow pressure cycle (32 s): friction hysteresis")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(image_path("hysteresis"), dpi=110)
    plt.close(fig)

    def width(rows):
        half = len(rows) // 2
        up, down = rows[:half], rows[half:][::-1]
        return float(np.interp(375e3, up[:, 0], up[:, 1]) - np.interp(375e3, down[:, 0],
                                                                      down[:, 1]))

    # 4. Cost per step.
    print("timing ...")
    linear = mujoco.MjModel.from_xml_string(linear_xml((4e5, 3e5)))
    rates = {
        "MuJoCo alone (linear springs for muscles)": steps_per_second(linear, 0.0),
        "<muscle> (native)": steps_per_second(native, 1 / P_FIT),
        "FMU plugin, friction off": steps_per_second(plugin, 1.0),
        "FMU plugin, friction on": steps_per_second(plugin_friction, 1.0),
        'FMU plugin, friction on, history="fmu"': steps_per_second(
            arm.arm_model(arm.DMSP10 + " friction=true", extra={"history": "fmu"}), 1.0),
    }
    base = 1.0 / rates["MuJoCo alone (linear springs for muscles)"]

    # The page.
    lines = [
        "# MuJoCo: the McKibben FMU against MuJoCo's `<muscle>`",
        "",
        "Generated by `make mujoco-docs` (`examples/mujoco_vs_native_muscle.py`). The arm is "
        "`examples/mujoco/arm.xml` (two Festo DMSP-10 muscles, moment arm 20 mm); how to run it "
        "is in [mujoco.md](mujoco.md).",
        "",
        "## The fit",
        "",
        f"MuJoCo's `<muscle>` fitted to the FMU's tension at {P_FIT / 1e3:.0f} kPa over muscle "
        f"lengths {STROKE[0] * 1e3:.1f} .. {STROKE[1] * 1e3:.1f} mm (least squares on range, "
        f"force and lmin; lmax = {LMAX}): range = [{prm[0]:.4f}, {prm[1]:.4f}], force = "
        f"{prm[2]:.1f} N, lmin = {prm[4]:.4f}, lengthrange = [{lengthrange[0]:.5f}, "
        f"{lengthrange[1]:.5f}] m; RMS error {fit_rms:.2f} N. Activation = pressure / "
        f"{P_FIT / 1e3:.0f} kPa.",
        "",
        "| pressure | RMS difference over the stroke | largest FMU tension |",
        "|---|---|---|",
    ]
    for pressure, (rms, peak) in errors.items():
        lines.append(f"| {pressure / 1e3:.0f} kPa | {rms:.1f} N | {peak:.1f} N |")
    lines += [
        "",
        "![static](img/mujoco_static.png)",
        "",
        "Where they diverge: the `<muscle>` scales its fitted curve by activation, so at lower "
        "pressures it keeps the 600 kPa shape. The FMU's muscle loses stroke as the pressure "
        "falls (the slack point moves to longer lengths) and its tension is not proportional "
        "to pressure: the bladder takes a threshold pressure before the sleeve pulls ("
        + ", ".join(f"{p / 1e3:.0f} kPa at {c:.0%} contraction"
                    for c, p in sorted(thresholds.items())) + "), above which the "
        "tension grows about linearly. At 600 kPa the fit holds; at 150 kPa the `<muscle>` "
        "pulls where the real muscle is slack.",
        "",
        "## The same task",
        "",
        "Same controller (pressures; the `<muscle>` gets pressure / 600 kPa), same torque pulses.",
        "",
        "| | FMU muscles | `<muscle>` |",
        "|---|---|---|",
    ]
    d_fmu, d_nat = pulse_deflection(task_fmu), pulse_deflection(task_nat)
    for i, (a, b) in enumerate(arm.PULSES):
        p = arm.P_LOW if i == 0 else arm.P_HIGH
        lines.append(f"| deflection under {arm.PULSE} N m at {p / 1e3:.0f} kPa common mode | "
                     f"{d_fmu[i]:.4f} rad | {d_nat[i]:.4f} rad |")
    final = lambda t: t[-1]  # noqa: E731
    lines += [
        f"| flexor / extensor pressure at the end | {final(task_fmu)[3] / 1e3:.0f} / "
        f"{final(task_fmu)[4] / 1e3:.0f} kPa | {final(task_nat)[3] / 1e3:.0f} / "
        f"{final(task_nat)[4] / 1e3:.0f} kPa |",
        "",
        "![task](img/mujoco_task.png)",
        "",
        "## Hysteresis",
        "",
        "Flexor pressure 250 -> 500 -> 250 kPa over 32 s, extensor at 350 kPa. Angle difference "
        "between the rising and the falling branch at 375 kPa:",
        "",
        "| | loop width |",
        "|---|---|",
    ]
    for label, rows in cycles.items():
        lines.append(f"| {label} | {abs(width(rows)):.4f} rad |")
    lines += [
        "",
        "Without friction the FMU's loop is the joint damping's viscous lag only. The `<muscle>`'s "
        "loop is its force-velocity curve and activation lag: it shrinks as the cycle slows, "
        "while the friction loop of the FMU stays (it is rate-independent, eq. 2.4).",
        "",
        "![hysteresis](img/mujoco_hysteresis.png)",
        "",
        "## Cost per step",
        "",
        "`mujoco.rollout` (steps in C, one thread), 5,000 steps of 1 ms from q = 0 with the "
        "pressures swinging in antiphase (350 +- 100 kPa, 1 Hz), best of 9, on the machine that "
        "generated this page (shared with other jobs: expect noise of some 20%). The baseline replaces each muscle by a linear "
        "spring fitted at the equilibrium, MuJoCo's cheapest actuator on the same motion.",
        "",
        "| arm with | steps per second | real-time factor (1 ms steps) | time per step | "
        "actuators' share of the step |",
        "|---|---|---|---|---|",
    ]
    for label, rate in rates.items():
        share = max(0.0, 1.0 - base * rate)
        lines.append(f"| {label} | {rate:,.0f} | {rate / 1000:.0f}x | {1e6 / rate:.2f} us | "
                     f"{share:.0%} |")
    lines += [
        "",
        "The actuators' share is the step time above the baseline. With the plugin it is the two "
        "FMUs: each step sets the inputs and reads the force (compute), then steps the FMU "
        "(advance) and, by default, saves the FMU state (fmi2GetFMUstate, "
        "fmi2SerializedFMUstateSize, fmi2SerializeFMUstate) into `plugin_state`. That saving is "
        "most of the cost; with `history=\"fmu\"` the history stays inside the FMU and the "
        "muscles themselves cost about a microsecond per step.",
        "",
    ]
    report.write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
