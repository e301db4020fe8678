"""An elbow in MuJoCo driven by two McKibbenMuscle FMUs (Festo DMSP-10) through the
actuator_fmus.fmu plugin: position control, then stiffness raised by co-contraction at a fixed
angle, with external torque pulses that show the stiffness. The model is examples/mujoco/arm.xml.

    .venv/bin/python examples/mujoco_arm.py --out out/mujoco      (make mujoco-arm)

Writes <out>/arm.csv (time, angle, muscle lengths, forces, pressures, external torque),
arm.png, and with --gif a rendered arm.gif when offscreen rendering works
(MUJOCO_GL=egl, else osmesa). Importable: tests/fmpy/test_mujoco.py and
examples/mujoco_vs_native_muscle.py build their models with `arm_model`.

The controller sets the two pressures around a common-mode pressure p_c:
p_flexor = p_c + u/2, p_extensor = p_c - u/2, u = kp e + ki int(e) - kd dq with e = q_ref - q,
each clamped to 0 .. 600 kPa. During a torque pulse it holds its pressures (open loop), so the
deflection measures the muscles' stiffness: k = r^2 (k_flexor + k_extensor) - m g l sin q."""

import argparse
import csv
import math
import os
import pathlib
import re
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
ARM_XML = ROOT / "examples" / "mujoco" / "arm.xml"
PLUGIN = ROOT / "target" / "mujoco-plugin" / "release" / "libactuator_fmus_mujoco.so"
FMU_DIR = ROOT / "target" / "fmu"

# The geometry of arm.xml (see its header).
PULLEY_RADIUS = 0.02  # m, the moment arm of both muscles
HANG = 0.2375  # m, muscle length at q = 0
NOMINAL_LENGTH = 0.25  # m, DMSP-10
MAX_PRESSURE = 600e3  # Pa, ctrlrange
DMSP10 = "preset=DMSP-10 nominal_length=0.25"
LENGTH_OFFSET = -0.04695523289953723  # m, arm.xml's length_offset: muscle = tendon + offset

_loaded = False


def load_plugin():
    """Registers the plugin with MuJoCo once per process (mujoco.mj_loadPluginLibrary)."""
    global _loaded
    import mujoco

    if not _loaded:
        assert PLUGIN.exists(), f"{PLUGIN} is missing: run `make mujoco-plugin` first"
        mujoco.mj_loadPluginLibrary(str(PLUGIN))
        _loaded = True


def _set_config(xml, actuator, key, value):
    """Sets <config key=...> of the plugin actuator named `actuator` in the MJCF text."""
    block = re.search(rf'<plugin name="{actuator}".*?</plugin>', xml, re.S)
    assert block, actuator
    text = block.group(0)
    pattern = rf'<config key="{key}" value="[^"]*"/>'
    line = f'<config key="{key}" value="{value}"/>'
    new = re.sub(pattern, line, text) if re.search(pattern, text) else text.replace(
        "</plugin>", f"  {line}\n    </plugin>")
    return xml.replace(text, new)


def arm_xml(parameters=DMSP10, extensor_parameters=None, fmu="McKibbenMuscle", extra=None,
            timestep=None):
    """arm.xml with an absolute FMU path and the given FMU parameters (`extra`: more config keys
    for both muscles, e.g. {"velocity_input": ...})."""
    xml = ARM_XML.read_text()
    path = FMU_DIR / f"{fmu}.fmu"
    assert path.exists(), f"{path} is missing: run `make fmus` first"
    for name, params in (("flexor", parameters), ("extensor", extensor_parameters or parameters)):
        xml = _set_config(xml, name, "fmu", str(path))
        xml = _set_config(xml, name, "parameters", params)
        for key, value in (extra or {}).items():
            xml = _set_config(xml, name, key, value)
    if timestep is not None:
        xml = xml.replace('<option timestep="0.001"/>', f'<option timestep="{timestep}"/>')
    return xml


def arm_model(*args, **kwargs):
    import mujoco

    load_plugin()
    return mujoco.MjModel.from_xml_string(arm_xml(*args, **kwargs))


def minimum_jerk(t, t0, t1, q0, q1):
    s = min(max((t - t0) / (t1 - t0), 0.0), 1.0)
    return q0 + (q1 - q0) * s ** 3 * (10 - 15 * s + 6 * s * s)


Q_TARGET = 0.3  # rad
P_LOW, P_HIGH = 250e3, 450e3  # Pa, common-mode pressure before and after co-contraction
PULSE = 0.3  # N m, external torque pulses (lowering the hand)
PULSES = ((2.5, 3.2), (5.0, 5.7))  # s


class Controller:
    """PID on the angle around a scheduled common-mode pressure; open loop during torque pulses."""

    def __init__(self, kp=1.5e6, ki=3e6, kd=6e4):
        self.kp, self.ki, self.kd = kp, ki, kd
        self.integral = 0.0
        self.last_u = 0.0
        self.held = None

    @staticmethod
    def reference(t):
        """(q_ref rad, common-mode pressure Pa, external torque N m) of the task at time t."""
        q_ref = minimum_jerk(t, 0.5, 2.0, 0.0, Q_TARGET)
        p_common = P_LOW + (P_HIGH - P_LOW) * min(max(t - 3.5, 0.0) / 1.0, 1.0)
        torque = -PULSE if any(a <= t < b for a, b in PULSES) else 0.0
        return q_ref, p_common, torque

    def __call__(self, t, q, dq, dt):
        q_ref, p_common, torque = self.reference(t)
        if torque:
            if self.held is None:
                self.held = self.pressures(p_common, self.last_u)
            return q_ref, self.held, torque
        self.held = None
        error = q_ref - q
        # Anti-windup: the integral alone never asks for more than the full pressure range.
        self.integral = min(max(self.integral + error * dt, -MAX_PRESSURE / self.ki),
                            MAX_PRESSURE / self.ki)
        u = self.kp * error + self.ki * self.integral - self.kd * dq
        self.last_u = u
        return q_ref, self.pressures(p_common, u), torque

    @staticmethod
    def pressures(p_common, u):
        return (min(max(p_common + 0.5 * u, 0.0), MAX_PRESSURE),
                min(max(p_common - 0.5 * u, 0.0), MAX_PRESSURE))


COLUMNS = ["time_s", "angle_rad", "angle_ref_rad", "flexor_length_m", "extensor_length_m",
           "flexor_force_N", "extensor_force_N", "flexor_pressure_Pa", "extensor_pressure_Pa",
           "external_torque_Nm"]


def run_task(model, duration=6.5, record_every=10, frames=None, fps=12.5):
    """The arm task; rows of COLUMNS every `record_every` steps, and rendered frames if asked."""
    import mujoco

    data = mujoco.MjData(model)
    controller = Controller()
    dt = model.opt.timestep
    offset = LENGTH_OFFSET
    rows = []
    renderer = frames is not None and _renderer(model)
    next_frame = 0.0
    steps = int(round(duration / dt))
    for k in range(steps):
        q, dq = data.qpos[0], data.qvel[0]
        q_ref, (pf, pe), torque = controller(data.time, q, dq, dt)
        data.ctrl[:] = (pf, pe)
        data.qfrc_applied[0] = torque
        if k % record_every == 0:
            mujoco.mj_forward(model, data)
            rows.append([data.time, q, q_ref, data.actuator_length[0] + offset,
                         data.actuator_length[1] + offset, -data.actuator_force[0],
                         -data.actuator_force[1], pf, pe, torque])
        if renderer and data.time >= next_frame - 1e-9:
            # Each muscle's colour brightens with its pressure (drawing only; physics unchanged).
            for i, pressure in enumerate((pf, pe)):
                level = 0.25 + 0.75 * pressure / MAX_PRESSURE
                model.tendon_rgba[i] = (level, 0.15, 0.15, 1) if i == 0 else (0.15, 0.2, level, 1)
            renderer.update_scene(data, camera=_camera())
            frames.append(renderer.render().copy())
            next_frame += 1.0 / fps
        mujoco.mj_step(model, data)
    return np.array(rows)


def _camera():
    import mujoco

    cam = mujoco.MjvCamera()
    cam.lookat[:] = (0.1, 0.0, 0.06)
    cam.distance, cam.azimuth, cam.elevation = 0.75, 90.0, -5.0
    return cam


def _renderer(model):
    """A MuJoCo offscreen renderer, or None when no GL backend works here."""
    import mujoco

    try:
        return mujoco.Renderer(model, 240, 320)
    except Exception as error:  # no EGL/OSMesa context: render nothing
        print(f"offscreen rendering unavailable ({error}); no GIF")
        return None


def write_csv(rows, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        w.writerows(rows.tolist())


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = rows[:, 0]
    fig, ax = plt.subplots(4, 1, figsize=(8, 10), sharex=True)
    ax[0].plot(t, rows[:, 2], "k--", label="reference (rad)")
    ax[0].plot(t, rows[:, 1], label="elbow angle (rad)")
    ax[0].set_ylabel("angle (rad)")
    ax[1].plot(t, rows[:, 7] / 1e3, "r", label="flexor pressure (kPa)")
    ax[1].plot(t, rows[:, 8] / 1e3, "b", label="extensor pressure (kPa)")
    ax[1].set_ylabel("gauge pressure (kPa)")
    ax[2].plot(t, rows[:, 5], "r", label="flexor tension (N)")
    ax[2].plot(t, rows[:, 6], "b", label="extensor tension (N)")
    ax[2].set_ylabel("muscle force (N)")
    ax[3].plot(t, rows[:, 3] * 1e3, "r", label="flexor length (mm)")
    ax[3].plot(t, rows[:, 4] * 1e3, "b", label="extensor length (mm)")
    ax3 = ax[3].twinx()
    ax3.plot(t, rows[:, 9], "g:", label="external torque (N m)")
    ax3.set_ylabel("external torque (N m)")
    ax[3].set_ylabel("muscle length (mm)")
    ax[3].set_xlabel("time (s)")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(loc="upper left", fontsize=8)
    ax3.legend(loc="lower right", fontsize=8)
    fig.suptitle("Antagonistic elbow in MuJoCo, two McKibbenMuscle FMUs (Festo DMSP-10):\n"
                 f"move to {Q_TARGET} rad, {PULSE} N m pulses at {P_LOW / 1e3:.0f} kPa and at "
                 f"{P_HIGH / 1e3:.0f} kPa co-contraction")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def pulse_stiffness(rows):
    """Joint stiffness (N m/rad) from each torque pulse: torque over the settled deflection."""
    t, q, torque = rows[:, 0], rows[:, 1], rows[:, 9]
    result = []
    for start, end in PULSES:
        before = q[(t > start - 0.1) & (t < start)].mean()
        during = q[(t > end - 0.1) & (t < end)].mean()
        amplitude = torque[(t >= start) & (t < end)].min()
        result.append(amplitude / (during - before))
    return result


def stiffness_sweep(commons=np.linspace(250e3, 550e3, 7), difference=100e3, dtau=0.02):
    """Joint stiffness over co-contraction at a fixed pressure difference: measured in MuJoCo by
    +-dtau torque perturbations about the equilibrium, and predicted from the FMU's own
    `stiffness` output, k = r^2 (k_flexor + k_extensor) - m g l sin q.
    Rows: (common-mode Pa, angle rad, measured N m/rad, predicted N m/rad)."""
    import mujoco

    from actuator_fmus import Slave

    fmu = Slave("McKibbenMuscle", preset=5, nominal_length=0.25)
    model = arm_model()
    forearm = model.body("forearm").id
    mgl = -model.opt.gravity[2] * model.body_mass[forearm] * model.body_ipos[forearm][0]

    def rest(pressures, torque):
        data = mujoco.MjData(model)
        data.ctrl[:] = pressures
        data.qfrc_applied[0] = torque
        for _ in range(3000):
            mujoco.mj_step(model, data)
        return data.qpos[0]

    rows = []
    for common in commons:
        pressures = (common + difference / 2, common - difference / 2)
        q = rest(pressures, 0.0)
        measured = 2 * dtau / (rest(pressures, dtau) - rest(pressures, -dtau))
        lf, le = HANG - PULLEY_RADIUS * q, HANG + PULLEY_RADIUS * q
        k = (fmu.at("stiffness", length=lf, pressure=pressures[0])
             + fmu.at("stiffness", length=le, pressure=pressures[1]))
        rows.append((common, q, measured, PULLEY_RADIUS ** 2 * k - mgl * math.sin(q)))
        print(f"  common mode {common / 1e3:.0f} kPa: q = {q:.4f} rad, k = {measured:.4f} "
              f"(predicted {rows[-1][3]:.4f}) N m/rad")
    return np.array(rows)


def plot_stiffness(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(rows[:, 0] / 1e3, rows[:, 3], "k-", label="from the FMU's stiffness outputs (N m/rad)")
    ax.plot(rows[:, 0] / 1e3, rows[:, 2], "o", label="measured in MuJoCo, +-0.02 N m (N m/rad)")
    ax.set_xlabel("common-mode pressure (kPa), flexor - extensor = 100 kPa")
    ax.set_ylabel("joint stiffness (N m/rad)")
    ax.set_title("Elbow stiffness over co-contraction: r^2 (k_flexor + k_extensor) - m g l sin q")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="out/mujoco")
    parser.add_argument("--gif", action="store_true", help="render a GIF (needs EGL or OSMesa)")
    parser.add_argument("--stiffness", action="store_true",
                        help="also sweep the co-contraction: arm_stiffness.png")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.gif:
        os.environ.setdefault("MUJOCO_GL", "egl")
    model = arm_model()
    frames = [] if args.gif else None
    start = time.perf_counter()
    rows = run_task(model, frames=frames)
    wall = time.perf_counter() - start
    write_csv(rows, out / f"arm.csv")
    plot(rows, out / f"arm.png")
    soft, stiff = pulse_stiffness(rows)
    print(f"simulated {rows[-1, 0]:.2f} s in {wall:.2f} s wall (recording included)")
    print(f"angle at 3.4 s: {rows[np.searchsorted(rows[:, 0], 3.4), 1]:.4f} rad (reference {Q_TARGET})")
    print(f"joint stiffness from the pulses: {soft:.2f} N m/rad at {P_LOW / 1e3:.0f} kPa, "
          f"{stiff:.2f} N m/rad at {P_HIGH / 1e3:.0f} kPa co-contraction")
    if frames:
        from PIL import Image

        images = [Image.fromarray(f) for f in frames]
        images[0].save(out / f"arm.gif", save_all=True, append_images=images[1:],
                       duration=round(1000 / 12.5), loop=0)
        print(f"wrote {out / 'arm.gif'} ({len(images)} frames)")
    print(f"wrote {out / 'arm.csv'} and {out / 'arm.png'}")
    if args.stiffness:
        print("joint stiffness over co-contraction ...")
        rows = stiffness_sweep()
        plot_stiffness(rows, out / "arm_stiffness.png")
        worst = np.max(np.abs(rows[:, 2] / rows[:, 3] - 1))
        print(f"largest relative difference {worst:.1e}; wrote {out / 'arm_stiffness.png'}")


if __name__ == "__main__":
    main()
