"""Time-optimal Cartesian timing (`follow(..., retime=True)`, :mod:`cartesian.retime`).

Independent answers: the bang-bang law of a straight joint path (analytic), toppra (the
reference TOPP-RA implementation) on the same joint path with the same limits, finite
differences of the planned rates, and the limits themselves at every sample.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import cartesian
from cartesian.retime import LIMIT_MARGIN, SMOOTHING_PERIODS, optimal_speeds, timing_from_speeds
from kinplan.trajectory.sampling import joint_speeds

UR5_START = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
PANDA_START = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])


def _line(robot, q0, offset):
    start = robot.fk(q0)
    return cartesian.Line(start, pin.SE3(start.rotation, start.translation + np.asarray(offset)))


def test_a_straight_joint_path_gets_the_bang_bang_law():
    """q(s) = s on one joint, |q̇| ≤ v, |q̈| ≤ a: accelerate at a, cruise at v, brake at a. The
    duration is 1/v + v/a when the cruise is reached, 2/√a when not (limits scaled by the
    solver's margin), to the grid's resolution."""
    s = np.linspace(0.0, 1.0, 2001)
    dq, d2q = np.ones((s.size, 1)), np.zeros((s.size, 1))
    for v, a in ((0.5, 1.0), (4.0, 1.0)):
        speeds = optimal_speeds(s, dq, d2q, np.array([v]), np.array([a]), math.inf)
        timing = timing_from_speeds(s, speeds, 1e-3)
        v_m, a_m = LIMIT_MARGIN * v, LIMIT_MARGIN * a
        expected = 1 / v_m + v_m / a_m if v_m**2 / a_m < 1 else 2 / math.sqrt(a_m)
        assert timing.duration == pytest.approx(expected, rel=2e-3)
        assert np.max(timing.sd) <= v_m * (1 + 1e-12)
        assert np.max(np.abs(timing.sdd)) <= a_m * (1 + 1e-9)
        assert timing.sd[0] == 0.0 and timing.sd[-1] == 0.0 and timing.s[-1] == 1.0


def test_the_solver_matches_toppra_on_a_curved_joint_path():
    """Two joints, q = (s, 0.3 sin 3s): toppra's duration, within 0.1 % once the margin is
    taken out (the same discretisation of the same constraints)."""
    toppra = pytest.importorskip("toppra")
    from toppra import algorithm, constraint

    toppra.setup_logging("WARNING")
    s = np.linspace(0.0, 1.0, 601)
    q = np.stack([s, 0.3 * np.sin(3 * s)], 1)
    dq = np.stack([np.ones_like(s), 0.9 * np.cos(3 * s)], 1)
    d2q = np.stack([np.zeros_like(s), -2.7 * np.sin(3 * s)], 1)
    v, a = np.array([1.0, 0.5]), np.array([1.0, 0.7])
    timed = timing_from_speeds(s, optimal_speeds(s, dq, d2q, v, a, math.inf), 1e-3)
    # the law is averaged over two windows of SMOOTHING_PERIODS samples each (its acceleration
    # jumps become ramps the samples can represent): that lengthens it by exactly 2 windows
    ours = timed.duration - 2 * SMOOTHING_PERIODS * 1e-3
    limits = [
        constraint.JointVelocityConstraint(np.stack([-v, v], 1)),
        constraint.JointAccelerationConstraint(np.stack([-a, a], 1)),
    ]
    path = toppra.SplineInterpolator(s, q)
    reference = algorithm.TOPPRA(
        limits, path, gridpoints=s, parametrizer="ParametrizeConstAccel"
    ).compute_trajectory(0, 0)
    assert ours * math.sqrt(LIMIT_MARGIN) == pytest.approx(reference.duration, rel=1e-3)


@pytest.mark.parametrize(
    ("name", "start", "offset"),
    [("ur5", UR5_START, [0, 0.3, 0]), ("panda", PANDA_START, [0, 0.3, 0])],
)
def test_retimed_lines_are_optimal_within_every_limit(request, name, start, offset):
    """A 0.3 m line at 0.5 m/s with joint accelerations ≤ 5 rad/s²: ok, on the exact path,
    every joint within its speed and acceleration limits at every sample (rates, mean speeds,
    and q̈ checked against finite differences of q̇), the tool never faster than 0.5 m/s,
    at rest at both ends; and within 1.5 % of toppra's duration on the same joint path without
    the tool-speed cap."""
    robot = request.getfixturevalue(name)
    line = _line(robot, start, offset)
    plan = cartesian.follow(
        robot, line, speed=0.5, dt=0.001, q_seed=start, retime=True, max_acceleration=5.0
    )
    assert plan.ok and plan.retimed, plan
    assert plan.max_deviation <= 1e-7
    speeds = joint_speeds(plan.q, plan.qd, plan.t)
    assert np.all(speeds <= robot.velocity_limit)
    assert np.max(np.abs(plan.qdd)) <= 5.0
    finite_difference = np.gradient(plan.qd, plan.t, axis=0)[1:-1]
    assert np.max(np.abs(finite_difference)) <= 5.0 * 1.01
    # the tool's speed along the path (its positions are on the path within 1e-7 m, which
    # over 1 ms would blur a speed by 2e-4 m/s)
    assert plan.s.max() <= 1.0 and plan.retimed
    tool_speed = line.length * np.diff(plan.s) / np.diff(plan.t)
    assert tool_speed.max() <= 0.5 * (1 + 1e-12)
    assert np.all(plan.qd[0] == 0) and np.all(plan.qd[-1] == 0)
    # the optimum: somewhere a limit is active (the tool speed cap or a joint acceleration)
    assert tool_speed.max() > 0.49 or np.max(np.abs(plan.qdd)) > 0.98 * 5.0


def test_a_path_through_a_singularity_has_no_finite_timing(planar_2r):
    """Through the base of the 2R arm (l1 = l2) θ1 must turn by π at a point: no timing keeps
    the joint speeds finite; retiming fails honestly at that point."""
    line = cartesian.Line([0.5, 0.0, 0.0], [-0.5, 0.0, 0.0])
    plan = cartesian.follow(planar_2r, line, speed=0.1, q_seed=[-1.3, 2.6], retime=True)
    assert not plan.ok and plan.status in ("singular", "velocity_limit")
    assert abs(plan.events[0].position[0]) < 0.1  # at the base


def test_acceleration_limits_are_checked_without_retiming(ur5):
    """With joint acceleration limits and no retiming, a motion that breaks them stops at the
    first such sample with an acceleration_limit event that names the joint and offers
    retiming (which then passes)."""
    line = _line(ur5, UR5_START, [0, 0.3, 0])
    plan = cartesian.follow(ur5, line, speed=0.5, q_seed=UR5_START, max_acceleration=1.0)
    assert plan.status == "acceleration_limit", plan
    event = plan.events[0]
    assert event.joint in ur5.joint_names and abs(event.value) > event.limit == 1.0
    assert "retime" in event.remedy
    retimed = cartesian.follow(
        ur5, line, speed=0.5, q_seed=UR5_START, max_acceleration=1.0, retime=True
    )
    assert retimed.ok and np.max(np.abs(retimed.qdd)) <= 1.0


@pytest.mark.parametrize(("name", "start"), [("ur5", UR5_START), ("panda", PANDA_START)])
def test_retimed_lines_match_toppra(request, name, start):
    """Without a tool-speed cap, a 0.3 m line under joint velocity limits and 5 rad/s²: kinplan's
    duration within 1 % of toppra's on the same joint path (sampled at 1,000 points by kinplan's
    IK to 1e-12 m, so that toppra's spline does not differentiate IK noise), never shorter."""
    toppra = pytest.importorskip("toppra")
    from toppra import algorithm, constraint

    from cartesian.geometry import trace_geometry
    from cartesian.tracker import Tracker

    toppra.setup_logging("WARNING")
    robot = request.getfixturevalue(name)
    line = _line(robot, start, [0, 0.3, 0])
    plan = cartesian.follow(
        robot, line, speed=100.0, acceleration=1e6, dt=0.001, q_seed=start, retime=True,
        max_acceleration=5.0,
    )  # fmt: skip
    assert plan.ok, plan
    tracker = Tracker(robot, False, 1e-12, 1e-12, 0.0, 1.0, 0.05)
    geometry = trace_geometry(tracker, line, np.linspace(0.0, 1.0, 1000), start)
    v, a = robot.velocity_limit, np.full(robot.nq, 5.0)
    limits = [
        constraint.JointVelocityConstraint(np.stack([-v, v], 1)),
        constraint.JointAccelerationConstraint(np.stack([-a, a], 1)),
    ]
    reference = algorithm.TOPPRA(
        limits, toppra.SplineInterpolator(geometry.s, geometry.q), gridpoints=geometry.s,
        parametrizer="ParametrizeConstAccel",
    ).compute_trajectory(0, 0)  # fmt: skip
    ratio = plan.duration / reference.duration
    assert 1.0 - 1e-3 <= ratio <= 1.01, (plan.duration, reference.duration)
