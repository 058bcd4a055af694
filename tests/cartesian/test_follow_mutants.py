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
from kinplan.model.robot import planar_arm

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


def test_a_step_too_coarse_for_a_continuous_swing_is_a_sampling_refusal(planar_2r):
    line = cartesian.Line(*BESIDE_AXIS)
    plan = cartesian.follow(
        planar_2r, line, duration=2.0, dt=0.08, q_seed=ELBOW_UP, singular_threshold=0.0
    )
    assert plan.status == "sampling", plan
    event = plan.events[0]
    k = event.index
    step = fine_step(planar_2r, line, event.t - 0.08, event.t)
    assert event.joint == "joint1" and event.limit == 0.05
    assert event.value == pytest.approx(step[0], abs=1e-4)  # the continuous solution's step
    assert "sampling is too coarse" in event.message
    assert len(plan.q) == k and np.all(plan.q[:, 1] > 0)
    # the remedy names the largest period that was planned and represents the swing
    assert event.remedy.startswith("sample more finely: dt = ")
    dt = float(event.remedy.split("dt = ")[1].split(" s")[0])
    assert dt < 0.08
    finer = cartesian.follow(
        planar_2r, line, duration=2.0, dt=dt, q_seed=ELBOW_UP, singular_threshold=0.0
    )
    assert finer.status != "sampling", finer


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


# ---------------------------------------------------------------------------- issue 20, third pass
LINE_2R = ([1.2, 0.3, 0.0], [0.4, 1.1, 0.0])


@pytest.mark.parametrize("key", ["position_only", "retime"])
def test_follow_names_a_flag_that_is_not_a_boolean(planar_2r, key):
    line = cartesian.Line(*LINE_2R)
    with pytest.raises(InputError, match=key):
        cartesian.follow(planar_2r, line, duration=1.0, **{key: "yes"})


@pytest.mark.parametrize("value", [0.0, -1e-3], ids=["zero", "negative"])
def test_rotation_tolerance_is_refused_before_any_planning(value):
    """A position-only arm never uses the rotation tolerance, yet a tolerance ≤ 0 is refused by
    follow itself, before any inverse kinematics runs."""
    arm = planar_arm([1.0, 1.0])

    def no_ik(*args, **kwargs):
        raise AssertionError("follow ran inverse kinematics before checking its arguments")

    arm.ik = no_ik
    line = cartesian.Line(*LINE_2R)
    with pytest.raises(InputError, match=r"rotation_tolerance must be > 0 \[rad\]"):
        cartesian.follow(arm, line, duration=1.0, rotation_tolerance=value)


def test_a_3_vector_path_holds_the_seeds_orientation(ur5):
    """A line of 3-vectors on the UR5: the tool keeps the orientation of q_seed (its FK), which
    differs from the neutral configuration's, at every sample."""
    q0 = np.radians([30, -100, 100, -60, -90, 20])
    start = ur5.fk(q0)
    assert not np.allclose(ur5.fk(ur5.neutral()).rotation, start.rotation, atol=0.1)
    plan = cartesian.follow(
        ur5, cartesian.Line(start.translation, start.translation + [0, 0.05, 0]), duration=0.5,
        q_seed=q0,
    )  # fmt: skip
    assert plan.ok and not plan.position_only
    for q in plan.q[:: max(1, len(plan.q) // 10)]:
        np.testing.assert_allclose(ur5.fk(q).rotation, start.rotation, atol=1e-6)


def test_the_offered_retime_keeps_the_seeds_branch(planar_2r):
    """A velocity-limited plan on the elbow-down branch (not the one IK from the neutral seed
    picks) offers the duration of the retimed plan on that same branch: the one retime=True
    gives from the same seed."""
    line = cartesian.Line(*LINE_2R)
    down = -elbow_up_ik(1.2, -0.3)
    plan = cartesian.follow(planar_2r, line, duration=0.2, q_seed=down)
    assert plan.status == "velocity_limit" and np.all(plan.q[:, 1] < 0)
    retimed = cartesian.follow(planar_2r, line, duration=0.2, q_seed=down, retime=True)
    assert retimed.ok and retimed.retimed and np.all(retimed.q[:, 1] < 0)
    other = cartesian.follow(planar_2r, line, duration=0.2, q_seed=-down, retime=True)
    assert other.ok and np.all(other.q[:, 1] > 0)
    assert abs(other.duration - retimed.duration) > 1e-3  # the branches differ in time
    assert plan.retime_duration == pytest.approx(retimed.duration)


def test_a_retimed_path_leaving_the_reach_is_the_nominal_plan_from_the_seed(planar_2r):
    """retime=True on a line that leaves the 2R's reach: the geometric pass fails, and the plan
    is the nominal one from the same seed (elbow-down), up to the unreachable sample."""
    line = cartesian.Line([1.2, 0.3, 0.0], [2.1, 0.3, 0.0])
    down = -elbow_up_ik(1.2, -0.3)
    nominal = cartesian.follow(planar_2r, line, duration=1.0, q_seed=down)
    retimed = cartesian.follow(planar_2r, line, duration=1.0, q_seed=down, retime=True)
    assert nominal.status == retimed.status != "ok" and not retimed.retimed
    assert len(retimed.q) > 10 and np.all(retimed.q[:, 1] < 0)
    np.testing.assert_array_equal(retimed.q, nominal.q)


def path_acceleration(plan) -> np.ndarray:
    """s̈ of a plan from its uniformly sampled s(t) (central second differences)."""
    h = plan.t[1] - plan.t[0]
    uniform = np.flatnonzero(np.abs(np.diff(plan.t) - h) < 1e-12)
    k = uniform[(uniform > 0) & np.isin(uniform - 1, uniform)]  # h before and after sample k
    return (plan.s[k + 1] - 2 * plan.s[k] + plan.s[k - 1]) / h**2


def test_retiming_keeps_the_nominal_path_acceleration_unless_joints_limit_it(planar_2r):
    """The 2R has no joint acceleration limits: the retimed law (slowed by joint speed limits)
    accelerates along the path no harder than the nominal trapezoid. With (generous) joint
    acceleration limits, those bound it instead: it accelerates far harder than the nominal law,
    is faster, and keeps every joint within its limit."""
    assert not np.isfinite(planar_2r.acceleration_limit).any()
    line = cartesian.Line(*LINE_2R)
    kwargs = {"duration": 1.0, "q_seed": [0.3, 1.2], "velocity_scale": 0.15}
    nominal = cartesian.follow(planar_2r, line, **kwargs)
    assert nominal.status == "velocity_limit"
    nominal_sdd = np.abs(path_acceleration(cartesian.follow(planar_2r, line, duration=1.0,
                                                             q_seed=[0.3, 1.2]))).max()  # fmt: skip
    retimed = cartesian.follow(planar_2r, line, retime=True, **kwargs)
    assert retimed.ok and retimed.retimed
    assert np.abs(path_acceleration(retimed)).max() <= nominal_sdd * (1 + 1e-3)
    fast = cartesian.follow(planar_2r, line, retime=True, max_acceleration=1e3, **kwargs)
    assert fast.ok and fast.retimed and fast.duration < retimed.duration
    assert np.abs(path_acceleration(fast)).max() > 2 * nominal_sdd
    assert np.all(np.abs(fast.qdd) <= 1e3 * (1 + 1e-6))


def test_peak_speed_ratio_of_a_slow_plan_is_its_margin(planar_2r):
    """A slow plan has margin: its peak speed ratio is below 1, the largest joint speed over
    its limit (the rates; for a slow smooth motion the mean speeds between samples are below
    them), so that the same path at that many times the speed just fits."""
    line = cartesian.Line(*LINE_2R)
    plan = cartesian.follow(planar_2r, line, duration=4.0, q_seed=[0.3, 1.2])
    assert plan.ok
    rates = np.abs(plan.qd) / planar_2r.velocity_limit
    assert 0.0 < plan.peak_speed_ratio < 1.0
    assert plan.peak_speed_ratio == pytest.approx(rates.max(), rel=1e-3)


def test_collision_event_states_the_check(ur5):
    """A wall across a UR5 seam: the event's value is the check's signed distance (≤ 0: in
    contact), its limit the clearance (0), its position the path point of its sample; the
    message names both bodies, the depth the check measured, where and when; the plan keeps
    the check, and its repr ends with the message. Without a cell there is no check."""
    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    start = ur5.fk(q0)
    seam = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    cell = kinplan.WorkCell(ur5)
    cell.add_box("wall", [0.3, 0.004, 0.4], pin.SE3(np.eye(3), seam.position(np.array([0.5]))[0]))
    plan = cartesian.follow(ur5, seam, speed=0.2, q_seed=q0, cell=cell)
    assert plan.status == "collision", plan
    event, check = plan.events[0], plan.cell_check
    assert check is not None and check.index == event.index and check.kind == "obstacle"
    assert event.value == check.distance <= 0.0 and event.limit == 0.0
    k = event.index
    np.testing.assert_allclose(event.position, seam.position(np.array([event.s]))[0], atol=1e-12)
    first, second = check.bodies
    assert (
        f"{first} collides with {second} ({1e3 * check.penetration:.1f} mm deep)" in event.message
    )
    assert check.penetration == pytest.approx(-check.distance)
    t = plan.t if k < len(plan.t) else np.append(plan.t, event.t)  # the failing sample's time
    when = (
        f"between samples at t = {t[k - 1]:.4f} and {t[k]:.4f} s"
        if check.between
        else f"at the sample at t = {event.t:.4f} s"
    )
    assert when in event.message
    assert (
        check.point is not None and f"near {cartesian.events.where(check.point)}" in event.message
    )
    assert repr(plan).endswith(f": {event.message})")
    free = cartesian.follow(ur5, seam, speed=0.2, q_seed=q0)
    assert free.ok and free.cell_check is None and repr(free).endswith(" m)")


def test_a_clearance_violation_states_the_distance_and_the_margin(ur5):
    """A ball 3 cm off the motion and a 5 cm clearance: the event's value is the distance kept
    (> 0), its limit the clearance, and the message says how far inside the margin it is."""
    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    start = ur5.fk(q0)
    seam = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    cell = kinplan.WorkCell(ur5)
    ball = seam.position(np.array([0.5]))[0] + [0.0, 0.0, 0.25]
    cell.add_sphere("ball", 0.02, pin.SE3(np.eye(3), ball))
    free = cartesian.follow(ur5, seam, speed=0.2, q_seed=q0, cell=cell)
    assert free.ok and free.cell_check is not None and free.cell_check.index is None
    margin = free.min_clearance + 0.02
    plan = cartesian.follow(ur5, seam, speed=0.2, q_seed=q0, cell=cell, clearance=margin)
    assert plan.status == "collision"
    event, check = plan.events[0], plan.cell_check
    assert event.limit == margin and 0.0 < event.value == check.distance < margin
    assert check.penetration == pytest.approx(margin - check.distance)
    assert f"comes within {1e3 * check.distance:.1f} mm of" in event.message
    assert f"{1e3 * check.penetration:.1f} mm inside the clearance {1e3 * margin:.1f} mm" in (
        event.message
    )


def test_a_cell_built_for_another_robot_is_checked_with_the_planned_one(ur5):
    """A cell made around the stock UR5, used to plan a UR5 whose base is 1 m further along x:
    the motion is checked with the planned robot's links (a wall across its seam stops it;
    the stock arm's links are 1 m away from that wall)."""
    moved = kinplan.load_robot("ur5", base_pose=pin.SE3(np.eye(3), np.array([1.0, 0.0, 0.0])))
    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    start = moved.fk(q0)
    seam = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    cell = kinplan.WorkCell(ur5)
    cell.add_box("wall", [0.3, 0.004, 0.4], pin.SE3(np.eye(3), seam.position(np.array([0.5]))[0]))
    free = cartesian.follow(moved, seam, speed=0.2, q_seed=q0)
    assert free.ok and cell.check_motion(free.q).index is None  # the stock arm misses the wall
    plan = cartesian.follow(moved, seam, speed=0.2, q_seed=q0, cell=cell)
    assert plan.status == "collision" and "wall" in plan.events[0].message, plan
    assert plan.cell is not cell and plan.cell.robot is moved
