"""How sampled motions are checked: the sampling step of a motion and its joint speeds.

A motion is checked at its samples, so it must have enough of them: one shorter than
:data:`MIN_INTERVALS` sampling periods is sampled at duration / MIN_INTERVALS instead (a 1 ms
move is not checked at its two resting ends only). Between two samples a joint moves at its mean
speed |Δq| / Δt at least somewhere, so that counts as a speed of the sample that ends the interval
along with the rates q̇ themselves (:func:`joint_speeds`).
"""

from __future__ import annotations

import numpy as np

#: Fewest sampling intervals of a motion (joint or Cartesian).
MIN_INTERVALS = 16


def motion_step(duration: float, dt: float) -> float:
    """Sampling step [s] of a motion of ``duration`` [s] at the requested period ``dt`` [s]:
    ``dt``, or duration / :data:`MIN_INTERVALS` when that is smaller (and the duration > 0)."""
    return min(dt, duration / MIN_INTERVALS) if duration > 0 else dt


def joint_speeds(q: np.ndarray, qd: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Joint speeds (N, nq) [rad/s or m/s] of a sampled motion: at sample k the larger of
    |q̇_k| and the mean speed |q_k − q_(k−1)| / (t_k − t_(k−1)) of the interval ending there.

    Args:
        q: Joint positions (N, nq).
        qd: Joint velocities (N, nq).
        t: Sample times (N,) [s], increasing.
    """
    speeds = np.abs(qd)
    if len(t) > 1:
        mean = np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None]
        speeds[1:] = np.maximum(speeds[1:], mean)
    return speeds


def hermite_between(
    t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, fractions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The quintic Hermite interpolant of samples (exact in q, q̇ and q̈ at every sample: the
    motion viewers and exports play between the samples) inside every interval.

    Args:
        t: Sample times (N,) [s], increasing, N ≥ 2.
        q, qd, qdd: Positions, velocities, accelerations at the samples (N, n).
        fractions: Where to evaluate inside each interval, (F,) in [0, 1].

    Returns:
        (times, q, q̇, q̈): times (N−1, F) [s] and the interpolant's values (N−1, F, n).
    """
    h = np.diff(t)  # (N−1,)
    d = q[1:] - q[:-1]
    v0, v1, a0, a1 = qd[:-1], qd[1:], qdd[:-1], qdd[1:]
    hh = h[:, None]
    # the coefficients of kinplan._profiles.quintic_coefficients, per interval and joint
    c3 = (20.0 * d - (8.0 * v1 + 12.0 * v0) * hh - (3.0 * a0 - a1) * hh**2) / (2.0 * hh**3)
    c4 = (-30.0 * d + (14.0 * v1 + 16.0 * v0) * hh + (3.0 * a0 - 2.0 * a1) * hh**2) / (2.0 * hh**4)
    c5 = (12.0 * d - 6.0 * (v1 + v0) * hh + (a1 - a0) * hh**2) / (2.0 * hh**5)
    tau = h[:, None] * np.asarray(fractions, dtype=float)[None, :]  # (N−1, F)
    x = tau[:, :, None]
    c0, c1, c2 = q[:-1, None, :], v0[:, None, :], 0.5 * a0[:, None, :]
    c3, c4, c5 = c3[:, None, :], c4[:, None, :], c5[:, None, :]
    position = c0 + x * (c1 + x * (c2 + x * (c3 + x * (c4 + x * c5))))
    velocity = c1 + x * (2.0 * c2 + x * (3.0 * c3 + x * (4.0 * c4 + x * 5.0 * c5)))
    acceleration = 2.0 * c2 + x * (6.0 * c3 + x * (12.0 * c4 + x * 20.0 * c5))
    return t[:-1, None] + tau, position, velocity, acceleration
