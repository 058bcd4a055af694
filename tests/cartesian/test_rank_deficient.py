"""A rank-deficient arm (issue 26): Stretch RE2-style, 8 joints whose full tool pose has rank 5
(tests/urdf/rank_deficient_arm.urdf: a lift, four telescoping segments along one axis, a wrist).

A line the arm can follow is ``ok`` with its true speeds (the minimum-norm rates J⁺ẋ of the 5
directions it has: each segment a quarter of the arm's speed), even at 99 % of its limits; a line
in a direction it cannot move the tool in is refused because of the rank (not as a speed or a
joint needing kilometres), and the remedy it prints (position_only=True) works.

Independent answers: the Jacobian's columns (the segments' common axis, the lift's), finite
differences of FK along the plan, numpy's SVD. Tolerances as stated at each assertion.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import TESTS

import cartesian
import kinplan
from cartesian.tracker import truncated_pinv
from kinplan.model.sources import example_robot_data_dir

ARM = TESTS / "urdf" / "rank_deficient_arm.urdf"
#: lift 0.6 m, each segment 5 cm out, wrist yaw, pitch, roll (rad)
Q0 = np.array([0.6, 0.05, 0.05, 0.05, 0.05, 0.3, -0.4, 0.2])
SEGMENTS = slice(1, 5)
#: follow's default tool position tolerance [m]
TOLERANCE = 1e-7


@pytest.fixture(scope="module")
def arm() -> kinplan.Robot:
    return kinplan.load_robot(ARM)


def held_line(arm: kinplan.Robot, direction, length: float = 0.03) -> cartesian.Line:
    """A line from the tool at Q0, ``length`` [m] along ``direction``, orientation held."""
    pose = arm.fk(Q0)
    u = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    return cartesian.Line(pose, pin.SE3(pose.rotation, pose.translation + length * u))


def axes(arm: kinplan.Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(the segments' common axis, the lift's axis, the tool direction the arm cannot move in
    without turning), unit vectors [m] in the world at Q0, from the Jacobian's columns."""
    J = arm.jacobian(Q0)
    segment = J[:3, 1] / np.linalg.norm(J[:3, 1])
    lift = J[:3, 0] / np.linalg.norm(J[:3, 0])
    sideways = np.cross(segment, lift)
    return segment, lift, sideways / np.linalg.norm(sideways)


def test_the_arm_has_rank_5_of_6(arm):
    assert arm.nq == 8 and arm.task_rank(False) == 5 and arm.task_rank(True) == 3
    J = arm.jacobian(Q0)
    # the four segments are one axis (to the URDF's 1e-16 rad), with no rotation
    for k in range(2, 5):
        np.testing.assert_allclose(J[:, k], J[:, 1], atol=1e-15)
    np.testing.assert_allclose(J[3:, 1], 0.0, atol=1e-15)
    singular = np.linalg.svd(J, compute_uv=False)
    assert singular[4] > 0.5 and singular[5] < 1e-15 * singular[0]
    # the arm's axis is the base's -x to 5.2e-6 rad (1.5708 for π/2 twice, as in Stretch's
    # URDF: √2 · 3.67e-6)
    segment, _, _ = axes(arm)
    tilt = np.linalg.norm(np.cross(segment, [-1.0, 0.0, 0.0]))
    assert tilt == pytest.approx(np.sqrt(2) * (1.5708 - np.pi / 2), rel=1e-3)


@pytest.mark.parametrize(
    "weights", [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0)], ids=["arm", "lift", "both"]
)
def test_line_the_arm_can_follow_is_ok_at_its_true_speeds(arm, weights):
    """A 3 cm line along the arm, the lift or both, timed (duration scaled) so that its peak
    joint speed is 99 % of the limit (±0.2 %): ok, with the rates the path needs (each segment a
    quarter of the arm's share, the lift its share: FK along the plan); 3 % faster
    than the limits: a velocity_limit of about 1.02× (the grid's phase: ±0.2 %)."""
    segment, lift, _ = axes(arm)
    direction = weights[0] * segment + weights[1] * lift
    line = held_line(arm, direction)
    first = cartesian.follow(arm, line, duration=1.0, q_seed=Q0)
    assert first.ok
    # a trapezoid of duration T is the same motion time-scaled: speeds scale as 1/T
    duration = first.peak_speed_ratio / 0.99
    plan = cartesian.follow(arm, line, duration=duration, q_seed=Q0)
    assert plan.ok, plan.events[0].message if plan.events else plan.status
    assert plan.fraction == 1.0 and plan.max_deviation <= TOLERANCE
    # the grid samples the profile at other phases once time-scaled: 0.99 to within 0.2 %
    assert plan.peak_speed_ratio == pytest.approx(0.99, abs=2e-3)
    assert (np.abs(plan.qd) / arm.velocity_limit).max() <= plan.peak_speed_ratio
    # true motion: each segment moves a quarter of the tool's travel along the arm, the lift
    # its travel along the lift (FK of the plan's q, an independent reading of the motion)
    tool = arm.tool_positions(plan.q) - arm.fk(Q0).translation
    basis = np.array([segment, lift])  # orthogonal to 5e-6 rad
    along_arm, along_lift = (tool @ np.linalg.pinv(basis)).T
    np.testing.assert_allclose(tool, np.column_stack([along_arm, along_lift]) @ basis, atol=1e-9)
    moved = plan.q - Q0
    np.testing.assert_allclose(moved[:, SEGMENTS], np.outer(along_arm / 4, np.ones(4)), atol=1e-9)
    np.testing.assert_allclose(moved[:, 0], along_lift, atol=1e-9)
    # and the rates are those of that motion: the trapezoid rule integrates them into q up to
    # its own error, at most Δq̈·h²/8 where the profile's acceleration jumps by Δq̈ ≤ 2 max|q̈|
    steps = np.diff(plan.t)[:, None]
    bound = np.abs(plan.qdd).max() * (steps.max() ** 2) / 4
    assert bound < 1e-4
    np.testing.assert_allclose(np.diff(plan.q, axis=0), 0.5 * steps * (plan.qd[1:] + plan.qd[:-1]),
                               atol=bound)  # fmt: skip
    np.testing.assert_allclose(plan.qd[:, 5:], 0.0, atol=1e-9)  # the wrist stays still
    faster = cartesian.follow(arm, line, duration=duration * 0.99 / 1.02, q_seed=Q0)
    assert faster.status == "velocity_limit"
    binding = "joint_lift" if weights[1] else "joint_arm_l3"
    assert faster.events[0].joint == binding
    needed = float(faster.events[0].message.split("needs up to ")[1].split("×")[0])
    assert 1.0 < needed <= 1.025


def test_line_the_arm_cannot_follow_is_refused_for_its_rank(arm):
    _, _, sideways = axes(arm)
    line = held_line(arm, sideways)
    plan = cartesian.follow(arm, line, duration=1.0, q_seed=Q0)
    assert plan.status == "unreachable" and plan.fraction < 0.05
    (event,) = plan.events
    message = event.message
    assert "the 8 joints of rank_deficient_arm move its tool pose in only 5 independent " in message
    assert "(rank 5 of the 6-D task), and the path leaves them" in message
    assert "velocity" not in message and "limit" not in message
    # the direction it names is the one the path asks for (sideways, with no rotation)
    listed = message.split("move along (")[1].split(")")[0].split(", ")
    named = {axis: float(value) for axis, value in (item.split() for item in listed)}
    direction = np.array([named[a] for a in ("x", "y", "z")])
    assert abs(direction @ sideways) == pytest.approx(np.linalg.norm(direction), abs=2e-3)
    assert "position_only=True" in event.remedy
    # the remedy, applied as printed: the tool position alone can move sideways (the wrist
    # turns), within every limit
    followed = cartesian.follow(arm, line, duration=1.0, q_seed=Q0, position_only=True)
    assert followed.ok and followed.max_deviation <= TOLERANCE
    assert followed.peak_speed_ratio < 1.0
    # the geometric pre-check says the same
    check = cartesian.check_reachability(arm, line, q_seed=Q0)
    assert check.events[0].kind == "unreachable" and "rank 5 of the 6-D task" in (
        check.events[0].message
    )


def test_line_off_the_arm_axis_by_its_rounding_is_refused_for_its_rank(arm):
    """A 10 cm line along the base's -x, which the arm's axis misses by 5.2e-6 rad: the tool
    drifts off it by 5.2e-6 m per metre, and leaves the 1e-7 m tolerance 2-3 cm along it. That
    is said as the rank (the arm cannot move the tool along the difference), not as a speed
    or a branch flip; along the arm's own axis the same line is ok."""
    segment, _, _ = axes(arm)
    plan = cartesian.follow(arm, held_line(arm, [-1.0, 0.0, 0.0], 0.1), speed=0.1, q_seed=Q0)
    assert plan.status == "unreachable"
    assert "rank 5 of the 6-D task" in plan.events[0].message
    assert "beyond what its joints can do (tolerances 1e-07 m, 1e-07 rad)" in (
        plan.events[0].message
    )
    # where the drift (5.2e-7 m per 10 cm) passes the tolerance; the wrist's 1e-7 rad of
    # orientation tolerance buys a little more
    drift = np.linalg.norm(np.cross(segment, [-1.0, 0.0, 0.0])) * 0.1  # [m] over the line
    assert TOLERANCE <= plan.events[0].s * drift <= 2 * TOLERANCE
    along = cartesian.follow(arm, held_line(arm, segment, 0.1), speed=0.1, q_seed=Q0)
    assert along.ok


def test_position_task_of_rank_1_is_refused_for_its_rank():
    """example-robot-data's double pendulum: its only tool frame, link2, lies on joint2's axis,
    so the tool moves on a circle (rank 1 of the 2 position rows it uses); a straight line is
    refused for that reason, in metres only (a position task)."""
    robots = example_robot_data_dir() / "example-robot-data" / "robots"
    limits = {j: {"lower": -3.14, "upper": 3.14, "velocity": 5.0} for j in ("joint1", "joint2")}
    pendulum = kinplan.load_robot(
        robots / "double_pendulum_description/urdf/double_pendulum.urdf", limits=limits
    )
    assert pendulum.task_rank(True) == 1 and len(pendulum.task_rows(True)) == 2
    q0 = np.array([0.3, 0.4])
    start = pendulum.fk(q0).translation
    plan = cartesian.follow(pendulum, cartesian.Line(start, start + [0.0, 0.02, 0.0]),
                            duration=1.0, q_seed=q0)  # fmt: skip
    assert plan.status == "unreachable" and plan.fraction < 0.05
    message = plan.events[0].message
    assert "in only 1 independent direction (rank 1 of the 2-D task), and the path leaves it" in (
        message
    )
    assert "[m; unit vector]" in message and "rad" not in message
    assert "(tolerance 1e-07 m)" in message


def test_retimed_line_of_the_rank_deficient_arm_is_ok(arm):
    segment, lift, _ = axes(arm)
    line = held_line(arm, segment + lift)
    plan = cartesian.follow(arm, line, speed=0.15, q_seed=Q0, retime=True)
    assert plan.ok and plan.peak_speed_ratio <= 1.0 + 1e-9
    np.testing.assert_allclose(plan.qd[:, SEGMENTS], plan.qd[:, [1]] * np.ones(4), atol=1e-12)


def test_truncated_pinv_keeps_the_rank_directions_only():
    rng = np.random.default_rng(26)
    U = np.linalg.qr(rng.normal(size=(6, 6)))[0]
    V = np.linalg.qr(rng.normal(size=(8, 8)))[0]
    singular = np.array([3.0, 2.0, 1.5, 1.0, 0.5, 1e-9])  # the last: an axis parallel to 1e-9
    J = U[:, :6] @ np.diag(singular) @ V[:, :6].T
    pinv = truncated_pinv(J, 5)
    expected = V[:, :5] @ np.diag(1 / singular[:5]) @ U[:, :5].T
    np.testing.assert_allclose(pinv, expected, atol=1e-12)
    assert np.abs(pinv).max() < 10  # np.linalg.pinv keeps the 1e-9: entries near 1e9
    assert np.abs(np.linalg.pinv(J)).max() > 1e8
    # stacks, and full rank equals numpy's
    stack = rng.normal(size=(4, 6, 8))
    np.testing.assert_allclose(truncated_pinv(stack, 6), np.linalg.pinv(stack), atol=1e-12)
