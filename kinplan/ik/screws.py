"""Screw geometry shared by the closed-form IK solvers: joint screws at q = 0, rotations,
angle choice among 2π equivalents, and the tolerances of the closed forms.

(See :mod:`kinplan.ik.closed_form` for how the solvers read a robot's geometry.)
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)

TAU = 2.0 * np.pi

#: Largest excess of a cosine or sine ratio over 1 still treated as reachable (rounding at the rim).
CLAMP = 1e-10

#: Below this length [m] or sine, an angle is free (singular) and taken from the reference.
FREE_TOL = 1e-12

#: Tolerance of the structural checks on unit vectors and of intersections [m].
STRUCTURE_TOL = 1e-9

#: Joint values this far outside a limit [rad] are accepted and clipped onto it.
LIMIT_TOL = 1e-12

#: Two solutions of a pose closer than this [rad, every joint, modulo 2π] are one.
DISTINCT_TOL = 1e-9

#: Tolerance [m, rad] for the out-of-plane offset and the orientation of a planar 2R target.
PLANAR_TOL = 1e-9

SIGNS = np.array([1.0, -1.0])

#: Smallest normal float, a floor for divisors.
TINY = float(np.finfo(float).tiny)

#: Below π by this margin, the 2π-equivalent nearest a reference is unambiguous (no tie).
HALF_TURN_SAFE = np.pi - 1e-9


# ---------------------------------------------------------------------------- small geometry
def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles [rad] wrapped into [−π, π]."""
    return angle - TAU * np.round(angle / TAU)


def skew(axis: np.ndarray) -> np.ndarray:
    """The matrix [u]× with [u]× v = u × v (numpy's cross is slow on small arrays)."""
    x, y, z = axis
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rotate_about(
    v: np.ndarray, axis: np.ndarray, angle: np.ndarray, cross_t: np.ndarray | None = None
) -> np.ndarray:
    """Rotate vectors ``v`` (..., 3) about the unit ``axis`` (3,) by ``angle`` (...) [rad].

    ``cross_t`` is ``skew(axis).T`` when the caller has it at hand.
    """
    cross_t = skew(axis).T if cross_t is None else cross_t
    c = np.cos(angle)[..., None]
    s = np.sin(angle)[..., None]
    return v * c + (v @ cross_t) * s + axis * ((v @ axis)[..., None] * (1.0 - c))


def rotate_about_line(
    x: np.ndarray, point: np.ndarray, axis: np.ndarray, angle: np.ndarray, cross_t: np.ndarray
) -> np.ndarray:
    """Rotate points ``x`` (..., 3) about the line through ``point`` along unit ``axis``."""
    return point + rotate_about(x - point, axis, angle, cross_t)


def rotate_by(rotations: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``rotations`` (N, 3, 3) applied to vectors ``v`` (N, ..., 3)."""
    return np.einsum("nij,n...j->n...i", rotations, v)


def wrap_near(
    values: np.ndarray, ref: np.ndarray, lower: np.ndarray, upper: np.ndarray
) -> np.ndarray:
    """The 2π-equivalent of each joint value within the limits nearest ``ref``; NaN if none.

    Args:
        values: Joint values [rad] (NaN allowed), shape (..., n).
        ref: Reference configuration, broadcastable to ``values`` (clipped into the limits).
        lower: Lower limits, shape (n,).
        upper: Upper limits, shape (n,).
    """
    ref = np.clip(ref, lower, upper)
    k0 = np.round((ref - values) / TAU)
    candidates = values[..., None] + TAU * (k0[..., None] + np.array([-1.0, 0.0, 1.0]))
    inside = (candidates >= lower[:, None] - LIMIT_TOL) & (candidates <= upper[:, None] + LIMIT_TOL)
    distance = np.where(inside, np.abs(candidates - np.asarray(ref)[..., None]), np.inf)
    best = np.argmin(distance, axis=-1)[..., None]
    chosen = np.take_along_axis(candidates, best, axis=-1)[..., 0]
    found = np.isfinite(np.take_along_axis(distance, best, axis=-1)[..., 0])
    return np.where(found, np.clip(chosen, lower, upper), np.nan)


def near_angle(value: float, ref: float, lower: float, upper: float) -> float | None:
    """:func:`wrap_near` for one joint, in plain floats.

    Args:
        value: Joint value [rad], any 2π representative.
        ref: Reference value [rad], already clipped into [lower, upper].
        lower: Lower limit [rad].
        upper: Upper limit [rad].

    Returns:
        The 2π-equivalent of ``value`` within the limits nearest ``ref`` (clipped onto a limit
        it exceeds by at most ``LIMIT_TOL``), or None when no equivalent is within the limits.
    """
    k = round((ref - value) / TAU)
    candidate = value + TAU * k
    if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL and (
        abs(candidate - ref) < HALF_TURN_SAFE  # the neighbours at ±2π are farther: done
    ):
        return min(max(candidate, lower), upper)
    best, best_distance = None, math.inf
    for shift in (k - 1, k, k + 1):  # the order of wrap_near: ties go to the first
        candidate = value + TAU * shift
        if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL:
            distance = abs(candidate - ref)
            if distance < best_distance:
                best, best_distance = candidate, distance
    return None if best is None else min(max(best, lower), upper)


def joint_choice(
    value: float, joint: tuple[float, float, float, float, float]
) -> tuple[float, float] | None:
    """One joint's value for the nearest solution and its share of the distance.

    Args:
        value: Joint value [rad], any 2π representative.
        joint: (reference, reference clipped into the limits, lower, upper, weight) [rad, –].

    Returns:
        (q, w·(q − reference)²) with q as :func:`near_angle` chooses it, or None (no q within
        limits).
    """
    ref, clipped, lower, upper, weight = joint
    q = value + TAU * round((clipped - value) / TAU)
    if not (lower <= q <= upper and -HALF_TURN_SAFE < q - clipped < HALF_TURN_SAFE):
        near = near_angle(value, clipped, lower, upper)  # near a limit or half a turn away
        if near is None:
            return None
        q = near
    return q, weight * (q - ref) ** 2


def joint_choice_many(
    values: np.ndarray,
    ref: np.ndarray,
    clipped: np.ndarray,
    lower: float,
    upper: float,
    weight: float,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`joint_choice` of many values of one joint, vectorised (the batch closed forms).

    The equivalent nearest the reference, ``c = value + 2π·round((clipped − value)/2π)``, is
    within half a turn of it, so its neighbours at ±2π are farther: it is the choice when it is
    within the limits, else the neighbour on the side of the limits (when that one is within
    them). Only at half a turn (|c − clipped| ≥ ``HALF_TURN_SAFE``), where two equivalents tie,
    does :func:`near_angle` decide, value by value.

    Args:
        values: Joint values [rad], any 2π representative (NaN: none), shape (..., N).
        ref: References [rad], shape (N,).
        clipped: The references clipped into the limits [rad], shape (N,).
        lower, upper: The joint's limits [rad] (±inf for a continuous joint).
        weight: The joint's weight in the distance.

    Returns:
        (q, cost) shaped like ``values``: q as :func:`joint_choice` chooses it, and
        w·(q − ref)², inf where no equivalent is within the limits (q is then meaningless).
    """
    with np.errstate(invalid="ignore"):
        turns = np.round((clipped - values) / TAU)
        q = values + TAU * turns
        tie = np.abs(q - clipped) >= HALF_TURN_SAFE
        turns -= q > upper + LIMIT_TOL  # value + 2π·turns as near_angle: the same last bit
        turns += q < lower - LIMIT_TOL
        q = values + TAU * turns
        valid = (q >= lower - LIMIT_TOL) & (q <= upper + LIMIT_TOL)
        np.minimum(np.maximum(q, lower, out=q), upper, out=q)
    cost = q - ref
    cost *= cost
    if weight != 1.0:
        cost *= weight
    np.copyto(cost, np.inf, where=~valid)
    if tie.any():
        for index in zip(*np.nonzero(tie)):
            near = near_angle(float(values[index]), float(clipped[index[-1]]), lower, upper)
            if near is None:
                cost[index] = np.inf
            else:
                q[index] = near
                cost[index] = weight * (near - float(ref[index[-1]])) ** 2
    return q, cost


def compose_scan(maps: np.ndarray) -> np.ndarray:
    """Prefix compositions of branch maps by doubling (Hillis–Steele), O(N log N) in numpy.

    Args:
        maps: (N, S) ints; row i maps the branch at sample i − 1 to the branch at sample i
            (row 0 is ignored).

    Returns:
        (N, S): row i maps the branch at sample 0 to the branch at sample i.
    """
    prefix = maps.copy()
    prefix[0] = np.arange(maps.shape[1])
    offset = 1
    while offset < len(prefix):
        prefix[offset:] = np.take_along_axis(prefix[offset:], prefix[:-offset], axis=1)
        offset *= 2
    return prefix


# ---------------------------------------------------------------------------- model geometry
@dataclass(frozen=True)
class Screws:
    """Joint axes and tool pose of a serial chain at q = 0, in the world frame.

    Attributes:
        directions: Unit joint axes (n, 3) (the direction of positive rotation).
        points: A point on each axis (n, 3) [m].
        tool: Tool pose at q = 0.
    """

    directions: np.ndarray
    points: np.ndarray
    tool: pin.SE3


def screws_at_zero(robot: Arm) -> Screws | None:
    """The joints as revolute screws at q = 0, or None if some joint is not revolute."""
    model = robot.model
    serial = all(model.parents[j] == j - 1 for j in range(1, model.njoints))
    if not serial or model.nq != model.nv or model.nq != model.njoints - 1:
        return None
    data = model.createData()
    jacobian = pin.computeJointJacobians(model, data, np.zeros(model.nq))  # WORLD, (6, nv)
    tool = pin.SE3(pin.updateFramePlacement(model, data, robot.tip_id))
    linear, angular = jacobian[:3].T, jacobian[3:].T
    unit = np.abs(np.linalg.norm(angular, axis=1) - 1.0) < STRUCTURE_TOL
    no_pitch = np.abs(np.sum(linear * angular, axis=1)) < STRUCTURE_TOL
    if not (np.all(unit) and np.all(no_pitch)):
        return None
    # linear = p × u for an axis through p; u × (p × u) is the point of the axis nearest the origin
    return Screws(angular.copy(), np.cross(angular, linear), tool)


def plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors (e, f) with (e, f, normal) right-handed."""
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    e = np.cross(normal, helper)
    e /= np.linalg.norm(e)
    return e, np.cross(normal, e)


def parallel(u: np.ndarray, v: np.ndarray) -> bool:
    return bool(np.linalg.norm(np.cross(u, v)) < STRUCTURE_TOL)


def perpendicular(u: np.ndarray, v: np.ndarray) -> bool:
    return bool(abs(u @ v) < STRUCTURE_TOL)


def line_meet(
    p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray
) -> tuple[np.ndarray, float]:
    """The midpoint of the shortest segment between the non-parallel lines (p, u) and (q, v)
    (points [m], unit directions), and its length [m]."""
    w = p - q
    b = float(u @ v)
    d, e = float(u @ w), float(v @ w)
    denominator = 1.0 - b * b
    s = (b * e - d) / denominator
    t = (e - b * d) / denominator
    a_point, b_point = p + s * u, q + t * v
    return 0.5 * (a_point + b_point), float(np.linalg.norm(a_point - b_point))


def sine_between(u: np.ndarray, v: np.ndarray) -> float:
    """|sin| of the angle between unit vectors ``u`` and ``v``."""
    return float(np.linalg.norm(np.cross(u, v)))
