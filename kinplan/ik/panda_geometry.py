"""The panda-type arm's geometry, read from the model (:class:`PandaGeometry`,
:func:`panda_geometry`), and the plain-float arithmetic of its closed form: vectors as 3-tuples,
rotation matrices as row-major 9-tuples (numpy's per-call overhead would dominate a 3-vector
computation), and the same helpers on 3-tuples of arrays for the vectorised path.

The panda modules import only those before them: ``panda_geometry`` →
:mod:`~kinplan.ik.panda_subproblems` → :mod:`~kinplan.ik.panda_intervals` →
:mod:`~kinplan.ik.panda_batch` → :mod:`~kinplan.ik.panda` (:class:`~kinplan.ik.panda.PandaIK`,
the solver; its compiled per-θ7 solve, :mod:`~kinplan.ik.panda_kernel`, imports none of them).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinplan.ik.screws import STRUCTURE_TOL, screws_at_zero
from kinplan.model.arm import Arm

Vec = tuple[float, float, float]
Mat = tuple[float, float, float, float, float, float, float, float, float]


# ---------------------------------------------------------------------------- float vectors
def dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def matvec(m: Mat, v: Vec) -> Vec:
    """``m`` (row-major 3×3) times ``v``."""
    x, y, z = v
    return (
        m[0] * x + m[1] * y + m[2] * z,
        m[3] * x + m[4] * y + m[5] * z,
        m[6] * x + m[7] * y + m[8] * z,
    )


def matmul(a: Mat, b: Mat) -> Mat:
    """Product of two row-major 3×3 matrices."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (
        a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8,
        a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8,
        a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8,
    )  # fmt: skip


def rotate(v: Vec, axis: Vec, angle: float) -> Vec:
    """``v`` rotated about the unit ``axis`` by ``angle`` [rad] (Rodrigues)."""
    return rotate_cs(v, axis, math.cos(angle), math.sin(angle))


def rotate_cs(v: Vec, axis: Vec, c: float, s: float) -> Vec:
    """``v`` rotated about the unit ``axis`` by the angle of cosine ``c`` and sine ``s``."""
    ax, ay, az = axis
    x, y, z = v
    k = (ax * x + ay * y + az * z) * (1.0 - c)
    return (
        x * c + (ay * z - az * y) * s + ax * k,
        y * c + (az * x - ax * z) * s + ay * k,
        z * c + (ax * y - ay * x) * s + az * k,
    )


def rotation_matrix(axis: Vec, angle: float) -> Mat:
    """Row-major rotation matrix about the unit ``axis`` by ``angle`` [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    x, y, z = axis
    return (
        c + x * x * t, x * y * t - z * s, x * z * t + y * s,
        y * x * t + z * s, c + y * y * t, y * z * t - x * s,
        z * x * t - y * s, z * y * t + x * s, c + z * z * t,
    )  # fmt: skip


# The float helpers above on 3-tuples of arrays (element by element, the same arithmetic), for
# the vectorised path (PandaIK.nearest_many).
sub_many: Callable[..., Any] = sub
dot_many: Callable[..., Any] = dot
cross_many: Callable[..., Any] = cross
matvec_many: Callable[..., Any] = matvec
matmul_many: Callable[..., Any] = matmul
rotate_cs_many: Callable[..., Any] = rotate_cs


def map_floats(function: Callable[..., float], *arrays: np.ndarray) -> np.ndarray:
    """``function`` of plain floats applied element by element to 1-D arrays."""
    return np.array(list(map(function, *(np.asarray(a, dtype=float).tolist() for a in arrays))))


def rotation_matrix_cs(axis: Vec, c, s):
    """:func:`rotation_matrix` of the angle of cosine ``c`` and sine ``s`` (floats or arrays)."""
    t = 1.0 - c
    x, y, z = axis
    return (
        c + x * x * t, x * y * t - z * s, x * z * t + y * s,
        y * x * t + z * s, c + y * y * t, y * z * t - x * s,
        z * x * t - y * s, z * y * t + x * s, c + z * z * t,
    )  # fmt: skip


# ---------------------------------------------------------------------------- geometry
def floats(v: np.ndarray) -> Vec:
    return (float(v[0]), float(v[1]), float(v[2]))


def matrix_floats(m: np.ndarray) -> Mat:
    """A 3×3 matrix as 9 floats, row by row."""
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = (float(x) for x in m.reshape(9))
    return (m00, m01, m02, m10, m11, m12, m20, m21, m22)


def line_intersection(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray):
    """The common point of the lines p + t·u and q + r·v (unit u, v), or None when they are
    parallel or miss each other by more than the structure tolerance."""
    n = np.cross(u, v)
    if np.linalg.norm(n) < STRUCTURE_TOL:
        return None
    # closest points: solve [u, −v] (t, r) = q − p in the least-squares sense
    t, r = np.linalg.lstsq(np.column_stack([u, -v]), q - p, rcond=None)[0]
    a, b = p + t * u, q + r * v
    if np.linalg.norm(a - b) > STRUCTURE_TOL:
        return None
    return 0.5 * (a + b)


def distance_to_line(x: np.ndarray, p: np.ndarray, u: np.ndarray) -> float:
    d = x - p
    return float(np.linalg.norm(d - (d @ u) * u))


@dataclass(frozen=True)
class PandaGeometry:
    """A panda-type arm at q = 0, in the world (base) frame.

    Attributes:
        axes: Unit joint axes ω1…ω7.
        points: A point on each axis [m].
        shoulder: Common point ``s`` of axes 1, 2, 3 [m].
        wrist: Common point ``w`` of axes 5 and 6 [m].
        tool_rotation: Rotation of the tool frame at q = 0 (row-major).
        tool_translation: Position of the tool frame at q = 0 [m].
    """

    axes: tuple[Vec, ...]
    points: tuple[Vec, ...]
    shoulder: Vec
    wrist: Vec
    tool_rotation: Mat
    tool_translation: Vec


def panda_geometry(robot: Arm) -> PandaGeometry | None:
    """The panda-type geometry of ``robot`` (the structure :mod:`kinplan.ik.panda` describes), or
    None.

    Read from the Pinocchio model's joint placements, axes and tool frame (via the world-frame
    joint screws at q = 0); None for any arm without that structure.
    """
    if robot.nq != 7:
        return None
    screws = screws_at_zero(robot)
    if screws is None:
        return None
    u, p = screws.directions, screws.points
    shoulder = line_intersection(p[0], u[0], p[1], u[1])
    if shoulder is None or distance_to_line(shoulder, p[2], u[2]) > STRUCTURE_TOL:
        return None
    if np.linalg.norm(np.cross(u[1], u[2])) < STRUCTURE_TOL:
        return None
    wrist = line_intersection(p[4], u[4], p[5], u[5])
    if wrist is None:
        return None
    for point in (shoulder, wrist):  # θ4 must change the shoulder–wrist distance
        if distance_to_line(point, p[3], u[3]) < 1e3 * STRUCTURE_TOL:
            return None
    tool = screws.tool
    return PandaGeometry(
        axes=tuple(floats(a) for a in u),
        points=tuple(floats(x) for x in p),
        shoulder=floats(shoulder),
        wrist=floats(wrist),
        tool_rotation=matrix_floats(tool.rotation),
        tool_translation=floats(tool.translation),
    )
