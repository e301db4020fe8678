"""Force against length of the Festo DMSP-10 (McKibbenMuscle preset 5, nominal length 0.2 m)
through its free contraction, where the muscle goes slack, and up to and past max_length, under
FMPy. Run after `make fmus`:

    .venv/bin/python examples/slack_and_max_length.py   (or `make slack-docs`)

writes docs/img/slack_and_max_length.png and prints the figures docs/slack-and-limits.md quotes."""

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import simulate_fmu  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
FMU = str(ROOT / "target" / "fmu" / "McKibbenMuscle.fmu")
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


if __name__ == "__main__":
    main()
