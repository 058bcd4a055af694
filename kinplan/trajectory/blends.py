"""Linear segments with parabolic blends (LSPB): :func:`trapezoid` (from a duration, or
minimum time within limits, every joint synchronised to the slowest) and :func:`trapezoid_via`
(through via points, Craig; or exactly through them with pseudo via points)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinplan.errors import InfeasibleError, InputError
from kinplan.trajectory import _profiles
from kinplan.trajectory.arguments import (
    checked_blend_time,
    describe,
    duration_value,
    joint_vectors,
    knot_times,
    magnitudes,
    point_rows,
    positive_array,
)
from kinplan.trajectory.core import Trajectory, Waypoints, from_pieces

__all__ = ["DEFAULT_BLEND_FRACTION", "trapezoid", "trapezoid_via"]

DEFAULT_BLEND_FRACTION = 1.0 / 3.0
"""Blend time of :func:`trapezoid` given only a duration, as a fraction of it [-].

T/3 splits the motion into equal accelerating, cruising and decelerating thirds (cruise speed
1.5 |Δ|/T, acceleration 4.5 |Δ|/T²), the default of Corke's ``lspb``/``trapezoidal``.
"""


def trapezoid(
    q0: ArrayLike,
    qf: ArrayLike,
    duration: float | None = None,
    acceleration: ArrayLike | None = None,
    max_velocity: ArrayLike | None = None,
    max_acceleration: ArrayLike | None = None,
    blend_time: float | None = None,
) -> Trajectory:
    """Linear segment with parabolic blends (trapezoidal velocity), at rest at both ends.

    Give one of these combinations:

    - ``duration`` and ``acceleration`` (blend magnitude, scalar or per joint): the classic LSPB,
      blend time ``t_a = T/2 − sqrt(a²T² − 4a|Δ|)/(2a)`` per joint. Needs ``a ≥ 4|Δ|/T²``
      (equality is the triangular profile, no cruise).
    - ``duration`` and ``blend_time`` (0 < t_b ≤ T/2, common to every joint).
    - ``duration`` alone: blend time T/3 (:data:`DEFAULT_BLEND_FRACTION`).
    - ``max_velocity`` and ``max_acceleration`` (scalar or per joint): minimum time. Each joint's
      own minimum time is found (triangular when its cruise speed is not reached); every joint
      then takes the slowest one's duration, so all start and stop together, each within its
      own limits (a joint takes the slowest joint's blend time where its limits allow, so the
      joints switch together, otherwise the nearest admissible one). With ``duration`` as well,
      the motion lasts ``duration``, which must be at least the minimum time.

    Joints that do not move stay still; negative moves work. Moves smaller than 1e-150 rad
    (``_profiles.NEGLIGIBLE_MOVE``) are planned as still and the motion still ends exactly at qf.

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        duration: Motion time, > 0 [s].
        acceleration: Blend acceleration magnitude [rad/s²].
        max_velocity: Velocity limit, > 0 [rad/s]. The motion never exceeds it, not even by
            rounding (it is planned a few units of rounding below it).
        max_acceleration: Acceleration limit, > 0 [rad/s²]; never exceeded either.
        blend_time: Blend (acceleration) time [s].

    Returns:
        A trajectory of quadratic segments (one knot wherever any joint switches phase).

    Raises:
        InputError: an unsupported combination of arguments, bad shapes or values (as for
            :func:`cubic`; limits and accelerations within [:data:`MIN_MAGNITUDE`,
            :data:`MAX_MAGNITUDE`]).
        InfeasibleError: an acceleration below 4|Δ|/T² (the message states the minimum), or a
            duration shorter than the limits allow (the message states the minimum time).
    """
    q0, qf = joint_vectors(q0=q0, qf=qf)
    n = q0.size
    target = _profiles.without_negligible_moves(q0, qf)
    distance = np.abs(target - q0)
    if max_velocity is not None or max_acceleration is not None:
        if max_velocity is None or max_acceleration is None:
            raise InputError("give both max_velocity and max_acceleration for a minimum-time move")
        if acceleration is not None or blend_time is not None:
            raise InputError(
                "max_velocity/max_acceleration cannot be combined with acceleration or "
                "blend_time; give the limits, or a duration with an acceleration or blend time"
            )
        max_velocity = magnitudes(max_velocity, "max_velocity", n)
        max_acceleration = magnitudes(max_acceleration, "max_acceleration", n)
        requested = None if duration is None else duration_value(duration, "duration")
        knots, coefficients = _synchronised(q0, target, max_velocity, max_acceleration, requested)
        return from_pieces(knots, coefficients, end=qf, end_velocity=np.zeros(n))
    if duration is None:
        raise InputError(
            "trapezoid needs a duration (with an acceleration, a blend_time or neither), "
            "or max_velocity and max_acceleration for a minimum-time move"
        )
    duration = duration_value(duration, "duration")
    if acceleration is not None and blend_time is not None:
        raise InputError("give acceleration or blend_time, not both")
    if acceleration is not None:
        acceleration = magnitudes(acceleration, "acceleration", n)
        _profiles.check_lspb_acceleration(distance, duration, acceleration)
        blend = _profiles.lspb_blend_time(distance, duration, acceleration)
    else:
        fraction = DEFAULT_BLEND_FRACTION * duration
        given = None if blend_time is None else checked_blend_time(blend_time, duration)
        blend = np.full(n, fraction if given is None else given)
    knots, coefficients = _profiles.lspb_pieces(q0, target, duration, blend)
    return from_pieces(knots, coefficients, end=qf, end_velocity=np.zeros(n))


def trapezoid_via(
    points: ArrayLike,
    durations: ArrayLike,
    acceleration: ArrayLike,
    pass_through: bool = False,
) -> Trajectory:
    """Linear segments with parabolic blends through via points, at rest at both ends (Craig).

    Between the points the motion is linear; at each via point a parabolic blend of magnitude
    ``acceleration`` joins the two lines, centred on the point's nominal time, so the motion
    passes near the via point but not through it and never stops there. The first and last
    blends start and end at rest inside their segment, so the motion lasts ``sum(durations)``.

    With ``pass_through=True`` two pseudo via points are put around each via point k, at
    ``± δ_k`` in time with ``δ_k = min(durations[k-1], durations[k]) / 4``, on the line through
    the via point whose slope is the velocity heuristic (mean of the neighbouring chord slopes, 0
    where the motion turns). The blends happen at the pseudo via points, so the motion is on that
    line at the via point's nominal time: it passes through it exactly.

    Args:
        points: Positions, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
        durations: Nominal time from point k to point k + 1, shape (m − 1,), each > 0 [s].
        acceleration: Blend acceleration magnitude, scalar or per joint, > 0 [rad/s²].
        pass_through: Insert pseudo via points so the motion passes every via point (a bool).

    Returns:
        A trajectory of quadratic segments; its waypoints are the points at their nominal times.

    Raises:
        InputError: bad shapes or types, NaN or inf, durations out of range or so far apart
            that one is lost in the rounding of their sum, accelerations out of range.
        InfeasibleError: a blend does not fit (the message names the via point and the joint,
            the time needed and available, and what to change).
    """
    points = point_rows(points, "points")
    m, n = points.shape
    durations = positive_array(durations, "durations", m - 1)
    acceleration = magnitudes(acceleration, "acceleration", n)
    if not isinstance(pass_through, (bool, np.bool_)):
        raise InputError(f"pass_through must be True or False, got {describe(pass_through)}")
    times = knot_times(durations)
    waypoints = Waypoints(times, points)
    if m == 2:  # no via point: the classic LSPB
        target = _profiles.without_negligible_moves(points[0], points[1])
        distance = np.abs(target - points[0])
        _profiles.check_lspb_acceleration(distance, times[-1], acceleration)
        blend = _profiles.lspb_blend_time(distance, times[-1], acceleration)
        knots, coefficients = _profiles.lspb_pieces(points[0], target, times[-1], blend)
    else:
        if pass_through:
            corners, corner_times, names, span_names, half = _pseudo_via_points(points, times)
        else:
            corners, corner_times = points, times
            names = [f"point {k}" for k in range(m)]
            span_names = [f"durations[{k}]" for k in range(m - 1)]
        breaks, accelerations, widths = _profiles.blend_phases(
            corners, corner_times, acceleration, names, span_names
        )
        if pass_through:
            _check_through_via_points(widths, half)
        knots, coefficients = _profiles.constant_acceleration_pieces(
            corners[0], breaks, accelerations
        )
    return from_pieces(
        knots, coefficients, waypoints=waypoints, end=points[-1], end_velocity=np.zeros(n)
    )


def _synchronised(
    q0: np.ndarray,
    qf: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    requested: float | None,
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Knots [s] and coefficients of the synchronised minimum-time LSPB (or lasting ``requested``).

    A requested duration within rounding (relative 1e-12) of the minimum time is taken as the
    minimum time.
    """
    distance = np.abs(qf - q0)
    own = _profiles.lspb_minimum_times(distance, max_velocity, max_acceleration)
    slowest = int(np.argmax(own))
    if requested is not None and requested < own[slowest] * (1.0 - _profiles.RELATIVE_TOLERANCE):
        least = _profiles.round_up(float(own[slowest]))
        raise InfeasibleError(
            f"duration {requested:.6g} s is too short: joint {slowest} needs at least "
            f"{least:.6g} s to move {distance[slowest]:.6g} rad within max_velocity "
            f"{max_velocity[slowest]:.6g} rad/s and max_acceleration "
            f"{max_acceleration[slowest]:.6g} rad/s²; give a duration of at least "
            f"{least:.6g} s or raise the limits"
        )
    duration = _profiles.synchronised_minimum_time(distance, max_velocity, max_acceleration)
    if requested is not None:
        duration = max(requested, duration)
    return _profiles.synchronised_lspb(q0, qf, duration, max_velocity, max_acceleration)


def _pseudo_via_points(
    points: np.ndarray, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray, list[str], list[str], np.ndarray]:
    """Corners for ``pass_through``: each via point replaced by two pseudo via points.

    Returns:
        Corner positions (2m − 2, n) [rad], corner times (2m − 2,) [s], corner names and span
        names for messages, and the half-widths δ (m − 2,) [s] of the lines through the via points.
    """
    m, n = points.shape
    slopes = _profiles.heuristic_velocities(points, times, np.zeros(n), np.zeros(n))[1:-1]
    spans = np.diff(times)
    half = 0.25 * np.minimum(spans[:-1], spans[1:])
    via_times = times[1:-1]
    pseudo = np.empty((2 * (m - 2), n))
    pseudo[0::2] = points[1:-1] - slopes * half[:, None]
    pseudo[1::2] = points[1:-1] + slopes * half[:, None]
    pseudo_times = np.empty(2 * (m - 2))
    pseudo_times[0::2] = via_times - half
    pseudo_times[1::2] = via_times + half
    corners = np.vstack([points[0], pseudo, points[-1]])
    corner_times = np.concatenate([[0.0], pseudo_times, [times[-1]]])
    names = ["point 0"]
    span_names = ["durations[0]"]
    for k in range(1, m - 1):
        names += [f"the pseudo via point before point {k}", f"the pseudo via point after point {k}"]
        span_names += [f"durations[{k - 1}] and durations[{k}]", f"durations[{k}]"]
    names.append(f"point {m - 1}")
    return corners, corner_times, names, span_names, half


def _check_through_via_points(widths: np.ndarray, half: np.ndarray) -> None:
    """Raise InfeasibleError when a pseudo via point's blend reaches over its via point."""
    for k, delta in enumerate(half, start=1):
        for side, row in (("before", 2 * k - 1), ("after", 2 * k)):
            needed = 0.5 * widths[row]
            for j in np.flatnonzero(needed > delta * (1.0 + _profiles.RELATIVE_TOLERANCE)):
                raise InfeasibleError(
                    f"joint {j}: the blend at the pseudo via point {side} point {k} needs "
                    f"{needed[j]:.6g} s on that side of point {k} but only {delta:.6g} s is "
                    f"available, so the motion would miss point {k}; raise the acceleration or "
                    f"lengthen durations[{k - 1}] and durations[{k}]"
                )
