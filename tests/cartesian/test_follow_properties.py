"""Property tests of Cartesian following: what `ok` promises, over thousands of seeded lines.

For 2,000 random short lines per arm (ur5, panda, a planar 3R arm), from random configurations,
with random durations and sampling periods, every plan (ok or not) must be honest:

* the samples it returns (all of them when ok, the achieved part otherwise) are executable:
  joints within their limits, every joint speed — the rates q̇ and the mean speeds |Δq|/Δt
  between samples — within its limit, the tool on the path within the tolerance (checked by
  an independent FK), and q̇, q̈ consistent with q: the trapezoid rule integrates q̇ into q up to
  the error of the sampling itself, |Δq − h(q̇₀ + q̇₁)/2| ≤ h²|Δq̈| + noise, |Δq̈| the largest
  change of q̈ of any joint over the interval and its neighbours (a Newton correction moves
  every joint) (the trapezoid rule's error is at most
  h²|Δq̈|/8 at a kink of q̇, h³|q⃛|/12 ≈ h²|Δq̈|/12 on a smooth motion; a redundant arm adds the
  null-space part of the two-step prediction's error, 5h³|q⃛|/12);
* a failure names a true reason: a velocity event's value is above its limit, a joint-limit
  event's value beyond the joint's range, and the status is the first event's kind.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import cached_robot

import cartesian
import kinplan
from kinplan.trajectory.sampling import joint_speeds

LINES_PER_ARM = 2000
#: Tool position tolerance of the plans [m] (follow's default).
TOLERANCE = 1e-7
#: Joint noise of an IK solution within TOLERANCE (1e-7 m and 1e-7 rad) [rad]: the tolerance
#: over the smallest singular value of a non-singular sample's Jacobian, 5 mm (a wrist near its
#: singularity). The clamp this file guards against left residuals of h·|q̇| ≈ 5e-4 rad.
JOINT_NOISE = 2e-5


def _robot(name: str) -> kinplan.Robot:
    if name == "planar_3r":
        return kinplan.planar_arm([0.5, 0.4, 0.3])
    return cached_robot(name)


def _random_lines(robot: kinplan.Robot, count: int, seed: int):
    """(q0, line, duration, dt) of random short lines starting at random configurations."""
    rng = np.random.default_rng(seed)
    planar = robot.planar_reach() is not None
    for _ in range(count):
        q0 = robot.lower + (robot.upper - robot.lower) * rng.random(robot.nq)
        p0 = robot.fk(q0).translation
        direction = rng.normal(size=3)
        if planar:
            direction[2] = 0.0
        direction *= rng.uniform(0.001, 0.08) / np.linalg.norm(direction)
        duration = float(rng.uniform(0.01, 0.5))
        dt = float(rng.choice([0.001, 0.002, 0.005, 0.01]))
        yield q0, cartesian.Line(p0, p0 + direction), duration, dt


def _check_samples(
    robot: kinplan.Robot, plan: cartesian.CartesianPlan, consistency: bool = True
) -> None:
    """The executable-motion invariants of the samples a plan returns (``consistency``: also
    that the rates integrate into the positions, see the module docstring)."""
    q, qd, qdd, t = plan.q, plan.qd, plan.qdd, plan.t
    if len(t) == 0:
        return
    assert np.all(q >= robot.lower) and np.all(q <= robot.upper), plan
    speeds = joint_speeds(q, qd, t)
    assert np.all(speeds <= robot.velocity_limit), (speeds / robot.velocity_limit).max()
    tool = robot.tool_positions(q)  # independent of the follower's own bookkeeping
    deviation = np.linalg.norm(tool - plan.path.position(plan.s), axis=1)
    assert deviation.max() <= TOLERANCE * (1 + 1e-6), deviation.max()
    if consistency and len(t) > 1:
        h = np.diff(t)[:, None]
        residual = np.abs(np.diff(q, axis=0) - 0.5 * h * (qd[1:] + qd[:-1]))
        # the largest |Δq̈| over the joints, of each interval and its neighbours
        change = np.abs(np.diff(qdd, axis=0)).max(axis=1, keepdims=True)
        change[1:] = np.maximum(change[1:], change[:-1])
        change[:-1] = np.maximum(change[:-1], change[1:])
        bound = np.broadcast_to(h**2 * change + JOINT_NOISE, residual.shape)
        worst = np.unravel_index(np.argmax(residual - bound), residual.shape)
        assert np.all(residual <= bound), (worst, residual[worst], bound[worst])


def _check_events(robot: kinplan.Robot, plan: cartesian.CartesianPlan) -> None:
    """A failed plan's reason is true."""
    assert plan.ok == (not plan.events)
    if plan.ok:
        assert plan.status == "ok" and plan.fraction == 1.0
        return
    event = plan.events[0]
    assert plan.status == event.kind
    assert event.message and event.remedy
    assert plan.fraction <= event.s
    if event.kind in ("velocity_limit", "joint_limit"):
        j = robot.joint_names.index(event.joint)
        assert event.joint in event.message
    if event.kind == "velocity_limit":
        assert abs(event.value) > event.limit == robot.velocity_limit[j]
    if event.kind == "joint_limit":
        assert event.limit in (robot.lower[j], robot.upper[j])
        assert not robot.lower[j] <= event.value <= robot.upper[j]


@pytest.mark.parametrize("name", ["ur5", "panda", "planar_3r"])
def test_random_lines_are_honest(name):
    robot = _robot(name)
    statuses: dict[str, int] = {}
    for k, (q0, line, duration, dt) in enumerate(_random_lines(robot, LINES_PER_ARM, seed=12)):
        # every other line position-only; the others hold the start orientation (6+ joints)
        only = True if k % 2 else None
        plan = cartesian.follow(
            robot, line, duration=duration, dt=dt, q_seed=q0, position_only=only
        )
        statuses[plan.status] = statuses.get(plan.status, 0) + 1
        _check_samples(robot, plan)
        _check_events(robot, plan)
    # the sweep exercises both outcomes, not only one
    assert statuses.get("ok", 0) > LINES_PER_ARM // 2, statuses
    assert statuses.get("velocity_limit", 0) > 0 and statuses.get("joint_limit", 0) > 0, statuses


def test_issue_reproducer_is_a_joint_limit_not_a_clamp(ur5):
    """The UR5 line that used to be `ok` with joint 1 pinned at its lower limit (its reported
    q̇ pushing past it, the real speed 1.45× the limit)."""
    q0 = np.array([5.7586, -6.2611, -2.2901, 3.4730, 0.2409, -0.2670])
    p0 = ur5.fk(q0).translation
    line = cartesian.Line(p0, p0 + np.array([-0.0069, -0.0018, 0.0259]))
    plan = cartesian.follow(ur5, line, duration=0.105, dt=0.001, q_seed=q0, position_only=True)
    assert plan.status == "joint_limit"
    event = plan.events[0]
    assert event.joint == "shoulder_lift_joint" and event.limit == ur5.lower[1]
    assert event.value < ur5.lower[1]
    _check_samples(ur5, plan)


@pytest.mark.parametrize("duration", [1e-3, 1e-4])
def test_motion_shorter_than_a_sample_is_checked(ur5, duration):
    """A 2 cm line in 1 ms (or 0.1 ms) needs joint speeds far above the limits: refused with
    the speed it needs, not `ok` with two resting samples."""
    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    p0 = ur5.fk(q0).translation
    line = cartesian.Line(p0, p0 + np.array([0.02, 0.0, 0.0]))
    plan = cartesian.follow(ur5, line, duration=duration, dt=0.01, q_seed=q0)
    assert plan.status == "velocity_limit"
    # checked on 16 intervals, returned on the caller's grid (t = 0, duration): the first only
    np.testing.assert_array_equal(plan.t, [0.0])
    event = plan.events[0]
    assert event.value > event.limit and f"{event.value:.4g}" in event.message
    # the speed the whole motion needs: tens of times the limit, and the message says so
    assert plan.peak_speed_ratio > 10 and f"{plan.peak_speed_ratio:.3g}×" in event.message
    # the remedy names a duration that was planned: pasted as printed, it passes
    assert plan.slowdown is not None and plan.slowdown >= plan.peak_speed_ratio
    slower = float(event.remedy.split("duration=")[1].split(")")[0].split(";")[0])
    assert slower == pytest.approx(duration * plan.slowdown, rel=1e-3)
    assert cartesian.follow(ur5, line, duration=slower, dt=0.01, q_seed=q0).ok


def test_retime_is_offered_only_when_it_passes(ur5):
    """The velocity_limit remedy names retime=True only where the retimed plan is ok."""
    offered = refused = 0
    for q0, line, duration, dt in _random_lines(ur5, 300, seed=5):
        plan = cartesian.follow(ur5, line, duration=duration * 0.2, dt=dt, q_seed=q0)
        if plan.status != "velocity_limit":
            continue
        retimed = cartesian.follow(ur5, line, duration=duration * 0.2, dt=dt, q_seed=q0,
                                   retime=True)  # fmt: skip
        says_retime = "retime=True" in plan.events[0].remedy
        assert says_retime == retimed.ok, (plan.events[0].remedy, retimed)
        assert (plan.retime_duration is not None) == retimed.ok
        if retimed.ok:
            assert plan.retime_duration == pytest.approx(retimed.duration, rel=1e-12)
            # the retimed law switches its acceleration at every 0.5 mm of path, many times
            # between two samples, so the sampled q̈ does not bound the rule's error there
            _check_samples(ur5, retimed, consistency=False)
        offered += says_retime
        refused += not says_retime
    assert offered > 0 and refused > 0, (offered, refused)


def test_check_reachability_agrees_with_follow(planar_2r):
    """On lines through the base, to full stretch and at random, the geometric pre-check and
    the follower (speed limits lifted) agree on whether the path can be followed, and the
    pre-check names the singularity that follow meets (these used to differ: the analytic
    annulus check said ok through the base and at full stretch)."""
    rng = np.random.default_rng(7)
    verdicts: dict[tuple[str, str], int] = {}
    for i in range(240):
        a = rng.uniform(-2.0, 2.0, 3)
        a[2] = 0.0
        a *= min(1.0, 1.99 / np.linalg.norm(a))
        if i % 3 == 0:
            b = -a * rng.uniform(0.2, 1.0)  # through the base
        elif i % 3 == 1:
            b = 2.0 * a / np.linalg.norm(a)  # to full stretch
        else:
            b = np.append(rng.uniform(-2.0, 2.0, 2), 0.0)
        seed = planar_2r.ik(a, q_seed=rng.uniform(-3.0, 3.0, 2)).q
        line = cartesian.Line(a, b)
        check = cartesian.check_reachability(planar_2r, line, q_seed=seed)
        plan = cartesian.follow(
            planar_2r, line, duration=1.0, dt=0.001, q_seed=seed, velocity_scale=1e9
        )
        assert check.ok == plan.ok, (i, check, plan)
        if plan.status == "singular":  # the rim or the base, or a point beyond the rim
            assert check.status in ("singular", "unreachable"), (i, check, plan)
        verdicts[check.status, plan.status] = verdicts.get((check.status, plan.status), 0) + 1
    assert verdicts.get(("singular", "singular"), 0) > 50 and verdicts.get(("ok", "ok"), 0) > 20
