"""The actuator_fmus.fmu MuJoCo plugin (mujoco_plugin/) with our muscle FMUs inside MuJoCo.

Independent truths: the same FMU stepped by FMPy with the inputs MuJoCo gave the plugin (the
coupling), torque balance and stiffness of the arm solved here from the FMU's own force-length
curves and `stiffness` output with the arm's geometry written out by hand (the physics), and
MuJoCo's state functions (history carried in plugin_state)."""

import copy
import math
import os
import pathlib
import re
import subprocess
import sys

import mujoco
import numpy as np
import pytest
from scipy.optimize import brentq

from conftest import Slave, fmu_path

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "examples"))
import mujoco_arm as arm  # noqa: E402

R = arm.PULLEY_RADIUS
H = arm.HANG
# m g l of the forearm, from arm.xml's masses by hand: 0.3 kg rod from 0.02 to 0.3 m (centre
# 0.16 m), 0.2 kg hand at 0.3 m, pulley on the axis; MuJoCo's default gravity 9.81 m/s^2.
MGL = 9.81 * (0.3 * 0.16 + 0.2 * 0.3)


def muscle_lengths(q):
    """(flexor, extensor) lengths at elbow angle q (arm.xml's geometry: moment arm r)."""
    return H - R * q, H + R * q


# ---------------------------------------------------------------- the coupling, every variant

SLIDER = """
<mujoco>
  <option timestep="{h}"/>
  <extension><plugin plugin="actuator_fmus.fmu"/></extension>
  <worldbody>
    <site name="anchor" pos="0 0 0"/>
    <body name="end">
      <joint name="slide" type="slide" axis="0 0 -1"/>
      <geom type="sphere" size="0.01" mass="0.1"/>
      <site name="hook" pos="0 0 0"/>
    </body>
  </worldbody>
  <tendon><spatial name="muscle"><site site="anchor"/><site site="hook"/></spatial></tendon>
  <actuator>
    <plugin name="muscle" plugin="actuator_fmus.fmu" tendon="muscle">
      <config key="fmu" value="{fmu}"/>
      <config key="parameters" value="{parameters}"/>
      <config key="length_input" value="length"/>
      <config key="ctrl_input" value="pressure"/>
    </plugin>
  </actuator>
</mujoco>"""

# (model, FMU parameters, rest length m, stroke amplitude m): both muscles, friction and bladder
# off and on. Muscle A with its wall is slack below about 93 mm at these pressures and on its
# strands above 95 mm: its stroke spans both.
VARIANTS = [
    ("McKibbenMuscle", {}, 0.09, 0.004),
    ("McKibbenMuscle", {"friction": "true"}, 0.09, 0.004),
    ("McKibbenMuscle", {"bladder_model": 3}, 0.0935, 0.0015),
    ("McKibbenMuscle", {"bladder_model": 3, "friction": "true"}, 0.0935, 0.0015),
    ("McKibbenMuscle", {"preset": "DMSP-10", "nominal_length": 0.25, "friction": "true"}, 0.235,
     0.006),
    ("KnittedMuscle", {}, 0.4, 0.02),
    ("KnittedMuscle", {"friction": "true"}, 0.4, 0.02),
    ("KnittedMuscle", {"bladder_model": 1, "friction": "true"}, 0.4, 0.02),
    ("KnittedMuscle", {"preset": "fig1.16", "friction": "true"}, 0.08, 0.005),
]


def slider(model, parameters, h=1e-3):
    arm.load_plugin()
    text = " ".join(f"{k}={v}" for k, v in parameters.items())
    return mujoco.MjModel.from_xml_string(SLIDER.format(h=h, fmu=fmu_path(model),
                                                        parameters=text))


def fmpy_parameters(parameters):
    out = {}
    for key, value in parameters.items():
        if value in ("true", "false"):
            value = value == "true"
        elif key == "preset":
            value = {"DMSP-10": 5, "DMSP-40": 6, "fig1.16": 2}[value]
        out[key] = value
    return out


@pytest.mark.parametrize("model_name,parameters,rest,stroke", VARIANTS,
                         ids=[f"{m}-{'-'.join(f'{k}={v}' for k, v in p.items()) or 'default'}"
                              for m, p, _, _ in VARIANTS])
def test_plugin_force_is_the_fmu_stepped_with_mujocos_inputs(model_name, parameters, rest, stroke):
    """A prescribed stroke and pressure cycle through MuJoCo; FMPy steps the same FMU with the
    lengths and pressures MuJoCo handed the plugin and must read the same force every step."""
    h = 1e-3
    model = slider(model_name, parameters, h)
    data = mujoco.MjData(model)
    record = []
    for k in range(600):
        t = k * h
        data.qpos[0] = rest + stroke * math.sin(2 * math.pi * 2.5 * t)  # tendon length = qpos
        data.qvel[0] = 0.0
        data.ctrl[0] = 3e5 + 2e5 * math.sin(2 * math.pi * 1.5 * t)
        mujoco.mj_step(model, data)
        # After mj_step: the force and length of the step's start, the control it used.
        record.append((data.actuator_length[0], data.ctrl[0], -data.actuator_force[0]))
    reference = Slave(model_name, **fmpy_parameters(parameters), length=record[0][0],
                      pressure=record[0][1])
    forces = []
    for length, pressure, _ in record:
        forces.append(reference.at("force", length=length, pressure=pressure))
        reference.step(h)
    plugin = np.array([r[2] for r in record])
    assert np.abs(plugin).max() > 1.0, "the stroke produced no force"
    np.testing.assert_array_equal(plugin, forces)  # bit for bit: the same calls in the same order


def test_any_fmu_that_fits_the_mapping_pass_through_as_a_damper():
    """PassThrough (y = u) with u <- actuator velocity and force = -3 y on a free 2 kg slider: a
    viscous damper, so Euler's velocity follows v_k = v_0 (1 - h c / m)^k exactly."""
    arm.load_plugin()
    xml = f"""<mujoco><option timestep="0.001" gravity="0 0 0"/>
      <extension><plugin plugin="actuator_fmus.fmu"/></extension>
      <worldbody><body><joint name="x" type="slide" axis="1 0 0"/>
        <geom type="sphere" size="0.05" mass="2"/></body></worldbody>
      <actuator><plugin name="damper" plugin="actuator_fmus.fmu" joint="x">
        <config key="fmu" value="{fmu_path('PassThrough')}"/>
        <config key="velocity_input" value="u"/><config key="force_output" value="y"/>
        <config key="force_scale" value="-3"/>
      </plugin></actuator></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qvel[0] = 1.5
    velocities = []
    for _ in range(1000):
        mujoco.mj_step(model, data)
        velocities.append(data.qvel[0])
    k = np.arange(1, 1001)
    np.testing.assert_allclose(velocities, 1.5 * (1 - 1e-3 * 3 / 2) ** k, rtol=1e-12)
    # The continuous law, within Euler's first-order error (N h^2 a^2 / 2 = 1.1e-3).
    assert velocities[-1] == pytest.approx(1.5 * math.exp(-1.5), rel=2e-3)


# ---------------------------------------------------------------- the arm: statics

def settle(parameters=arm.DMSP10, pressures=(4e5, 3e5), torque=0.0, seconds=3.0, q0=0.0):
    model = arm.arm_model(parameters)
    data = mujoco.MjData(model)
    data.qpos[0] = q0
    data.ctrl[:] = pressures
    data.qfrc_applied[0] = torque
    for _ in range(int(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return data


class Curves:
    """The DMSP-10 FMU's own force-length curves (FMPy), friction off."""

    def __init__(self):
        self.fmu = Slave("McKibbenMuscle", preset=5, nominal_length=0.25)

    def force(self, length, pressure):
        return self.fmu.at("force", length=length, pressure=pressure)

    def stiffness(self, length, pressure):
        return self.fmu.at("stiffness", length=length, pressure=pressure)

    def torque(self, q, pf, pe, applied=0.0):
        """Net elbow torque (N m) at angle q: cables pull only, gravity -m g l cos q."""
        lf, le = muscle_lengths(q)
        return (R * (max(self.force(lf, pf), 0.0) - max(self.force(le, pe), 0.0))
                - MGL * math.cos(q) + applied)

    def equilibrium(self, pf, pe, applied=0.0):
        return brentq(lambda q: self.torque(q, pf, pe, applied), -1.0, 1.0, xtol=1e-13)


@pytest.fixture(scope="module")
def curves():
    return Curves()


@pytest.mark.parametrize("pressures", [(4e5, 3e5), (5.5e5, 4.5e5), (3e5, 3e5)])
def test_arm_rests_where_the_muscle_moments_balance_gravity(curves, pressures):
    data = settle(pressures=pressures)
    expected = curves.equilibrium(*pressures)
    assert abs(data.qvel[0]) < 1e-6, "not at rest"
    assert data.qpos[0] == pytest.approx(expected, abs=1e-6)
    # MuJoCo's lengths are the hand-written geometry.
    np.testing.assert_allclose(data.actuator_length + arm.LENGTH_OFFSET,
                               muscle_lengths(data.qpos[0]), atol=1e-12)


def test_joint_stiffness_grows_with_co_contraction_and_matches_the_muscles(curves):
    """Small torque perturbations (+-0.02 N m) about the equilibrium, at the same angle-holding
    pressure difference and two common modes: measured stiffness against
    k = r^2 (k_flexor + k_extensor) - m g l sin q from the FMU's `stiffness` outputs."""
    measured, predicted = [], []
    for pressures in [(3.5e5, 2.5e5), (5.5e5, 4.5e5)]:
        dtau = 0.02
        q_plus = settle(pressures=pressures, torque=dtau).qpos[0]
        q_minus = settle(pressures=pressures, torque=-dtau).qpos[0]
        k = 2 * dtau / (q_plus - q_minus)
        q = curves.equilibrium(*pressures)
        lf, le = muscle_lengths(q)
        k_muscles = curves.stiffness(lf, pressures[0]) + curves.stiffness(le, pressures[1])
        measured.append(k)
        predicted.append(R * R * k_muscles - MGL * math.sin(q))
    np.testing.assert_allclose(measured, predicted, rtol=1e-4)
    assert measured[1] > 1.2 * measured[0], f"co-contraction did not stiffen: {measured}"


# ---------------------------------------------------------------- the arm: history

def pressure_cycle(parameters, seconds=32.0):
    """Flexor pressure 250 -> 500 -> 250 kPa (triangle), extensor 350 kPa: (p_flexor, q)."""
    model = arm.arm_model(parameters)
    data = mujoco.MjData(model)
    out = []
    steps = int(seconds / model.opt.timestep)
    for k in range(steps):
        s = k / steps
        pf = 2.5e5 + 2.5e5 * (1 - abs(2 * s - 1))
        data.ctrl[:] = (pf, 3.5e5)
        mujoco.mj_step(model, data)
        out.append((pf, data.qpos[0], s < 0.5))
    return np.array(out)


def loop_width(cycle, pressure=3.75e5):
    """Angle difference between the rising and falling branches at one flexor pressure (rad)."""
    rising = cycle[cycle[:, 2] == 1]
    falling = cycle[cycle[:, 2] == 0][::-1]
    return (np.interp(pressure, rising[:, 0], rising[:, 1])
            - np.interp(pressure, falling[:, 0], falling[:, 1]))


def test_friction_gives_hysteresis_in_a_slow_pressure_cycle(curves):
    """32 s per cycle: without friction the loop is only the viscous lag of the joint damping.
    With it, each muscle's friction Cf P_eff (eq. 2.4, z = +-1 while sliding) opposes the motion
    on both branches, so the loop is 2 r Cf (P_eff,flexor + P_eff,extensor) / k wide, with P_eff
    (`effective_pressure`) and k (`stiffness`) from the FMU at the loop's middle."""
    smooth = loop_width(pressure_cycle(arm.DMSP10))
    rough = loop_width(pressure_cycle(arm.DMSP10 + " friction=true"))
    # Rising pressure lifts the hand against friction: it lags below the falling branch.
    assert rough < -0.02, rough
    # Measured with the DMSP-10 preset: 0.0031 rad against 0.0298 rad.
    assert abs(smooth) < 0.15 * abs(rough), (smooth, rough)
    pf, pe = 3.75e5, 3.5e5
    q = curves.equilibrium(pf, pe)
    lf, le = muscle_lengths(q)
    effective = (curves.fmu.at("effective_pressure", length=lf, pressure=pf)
                 + curves.fmu.at("effective_pressure", length=le, pressure=pe))
    k = R * R * (curves.stiffness(lf, pf) + curves.stiffness(le, pe)) - MGL * math.sin(q)
    friction_coefficient = float(curves.fmu.vars["friction_coefficient"].start)  # the default
    predicted = 2 * R * friction_coefficient * effective / k
    assert -(rough - smooth) == pytest.approx(predicted, rel=0.05)


def run_arm(model, data, seconds):
    controller = arm.Controller()
    out = []
    for _ in range(int(round(seconds / model.opt.timestep))):
        _, pressures, torque = controller(data.time, data.qpos[0], data.qvel[0],
                                          model.opt.timestep)
        data.ctrl[:] = pressures
        data.qfrc_applied[0] = torque
        mujoco.mj_step(model, data)
        out.append((data.qpos[0], data.qvel[0], *data.actuator_force))
    return np.array(out)


def test_runs_are_deterministic():
    model = arm.arm_model(arm.DMSP10 + " friction=true")
    first = run_arm(model, mujoco.MjData(model), 1.0)
    second = run_arm(model, mujoco.MjData(model), 1.0)
    other_model = arm.arm_model(arm.DMSP10 + " friction=true")
    third = run_arm(other_model, mujoco.MjData(other_model), 1.0)
    assert np.array_equal(first, second) and np.array_equal(first, third)


def test_friction_history_is_carried_in_plugin_state():
    """mj_getState/mj_setState, a copied mjData and mj_resetData continue exactly as the
    uninterrupted run; a state from another moment gives another continuation."""
    model = arm.arm_model(arm.DMSP10 + " friction=true")
    data = mujoco.MjData(model)
    data.ctrl[:] = (4.5e5, 2.5e5)
    for _ in range(300):
        mujoco.mj_step(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    saved = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, saved, spec)
    twin = copy.copy(data)

    def cycle(d):
        out = []
        for k in range(400):
            d.ctrl[:] = (4.5e5 - 2e5 * math.sin(math.pi * k / 400), 2.5e5)
            mujoco.mj_step(model, d)
            out.append(-d.actuator_force[0])
        return np.array(out)

    reference = cycle(data)
    later = cycle(data)  # friction state now differs from `saved`
    mujoco.mj_setState(model, data, saved, spec)
    assert np.array_equal(cycle(data), reference)
    assert np.array_equal(cycle(twin), reference)
    assert not np.array_equal(later, reference)

    fresh = mujoco.MjData(model)
    mujoco.mj_resetData(model, data)
    for d in (fresh, data):
        d.ctrl[:] = (4.5e5, 2.5e5)
    assert np.array_equal(cycle(fresh), cycle(data))


def test_threaded_rollout_equals_stepping_one_by_one():
    """mujoco.rollout on two threads (two mjData, FMU instances each) from four initial states:
    the same full-physics states, plugin_state included, as mj_setState + mj_step here."""
    from mujoco import rollout

    model = arm.arm_model(arm.DMSP10 + " friction=true")
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    size = mujoco.mj_stateSize(model, spec)
    data = mujoco.MjData(model)
    initial = []
    for q in (0.0, 0.1, -0.1, 0.2):
        mujoco.mj_resetData(model, data)
        data.qpos[0] = q
        initial.append(np.empty(size))
        mujoco.mj_getState(model, data, initial[-1], spec)
    initial = np.array(initial)
    control = np.tile([4e5, 3e5], (4, 300, 1))
    threaded, _ = rollout.rollout(model, [mujoco.MjData(model) for _ in range(2)], initial,
                                  control)
    for i in range(4):
        mujoco.mj_setState(model, data, initial[i], spec)
        for k in range(300):
            data.ctrl[:] = control[i, k]
            mujoco.mj_step(model, data)
            state = np.empty(size)
            mujoco.mj_getState(model, data, state, spec)
            assert np.array_equal(state, threaded[i, k]), (i, k)


def test_history_kept_in_the_fmu_is_the_same_physics_and_refuses_foreign_states():
    """history="fmu": nothing serialized per step; same trajectory, copies and resets work, and
    mj_setState to another moment is an error that names the option (never a silent restart)."""
    carried = arm.arm_model(arm.DMSP10 + " friction=true")
    kept = arm.arm_model(arm.DMSP10 + " friction=true", extra={"history": "fmu"})
    assert kept.plugin_statenum.tolist() == [3, 3]
    reference = run_arm(carried, mujoco.MjData(carried), 0.6)
    data = mujoco.MjData(kept)
    assert np.array_equal(run_arm(kept, data, 0.6), reference)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    saved = np.empty(mujoco.mj_stateSize(kept, spec))
    mujoco.mj_getState(kept, data, saved, spec)
    mujoco.mj_step(kept, data)
    mujoco.mj_setState(kept, data, saved, spec)
    with pytest.raises(Exception, match='history="plugin_state"'):
        mujoco.mj_step(kept, data)
    mujoco.mj_resetData(kept, data)
    fresh = mujoco.MjData(kept)
    assert np.array_equal(run_arm(kept, data, 0.2), run_arm(kept, fresh, 0.2))


def test_a_copy_continues_the_source_when_the_history_stays_in_the_fmu():
    kept = arm.arm_model(arm.DMSP10 + " friction=true", extra={"history": "fmu"})
    data = mujoco.MjData(kept)
    data.ctrl[:] = (4.5e5, 2.5e5)
    for _ in range(300):
        mujoco.mj_step(kept, data)
    twin = copy.copy(data)
    forces = []
    for d in (data, twin):
        out = []
        for k in range(300):
            d.ctrl[:] = (4.5e5 - 2e5 * math.sin(math.pi * k / 300), 2.5e5)
            mujoco.mj_step(kept, d)
            out.append(d.actuator_force.copy())
        forces.append(np.array(out))
    assert np.array_equal(forces[0], forces[1])


@pytest.mark.parametrize("damage", ["flip a byte", "NaN count", "huge count"])
def test_a_corrupted_plugin_state_is_an_error_not_a_crash(damage):
    model = arm.arm_model(arm.DMSP10 + " friction=true")
    data = mujoco.MjData(model)
    data.ctrl[:] = (4e5, 3e5)
    for _ in range(10):
        mujoco.mj_step(model, data)
    start = model.plugin_stateadr[0]
    if damage == "flip a byte":
        data.plugin_state[start + 20] += 1.0  # the FMU's checksum catches it
    elif damage == "NaN count":
        data.plugin_state[start + 2] = float("nan")
    else:
        data.plugin_state[start + 2] = 1e12
    with pytest.raises(Exception, match="actuator 'flexor'.*plugin_state"):
        mujoco.mj_step(model, data)


# ---------------------------------------------------------------- no allocation per step

COUNTING_MALLOC = r"""
#include <stddef.h>
extern void* __libc_malloc(size_t);
extern void* __libc_calloc(size_t, size_t);
extern void* __libc_realloc(void*, size_t);
extern void* __libc_memalign(size_t, size_t);
static unsigned long n;
unsigned long counted_allocations(void) { return n; }
#define COUNT __atomic_add_fetch(&n, 1, __ATOMIC_RELAXED)
void* malloc(size_t s) { COUNT; return __libc_malloc(s); }
void* calloc(size_t a, size_t b) { COUNT; return __libc_calloc(a, b); }
void* realloc(void* p, size_t s) { COUNT; return __libc_realloc(p, s); }
void* memalign(size_t a, size_t s) { COUNT; return __libc_memalign(a, s); }
void* aligned_alloc(size_t a, size_t s) { COUNT; return __libc_memalign(a, s); }
int posix_memalign(void** p, size_t a, size_t s) { COUNT; *p = __libc_memalign(a, s); return *p ? 0 : 12; }
"""

ALLOCATIONS_PER_STEP = r"""
import ctypes, math, sys
sys.path.insert(0, sys.argv[1])
import mujoco, mujoco_arm as arm
count = ctypes.CDLL(None).counted_allocations
count.restype = ctypes.c_ulong
model = arm.arm_model(arm.DMSP10 + " friction=true", extra={"history": sys.argv[2]})
data = mujoco.MjData(model)
def run(steps):
    for k in range(steps):
        data.ctrl[0] = 3.5e5 + 1e5 * math.sin(k / 100)
        data.ctrl[1] = 3.5e5 - 1e5 * math.sin(k / 100)
        mujoco.mj_step(model, data)
run(200)
before = count()
run(1000)
per_step = (count() - before) / 1000
before = count()
mujoco.MjData(model)  # allocates: the counter counts
print(per_step, count() - before)
"""


def test_a_step_allocates_nothing(tmp_path):
    """malloc counted under LD_PRELOAD over 1000 steps of the moving arm with history="fmu":
    neither the plugin nor the FMU allocates. (With the history in plugin_state the plugin runs
    the same code plus packing into buffers it owns; the FMU's fmi2GetFMUstate and
    fmi2SerializeFMUstate allocate.)"""
    library = tmp_path / "libcount.so"
    (tmp_path / "count.c").write_text(COUNTING_MALLOC)
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", str(library), str(tmp_path / "count.c")],
                   check=True)
    run = subprocess.run([sys.executable, "-c", ALLOCATIONS_PER_STEP, str(ROOT / "examples"),
                          "fmu"], env={**os.environ, "LD_PRELOAD": str(library)},
                         capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert run.returncode == 0, run.stderr
    per_step, sanity = (float(x) for x in run.stdout.split()[-2:])
    assert sanity > 0, "the counter counted nothing: LD_PRELOAD did not take"
    assert per_step == 0.0


# ---------------------------------------------------------------- errors name their cause

ERRORS = [
    ({"fmu": "/nonexistent/Muscle.fmu"}, "cannot read FMU '/nonexistent/Muscle.fmu'"),
    ({"length_input": "lenght"}, "has no variable 'lenght'"),
    ({"force_output": "pressure"}, "'pressure' must be a Real output"),
    ({"parameters": "preset=99"}, "preset refused"),
    ({"parameters": "preset=DMSP-99"}, "preset name (none, A, B, C, D, DMSP-10, DMSP-40, DMSP-5, DMSP-20)"),
    ({"parameters": "turnz=3"}, "parameter 'turnz': McKibbenMuscle has no such variable"),
    ({"parameters": "force=3"}, "'force' is an output, not a parameter or input"),
    ({"parameters": "friction=maybe"}, "'friction' = 'maybe' is not true or false"),
    ({"force_scale": "fast"}, "'force_scale' = 'fast' is not a finite number"),
    ({"history": "disk"}, "'history' = 'disk' is neither plugin_state nor fmu"),
]


@pytest.mark.parametrize("config,message", ERRORS, ids=[m for _, m in ERRORS])
def test_configuration_errors_name_the_cause(config, message):
    arm.load_plugin()
    xml = arm.arm_xml()
    for key, value in config.items():
        xml = arm._set_config(xml, "flexor", key, value)
    with pytest.raises(Exception) as error:
        mujoco.MjModel.from_xml_string(xml)
    assert "actuator_fmus.fmu" in str(error.value)
    assert message in str(error.value)


def test_one_plugin_instance_for_two_actuators_is_refused():
    """Each actuator needs its own FMU instance: a shared <instance> is an error, not two
    actuators writing one FMU's force."""
    arm.load_plugin()
    xml = arm.arm_xml()
    actuators = re.search(r"<actuator>.*</actuator>", xml, re.S).group(0)
    shared = f"""<extension><plugin plugin="actuator_fmus.fmu"><instance name="shared">
      <config key="fmu" value="{fmu_path('McKibbenMuscle')}"/>
      <config key="parameters" value="{arm.DMSP10}"/>
      <config key="length_input" value="length"/><config key="ctrl_input" value="pressure"/>
    </instance></plugin></extension>"""
    xml = re.sub(r"<extension>.*?</extension>", shared, xml, flags=re.S)
    xml = xml.replace(actuators, """<actuator>
      <plugin name="flexor" instance="shared" tendon="flexor"/>
      <plugin name="extensor" instance="shared" tendon="extensor"/></actuator>""")
    with pytest.raises(Exception, match="2 actuators share one plugin instance"):
        model = mujoco.MjModel.from_xml_string(xml)
        mujoco.MjData(model)


def test_an_fmu_error_during_a_step_is_a_mujoco_error():
    """out_of_range_policy=2: the FMU discards a step at a length beyond the muscle's range."""
    arm.load_plugin()
    xml = arm._set_config(arm.arm_xml(arm.DMSP10 + " out_of_range_policy=2"), "flexor",
                          "length_offset", "0.5")
    with pytest.raises(Exception) as error:
        # MuJoCo's compiler already steps the model once, so the error may come from there.
        model = mujoco.MjModel.from_xml_string(xml)
        mujoco.mj_step(model, mujoco.MjData(model))
    text = str(error.value)
    assert "actuator 'flexor'" in text and "fmi2DoStep returned fmi2Discard" in text
    assert "outside the model's valid range" in text  # the FMU's own log line
