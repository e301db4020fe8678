"""Robot joint driven by an antagonistic pair of McKibbenMuscle FMUs, co-simulated with FMPy's
slave API (FMI 2.0, or FMI 3.0 with `ACTUATOR_FMUS_FMI=3`). `tools/examples/robot_joint.rs` runs the same algorithm through the `fmi` crate; both
read `examples/robot_joint.json` and must give the same trajectory.

The joint: a pulley of radius r (`moment_arm`) carries a pendulum (inertia I, viscous damping c,
mass m at distance l). The flexor's length is L0 - r q and the extensor's L0 + r q, so the joint
torque is r (F_flexor - F_extensor). The controller commands a pressure difference
u = P_flexor - P_extensor = k_ff sin(q_ref) + k_p (q_ref - q) + k_d (dq_ref - dq) around a
common-mode pressure, each pressure saturated to 0 .. max_pressure. k_ff sin(q_ref) is the
gravity load divided by the pair's torque per pascal at rest, r dF/dP (eq. 2.3 at L0).

Each communication step h (fixed-step semi-implicit Euler for the joint):
  1. set both muscles' pressure and length from (q, dq) at t, do_step(t, h) on both;
  2. read the forces (quasi-static muscles: the forces at the held inputs);
  3. dq += h (tau - c dq - m g l sin q) / I, then q += h dq (the new velocity).

Writes out/robot_joint.csv and out/robot_joint.png."""

import json
import math
import pathlib

from .paths import ROOT, fmu_path

PARAMETERS = ROOT / "examples" / "robot_joint.json"
COLUMNS = ["time", "q", "dq", "q_ref", "p_flexor", "p_extensor", "f_flexor", "f_extensor", "torque"]


def load_parameters(path=PARAMETERS):
    """The joint's parameters from examples/robot_joint.json (SI units: m, kg, kg m2, N m s, Pa, s)."""
    with open(path) as f:
        return json.load(f)


def reference(p, t):
    """Quintic (minimum-jerk shaped) moves between the waypoints, `segment_time` each; (q, dq)."""
    points, T = p["waypoints"], p["segment_time"]
    k = min(int(t / T), len(points) - 2)
    s = min(max((t - k * T) / T, 0.0), 1.0)
    dq = points[k + 1] - points[k]
    shape = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
    slope = 30.0 * s * s * (1.0 - s) * (1.0 - s)
    return points[k] + dq * shape, dq * slope / T


def pressures(p, t, q, dq):
    """PD with gravity feed-forward on the pressure difference, around the common mode."""
    q_ref, dq_ref = reference(p, t)
    u = p["feedforward_gain"] * math.sin(q_ref) + p["kp"] * (q_ref - q) + p["kd"] * (dq_ref - dq)
    pc, pmax = p["common_mode_pressure"], p["max_pressure"]
    return q_ref, min(max(pc + 0.5 * u, 0.0), pmax), min(max(pc - 0.5 * u, 0.0), pmax)


class Muscle:
    """One McKibbenMuscle instance through FMPy's slave, addressed by value references."""

    def __init__(self, name, parameters, length):
        from fmpy import extract, read_model_description

        from .fmu import CoSimulation
        from .names import fmi2_type

        path = fmu_path("McKibbenMuscle")
        md = read_model_description(path)
        self.vr = {v.name: (v.valueReference, fmi2_type(v)) for v in md.modelVariables}
        self.unzipped = extract(path)
        self.fmu = CoSimulation(self.unzipped, name, md)
        self.fmu.instantiate()
        self.fmu.enterInitializationMode(startTime=0.0)
        for key, value in dict(parameters, length=length).items():
            vr, kind = self.vr[key]
            if kind == "Real":
                self.fmu.setReal([vr], [float(value)])
            elif kind in ("Integer", "Enumeration"):
                self.fmu.setInteger([vr], [int(value)])
            else:
                self.fmu.setBoolean([vr], [bool(value)])
        self.fmu.exitInitializationMode()
        self.inputs = [self.vr["pressure"][0], self.vr["length"][0]]
        self.force = [self.vr["force"][0]]

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def simulate(p, stop_time=None):
    """The co-simulation; returns the recorded rows (every `record_every` steps, and the last).
    A row holds the time t_k+1 and the state (q, dq) there, then what acted during the step from
    t_k: the reference angle at t_k, the pressures, the forces and the torque."""
    h, r, L0 = p["step"], p["moment_arm"], p["rest_length"]
    n = int(round((p["stop_time"] if stop_time is None else stop_time) / h))
    mgl = p["mass"] * p["gravity"] * p["com_distance"]
    flexor = Muscle("flexor", p["muscle_parameters"], L0)
    extensor = Muscle("extensor", p["muscle_parameters"], L0)
    q, dq = 0.0, 0.0
    rows = []
    try:
        for k in range(n):
            t = k * h
            q_ref, p1, p2 = pressures(p, t, q, dq)
            flexor.fmu.setReal(flexor.inputs, [p1, L0 - r * q])
            extensor.fmu.setReal(extensor.inputs, [p2, L0 + r * q])
            flexor.fmu.doStep(t, h)
            extensor.fmu.doStep(t, h)
            f1 = flexor.fmu.getReal(flexor.force)[0]
            f2 = extensor.fmu.getReal(extensor.force)[0]
            torque = r * (f1 - f2)
            dq = dq + h * (torque - p["damping"] * dq - mgl * math.sin(q)) / p["inertia"]
            q = q + h * dq
            if (k + 1) % p["record_every"] == 0 or k + 1 == n:
                rows.append([(k + 1) * h, q, dq, q_ref, p1, p2, f1, f2, torque])
    finally:
        flexor.close()
        extensor.close()
    return rows


def write_csv(rows, path):
    """Writes the trajectory rows (COLUMNS: s, rad, rad/s, rad, Pa, Pa, N, N, N m) to `path`."""
    with open(path, "w") as f:
        f.write(",".join(COLUMNS) + "\n")
        for row in rows:
            f.write(",".join(repr(float(x)) for x in row) + "\n")


def read_csv(path):
    """(header, rows) of a trajectory CSV written by `write_csv` (SI units)."""
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [[float(x) for x in line.split(",")] for line in f if line.strip()]
    return header, rows


def plot(rows, path):
    """Writes the trajectory's plot to `path`: angle in deg, pressures in kPa, forces in N, torque in
    N m."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    a = np.array(rows)
    t = a[:, 0]
    fig, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True)
    axes[0].plot(t, np.degrees(a[:, 3]), "--", label="reference angle (deg)")
    axes[0].plot(t, np.degrees(a[:, 1]), label="joint angle (deg)")
    axes[0].set_ylabel("angle (deg)")
    axes[1].plot(t, a[:, 4] / 1e3, label="flexor pressure (kPa)")
    axes[1].plot(t, a[:, 5] / 1e3, label="extensor pressure (kPa)")
    axes[1].set_ylabel("gauge pressure (kPa)")
    axes[2].plot(t, a[:, 6], label="flexor force (N)")
    axes[2].plot(t, a[:, 7], label="extensor force (N)")
    axes[2].set_ylabel("muscle force (N)")
    axes[3].plot(t, a[:, 8], color="C2", label="joint torque r (F_flexor - F_extensor) (N m)")
    axes[3].set_ylabel("joint torque (N m)")
    axes[3].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    fig.suptitle("Antagonistic McKibbenMuscle pair on a pulley: PD pressure control (FMPy)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def add_arguments(parser):
    """The options of `actuator-fmus robot-joint` (stop time in s)."""
    parser.add_argument("--out", default="out", help="output directory (default: out)")
    parser.add_argument("--stop-time", type=float, default=None, help="s (default: the parameters file's)")
    parser.add_argument("--no-plot", action="store_true", help="write only the CSV")


def main(args):
    """Simulates the joint and writes <out>/robot_joint.csv (SI units) and .png; returns 0."""
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    p = load_parameters()
    rows = simulate(p, args.stop_time)
    write_csv(rows, out / "robot_joint.csv")
    err = max(abs(row[1] - row[3]) for row in rows)
    print(f"{len(rows)} rows, largest tracking error {math.degrees(err):.2f} deg; wrote {out}/robot_joint.csv")
    if not args.no_plot:
        plot(rows, out / "robot_joint.png")
        print(f"wrote {out}/robot_joint.png")
    return 0

