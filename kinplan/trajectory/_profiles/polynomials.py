"""Polynomials fixed by boundary conditions: Hermite cubics, quintics, the clamped cubic spline
through via points (one tridiagonal solve for all joints) and the 4-3-4 profile (private; after
:mod:`~kinplan.trajectory._profiles.basics` in :mod:`kinplan.trajectory._profiles`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from kinplan.trajectory._profiles.basics import Pieces

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
