"""MultiferroicMotor (Table 3.1) under FMPy, dissertation chapter 3. Writes to <out>/:

- motor_stepping.csv and motor_stepping.png: rotor angle and strain direction against time under the
  60-degree stepping schedule, at the default 100 us period (discrete steps) and at 25 us
  (continuous rotation);
- motor_torque.png: torque on the bar against the onion state's offset from it, with the rotor
  locked, (a) as the strain direction turns a full circle at 1 GPa and (b) as the stress rises to
  2 GPa at -45 degrees (Fig. 3.3a), with the text's 2.1e-18 N m.

The demo checks the issue's numbers on the way and fails loudly if the FMU disagrees."""

import argparse
import math
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from fmpy import read_model_description

from actuator_fmus import fmu_path, simulate  # simulate: inputs without a column keep their start values

MODEL = "MultiferroicMotor"
FMU = fmu_path(MODEL)
OUTPUTS = ["torque", "rotor_angle", "rotor_speed", "onion_angle", "offset_angle", "applied_strain_direction"]


def stepping(period, steps=12, samples_per_period=100):
    return simulate(
        MODEL,
        start_values={"schedule": "stepping_schedule", "step_period": period},
        output=OUTPUTS,
        stop_time=steps * period,
        output_interval=period / samples_per_period,
    )


def locked(signals, **start):
    return simulate(
        MODEL,
        input=signals,
        start_values={"rotor_locked": True, **start},
        output=OUTPUTS,
        stop_time=1.0,
        output_interval=1.0 / (signals.size - 1),
    )


def ramp(name, start, stop, points):
    """A ramp of one input; the motor's other inputs are given explicitly (no load)."""
    s = np.zeros(points + 1, dtype=[("time", float), (name, float), ("load_torque", float)])
    s["time"] = np.linspace(0.0, 1.0, points + 1)
    s[name] = np.linspace(start, stop, points + 1)
    return s


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="out", help="output directory")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = read_model_description(FMU)
    start = {v.name: float(v.start) for v in md.modelVariables if v.type == "Real" and v.start is not None}

    print("[1/3] stepping schedule, 100 us and 25 us periods", file=sys.stderr, flush=True)
    slow = stepping(start["step_period"])
    fast = stepping(25e-6)
    for r in (slow, fast):
        turned = math.degrees(r["rotor_angle"][-1])
        assert abs(turned - 720.0) < 10.0, f"12 steps should turn 720 degrees, got {turned}"
    header = "time_s,rotor_angle_rad,applied_strain_direction_rad,onion_angle_rad,rotor_speed_rad_per_s,torque_Nm"
    columns = ["time", "rotor_angle", "applied_strain_direction", "onion_angle", "rotor_speed", "torque"]
    np.savetxt(out / "motor_stepping.csv", np.column_stack([slow[c] for c in columns]), delimiter=",",
               header=header, comments="")

    fig, axes = plt.subplots(2, 1, figsize=(8, 7))
    for ax, r, label in ((axes[0], slow, "100 \u00b5s period: discrete steps"),
                         (axes[1], fast, "25 \u00b5s period: continuous rotation")):
        t_us = r["time"] * 1e6
        ax.step(t_us, np.degrees(r["applied_strain_direction"]), where="post", color="0.55",
                label="strain direction (principal tension)")
        ax.plot(t_us, np.degrees(r["onion_angle"]), color="tab:orange", lw=0.8, label="onion state")
        ax.plot(t_us, np.degrees(r["rotor_angle"]), color="tab:blue", lw=1.6, label="rotor (bar)")
        ax.set_title(label, fontsize=10)
        ax.set_ylabel("angle (deg)")
        ax.set_yticks(np.arange(-60, 781, 120))
        ax.grid(alpha=0.3)
    axes[1].set_xlabel("time (\u00b5s)")
    axes[0].legend(loc="upper left", fontsize=8)
    fig.suptitle("MultiferroicMotor, Table 3.1, 200 MPa stepped by 60\u00b0 (section 3.2.2)")
    fig.tight_layout()
    fig.savefig(out / "motor_stepping.png", dpi=120)
    plt.close(fig)

    print("[2/3] locked rotor: strain direction turned at 1 GPa", file=sys.stderr, flush=True)
    turn = locked(ramp("strain_direction", math.radians(-45), math.radians(-45 + 360), 720), stress=1e9)
    print("[3/3] locked rotor: stress sweep at -45 degrees", file=sys.stderr, flush=True)
    sweep = locked(ramp("stress", 0.0, 2e9, 400), strain_direction=math.radians(-45))
    best = int(np.argmax(sweep["torque"]))
    peak = sweep["torque"][best]
    assert abs(peak / 2.1e-18 - 1) < 0.05, f"peak torque {peak:e} is not 2.1e-18 N m within 5%"
    radius, thickness = 0.5 * start["ring_outer_diameter"], start["thickness"]
    density = peak / (math.pi * radius**2 * thickness)
    print(f"peak locked-rotor torque {peak:.4e} N m at offset {math.degrees(sweep['offset_angle'][best]):.1f} deg; "
          f"torque density over the ring's footprint disc {density:.0f} N m/m3 (text: 260)")

    fig, ax = plt.subplots(figsize=(7, 4.5))
    order = np.argsort(turn["offset_angle"])
    ax.plot(np.degrees(turn["offset_angle"][order]), turn["torque"][order] * 1e18, color="tab:blue",
            label="strain direction turned a full circle, 1 GPa")
    ax.plot(np.degrees(sweep["offset_angle"]), sweep["torque"] * 1e18, "o", ms=2.5, color="tab:red",
            label="stress 0 \u2192 2 GPa at \u221245\u00b0 (Fig. 3.3a)")
    ax.axhline(2.1, color="0.5", ls="--", lw=0.8)
    ax.text(-175, 2.17, "text: about 2.1e-18 N m", color="0.4", fontsize=8)
    ax.axhline(0, color="0.7", lw=0.8)
    ax.set_xlim(-180, 180)
    ax.set_xticks(np.arange(-180, 181, 45))
    ax.set_xlabel("offset of the onion state from the bar (deg)")
    ax.set_ylabel("torque on the bar (10\u207b\u00b9\u2078 N m)")
    ax.set_title("MultiferroicMotor, Table 3.1, rotor locked (eq. 3.2-3.3)", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "motor_torque.png", dpi=120)
    plt.close(fig)
    print(f"wrote {out / 'motor_stepping.csv'}, {out / 'motor_stepping.png'}, {out / 'motor_torque.png'}")


if __name__ == "__main__":
    main()
