"""Cartesian following: what the mutation survivors of ``cartesian/follow.py``,
``cartesian/tracker.py`` and ``cartesian/geometry.py`` showed untested, checked against
independent answers: the acceleration event against the q̈ of the unlimited plan (itself
d(q̇)/dt), a step too coarse for a continuous motion against a finely sampled plan of the same
law, the reachability pre-check against the planar 2R's closed form and its annulus, and the
arguments an error message must name."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

import cartesian
import kinplan
from cartesian.geometry import trace_between
from cartesian.tracker import SINGULAR_FRACTION, Tracker
from kinplan.errors import InputError
from kinplan.robot import planar_arm

#: Passing 2 cm beside the 2R's base axis in 2 s: joint1 swings round fast but continuously.
BESIDE_AXIS = ([0.5, 0.02, 0.0], [-0.5, 0.02, 0.0])
ELBOW_UP = [-1.3, 2.6]


def elbow_up_ik(x: float, y: float) -> np.ndarray:
    """The unit 2R's elbow-up (θ2 > 0) solution, closed form."""
    t2 = np.arccos((x * x + y * y - 2.0) / 2.0)
    return np.array([np.arctan2(y, x) - np.arctan2(np.sin(t2), 1.0 + np.cos(t2)), t2])


# ---------------------------------------------------------------------------- acceleration
def test_acceleration_event_names_the_first_sample_over_its_joint_limit(planar_2r):
    """A joint acceleration limit below the motion's: the event is at the first sample whose
    q̈ (of the unlimited plan, the derivative of its q̇) exceeds a limit, for the joint
    furthest over, with its signed q̈ and its limit; retiming is offered and passes."""
    line = cartesian.Line([1.2, 0.3, 0.0], [0.3, 1.2, 0.0])
    free = cartesian.follow(planar_2r, line, duration=1.0, profile="quintic", q_seed=[0.3, 1.2])
    assert free.ok
    qdd_fd = np.gradient(free.qd, free.t, axis=0)  # q̈ is the time derivative of q̇
    np.testing.assert_allclose(free.qdd[2:-2], qdd_fd[2:-2], atol=0.01 * np.abs(qdd_fd).max())
    limit = np.array([3.0, 5.0])
    plan = cartesian.follow(
        planar_2r, line, duration=1.0, profile="quintic", q_seed=[0.3, 1.2], max_acceleration=limit
    )
    assert plan.status == "acceleration_limit"
    event = plan.events[0]
    over = np.abs(free.qdd) / limit
    k = int(np.flatnonzero((over > 1.0 + 1e-9).any(axis=1))[0])
    j = int(np.argmax(over[k]))
    assert event.kind == "acceleration_limit" and event.index == k and len(plan.q) == k
    assert event.t == free.t[k] and event.s == free.s[k]
    assert event.joint == planar_2r.joint_names[j]
    assert event.value == pytest.approx(free.qdd[k, j], rel=1e-6)
    assert event.limit == limit[j]
    np.testing.assert_allclose(event.position, line.position(free.s[k : k + 1])[0], atol=1e-12)
    peak = over.max()
    assert f"{peak:.3g}×" in event.message and f"{np.sqrt(peak):.3g}" in event.remedy
    assert plan.retime_duration is not None and "retime=True" in event.remedy
    retimed = cartesian.follow(
        planar_2r,
        line,
        duration=1.0,
        profile="quintic",
        q_seed=[0.3, 1.2],
        max_acceleration=limit,
        retime=True,
    )
    assert retimed.ok and retimed.retimed
    assert retimed.duration == pytest.approx(plan.retime_duration)
    assert np.all(np.abs(retimed.qdd) <= limit * (1 + 1e-6))
    # one number limits every joint alike
    same = cartesian.follow(
        planar_2r, line, duration=1.0, profile="quintic", q_seed=[0.3, 1.2], max_acceleration=3.0
    )
    assert same.status == "acceleration_limit" and same.events[0].limit == 3.0


# ---------------------------------------------------------------------------- coarse steps
def fine_step(planar_2r, line, t0: float, t1: float) -> np.ndarray:
    """q(t1) − q(t0) of the same law sampled every millisecond (the continuous motion)."""
    fine = cartesian.follow(
        planar_2r, line, duration=2.0, dt=0.001, q_seed=ELBOW_UP, velocity_scale=1e9,
        singular_threshold=0.0,
    )  # fmt: skip
    assert fine.ok
    q_at = [np.array([np.interp(t, fine.t, fine.q[:, i]) for i in range(2)]) for t in (t0, t1)]
    return q_at[1] - q_at[0]


def test_a_step_too_coarse_for_a_continuous_swing_is_a_sampling_jump(planar_2r):
    line = cartesian.Line(*BESIDE_AXIS)
    plan = cartesian.follow(
        planar_2r, line, duration=2.0, dt=0.08, q_seed=ELBOW_UP, singular_threshold=0.0
    )
    assert plan.status == "jump", plan
    event = plan.events[0]
    k = event.index
    step = fine_step(planar_2r, line, event.t - 0.08, event.t)
    assert event.joint == "joint1" and event.limit == 0.05
    assert event.value == pytest.approx(step[0], abs=1e-4)  # the continuous solution's step
    assert "sampling is too coarse" in event.message and "a dt well below 0.08 s" in event.remedy
    assert len(plan.q) == k and np.all(plan.q[:, 1] > 0)


def test_a_coarse_step_faster_than_the_joint_allows_is_a_velocity_event(planar_2r):
    """The same coarse step with half the speed limits: its mean speed over the step exceeds
    the limit, so it is a velocity event at that sample, with the mean speed as its value."""
    line = cartesian.Line(*BESIDE_AXIS)
    plan = cartesian.follow(
        planar_2r, line, duration=2.0, dt=0.08, q_seed=ELBOW_UP, singular_threshold=0.0,
        velocity_scale=0.5,
    )  # fmt: skip
    assert plan.status == "velocity_limit", plan
    event = plan.events[0]
    limit = 0.5 * planar_2r.velocity_limit[0]
    step = fine_step(planar_2r, line, event.t - 0.08, event.t)
    assert event.joint == "joint1" and event.limit == pytest.approx(limit)
    assert event.value == pytest.approx(abs(step[0]) / 0.08, rel=1e-3)
    assert event.value > limit and len(plan.q) == event.index
    peak = max(plan.peak_speed_ratio, event.value / limit)
    assert f"{peak:.3g}×" in event.message or f"{event.value / limit:.3g}" in event.remedy


# ---------------------------------------------------------------------------- geometry
def planar_tracker(robot, jump_tolerance: float) -> Tracker:
    threshold = SINGULAR_FRACTION * robot.reference_manipulability(True)
    return Tracker(robot, True, 1e-9, 1e-9, threshold, 1.0, jump_tolerance)


def test_trace_between_follows_the_branch_it_starts_on(planar_2r):
    """From the elbow-down solution (not the one IK from the neutral seed gives), the finer
    trace ends on the elbow-down solution of the end point (the closed form's)."""
    line = cartesian.Line([1.2, 0.3, 0.0], [0.4, 1.1, 0.0])
    down = -elbow_up_ik(1.2, -0.3) * [1, 1]  # mirror of the elbow-up solution of (1.2, 0.3)
    np.testing.assert_allclose(planar_2r.fk(down).translation[:2], [1.2, 0.3], atol=1e-12)
    for jump_tolerance in (0.05, 0.01):
        q = trace_between(planar_tracker(planar_2r, jump_tolerance), line, 0.0, 1.0, down)
        assert isinstance(q, np.ndarray)
        np.testing.assert_allclose(q, -elbow_up_ik(0.4, -1.1), atol=1e-7)


def test_trace_between_cannot_start_from_a_configuration_off_the_path(planar_2r):
    line = cartesian.Line([1.2, 0.3, 0.0], [0.4, 1.1, 0.0])
    tracker = planar_tracker(planar_2r, 0.05)
    assert trace_between(tracker, line, 0.0, 1.0, np.array([2.0, -2.5])) is None


def test_reachability_stays_on_the_seeds_branch(planar_2r):
    line = cartesian.Line([1.2, 0.3, 0.0], [0.4, 1.1, 0.0])
    down = -elbow_up_ik(1.2, -0.3)
    result = cartesian.check_reachability(planar_2r, line, q_seed=down)
    assert result.ok and result.fraction == 1.0 and not result.events
    assert np.all(result.q[:, 1] < 0)
    for s, q in zip(result.s, result.q, strict=True):
        x, y = line.position(np.array([s]))[0][:2]
        np.testing.assert_allclose(q, -elbow_up_ik(x, -y), atol=1e-6)


def test_planar_annulus_boundaries(planar_2r):
    """A line from the stretched arm inward is reachable only singularly (its first point is on
    the outer circle, inside the annulus); a point 1 µm outside is unreachable, and the result
    says so (ok False)."""
    stretched = cartesian.check_reachability(planar_2r, cartesian.Line([2.0, 0, 0], [1.5, 0, 0]))
    assert stretched.status == "singular" and stretched.events[0].s == 0.0
    assert stretched.events[0].t == 0.0 and stretched.events[0].index == 0
    outside = cartesian.check_reachability(planar_2r, cartesian.Line([1.5, 0, 0], [2.000001, 0, 0]))
    assert outside.ok is False and outside.status == "unreachable"
    assert outside.events[0].s == 1.0 and "exceeds the reach" in outside.events[0].message
    np.testing.assert_allclose(outside.events[0].position, [2.000001, 0, 0])
    # an arm with a hole: a line starting exactly on the inner circle is reachable
    holed = planar_arm([1.0, 0.5])
    inner = cartesian.check_reachability(
        holed, cartesian.Line([0.5, 0, 0], [0.5, 0.8, 0]), q_seed=[0.0, 3.0], singular_threshold=0.0
    )
    assert inner.status != "unreachable", inner
    hole = cartesian.check_reachability(holed, cartesian.Line([0.49, 0, 0], [0.49, 0.8, 0]))
    assert hole.status == "unreachable" and "inside the hole" in hole.events[0].message


def test_ur5_reachability_position_only_and_held_orientation(ur5):
    q0 = np.radians([0, -100, 100, -90, -90, 0])
    start = ur5.fk(q0).translation
    line = cartesian.Line(start, start + [0.0, 0.1, 0.0])  # 3-vectors: orientation held
    held = cartesian.check_reachability(ur5, line, q_seed=q0)
    assert held.ok
    for q in held.q:
        np.testing.assert_allclose(ur5.fk(q).rotation, ur5.fk(q0).rotation, atol=1e-6)
    free = cartesian.check_reachability(ur5, line, q_seed=q0, position_only=True)
    assert free.ok
    # into the stretched arm: the default threshold is the position task's, as follow's
    far = cartesian.Line(start, start + 2.0 * (start - [0, 0, 0.089159]))
    stopped = cartesian.check_reachability(ur5, far, q_seed=q0, position_only=True)
    assert stopped.status in ("singular", "unreachable")
    if stopped.status == "singular":
        threshold = SINGULAR_FRACTION * ur5.reference_manipulability(True)
        assert stopped.events[0].limit == pytest.approx(threshold)


# ---------------------------------------------------------------------------- arguments
@pytest.mark.parametrize(
    ("key", "value", "words"),
    [
        ("dt", 0.0, r"dt must be > 0 \[s\]"),
        ("speed", -0.1, r"speed must be > 0 \[m/s\]"),
        ("acceleration", 0.0, r"acceleration must be > 0 \[m/s²\]"),
        ("velocity_scale", 0.0, r"velocity_scale must be > 0"),
        ("jump_tolerance", 0.0, r"jump_tolerance must be > 0 \[rad\]"),
        ("tolerance", 0.0, r"tolerance must be > 0 \[m\]"),
        ("rotation_tolerance", 0.0, r"rotation_tolerance must be > 0 \[rad\]"),
        ("clearance", -0.001, r"clearance must be ≥ 0"),
        ("max_acceleration", 0.0, r"max_acceleration must be > 0"),
        ("max_acceleration", [1.0, 2.0, 3.0], r"max_acceleration"),
        ("max_acceleration", [1.0, -2.0], r"max_acceleration must be > 0 for every joint"),
        ("singular_threshold", -1.0, r"singular_threshold must be ≥ 0"),
        ("cell", "a cell", r"cell must be a kinplan.WorkCell"),
    ],
)
def test_follow_names_the_bad_argument(planar_2r, key, value, words):
    line = cartesian.Line([1.2, 0.3, 0.0], [0.3, 1.2, 0.0])
    kwargs = {"duration": 1.0} if key != "speed" else {}
    with pytest.raises(InputError, match=words):
        cartesian.follow(planar_2r, line, **kwargs, **{key: value})


def test_follow_names_a_robot_or_path_that_is_not_one(planar_2r):
    line = cartesian.Line([1.2, 0.3, 0.0], [0.3, 1.2, 0.0])
    with pytest.raises(InputError, match="robot must be a kinplan.Robot"):
        cartesian.follow("planar_2r", line, duration=1.0)
    with pytest.raises(InputError, match="path must be a cartesian path"):
        cartesian.follow(planar_2r, [[1.2, 0.3, 0.0], [0.3, 1.2, 0.0]], duration=1.0)


def test_seed_and_clearance_are_used(planar_2r):
    line = cartesian.Line([1.2, 0.3, 0.0], [0.4, 1.1, 0.0])
    down = -elbow_up_ik(1.2, -0.3)
    for retime in (False, True):
        plan = cartesian.follow(planar_2r, line, duration=1.0, q_seed=down, retime=retime)
        assert plan.ok and np.all(plan.q[:, 1] < 0)
    ur5 = cached_robot("ur5")
    q0 = np.radians([0, -100, 100, -90, -90, 0])
    start = ur5.fk(q0)
    seam = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0, 0.05, 0]))
    cell = kinplan.WorkCell(ur5)
    plan = cartesian.follow(ur5, seam, duration=0.5, q_seed=q0, cell=cell, clearance=0.01)
    assert plan.ok and plan.min_clearance == np.inf
    plain = cartesian.follow(ur5, seam, duration=0.5, q_seed=q0)
    assert plain.min_clearance == np.inf and plain.cell is None


def test_reachability_stops_where_the_line_leaves_the_reach_sphere(ur5):
    """A line from a comfortable pose radially outward: with the singularity monitor off, the
    first unreachable point is where the line crosses the sphere of radius reach() about the
    first joint (bisected to 1e-7 of the path); an event at a path's first point has index 0,
    t 0, and a position error no smaller than the distance beyond the reach."""
    q0 = np.radians([0, -100, 100, -90, -90, 0])
    start, origin = ur5.fk(q0).translation, ur5.model.jointPlacements[1].translation
    outward = (start - origin) / np.linalg.norm(start - origin)
    line = cartesian.Line(start, origin + 1.2 * outward)
    result = cartesian.check_reachability(
        ur5, line, q_seed=q0, position_only=True, singular_threshold=0.0
    )
    assert result.ok is False and result.status == "unreachable", result
    event = result.events[0]
    crossing = ur5.shoulder_distance(line.position(np.array([event.s]))[0])
    assert crossing == pytest.approx(ur5.reach(), abs=1e-6)
    assert event.t == 0.0 and event.index == len(result.q)
    assert result.fraction == result.s[-1] < event.s < result.fraction + 1e-6
    assert repr(result) == (
        f"Reachability(unreachable, fraction {result.fraction:.3f}, {len(result.s)} points: "
        f"{event.message})"
    )
    outside = cartesian.Line(origin + 1.1 * outward, origin + 1.2 * outward)
    result = cartesian.check_reachability(ur5, outside, q_seed=q0, position_only=True)
    assert result.status == "unreachable" and result.fraction == 0.0 and len(result.q) == 0
    event = result.events[0]
    assert (event.index, event.t, event.s) == (0, 0.0, 0.0)
    np.testing.assert_allclose(event.position, origin + 1.1 * outward, atol=1e-12)
    assert event.value >= 1.1 - ur5.reach() - 1e-9
    assert repr(result).startswith("Reachability(unreachable, fraction 0.000, 0 points: ")


def test_reachability_bisects_so_no_checked_step_exceeds_a_tenth_of_a_radian(planar_2r):
    line = cartesian.Line(*BESIDE_AXIS)
    result = cartesian.check_reachability(planar_2r, line, q_seed=ELBOW_UP, singular_threshold=0.0)
    assert result.ok and repr(result) == f"Reachability(ok, fraction 1.000, {len(result.s)} points)"
    assert len(result.s) > 100 and np.all(np.diff(result.s) > 0)
    assert np.abs(np.diff(result.q, axis=0)).max() <= 0.1
    for s, q in zip(result.s[::10], result.q[::10], strict=True):  # on the elbow-up branch
        x, y = line.position(np.array([s]))[0][:2]
        np.testing.assert_allclose(q, elbow_up_ik(x, y), atol=1e-6)
    with pytest.raises(InputError, match="q_seed"):
        cartesian.check_reachability(planar_2r, line, q_seed=[0.0])
