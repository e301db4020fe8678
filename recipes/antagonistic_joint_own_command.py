"""Drive an antagonistic McKibben joint with your own controller, two ways.  Run after `make fmus`:
    .venv/bin/python recipes/antagonistic_joint_own_command.py

1. Torque commands, as gazebo-fmi passes its controller's effort: McKibbenJoint with
   `command_mode` 1 finds the two pressures that give the commanded torque at the current angle
   and says (`torque_saturated`) when the muscles cannot deliver it. Here a PD torque controller
   with gravity feedforward holds a pendulum that this script integrates.
2. Your own pressures: PulleyJoint with `external_pressures` bypasses its built-in controller, and
   two McKibbenMuscle FMUs pull on it; here a PI pressure law of our own moves it to 0.25 rad.
"""

import math

from actuator_fmus import Slave  # an initialized FMU addressed by variable names

H = 1e-3
INERTIA, DAMPING, MGL = 0.004, 0.05, 0.25 * 9.81 * 0.12  # the PulleyJoint's pendulum

# 1. Torque commands.
joint = Slave("McKibbenJoint", command_mode=1)
q = dq = 0.0
target = 0.2
worst_late_error, saturated_in_window, saturated_steps = 0.0, 0, 0
for k in range(3000):
    t = k * H
    q_ref = target * min(1.0, t / 0.5)  # ramp to 0.2 rad in 0.5 s
    effort = MGL * math.sin(q_ref) + 2.0 * (q_ref - q) - 0.1 * dq  # your controller, N.m
    if 1.5 <= t < 1.6:
        effort = 5.0  # more than the muscles can give: delivered torque is the largest reachable
    joint.step(H, actuatorInput=effort, jointPosition=q, jointVelocity=dq)
    torque, saturated = joint.get("jointTorque", "torque_saturated")
    saturated_steps += saturated
    saturated_in_window += saturated and 1.5 <= t < 1.6
    if not saturated:
        assert abs(torque - effort) <= 1e-6 * max(abs(effort), 1e-3), (t, torque, effort)
    dq += H * (torque - DAMPING * dq - MGL * math.sin(q)) / INERTIA
    q += H * dq
    if t > 2.7:
        worst_late_error = max(worst_late_error, abs(q - target))
pf, pe = joint.get("flexor_pressure", "extensor_pressure")
joint.close()
print(f"1. torque commands: angle {q:.4f} rad for a target of {target} rad (pressures {pf / 1e3:.1f} and "
      f"{pe / 1e3:.1f} kPa); saturated in all {saturated_in_window} steps of the 5 N.m request and "
      f"{saturated_steps - saturated_in_window} steps of the recovery after it")
assert worst_late_error < 0.02 and saturated_in_window == 100

# 2. Your own pressures into PulleyJoint, two McKibbenMuscle FMUs pulling on it.
pulley = Slave("PulleyJoint", external_pressures=True)
flexor, extensor = Slave("McKibbenMuscle", length=0.09), Slave("McKibbenMuscle", length=0.09)
force_f = force_e = 0.0
pc, integral, target = 3.5e5, 0.0, 0.25
commands = (pc, pc)
for k in range(4000):
    pulley.step(H, flexor_force=force_f, extensor_force=force_e, flexor_pressure_command=commands[0],
                extensor_pressure_command=commands[1])
    q, dq = pulley.get("joint_angle", "joint_velocity")
    p_f, p_e, l_f, l_e = pulley.get("flexor_pressure", "extensor_pressure", "flexor_length", "extensor_length")
    flexor.step(H, pressure=p_f, length=l_f)
    extensor.step(H, pressure=p_e, length=l_e)
    force_f, force_e = flexor.get("force"), extensor.get("force")
    # Your controller: PI on the angle, all of it on the flexor; the extensor holds the common mode.
    integral += H * (target - q)
    commands = (pc + 2e6 * (target - q) + 4e6 * integral - 1e5 * dq, pc)
print(f"2. external pressures: angle {q:.4f} rad for a target of {target} rad "
      f"(flexor {p_f / 1e3:.1f} kPa, extensor {p_e / 1e3:.1f} kPa)")
assert abs(q - target) < 0.01 and p_e == pc
for s in (pulley, flexor, extensor):
    s.close()
