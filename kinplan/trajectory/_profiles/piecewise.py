"""Motions whose acceleration or jerk is piecewise constant, as polynomial pieces on knots common
to every joint (private; after :mod:`~kinplan.trajectory._profiles.basics` in
:mod:`kinplan.trajectory._profiles`,
used by :mod:`~kinplan.trajectory._profiles.lspb` and :mod:`~kinplan.trajectory._profiles.scurve`).
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.trajectory._profiles.basics import Pieces

KNOT_MERGE_TOLERANCE = 64.0 * np.finfo(float).eps
"""Phase boundaries of different joints closer than this fraction of the duration are merged
into one knot [-]: a few units of rounding of the duration, so that merging moves no phase by
more than rounding, whatever the ratio of the shortest phase to the whole motion."""


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
