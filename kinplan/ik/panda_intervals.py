"""The interval arithmetic of the panda's θ7 search: the θ7 values at which the elbow can reach
form intervals, assembled from angle pieces taken modulo 2π (:func:`cos_range`,
:func:`intervals_within`), and the search's trial values are moved into them (:func:`project`;
:func:`project_many` on arrays). The search's stages are the constants below.

Third of the panda modules, which import only those before them:
:mod:`~kinplan.ik.panda_geometry` → :mod:`~kinplan.ik.panda_subproblems` → ``panda_intervals`` →
:mod:`~kinplan.ik.panda_batch` → :mod:`~kinplan.ik.panda`.
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.ik.screws import TAU

#: θ7 search: offsets [rad] tried on either side of the reference θ7, in this order ...
Q7_STEPS = (0.05, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4)
#: ... then uniform grids over the θ7 range with this many cells (cell centres), in this order.
Q7_GRIDS = (16, 64, 256, 1024)
#: A θ7 value moved onto the edge of the set where the elbow can reach goes this far inside
#: (or to the middle of a narrower interval) [rad], clear of the rounding at the edge.
Q7_EDGE_MARGIN = 1e-7


def cos_range(x0: float, x1: float) -> tuple[float, float]:
    """(min, max) of cos x over the interval [x0, x1] [rad]."""
    if x1 - x0 >= TAU:
        return -1.0, 1.0
    c0, c1 = math.cos(x0), math.cos(x1)
    high = 1.0 if math.floor(x1 / TAU) * TAU >= x0 else max(c0, c1)
    low = -1.0 if math.floor((x1 - math.pi) / TAU) * TAU + math.pi >= x0 else min(c0, c1)
    return low, high


def intervals_within(
    pieces: list[tuple[float, float]], lower: float, upper: float
) -> list[tuple[float, float]]:
    """The union of ``pieces`` (angle intervals [rad], each taken modulo 2π) within
    [lower, upper], as sorted disjoint intervals."""
    found = []
    for start, end in pieces:
        for k in range(math.ceil((lower - end) / TAU), math.floor((upper - start) / TAU) + 1):
            a, b = max(start + k * TAU, lower), min(end + k * TAU, upper)
            if a <= b:
                found.append((a, b))
    found.sort()
    merged: list[tuple[float, float]] = []
    for a, b in found:
        if merged and a <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def project(value: float, intervals: list[tuple[float, float]]) -> float:
    """``value`` if it lies in one of ``intervals``, else the nearest edge moved
    ``Q7_EDGE_MARGIN`` inside (or to the middle of a narrower interval)."""
    best, best_distance = value, math.inf
    for a, b in intervals:
        if a <= value <= b:
            return value
        margin = min(Q7_EDGE_MARGIN, 0.5 * (b - a))
        edge = a + margin if value < a else b - margin
        distance = abs(edge - value)
        if distance < best_distance:
            best, best_distance = edge, distance
    return best


def project_many(values: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """:func:`project` of rows of values (P, V) onto rows of intervals (P, M) (NaN: none)."""
    a, b = starts[:, None, :], ends[:, None, :]
    x = values[:, :, None]
    with np.errstate(invalid="ignore"):
        inside = np.any((a <= x) & (x <= b), axis=2)
        margin = np.minimum(Q7_EDGE_MARGIN, 0.5 * (b - a))
        edge = np.where(x < a, a + margin, b - margin)
        distance = np.nan_to_num(np.abs(edge - x), nan=np.inf)
    best = np.argmin(distance, axis=2)[..., None]  # ties: the first interval
    projected = np.take_along_axis(edge, best, axis=2)[..., 0]
    return np.where(inside, values, projected)
