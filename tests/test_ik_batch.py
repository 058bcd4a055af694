"""Robot.ik_batch: the same answers as Robot.ik, target for target, and its batch kinematics.

Closed-form arms (UR5, planar 2R, panda) must give ik's success and the same q; numerical arms
(no closed form) the same success on reachable targets within the tolerance, every q within the
limits. The vectorised forward kinematics and Jacobians are checked against Pinocchio.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import kinplan
from kinplan.batch_ik import BatchKinematics, log3

URDF = Path(__file__).parent / "urdf"


def _targets(robot, rng, reachable: int, random: int):
    """SE3 targets: FK of random configurations, then random poses in a 2 m box."""
    poses = [robot.fk(robot.random_configuration(rng)) for _ in range(reachable)]
    for _ in range(random):
        rotation = pin.SE3.Random().rotation
        poses.append(pin.SE3(rotation, rng.uniform(-1.0, 1.0, 3)))
    return poses


def _tool_errors(robot, q, targets):
    """Position [m] and rotation [rad] errors of the tool at each row of q."""
    out = []
    for row, target in zip(q, targets):
        pose = robot.fk(row)
        out.append(
            (
                np.linalg.norm(pose.translation - target.translation),
                np.linalg.norm(pin.log3(pose.rotation.T @ target.rotation)),
            )
        )
    return np.array(out)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_closed_form_arms_agree_with_ik(name):
    robot = kinplan.load_robot(name)
    rng = np.random.default_rng(11)
    targets = _targets(robot, rng, 60, 40)
    q, success = robot.ik_batch(targets)
    results = [robot.ik(t) for t in targets]
    expected = np.array([r.success for r in results])
    np.testing.assert_array_equal(success, expected)
    assert success[:60].all()  # FK of configurations within the limits: always reachable
    both = np.flatnonzero(success)
    np.testing.assert_allclose(q[both], np.array([results[k].q for k in both]), atol=1e-9)
    errors = _tool_errors(robot, q[both], [targets[k] for k in both])
    assert errors[:, 0].max() <= 1e-6 and errors[:, 1].max() <= 1e-6
    assert np.all((q >= robot.lower - 1e-12) & (q <= robot.upper + 1e-12))


def test_planar_positions_and_seeds_per_target():
    robot = kinplan.load_robot("planar_2r")
    rng = np.random.default_rng(3)
    q_true = np.array([robot.random_configuration(rng) for _ in range(50)])
    positions = robot.tool_positions(q_true)
    # a seed near each configuration keeps its elbow branch
    q, success = robot.ik_batch(positions, q_seed=q_true + 0.05)
    assert success.all()
    np.testing.assert_allclose(q, q_true, atol=1e-9)
    # one seed for all, and the same answers as ik
    q, success = robot.ik_batch(positions, q_seed=[0.3, 0.3])
    for row, position in zip(q, positions):
        np.testing.assert_allclose(row, robot.ik(position, q_seed=[0.3, 0.3]).q, atol=1e-9)
    # out of reach: r > 2 m
    q, success = robot.ik_batch(np.array([[2.5, 0.0, 0.0], [0.0, 1.0, 0.0]]))
    assert success.tolist() == [False, True]


@pytest.mark.parametrize("urdf", ["skewed_axes.urdf", "prismatic_gantry.urdf"])
def test_numerical_arms_reach_what_ik_reaches(urdf):
    robot = kinplan.load_robot(URDF / urdf)
    assert robot.batch_solver.method(False) == "levenberg-marquardt"
    rng = np.random.default_rng(5)
    targets = _targets(robot, rng, 40, 0)
    seeds = np.array([robot.random_configuration(rng) for _ in targets])
    q, success = robot.ik_batch(targets, q_seed=seeds)
    expected = np.array([robot.ik(t, q_seed=s).success for t, s in zip(targets, seeds)])
    assert success.sum() >= expected.sum() - 1, (success.sum(), expected.sum())
    errors = _tool_errors(robot, q[success], [t for t, ok in zip(targets, success) if ok])
    assert errors[:, 0].max() <= 1e-6 and errors[:, 1].max() <= 1e-6
    assert np.all((q >= robot.lower - 1e-12) & (q <= robot.upper + 1e-12))


def test_numerical_position_only_and_unreachable():
    robot = kinplan.load_robot(URDF / "skewed_axes.urdf")
    rng = np.random.default_rng(8)
    reached = robot.tool_positions([robot.random_configuration(rng) for _ in range(10)])
    far = np.array([[50.0, 0.0, 0.0]])
    q, success = robot.ik_batch(np.vstack([reached, far]), max_restarts=2)
    assert success[:10].all() and not success[10]
    assert np.all(np.isfinite(q))


def test_arm_without_batch_kinematics_loops_over_ik():
    robot = kinplan.load_robot(URDF / "mimic_arm.urdf")
    rng = np.random.default_rng(2)
    targets = [robot.fk(robot.random_configuration(rng)) for _ in range(3)]
    q, success = robot.ik_batch(targets)
    expected = [robot.ik(t) for t in targets]
    np.testing.assert_array_equal(success, [r.success for r in expected])
    np.testing.assert_allclose(q, [r.q for r in expected])


def test_continuous_joints_come_back_nearest_the_seed():
    robot = kinplan.load_robot(URDF / "continuous_arm.urdf")
    rng = np.random.default_rng(4)
    q_true = robot.random_configuration(rng)
    seed = q_true + 2.0 * np.pi * np.isinf(robot.upper)  # a whole turn away on the unbounded
    q, success = robot.ik_batch([robot.fk(q_true)], q_seed=seed + 0.01)
    single = robot.ik(robot.fk(q_true), q_seed=seed + 0.01)
    assert success[0] == single.success
    np.testing.assert_allclose(q[0], single.q, atol=1e-6)


def test_target_forms_and_empty_batches():
    robot = kinplan.load_robot("ur5")
    pose = robot.fk(np.array([0.1, -1.2, 1.1, -1.4, -1.5, 0.2]))
    as_list, ok1 = robot.ik_batch([pose, pose])
    as_array, ok2 = robot.ik_batch(np.array([pose.homogeneous] * 2))
    np.testing.assert_array_equal(as_list, as_array)
    assert ok1.all() and ok2.all()
    q, success = robot.ik_batch(np.zeros((0, 4, 4)))
    assert q.shape == (0, 6) and success.shape == (0,)
    q, success = robot.ik_batch([])
    assert q.shape == (0, 6)


@pytest.mark.parametrize(
    "targets, seed, words",
    [
        (np.zeros((2, 3, 3)), None, "shape"),
        (np.full((1, 4, 4), np.nan), None, "not finite"),
        (np.array([np.diag([2.0, 1.0, 1.0, 1.0])]), None, "rotation"),
        (np.array([np.diag([1.0, 1.0, -1.0, 1.0])]), None, "rotation"),
        (np.array([[[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]]), None, "0 0 0 1"),
        ("ur5", None, "targets must be"),
        ([pin.SE3.Identity(), "x"], None, "mixes"),
        (np.array([[0.4, 0.0, 0.3]]), np.zeros(5), "q_seed"),
        (np.array([[0.4, 0.0, 0.3]]), np.zeros((2, 6)), "q_seed"),
        (np.array([[0.4, 0.0, 0.3]]), np.full(6, np.nan), "finite"),
    ],
)
def test_misuse_raises_input_error(targets, seed, words):
    robot = kinplan.load_robot("ur5")
    with pytest.raises(kinplan.InputError, match=words):
        robot.ik_batch(targets, q_seed=seed)


@pytest.mark.parametrize(
    "source",
    ["ur5", "panda", "planar_2r", URDF / "skewed_axes.urdf", URDF / "prismatic_gantry.urdf"],
)
def test_batch_kinematics_match_pinocchio(source):
    robot = kinplan.load_robot(source)
    kinematics = BatchKinematics.of(robot)
    assert kinematics is not None
    rng = np.random.default_rng(9)
    q = np.array([robot.random_configuration(rng) for _ in range(20)])
    positions, rotations, jacobians = kinematics.fk_jacobian(q)
    for k, row in enumerate(q):
        pose, J = robot.pose_and_jacobian(row)
        np.testing.assert_allclose(positions[k], pose.translation, atol=1e-12)
        np.testing.assert_allclose(rotations[k], pose.rotation, atol=1e-12)
        np.testing.assert_allclose(jacobians[k], J, atol=1e-12)


def test_batch_kinematics_refuse_mimic_joints():
    assert BatchKinematics.of(kinplan.load_robot(URDF / "mimic_arm.urdf")) is None


def test_log3_matches_pinocchio_also_near_half_turns():
    rng = np.random.default_rng(1)
    rotations = [pin.SE3.Random().rotation for _ in range(50)]
    for angle in (np.pi, np.pi - 1e-5, np.pi - 2e-3, 1e-9, 0.0):
        axis = rng.normal(size=3)
        rotations.append(pin.exp3(angle * axis / np.linalg.norm(axis)))
    got = log3(np.array(rotations))
    for R, w in zip(rotations, got):
        np.testing.assert_allclose(pin.exp3(w), R, atol=1e-9)
        assert np.linalg.norm(w) <= np.pi + 1e-12
