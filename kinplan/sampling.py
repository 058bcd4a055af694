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
