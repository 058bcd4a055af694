"""Exact extremes of a joint trajectory's polynomial pieces: the continuous motion between the
samples, not only the samples.

A :class:`~kinplan.trajectory.Trajectory` is a list of polynomial segments. Over one segment
the extremes of a polynomial are at the segment's ends or where its derivative vanishes; the
derivative's roots are found for every segment and joint at once (eigenvalues of batched
companion matrices, in the segment's normalised time u = τ/h ∈ [0, 1]) and the polynomial is
evaluated there, at both ends and on a uniform grid of :data:`GRID` points (a safety net for
nearly multiple roots). Every candidate is a point of the motion, so the extremes found are
never beyond the true ones, and they include every critical point: they are the true extremes
up to the rounding of a root (an error of δ in a root changes the value by O(δ²)).

:func:`joint_peaks` gives the lowest and highest position, the largest speed and the largest
acceleration magnitude of every joint, and when they happen.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kinplan.trajectory import Segment, Trajectory

__all__ = ["GRID", "JointPeaks", "joint_peaks", "polynomial_extremes", "segment_peaks"]

GRID = 17
"""Evaluation points per segment besides the ends and the critical points (a safety net) [-]."""

_NEGLIGIBLE = 1e-13
"""A derivative coefficient below this share of the largest one (in normalised time) does not
raise the derivative's degree [-]."""


@dataclass(frozen=True)
class JointPeaks:
    """Extremes of every joint over a continuous motion.

    Attributes:
        lowest: Lowest position of each joint [rad or m], shape (n,).
        highest: Highest position of each joint [rad or m], shape (n,).
        speed: Largest |velocity| of each joint [rad/s or m/s], shape (n,).
        acceleration: Largest |acceleration| of each joint [rad/s² or m/s²], shape (n,).
        t_lowest, t_highest, t_speed, t_acceleration: When each happens [s], shape (n,).
    """

    lowest: np.ndarray
    highest: np.ndarray
    speed: np.ndarray
    acceleration: np.ndarray
    t_lowest: np.ndarray
    t_highest: np.ndarray
    t_speed: np.ndarray
    t_acceleration: np.ndarray


def joint_peaks(trajectory: Trajectory) -> JointPeaks:
    """The extremes of position, speed and acceleration of every joint of a trajectory, over
    the continuous motion (every segment, between any samples).

    Args:
        trajectory: The motion.

    Returns:
        The peaks; a motion of zero duration has its start position as both extremes and zero
        speed and acceleration.
    """
    return segment_peaks(trajectory.segments, trajectory.start)


def segment_peaks(pieces: Sequence[Segment], start: np.ndarray) -> JointPeaks:
    """:func:`joint_peaks` of polynomial segments (contiguous or not; times as they are).

    Args:
        pieces: The segments.
        start: Position [rad] to report when no segment lasts (shape (n,)).
    """
    segments = [s for s in pieces if s.duration > 0.0]
    n = len(start)
    if not segments:
        start = np.array(start, dtype=float)
        zero = np.zeros(n)
        return JointPeaks(start, start.copy(), zero, zero.copy(), zero.copy(), zero.copy(),
                          zero.copy(), zero.copy())  # fmt: skip
    degree = max(s.degree for s in segments)
    position = np.zeros((len(segments), n, degree + 1))
    for k, segment in enumerate(segments):
        position[k, :, : segment.degree + 1] = segment.coefficients
    h = np.array([s.duration for s in segments])
    t0 = np.array([s.t0 for s in segments])
    powers = np.arange(degree + 1)
    velocity = (position * powers)[:, :, 1:] if degree >= 1 else np.zeros_like(position)
    acceleration = (
        (position * powers * (powers - 1))[:, :, 2:] if degree >= 2 else np.zeros_like(position)
    )
    lowest, t_lowest, highest, t_highest = _per_joint(position, h, t0)
    v_low, tv_low, v_high, tv_high = _per_joint(velocity, h, t0)
    a_low, ta_low, a_high, ta_high = _per_joint(acceleration, h, t0)
    speed = np.maximum(-v_low, v_high)
    t_speed = np.where(-v_low > v_high, tv_low, tv_high)
    peak_acceleration = np.maximum(-a_low, a_high)
    t_acceleration = np.where(-a_low > a_high, ta_low, ta_high)
    return JointPeaks(
        lowest, highest, speed, peak_acceleration, t_lowest, t_highest, t_speed, t_acceleration
    )


def _per_joint(
    coefficients: np.ndarray, h: np.ndarray, t0: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Lowest and highest value of each joint over all segments, and their times [s]."""
    segments, n, width = coefficients.shape
    flat = coefficients.reshape(segments * n, width)
    durations = np.repeat(h, n)
    low, u_low, high, u_high = polynomial_extremes(flat, durations)
    low, high = low.reshape(segments, n), high.reshape(segments, n)
    t_low = t0[:, None] + u_low.reshape(segments, n) * h[:, None]
    t_high = t0[:, None] + u_high.reshape(segments, n) * h[:, None]
    k_low, k_high = np.argmin(low, axis=0), np.argmax(high, axis=0)
    joints = np.arange(n)
    return (low[k_low, joints], t_low[k_low, joints], high[k_high, joints], t_high[k_high, joints])


def polynomial_extremes(
    coefficients: np.ndarray, durations: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Lowest and highest value of polynomials over their intervals.

    Args:
        coefficients: Shape (K, d + 1), lowest power first, in local time τ [s].
        durations: Interval lengths h ≥ 0, shape (K,) [s]: polynomial k on τ ∈ [0, h_k].

    Returns:
        (lowest, u of the lowest, highest, u of the highest), each shape (K,); u = τ/h ∈ [0, 1]
        is where the extreme is, in normalised time.
    """
    count, width = coefficients.shape
    scaled = coefficients * durations[:, None] ** np.arange(width)  # in u = τ / h
    candidates = [np.zeros((count, 1)), np.ones((count, 1)), np.tile(np.linspace(0, 1, GRID),
                  (count, 1))]  # fmt: skip
    if width >= 3:
        derivative = scaled[:, 1:] * np.arange(1, width)
        candidates.append(np.clip(_real_parts_of_roots(derivative), 0.0, 1.0))
    u = np.hstack(candidates)
    values = np.broadcast_to(scaled[:, -1:], u.shape).copy()
    for level in range(width - 2, -1, -1):
        values *= u
        values += scaled[:, level : level + 1]
    rows = np.arange(count)
    k_low, k_high = np.argmin(values, axis=1), np.argmax(values, axis=1)
    return values[rows, k_low], u[rows, k_low], values[rows, k_high], u[rows, k_high]


def _real_parts_of_roots(coefficients: np.ndarray) -> np.ndarray:
    """Real parts of the roots of polynomials (lowest power first), shape (K, m) for degree m
    (rows of a lower effective degree padded with 0: a point of the interval)."""
    count, width = coefficients.shape
    degree = width - 1
    roots = np.zeros((count, max(degree, 1)))
    scale = np.max(np.abs(coefficients), axis=1)
    significant = np.abs(coefficients) > _NEGLIGIBLE * scale[:, None]
    effective = np.where(
        significant.any(axis=1), width - 1 - np.argmax(significant[:, ::-1], axis=1), 0
    )
    for m in range(1, degree + 1):
        rows = np.flatnonzero(effective == m)
        if rows.size == 0:
            continue
        c = coefficients[rows, : m + 1]
        monic = c[:, :m] / c[:, m : m + 1]
        if m == 1:
            roots[rows, 0] = -monic[:, 0]
            continue
        companion = np.zeros((rows.size, m, m))
        companion[:, 1:, :-1] = np.eye(m - 1)
        companion[:, :, -1] = -monic
        with np.errstate(all="ignore"):
            eigen = np.linalg.eigvals(companion)
        real = np.real(eigen)
        roots[rows, :m] = np.where(np.isfinite(real), real, 0.0)
    return roots
