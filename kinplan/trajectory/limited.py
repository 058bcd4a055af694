"""Profiles timed by kinematic limits: :func:`scurve` (jerk-limited point to point) and
:func:`time_optimal` (the fastest motion through waypoints under velocity and acceleration
limits, TOTG; the method is in :mod:`kinplan.trajectory.totg`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from kinplan.errors import InfeasibleError, InputError
from kinplan.trajectory import _profiles
from kinplan.trajectory.arguments import (
    check_magnitudes,
    duration_value,
    joint_vectors,
    magnitudes,
    point_rows,
    scalar_value,
)
from kinplan.trajectory.core import Trajectory, Waypoints, from_pieces

__all__ = ["scurve", "time_optimal"]


def scurve(
    q0: ArrayLike,
    qf: ArrayLike,
    max_velocity: ArrayLike,
    max_acceleration: ArrayLike,
    max_jerk: ArrayLike,
    duration: float | None = None,
) -> Trajectory:
    """Jerk-limited (seven-phase S-curve) point-to-point motion, at rest at both ends.

    Each joint's own minimum-time profile is found in closed form (jerk up, constant
    acceleration, jerk down, cruise, and the mirror image; phases drop out when the joint does
    not reach its velocity or acceleration limit), the same duration as ruckig's for one degree
    of freedom. Every joint then takes the slowest joint's duration, so all start and stop
    together within their own limits: a joint takes the slowest joint's phase times (the joints
    switch together and move on the straight line in joint space) where its limits allow, and
    otherwise its own profile stretched in time, which divides its speed, acceleration and jerk
    by s, s² and s³ for a stretch s ≥ 1. The limits are never exceeded, not even by rounding
    (the motion is planned a few units of rounding below them, 16 ulp relative, and checked as
    sampled).

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        max_velocity: Velocity limit, scalar or per joint, > 0 [rad/s].
        max_acceleration: Acceleration limit, scalar or per joint, > 0 [rad/s²].
        max_jerk: Jerk limit, scalar or per joint, > 0 [rad/s³].
        duration: Motion time [s]; default the minimum time. A longer duration stretches the
            slowest joint's profile in time.

    Returns:
        A trajectory of cubic segments (one knot wherever any joint switches phase), acceleration
        continuous, jerk piecewise constant; zero duration when nothing moves.

    Raises:
        InputError: bad shapes or values, non-positive or NaN limits (as for :func:`trapezoid`).
        InfeasibleError: ``duration`` shorter than the limits allow (the message states the
            minimum time).
    """
    q0, qf = joint_vectors(q0=q0, qf=qf)
    n = q0.size
    max_velocity = magnitudes(max_velocity, "max_velocity", n)
    max_acceleration = magnitudes(max_acceleration, "max_acceleration", n)
    max_jerk = magnitudes(max_jerk, "max_jerk", n)
    requested = None if duration is None else duration_value(duration, "duration")
    target = _profiles.without_negligible_moves(q0, qf)
    distance = np.abs(target - q0)
    limits = (max_velocity, max_acceleration, max_jerk)
    own = _profiles.scurve_minimum_times(distance, *limits)
    slowest = int(np.argmax(own))
    if requested is not None:
        _check_requested_duration(requested, own[slowest], slowest, distance, limits)
    reduced = [limit * (1.0 - _profiles.LIMIT_MARGIN) for limit in limits]
    minimum = float(np.max(_profiles.scurve_minimum_times(distance, *reduced)))
    duration = minimum if requested is None else max(requested, minimum)
    knots, coefficients = _profiles.synchronised_scurve(q0, target, duration, *limits)
    zero = np.zeros(n)
    return from_pieces(knots, coefficients, end=qf, end_velocity=zero, end_acceleration=zero)


def time_optimal(
    points: ArrayLike,
    max_velocity: ArrayLike,
    max_acceleration: ArrayLike,
    max_deviation: float = 0.0,
    duration: float | None = None,
) -> Trajectory:
    """Time-optimal motion along a joint-space path through waypoints (TOTG), rest to rest.

    The path (Kunz & Stilman 2012) is made of straight lines between the points, each corner
    replaced by a circular blend that passes within ``max_deviation`` of it (Euclidean norm over
    the joints); with ``max_deviation=0`` the path goes exactly through every point and the
    motion stops at each corner (a corner that reverses the direction stops too; points on a
    straight line are passed without stopping). The timing is the fastest one that keeps every
    joint within its velocity and acceleration limits; see :mod:`kinplan.trajectory.totg` for the
    method, the representation and its accuracy (lines exact; blends as quintics that keep the
    path to 1e-12 rad, planned 1e-4 below the limits and checked on dense samples).

    Args:
        points: Joint-space points, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
            Consecutive duplicates (closer than 1e-12 rad) are dropped; when every point is the
            same, the result is a motion of zero duration (or of ``duration``, standing still).
        max_velocity: Velocity limit, scalar or per joint, > 0 [rad/s].
        max_acceleration: Acceleration limit, scalar or per joint, > 0 [rad/s²].
        max_deviation: Largest distance of the path from a corner, ≥ 0 [rad].
        duration: Motion time [s]; default the minimum. A longer duration plays the optimal
            timing uniformly slower.

    Returns:
        A trajectory of quadratic (lines) and quintic (blends) segments; its waypoints are the
        points at the times the motion is nearest them.

    Raises:
        InputError: bad shapes or values, non-positive or NaN limits, a negative or NaN
            ``max_deviation``.
        InfeasibleError: ``duration`` shorter than the limits allow (the message states the
            minimum time).
    """
    from kinplan.trajectory import totg  # builds on this module's profiles

    points = point_rows(points, "points")
    n = points.shape[1]
    max_velocity = magnitudes(max_velocity, "max_velocity", n)
    max_acceleration = magnitudes(max_acceleration, "max_acceleration", n)
    deviation = scalar_value(max_deviation, "max_deviation")
    if deviation < 0.0:
        raise InputError(f"max_deviation must be >= 0 rad, got {deviation}")
    check_magnitudes(np.asarray(deviation), "max_deviation")
    requested = None if duration is None else duration_value(duration, "duration")
    plan = totg.plan(points, max_velocity, max_acceleration, deviation, requested)
    return from_pieces(
        plan.knots,
        plan.coefficients,
        waypoints=Waypoints(plan.waypoint_times(), plan.path.points),
        end=points[-1],
        end_velocity=np.zeros(n),
    )  # the end acceleration is the braking one, as for the minimum-time trapezoid


def _check_requested_duration(
    requested: float,
    least: float,
    joint: int,
    distance: np.ndarray,
    limits: Sequence[np.ndarray],
) -> None:
    """InfeasibleError stating the minimum time when ``requested`` is below ``least`` (relative
    slack :data:`~kinplan.trajectory._profiles.RELATIVE_TOLERANCE` for rounding)."""
    if requested >= least * (1.0 - _profiles.RELATIVE_TOLERANCE):
        return
    names = ("max_velocity", "max_acceleration", "max_jerk")
    units = ("rad/s", "rad/s²", "rad/s³")
    parts = [
        f"{name} {limit[joint]:.6g} {unit}"
        for name, limit, unit in zip(names, limits, units, strict=False)
    ]
    within = ", ".join(parts[:-1]) + f" and {parts[-1]}"
    rounded = _profiles.round_up(float(least))
    raise InfeasibleError(
        f"duration {requested:.6g} s is too short: joint {joint} needs at least {rounded:.6g} s "
        f"to move {distance[joint]:.6g} rad within {within}; give a duration of at least "
        f"{rounded:.6g} s or raise the limits"
    )
