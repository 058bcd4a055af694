"""Profile mathematics behind :mod:`kinplan.trajectory` (private).

Every function works on all joints at once: a joint quantity is an array of shape (n,), a list of
points has shape (m, n). Polynomial coefficients have shape (n, degree + 1), lowest power first,
in the segment's local time τ = t − t0. Inputs are already validated by the caller; only the
feasibility of the timing is checked here (:class:`~kinplan.errors.InfeasibleError`).

Joints are numbered from 0 in messages, as in the arrays.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from kinplan.errors import InfeasibleError

#: The 1-D time laws every planner offers.
PROFILES = ("trapezoid", "quintic", "cubic")
#: The time laws of joint-space point-to-point moves: the 1-D ones, the jerk-limited S-curve and
#: the time-optimal timing under velocity and acceleration limits.
PTP_PROFILES = (*PROFILES, "scurve", "time_optimal")
#: Peaks of a rest-to-rest cubic / quintic over |Δ| in time T: speed k_v |Δ|/T and acceleration
#: k_a |Δ|/T², as (k_v, k_a).
REST_TO_REST_PEAKS = {"cubic": (1.5, 6.0), "quintic": (15.0 / 8.0, 10.0 / math.sqrt(3.0))}

Pieces = tuple[np.ndarray, list[np.ndarray]]
"""Knot times, shape (S + 1,) starting at 0 [s], and S coefficient arrays of shape (n, d + 1)."""

RELATIVE_TOLERANCE = 1e-12
"""Relative slack for feasibility tests, against rounding [-]."""

KNOT_MERGE_TOLERANCE = 64.0 * np.finfo(float).eps
"""Phase boundaries of different joints closer than this fraction of the duration are merged
into one knot [-]: a few units of rounding of the duration, so that merging moves no phase by
more than rounding, whatever the ratio of the shortest phase to the whole motion."""

LIMIT_MARGIN = 16.0 * np.finfo(float).eps
"""Relative margin below velocity and acceleration limits that a minimum-time profile is planned
for, so that the rounding of building and sampling it never exceeds the limits [-]."""

NEGLIGIBLE_MOVE = 1e-150
"""Moves smaller than this [rad or m] are planned as no move by the trapezoidal profiles: their
blend times and accelerations would fall into the subnormal range, where quotients lose their
digits. The trajectory still ends exactly at its target (the end state is given)."""


def without_negligible_moves(q0: np.ndarray, qf: np.ndarray) -> np.ndarray:
    """``qf`` with every joint that moves less than :data:`NEGLIGIBLE_MOVE` put back at ``q0``."""
    return np.where(np.abs(qf - q0) > NEGLIGIBLE_MOVE, qf, q0)


def round_up(value: float, digits: int = 6) -> float:
    """``value`` > 0 rounded up to ``digits`` significant digits.

    A minimum stated in a message this way is itself feasible when the caller copies it.
    """
    rounded = float(f"{value:.{digits}g}")
    if rounded >= value:
        return rounded
    unit = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return float(f"{rounded + unit:.{digits}g}")


def round_down(value: float, digits: int = 6) -> float:
    """``value`` > 0 rounded down to ``digits`` significant digits (a largest speed stated in a
    message: copied, it is still within what was planned)."""
    rounded = float(f"{value:.{digits}g}")
    if rounded <= value:
        return rounded
    unit = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return float(f"{rounded - unit:.{digits}g}")


# ----------------------------------------------------------------------------------------------
# Polynomials fixed by boundary conditions
# ----------------------------------------------------------------------------------------------


def hermite_cubic(
    q0: np.ndarray, q1: np.ndarray, v0: np.ndarray, v1: np.ndarray, h: float
) -> np.ndarray:
    """Cubic with given positions [rad] and velocities [rad/s] at τ = 0 and τ = h [s]."""
    slope = (q1 - q0) / h
    a2 = (3.0 * slope - 2.0 * v0 - v1) / h
    a3 = (v0 + v1 - 2.0 * slope) / h**2
    return np.stack([q0, v0, a2, a3], axis=1)


def quintic_coefficients(
    q0: np.ndarray,
    q1: np.ndarray,
    v0: np.ndarray,
    v1: np.ndarray,
    a0: np.ndarray,
    a1: np.ndarray,
    h: float | np.ndarray,
) -> np.ndarray:
    """Quintic with given position, velocity and acceleration at τ = 0 and τ = h [s]."""
    d = q1 - q0
    c3 = (20.0 * d - (8.0 * v1 + 12.0 * v0) * h - (3.0 * a0 - a1) * h**2) / (2.0 * h**3)
    c4 = (-30.0 * d + (14.0 * v1 + 16.0 * v0) * h + (3.0 * a0 - 2.0 * a1) * h**2) / (2.0 * h**4)
    c5 = (12.0 * d - 6.0 * (v1 + v0) * h + (a1 - a0) * h**2) / (2.0 * h**5)
    return np.stack([q0, v0, 0.5 * a0, c3, c4, c5], axis=1)


# ----------------------------------------------------------------------------------------------
# Cubic splines through via points
# ----------------------------------------------------------------------------------------------


def solve_tridiagonal(
    lower: np.ndarray, diagonal: np.ndarray, upper: np.ndarray, rhs: np.ndarray
) -> np.ndarray:
    """Thomas algorithm for a diagonally dominant tridiagonal system, all columns at once.

    Args:
        lower: Sub-diagonal, shape (k,); ``lower[0]`` is unused.
        diagonal: Main diagonal, shape (k,).
        upper: Super-diagonal, shape (k,); ``upper[-1]`` is unused.
        rhs: Right-hand sides, shape (k, n).

    Returns:
        The solution, shape (k, n).
    """
    k = diagonal.size
    c = np.zeros(k)
    d = np.zeros_like(rhs, dtype=float)
    c[0] = upper[0] / diagonal[0]
    d[0] = rhs[0] / diagonal[0]
    for i in range(1, k):
        pivot = diagonal[i] - lower[i] * c[i - 1]
        c[i] = upper[i] / pivot
        d[i] = (rhs[i] - lower[i] * d[i - 1]) / pivot
    for i in range(k - 2, -1, -1):
        d[i] -= c[i] * d[i + 1]
    return d


def spline_velocities(
    points: np.ndarray, times: np.ndarray, v0: np.ndarray, vf: np.ndarray
) -> np.ndarray:
    """Knot velocities of the clamped cubic spline (acceleration continuous at every via point).

    Continuity of acceleration at via point i, with h = durations of the adjacent segments, gives
    ``h[i] v[i-1] + 2 (h[i-1] + h[i]) v[i] + h[i-1] v[i+1]
    = 3 (h[i] s[i-1] + h[i-1] s[i])`` where ``s`` are the chord slopes.

    Args:
        points: Positions, shape (m, n) [rad].
        times: Strictly increasing knot times, shape (m,) [s].
        v0: Start velocity, shape (n,) [rad/s].
        vf: End velocity, shape (n,) [rad/s].

    Returns:
        Velocities at every knot, shape (m, n) [rad/s], ``v0`` and ``vf`` at the ends.
    """
    h = np.diff(times)
    slopes = np.diff(points, axis=0) / h[:, None]
    velocities = np.vstack([v0, np.zeros((points.shape[0] - 2, points.shape[1])), vf])
    if points.shape[0] > 2:
        rhs = 3.0 * (h[1:, None] * slopes[:-1] + h[:-1, None] * slopes[1:])
        rhs[0] -= h[1] * v0
        rhs[-1] -= h[-2] * vf
        velocities[1:-1] = solve_tridiagonal(h[1:], 2.0 * (h[:-1] + h[1:]), h[:-1], rhs)
    return velocities


def heuristic_velocities(
    points: np.ndarray, times: np.ndarray, v0: np.ndarray, vf: np.ndarray
) -> np.ndarray:
    """Knot velocities by the heuristic: mean of the neighbouring chord slopes, 0 at a turn.

    Returns:
        Velocities at every knot, shape (m, n) [rad/s], ``v0`` and ``vf`` at the ends; at a via
        point where the slope changes sign (or either slope is 0) the velocity is 0.
    """
    slopes = np.diff(points, axis=0) / np.diff(times)[:, None]
    before, after = slopes[:-1], slopes[1:]
    inner = np.where(np.sign(before) * np.sign(after) > 0, 0.5 * (before + after), 0.0)
    return np.vstack([v0, inner, vf])


def hermite_peaks(
    points: np.ndarray, times: np.ndarray, velocities: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Exact peak |velocity| and |acceleration| per joint of Hermite cubics through knots.

    On a segment of duration h the acceleration is linear, from a₀ = (6Δ/h − 4v₀ − 2v₁)/h to
    a₁ = (−6Δ/h + 2v₀ + 4v₁)/h, so its peak is at a knot; the velocity is quadratic, with its
    extreme v₀ + a₀τ*/2 where the acceleration crosses zero at τ* = h a₀/(a₀ − a₁).

    Args:
        points: Positions, shape (m, n) [rad].
        times: Strictly increasing knot times, shape (m,) [s].
        velocities: Knot velocities, shape (m, n) [rad/s].

    Returns:
        (peak speed, peak acceleration), each shape (n,) [rad/s, rad/s²].
    """
    h = np.diff(times)[:, None]
    delta = np.diff(points, axis=0)
    v0, v1 = velocities[:-1], velocities[1:]
    a0 = (6.0 * delta / h - 4.0 * v0 - 2.0 * v1) / h
    a1 = (-6.0 * delta / h + 2.0 * v0 + 4.0 * v1) / h
    crossing = a0 * a1 < 0.0
    tau = np.where(crossing, h * a0 / np.where(crossing, a0 - a1, 1.0), 0.0)
    inner = np.where(crossing, np.abs(v0 + 0.5 * a0 * tau), 0.0)
    speed = np.max(np.vstack([np.abs(velocities), inner]), axis=0)
    acceleration = np.max(np.vstack([np.abs(a0), np.abs(a1)]), axis=0)
    return speed, acceleration


def hermite_pieces(points: np.ndarray, times: np.ndarray, velocities: np.ndarray) -> Pieces:
    """One Hermite cubic per segment through ``points`` with the given knot velocities."""
    coefficients = [
        hermite_cubic(points[k], points[k + 1], velocities[k], velocities[k + 1], h)
        for k, h in enumerate(np.diff(times))
    ]
    return times - times[0], coefficients


# ----------------------------------------------------------------------------------------------
# Piecewise-constant acceleration (trapezoidal velocity profiles and parabolic blends)
# ----------------------------------------------------------------------------------------------


def merged_knots(breaks: np.ndarray) -> np.ndarray:
    """Sorted union of every joint's phase boundaries, knots closer than rounding merged.

    Args:
        breaks: Phase boundaries per joint, shape (n, K + 1), from 0 to the common duration [s].

    Returns:
        Knot times from 0 to the duration exactly, shape (S + 1,) [s].
    """
    duration = float(breaks[0, -1])
    candidates = np.sort(breaks, axis=None).tolist()  # repeated values are skipped below
    tolerance = KNOT_MERGE_TOLERANCE * duration
    knots = [0.0]
    for t in candidates:
        if t - knots[-1] > tolerance and duration - t > tolerance:
            knots.append(t)
    knots.append(duration)  # [0, 0] for a motion of zero duration: one empty segment
    return np.asarray(knots)


def constant_derivative_pieces(
    q0: np.ndarray,
    breaks: np.ndarray,
    values: np.ndarray,
    order: int,
    spans: np.ndarray | None = None,
) -> Pieces:
    """Polynomial segments of a motion whose ``order``-th derivative is piecewise constant.

    Every joint has K phases; joint j's ``order``-th derivative is ``values[j, k]`` between
    ``breaks[j, k]`` and ``breaks[j, k + 1]`` (phases may be empty). The state at each phase
    start is the Taylor expansion of the previous phase, summed as running totals; the joints'
    phase boundaries are merged into common knots (:func:`merged_knots`), and on each merged
    interval every joint is one polynomial of degree ``order``.

    Args:
        q0: Start position, shape (n,) [rad]; the motion starts at rest (every derivative below
            ``order`` is 0).
        breaks: Non-decreasing phase boundaries, shape (n, K + 1), from 0 to the duration [s].
        values: The ``order``-th derivative in each phase, shape (n, K) [rad/s^order].
        order: 2 for piecewise-constant acceleration, 3 for piecewise-constant jerk.
        spans: The phase durations, shape (n, K) [s]; default ``diff(breaks)``. Give them when
            they are known: the difference of two rounded boundaries loses the digits of a
            short phase after a long one (a jerk phase of 1e-6 s after 100 s of constant
            acceleration keeps only 8 of them), and the motion would not come to rest.

    Returns:
        Knots and coefficient arrays of shape (n, order + 1).
    """
    spans = np.diff(breaks, axis=1) if spans is None else spans
    starts: list[np.ndarray] = [np.empty(0)] * order  # derivative d at each phase start
    for d in range(order - 1, -1, -1):
        increment = np.zeros_like(spans)
        for i in range(1, order - d):
            increment = increment + starts[d + i][:, :-1] * spans**i / math.factorial(i)
        if order - d == 1:
            increment = values * spans
        else:
            increment = increment + values * spans ** (order - d) / math.factorial(order - d)
        initial = q0[:, None] if d == 0 else np.zeros((q0.size, 1))
        totals = np.cumsum(increment, axis=1)
        starts[d] = np.concatenate([initial, initial + totals if d == 0 else totals], axis=1)
    knots = merged_knots(breaks)
    joints = np.arange(q0.size)[None, :]
    middles = 0.5 * (knots[:-1] + knots[1:])
    phase = np.sum(breaks[None, :, 1:-1] <= middles[:, None, None], axis=2)  # (S, n)
    top = values[joints, phase]
    s = knots[:-1, None] - breaks[joints, phase]
    coefficients = []
    for d in range(order):
        value = starts[d][joints, phase]
        for i in range(1, order - d):
            value = value + starts[d + i][joints, phase] * s**i / math.factorial(i)
        value = value + top * s ** (order - d) / math.factorial(order - d)
        coefficients.append(value / math.factorial(d))
    coefficients.append(top / math.factorial(order))
    return knots, list(np.stack(coefficients, axis=2))


def constant_acceleration_pieces(
    q0: np.ndarray, breaks: np.ndarray, accelerations: np.ndarray
) -> Pieces:
    """Quadratic segments of a motion with piecewise-constant acceleration, from rest.

    :func:`constant_derivative_pieces` of order 2.

    Args:
        q0: Start position, shape (n,) [rad]; the motion starts at rest.
        breaks: Non-decreasing phase boundaries, shape (n, K + 1), from 0 to the duration [s].
        accelerations: Phase accelerations, shape (n, K) [rad/s²].

    Returns:
        Knots and coefficient arrays of shape (n, 3).
    """
    return constant_derivative_pieces(q0, breaks, accelerations, 2)


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
# Piecewise-constant jerk (seven-phase S-curves)
# ----------------------------------------------------------------------------------------------

SCURVE_JERK_SIGNS = np.array([1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 1.0])
"""Jerk of the seven phases of a rest-to-rest S-curve, in units of its peak jerk [-]: jerk up,
constant acceleration, jerk down, cruise, and the mirror image."""


def scurve_phase_times(
    distance: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    max_jerk: np.ndarray,
) -> np.ndarray:
    """Phase times of each joint's own minimum-time rest-to-rest seven-phase profile.

    The profile is symmetric: jerk phases of ``t_j``, constant-acceleration phases of ``t_a``
    and one cruise of ``t_v``, duration ``4 t_j + 2 t_a + t_v``. With V, A, J the limits and
    D = |Δ| (closed forms, no iteration):

    - the ramp to V takes ``t_j = min(A/J, sqrt(V/J))`` and ``t_a = max(V/A − A/J, 0)``; when
      ``D ≥ V (2 t_j + t_a)`` the joint cruises at V for ``t_v = D/V − (2 t_j + t_a)``;
    - otherwise, when ``D ≥ 2 A³/J²``, it reaches A but not V: peak speed ``v_p`` solves
      ``v_p²/A + v_p A/J = D`` (taken in the cancellation-free form
      ``v_p = 2D / (A/J + sqrt((A/J)² + 4D/A))``), ``t_j = A/J``, ``t_a = v_p/A − A/J``;
    - otherwise it reaches neither: ``t_j = (D / 2J)^(1/3)``, ``t_a = t_v = 0``.

    Args:
        distance: Move magnitudes |qf − q0|, shape (n,) [rad].
        max_velocity: Velocity limits, shape (n,) [rad/s].
        max_acceleration: Acceleration limits, shape (n,) [rad/s²].
        max_jerk: Jerk limits, shape (n,) [rad/s³].

    Returns:
        ``(t_j, t_a, t_v)`` per joint, shape (n, 3) [s]; zeros for joints that do not move.
    """
    v, a, j = max_velocity, max_acceleration, max_jerk
    ramp_jerk = np.minimum(a / j, np.sqrt(v / j))
    ramp_constant = np.maximum(v / a - a / j, 0.0)
    ramp = 2.0 * ramp_jerk + ramp_constant
    cruises = distance >= v * ramp
    b = a / j
    peak = 2.0 * distance / (b + np.sqrt(b**2 + 4.0 * distance / a))
    reaches_acceleration = distance >= 2.0 * a**3 / j**2
    t_j = np.where(
        cruises, ramp_jerk, np.where(reaches_acceleration, b, np.cbrt(0.5 * distance / j))
    )
    t_a = np.where(
        cruises,
        ramp_constant,
        np.where(reaches_acceleration, np.maximum(peak / a - b, 0.0), 0.0),
    )
    t_v = np.where(cruises, np.maximum(distance / v - ramp, 0.0), 0.0)
    return np.stack([t_j, t_a, t_v], axis=1)


def scurve_durations(phase_times: np.ndarray) -> np.ndarray:
    """Durations ``4 t_j + 2 t_a + t_v`` of seven-phase profiles, shape (n,) [s]."""
    return 4.0 * phase_times[:, 0] + 2.0 * phase_times[:, 1] + phase_times[:, 2]


def scurve_peaks(distance: np.ndarray, phase_times: np.ndarray) -> tuple[np.ndarray, ...]:
    """Peak speed, acceleration and jerk of rest-to-rest seven-phase profiles over ``distance``.

    The jerk follows from the phase times and the distance, ``D = J t_j (t_j + t_a)
    (2 t_j + t_a + t_v)``, so a profile built with it ends exactly (up to rounding) at D for any
    phase times; peak acceleration ``J t_j``, peak speed ``D / (2 t_j + t_a + t_v)``.

    Returns:
        Peak speeds, accelerations and jerks, each of shape (n,) [rad/s, rad/s², rad/s³]; 0 for
        joints that do not move.
    """
    t_j, t_a, t_v = phase_times.T
    moving = distance > 0.0
    half = 2.0 * t_j + t_a + t_v
    jerk = np.divide(distance, t_j * (t_j + t_a) * half, out=np.zeros_like(distance), where=moving)
    speed = np.divide(distance, half, out=np.zeros_like(distance), where=moving)
    return speed, jerk * t_j, jerk


def scurve_pieces(
    q0: np.ndarray, qf: np.ndarray, phase_times: np.ndarray, duration: float
) -> Pieces:
    """Cubic segments of rest-to-rest seven-phase profiles with the given phase times.

    Args:
        q0: Start positions, shape (n,) [rad].
        qf: End positions, shape (n,) [rad].
        phase_times: ``(t_j, t_a, t_v)`` per joint, shape (n, 3), every moving joint's phases
            lasting ``duration`` together (up to rounding) [s].
        duration: Motion time [s]; joints that do not move stay still for that long.

    Returns:
        Knots and coefficient arrays of shape (n, 4) (one knot wherever a joint switches phase).
    """
    delta = qf - q0
    _, _, jerk = scurve_peaks(np.abs(delta), phase_times)
    t_j, t_a, t_v = phase_times.T
    spans = np.stack([t_j, t_a, t_j, t_v, t_j, t_a, t_j], axis=1)
    breaks = np.hstack([np.zeros((q0.size, 1)), np.cumsum(spans, axis=1)])
    breaks[:, -1] = max(duration, float(breaks[:, -2].max()))  # one common end
    jerks = (np.sign(delta) * jerk)[:, None] * SCURVE_JERK_SIGNS[None, :]
    return constant_derivative_pieces(q0, breaks, jerks, 3, spans)


def cubic_peak_rates(
    knots: np.ndarray, coefficients: Sequence[np.ndarray]
) -> tuple[np.ndarray, ...]:
    """Largest |velocity|, |acceleration| and |jerk| of cubic pieces, evaluated as sampled.

    The acceleration of a cubic piece is linear in τ (extremes at the ends of the piece), its
    velocity quadratic (extremes at the ends or at the vertex τ = −c2 / (3 c3)). Each is
    evaluated by Horner's rule on ``[c1, 2 c2, 3 c3]`` and ``[2 c2, 6 c3]``, as
    :meth:`kinplan.trajectory.Trajectory.sample` does.

    Args:
        knots: Knot times, shape (S + 1,) [s].
        coefficients: S arrays of shape (n, 4).

    Returns:
        Peak speeds, accelerations and jerks, each of shape (n,) [rad/s, rad/s², rad/s³].
    """
    c = np.stack(coefficients)  # (S, n, 4)
    h = np.diff(knots)[:, None]
    velocity = c[:, :, 1:] * np.array([1.0, 2.0, 3.0])
    acceleration = c[:, :, 2:] * np.array([2.0, 6.0])
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = -c[:, :, 2] / (3.0 * c[:, :, 3])
    inside = np.isfinite(vertex) & (vertex > 0.0) & (vertex < h)
    vertex = np.where(inside, vertex, 0.0)

    def speed_at(tau: np.ndarray) -> np.ndarray:
        return np.abs((velocity[:, :, 2] * tau + velocity[:, :, 1]) * tau + velocity[:, :, 0])

    speed = np.maximum(np.maximum(speed_at(0.0 * h), speed_at(h)), speed_at(vertex))
    at_end = np.abs(acceleration[:, :, 1] * h + acceleration[:, :, 0])
    peak_acceleration = np.maximum(np.abs(acceleration[:, :, 0]), at_end)
    return speed.max(axis=0), peak_acceleration.max(axis=0), np.abs(6.0 * c[:, :, 3]).max(axis=0)


def scurve_minimum_times(
    distance: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    max_jerk: np.ndarray,
) -> np.ndarray:
    """Each joint's own minimum time of a rest-to-rest seven-phase move, shape (n,) [s]."""
    return scurve_durations(scurve_phase_times(distance, max_velocity, max_acceleration, max_jerk))


def synchronised_scurve(
    q0: np.ndarray,
    qf: np.ndarray,
    duration: float,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    max_jerk: np.ndarray,
) -> Pieces:
    """Seven-phase profile of every joint lasting ``duration``, within every joint's limits.

    The profiles are planned for limits reduced by :data:`LIMIT_MARGIN`. The slowest joint (the
    reference) takes its own minimum-time profile stretched in time to ``duration``; stretching
    by a factor s ≥ 1 divides speed, acceleration and jerk by s, s² and s³, so a stretched
    profile stays within the limits it was planned for. Every other joint takes the reference's
    phase times (so the joints switch together and move on the straight line in joint space)
    when its speed, acceleration and jerk stay within its own limits that way, otherwise its own
    minimum-time profile stretched to ``duration``. The pieces are then checked as they will be
    sampled (:func:`cubic_peak_rates`); if rounding still pushes a joint over a limit, the
    motion is slowed by a few more units of rounding, as in :func:`synchronised_lspb`.

    Args:
        q0: Start positions, shape (n,) [rad].
        qf: End positions, shape (n,) [rad].
        duration: Motion time [s], at least every joint's minimum time for the reduced limits.
        max_velocity: Velocity limits, shape (n,) [rad/s].
        max_acceleration: Acceleration limits, shape (n,) [rad/s²].
        max_jerk: Jerk limits, shape (n,) [rad/s³].

    Returns:
        Knots and coefficient arrays of shape (n, 4).
    """
    distance = np.abs(qf - q0)
    if not np.any(distance > 0.0):  # nothing moves
        return scurve_pieces(q0, qf, np.zeros((q0.size, 3)), duration)
    reduced = 1.0 - LIMIT_MARGIN
    limits = (max_velocity * reduced, max_acceleration * reduced, max_jerk * reduced)
    own = scurve_phase_times(distance, *limits)
    own_durations = scurve_durations(own)
    reference = int(np.argmax(own_durations))
    stretch = LIMIT_MARGIN
    for _ in range(64):
        with np.errstate(divide="ignore", invalid="ignore"):
            stretched = own * (duration / own_durations)[:, None]
        stretched[distance == 0.0] = 0.0
        together = np.broadcast_to(stretched[reference], own.shape)
        peaks = scurve_peaks(distance, together)
        fits = np.all([p <= lim for p, lim in zip(peaks, limits, strict=True)], axis=0)
        phase_times = np.where(fits[:, None], together, stretched)
        knots, coefficients = scurve_pieces(q0, qf, phase_times, duration)
        sampled = cubic_peak_rates(knots, coefficients)
        within = (max_velocity, max_acceleration, max_jerk)
        if all(np.all(p <= lim) for p, lim in zip(sampled, within, strict=True)):
            return knots, coefficients
        duration *= 1.0 + stretch
        stretch *= 2.0
    raise InfeasibleError(  # unreachable: each pass slows the motion by twice as much
        "the synchronised S-curve could not be kept within the limits against rounding; "
        "give slightly lower max_velocity, max_acceleration or max_jerk"
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


# ----------------------------------------------------------------------------------------------
# 4-3-4
# ----------------------------------------------------------------------------------------------


def _power_row(degree: int, tau: float, derivative: int) -> np.ndarray:
    """The ``derivative``-th derivative of [1, τ, τ², ..., τ^degree] at ``tau``."""
    row = np.zeros(degree + 1)
    for power in range(derivative, degree + 1):
        row[power] = math.perm(power, derivative) * tau ** (power - derivative)
    return row


def four_three_four_coefficients(
    q: Sequence[np.ndarray], durations: Sequence[float] | np.ndarray
) -> list[np.ndarray]:
    """Coefficients of the 4-3-4 profile through four points, at rest at both ends.

    14 unknowns (5 + 4 + 5): positions at both ends of every segment (6), zero velocity and
    acceleration at the start and the end (4), continuity of velocity and acceleration at the two
    inner knots (4). The matrix depends only on the durations, so one solve serves every joint.

    Args:
        q: Start, lift-off, set-down and end positions, each of shape (n,) [rad].
        durations: The three segment durations [s].

    Returns:
        Coefficient arrays of shapes (n, 5), (n, 4), (n, 5).
    """
    degrees = (4, 3, 4)
    offsets = (0, 5, 9)
    h1, h2, h3 = durations

    def row(segment: int, tau: float, derivative: int) -> np.ndarray:
        out = np.zeros(14)
        start, degree = offsets[segment], degrees[segment]
        out[start : start + degree + 1] = _power_row(degree, tau, derivative)
        return out

    zero = np.zeros_like(q[0])
    equations = [
        (row(0, 0.0, 0), q[0]),  # start position, at rest
        (row(0, 0.0, 1), zero),
        (row(0, 0.0, 2), zero),
        (row(0, h1, 0), q[1]),  # lift-off, from both sides
        (row(1, 0.0, 0), q[1]),
        (row(1, h2, 0), q[2]),  # set-down, from both sides
        (row(2, 0.0, 0), q[2]),
        (row(2, h3, 0), q[3]),  # end position, at rest
        (row(2, h3, 1), zero),
        (row(2, h3, 2), zero),
        (row(0, h1, 1) - row(1, 0.0, 1), zero),  # velocity and acceleration continuous
        (row(0, h1, 2) - row(1, 0.0, 2), zero),
        (row(1, h2, 1) - row(2, 0.0, 1), zero),
        (row(1, h2, 2) - row(2, 0.0, 2), zero),
    ]
    matrix = np.array([equation[0] for equation in equations])
    rhs = np.array([equation[1] for equation in equations])
    solution = np.linalg.solve(matrix, rhs)  # (14, n): every joint at once
    return [solution[o : o + d + 1].T for o, d in zip(offsets, degrees, strict=True)]
