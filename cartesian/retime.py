"""Time-optimal timing of a geometric path under joint velocity and acceleration limits.

The path is fixed: its joint positions q(s), with q' = dq/ds and q'' = d²q/ds² along it, come
from the geometric pass. Its timing is the law s(t). With x = ṡ² and u = s̈, every joint j must
keep

    |q'_j ṡ| ≤ v_j                      (speed:        x ≤ (v_j / q'_j)²)
    |q'_j u + q''_j x| ≤ a_j            (acceleration: linear in u and x)

and the tool its speed L ṡ ≤ v_tool (and, where no joint acceleration is limited, its path
acceleration |u| ≤ u_max). This is the TOPP-RA formulation (Pham & Pham, IEEE T-RO 2018): on a
grid s_0 < … < s_N, u is constant over each interval, x_(i+1) = x_i + 2 Δ_i u_i, and the
constraints hold at both ends of every interval (the "interpolation" discretisation). A backward
pass computes, from the end at rest, the largest x_i from which the rest of the path can still be
followed (the controllable sets, here upper bounds); a forward pass from the start at rest then
takes the largest admissible u at every step. With one path parameter every step is a small
linear programme in one unknown, solved in closed form.

The result is a chain of constant-acceleration segments of s(t), sampled at once
(:func:`timing_from_speeds`).
The limits used are :data:`LIMIT_MARGIN` of the true ones, which absorbs the variation of q' and
q'' between grid points; the follower checks the true limits at its samples.
"""

from __future__ import annotations

import math

import numpy as np

from cartesian.timing import PathTiming
from kinplan.sampling import motion_step
from kinplan.trajectory import time_grid

#: Share of the joint limits the solver plans with (the rest absorbs the grid's discretisation).
LIMIT_MARGIN = 0.995
#: Spacing of the geometric grid along the path [m], and its bounds on the number of points.
GRID_SPACING = 0.001
GRID_POINTS = (201, 2001)
#: |q'_j| below this is a joint that does not move along the path there.
_STILL = 1e-12


def grid_points(length: float) -> int:
    """Number of points of the geometric grid of a path of ``length`` [m]."""
    return int(np.clip(np.ceil(length / GRID_SPACING) + 1, *GRID_POINTS))


def _acceleration_rows(
    dq: np.ndarray, d2q: np.ndarray, limit: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The acceleration constraints |α u + β x| ≤ a written as u ∈ [m x − r, m x + r].

    Args:
        dq: α = q' per grid point and joint (N, nq).
        d2q: β = q'' (N, nq).
        limit: a per joint (nq,), inf where unlimited.

    Returns:
        (r, m, x_cap): r = a/|α| and m = −β/α (N, nq) (r = inf where a joint is unlimited or
        still), and the cap on x of still joints, |β| x ≤ a (N,).
    """
    still = np.abs(dq) <= _STILL
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(still, np.inf, limit / np.abs(dq))
        m = np.where(still, 0.0, -d2q / dq)
        cap = np.where(still & (np.abs(d2q) > 0), limit / np.abs(d2q), np.inf).min(axis=1)
    m = np.where(np.isfinite(r), m, 0.0)
    return r, m, cap


def optimal_speeds(
    s: np.ndarray,
    dq: np.ndarray,
    d2q: np.ndarray,
    velocity_limit: np.ndarray,
    acceleration_limit: np.ndarray,
    max_path_speed: float,
    max_path_acceleration: float = math.inf,
) -> np.ndarray:
    """The time-optimal path speed ṡ at the grid points, at rest at both ends.

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
    n = len(s)
    delta = np.diff(s)
    # speed caps on x = ṡ²
    with np.errstate(divide="ignore"):
        speed_cap = np.min((LIMIT_MARGIN * velocity_limit / np.abs(dq)) ** 2, axis=1)
    x_cap = np.minimum(speed_cap, max_path_speed**2)
    # acceleration rows at each point, and those of the next point expressed at this one:
    # at s_(i+1), α' u + β' x_(i+1) = (α' + 2Δβ') u + β' x_i
    limit = LIMIT_MARGIN * acceleration_limit
    r_here, m_here, still_cap = _acceleration_rows(dq, d2q, limit)
    x_cap = np.minimum(x_cap, still_cap)
    shifted = dq[1:] + 2.0 * delta[:, None] * d2q[1:]
    r_next, m_next, _ = _acceleration_rows(shifted, d2q[1:], limit)
    r = np.concatenate([r_here[:-1], r_next], axis=1)
    m = np.concatenate([m_here[:-1], m_next], axis=1)
    if math.isfinite(max_path_acceleration):
        r = np.concatenate([r, np.full((n - 1, 1), max_path_acceleration)], axis=1)
        m = np.concatenate([m, np.zeros((n - 1, 1))], axis=1)
    # where u's interval is empty for any x above a bound (two rows cross): cap x there
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = m[:, :, None] - m[:, None, :]
        crossing = np.where(gap > 0, (r[:, :, None] + r[:, None, :]) / gap, np.inf)
    x_cap[:-1] = np.minimum(x_cap[:-1], crossing.min(axis=(1, 2), initial=np.inf))
    x_cap[0] = x_cap[-1] = 0.0
    x_cap = np.maximum(x_cap, 0.0)

    # backward pass: largest x_i with a u ≥ lower(x_i) that reaches x_(i+1) ≤ K_(i+1):
    # x (1 + 2Δ m_c) ≤ K + 2Δ r_c for every row c with 1 + 2Δ m_c > 0
    den = 1.0 + 2.0 * delta[:, None] * m
    with np.errstate(invalid="ignore"):
        num = np.where(den > 0, 2.0 * delta[:, None] * r, np.inf)
    den = np.where(den > 0, den, 1.0)
    # (plain floats: a dozen rows per step, where numpy's call overhead would dominate)
    num_rows, den_rows = num.tolist(), den.tolist()
    caps = x_cap.tolist()
    reach = [0.0] * n
    for i in range(n - 2, -1, -1):
        after = reach[i + 1]
        bound = min([(after + a) / b for a, b in zip(num_rows[i], den_rows[i])])
        reach[i] = min(caps[i], bound)
    # forward pass: the largest admissible u from the start at rest
    slope_rows, radius_rows = m.tolist(), r.tolist()
    two_delta = (2.0 * delta).tolist()
    x = [0.0] * n
    for i in range(n - 1):
        here = x[i]
        upper = min([slope * here + radius for slope, radius in zip(slope_rows[i], radius_rows[i])])
        x[i + 1] = max(0.0, min(reach[i + 1], here + two_delta[i] * upper))
    x = np.array(x)
    return np.sqrt(x)


def timing_from_speeds(s: np.ndarray, speed: np.ndarray, dt: float) -> PathTiming | None:
    """Sample the law s(t) of constant path acceleration between grid points with the given
    speeds ṡ [1/s] every ``dt`` seconds (or finer for a short motion:
    :func:`kinplan.sampling.motion_step`), the last sample exactly at the end; None when two
    neighbouring points are both at rest (no finite timing: a singular point).

    Between grid points i and i+1 the law is s_i + ṡ_i τ + ½ s̈_i τ² with s̈_i = (ṡ_(i+1)² −
    ṡ_i²) / (2 Δs_i), reached in τ_i = 2 Δs_i / (ṡ_i + ṡ_(i+1)); evaluated for all samples at
    once.
    """
    ds = np.diff(s)
    pair = speed[:-1] + speed[1:]
    if np.any(pair <= 0):
        return None
    durations = 2.0 * ds / pair
    accel = (speed[1:] - speed[:-1]) / durations
    knots = np.concatenate(([0.0], np.cumsum(durations)))
    duration = float(knots[-1])
    t = time_grid(duration, motion_step(duration, dt))
    piece = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(ds) - 1)
    tau = t - knots[piece]
    s_t = np.clip(s[piece] + (speed[piece] + 0.5 * accel[piece] * tau) * tau, 0.0, 1.0)
    sd = speed[piece] + accel[piece] * tau
    sdd = accel[piece]
    s_t[-1], sd[-1], sdd[-1] = 1.0, 0.0, 0.0
    return PathTiming(t, s_t, sd, sdd, duration)
