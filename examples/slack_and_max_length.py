"""Force against length of the Festo DMSP-10 (McKibbenMuscle preset 5, nominal length 0.2 m)
through its free contraction, where the muscle goes slack, and up to and past max_length; the
same for McKibbenJoint's two muscles against the joint angle and for KnittedMuscle, under FMPy.
Run after `make fmus`:

    .venv/bin/python examples/slack_and_max_length.py   (or `make slack-docs`)

writes docs/img/slack_and_max_length.png and docs/img/slack_and_max_length_joint_knitted.png and
prints the figures docs/slack-and-limits.md quotes."""

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import simulate_fmu  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
FMU = str(ROOT / "target" / "fmu" / "McKibbenMuscle.fmu")
JOINT = str(ROOT / "target" / "fmu" / "McKibbenJoint.fmu")
KNITTED = str(ROOT / "target" / "fmu" / "KnittedMuscle.fmu")
MUSCLE = {"preset": 5, "nominal_length": 0.2}
PRESSURES = [1e5, 3e5, 6e5]  # Pa


def sweep(pressure, lengths, **start):
    """Force (N) and slack flag along `lengths` (m) at `pressure` (Pa)."""
    n = len(lengths)
    t = np.linspace(0.0, 1.0, n)
    signal = np.array(list(zip(t, np.full(n, pressure), lengths)),
                      dtype=[("time", float), ("pressure", float), ("length", float)])
    r = simulate_fmu(FMU, stop_time=1.0, output_interval=1.0 / (n - 1),
                     start_values={**MUSCLE, **start}, input=signal,
                     output=["force", "slack", "input_clamped", "max_length"])
    return r["force"], r["slack"], r["input_clamped"], r["max_length"][0]


def main():
    _, _, _, max_length = sweep(3e5, np.array([0.18, 0.18]))
    lengths = np.linspace(0.6 * 0.2, max_length + 0.02 * 0.2, 1601)
    fig, (ax, ax_log) = plt.subplots(1, 2, figsize=(12, 4.8))
    for pressure, colour in zip(PRESSURES, ["tab:blue", "tab:orange", "tab:green"]):
        force, slack, clamped, _ = sweep(pressure, lengths)
        signed, _, _, _ = sweep(pressure, lengths, signed_force=True)
        kpa = pressure / 1e3
        ax.plot(lengths * 1e3, force, color=colour, label=f"{kpa:.0f} kPa, tension only (N)")
        ax.plot(lengths * 1e3, signed, color=colour, ls="--",
                label=f"{kpa:.0f} kPa, signed_force (N)")
        ax_log.semilogy(lengths * 1e3, np.maximum(force, 1e-3), color=colour,
                        label=f"{kpa:.0f} kPa, tension only (N)")
        taut = np.nonzero(~slack.astype(bool))[0]
        free = lengths[taut[0]] if taut.size else float("nan")
        inside = lengths <= max_length
        print(f"{kpa:.0f} kPa: slack below {free * 1e3:.2f} mm "
              f"(contraction {1 - free / 0.2:.3f}); largest force inside max_length "
              f"{force[inside].max():.4g} N; beyond it {force[~inside].min():.4g} .. "
              f"{force[~inside].max():.4g} N (input_clamped {bool(clamped[~inside].all())})")
    for a in (ax, ax_log):
        a.axvline(max_length * 1e3, color="k", lw=0.8, ls=":", label=f"max_length {max_length * 1e3:.1f} mm")
        a.set_xlabel("muscle length (mm)")
        a.grid(alpha=0.3)
    ax.set_ylim(-150, 600)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylabel("force (N)")
    ax.set_title("Through the free contraction: slack, force 0 (linear)")
    ax_log.set_ylabel("force (N, log scale; 1e-3 N shown for 0)")
    ax_log.set_title("Up to and past max_length (log)")
    ax.legend(fontsize=7, loc="upper left")
    ax_log.legend(fontsize=7, loc="upper left")
    fig.suptitle("McKibbenMuscle, Festo DMSP-10 (preset 5, nominal length 200 mm): force against length")
    fig.tight_layout()
    out = ROOT / "docs" / "img" / "slack_and_max_length.png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out.relative_to(ROOT)}")


def simulate(fmu, inputs, outputs, start):
    """`outputs` along the input columns `inputs` ({name: array}), one sample per step: FMPy
    records the outputs of the step that starts at a sample at the next one, so sample `k + 1`
    holds the outputs for input `k`; returned aligned with the inputs (the last input repeated)."""
    names = list(inputs)
    columns = [np.append(inputs[k], inputs[k][-1]) for k in names]
    n = len(columns[0])
    t = np.linspace(0.0, 1.0, n)
    signal = np.array(list(zip(t, *columns)), dtype=[("time", float)] + [(k, float) for k in names])
    r = simulate_fmu(fmu, stop_time=1.0, output_interval=1.0 / (n - 1), start_values=start,
                     input=signal, output=outputs)
    return {k: r[k][1:] for k in outputs}


def joint_and_knitted():
    """McKibbenJoint (bare sleeves, b = 111.3 mm, short muscles: rest lengths 70 mm, moment arm
    15 mm) against the joint angle, and KnittedMuscle (the section 1.4 prototype's geometry)
    against its length."""
    fig, ((j_lin, j_log), (k_lin, k_log)) = plt.subplots(2, 2, figsize=(12, 9.6))
    b, rest, arm = 0.1113, 0.07, 0.015
    short = {"flexor_rest_length": rest, "extensor_rest_length": rest}
    one = simulate(JOINT, {"jointPosition": np.zeros(2)}, ["max_position"], short)
    max_position = one["max_position"][0]
    breaking = (1.05 * b - rest) / arm
    q = np.linspace(-breaking - 0.1, breaking + 0.1, 3201)
    u = 1e5
    outputs = ["jointTorque", "flexor_force", "extensor_force", "flexor_slack", "input_clamped"]
    r = simulate(JOINT, {"actuatorInput": np.full(q.size, u), "jointPosition": q}, outputs, short)
    s = simulate(JOINT, {"actuatorInput": np.full(q.size, u), "jointPosition": q}, outputs,
                 {**short, "signed_force": True})
    j_lin.plot(q, r["jointTorque"], color="tab:blue", label="jointTorque, tension only (N m)")
    j_lin.plot(q, s["jointTorque"], color="tab:blue", ls="--", label="jointTorque, signed_force (N m)")
    j_log.semilogy(q, np.maximum(r["flexor_force"], 1e-3), color="tab:red", label="flexor_force (N)")
    j_log.semilogy(q, np.maximum(r["extensor_force"], 1e-3), color="tab:green", label="extensor_force (N)")
    slack = q[r["flexor_slack"].astype(bool)]
    inside = np.abs(q) <= max_position
    right = (q > max_position) & (q <= breaking)
    slope = np.polyfit(rest + arm * q[right], r["extensor_force"][right], 1)[0]
    print(f"McKibbenJoint, actuatorInput {u / 1e3:.0f} kPa: max_position {max_position:.4f} rad, "
          f"flexor slack from {slack.min():.3f} rad; largest |torque| inside max_position "
          f"{np.abs(r['jointTorque'][inside]).max():.3f} N m, at the breaking angle {breaking:.3f} rad "
          f"{np.abs(r['jointTorque'][right]).max():.3f} N m; extensor slope past b {slope:.4g} N/m")
    for a in (j_lin, j_log):
        for x, label in [(max_position, f"max_position {max_position:.3f} rad"),
                         (breaking, f"breaking angle {breaking:.3f} rad")]:
            a.axvline(x, color="k", lw=0.8, ls=":" if x == max_position else "-.", label=label)
            a.axvline(-x, color="k", lw=0.8, ls=":" if x == max_position else "-.")
        a.set_xlabel("jointPosition (rad)")
        a.grid(alpha=0.3)
    j_lin.set_ylim(-6.0, 6.0)
    j_lin.set_ylabel("jointTorque (N m)")
    j_lin.set_title("McKibbenJoint: torque (linear, clipped to +-6 N m)")
    j_log.set_ylabel("muscle force (N, log scale; 1e-3 N shown for 0)")
    j_log.set_title("McKibbenJoint: muscle forces, slack and on the strands (log)")

    free = simulate(KNITTED, {"pressure": np.zeros(2), "length": np.full(2, 0.4)},
                    ["max_length", "free_contraction_length"], {})
    k_max, k_free = free["max_length"][0], free["free_contraction_length"][0]
    k_break = k_max * 1.05
    lengths = np.linspace(0.1, k_break + 0.01, 1601)
    for pressure, colour in zip([1e4, 2e4, 5e4], ["tab:blue", "tab:orange", "tab:green"]):
        inputs = {"pressure": np.full(lengths.size, pressure), "length": lengths}
        r = simulate(KNITTED, inputs, ["force", "slack", "input_clamped"], {})
        s = simulate(KNITTED, inputs, ["force"], {"signed_force": True})
        kpa = pressure / 1e3
        k_lin.plot(lengths * 1e3, r["force"], color=colour, label=f"{kpa:.0f} kPa, tension only (N)")
        k_lin.plot(lengths * 1e3, s["force"], color=colour, ls="--", label=f"{kpa:.0f} kPa, signed_force (N)")
        k_log.semilogy(lengths * 1e3, np.maximum(r["force"], 1e-3), color=colour,
                       label=f"{kpa:.0f} kPa, tension only (N)")
        taut = lengths[~r["slack"].astype(bool)]
        inside = lengths <= k_max
        on_yarn = (lengths > k_max) & (lengths <= k_break)
        slope = np.polyfit(lengths[on_yarn], r["force"][on_yarn], 1)[0]
        print(f"KnittedMuscle {kpa:.0f} kPa: slack below {taut.min() * 1e3:.1f} mm; force at max_length "
              f"{r['force'][inside][-1]:.4g} N, at the breaking length "
              f"{r['force'][on_yarn].max():.4g} N (slope {slope:.4g} N/m); clamped beyond "
              f"{bool(r['input_clamped'][lengths > k_break].all())}")
    for a in (k_lin, k_log):
        a.axvline(k_max * 1e3, color="k", lw=0.8, ls=":", label=f"max_length {k_max * 1e3:.1f} mm")
        a.axvline(k_break * 1e3, color="k", lw=0.8, ls="-.", label=f"breaking length {k_break * 1e3:.1f} mm")
        a.set_xlabel("muscle length (mm)")
        a.grid(alpha=0.3)
    k_lin.axvline(k_free * 1e3, color="grey", lw=0.8, ls="--",
                  label=f"free_contraction_length {k_free * 1e3:.1f} mm")
    k_lin.set_ylim(-300, 1500)
    k_lin.axhline(0.0, color="k", lw=0.5)
    k_lin.set_ylabel("force (N)")
    k_lin.set_title("KnittedMuscle: through the free contraction (linear)")
    k_log.set_ylabel("force (N, log scale; 1e-3 N shown for 0)")
    k_log.set_title("KnittedMuscle: up to and past max_length, on the yarn (log)")
    for a in (j_lin, j_log, k_lin, k_log):
        a.legend(fontsize=7, loc="best")
    fig.suptitle("Slack and the stretching strands: McKibbenJoint (actuatorInput 100 kPa, bare sleeves, "
                 "rest lengths 70 mm)\nand KnittedMuscle (the section 1.4 prototype's knit)")
    fig.tight_layout()
    out = ROOT / "docs" / "img" / "slack_and_max_length_joint_knitted.png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
    joint_and_knitted()
