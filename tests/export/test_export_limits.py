"""Exports refuse motions beyond the robot's limits, whatever built them (issue 26).

What a controller runs is the quintic Hermite through the samples (the URScript servo stream
resamples it; a ROS controller given positions, velocities and accelerations interpolates it):
positions, velocities and declared accelerations of that interpolant are checked at the samples
and between them. Seeded random trajectories within the limits are written (and their servo
stream, read back from the URScript text, keeps the speed limits); the same trajectories run
faster, or moved beyond a position limit, are refused by every export with a message naming the
joint, the time, the value and the limit.
"""

from __future__ import annotations

import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

import kinplan
from kinplan import export, trajectory
from kinplan.errors import InputError, KinplanError
from kinplan.trajectory.motion import sampled

SERVOJ = re.compile(r"^\s*servoj\(\[([^\]]*)\], t=", re.M)
#: Peak speed and acceleration of a rest-to-rest quintic of amplitude 1 over 1 s.
QUINTIC_PEAK_SPEED = 1.875
QUINTIC_PEAK_ACCELERATION = 10.0 / math.sqrt(3.0)


@pytest.fixture(scope="module")
def ur5():
    return kinplan.load_robot("ur5")


@pytest.fixture(scope="module")
def ur5_accel():
    """A UR5 whose elbow declares an acceleration limit of 4 rad/s²."""
    return kinplan.load_robot("ur5", limits={"elbow_joint": {"acceleration": 4.0}})


def _exports(plan, tmp_path):
    """Every export of a motion (the URScript one only for a UR arm)."""
    writers = {
        "write_csv": lambda: export.write_csv(tmp_path / "m.csv", plan, plan.robot.joint_names),
        "joint_trajectory": lambda: export.joint_trajectory(plan),
        "write_joint_trajectory": lambda: export.write_joint_trajectory(tmp_path / "m.json", plan),
        "servo_samples": lambda: export.servo_samples(plan),
    }
    if not export.ur_arm_problem(plan.robot):
        writers["urscript"] = lambda: export.urscript(plan)
    return writers


def _quintic(robot, rng, speed_share, accel_share=None):
    """A rest-to-rest quintic between two random configurations inside the limits, timed so
    that its worst joint runs at ``speed_share`` of its velocity limit (and, when given, at
    ``accel_share`` of a declared acceleration limit, whichever needs longer)."""
    low = np.maximum(robot.lower, -np.pi) + 0.05
    high = np.minimum(robot.upper, np.pi) - 0.05
    q0, q1 = rng.uniform(low, high), rng.uniform(low, high)
    span = np.abs(q1 - q0)
    duration = float(np.max(QUINTIC_PEAK_SPEED * span / (speed_share * robot.velocity_limit)))
    if accel_share is not None:
        finite = np.isfinite(robot.acceleration_limit)
        needed = (
            QUINTIC_PEAK_ACCELERATION
            * span[finite]
            / (accel_share * robot.acceleration_limit[finite])
        )
        duration = max(duration, float(np.sqrt(np.max(needed))))
    return trajectory.quintic(q0, q1, duration), q0, q1


@pytest.mark.parametrize("seed", range(12))
def test_motions_within_the_limits_are_written(ur5, tmp_path, seed):
    rng = np.random.default_rng(seed)
    motion, _, _ = _quintic(ur5, rng, rng.uniform(0.3, 0.97))
    plan = sampled(motion, ur5, dt=float(rng.choice([0.004, 0.01, 0.03])))
    for write in _exports(plan, tmp_path).values():
        write()
    # the servo stream the controller runs, read back from the text: within the speed limits
    script = export.urscript(plan, period=0.008)
    targets = np.array([[float(x) for x in m.split(",")] for m in SERVOJ.findall(script)])
    speeds = np.abs(np.diff(targets, axis=0)) / 0.008
    assert np.all(speeds <= ur5.velocity_limit * (1 + 1e-6)), speeds.max(axis=0)


@pytest.mark.parametrize("seed", range(12))
def test_motions_too_fast_are_refused_by_every_export(ur5, tmp_path, seed):
    rng = np.random.default_rng(100 + seed)
    share = float(rng.uniform(1.02, 500.0))
    motion, q0, q1 = _quintic(ur5, rng, share)
    plan = sampled(motion, ur5, dt=0.01)
    worst = int(np.argmax(np.abs(q1 - q0) / ur5.velocity_limit))
    for what, write in _exports(plan, tmp_path).items():
        with pytest.raises(export.LimitViolationError) as info:
            write()
        error = info.value
        assert isinstance(error, InputError) and isinstance(error, KinplanError)
        assert error.quantity == "velocity" and error.joint == ur5.joint_names[worst], what
        assert error.limit == ur5.velocity_limit[worst]
        np.testing.assert_allclose(abs(error.value) / error.limit, share, rtol=0.01)
        message = str(error)
        assert what.endswith(message.split(" refuses a motion beyond")[0]), message
        assert ur5.joint_names[worst] in message and "velocity limit" in message
        assert f"t = {error.t:.4f} s" in message
        assert "slower" in message
    assert not (tmp_path / "m.csv").exists() and not (tmp_path / "m.json").exists()


def test_the_remedy_as_printed_works(ur5, tmp_path):
    """ "at least F× slower": the same motion with its duration multiplied by F is written."""
    rng = np.random.default_rng(7)
    motion, q0, q1 = _quintic(ur5, rng, 3.7)
    with pytest.raises(export.LimitViolationError) as info:
        export.urscript(sampled(motion, ur5))
    factor = float(re.search(r"at least ([0-9.]+)× slower", str(info.value)).group(1))
    slower = trajectory.quintic(q0, q1, motion.duration * factor)
    export.urscript(sampled(slower, ur5))


def test_the_issue_example_zero_to_100_rad_in_a_tenth_of_a_second(ur5, tmp_path):
    plan = sampled(trajectory.cubic(np.zeros(6), np.full(6, 100.0), 0.1), ur5)
    for what, write in _exports(plan, tmp_path).items():
        with pytest.raises(export.LimitViolationError, match=r"beyond its upper limit") as info:
            write()
        assert info.value.quantity == "position", what
    # within the position limits but 474× too fast per servo period
    q1 = np.array([3.0, -3.0, 3.0, 3.0, -3.0, 3.0])
    plan = sampled(trajectory.cubic(np.zeros(6), q1, 0.1), ur5)
    with pytest.raises(export.LimitViolationError, match=r"velocity limit 3\.15 rad/s"):
        export.urscript(plan)


@pytest.mark.parametrize("seed", range(8))
def test_declared_accelerations_are_checked(ur5_accel, tmp_path, seed):
    rng = np.random.default_rng(200 + seed)
    elbow = ur5_accel.joint_names.index("elbow_joint")
    within, _, _ = _quintic(ur5_accel, rng, 0.5, accel_share=0.95)
    for write in _exports(sampled(within, ur5_accel, dt=0.005), tmp_path).values():
        write()
    # the same path faster: the elbow beyond 4 rad/s², its speed still within its limit
    q0, q1 = within.sample(0.0)[0], within.sample(within.duration)[0]
    span = abs(q1[elbow] - q0[elbow])
    if span < 0.05:
        q1[elbow] = q0[elbow] + (0.3 if q0[elbow] < 0 else -0.3)
        span = 0.3
    fast = math.sqrt(QUINTIC_PEAK_ACCELERATION * span / (4.0 * 1.5))  # 1.5× the limit
    fast = max(fast, float(np.max(QUINTIC_PEAK_SPEED * np.abs(q1 - q0) / ur5_accel.velocity_limit)))
    motion = trajectory.quintic(q0, q1, fast)
    peak = QUINTIC_PEAK_ACCELERATION * span / fast**2
    plan = sampled(motion, ur5_accel, dt=0.005)
    if peak <= 4.0 * 1.01:  # the speed limit forced a duration within the acceleration limit
        export.urscript(plan)
        return
    for what, write in _exports(plan, tmp_path).items():
        with pytest.raises(export.LimitViolationError, match="acceleration limit 4 rad/s²") as e:
            write()
        assert e.value.joint == "elbow_joint" and e.value.quantity == "acceleration", what


def test_without_declared_accelerations_none_are_checked(ur5):
    """The UR5 URDF declares no acceleration limit: a quick but slow-enough move is written."""
    q0 = np.zeros(6)
    q1 = np.array([0.0, 0.0, 0.2, 0.0, 0.0, 0.0])  # 0.2 rad in 0.2 s: 1.9 rad/s, 29 rad/s²
    export.urscript(sampled(trajectory.quintic(q0, q1, 0.2), ur5))


def test_samples_whose_rates_disagree_with_the_positions_are_refused(ur5):
    """A motion whose samples jump with q̇ = 0 (each sample within the limits, q̇ and q̈ zero):
    the interpolant the controller runs moves between the samples far beyond the speed limit."""
    t = np.arange(11) * 0.01
    q = np.zeros((11, 6))
    q[6:, 0] = 0.5  # a 0.5 rad step between two samples 10 ms apart
    plan = SimpleNamespace(
        kind="joint", description="a step", t=t, q=q, qd=np.zeros_like(q), qdd=np.zeros_like(q),
        robot=ur5, tool_positions=None, planned_paths=(), waypoints=None, moves=(), events=(),
        ok=True, status="ok",
    )  # fmt: skip
    with pytest.raises(export.LimitViolationError, match="shoulder_pan_joint moves at") as info:
        export.joint_trajectory(plan)
    assert 0.05 < info.value.t < 0.06  # between the samples at 0.05 and 0.06 s
    assert abs(info.value.value) > 50.0  # 1.875 · 0.5 / 0.01 rad/s


def test_a_program_names_the_move(ur5, tmp_path):
    """A program plan's refusal names the move running at that instant."""
    moves = [SimpleNamespace(number=1, label="ptp to a", t0=0.0, t1=0.05, status="ok"),
             SimpleNamespace(number=2, label="lin to b", t0=0.05, t1=0.1, status="ok")]  # fmt: skip
    motion = sampled(trajectory.cubic(np.zeros(6), np.array([0, 0, 0, 0, 0, 3.0]), 0.1), ur5)
    plan = SimpleNamespace(**{k: getattr(motion, k) for k in ("t", "q", "qd", "qdd", "robot")})
    plan.__dict__.update(
        kind="program", description="p", tool_positions=None, planned_paths=(), waypoints=None,
        moves=moves, events=(), ok=True, status="ok",
    )  # fmt: skip
    with pytest.raises(export.LimitViolationError, match=r"in move (1|2) \((ptp to a|lin to b)\)"):
        export.urscript(plan)


def test_random_motions_property(ur5, tmp_path):
    """Seeded property sweep: 100 random quintics and cubic splines through via points, each
    written exactly when an independent dense evaluation of the trajectory (100 points per
    sample interval) keeps every joint within 99 % of its limits, refused when it breaks one by
    more than 1 %."""
    rng = np.random.default_rng(26)
    written = refused = 0
    for _ in range(100):
        low, high = np.maximum(ur5.lower, -4.0), np.minimum(ur5.upper, 4.0)
        points = rng.uniform(1.3 * low, 1.3 * high, (int(rng.integers(2, 5)), 6))
        if rng.uniform() < 0.75:
            points = np.clip(points, 0.9 * low, 0.9 * high)
        steps = np.max(np.abs(np.diff(points, axis=0)) / ur5.velocity_limit, axis=1)
        share = rng.uniform(0.15, 2.0)  # mean speed of the slowest-needing joint / its limit
        times = np.concatenate([[0.0], np.cumsum(np.maximum(steps / share, 0.05))])
        motion = trajectory.cubic_via(points, times)
        dt = float(rng.choice([0.005, 0.01, 0.02]))
        plan = sampled(motion, ur5, dt=dt)
        dense = np.linspace(0.0, motion.duration, 100 * len(plan.t))
        q, qd, _ = motion.sample(dense)
        outside = np.maximum(ur5.lower - q, q - ur5.upper).max()
        ratio = (np.abs(qd) / ur5.velocity_limit).max()
        if outside <= 0.0 and ratio <= 0.99:
            export.write_csv(tmp_path / "ok.csv", plan, ur5.joint_names)
            export.urscript(plan)
            written += 1
        elif outside > 0.01 or (outside <= 0.0 and ratio > 1.01):
            kind = "position" if outside > 0.01 else "velocity"
            for what, write in _exports(plan, tmp_path).items():
                with pytest.raises(export.LimitViolationError) as info:
                    write()
                assert info.value.quantity == kind, (what, str(info.value))
            refused += 1
    assert written >= 15 and refused >= 15, (written, refused)
