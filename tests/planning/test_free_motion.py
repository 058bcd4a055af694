"""kinplan.free_motion: collision-free timed joint motions, re-checked independently.

Every returned motion is re-checked with Pinocchio and coal called directly (``independent.py``:
the URDF read again, trimesh's convex hulls, the obstacles rebuilt from their sizes) at joint
steps of at most 0.5°; the timing is checked against the limits on dense samples; statuses,
messages and bad inputs are checked one by one.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from free_motion_cells import colliding_pairs, panda_cell, ur5_cell
from independent import Recheck, obstacles_of

import kinplan
from kinplan import InputError, KinplanError
from kinplan.planning import STATUSES, MotionPlan, free_motion
from kinplan.planning.planner import motion_limits
from kinplan.trajectory.motion import SampledMotion, as_sampled_motion

JOINT_EXACT = 1e-12  # [rad]: where a motion must start and end
LIMIT_SLACK = 1e-6  # relative slack on the velocity and acceleration limits (TOTG: 1e-4 below)


@pytest.fixture(scope="module")
def ur5():
    cell = ur5_cell()
    return cell, Recheck(cell.robot, obstacles_of(cell), str(cell.srdf_path))


@pytest.fixture(scope="module")
def panda():
    cell = panda_cell()
    return cell, Recheck(cell.robot, obstacles_of(cell), str(cell.srdf_path))


def assert_sound(plan: MotionPlan, start, goal, recheck: Recheck, clearance: float = 0.0):
    """ok, from start to goal exactly, within the limits, free when re-checked independently."""
    assert plan.ok, plan.summary()
    assert plan.status == "ok" and plan.events == ()
    robot = plan.robot
    q0, _, _ = plan.trajectory.sample(0.0)
    q1, qd1, _ = plan.trajectory.sample(plan.trajectory.duration)
    np.testing.assert_allclose(q0, start, atol=JOINT_EXACT, rtol=0)
    np.testing.assert_allclose(q1, goal, atol=JOINT_EXACT, rtol=0)
    np.testing.assert_allclose(qd1, 0.0, atol=1e-9)
    np.testing.assert_allclose(plan.waypoints[0], start, atol=0, rtol=0)
    np.testing.assert_allclose(plan.waypoints[-1], goal, atol=JOINT_EXACT, rtol=0)
    velocity, acceleration = motion_limits(robot, None, None)
    t = np.linspace(0.0, plan.trajectory.duration, 4001)
    q, qd, qdd = plan.trajectory.sample(t)
    assert np.all(np.abs(qd) <= velocity * (1 + LIMIT_SLACK)), np.max(np.abs(qd) / velocity)
    assert np.all(np.abs(qdd) <= acceleration * (1 + LIMIT_SLACK)), np.max(
        np.abs(qdd) / acceleration
    )
    assert np.all(q >= robot.lower - 1e-9) and np.all(q <= robot.upper + 1e-9)
    hits = recheck.motion(plan.trajectory, clearance)
    assert hits == [], f"{len(hits)} colliding samples, the first {hits[:1]}"
    assert plan.min_clearance >= clearance - 1e-6


# ------------------------------------------------------------------------------ solved motions
def test_ur5_pairs_whose_straight_move_collides_are_solved_and_free(ur5):
    cell, recheck = ur5
    pairs = colliding_pairs(cell, 4, seed=11)
    for start, goal in pairs:  # the independent check sees the straight move collide too
        straight = kinplan.trajectory.time_optimal(np.array([start, goal]), 1.0, 2.0)
        assert recheck.motion(straight) != []
    for k, (start, goal) in enumerate(pairs):
        plan = free_motion(cell.robot, start, goal, cell, seed=k)
        assert_sound(plan, start, goal, recheck)
        assert len(plan.waypoints) >= 3  # it had to go around


def test_panda_pairs_are_solved_and_free(panda):
    cell, recheck = panda
    for k, (start, goal) in enumerate(colliding_pairs(cell, 2, seed=12)):
        plan = free_motion(cell.robot, start, goal, cell, seed=k, time_limit=3.0)
        assert_sound(plan, start, goal, recheck)


def test_clearance_is_kept_all_along(ur5):
    cell, recheck = ur5
    # (the shoulder stays 24 mm above the table whatever the joints: 15 mm can be kept)
    (start, goal), *_ = colliding_pairs(cell, 1, seed=13, clearance=0.015)
    plan = free_motion(cell.robot, start, goal, cell, clearance=0.015, time_limit=3.0)
    assert_sound(plan, start, goal, recheck, clearance=0.015 - 1e-6)
    assert plan.clearance == 0.015


def test_a_pose_goal_ends_on_the_pose(ur5):
    cell, recheck = ur5
    robot = cell.robot
    start = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    target = pin.SE3(pin.rpy.rpyToMatrix(np.pi, 0.0, 0.0), np.array([0.5, -0.35, 0.4]))
    plan = free_motion(robot, start, target, cell, time_limit=3.0)  # between the shelf boards
    end = plan.trajectory.sample(plan.trajectory.duration)[0]
    assert_sound(plan, start, end, recheck)
    np.testing.assert_allclose(plan.goal, end, atol=JOINT_EXACT)
    pose = robot.fk(end)
    np.testing.assert_allclose(pose.translation, target.translation, atol=1e-6)
    assert np.linalg.norm(pin.log3(pose.rotation.T @ target.rotation)) < 1e-6


def test_the_same_seed_gives_the_same_motion_and_another_seed_may_not(ur5):
    cell, _ = ur5
    (start, goal), *_ = colliding_pairs(cell, 1, seed=14)
    first = free_motion(cell.robot, start, goal, cell, seed=3)
    again = free_motion(cell.robot, start, goal, cell, seed=3)
    assert first.ok and again.ok
    np.testing.assert_array_equal(first.waypoints, again.waypoints)
    np.testing.assert_array_equal(first.q, again.q)
    others = [free_motion(cell.robot, start, goal, cell, seed=s).waypoints for s in (4, 5)]
    assert any(w.shape != first.waypoints.shape or np.any(w != first.waypoints) for w in others)


def test_a_free_straight_move_stays_straight(ur5):
    cell, recheck = ur5
    start = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    goal = np.radians([10.0, -100.0, 90.0, -80.0, -90.0, 30.0])
    assert cell.check_motion(np.array([start, goal])).ok
    plan = free_motion(cell.robot, start, goal, cell)
    assert_sound(plan, start, goal, recheck)
    assert len(plan.waypoints) == 2


# ------------------------------------------------------------------------------ the plan object
def test_a_plan_is_a_sampled_motion_on_the_callers_grid(ur5):
    cell, _ = ur5
    (start, goal), *_ = colliding_pairs(cell, 1, seed=15)
    plan = free_motion(cell.robot, start, goal, cell)
    assert isinstance(plan, SampledMotion) and as_sampled_motion(plan) is plan
    assert plan.kind == "joint" and plan.status in STATUSES
    assert plan.t[0] == 0.0 and plan.t[-1] == plan.trajectory.duration
    assert np.all(np.diff(plan.t)[:-1] == pytest.approx(plan.dt, abs=1e-12))
    q, qd, qdd = plan.trajectory.sample(plan.t)
    np.testing.assert_array_equal(plan.q, q)
    np.testing.assert_array_equal(plan.qd, qd)
    np.testing.assert_array_equal(plan.qdd, qdd)
    np.testing.assert_allclose(plan.tool_positions, cell.robot.tool_positions(q), atol=1e-12)
    k = len(plan.waypoints)
    assert plan.waypoints.shape == (k, cell.robot.nq) and plan.waypoints.times.shape == (k,)
    assert np.all(np.diff(plan.waypoints.times) > 0)
    np.testing.assert_array_equal(plan.waypoints.positions, np.asarray(plan.waypoints))
    assert 0.0 < plan.planning_time < 10.0
    assert math.isfinite(plan.min_clearance) and plan.min_clearance >= 0.0
    assert f"{k} waypoints" in plan.summary()


def test_the_viewer_takes_a_plan(ur5, tmp_path):
    cell, _ = ur5
    (start, goal), *_ = colliding_pairs(cell, 1, seed=16)
    plan = free_motion(cell.robot, start, goal, cell)
    path = tmp_path / "transit.html"
    kinplan.viewer.save_html(cell.robot, plan, path)
    assert path.stat().st_size > 10_000


# ------------------------------------------------------------------------------ every status
def test_start_in_collision_names_the_pair_and_depth(ur5):
    cell, _ = ur5
    start = np.radians([0.0, 45.0, 0.0, 0.0, 0.0, 0.0])  # the upper arm down through the table
    goal = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    plan = free_motion(cell.robot, start, goal, cell)
    assert plan.status == "start_in_collision" and not plan.ok
    (event,) = plan.events
    deepest = cell.collisions(start)[0]
    assert event.kind == "start_in_collision" and event.bodies == deepest.bodies
    assert event.distance == pytest.approx(deepest.distance, abs=1e-12)
    assert "table" in event.message and "mm" in event.message and event.remedy
    assert plan.trajectory.duration == 0.0 and len(plan.t) == 1
    np.testing.assert_array_equal(plan.q[0], start)


def test_goal_in_collision_names_the_pair(ur5):
    cell, _ = ur5
    start = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    goal = np.radians([0.0, 45.0, 0.0, 0.0, 0.0, 0.0])
    plan = free_motion(cell.robot, start, goal, cell)
    assert plan.status == "goal_in_collision"
    assert plan.events[0].bodies == cell.collisions(goal)[0].bodies
    assert "the goal is in collision" in plan.events[0].message


def test_a_pose_inside_an_obstacle_is_a_goal_in_collision(ur5):
    cell, _ = ur5
    start = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    inside = pin.SE3(pin.rpy.rpyToMatrix(np.pi, 0.0, 0.0), np.array([0.4, 0.35, 0.5]))  # pillar
    plan = free_motion(cell.robot, start, inside, cell)
    assert plan.status == "goal_in_collision"
    assert "every IK solution" in plan.events[0].message


def test_an_unreachable_pose_says_how_far(ur5):
    cell, _ = ur5
    start = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    plan = free_motion(cell.robot, start, pin.SE3(np.eye(3), np.array([3.0, 0.0, 0.5])), cell)
    assert plan.status == "unreachable"
    assert "reaches" in plan.events[0].message and "3.0000, 0.0000, 0.5000" in str(plan.events[0])


def test_no_path_within_the_time_limit_says_so(ur5):
    cell, _ = ur5
    (start, goal), *_ = colliding_pairs(cell, 1, seed=17)
    plan = free_motion(cell.robot, start, goal, cell, time_limit=1e-6)
    assert plan.status == "no_path"
    assert "time limit" in plan.events[0].message and "time_limit" in plan.events[0].remedy


def test_a_goal_behind_the_table_needs_any_turn(ur5):
    cell, recheck = ur5
    start = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    goal = start + np.array([0.0, 2.0 * np.pi, 0.0, 0.0, 0.0, 0.0])  # the same pose, wound
    plan = free_motion(cell.robot, start, goal, cell, time_limit=0.3)
    assert plan.status == "no_path" and "any_turn=True" in plan.events[0].remedy
    wound = free_motion(cell.robot, start, goal, cell, any_turn=True)
    assert wound.ok and len(wound.waypoints) == 1 + 1
    np.testing.assert_allclose(wound.goal, start, atol=1e-9)  # the same pose, unwound
    assert_sound(wound, start, start, recheck)


# ------------------------------------------------------------------------------ bad inputs
@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"start": np.zeros(5)}, "start must hold 6 joint values"),
        ({"start": [np.nan] * 6}, "start must be finite"),
        ({"start": np.full(6, 7.0)}, "start is outside the joint limits"),
        ({"goal": np.full(6, -7.0)}, "goal is outside the joint limits"),
        ({"goal": "home"}, "goal must be a joint vector"),
        ({"goal": None}, "goal must be a joint vector"),
        ({"time_limit": 0.0}, "time_limit"),
        ({"time_limit": -1.0}, "time_limit"),
        ({"time_limit": float("nan")}, "time_limit"),
        ({"time_limit": "1"}, "time_limit"),
        ({"seed": 1.5}, "seed must be an integer"),
        ({"seed": -1}, "seed must be an integer"),
        ({"seed": True}, "seed must be an integer"),
        ({"clearance": -0.01}, "clearance"),
        ({"max_velocity": 0.0}, "max_velocity"),
        ({"max_acceleration": [1.0] * 5}, "max_acceleration"),
        ({"cell": "cell.yaml"}, "cell must be a kinplan.WorkCell"),
        ({"robot": "ur5"}, "robot must be a kinplan.Robot"),
        ({"blend": -0.1}, "blend"),
        ({"any_turn": 1}, "any_turn"),
    ],
)
def test_bad_inputs_raise_kinplan_errors(ur5, change, words):
    cell, _ = ur5
    args = {
        "robot": cell.robot,
        "start": np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0]),
        "goal": np.radians([90.0, -90.0, 90.0, -90.0, -90.0, 0.0]),
        "cell": cell,
    }
    args.update(change)
    positional = [args.pop(k) for k in ("robot", "start", "goal", "cell")]
    with pytest.raises(InputError, match=words) as raised:
        free_motion(*positional, **args)
    assert isinstance(raised.value, KinplanError)


def test_a_cell_of_another_robot_is_refused(ur5, panda):
    cell, _ = ur5
    other, _ = panda
    with pytest.raises(InputError, match="the cell is built around"):
        free_motion(cell.robot, np.zeros(6), np.zeros(6), other)


def test_the_exports_of_kinplan():
    assert kinplan.free_motion is free_motion and kinplan.MotionPlan is MotionPlan
    assert {"free_motion", "MotionPlan"} <= set(kinplan.__all__)
