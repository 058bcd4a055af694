"""Time-optimal path speeds in the phase plane: the reachability passes of TOPP-RA.

A path q(s) is timed by its speed x = ṡ² and acceleration u = s̈ along s. On each interval of
a grid of nodes s_0 < … < s_I, u is constant (so x is linear in s: x_(i+1) = x_i + 2Δ_i u_i),
and every joint limit is imposed at both ends of the interval with that u:

    |q'_j ṡ| ≤ v_j                        (speed:        x ≤ (v_j / q'_j)²)
    |q'_j u + q''_j x| ≤ a_j              (acceleration: one row, linear in u and x)

written ``−w − g x ≤ u ≤ w − g x`` (w = a/|α|, g = β/α for a row α u + β x; the end of the
interval reads α = q'_end + 2Δ q''_end, β = q''_end). Each row being linear in (u, x), the
largest controllable x at a node follows from the next node's in closed form (Fourier–Motzkin
elimination of u: the reachability analysis of TOPP-RA, Pham & Pham, IEEE T-RO 2018, with no
linear programme), and a forward pass from rest takes the largest admissible u at every node.

One implementation serves joint-space paths through waypoints (:mod:`kinplan.trajectory.totg`)
and Cartesian paths (:mod:`cartesian.retime`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Intervals:
    """The path cut into intervals between nodes, with their limits in the phase plane.

    On interval i (from node i to node i + 1, ``delta[i]`` long) every limit reads
    ``−w − g x ≤ u ≤ w − g x`` for the path acceleration u and x = ṡ² at node i (one column
    per limit; w = inf for none), and x ≤ ``ceiling[i]`` at node i. ``free[i]`` marks a line:
    its limits are constant, so u need not be constant on it.
    """

    s: np.ndarray  # (I + 1,) node parameters
    delta: np.ndarray  # (I,)
    w: np.ndarray  # (I, R)
    g: np.ndarray  # (I, R)
    ceiling: np.ndarray  # (I,)
    free: np.ndarray  # (I,) bool
    piece: np.ndarray  # (I,)
    stop: np.ndarray  # (I + 1,) bool: the motion is at rest at this node


def intervals(
    s: np.ndarray,
    first_start: np.ndarray,
    second_start: np.ndarray,
    first_end: np.ndarray,
    second_end: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    scale: np.ndarray | float = 1.0,
    *,
    free: np.ndarray | None = None,
    piece: np.ndarray | None = None,
    stops: np.ndarray | None = None,
    max_path_speed: float = math.inf,
    max_path_acceleration: float = math.inf,
) -> Intervals:
    """The limits on each interval of a grid (see :class:`Intervals`).

    Args:
        s: Nodes, increasing, shape (I + 1,).
        first_start, second_start: q' and q'' at each interval's start, shape (I, n).
        first_end, second_end: q' and q'' at each interval's end, shape (I, n).
        max_velocity: Velocity limits (n,) (inf: none) [rad/s or m/s].
        max_acceleration: Acceleration limits (n,) (inf: none) [rad/s² or m/s²].
        scale: Share of the limits planned for, per interval (I,) or one number.
        free: Intervals whose limits are constant (straight lines), shape (I,); default none.
        piece: A label per interval (e.g. the path piece), shape (I,); default 0.
        stops: Parameters of nodes where the motion must rest (besides both ends).
        max_path_speed: Largest ṡ.
        max_path_acceleration: Largest |s̈|.
    """
    delta = np.diff(s)
    count = delta.size
    free = np.zeros(count, dtype=bool) if free is None else free
    piece = np.zeros(count, dtype=int) if piece is None else piece
    scale = np.broadcast_to(np.asarray(scale, dtype=float), (count,))[:, None]
    acceleration = max_acceleration[None, :] * scale
    velocity = max_velocity[None, :] * scale
    # Rows at the start of the interval (alpha u + beta x); at its end, with x_end = x + 2Δu.
    alpha = np.hstack([first_start, first_end + 2.0 * delta[:, None] * second_end])
    beta = np.hstack([second_start, second_end])
    limit = np.hstack([acceleration, acceleration])
    if math.isfinite(max_path_acceleration):  # |u| ≤ max: a row with α = 1, β = 0
        alpha = np.hstack([alpha, np.ones((count, 1))])
        beta = np.hstack([beta, np.zeros((count, 1))])
        limit = np.hstack([limit, np.full((count, 1), max_path_acceleration)])
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        w = np.where(alpha != 0.0, limit / np.abs(alpha), np.inf)
        g = np.where(alpha != 0.0, beta / alpha, 0.0)
        # rows with alpha = 0 bound x alone: |beta| x ≤ a
        alone = np.where((alpha == 0.0) & (beta != 0.0), limit / np.abs(beta), np.inf)
        speed_bound = np.where(first_start != 0.0, (velocity / first_start) ** 2, np.inf)
        # Largest x for which some u meets every row: each lower bound below each upper one.
        spread = np.abs(g[:, :, None] - g[:, None, :])
        pair = (w[:, :, None] + w[:, None, :]) / spread
    g = np.where(np.isfinite(w), g, 0.0)  # an unlimited row bounds nothing
    pair = np.where((spread > 0.0) & np.isfinite(pair), pair, np.inf)
    ceiling = np.minimum.reduce([pair.min(axis=(1, 2)), alone.min(axis=1), speed_bound.min(axis=1)])
    ceiling = np.minimum(ceiling, max_path_speed**2)
    stop = np.zeros(s.size, dtype=bool)
    stop[0] = stop[-1] = True
    if stops is not None and stops.size:
        stop[np.searchsorted(s, stops)] = True
    return Intervals(s, delta, w, g, ceiling, free, piece, stop)


def controllable(intervals: Intervals) -> np.ndarray:
    """Backward pass: the largest x = ṡ² at each node from which the end can still be reached
    at rest within the limits, shape (I + 1,).

    From node i + 1 with largest controllable x = k, the largest x at node i is
    ``min(ceiling_i, min_r (k + 2Δ w_r) / (1 − 2Δ g_r))`` over the rows with 1 − 2Δ g_r > 0
    (braking at the lower bound of every row must reach k); the other rows never bind.
    """
    d = intervals.delta[:, None]
    shrink = 1.0 - 2.0 * d * intervals.g
    usable = (shrink > 0.0) & np.isfinite(intervals.w)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(usable, 1.0 / shrink, 0.0)
        offset = np.where(usable, 2.0 * d * intervals.w / shrink, np.inf)
    rows = row_lists(slope, offset)
    ceiling = intervals.ceiling.tolist()
    stop = intervals.stop.tolist()
    k = [0.0] * (len(ceiling) + 1)
    value = 0.0
    for i in range(len(ceiling) - 1, -1, -1):
        best = ceiling[i]
        for a, b in zip(*rows[i]):  # plain floats: far faster than numpy on a dozen values
            bound = a * value + b
            if bound < best:
                best = bound
        value = 0.0 if stop[i] else max(best, 0.0)
        k[i] = value
    return np.array(k)


def fastest(intervals: Intervals, controllable: np.ndarray) -> np.ndarray:
    """Forward pass: the fastest x = ṡ² at each node, from rest, staying controllable.

    From x at node i the largest path acceleration is ``min_r (w_r − g_r x)``; the next node
    takes ``min(k_{i+1}, x + 2Δ u)`` (and the ceiling on a line, whose limits are constant).
    """
    rows = row_lists(-intervals.g, intervals.w)  # w = inf: no bound
    delta = intervals.delta.tolist()
    free = intervals.free.tolist()
    ceiling = intervals.ceiling.tolist()
    k = controllable.tolist()
    x = [0.0] * (len(delta) + 1)
    value = 0.0
    for i in range(len(delta)):
        upper = math.inf
        for a, b in zip(*rows[i]):
            bound = a * value + b
            if bound < upper:
                upper = bound
        reach = value + 2.0 * delta[i] * upper
        if free[i] and ceiling[i] < reach:
            reach = ceiling[i]
        value = max(min(k[i + 1], reach), 0.0)
        x[i + 1] = value
    return np.array(x)


def row_lists(slope: np.ndarray, offset: np.ndarray) -> list[tuple[list[float], list[float]]]:
    """Per interval, the rows' slopes and offsets as lists of Python floats."""
    return list(zip(slope.tolist(), offset.tolist(), strict=True))


@dataclass(frozen=True, eq=False)
class PathLaw:
    """The path parameter against time: one constant path acceleration per phase.

    Phase k starts at time ``t[k]`` at path parameter ``s[k]`` with path speed ``sd[k]`` and
    lasts ``h[k]`` with path acceleration ``sdd[k]``: s(t) = s[k] + sd[k] τ + sdd[k] τ² / 2,
    τ = t − t[k]. Phases lie within one piece of the path (``piece[k]``).
    """

    t: np.ndarray
    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray
    h: np.ndarray
    piece: np.ndarray

    @property
    def duration(self) -> float:
        """End time [s]."""
        return float(self.t[-1] + self.h[-1]) if self.t.size else 0.0

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, ṡ and s̈ at the times ``t`` (clipped to the motion), each of shape (len(t),)."""
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        k = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, self.t.size - 1)
        tau = t - self.t[k]
        s = self.s[k] + (self.sd[k] + 0.5 * self.sdd[k] * tau) * tau
        return s, self.sd[k] + self.sdd[k] * tau, self.sdd[k].copy()

    def stretched(self, factor: float) -> PathLaw:
        """The same law played ``factor`` ≥ 1 times slower (speeds / factor, accelerations /
        factor²)."""
        return PathLaw(
            self.t * factor,
            self.s,
            self.sd / factor,
            self.sdd / factor**2,
            self.h * factor,
            self.piece,
        )
