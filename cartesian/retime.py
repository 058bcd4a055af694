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

from cartesian.timing import PathTiming, TimeLaw, at_times
from kinplan.trajectory import phase_plane, time_grid

#: Share of the joint limits the solver plans with (the rest absorbs the grid's discretisation).
LIMIT_MARGIN = 0.995
#: Spacing of the geometric grid along the path [m], and its bounds on the number of points.
GRID_SPACING = 0.001
GRID_POINTS = (201, 2001)


def grid_points(length: float, feature: float = math.inf) -> int:
    """Number of points of the geometric grid of a path of ``length`` [m] whose shortest
    feature (a weave's corner, :func:`path_feature`) is ``feature`` [m] long: every
    :data:`GRID_SPACING`, and at least 8 points per feature, within :data:`GRID_POINTS` (the
    upper bound raised to what the features need, up to :data:`MAX_GRID_POINTS`)."""
    spacing = min(GRID_SPACING, feature / 8.0)
    points = np.ceil(length / spacing) + 1
    upper = min(max(GRID_POINTS[1], points), MAX_GRID_POINTS)
    return int(np.clip(points, GRID_POINTS[0], upper))


#: Most points of the geometric grid (a long weave).
MAX_GRID_POINTS = 20001


def path_feature(path: object) -> float:
    """The shortest geometric feature of a path [m] the timing must resolve (``feature_length``
    of a path that has one, e.g. a weave's rounded corners; inf otherwise)."""
    return float(getattr(path, "feature_length", math.inf))


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
    speeds ṡ [1/s], averaged over a window of :data:`SMOOTHING_PERIODS` · ``dt``
    (:func:`smoothed`), every ``dt`` seconds, the last sample exactly at the end; None when two
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
    fractions, duration = smoothed(law, SMOOTHING_PERIODS * dt)
    timing = at_times(fractions, time_grid(duration, dt), duration)
    # the averaged law's s is a second difference of double integrals (exact to ~1e-12): the
    # mean speed between two samples never exceeds the law's top speed but for that rounding,
    # which a step capped at top speed × Δt removes
    top = float(speed.max()) * np.diff(timing.t)
    capped = timing.s.copy()
    for k in range(1, len(capped) - 1):
        capped[k] = min(capped[k], capped[k - 1] + top[k - 1])
    timing.s = capped
    return timing


#: Width of each of the two moving averages of a retimed law, in sampling periods: its path
#: acceleration jumps (bang-bang, and at every grid point) become smooth ramps (continuous
#: jerk) that the quintic interpolant between samples follows without overshooting.
SMOOTHING_PERIODS = 2.0


def smoothed(law: phase_plane.PathLaw, width: float) -> tuple[TimeLaw, float]:
    """The law averaged twice over a moving window of ``width`` [s] (a triangular window of
    2 ``width``): s̃(t) = (1/w²) ∬ s over the windows before t, with s = 0 before the start
    and 1 after the end. Its speed and acceleration are averages of the law's (so within the
    law's largest), its acceleration continuously differentiable; the motion is at rest with
    zero acceleration at both ends and lasts 2 ``width`` longer.

    With S1 = ∫ s and S2 = ∫ S1 (exact: the law is piecewise quadratic):
    s̃(t) = (S2(t) − 2 S2(t − w) + S2(t − 2w)) / w², and ṡ̃, s̈̃ the same differences of S1
    and s.

    Returns:
        (law, duration): the averaged law t ↦ (s, ṡ, s̈) and its duration [s].
    """
    end = law.duration
    s0, v0, a0, h = law.s, law.sd, law.sdd, law.h
    first = s0 * h + v0 * h**2 / 2.0 + a0 * h**3 / 6.0  # ∫ s over each phase
    first_start = np.concatenate(([0.0], np.cumsum(first)))
    second = first_start[:-1] * h + s0 * h**2 / 2.0 + v0 * h**3 / 6.0 + a0 * h**4 / 24.0
    second_start = np.concatenate(([0.0], np.cumsum(second)))
    last = law.t.size - 1
    top_speed = float(law.sd.max(initial=0.0))
    total_first, total_second = float(first_start[-1]), float(second_start[-1])

    def integrals(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, S1 and S2 at the times t (any: before the start and after the end too)."""
        inside = np.clip(t, 0.0, end)
        k = np.clip(np.searchsorted(law.t, inside, side="right") - 1, 0, last)
        tau = inside - law.t[k]
        position = s0[k] + tau * (v0[k] + tau * a0[k] / 2.0)
        one = first_start[k] + tau * (s0[k] + tau * (v0[k] / 2.0 + tau * a0[k] / 6.0))
        two = second_start[k] + tau * (
            first_start[k] + tau * (s0[k] / 2.0 + tau * (v0[k] / 6.0 + tau * a0[k] / 24.0))
        )
        after = np.maximum(t - end, 0.0)
        position = np.where(t <= 0.0, 0.0, np.where(t >= end, 1.0, position))
        one = np.where(t >= end, total_first + after, one)
        two = np.where(t >= end, total_second + total_first * after + after**2 / 2.0, two)
        return position, one, two

    def fractions(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.asarray(t, dtype=float)
        p0, i0, j0 = integrals(t)
        p1, i1, j1 = integrals(t - width)
        p2, i2, j2 = integrals(t - 2.0 * width)
        scale = 1.0 / width**2
        s = (j0 - 2.0 * j1 + j2) * scale
        # means of the law's speeds: never above their largest (but for rounding)
        speed = np.clip((i0 - 2.0 * i1 + i2) * scale, 0.0, top_speed)
        return np.clip(s, 0.0, 1.0), speed, (p0 - 2.0 * p1 + p2) * scale

    return fractions, end + 2.0 * width
