"""Trapezoidal velocity profiles: linear segments with parabolic blends (LSPB), rest to rest and
synchronised within every joint's limits, and Craig's blends through via points (private; after
:mod:`~kinplan.trajectory._profiles.basics` and :mod:`~kinplan.trajectory._profiles.piecewise` in
:mod:`kinplan.trajectory._profiles`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from kinplan.errors import InfeasibleError
from kinplan.trajectory._profiles.basics import (
    LIMIT_MARGIN,
    NEGLIGIBLE_MOVE,
    RELATIVE_TOLERANCE,
    Pieces,
    round_up,
)
from kinplan.trajectory._profiles.piecewise import constant_acceleration_pieces

# ----------------------------------------------------------------------------------------------
# Piecewise-constant acceleration (trapezoidal velocity profiles and parabolic blends)
# ----------------------------------------------------------------------------------------------


def lspb_blend_time(distance: np.ndarray, duration: float, acceleration: np.ndarray) -> np.ndarray:
    """Blend time of the classic LSPB from its acceleration (the lecture's quadratic in t_a).

    ``t_a = T/2 − sqrt(a²T² − 4a|Δ|) / (2a)``, evaluated in the cancellation-free form
    ``2|Δ| / (aT + sqrt(a²T² − 4a|Δ|))``. The discriminant is clipped at 0, so call it only after
    checking ``a ≥ 4|Δ|/T²``.

    Args:
        distance: Move magnitudes |qf − q0|, shape (n,) [rad].
        duration: Motion time T [s].
        acceleration: Blend acceleration magnitudes, shape (n,) [rad/s²].

    Returns:
        Blend times, shape (n,) [s], in [0, T/2].
    """
    a_t = acceleration * duration
    root = np.sqrt(np.maximum(a_t**2 - 4.0 * acceleration * distance, 0.0))
    return np.minimum(2.0 * distance / (a_t + root), 0.5 * duration)


def check_lspb_acceleration(
    distance: np.ndarray, duration: float, acceleration: np.ndarray
) -> None:
    """Raise InfeasibleError when a joint's acceleration is below 4|Δ|/T².

    Args:
        distance: Move magnitudes |qf − q0|, shape (n,) [rad].
        duration: Motion time T [s].
        acceleration: Blend acceleration magnitudes, shape (n,) [rad/s²].
    """
    minimum = 4.0 * distance / duration**2
    for j in np.flatnonzero(acceleration < minimum * (1.0 - RELATIVE_TOLERANCE)):
        raise InfeasibleError(
            f"joint {j}: acceleration {acceleration[j]:.6g} rad/s² is too low for a "
            f"{distance[j]:.6g} rad move in {duration:.6g} s; it must be at least "
            f"{round_up(minimum[j]):.6g} rad/s² (4|qf-q0|/T²); raise the acceleration or the "
            "duration"
        )


def lspb_pieces(q0: np.ndarray, qf: np.ndarray, duration: float, blend: np.ndarray) -> Pieces:
    """Linear segment with parabolic blends of length ``blend`` per joint, rest to rest.

    Args:
        q0: Start positions, shape (n,) [rad].
        qf: End positions, shape (n,) [rad].
        duration: Motion time T [s].
        blend: Blend (acceleration) time per joint, shape (n,), in (0, T/2] for moving joints [s].

    Returns:
        Knots and coefficient arrays of shape (n, 3).
    """
    delta = qf - q0
    moving = delta != 0.0
    blend = np.where(moving, blend, 0.0)
    acc = np.divide(delta, blend * (duration - blend), out=np.zeros_like(delta), where=moving)
    breaks = np.stack(
        [np.zeros_like(blend), blend, duration - blend, np.full_like(blend, duration)]
    )
    accelerations = np.stack([acc, np.zeros_like(acc), -acc], axis=1)
    return constant_acceleration_pieces(q0, breaks.T, accelerations)


def lspb_minimum_times(
    distance: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray
) -> np.ndarray:
    """Each joint's own minimum time of a rest-to-rest move within its limits.

    Triangular (``2 sqrt(|Δ|/a)``) when the cruise speed is not reached (``|Δ| < v²/a``),
    otherwise ``|Δ|/v + v/a``.

    Returns:
        Minimum times, shape (n,) [s]; 0 for joints that do not move.
    """
    reaches_cruise = distance >= max_velocity**2 / max_acceleration
    return np.where(
        reaches_cruise,
        distance / max_velocity + max_velocity / max_acceleration,
        2.0 * np.sqrt(distance / max_acceleration),
    )


def _limit_ratio(
    distance: np.ndarray,
    duration: float,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    blend: np.ndarray,
) -> np.ndarray:
    """Largest of cruise speed / max_velocity and acceleration / max_acceleration per joint [-].

    The cruise speed of an LSPB of duration T with blend t is ``|Δ|/(T − t)`` and its blend
    acceleration ``|Δ|/(t (T − t))``; both are evaluated directly (no cancellation for t ≤ T/2).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        rest = duration - blend
        speed = distance / (rest * max_velocity)
        acceleration = distance / (blend * rest * max_acceleration)
    ratio = np.maximum(speed, acceleration)
    return np.where(distance > 0.0, np.nan_to_num(ratio, nan=np.inf), 0.0)


def synchronised_minimum_time(
    distance: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray
) -> float:
    """Shortest common duration of the synchronised LSPB [s], planned for the limits reduced by
    :data:`LIMIT_MARGIN` (longer than the slowest joint's own minimum time by about 1e-15
    relative); 0 when nothing moves."""
    reduced = 1.0 - LIMIT_MARGIN
    own = lspb_minimum_times(distance, max_velocity * reduced, max_acceleration * reduced)
    return float(np.max(own))


def synchronised_blend_times(
    distance: np.ndarray,
    duration: float,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    reference_joint: int,
) -> np.ndarray:
    """Blend times that make every joint last ``duration`` within its own limits.

    For duration T, a joint's admissible blend times form the interval [lo, hi]: ``lo`` is the
    blend time at its maximum acceleration (a shorter blend needs more) and
    ``hi = min(T/2, T − |Δ|/v_max)`` (a longer blend needs a higher cruise speed). The reference
    joint (the slowest) takes its blend at maximum acceleration, exactly ``min(v/a, sqrt(|Δ|/a))``
    when T is its own minimum time (the quadratic for ``lo`` has a double root there, where
    solving it would lose half the digits); every joint takes that blend time clipped to its own
    interval, so the joints switch together whenever their limits allow it. T must be at least
    every joint's minimum time.

    Where rounding makes ``hi < lo`` (a joint at both limits) the end whose limits are better
    kept wins: ``lo`` is accurate when t ≪ T (``hi = T − |Δ|/v`` cancels there), ``hi`` near
    T/2 (the quadratic for ``lo`` is ill-conditioned there); both are evaluated and the one with
    the smaller excess over the limits is taken.

    Args:
        distance: Move magnitudes |qf − q0|, shape (n,) [rad].
        duration: Common motion time T [s], at least every joint's minimum time.
        max_velocity: Velocity limits, shape (n,) [rad/s].
        max_acceleration: Acceleration limits, shape (n,) [rad/s²].
        reference_joint: The joint whose own minimum time is the longest.

    Returns:
        Blend times, shape (n,) [s].
    """
    lo = lspb_blend_time(distance, duration, max_acceleration)
    hi = np.minimum(0.5 * duration, duration - distance / max_velocity)
    r = reference_joint
    own = lspb_minimum_times(
        distance[r : r + 1], max_velocity[r : r + 1], max_acceleration[r : r + 1]
    )
    if duration <= own[0]:
        target = min(
            max_velocity[r] / max_acceleration[r], math.sqrt(distance[r] / max_acceleration[r])
        )
    else:
        target = lo[r]
    blend = np.minimum(np.maximum(target, lo), hi)
    conflict = lo > hi
    if np.any(conflict):
        at_lo = _limit_ratio(distance, duration, max_velocity, max_acceleration, lo)
        at_hi = _limit_ratio(distance, duration, max_velocity, max_acceleration, hi)
        blend = np.where(conflict, np.where(at_lo <= at_hi, lo, hi), blend)
    return blend


def peak_rates(knots: np.ndarray, coefficients: Sequence[np.ndarray]) -> tuple[np.ndarray, ...]:
    """Largest |velocity| and |acceleration| of quadratic pieces, rounded as they are sampled.

    The velocity of a quadratic piece is linear in τ, so its extremes are at the ends of the
    piece; it is evaluated as :meth:`kinplan.trajectory.Trajectory.sample` does (Horner on
    ``[c1, 2 c2]`` at τ = 0 and τ = t1 − t0, in floating point), and floating-point rounding is
    monotonic, so no sample in between exceeds these values.

    Args:
        knots: Knot times, shape (S + 1,) [s].
        coefficients: S arrays of shape (n, 3).

    Returns:
        Peak speeds and peak acceleration magnitudes, each of shape (n,) [rad/s, rad/s²].
    """
    c = np.stack(coefficients)  # (S, n, 3)
    doubled = 2.0 * c[:, :, 2]
    at_end = doubled * np.diff(knots)[:, None] + c[:, :, 1]
    speed = np.maximum(np.abs(c[:, :, 1]), np.abs(at_end)).max(axis=0)
    return speed, np.abs(doubled).max(axis=0)


def synchronised_lspb(
    q0: np.ndarray,
    qf: np.ndarray,
    duration: float,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
) -> Pieces:
    """LSPB of every joint lasting ``duration``, never exceeding the limits, not even by rounding.

    The timing is planned for limits reduced by :data:`LIMIT_MARGIN` (a few units of rounding),
    and the pieces are then checked as they will be sampled (:func:`peak_rates`). In the rare case
    that rounding still pushes a joint over a limit (knots of different joints merged within
    rounding), the motion is slowed by a few more units of rounding until none is exceeded.

    Args:
        q0: Start positions, shape (n,) [rad].
        qf: End positions, shape (n,) [rad].
        duration: Motion time [s], at least :func:`lspb_minimum_times` for the reduced limits.
        max_velocity: Velocity limits, shape (n,) [rad/s].
        max_acceleration: Acceleration limits, shape (n,) [rad/s²].

    Returns:
        Knots and coefficient arrays of shape (n, 3); the last knot is ``duration`` unless it
        had to be stretched (by at most a few units of rounding in practice).
    """
    distance = np.abs(qf - q0)
    if duration == 0.0:  # nothing moves
        return lspb_pieces(q0, qf, 0.0, np.zeros_like(distance))
    velocity = max_velocity * (1.0 - LIMIT_MARGIN)
    acceleration = max_acceleration * (1.0 - LIMIT_MARGIN)
    reference = int(np.argmax(lspb_minimum_times(distance, velocity, acceleration)))
    stretch = LIMIT_MARGIN
    for _ in range(64):
        blend = synchronised_blend_times(distance, duration, velocity, acceleration, reference)
        knots, coefficients = lspb_pieces(q0, qf, duration, blend)
        speed, peak = peak_rates(knots, coefficients)
        if np.all(speed <= max_velocity) and np.all(peak <= max_acceleration):
            return knots, coefficients
        duration *= 1.0 + stretch
        stretch *= 2.0
    raise InfeasibleError(  # unreachable: each pass slows the motion by twice as much
        "the synchronised trapezoid could not be kept within the limits against rounding; "
        "give slightly lower max_velocity or max_acceleration"
    )


# ----------------------------------------------------------------------------------------------
# Linear segments with parabolic blends through via points (Craig)
# ----------------------------------------------------------------------------------------------


def _end_blend(distance: np.ndarray, span: float, acceleration: np.ndarray) -> np.ndarray:
    """Blend time at a rest end of a segment: ``t = d − sqrt(d² − 2|Δ|/a)``, the blend of the
    rest-to-rest LSPB over 2|Δ| in 2d, of which this end is the first half."""
    return lspb_blend_time(2.0 * distance, 2.0 * span, acceleration)


def _check_end_segment(
    distance: np.ndarray, span: float, acceleration: np.ndarray, where: str, durations_name: str
):
    minimum = 2.0 * distance / span**2
    for j in np.flatnonzero(acceleration < minimum * (1.0 - RELATIVE_TOLERANCE)):
        raise InfeasibleError(
            f"joint {j}: acceleration {acceleration[j]:.6g} rad/s² is too low to {where} "
            f"({distance[j]:.6g} rad in {span:.6g} s); it must be at least "
            f"{round_up(minimum[j]):.6g} "
            f"rad/s² (2|Δ|/t²); raise the acceleration or lengthen {durations_name}"
        )


def blend_phases(
    points: np.ndarray,
    times: np.ndarray,
    acceleration: np.ndarray,
    names: Sequence[str],
    span_names: Sequence[str],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Craig's linear segments with parabolic blends, at rest at both ends.

    The blend at an inner corner k is centred on its nominal time, lasts
    ``|v[k] − v[k−1]| / a`` and does not pass through the corner. The first and last blends start
    or end at rest inside their segment, so the whole motion lasts ``times[-1]``.

    Args:
        points: Corner positions, shape (m, n), m ≥ 3 [rad].
        times: Nominal corner times, strictly increasing from 0, shape (m,) [s].
        acceleration: Blend acceleration magnitudes, shape (n,) [rad/s²].
        names: How to call each corner in messages, length m.
        span_names: How to call each span in messages (what the user can lengthen), length m − 1.

    Returns:
        ``breaks`` (n, 2m) and ``accelerations`` (n, 2m − 1) for
        :func:`constant_acceleration_pieces`, and the blend widths (m, n) [s].

    Raises:
        InfeasibleError: an end blend needs more than its segment, or two blends overlap.
    """
    spans = np.diff(times)
    delta = np.diff(points, axis=0)
    delta[np.abs(delta) <= NEGLIGIBLE_MOVE] = 0.0
    distance = np.abs(delta)
    _check_end_segment(distance[0], spans[0], acceleration, f"leave {names[0]}", span_names[0])
    _check_end_segment(
        distance[-1], spans[-1], acceleration, f"stop at {names[-1]}", span_names[-1]
    )
    first = _end_blend(distance[0], spans[0], acceleration)
    last = _end_blend(distance[-1], spans[-1], acceleration)
    velocity = delta / spans[:, None]
    velocity[0] = delta[0] / (spans[0] - 0.5 * first)
    velocity[-1] = delta[-1] / (spans[-1] - 0.5 * last)
    change = np.vstack([velocity[0], np.diff(velocity, axis=0), -velocity[-1]])
    widths = np.abs(change) / acceleration
    widths[0], widths[-1] = first, last
    _check_linear_parts(widths, spans, names, span_names)
    blend_acc = np.divide(change, widths, out=np.zeros_like(change), where=widths > 0.0)
    centres = times[:, None] + np.zeros_like(widths)
    centres[0] = 0.5 * first
    centres[-1] = times[-1] - 0.5 * last
    starts = centres - 0.5 * widths
    ends = centres + 0.5 * widths
    breaks = np.empty((points.shape[1], 2 * points.shape[0]))
    breaks[:, 0::2] = starts.T
    breaks[:, 1::2] = ends.T
    breaks[:, 0], breaks[:, -1] = 0.0, times[-1]
    breaks = np.clip(np.maximum.accumulate(breaks, axis=1), 0.0, times[-1])
    accelerations = np.zeros((points.shape[1], 2 * points.shape[0] - 1))
    accelerations[:, 0::2] = blend_acc.T
    return breaks, accelerations, widths


def _check_linear_parts(
    widths: np.ndarray, spans: np.ndarray, names: Sequence[str], span_names: Sequence[str]
):
    """Raise InfeasibleError when two neighbouring blends overlap (negative linear part)."""
    share = np.full(widths.shape[0], 0.5)
    share[0] = share[-1] = 1.0  # the end blends lie wholly inside their segment
    needed = share[:-1, None] * widths[:-1] + share[1:, None] * widths[1:]
    slack = RELATIVE_TOLERANCE * max(float(np.sum(spans)), 1.0)
    for k, j in zip(*np.nonzero(needed > spans[:, None] + slack), strict=True):
        raise InfeasibleError(
            f"joint {j}: the blends at {names[k]} and {names[k + 1]} need {needed[k, j]:.6g} s "
            f"but only {spans[k]:.6g} s separate them; raise the acceleration or lengthen "
            f"{span_names[k]}"
        )
