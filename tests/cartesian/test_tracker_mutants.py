"""The follower's :class:`~cartesian.tracker.Tracker`: what the mutation survivors of
``cartesian/tracker.py`` showed untested, each checked against an independent answer.

- ``Tracker.rescue`` (the sample Newton cannot reach from its prediction): against the planar
  2R's two closed-form solutions, on an arm whose joint limits leave only one of them;
- the pseudo-inverse fallback of a structurally rank-deficient task: an arm with two coincident
  joint axes (a redundant turntable), whose minimum-norm rates split the motion equally;
- the rank floor of the singularity monitor: scale invariance (the same path on an arm ten
  times smaller is followed in the same joint motion);
- events at the first sample, the velocity and acceleration events' joint and text, and the
  start configuration's full pose.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import TESTS

import cartesian
import kinplan
from cartesian.tracker import Tracker
from kinplan.model.robot import planar_arm

#: Unit 2R whose first joint cannot go below −0.5 rad: of the two solutions of (1, 0), the
#: elbow-up one (θ1 = −π/3) is beyond that limit and only the elbow-down one is left.
LIMITED = {"lower": [-0.5, -np.pi], "upper": [np.pi, np.pi]}
ELBOW_UP_1_0 = np.array([-np.pi / 3, 2 * np.pi / 3])  # tool at (1, 0), θ1 beyond −0.5
ELBOW_DOWN_1_0 = np.array([np.pi / 3, -2 * np.pi / 3])


def two_r_solutions(x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """The unit 2R's elbow-up (θ2 > 0) and elbow-down solutions of (x, y), closed form."""
    t2 = np.arccos((x * x + y * y - 2.0) / 2.0)
    up = np.array([np.arctan2(y, x) - np.arctan2(np.sin(t2), 1.0 + np.cos(t2)), t2])
    down = np.array([np.arctan2(y, x) + np.arctan2(np.sin(t2), 1.0 + np.cos(t2)), -t2])
    return up, down


def tracker(robot, position_only: bool = True, jump_tolerance: float = 0.05) -> Tracker:
    return Tracker(robot, position_only, 1e-9, 1e-9, 0.0, 1.0, jump_tolerance)


# ---------------------------------------------------------------------------- rescue
def test_the_closed_form_solutions_used_below():
    arm = planar_arm([1.0, 1.0])
    for q in (ELBOW_UP_1_0, ELBOW_DOWN_1_0):
        np.testing.assert_allclose(arm.fk(q).translation, [1.0, 0.0, 0.0], atol=1e-12)
    up, down = two_r_solutions(1.0, 0.6)
    for q in (up, down):
        np.testing.assert_allclose(arm.fk(q).translation, [1.0, 0.6, 0.0], atol=1e-12)


def test_newton_stalls_at_the_stretched_arm_for_a_target_along_it():
    """The premise of the rescue tests: at the stretched 2R no joint moves the tool along the
    arm, so Newton from there cannot reach (1, 0) (the Jacobian's transpose maps the error to 0)."""
    arm = planar_arm([1.0, 1.0], **LIMITED)
    q, converged, error, *_ = tracker(arm).solve(np.zeros(2), np.array([1.0, 0, 0]), None, None, 60)
    assert not converged and error == pytest.approx(1.0)


def test_rescue_reports_a_target_reachable_only_on_another_branch():
    """The previous sample on the elbow-up branch at (1, 0.6); the next target (1, 0) is, on that
    branch, beyond joint1's lower limit: the full solver finds only the elbow-down solution, and
    the event is a jump at that sample naming the joint that would move most (joint2, from the
    elbow-up to the elbow-down angle), with the jump tolerance as its limit."""
    arm = planar_arm([1.0, 1.0], **LIMITED)
    assert ELBOW_UP_1_0[0] < arm.lower[0] and arm.lower[0] <= ELBOW_DOWN_1_0[0]
    q_prev, _ = two_r_solutions(1.0, 0.6)
    assert np.all((arm.lower <= q_prev) & (q_prev <= arm.upper))
    target = np.array([1.0, 0.0, 0.0])
    event = tracker(arm, jump_tolerance=0.07).rescue(
        7, 0.35, 0.25, np.zeros(2), q_prev, target, None
    )
    assert isinstance(event, cartesian.Event), event
    jumps = ELBOW_DOWN_1_0 - q_prev
    j = int(np.argmax(np.abs(jumps)))
    assert j == 1 and abs(jumps[j]) > 3.0
    assert event.kind == "jump" and (event.index, event.t, event.s) == (7, 0.35, 0.25)
    assert event.joint == "joint2" == arm.joint_names[j]
    assert event.value == pytest.approx(jumps[j], abs=1e-9)
    assert event.limit == 0.07
    np.testing.assert_array_equal(event.position, target)
    assert "reachable only on another branch" in event.message
    assert f"from {q_prev[j]:.4f} to {ELBOW_DOWN_1_0[j]:.4f} rad" in event.message
    assert "(1.0000, 0.0000, 0.0000) m" in event.message
    assert "q_seed" in event.remedy and "split the path" in event.remedy


def test_rescue_returns_the_full_solvers_answer_on_the_same_branch():
    """From a previous sample near the elbow-down solution (within the jump tolerance), or with
    no previous sample, the rescue returns the full solver's configuration: the closed form's."""
    arm = planar_arm([1.0, 1.0], **LIMITED)
    target = np.array([1.0, 0.0, 0.0])
    follower = tracker(arm)
    q_prev = ELBOW_DOWN_1_0 + [0.03, -0.02]
    q = follower.rescue(3, 0.1, 0.2, np.zeros(2), q_prev, target, None)
    assert isinstance(q, np.ndarray)
    np.testing.assert_allclose(q, ELBOW_DOWN_1_0, atol=1e-7)
    first = follower.rescue(0, 0.0, 0.0, np.zeros(2), None, target, None)
    assert isinstance(first, np.ndarray)
    np.testing.assert_allclose(first, ELBOW_DOWN_1_0, atol=1e-7)


def test_rescue_of_a_pose_checks_the_orientation_too(planar_2r):
    """The 2R's full task (x, y and the rotation about z): a pose whose rotation the elbow-down
    solution has is found although the previous sample is nearer the elbow-up one; a pose tilted
    about x is out of reach (within the reach, but no configuration has its rotation), and the
    event says how far the closest pose is."""
    follower = tracker(planar_2r, position_only=False, jump_tolerance=0.2)
    target = np.array([1.0, 0.0, 0.0])
    down = pin.utils.rotate("z", float(ELBOW_DOWN_1_0.sum()))
    q = follower.rescue(2, 0.1, 0.1, np.zeros(2), ELBOW_DOWN_1_0 + 0.1, target, down)
    assert isinstance(q, np.ndarray)
    np.testing.assert_allclose(q, ELBOW_DOWN_1_0, atol=1e-7)
    tilted = pin.utils.rotate("x", np.pi / 2)
    event = follower.rescue(2, 0.1, 0.1, np.zeros(2), ELBOW_DOWN_1_0, target, tilted)
    assert isinstance(event, cartesian.Event)
    assert event.kind == "unreachable" and (event.index, event.t, event.s) == (2, 0.1, 0.1)
    assert "out of reach" in event.message and "within the arm's reach" in event.message
    assert "rad away" in event.message  # the rotation error of the closest pose is stated
    assert event.value > 0.1  # the closest pose's position error


def test_start_reaches_the_full_pose_on_the_seeds_side(planar_2r):
    """The first configuration solves the pose, rotation included: from a seed nearer the
    elbow-up solution, the pose with the elbow-down rotation gives the elbow-down solution."""
    follower = tracker(planar_2r, position_only=False)
    down = pin.utils.rotate("z", float(ELBOW_DOWN_1_0.sum()))
    q = follower.start(np.array([1.0, 0.0, 0.0]), down, ELBOW_UP_1_0 + 0.05)
    np.testing.assert_allclose(q, ELBOW_DOWN_1_0, atol=1e-7)
    position_only = tracker(planar_2r).start(np.array([1.0, 0.0, 0.0]), None, ELBOW_UP_1_0 + 0.05)
    np.testing.assert_allclose(position_only, ELBOW_UP_1_0, atol=1e-7)


# ---------------------------------------------------------------------------- first sample
@pytest.mark.parametrize("seed", [[0.0, 1.5], [2.7, 1.8]], ids=["near", "far"])
def test_a_path_starting_beyond_a_joint_limit_is_a_joint_limit_event_at_sample_0(seed):
    """(1, 0) with joint1 ≥ −0.5 and joint2 ≥ 0.5: both solutions of the unit 2R (θ2 = ±2π/3,
    each up to turns of 2π) are beyond a limit, so the full IK fails; the first sample is still
    reachable and is a joint_limit event at index 0, t = 0 (not "unreachable"), naming a joint
    of the elbow-up solution with its value and the limit it is beyond. From the far seed
    Newton needs more than the short pass's 12 iterations (the longer search finds it)."""
    arm = planar_arm([1.0, 1.0], lower=[-0.5, 0.5], upper=[np.pi, np.pi])
    line = cartesian.Line([1.0, 0.0, 0.0], [1.0, 0.4, 0.0])
    plan = cartesian.follow(arm, line, duration=1.0, q_seed=seed)
    assert plan.status == "joint_limit", plan
    event = plan.events[0]
    assert (event.index, event.t, event.s) == (0, 0.0, 0.0) and len(plan.q) == 0
    j = arm.joint_names.index(event.joint)
    turns = (event.value - ELBOW_UP_1_0[j]) / (2 * np.pi)
    assert turns == pytest.approx(round(turns), abs=1e-6)  # the elbow-up angle, up to turns
    upper = event.value > arm.upper[j]
    assert event.limit == (arm.upper[j] if upper else arm.lower[j])
    assert upper or event.value < arm.lower[j]
    assert f"{'upper' if upper else 'lower'} limit {event.limit:.4f} rad" in event.message
    np.testing.assert_array_equal(event.position, [1.0, 0.0, 0.0])


# ---------------------------------------------------------------------------- rank-deficient
TWIN_AXIS_URDF = """<?xml version="1.0"?>
<robot name="twin_axis">
  <link name="base"/><link name="turntable"/><link name="arm"/><link name="tool"/>
  <joint name="joint1" type="revolute">
    <parent link="base"/><child link="turntable"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.0" upper="3.0" effort="10" velocity="2.0"/>
  </joint>
  <joint name="joint2" type="revolute">
    <parent link="turntable"/><child link="arm"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.0" upper="3.0" effort="10" velocity="2.0"/>
  </joint>
  <joint name="tool_mount" type="fixed">
    <parent link="arm"/><child link="tool"/><origin xyz="0.5 0 0"/>
  </joint>
</robot>
"""


@pytest.fixture(scope="module")
def twin_axis(tmp_path_factory):
    """Two revolute joints about the same axis, tool 0.5 m out: the tool moves on a circle, its
    position task has 2 rows (x, y) but rank 1."""
    path = tmp_path_factory.mktemp("twin") / "twin_axis.urdf"
    path.write_text(TWIN_AXIS_URDF)
    return kinplan.load_robot(path)


def test_a_rank_deficient_task_splits_the_motion_equally(twin_axis):
    """An arc of the tool's circle: followed exactly; the minimum-norm rates of two coincident
    axes are equal (q̇1 = q̇2 = ω/2 for the tool's angular rate ω), q̈ is their time derivative,
    and the manipulability is the one singular value, √2 × 0.5 m."""
    assert twin_axis.task_rank(True) == 1 and len(twin_axis.task_rows(True)) == 2
    arc = cartesian.Arc([0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [-0.5, 0.0, 0.0])
    plan = cartesian.follow(twin_axis, arc, duration=2.0, profile="quintic", q_seed=[0.1, -0.1])
    assert plan.ok, plan
    angle = np.unwrap(np.arctan2(plan.tool_positions[:, 1], plan.tool_positions[:, 0]))
    np.testing.assert_allclose(plan.q.sum(axis=1), angle, atol=1e-7)
    omega = np.gradient(angle, plan.t)
    np.testing.assert_allclose(plan.qd[:, 0], plan.qd[:, 1], atol=1e-12)
    np.testing.assert_allclose(
        plan.qd.sum(axis=1)[1:-1], omega[1:-1], atol=2e-3 * np.abs(omega).max()
    )
    qdd_fd = np.gradient(plan.qd, plan.t, axis=0)
    np.testing.assert_allclose(plan.qdd[2:-2], qdd_fd[2:-2], atol=0.01 * np.abs(qdd_fd).max())
    np.testing.assert_allclose(plan.manipulability, np.sqrt(2) * 0.5, rtol=1e-9)
    assert plan.max_deviation < 1e-6


# ---------------------------------------------------------------------------- rank floor
def test_the_rank_floor_scales_with_the_arm(planar_2r):
    """With the singularity monitor off (threshold 0), a radial line to 6 µm short of the full
    stretch (sin θ2 ≈ 0.005) is followed; the same line on the same arm ten times smaller (its
    manipulability a hundred times smaller) is followed in the same joint motion (the position
    tolerance scaled alike)."""
    small = planar_arm([0.1, 0.1])
    reach = 2.0 - 6.25e-6
    plans = [
        cartesian.follow(arm, cartesian.Line([1.5 * k, 0, 0], [reach * k, 0, 0]), duration=1.0,
                         q_seed=[-0.5, 1.0], singular_threshold=0.0, velocity_scale=1e6,
                         tolerance=1e-10 * k)
        for arm, k in ((planar_2r, 1.0), (small, 0.1))
    ]  # fmt: skip
    for plan in plans:
        assert plan.ok, plan
    np.testing.assert_allclose(plans[1].q, plans[0].q, atol=1e-5)
    assert plans[1].min_manipulability == pytest.approx(
        0.01 * plans[0].min_manipulability, rel=1e-4
    )
    assert np.sin(plans[0].q[-1, 1]) == pytest.approx(0.005, rel=0.01)


# ------------------------------------------------------------------ velocity and acceleration
def test_a_scaled_speed_limit_is_named_in_the_velocity_event(planar_2r):
    line = cartesian.Line([1.2, 0.3, 0.0], [0.3, 1.2, 0.0])
    rated = cartesian.follow(planar_2r, line, duration=0.1, q_seed=[0.3, 1.2])
    assert rated.status == "velocity_limit" and "of its rating" not in rated.events[0].message
    assert rated.events[0].limit == pytest.approx(planar_2r.velocity_limit[0])
    scaled = cartesian.follow(planar_2r, line, duration=0.2, q_seed=[0.3, 1.2], velocity_scale=0.5)
    assert scaled.status == "velocity_limit"
    event = scaled.events[0]
    j = planar_2r.joint_names.index(event.joint)
    assert event.limit == pytest.approx(0.5 * planar_2r.velocity_limit[j])
    assert f"{event.limit:.4g} rad/s (0.5 of its rating)" in event.message


def test_acceleration_event_names_the_joint_furthest_over_its_limit(planar_2r):
    """Joint2 limited far more tightly than joint1: the event names joint2 (the ratio |q̈|/limit
    is largest there at the first sample over), with its q̈ from the unlimited plan."""
    line = cartesian.Line([1.2, 0.3, 0.0], [0.3, 1.2, 0.0])
    free = cartesian.follow(planar_2r, line, duration=1.0, profile="quintic", q_seed=[0.3, 1.2])
    limit = np.array([1e3, 1.0])
    plan = cartesian.follow(
        planar_2r, line, duration=1.0, profile="quintic", q_seed=[0.3, 1.2], max_acceleration=limit
    )
    assert plan.status == "acceleration_limit"
    event = plan.events[0]
    over = np.abs(free.qdd) / limit
    k = int(np.flatnonzero((over > 1.0 + 1e-9).any(axis=1))[0])
    assert event.index == k and event.joint == "joint2" and event.limit == 1.0
    assert event.value == pytest.approx(free.qdd[k, 1], rel=1e-6)


# ---------------------------------------------------------------------------- mimic joints
def test_joint_accelerations_of_an_arm_with_a_mimic_joint():
    """An arm whose joint_3 drives a coupled joint (a mimic: its J̇ comes from Pinocchio, sample
    by sample, at the samples' configurations): q̈ is still the time derivative of q̇."""

    arm = kinplan.load_robot(TESTS / "urdf" / "mimic_arm.urdf")
    assert arm.mimic_joints
    q0 = arm.neutral() + 0.3
    p0 = arm.fk(q0).translation
    line = cartesian.Line(p0, p0 + [0.02, 0.0, -0.03])
    plan = cartesian.follow(arm, line, duration=1.0, q_seed=q0, position_only=True,
                            profile="quintic")  # fmt: skip
    assert plan.ok, plan
    qdd_fd = np.gradient(plan.qd, plan.t, axis=0)
    np.testing.assert_allclose(plan.qdd[2:-2], qdd_fd[2:-2], atol=0.01 * np.abs(qdd_fd).max())
