"""Robot properties the mutation survivors of ``kinplan/model/robot.py`` showed untested, each
checked
against an independent answer: the reach against a bounded optimiser started from sampled
configurations, the chain length as an upper bound of every sampled tool distance, batch IK
against per-target IK and the FK of its answers, J̇ against central differences of the
Jacobian, and the arguments an error message must name."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from conftest import TESTS, cached_robot
from scipy.optimize import minimize

import kinplan
from kinplan.errors import InputError
from kinplan.model.extent import chain_length
from kinplan.model.robot import manipulability_of, planar_arm

URDF = TESTS / "urdf"
#: Arms without a planar annulus: UR5 (shoulder above the base), panda (7 joints), a gantry
#: whose first two joints are prismatic.
SPATIAL = ["ur5", "panda", str(URDF / "prismatic_gantry.urdf")]


def bounds(robot) -> tuple[np.ndarray, np.ndarray]:
    """Position limits, continuous joints within [−π, π]."""
    lower = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    upper = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    return lower, upper


def shoulder_distances(robot, q: np.ndarray) -> np.ndarray:
    """Distances [m] of the tool from the first joint's origin, computed here from FK."""
    origin = robot.model.jointPlacements[1].translation
    return np.linalg.norm(robot.tool_positions(q) - origin, axis=1)


@pytest.mark.parametrize("source", SPATIAL)
def test_reach_is_the_largest_tool_distance_a_bounded_optimiser_finds(source):
    robot = kinplan.load_robot(source)  # a new robot: reach() is cached per instance
    lower, upper = bounds(robot)
    q = np.random.default_rng(1).uniform(lower, upper, (2000, robot.nq))
    sampled = shoulder_distances(robot, q)
    origin = robot.model.jointPlacements[1].translation

    def minus_distance(row):
        return -float(np.linalg.norm(robot.fk(row).translation - origin))

    best = max(
        -minimize(
            minus_distance, q[i], bounds=list(zip(lower, upper)), method="L-BFGS-B",
            options={"ftol": 1e-15, "gtol": 1e-12},
        ).fun
        for i in np.argsort(-sampled)[:3]
    )  # fmt: skip
    reach = robot.reach()
    assert reach >= sampled.max()
    np.testing.assert_allclose(reach, best, rtol=1e-8)
    # the chain laid end to end (prismatic joints at their longest) bounds every distance
    assert chain_length(robot) >= reach


def test_chain_length_counts_every_prismatic_extension_and_the_tool_offset():
    gantry = kinplan.load_robot(URDF / "prismatic_gantry.urdf")
    # joint offsets 0.1 + 0.1 + 0.35 + 0.3 + 0.08, tool 0.1, rail 0.5 and lift 0.4 extended
    np.testing.assert_allclose(chain_length(gantry), 0.1 + 0.1 + 0.35 + 0.3 + 0.08 + 0.1 + 0.9)
    lower, upper = bounds(gantry)
    q = np.random.default_rng(2).uniform(lower, upper, (500, gantry.nq))
    q[:, :2] = upper[:2]  # rail and lift at their ends
    assert shoulder_distances(gantry, q).max() <= chain_length(gantry)
    # rail and lift are the prismatic joints (yourdfpy reads the joint types independently)
    urdf = yourdfpy.URDF.load(str(URDF / "prismatic_gantry.urdf"), load_meshes=False)
    kinds = [urdf.joint_map[name].type == "prismatic" for name in gantry.joint_names]
    assert gantry.prismatic.tolist() == kinds == [True, True, False, False, False, False]
    assert not planar_arm([0.4, 0.3]).prismatic.any()


def test_planar_reach_is_the_sum_of_the_link_lengths_and_no_sample_goes_further():
    arm = planar_arm([0.4, 0.3, 0.2])
    assert arm.reach() == pytest.approx(0.9, abs=1e-12)
    q = np.random.default_rng(3).uniform(arm.lower, arm.upper, (500, 3))
    assert shoulder_distances(arm, q).max() <= arm.reach() + 1e-12


# ---------------------------------------------------------------------------- batch IK
def reachable_poses(robot, count: int, seed: int) -> tuple[np.ndarray, list[pin.SE3]]:
    rng = np.random.default_rng(seed)
    q = np.array([robot.random_configuration(rng) for _ in range(count)])
    return q, [robot.fk(row) for row in q]


def assert_reaches(robot, q: np.ndarray, poses, position_only=False, tol=1e-5) -> None:
    for row, pose in zip(q, poses, strict=True):
        reached = robot.fk(row)
        np.testing.assert_allclose(reached.translation, pose.translation, atol=tol)
        if not position_only:
            np.testing.assert_allclose(reached.rotation, pose.rotation, atol=tol)
        assert robot.within_limits(row)


@pytest.mark.parametrize("name", ["ur5", "prismatic_gantry"])
def test_batch_ik_equals_per_target_ik(name):
    robot = cached_robot(name) if name == "ur5" else kinplan.load_robot(URDF / f"{name}.urdf")
    q_true, poses = reachable_poses(robot, 6, 4)
    seeds = np.clip(q_true + 0.05, robot.lower, robot.upper)
    q, success = robot.ik_batch(poses, seeds)
    assert success.all()
    assert_reaches(robot, q, poses)
    for k, pose in enumerate(poses):
        single = robot.ik(pose, q_seed=seeds[k])
        assert single.success
        if name == "ur5":  # the closed form: the same branch, the one nearest the seed
            np.testing.assert_allclose(q[k], single.q, atol=1e-6)


def test_batch_ik_per_target_seeds_pick_each_targets_branch(ur5):
    q_true, poses = reachable_poses(ur5, 5, 5)
    # one seed for all: every answer is the branch nearest that one seed
    q_one, _ = ur5.ik_batch(poses, ur5.neutral())
    q_each, success = ur5.ik_batch(poses, q_true)
    assert success.all()
    np.testing.assert_allclose(q_each, q_true, atol=1e-6)  # each seed is its own answer
    for k, pose in enumerate(poses):
        np.testing.assert_allclose(q_one[k], ur5.ik(pose, q_seed=ur5.neutral()).q, atol=1e-6)


def test_batch_ik_position_only_ignores_the_orientation(ur5):
    _, poses = reachable_poses(ur5, 4, 6)
    turned = [
        pin.SE3(pin.exp3(np.array([0.0, 2.5, 0.0])) @ p.rotation, p.translation) for p in poses
    ]
    q, success = ur5.ik_batch(turned, position_only=True)
    assert success.all()
    assert_reaches(ur5, q, turned, position_only=True)


def test_batch_ik_continuous_joints_come_back_nearest_a_seed_turns_away():
    arm = kinplan.load_robot(URDF / "continuous_arm.urdf")
    q_true, poses = reachable_poses(arm, 4, 7)
    unbounded = ~np.isfinite(arm.lower)
    seeds = q_true.copy()
    seeds[:, unbounded] += 2 * np.pi * np.array([[2], [-1], [3], [-2]])  # whole turns away
    q, success = arm.ik_batch(poses, seeds)
    assert success.all()
    assert np.all(np.abs(q[:, unbounded] - seeds[:, unbounded]) <= np.pi + 1e-9)
    assert_reaches(arm, q, poses)


def test_batch_ik_checks_its_seeds_tolerances_and_counts(ur5):
    _, poses = reachable_poses(ur5, 2, 8)
    with pytest.raises(InputError, match=r"q_seed must be one configuration \(6,\)"):
        ur5.ik_batch(poses, np.zeros((3, 6)))
    with pytest.raises(InputError, match="q_seed must be one configuration"):
        ur5.ik_batch(poses, "home")
    with pytest.raises(InputError, match="q_seed must be finite"):
        ur5.ik_batch(poses, np.full((2, 6), np.nan))
    with pytest.raises(InputError, match="q_seed"):
        ur5.ik_batch(poses, [0.0, 0.0, np.nan, 0.0, 0.0, 0.0])
    with pytest.raises(InputError, match="position_tolerance"):
        ur5.ik_batch(poses, position_tolerance=-1.0)
    with pytest.raises(InputError, match="rotation_tolerance"):
        ur5.ik_batch(poses, rotation_tolerance=0.0)
    with pytest.raises(InputError, match="max_iterations"):
        ur5.ik_batch(poses, max_iterations=0)
    q, success = ur5.ik_batch(poses, max_restarts=0)  # no restarts is a valid request
    assert success.all()
    assert_reaches(ur5, q, poses)


# ---------------------------------------------------------------------------- kinematics
def test_jacobian_time_variations_are_central_differences_of_the_jacobian(panda):
    rng = np.random.default_rng(9)
    q = np.array([panda.random_configuration(rng) for _ in range(3)])
    qd = rng.normal(size=q.shape)
    h = 1e-6
    expected = np.array(
        [(panda.jacobian(a + h * v) - panda.jacobian(a - h * v)) / (2 * h) for a, v in zip(q, qd)]
    )
    np.testing.assert_allclose(panda.jacobian_time_variations(q, qd), expected, atol=1e-6)


def test_manipulability_of_a_rank_zero_task_is_zero():
    assert manipulability_of(np.zeros((3, 2)), 0) == 0.0
    np.testing.assert_array_equal(manipulability_of(np.zeros((4, 3, 2)), 0), np.zeros(4))
    J = np.diag([2.0, 3.0, 0.0])  # rank 2 of 3: the product of the two largest singular values
    assert manipulability_of(J, 2) == pytest.approx(6.0)


def test_reference_manipulability_is_per_task(ur5):
    position_only, full = ur5.reference_manipulability(True), ur5.reference_manipulability(False)
    assert position_only != pytest.approx(full, rel=1e-3)
    rng = np.random.default_rng(10)
    q = np.array([ur5.random_configuration(rng) for _ in range(400)])
    # the medians over random configurations agree with the low-discrepancy ones to ~25 %
    for flag, value in ((True, position_only), (False, full)):
        median = np.median([ur5.manipulability(row, flag) for row in q])
        assert value == pytest.approx(median, rel=0.25)


def test_within_limits_takes_an_integer_tolerance(ur5):
    q = ur5.upper.copy()
    q[0] += 0.5
    assert not ur5.within_limits(q, 0) and not ur5.within_limits(q, 0.0)
    assert ur5.within_limits(q, 1) and ur5.within_limits(q, 1.0)


# ---------------------------------------------------------------------------- construction
def test_base_pose_is_kept_and_moves_the_tool():
    plain = cached_robot("ur5")
    assert plain.base_pose.isApprox(pin.SE3.Identity())
    base = pin.SE3(pin.exp3(np.array([0.0, 0.0, 0.4])), np.array([0.5, -0.2, 0.1]))
    moved = kinplan.load_robot("ur5", base_pose=base)
    assert moved.base_pose.isApprox(base)
    q = np.radians([10, -80, 70, -60, 40, 20])
    assert (base * plain.fk(q)).isApprox(moved.fk(q), 1e-12)
    with pytest.raises(InputError, match="base_pose"):
        kinplan.load_robot("ur5", base_pose=np.eye(3))


def test_planar_arm_keeps_its_name_and_limits_and_checks_their_sizes():
    arm = planar_arm(
        [0.5, 0.4], lower=-2.0, upper=[2.0, 2.5], velocity_limit=[1.5, 2.5], name="two"
    )
    assert arm.name == "two"
    np.testing.assert_allclose(arm.velocity_limit, [1.5, 2.5])
    np.testing.assert_allclose(arm.upper, [2.0, 2.5])
    np.testing.assert_allclose(arm.lower, [-2.0, -2.0])
    for key in ("lower", "upper", "velocity_limit"):
        with pytest.raises(InputError, match=key):
            planar_arm([0.5, 0.4], **{key: [1.0, 1.0, 1.0]})
    with pytest.raises(InputError, match=r"lengths \(link lengths\).*\[m\]"):
        planar_arm([[0.5, 0.4]])


def test_errors_name_the_shape_the_source_and_the_reason(ur5):
    with pytest.raises(InputError, match=r"shape \(5,\)"):
        ur5.check_q(np.zeros(5))
    with pytest.raises(InputError, match=r"\[rad or m\]"):
        ur5.tool_positions(np.zeros((2, 5)))
    long_path = "a/" * 3000 + "arm.urdf"  # the OS refuses the name: the message shortens it
    with pytest.raises(kinplan.RobotNotFoundError) as caught:
        kinplan.load_robot(long_path)
    text = str(caught.value)
    assert f"cannot use {long_path[:77] + '...'!r} as a robot (File name too long)" in text
    assert "give a robot name (" in text and "ur5" in text and long_path not in text
