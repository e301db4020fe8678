"""The section 1.4 knitted prototype (dissertation ch. 1) through the KnittedMuscle FMU:
- out/knitted_curves.png: force-length at 14 kPa for each shape model (ideal cylinder, tubular
  knit, non-cylindrical), and the non-cylindrical one with friction Cf = 0.25 (Fig. 1.18);
- out/knitted_profile.png: the non-cylindrical radius profile at several lengths (Fig. 1.12).
  The FMU cannot return a profile: it comes from
  `cargo run --release -p actuator-fmus-tools --bin knitted_profile`,
  which prints it as CSV from the crate's physics."""

import argparse
import io
import pathlib
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from actuator_fmus import ROOT, Slave  # noqa: E402

PRESSURE = 14e3
SHAPES = {0: "ideal cylinder (eq. 1.8)", 1: "tubular knit (eq. 1.14)", 2: "non-cylindrical (eq. 1.17-1.20)"}


def force_curve(lengths, **parameters):
    m = Slave("KnittedMuscle", length=lengths[0], **parameters)
    f = np.array([m.at("force", pressure=PRESSURE, length=L) for L in lengths])
    m.close()
    return f


def friction_loop(**parameters):
    m = Slave("KnittedMuscle", length=0.514, friction=True, friction_coefficient=0.25, **parameters)
    lengths = np.linspace(m.get("max_length"), m.get("min_length"), 300)
    path = np.concatenate([lengths, lengths[::-1]])
    forces = []
    for L in path:
        m.step(pressure=PRESSURE, length=L)
        forces.append(m.get("force"))
    m.close()
    return path, np.array(forces)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="out")
    out = pathlib.Path(parser.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)

    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    for shape, label in SHAPES.items():
        m = Slave("KnittedMuscle", shape_model=shape, length=0.4)
        lo, hi = m.get("min_length", "max_length")
        m.close()
        lengths = np.linspace(max(lo, 0.15), hi, 400)
        ax.plot(lengths * 1e3, force_curve(lengths, shape_model=shape), label=label)
    path, forces = friction_loop(shape_model=2)
    rising = np.append(np.diff(path) > 0, np.diff(path)[-1] > 0)
    ax.plot(path[rising] * 1e3, forces[rising], "k-", lw=1,
            label="non-cylindrical, friction Cf = 0.25, extension (length rising, Fig. 1.18)")
    ax.plot(path[~rising] * 1e3, forces[~rising], "k--", lw=1,
            label="non-cylindrical, friction Cf = 0.25, contraction (length falling)")
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_xlabel("length (mm)")
    ax.set_ylabel("force (N)")
    ax.set_title("Knitted prototype (m = 22, n = 49, 514 mm) at 14 kPa: force of each shape model;\n"
                 "the tubular knit lies on the ideal cylinder at m = 22", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "knitted_curves.png", dpi=120)
    print(f"wrote {out / 'knitted_curves.png'}")

    profile = ["cargo", "run", "-q", "--release", "-p", "actuator-fmus-tools", "--bin", "knitted_profile"]
    csv = subprocess.run(profile, cwd=ROOT, check=True, capture_output=True, text=True).stdout
    data = np.loadtxt(io.StringIO(csv), delimiter=",", skiprows=1)
    fig, ax = plt.subplots(figsize=(10, 3.6))
    for length in np.unique(data[:, 0])[::-1]:
        ring = data[data[:, 0] == length]
        line, = ax.plot(ring[:, 1] * 1e3, ring[:, 2] * 1e3, label=f"L = {length * 1e3:.0f} mm")
        ax.plot(ring[:, 1] * 1e3, -ring[:, 2] * 1e3, color=line.get_color())
    ax.set_xlabel("axial position (mm)")
    ax.set_ylabel("radius (mm)")
    ax.set_aspect("equal")
    ax.set_title("Non-cylindrical prototype: the pocket grows from full extension to free contraction")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    fig.savefig(out / "knitted_profile.png", dpi=120)
    print(f"wrote {out / 'knitted_profile.png'}")


if __name__ == "__main__":
    main()
