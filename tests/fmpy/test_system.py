"""The robot joint as a system (systems/): two McKibbenMuscle FMUs and the PulleyJoint FMU joined by
plain connections, run as an SSP by fmpy.ssp.simulation.simulate_ssp and as a container FMU built
by fmu-manipulation-toolbox. Both couple the FMUs Jacobi-style (every FMU steps with its inputs
from the previous exchange), so the muscle forces reach the joint one step later than in
`actuator-fmus robot-joint` (Gauss-Seidel): the trajectories agree closely, not to rounding."""

import math

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from conftest import ROOT

STEP = 1e-3


from actuator_fmus import robot_joint, systems

REFERENCE = np.array(robot_joint.read_csv(ROOT / "tests" / "data" / "robot_joint_ref.csv")[1])
PARAMS = robot_joint.load_parameters()


@pytest.fixture(scope="module")
def ssp_result(tmp_path_factory):
    return systems.run_ssp(systems.build_ssp(tmp_path_factory.mktemp("ssp")))


@pytest.fixture(scope="module")
def container(tmp_path_factory):
    return systems.build_container(tmp_path_factory.mktemp("container"))


def test_ssp_runs_and_tracks_like_the_two_fmu_cosimulation(ssp_result):
    # simulate_ssp records each row at the start of its step with the values at its end.
    t = ssp_result["time"] + STEP
    q = np.interp(REFERENCE[:, 0], t, ssp_result["joint.joint_angle"])
    q_ref = np.interp(REFERENCE[:, 0], t, ssp_result["joint.reference_angle"])
    expected = [robot_joint.reference(PARAMS, t)[0] for t in REFERENCE[:, 0]]
    np.testing.assert_allclose(q_ref, expected, rtol=1e-12, atol=1e-12)
    # The extra step of coupling delay moves the angle by less than 0.02 degrees.
    assert np.max(np.abs(q - REFERENCE[:, 1])) < 3e-4
    assert np.max(np.abs(q - q_ref)) < math.radians(3)


def test_ssp_joint_torque_is_the_pulley_times_the_delivered_forces(ssp_result):
    # The joint steps with the forces the connections delivered at the previous exchange.
    torque = ssp_result["joint.joint_torque"][1:]
    forces = ssp_result["joint.flexor_force"][:-1] - ssp_result["joint.extensor_force"][:-1]
    np.testing.assert_allclose(torque, PARAMS["moment_arm"] * forces, rtol=1e-12, atol=1e-15)
    # And the forces delivered are the muscles' outputs (a plain connection).
    np.testing.assert_array_equal(ssp_result["joint.flexor_force"], ssp_result["flexor.force"])


def test_container_fmu_validates(container):
    assert validate_fmu(str(container)) == []
    names = {v.name for v in read_model_description(str(container)).modelVariables}
    assert {"joint_angle", "reference_angle", "joint_torque", "flexor_force", "extensor_force"} <= names


def test_container_fmu_simulates_the_same_system_as_the_ssp(container, ssp_result):
    c = systems.run_container(container)
    assert c["time"][-1] == pytest.approx(4.0)
    # Same Jacobi exchange as simulate_ssp; the container reports at the end of each step.
    q_container = np.interp(REFERENCE[:, 0], c["time"], c["joint_angle"])
    q_ssp = np.interp(REFERENCE[:, 0], ssp_result["time"] + STEP, ssp_result["joint.joint_angle"])
    np.testing.assert_allclose(q_container, q_ssp, rtol=0, atol=1e-10)
    assert np.max(np.abs(q_container - REFERENCE[:, 1])) < 3e-4
