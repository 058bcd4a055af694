"""Polynomial profiles: :func:`cubic`, :func:`quintic`, :func:`cubic_via` (splines through via
points), :func:`four_three_four` and :func:`spline` (through points, timed by the limits)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinplan.errors import InfeasibleError, InputError
from kinplan.trajectory import _profiles
from kinplan.trajectory.arguments import (
    checked_via_velocities,
    duration_value,
    increasing_times,
    joint_vectors,
    knot_times,
    magnitudes,
    point_rows,
    positive_array,
)
from kinplan.trajectory.core import (
    Segment,
    Trajectory,
    Waypoints,
    check_rates_continuous,
    from_pieces,
)

__all__ = ["cubic", "cubic_via", "four_three_four", "quintic", "spline"]


def cubic(
    q0: ArrayLike, qf: ArrayLike, duration: float, v0: ArrayLike = 0.0, vf: ArrayLike = 0.0
) -> Trajectory:
    """One cubic per joint from (q0, v0) to (qf, vf) in ``duration``.

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        duration: Motion time, > 0 [s].
        v0: Start velocity [rad/s].
        vf: End velocity [rad/s].

    Returns:
        A one-segment trajectory of degree 3.

    Raises:
        InputError: not numbers, mismatched lengths, NaN or inf, values beyond
            :data:`MAX_MAGNITUDE`, or a duration outside [:data:`MIN_DURATION`,
            :data:`MAX_DURATION`].
    """
    q0, qf, v0, vf = joint_vectors(q0=q0, qf=qf, v0=v0, vf=vf)
    duration = duration_value(duration, "duration")
    segment = Segment(0.0, duration, _profiles.hermite_cubic(q0, qf, v0, vf, duration))
    return Trajectory([segment], end=qf, end_velocity=vf)


def quintic(
    q0: ArrayLike,
    qf: ArrayLike,
    duration: float,
    v0: ArrayLike = 0.0,
    vf: ArrayLike = 0.0,
    a0: ArrayLike = 0.0,
    af: ArrayLike = 0.0,
) -> Trajectory:
    """One quintic per joint from (q0, v0, a0) to (qf, vf, af) in ``duration``.

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        duration: Motion time, > 0 [s].
        v0: Start velocity [rad/s].
        vf: End velocity [rad/s].
        a0: Start acceleration [rad/s²].
        af: End acceleration [rad/s²].

    Returns:
        A one-segment trajectory of degree 5.

    Raises:
        InputError: not numbers, mismatched lengths, NaN or inf, values beyond
            :data:`MAX_MAGNITUDE`, or a duration outside [:data:`MIN_DURATION`,
            :data:`MAX_DURATION`].
    """
    q0, qf, v0, vf, a0, af = joint_vectors(q0=q0, qf=qf, v0=v0, vf=vf, a0=a0, af=af)
    duration = duration_value(duration, "duration")
    coefficients = _profiles.quintic_coefficients(q0, qf, v0, vf, a0, af, duration)
    return Trajectory(
        [Segment(0.0, duration, coefficients)], end=qf, end_velocity=vf, end_acceleration=af
    )


def cubic_via(
    points: ArrayLike,
    times: ArrayLike,
    v0: ArrayLike = 0.0,
    vf: ArrayLike = 0.0,
    via_velocities: ArrayLike | str | None = None,
) -> Trajectory:
    """One cubic per segment through every point.

    By default the velocities at the via points are chosen so that velocity and acceleration
    are continuous there (the clamped cubic spline: one tridiagonal solve for all joints).

    Args:
        points: Positions to pass, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
        times: Strictly increasing times of the points, shape (m,) [s]. They may start at any
            t0: the trajectory's time 0 is ``times[0]`` (segment durations are what count).
        v0: Velocity at the first point [rad/s].
        vf: Velocity at the last point [rad/s].
        via_velocities: ``None`` (continuous acceleration); ``"heuristic"`` (mean of the
            neighbouring chord slopes, 0 where the slope changes sign; velocity continuous,
            acceleration not); or the velocities at the m − 2 via points, shape (m − 2, n), or
            (m − 2,) for one joint, or (n,) for one via point; ``[]`` when m = 2 [rad/s].

    Returns:
        A trajectory of m − 1 cubic segments, waypoints at the given points.

    Raises:
        InputError: not numbers, bad shapes, NaN or inf, values beyond :data:`MAX_MAGNITUDE`,
            times that do not strictly increase, or steps between them outside
            [:data:`MIN_DURATION`, :data:`MAX_DURATION`].
    """
    points = point_rows(points, "points")
    m, n = points.shape
    times = increasing_times(times, m)
    v0, vf = joint_vectors(n=n, v0=v0, vf=vf)
    if via_velocities is None:
        velocities = _profiles.spline_velocities(points, times, v0, vf)
    elif isinstance(via_velocities, str):
        if via_velocities != "heuristic":
            raise InputError(
                f"via_velocities must be None, 'heuristic' or an array, got {via_velocities!r}"
            )
        velocities = _profiles.heuristic_velocities(points, times, v0, vf)
    else:
        velocities = np.vstack([v0, checked_via_velocities(via_velocities, m, n), vf])
    knots, coefficients = _profiles.hermite_pieces(points, times, velocities)
    return from_pieces(
        knots,
        coefficients,
        waypoints=Waypoints(times - times[0], points),
        end=points[-1],
        end_velocity=vf,
    )


def four_three_four(
    q0: ArrayLike,
    q_lift: ArrayLike,
    q_set: ArrayLike,
    qf: ArrayLike,
    durations: ArrayLike,
) -> Trajectory:
    """The 4-3-4 profile: lift-off (degree 4), travel (degree 3), set-down (degree 4).

    Passes the four points at the knots, velocity and acceleration continuous there, at rest
    (zero velocity and acceleration) at both ends. One 14 × 14 solve serves every joint.

    Args:
        q0: Start position [rad].
        q_lift: Lift-off position, reached after ``durations[0]`` [rad].
        q_set: Set-down position, reached ``durations[1]`` later [rad].
        qf: End position, reached ``durations[2]`` later [rad].
        durations: The three segment durations, each > 0 [s].

    Returns:
        A trajectory of three segments of degrees 4, 3 and 4.

    Raises:
        InputError: mismatched lengths, NaN or inf, durations out of range, or durations so far
            apart (a factor of about 1e7) that the solve cannot meet the conditions to 1e-9.
    """
    q0, q_lift, q_set, qf = joint_vectors(q0=q0, q_lift=q_lift, q_set=q_set, qf=qf)
    durations = positive_array(durations, "durations", 3)
    knots = knot_times(durations)
    try:
        coefficients = _profiles.four_three_four_coefficients([q0, q_lift, q_set, qf], durations)
    except np.linalg.LinAlgError as error:
        raise InputError(
            f"durations {durations.tolist()} s are too far apart for the 4-3-4 solve; give "
            "durations within a factor of about 1e6 of each other"
        ) from error
    check_rates_continuous(coefficients, durations)
    zero = np.zeros(q0.size)
    return from_pieces(
        knots,
        coefficients,
        waypoints=Waypoints(knots, np.vstack([q0, q_lift, q_set, qf])),
        end=qf,
        end_velocity=zero,
        end_acceleration=zero,
    )


def spline(
    points: ArrayLike,
    max_velocity: ArrayLike,
    max_acceleration: ArrayLike,
    duration: float | None = None,
) -> Trajectory:
    """A smooth motion through joint-space points: the clamped cubic spline, timed by the limits.

    The knot times are proportional to the chord lengths (Euclidean distance over the joints
    between consecutive points), so the shape in joint space does not depend on the timing; the
    spline is at rest at both ends, with velocity and acceleration continuous at every point
    (:func:`cubic_via`). The time scale is then the smallest that keeps every joint within its
    velocity and acceleration limits (peaks computed exactly per cubic, not sampled), or the
    given ``duration``. Scaling time by k divides the velocities by k and the accelerations by
    k², so the geometry stays the same.

    Args:
        points: Joint-space points, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
            Consecutive duplicates (within 1e-12 rad of each other) are dropped; when every
            point is the same, the motion has zero duration (or stands still for ``duration``).
        max_velocity: Velocity limit, scalar or per joint, > 0 [rad/s].
        max_acceleration: Acceleration limit, scalar or per joint, > 0 [rad/s²].
        duration: Motion time [s]; default the minimum within the limits.

    Returns:
        A trajectory of cubic segments, one per pair of consecutive (distinct) points, with the
        points as waypoints.

    Raises:
        InputError: bad shapes or values, non-positive or NaN limits.
        InfeasibleError: ``duration`` shorter than the limits allow (the message states the
            minimum time and the joint that sets it).
    """
    points = point_rows(points, "points")
    n = points.shape[1]
    max_velocity = magnitudes(max_velocity, "max_velocity", n)
    max_acceleration = magnitudes(max_acceleration, "max_acceleration", n)
    requested = None if duration is None else duration_value(duration, "duration")
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    points = points[np.concatenate(([True], steps > 1e-12))]
    zero = np.zeros(n)
    if len(points) < 2:
        if requested is None:
            return Trajectory([Segment(0.0, 0.0, points[0][:, None].copy())])
        return cubic(points[0], points[0], requested)
    chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
    unit_times = np.concatenate(([0.0], np.cumsum(chords / chords.sum())))
    velocities = _profiles.spline_velocities(points, unit_times, zero, zero)
    speed, acceleration = _profiles.hermite_peaks(points, unit_times, velocities)
    # time scale k: peak speed / k and peak acceleration / k² within the limits
    by_speed = speed / max_velocity
    by_acceleration = np.sqrt(acceleration / max_acceleration)
    minimum = float(max(by_speed.max(), by_acceleration.max()))
    if requested is not None and requested < minimum * (1.0 - 1e-12):
        j = int(np.argmax(np.maximum(by_speed, by_acceleration)))
        what = "velocity" if by_speed[j] >= by_acceleration[j] else "acceleration"
        raise InfeasibleError(
            f"duration {requested:g} s is too short for this spline: joint {j} would exceed its "
            f"{what} limit; the minimum is {minimum:.6g} s"
        )
    scale = minimum * (1.0 + 1e-12) if requested is None else requested
    times = unit_times * scale
    return cubic_via(points, times)
