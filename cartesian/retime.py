"""Time-optimal timing of a geometric path under joint velocity and acceleration limits.

The path is fixed: its joint positions q(s), with q' = dq/ds and q'' = d²q/ds² along it, come
from the geometric pass. Its timing is the law s(t). With x = ṡ² and u = s̈, every joint j must
keep

    |q'_j ṡ| ≤ v_j                      (speed:        x ≤ (v_j / q'_j)²)
    |q'_j u + q''_j x| ≤ a_j            (acceleration: linear in u and x)

and the tool its speed L ṡ ≤ v_tool (and, where no joint acceleration is limited, its path
acceleration |s̈| ≤ u_max). This is the TOPP-RA formulation (Pham & Pham, IEEE T-RO 2018) on the
geometric grid, solved by the closed-form reachability passes of :mod:`kinplan.phase_plane`
(the same ones that time joint-space paths through waypoints).

The result is a chain of constant-acceleration segments of s(t), sampled at once
(:func:`timing_from_speeds`).
The limits used are :data:`LIMIT_MARGIN` of the true ones, which absorbs the variation of q' and
q'' between grid points; the follower checks the true limits at its samples.
"""

from __future__ import annotations

import math

import numpy as np

from cartesian.timing import PathTiming
from kinplan import phase_plane
from kinplan.sampling import motion_step
from kinplan.trajectory import time_grid

#: Share of the joint limits the solver plans with (the rest absorbs the grid's discretisation).
LIMIT_MARGIN = 0.995
#: Spacing of the geometric grid along the path [m], and its bounds on the number of points.
GRID_SPACING = 0.001
GRID_POINTS = (201, 2001)


def grid_points(length: float) -> int:
    """Number of points of the geometric grid of a path of ``length`` [m]."""
    return int(np.clip(np.ceil(length / GRID_SPACING) + 1, *GRID_POINTS))


def optimal_speeds(
    s: np.ndarray,
    dq: np.ndarray,
    d2q: np.ndarray,
    velocity_limit: np.ndarray,
    acceleration_limit: np.ndarray,
    max_path_speed: float,
    max_path_acceleration: float = math.inf,
) -> np.ndarray:
    """The time-optimal path speed ṡ at the grid points, at rest at both ends
    (:mod:`kinplan.phase_plane` on the grid's intervals, limits scaled by
    :data:`LIMIT_MARGIN`).

    Args:
        s: Grid of path fractions, increasing from 0 to 1 (N,).
        dq: q' at the grid points (N, nq) [rad or m per unit s].
        d2q: q'' at the grid points (N, nq).
        velocity_limit: Joint speed limits (nq,) [rad/s or m/s] (inf: none).
        acceleration_limit: Joint acceleration limits (nq,) [rad/s² or m/s²] (inf: none).
        max_path_speed: Largest ṡ [1/s] (the tool speed over the path length).
        max_path_acceleration: Largest |s̈| [1/s²] (inf: none).

    Returns:
        ṡ (N,) [1/s]; zero where the path cannot be followed at any speed (a singular point).
    """
    grid = phase_plane.intervals(
        s, dq[:-1], d2q[:-1], dq[1:], d2q[1:], velocity_limit, acceleration_limit,
        LIMIT_MARGIN, max_path_speed=max_path_speed,
        max_path_acceleration=max_path_acceleration,
    )  # fmt: skip
    x = phase_plane.fastest(grid, phase_plane.controllable(grid))
    return np.sqrt(np.maximum(x, 0.0))


def timing_from_speeds(s: np.ndarray, speed: np.ndarray, dt: float) -> PathTiming | None:
    """Sample the law s(t) of constant path acceleration between grid points with the given
    speeds ṡ [1/s] every ``dt`` seconds (or finer for a short motion:
    :func:`kinplan.sampling.motion_step`), the last sample exactly at the end; None when two
    neighbouring points are both at rest (no finite timing: a singular point).

    Between grid points i and i+1 the law is s_i + ṡ_i τ + ½ s̈_i τ² with s̈_i = (ṡ_(i+1)² −
    ṡ_i²) / (2 Δs_i), reached in τ_i = 2 Δs_i / (ṡ_i + ṡ_(i+1)); evaluated for all samples at
    once by :meth:`kinplan.phase_plane.PathLaw.evaluate`.
    """
    ds = np.diff(s)
    pair = speed[:-1] + speed[1:]
    if np.any(pair <= 0):
        return None
    durations = 2.0 * ds / pair
    knots = np.concatenate(([0.0], np.cumsum(durations)))
    law = phase_plane.PathLaw(
        t=knots[:-1], s=s[:-1], sd=speed[:-1], sdd=(speed[1:] - speed[:-1]) / durations,
        h=durations, piece=np.zeros(len(ds), dtype=int),
    )  # fmt: skip
    t = time_grid(law.duration, motion_step(law.duration, dt))
    s_t, sd, sdd = law.evaluate(t)
    s_t = np.clip(s_t, 0.0, 1.0)
    s_t[-1], sd[-1], sdd[-1] = 1.0, 0.0, 0.0
    return PathTiming(t, s_t, sd, sdd, law.duration)
