"""Jerk-limited seven-phase S-curves: each joint's minimum-time phases in closed form, their peaks,
cubic pieces and the synchronised profile within every joint's limits (private; after
:mod:`~kinplan.trajectory._profiles.basics` and :mod:`~kinplan.trajectory._profiles.piecewise` in
:mod:`kinplan.trajectory._profiles`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from kinplan.errors import InfeasibleError
from kinplan.trajectory._profiles.basics import LIMIT_MARGIN, Pieces
from kinplan.trajectory._profiles.piecewise import constant_derivative_pieces

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
