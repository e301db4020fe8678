"""Table 2.1's muscles A-D through the McKibbenMuscle FMU (dissertation ch. 2):
- out/mckibben_muscles.png: isobaric force-length curves, thick-walled bladder (16 layers);
- out/mckibben_hysteresis.png: a length cycle at constant pressure with friction on;
- out/mckibben_work.csv and a printed table: net work per cycle, thin and thick wall, beside the
  dissertation's statements about pre-strain."""

import argparse
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from actuator_fmus import Slave  # noqa: E402

MUSCLES = {1: ("A", 0.10325, "3% pre-strain"), 2: ("B", 0.1088, "52%"), 3: ("C", 0.0989, "82%"), 4: ("D", 0.1358, "2%, thin wide bladder")}
PRESSURES_KPA = [0, 172, 345, 517, 690]


def curve(preset, model, pressure, lengths, layers=16):
    m = Slave("McKibbenMuscle", preset=preset, bladder_model=model, bladder_layers=layers, length=lengths[0])
    f = np.array([m.at("force", pressure=pressure, length=L) for L in lengths])
    m.close()
    return f


def net_work(preset, model, pressure=6.9e5, top_fraction=0.99):
    """Pressurized contraction from the top of the stroke to zero force, unpressurized return.
    The top is the listed length or top_fraction of max_length, whichever is shorter: the force
    grows without bound at max_length, so the work depends on where the stroke starts."""
    m = Slave("McKibbenMuscle", preset=preset, bladder_model=model, bladder_layers=16, length=0.05)
    top = min(MUSCLES[preset][1], top_fraction * m.get("max_length"))
    lengths = np.linspace(m.get("min_length") * 1.01, top, 4000)
    fp = np.array([m.at("force", pressure=pressure, length=L) for L in lengths])
    f0 = np.array([m.at("force", pressure=0.0, length=L) for L in lengths])
    m.close()
    # Contracting down from the top, the stroke ends where the pressurized force first reaches zero.
    non_positive = np.nonzero(fp <= 0)[0]
    start = non_positive[-1] + 1 if non_positive.size else 0
    return np.trapezoid(fp[start:] - f0[start:], lengths[start:])


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="out")
    out = pathlib.Path(parser.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)

    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    for ax, (preset, (name, listed, note)) in zip(axes.flat, MUSCLES.items()):
        print(f"[{preset}/4] force-length curves of muscle {name}", file=sys.stderr, flush=True)
        m = Slave("McKibbenMuscle", preset=preset, bladder_model=5, length=0.08)
        lo, hi = m.get("min_length"), m.get("max_length")
        m.close()
        lengths = np.linspace(max(0.45 * listed, 1.05 * lo), min(listed, 0.995 * hi), 150)
        for p in PRESSURES_KPA:
            if name == "D" and p > 345:
                continue  # muscle D was tested only up to 345 kPa (its bladder failed)
            ax.plot(lengths / listed, curve(preset, 5, p * 1e3, lengths), label=f"{p} kPa")
        ax.axhline(0, color="0.6", lw=0.8)
        ax.set_ylim(-20, 160)
        ax.set_title(f"muscle {name} ({note}); max length {hi / listed:.3f}")
        ax.set_xlabel("length / listed length")
        ax.set_ylabel("force (N)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("McKibbenMuscle, the dissertation's thick-walled bladder (bladder_model 5, 16 layers), Table 2.1 presets")
    fig.tight_layout()
    fig.savefig(out / "mckibben_muscles.png", dpi=110)

    print("hysteresis loop of muscle D", file=sys.stderr, flush=True)
    m = Slave("McKibbenMuscle", preset=4, bladder_model=4, friction=True, friction_coefficient=2e-5, length=0.09)
    path = np.concatenate([np.linspace(0.09, 0.132, 200), np.linspace(0.132, 0.09, 200)])
    loop = []
    for L in path:
        m.step(pressure=3.45e5, length=L)
        loop.append(m.get("force"))
    m.close()
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    ax.plot(path[:200] * 1e3, loop[:200], label="extension")
    ax.plot(path[200:] * 1e3, loop[200:], label="contraction")
    ax.set_xlabel("length (mm)")
    ax.set_ylabel("force (N)")
    ax.set_title("Muscle D, thin wall, 345 kPa, friction Cf = 2e-5 m\u00b2 (eq. 2.4)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "mckibben_hysteresis.png", dpi=110)

    rows = []
    for preset in (1, 2, 3):
        # The dissertation's walls as written (README's work table) and the exact wall.
        for model, wall in ((4, "thin"), (5, "thick (16 layers)"), (3, "exact")):
            rows.append((MUSCLES[preset][0], wall, net_work(preset, model)))
    with open(out / "mckibben_work.csv", "w") as f:
        f.write("muscle,wall,net_work_J\n")
        for r in rows:
            f.write(f"{r[0]},{r[1]},{r[2]:.4f}\n")
    print("net work per cycle at 690 kPa (J), stroke top = min(listed length, 0.99 max_length):")
    for r in rows:
        print(f"  {r[0]}  {r[1]:18s} {r[2]:.3f}")
    print(f"wrote {out}/mckibben_muscles.png, mckibben_hysteresis.png, mckibben_work.csv")


if __name__ == "__main__":
    main()
