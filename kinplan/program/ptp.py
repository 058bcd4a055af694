"""Timing of joint-interpolated (``ptp``) moves within the joint velocity limits."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from kinplan import trajectory
from kinplan._profiles import PTP_PROFILES, REST_TO_REST_PEAKS
from kinplan.errors import KinplanError
from kinplan.program.schema import (
    DEFAULT_PTP_SPEED,
    FALLBACK_JOINT_SPEED,
    PTP_JERK_TIME,
    PTP_RAMP_TIME,
)
from kinplan.robot import Robot
from kinplan.sampling import joint_speeds
from kinplan.trajectory import Trajectory

__all__ = [
    "motion_limits",
    "peak_speed_ratio",
    "polynomial_duration",
    "ptp_through_trajectory",
    "ptp_trajectory",
]


def ptp_trajectory(
    robot: Robot,
    q_start: np.ndarray,
    q_goal: np.ndarray,
    duration: float | None,
    speed: float | None,
    profile: str,
) -> Trajectory:
    """The joint trajectory of a ``ptp`` move.

    Every joint cruises within ``speed`` × its velocity limit (a joint without a limit at
    :data:`~kinplan.program.FALLBACK_JOINT_SPEED`) and reaches it in
    :data:`~kinplan.program.PTP_RAMP_TIME`. ``scurve`` and ``time_optimal`` use the robot's
    acceleration limits where it has them (scaled by ``speed``; all of them with a
    ``duration``), ``scurve`` with jerk ramps of :data:`~kinplan.program.PTP_JERK_TIME`.

    Args:
        robot: The arm.
        q_start: Start configuration [rad], shape (nq,).
        q_goal: Goal configuration [rad], shape (nq,).
        duration: Duration [s], or None for the minimum time within the scaled limits.
        speed: Share of the joint velocity limits in (0, 1], or None for
            :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
        profile: ``trapezoid``, ``quintic``, ``cubic``, ``scurve`` or ``time_optimal``.

    Raises:
        InfeasibleError: an ``scurve`` or ``time_optimal`` ``duration`` the limits cannot meet
            (the message states the minimum).
        KinplanError: an unknown profile or a speed outside (0, 1].
    """
    if profile not in PTP_PROFILES:
        raise KinplanError(f"unknown profile {profile!r}; choose one of {', '.join(PTP_PROFILES)}")
    if speed is not None and not (0 < speed <= 1):
        raise KinplanError(f"ptp speed is a share of the joint limits in (0, 1], got {speed}")
    limit = robot.velocity_limit
    limit = np.where(np.isfinite(limit), limit, FALLBACK_JOINT_SPEED)
    max_velocity = limit * (DEFAULT_PTP_SPEED if speed is None else float(speed))
    max_acceleration = max_velocity / PTP_RAMP_TIME
    q0 = q_start
    if profile in ("scurve", "time_optimal"):
        velocity, acceleration = motion_limits(robot, duration, speed)
        if profile == "scurve":
            return trajectory.scurve(
                q0, q_goal, velocity, acceleration, acceleration / PTP_JERK_TIME, duration
            )
        return trajectory.time_optimal([q0, q_goal], velocity, acceleration, 0.0, duration)
    if profile == "trapezoid":
        if duration is None:
            return trajectory.trapezoid(
                q0, q_goal, max_velocity=max_velocity, max_acceleration=max_acceleration
            )
        return trajectory.trapezoid(q0, q_goal, duration=duration)
    if duration is None:
        distance = np.abs(q_goal - q0)
        duration = polynomial_duration(distance, max_velocity, max_acceleration, profile)
    if duration == 0.0:  # nothing moves
        return trajectory.trapezoid(q0, q_goal, max_velocity=1.0, max_acceleration=1.0)
    build = trajectory.quintic if profile == "quintic" else trajectory.cubic
    return build(q0, q_goal, duration)


def motion_limits(
    robot: Robot, duration: float | None, speed: float | None
) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration limits of a ptp timed by the robot's limits (``scurve``,
    ``time_optimal``, ``spline``): ``speed`` × the robot's limits (all of them when a duration
    is given), the trapezoid's ramp time where the robot has no acceleration limit.

    Returns:
        (velocity [rad/s], acceleration [rad/s²]), each shape (nq,).
    """
    limit = robot.velocity_limit
    limit = np.where(np.isfinite(limit), limit, FALLBACK_JOINT_SPEED)
    share = DEFAULT_PTP_SPEED if speed is None else float(speed)
    share = 1.0 if duration is not None else share
    velocity = limit * share
    known = robot.acceleration_limit
    acceleration = np.where(np.isfinite(known), known * share, velocity / PTP_RAMP_TIME)
    return velocity, acceleration


def ptp_through_trajectory(
    robot: Robot,
    points: np.ndarray,
    duration: float | None,
    speed: float | None,
    profile: str,
    blend: float = 0.0,
    times: Sequence[float] | None = None,
) -> Trajectory:
    """The joint trajectory of a ``ptp`` through several points, one motion rest to rest.

    Args:
        robot: The arm.
        points: The start configuration then the points to pass [rad], shape (m, nq).
        duration: Duration [s], or None for the minimum time within the scaled limits.
        speed: Share of the joint velocity and acceleration limits in (0, 1], or None for
            :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
        profile: ``time_optimal`` (:func:`kinplan.trajectory.time_optimal`, corners within
            ``blend``) or ``spline`` (:func:`kinplan.trajectory.spline`).
        blend: Largest deviation from a corner [rad] (``time_optimal``).
        times: ``spline``: the times [s] at which it passes ``points[1:]`` (the clamped cubic
            spline through them, :func:`kinplan.trajectory.cubic_via`); None: chord-length
            knot times, timed by the limits.

    Raises:
        InfeasibleError: a ``duration`` shorter than the limits allow (states the minimum).
        KinplanError: an unknown profile, a speed outside (0, 1], or a blend with ``spline``.
    """
    if speed is not None and not (0 < speed <= 1):
        raise KinplanError(f"ptp speed is a share of the joint limits in (0, 1], got {speed}")
    velocity, acceleration = motion_limits(robot, duration, speed)
    if profile == "time_optimal":
        return trajectory.time_optimal(points, velocity, acceleration, blend, duration)
    if profile == "spline":
        if blend:
            raise KinplanError("a spline passes through its points: blend goes with time_optimal")
        if times is not None:
            if len(times) != len(points) - 1:
                raise KinplanError(
                    f"expected {len(points) - 1} times, one per point, got {len(times)}"
                )
            return trajectory.cubic_via(points, [0.0, *times])
        return trajectory.spline(points, velocity, acceleration, duration)
    if times is not None:
        raise KinplanError("times go with profile spline")
    raise KinplanError(
        f"a ptp through several points is time_optimal or spline, got profile {profile!r}"
    )


def polynomial_duration(
    distance: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray, profile: str
) -> float:
    """Shortest duration of a rest-to-rest cubic/quintic within the speed and acceleration
    limits: peak speed k_v Δ/T, peak acceleration k_a Δ/T².

    Args:
        distance: |Δq| per joint [rad].
        max_velocity: Speed limit per joint [rad/s].
        max_acceleration: Acceleration limit per joint [rad/s²].
        profile: ``cubic`` or ``quintic``.

    Returns:
        The duration [s] (0 when nothing moves).
    """
    k_v, k_a = REST_TO_REST_PEAKS[profile]
    times = np.maximum(k_v * distance / max_velocity, np.sqrt(k_a * distance / max_acceleration))
    return float(times.max(initial=0.0))


def peak_speed_ratio(robot: Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> float:
    """Largest joint speed over its limit: the rates at the samples and the mean speeds
    between them (:func:`kinplan.sampling.joint_speeds`).

    Args:
        robot: The arm (its velocity limits; joints without one are left out).
        t: Sample times [s], shape (N,).
        q: Joint positions [rad], shape (N, nq).
        qd: Joint velocities [rad/s], shape (N, nq).

    Returns:
        The ratio [-] (0 without samples or limits).
    """
    if qd.size == 0:
        return 0.0
    limit = robot.velocity_limit
    finite = np.isfinite(limit)
    if not finite.any():
        return 0.0
    speeds = joint_speeds(q, qd, t)
    return float(np.max(speeds[:, finite] / limit[finite]))
