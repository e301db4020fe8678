"""Default scene: isobaric force-length curves of McKibbenMuscle (Table 2.1, muscle A) at
100-600 kPa, simulated under FMPy. Writes <out>/force_length.csv and <out>/force_length.png.

The length input ramps from 0.45 b to 0.99 b at each pressure; the FMU's force is compared with
eq. 2.3 on the way, so the demo fails loudly if the FMU and the equation ever disagree."""

import argparse
import math
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from fmpy import read_model_description, simulate_fmu

ROOT = pathlib.Path(__file__).resolve().parents[1]
FMU = ROOT / "target" / "fmu" / "McKibbenMuscle.fmu"
PRESSURES_KPA = [100, 200, 300, 400, 500, 600]


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="out", help="output directory")
    parser.add_argument("--points", type=int, default=200, help="samples per curve")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    md = read_model_description(str(FMU))
    start = {v.name: float(v.start) for v in md.modelVariables if v.type == "Real" and v.start is not None}
    b, n = start["strand_length"], start["turns"]

    rows = []
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for i, p_kpa in enumerate(PRESSURES_KPA):
        print(f"[{i + 1}/{len(PRESSURES_KPA)}] {p_kpa} kPa", file=sys.stderr, flush=True)
        t = np.linspace(0.0, 1.0, args.points)
        signals = np.zeros(t.size, dtype=[("time", float), ("pressure", float), ("length", float)])
        signals["time"] = t
        signals["pressure"] = p_kpa * 1e3
        signals["length"] = b * (0.45 + 0.54 * t)
        r = simulate_fmu(
            str(FMU),
            input=signals,
            output=["pressure", "length", "force", "volume"],
            stop_time=1.0,
            output_interval=1.0 / (args.points - 1),
        )
        eq_2_3 = r["pressure"] * (3 * r["length"] ** 2 - b**2) / (4 * math.pi * n**2)
        assert np.allclose(r["force"], eq_2_3, rtol=1e-9, atol=1e-12), "FMU disagrees with eq. 2.3"
        rows += [(p, L, F, V) for p, L, F, V in zip(r["pressure"], r["length"], r["force"], r["volume"])]
        ax.plot(r["length"] * 1e3, r["force"], label=f"{p_kpa} kPa")

    ax.axhline(0, color="0.6", lw=0.8)
    ax.axvline(b / math.sqrt(3) * 1e3, color="0.6", lw=0.8, ls="--")
    ax.text(b / math.sqrt(3) * 1e3, ax.get_ylim()[1] * 0.92, "  L = b/\u221a3", color="0.4")
    ax.set_xlabel("muscle length L (mm)")
    ax.set_ylabel("force F (N), tension positive")
    ax.set_title(f"McKibbenMuscle, ideal sleeve (eq. 2.3): b = {b * 1e3:.1f} mm, n = {n}")
    ax.legend(title="gauge pressure")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "force_length.png", dpi=120)

    with open(out / "force_length.csv", "w") as f:
        f.write("pressure_Pa,length_m,force_N,volume_m3\n")
        for row in rows:
            f.write(",".join(f"{x:.9g}" for x in row) + "\n")
    print(f"wrote {out / 'force_length.csv'} ({len(rows)} rows) and {out / 'force_length.png'}")


if __name__ == "__main__":
    main()
