"""Two McKibben muscle FMUs as MuJoCo actuators: an elbow held at 0.3 rad by a PI pressure
controller, then stiffened by co-contraction.  Run after `make fmus mujoco-plugin`:
    .venv/bin/python recipes/mujoco_arm.py

The model is examples/mujoco/arm.xml; docs/mujoco.md explains each line of its <plugin> blocks.
"""

import pathlib

import mujoco

ROOT = pathlib.Path(__file__).resolve().parents[1]

# 1. Register the plugin (once per process), then load the MJCF. Its FMU paths are relative to
#    the working directory; make them absolute so the recipe runs from anywhere.
mujoco.mj_loadPluginLibrary(str(ROOT / "target/mujoco-plugin/release/libactuator_fmus_mujoco.so"))
xml = (ROOT / "examples/mujoco/arm.xml").read_text()
xml = xml.replace('value="target/fmu/', f'value="{ROOT}/target/fmu/')
model = mujoco.MjModel.from_xml_string(xml)
data = mujoco.MjData(model)

# 2. Control: ctrl is each muscle's gauge pressure in Pa. PI on the angle around a common mode.
target, integral, h = 0.3, 0.0, model.opt.timestep
for k in range(6000):
    common = 250e3 if k < 3000 else 450e3  # co-contraction after 3 s
    error = target - data.qpos[0]
    integral += error * h
    u = 1.5e6 * error + 3e6 * integral - 6e4 * data.qvel[0]
    data.ctrl[:] = (min(max(common + u / 2, 0), 6e5), min(max(common - u / 2, 0), 6e5))
    mujoco.mj_step(model, data)
    if k in (2999, 5999):
        flexor, extensor = -data.actuator_force  # MuJoCo's sign: negative pulls
        print(f"t = {data.time:.1f} s: angle {data.qpos[0]:.4f} rad, pressures "
              f"{data.ctrl[0] / 1e3:.0f}/{data.ctrl[1] / 1e3:.0f} kPa, tensions "
              f"{flexor:.1f}/{extensor:.1f} N")
        assert abs(data.qpos[0] - target) < 2e-3

# 3. The muscles' history (friction; by default in plugin_state) is part of MuJoCo's state: a
#    copy, mj_getState/mj_setState and mj_resetData carry it.
saved = mujoco.MjData(model)
mujoco.mj_copyData(saved, model, data)
mujoco.mj_step(model, data)
mujoco.mj_step(model, saved)
assert (data.actuator_force == saved.actuator_force).all()
print(f"plugin_state: {model.plugin_statenum.tolist()} numbers per muscle; a copied mjData "
      "steps identically")
