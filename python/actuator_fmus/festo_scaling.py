"""The Festo DMSP scaling law's figure: `python -m actuator_fmus.festo_scaling DIR` reads
DIR/scaling.csv (written by `target/release/festo_law --out DIR`) and writes DIR/scaling.png.

Forces in N, pressures in kPa, contraction in % of the nominal length.
"""

import csv
import pathlib
import sys

PRESSURES_KPA = (0.0, 200.0, 400.0, 600.0)


def plot(directory):
    """Writes `directory`/scaling.png from `directory`/scaling.csv: force (N) against contraction (%)
    per DMSP size and pressure (kPa), the datasheet beside the law and the leave-one-out fits."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory = pathlib.Path(directory)
    with open(directory / "scaling.csv") as f:
        rows = [{**r, **{k: float(r[k]) for k in ("pressure_kpa", "contraction", "force_n", "model_force_n")}}
                for r in csv.DictReader(f)]
    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    colors = dict(zip(PRESSURES_KPA, plt.cm.viridis([0.0, 0.33, 0.66, 0.95])))
    panels = [("DMSP-10", "from DMSP-40"), ("DMSP-40", "from DMSP-10"), ("DMSP-5", None), ("DMSP-20", None)]
    for ax, (size, other) in zip(axes.flat, panels):
        for kpa in PRESSURES_KPA:
            def curve(source):
                pts = sorted((r for r in rows if r["size"] == size and r["source"] == source
                              and r["pressure_kpa"] == kpa), key=lambda r: r["contraction"])
                return [100 * r["contraction"] for r in pts], pts
            c, pts = curve("law")
            if other:
                ax.plot(c, [r["force_n"] for r in pts], "o", ms=4, color=colors[kpa],
                        label=f"datasheet, {kpa:g} kPa")
                ax.plot(c, [r["model_force_n"] for r in pts], "-", color=colors[kpa],
                        label=f"law from both fits, {kpa:g} kPa")
                c2, pts2 = curve(other)
                ax.plot(c2, [r["model_force_n"] for r in pts2], "--", color=colors[kpa],
                        label=f"law {other} fit alone, {kpa:g} kPa")
            else:
                ax.plot(c, [r["model_force_n"] for r in pts], "-", color=colors[kpa],
                        label=f"law, {kpa:g} kPa (no curves shipped)")
        title = (f"{size}: datasheet, law, and leave-one-out ({other} fit alone)" if other
                 else f"{size} from its catalogue numbers by the law (prediction)")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("contraction 1 - L / L_N (%)")
        ax.set_ylabel("force (N)")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    fig.suptitle("Festo DMSP scaling law: McKibbenMuscle with the exact wall (signed force, "
                 "inextensible strands) against the datasheets", fontsize=11)
    fig.tight_layout()
    fig.savefig(directory / "scaling.png", dpi=100)
    plt.close(fig)
    print(f"wrote {directory / 'scaling.png'}")


if __name__ == "__main__":
    plot(sys.argv[1] if len(sys.argv) > 1 else "docs/calibration")
