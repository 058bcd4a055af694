"""Quintic Hermite pieces through motion samples: a sampled motion as a :class:`Trajectory`.

:func:`hermite_segments` turns samples (t, q, qd, qdd) into polynomial pieces exact in
position, velocity and acceleration at every sample, so a sampled motion (a program plan, a
followed Cartesian path) can be evaluated like any other trajectory.
"""

from __future__ import annotations

import numpy as np

from kinplan.trajectory import Segment
from kinplan.trajectory._profiles import quintic_coefficients

__all__ = ["hermite_segments"]


def hermite_segments(
    t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> list[Segment]:
    """Quintic Hermite pieces through samples.

    Args:
        t: Sample times [s], shape (N,), increasing.
        q: Positions at the samples [rad or m], shape (N, n).
        qd: Velocities at the samples [rad/s or m/s], shape (N, n).
        qdd: Accelerations at the samples [rad/s² or m/s²], shape (N, n).

    Returns:
        One segment per interval between samples (a single zero-length one for one sample),
        exact in position, velocity and acceleration at every sample time.
    """
    if len(t) == 1:
        return [Segment(0.0, 0.0, q[:1].T.copy())]
    q0, q1, v0, v1, a0, a1 = (x.T for x in (q[:-1], q[1:], qd[:-1], qd[1:], qdd[:-1], qdd[1:]))
    coefficients = quintic_coefficients(q0, q1, v0, v1, a0, a1, np.diff(t))  # (n, 6, pieces)
    coefficients = np.moveaxis(coefficients, 2, 0)  # (pieces, n, 6)
    return [Segment(float(t[k]), float(t[k + 1]), coefficients[k]) for k in range(len(t) - 1)]
