"""Paden–Kahan subproblems on arrays, as IK-Geo states them (Elias & Wen, *IK-Geo: Unified
robot inverse kinematics using subproblem decomposition*, 2022), for the closed forms built
from a robot's screw axes (:mod:`kinplan.ik.spherical_wrist`).

Every function is vectorised over a leading batch shape ``...`` and returns angles [rad] with
a flag per solution (reachable) and, where a rotation can be free, a flag for that. Vectors are
expressed in the world frame at q = 0; axes are unit vectors (3,).

* :func:`sp1` — the rotation about ``k`` taking ``p`` towards ``q`` (one solution);
* :func:`sp2` — rotations about ``k1`` and ``k2`` with ``R(k1, θ1) p = R(k2, θ2) q`` (two);
* :func:`sp4` — the rotations about ``k`` with ``hᵀ R(k, θ) p = d`` (two).

Subproblem 3 (``‖R(k, θ) p − q‖ = d``) is, for parallel axes, the planar 2R elbow of
:func:`kinplan.ik.planar.planar_2r`, which the spherical-wrist solver uses directly.
"""

from __future__ import annotations

import numpy as np

from kinplan.ik.screws import CLAMP, FREE_TOL, SIGNS

#: Where subproblem 4 is free (p on the axis k), the largest mismatch of d still solved [m].
FREE_ROOM = 1e-9


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.sum(a * b, axis=-1)


def sp1(k: np.ndarray, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Subproblem 1: θ with ``R(k, θ) p`` pointing as ``q`` does about ``k`` (least squares).

    Args:
        k: Unit rotation axis, shape (3,).
        p, q: Vectors, shape (..., 3), broadcastable.

    Returns:
        (θ (...,) [rad], free (...,) bool): ``free`` where ``p`` or ``q`` lies on the axis
        (within ``FREE_TOL``): every θ is a solution there (θ is then meaningless).
    """
    p_perp = p - _dot(p, k)[..., None] * k
    q_perp = q - _dot(q, k)[..., None] * k
    sine = _dot(np.cross(p_perp, q_perp), k)
    cosine = _dot(p_perp, q_perp)
    free = (_dot(p_perp, p_perp) < FREE_TOL**2) | (_dot(q_perp, q_perp) < FREE_TOL**2)
    return np.arctan2(sine, cosine), free


def sp2(
    k1: np.ndarray, k2: np.ndarray, p: np.ndarray, q: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Subproblem 2: (θ1, θ2) with ``R(k1, θ1) p = R(k2, θ2) q`` for non-parallel axes.

    ``p`` and ``q`` should have equal lengths. The common vector ``z = R(k1, θ1) p`` lies on
    both cones, ``k1·z = k1·p`` and ``k2·z = k2·q``: ``z = α k1 + β k2 ± γ (k1 × k2)``.

    Args:
        k1, k2: Unit axes, not parallel, shape (3,).
        p, q: Vectors, shape (..., 3).

    Returns:
        (θ1, θ2) of shape (..., 2) [rad] (the ``+γ`` solution first), ``ok`` (..., 2) where
        the cones meet (within ``CLAMP`` of tangency), ``free`` (...,) where ``q`` lies on
        ``k2`` (then θ2 is free and meaningless here; θ1 is right, from ``z = q``).
    """
    c = float(k1 @ k2)
    normal = np.cross(k1, k2)
    n2 = float(normal @ normal)
    kp, kq = p @ k1, q @ k2
    alpha = (kp - c * kq) / n2
    beta = (kq - c * kp) / n2
    length2 = 0.5 * (_dot(p, p) + _dot(q, q))
    rest = length2 - alpha**2 - beta**2 - 2.0 * alpha * beta * c
    ok = rest >= -CLAMP * np.maximum(length2, 1e-300)
    gamma = np.sqrt(np.maximum(rest, 0.0) / n2)[..., None] * SIGNS  # (..., 2)
    z = (alpha[..., None, None] * k1 + beta[..., None, None] * k2) + gamma[..., None] * normal
    q_perp = q - kq[..., None] * k2
    free = _dot(q_perp, q_perp) < FREE_TOL**2
    # q on k2: z = q exactly (the cones touch there; γ would carry √ε of rounding)
    z = np.where(free[..., None, None], q[..., None, :], z)
    theta1, _ = sp1(k1, p[..., None, :], z)
    theta2, _ = sp1(k2, q[..., None, :], z)
    return theta1, theta2, np.broadcast_to(ok[..., None], theta1.shape), free


def sp4(
    h: np.ndarray, k: np.ndarray, p: np.ndarray, d: float | np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Subproblem 4: θ with ``h·R(k, θ) p = d`` (both solutions).

    With ``p = p∥ + p⊥`` along and across ``k``: ``A cos θ + B sin θ = d − (h·k)(k·p)``,
    ``A = h·p⊥``, ``B = p·(h × k)``.

    Args:
        h: Unit vector, shape (3,).
        k: Unit rotation axis, shape (3,).
        p: Vectors, shape (..., 3).
        d: Target values, broadcastable to (...,).

    Returns:
        θ (..., 2) [rad] (``+acos`` first), ``ok`` (..., 2) where a solution exists (within
        ``CLAMP``), ``free`` (...,) where ``A = B = 0`` (every θ solves it when d fits, within
        :data:`FREE_ROOM`; θ is then meaningless).
    """
    hk = float(h @ k)
    kp = p @ k
    a = p @ h - hk * kp
    b = p @ np.cross(h, k)
    radius = np.hypot(a, b)
    free = radius < FREE_TOL
    rhs = d - hk * kp
    ratio = rhs / np.maximum(radius, np.finfo(float).tiny)
    ok = np.where(free, np.abs(rhs) <= FREE_ROOM, np.abs(ratio) <= 1.0 + CLAMP)
    half = np.arccos(np.clip(ratio, -1.0, 1.0))
    theta = np.arctan2(b, a)[..., None] + SIGNS * half[..., None]
    return theta, np.broadcast_to(ok[..., None], theta.shape), free
