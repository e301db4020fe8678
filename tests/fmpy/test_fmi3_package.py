"""The package's modules that drive the FMUs point by point (chapter2, linearized, slave, motor,
robot_joint, sweep) run on the FMI 3.0 FMUs with `ACTUATOR_FMUS_FMI=3` and give the FMI 2.0
numbers bit for bit.

Each version runs in its own interpreter, as a user would run it: the switch is read when the
package is imported."""

import json
import os
import subprocess
import sys

from actuator_fmus.paths import FMI3_DIR, ROOT

# Every float goes out as float.hex: equal strings are equal bits.
PROGRAM = r"""
import json
from actuator_fmus import chapter2, linearized, motor, robot_joint, sweep
from actuator_fmus.fmu import CoSimulation
from actuator_fmus.paths import FMU_DIR, fmu_path
from actuator_fmus.slave import Slave

out = {"dir": str(FMU_DIR)}
h = lambda xs: [float(x).hex() for x in xs]

m = chapter2.Muscle(preset=1, bladder_model=chapter2.EXACT)
out["chapter2"] = h([m.max_length, m.min_length, m.strand, m.force(300e3, 0.1),
                     m.get("threshold_pressure", 0.0, 0.1), m.zero_force_length(690e3, 0.1)])
m.close()
out["chapter2_page"] = chapter2.page(chapter2.rows())

lin = linearized.Muscle(2)
out["linearized"] = h([x for L in (0.095, 0.105) for P in (100e3, 500e3) for x in lin.at(P, L)])
lin.close()

s = Slave("McKibbenMuscle", preset="DMSP_40", length=0.36, bladder_model=3, bladder_layers=8)
for k in range(20):
    s.step(1e-3, pressure=3e5 * k / 19, length=0.36 - 0.002 * k)
out["slave"] = h(s.get("force", "friction_force", "effective_pressure", "stress_hoop")) + [s.get("bladder_model")]
s.close()

motor_fmu = motor.Motor()
out["motor"] = h([motor_fmu.stepping(20e-6, 0.0, periods=7)])
motor_fmu.close()

p = robot_joint.load_parameters()
out["robot_joint"] = h([x for row in robot_joint.simulate(p, stop_time=0.05) for x in row])

fmu = CoSimulation(sweep._fmu_dir(open(fmu_path("McKibbenMuscle"), "rb").read()), "sweep")
vr = {v.name: v.valueReference for v in fmu.md.modelVariables}
fmu.instantiate()
out["sweep"] = h([sweep.net_work(fmu, vr, 0.5, 1.6e-3, 4, 40)])
fmu.freeInstance()
print(json.dumps(out))
"""


def run(version):
    env = {k: v for k, v in os.environ.items() if k not in ("ACTUATOR_FMUS_FMI", "ACTUATOR_FMUS_DIR")}
    if version == 3:
        env["ACTUATOR_FMUS_FMI"] = "3"
    done = subprocess.run([sys.executable, "-c", PROGRAM], env=env, cwd=ROOT, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_the_modules_give_the_fmi2_numbers_on_the_fmi3_fmus():
    fmi2, fmi3 = run(2), run(3)
    # The switch took effect: the second run read the FMI 3.0 FMUs.
    assert fmi3.pop("dir") == str(FMI3_DIR) and fmi2.pop("dir") != str(FMI3_DIR)
    assert fmi2.keys() == fmi3.keys()
    for key in fmi2:
        assert fmi3[key] == fmi2[key], key
    # The runs did something: forces are positive, the motor stepped 6 x 60 degrees.
    assert float.fromhex(fmi2["chapter2"][3]) > 0 and float.fromhex(fmi2["slave"][0]) > 0
    assert abs(float.fromhex(fmi2["motor"][0]) - 6 * 1.0471975511965976) < 0.5
