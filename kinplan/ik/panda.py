"""Semi-analytic inverse kinematics for 7-joint arms of the Franka Emika panda type.

With the last joint angle θ7 fixed, the remaining six joints have a closed form (the idea of He &
Liu, *Analytical Inverse Kinematics for Franka Emika Panda – a Geometrical Solver for 7-DOF
Manipulators with Unconventional Design*, 2021). It is derived here in the screw form of
:mod:`kinplan.ik.ur`, on the model's own frames: at q = 0 every joint i is a rotation about
a unit axis ``ωᵢ`` through a point ``pᵢ`` (world frame), and the tool pose is
``T(q) = exp(S1 θ1) ⋯ exp(S7 θ7) M``. The structure this needs, checked on the model:

* axes 1, 2, 3 meet in one point ``s`` (the shoulder centre; 1 ∦ 2, 2 ∦ 3);
* axes 5 and 6 meet in one point ``w`` (5 ∦ 6);
* ``s`` and ``w`` both lie off axis 4 (the elbow changes their distance).

Axis 7 and the tool frame are arbitrary (the panda's 0.088 m offset of axis 7 from the wrist is
the reason θ7 cannot be solved with the others). For a target pose ``T`` and a given θ7:

1. ``P = T M⁻¹ exp(−S7 θ7) = exp(S1 θ1) ⋯ exp(S6 θ6)``; joints 1–3 do not move ``s``, so
   ``y = P⁻¹ s = exp(−S6 θ6) exp(−S5 θ5) exp(−S4 θ4) s``.
2. θ4 (two branches): joints 5 and 6 do not change distances to ``w``, so
   ``|exp(−S4 θ4) s − w| = |y − w|`` (Paden–Kahan subproblem 3).
3. θ5, θ6 (two branches): rotate ``u = exp(−S4 θ4) s − w`` onto ``v = y − w`` about axes 5
   then 6 (subproblem 2).
4. θ1, θ2, θ3 (two branches): the shoulder rotation ``G = R1 R2 R3 = R_P R6ᵀ R5ᵀ R4ᵀ`` is
   split like an Euler-angle triple: ``R1 R2 ω3 = G ω3`` (subproblem 2), then θ3 from ``G e``
   for a unit ``e ⊥ ω3`` (subproblem 1).

Up to 8 solutions per θ7. Joint angles are equivalent modulo 2π: :meth:`PandaIK.solutions_q7`
lists each solution once, as its equivalent within the limits closest to mid-range;
:meth:`PandaIK.nearest` picks per joint the equivalent within the limits closest to the
reference. When θ7 of the reference admits no solution within the limits, θ7 is searched
coarse to fine over its range.

Everything per pose is plain Python floats (numpy's per-call overhead would dominate a 3-vector
computation): vectors are 3-tuples, rotation matrices row-major 9-tuples.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from operator import itemgetter
from typing import TYPE_CHECKING, Any

import numpy as np

from kinplan.errors import InputError
from kinplan.ik.base import self_check
from kinplan.ik.screws import (
    CLAMP,
    FREE_TOL,
    LIMIT_TOL,
    STRUCTURE_TOL,
    TAU,
    joint_choice,
    joint_choice_many,
    plane_basis,
    screws_at_zero,
)

if TYPE_CHECKING:  # type-only: kinplan.robot imports this module
    from kinplan.robot import Robot

logger = logging.getLogger(__name__)

Vec = tuple[float, float, float]
Mat = tuple[float, float, float, float, float, float, float, float, float]

#: Solutions this close [rad, max-norm] are the same solution (they meet at singularities).
_SAME_TOL = 1e-9
#: θ7 search: offsets [rad] tried on either side of the reference θ7, in this order ...
_Q7_STEPS = (0.05, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4)
#: ... then uniform grids over the θ7 range with this many cells (cell centres), in this order.
_Q7_GRIDS = (16, 64, 256, 1024)
#: A θ7 value moved onto the edge of the set where the elbow can reach goes this far inside
#: (or to the middle of a narrower interval) [rad], clear of the rounding at the edge.
_Q7_EDGE_MARGIN = 1e-7


# ---------------------------------------------------------------------------- float vectors
def _dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _matvec(m: Mat, v: Vec) -> Vec:
    """``m`` (row-major 3×3) times ``v``."""
    x, y, z = v
    return (
        m[0] * x + m[1] * y + m[2] * z,
        m[3] * x + m[4] * y + m[5] * z,
        m[6] * x + m[7] * y + m[8] * z,
    )


def _matmul(a: Mat, b: Mat) -> Mat:
    """Product of two row-major 3×3 matrices."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (
        a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8,
        a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8,
        a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8,
    )  # fmt: skip


def _rotate(v: Vec, axis: Vec, angle: float) -> Vec:
    """``v`` rotated about the unit ``axis`` by ``angle`` [rad] (Rodrigues)."""
    return _rotate_cs(v, axis, math.cos(angle), math.sin(angle))


def _rotate_cs(v: Vec, axis: Vec, c: float, s: float) -> Vec:
    """``v`` rotated about the unit ``axis`` by the angle of cosine ``c`` and sine ``s``."""
    ax, ay, az = axis
    x, y, z = v
    k = (ax * x + ay * y + az * z) * (1.0 - c)
    return (
        x * c + (ay * z - az * y) * s + ax * k,
        y * c + (az * x - ax * z) * s + ay * k,
        z * c + (ax * y - ay * x) * s + az * k,
    )


def _rotation_matrix(axis: Vec, angle: float) -> Mat:
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
_sub_many: Callable[..., Any] = _sub
_dot_many: Callable[..., Any] = _dot
_cross_many: Callable[..., Any] = _cross
_matvec_many: Callable[..., Any] = _matvec
_matmul_many: Callable[..., Any] = _matmul
_rotate_cs_many: Callable[..., Any] = _rotate_cs


def _map(function: Callable[..., float], *arrays: np.ndarray) -> np.ndarray:
    """``function`` of plain floats applied element by element to 1-D arrays."""
    return np.array(list(map(function, *(np.asarray(a, dtype=float).tolist() for a in arrays))))


def _rotation_matrix_cs(axis: Vec, c, s):
    """:func:`_rotation_matrix` of the angle of cosine ``c`` and sine ``s`` (floats or arrays)."""
    t = 1.0 - c
    x, y, z = axis
    return (
        c + x * x * t, x * y * t - z * s, x * z * t + y * s,
        y * x * t + z * s, c + y * y * t, y * z * t - x * s,
        z * x * t - y * s, z * y * t + x * s, c + z * z * t,
    )  # fmt: skip


def _project_many(values: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """:func:`_project` of rows of values (P, V) onto rows of intervals (P, M) (NaN: none)."""
    a, b = starts[:, None, :], ends[:, None, :]
    x = values[:, :, None]
    with np.errstate(invalid="ignore"):
        inside = np.any((a <= x) & (x <= b), axis=2)
        margin = np.minimum(_Q7_EDGE_MARGIN, 0.5 * (b - a))
        edge = np.where(x < a, a + margin, b - margin)
        distance = np.nan_to_num(np.abs(edge - x), nan=np.inf)
    best = np.argmin(distance, axis=2)[..., None]  # ties: the first interval
    projected = np.take_along_axis(edge, best, axis=2)[..., 0]
    return np.where(inside, values, projected)


def _cos_range(x0: float, x1: float) -> tuple[float, float]:
    """(min, max) of cos x over the interval [x0, x1] [rad]."""
    if x1 - x0 >= TAU:
        return -1.0, 1.0
    c0, c1 = math.cos(x0), math.cos(x1)
    high = 1.0 if math.floor(x1 / TAU) * TAU >= x0 else max(c0, c1)
    low = -1.0 if math.floor((x1 - math.pi) / TAU) * TAU + math.pi >= x0 else min(c0, c1)
    return low, high


def _intervals_within(
    pieces: list[tuple[float, float]], lower: float, upper: float
) -> list[tuple[float, float]]:
    """The union of ``pieces`` (angle intervals [rad], each taken modulo 2π) within
    [lower, upper], as sorted disjoint intervals."""
    found = []
    for start, end in pieces:
        for k in range(math.ceil((lower - end) / TAU), math.floor((upper - start) / TAU) + 1):
            a, b = max(start + k * TAU, lower), min(end + k * TAU, upper)
            if a <= b:
                found.append((a, b))
    found.sort()
    merged: list[tuple[float, float]] = []
    for a, b in found:
        if merged and a <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def _project(value: float, intervals: list[tuple[float, float]]) -> float:
    """``value`` if it lies in one of ``intervals``, else the nearest edge moved
    ``_Q7_EDGE_MARGIN`` inside (or to the middle of a narrower interval)."""
    best, best_distance = value, math.inf
    for a, b in intervals:
        if a <= value <= b:
            return value
        margin = min(_Q7_EDGE_MARGIN, 0.5 * (b - a))
        edge = a + margin if value < a else b - margin
        distance = abs(edge - value)
        if distance < best_distance:
            best, best_distance = edge, distance
    return best


# ---------------------------------------------------------------------------- subproblems
def _angle_about(axis: Vec, a: Vec, b: Vec, free: float) -> float:
    """The angle [rad] of the rotation about the unit ``axis`` taking ``a`` towards ``b``
    (Paden–Kahan subproblem 1, on the components perpendicular to ``axis``); ``free`` when
    ``a`` or ``b`` lies on the axis (then every angle is a solution)."""
    ux, uy, uz = axis
    x, y, z = a
    k = ux * x + uy * y + uz * z
    x, y, z = x - k * ux, y - k * uy, z - k * uz  # a without its axis component
    u, v, w = b
    k = ux * u + uy * v + uz * w
    u, v, w = u - k * ux, v - k * uy, w - k * uz
    if x * x + y * y + z * z < FREE_TOL**2 or u * u + v * v + w * w < FREE_TOL**2:
        return free
    return math.atan2(
        ux * (y * w - z * v) + uy * (z * u - x * w) + uz * (x * v - y * u), x * u + y * v + z * w
    )


@dataclass(frozen=True)
class _AxisPair:
    """Two non-parallel unit axes ``a`` and ``b`` with their precomputed products.

    Attributes:
        a, b: Unit axes (world frame at q = 0).
        c: a·b.
        normal: a × b.
        normal2: |a × b|² = 1 − c².
    """

    a: Vec
    b: Vec
    c: float
    normal: Vec
    normal2: float

    @classmethod
    def of(cls, a: Vec, b: Vec) -> _AxisPair:
        normal = _cross(a, b)
        return cls(a, b, _dot(a, b), normal, _dot(normal, normal))

    def solve(self, u: Vec, v: Vec, free_a: float, free_b: float) -> list[tuple[float, float]]:
        """Angles (θa, θb) [rad] with ``Rb(θb) Ra(θa) u = v`` (Paden–Kahan subproblem 2).

        ``u`` and ``v`` must have equal lengths (the caller's construction ensures it). The
        intermediate ``z = Ra(θa) u = Rb(−θb) v`` lies on both cones: z·a = u·a, z·b = v·b.

        Args:
            u, v: Vectors relative to the axes' common point.
            free_a, free_b: Angles used when the corresponding rotation is free (u on axis a,
                v on axis b).

        Returns:
            Zero, one (tangent cones) or two solutions.
        """
        (ax, ay, az), (bx, by, bz), (nx, ny, nz) = self.a, self.b, self.normal
        (ux, uy, uz), (vx, vy, vz) = u, v
        ka, kb = ux * ax + uy * ay + uz * az, vx * bx + vy * by + vz * bz
        c, n2 = self.c, self.normal2
        alpha = (ka - c * kb) / n2
        beta = (kb - c * ka) / n2
        length2 = 0.5 * (ux * ux + uy * uy + uz * uz + vx * vx + vy * vy + vz * vz)
        rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c
        if rest < -CLAMP * max(length2, 1e-300):
            return []
        gamma = math.sqrt(max(rest, 0.0) / n2)
        # z = m ± γ n with m = α a + β b. Subproblem 1 about a (u to z) and about b (z to v):
        # θa = atan2(a·(u × z), u·z − ka²), θb = atan2(b·(z × v), z·v − kb²), where the
        # triple products reduce to a·(u × m) = −β u·n, a·(u × n) = u·b − c ka,
        # b·(m × v) = −α v·n, b·(n × v) = v·a − c kb.
        un, ub = ux * nx + uy * ny + uz * nz, ux * bx + uy * by + uz * bz
        vn, va = vx * nx + vy * ny + vz * nz, vx * ax + vy * ay + vz * az
        sin_a, sin_a_g, cos_a = -beta * un, ub - c * ka, alpha * ka + beta * ub - ka * ka
        sin_b, sin_b_g, cos_b = -alpha * vn, va - c * kb, alpha * va + beta * kb - kb * kb
        # u (v) on axis a (b): every angle θa (θb) is a solution
        px, py, pz = ux - ka * ax, uy - ka * ay, uz - ka * az
        a_free = px * px + py * py + pz * pz < FREE_TOL**2
        px, py, pz = vx - kb * bx, vy - kb * by, vz - kb * bz
        b_free = px * px + py * py + pz * pz < FREE_TOL**2
        out = []
        for g in (gamma, -gamma) if gamma > 0.0 else (gamma,):
            theta_a = free_a if a_free else math.atan2(sin_a + g * sin_a_g, cos_a + g * un)
            theta_b = free_b if b_free else math.atan2(sin_b + g * sin_b_g, cos_b + g * vn)
            out.append((theta_a, theta_b))
        return out

    def solve_many(self, u, v):
        """:meth:`solve` on arrays (``u``, ``v``: 3-tuples of arrays or floats, broadcastable):
        both solutions, γ then −γ, on a new second-to-last axis, as atan2 arguments.

        Returns:
            ((y_a, x_a), (y_b, x_b), ok, near_free): θa = atan2(y_a, x_a) and θb likewise;
            ``ok`` where the cones meet; ``near_free`` where u or v lies within
            :data:`_NEAR_FREE` of its axis (then :meth:`solve` may take the free values: the
            caller leaves those to it).
        """
        (ax, ay, az), (bx, by, bz), (nx, ny, nz) = self.a, self.b, self.normal
        (ux, uy, uz), (vx, vy, vz) = u, v
        ka, kb = ux * ax + uy * ay + uz * az, vx * bx + vy * by + vz * bz
        c, n2 = self.c, self.normal2
        alpha = (ka - c * kb) / n2
        beta = (kb - c * ka) / n2
        length2 = 0.5 * (ux * ux + uy * uy + uz * uz + vx * vx + vy * vy + vz * vz)
        rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c
        ok = rest >= -CLAMP * np.maximum(length2, 1e-300)
        gamma = np.sqrt(np.maximum(rest, 0.0) / n2)
        un, ub = ux * nx + uy * ny + uz * nz, ux * bx + uy * by + uz * bz
        vn, va = vx * nx + vy * ny + vz * nz, vx * ax + vy * ay + vz * az
        sin_a, sin_a_g, cos_a = -beta * un, ub - c * ka, alpha * ka + beta * ub - ka * ka
        sin_b, sin_b_g, cos_b = -alpha * vn, va - c * kb, alpha * va + beta * kb - kb * kb
        px, py, pz = ux - ka * ax, uy - ka * ay, uz - ka * az
        near_free = px * px + py * py + pz * pz < _NEAR_FREE**2
        px, py, pz = vx - kb * bx, vy - kb * by, vz - kb * bz
        near_free = near_free | (px * px + py * py + pz * pz < _NEAR_FREE**2)
        g = np.stack(np.broadcast_arrays(gamma, -gamma), axis=-2)

        def expand(x):  # a lane axis for the two solutions
            return np.expand_dims(x, -2) if np.ndim(x) else x

        a_parts = (expand(sin_a) + g * expand(sin_a_g), expand(cos_a) + g * expand(un))
        b_parts = (expand(sin_b) + g * expand(sin_b_g), expand(cos_b) + g * expand(vn))
        return a_parts, b_parts, expand(ok), expand(near_free)


#: Per joint: (reference, reference clipped into the limits, lower, upper, weight) [rad, –].
_Joint = tuple[float, float, float, float, float]

#: The batch path (:meth:`PandaIK.nearest_many`) leaves to :meth:`PandaIK.nearest` every pose
#: where a vector comes within this [m or –] of a rotation axis it is turned about (the
#: single-pose path takes the reference's angle below ``FREE_TOL``).
_NEAR_FREE = 1e-9


# ---------------------------------------------------------------------------- geometry
def _floats(v: np.ndarray) -> Vec:
    return (float(v[0]), float(v[1]), float(v[2]))


def _matrix_floats(m: np.ndarray) -> Mat:
    """A 3×3 matrix as 9 floats, row by row."""
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = (float(x) for x in m.reshape(9))
    return (m00, m01, m02, m10, m11, m12, m20, m21, m22)


def _line_intersection(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray):
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


def _distance_to_line(x: np.ndarray, p: np.ndarray, u: np.ndarray) -> float:
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


def panda_geometry(robot: Robot) -> PandaGeometry | None:
    """The panda-type geometry of ``robot`` (see the module docstring), or None.

    Read from the Pinocchio model's joint placements, axes and tool frame (via the world-frame
    joint screws at q = 0); None for any arm without that structure.
    """
    if robot.nq != 7:
        return None
    screws = screws_at_zero(robot)
    if screws is None:
        return None
    u, p = screws.directions, screws.points
    shoulder = _line_intersection(p[0], u[0], p[1], u[1])
    if shoulder is None or _distance_to_line(shoulder, p[2], u[2]) > STRUCTURE_TOL:
        return None
    if np.linalg.norm(np.cross(u[1], u[2])) < STRUCTURE_TOL:
        return None
    wrist = _line_intersection(p[4], u[4], p[5], u[5])
    if wrist is None:
        return None
    for point in (shoulder, wrist):  # θ4 must change the shoulder–wrist distance
        if _distance_to_line(point, p[3], u[3]) < 1e3 * STRUCTURE_TOL:
            return None
    tool = screws.tool
    return PandaGeometry(
        axes=tuple(_floats(a) for a in u),
        points=tuple(_floats(x) for x in p),
        shoulder=_floats(shoulder),
        wrist=_floats(wrist),
        tool_rotation=_matrix_floats(tool.rotation),
        tool_translation=_floats(tool.translation),
    )


# ---------------------------------------------------------------------------- solver
class PandaIK:
    """Closed-form IK of a panda-type arm for a fixed θ7, with a θ7 search for :meth:`nearest`.

    Args:
        geometry: The arm at q = 0 (:func:`panda_geometry`).
        lower: Lower joint limits [rad], shape (7,).
        upper: Upper joint limits [rad], shape (7,).
        weights: Joint weights w of the distance Σ wᵢ Δqᵢ² by which :meth:`nearest` chooses
            (default: all ones), shape (7,).
    """

    nq = 7
    needs_rotation = True

    def __init__(
        self,
        geometry: PandaGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        self.geometry = geometry
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.weights = np.ones(7) if weights is None else np.asarray(weights, dtype=float)
        self._lo = [float(x) for x in self.lower]
        self._hi = [float(x) for x in self.upper]
        self._w = [float(x) for x in self.weights]
        self._limits = tuple(zip(self._lo, self._hi, self._w))
        self._mid_joints = self._joints(0.5 * (self.lower + self.upper))
        self._constants: tuple[np.ndarray, ...] | None = None  # of the compiled solve
        g = geometry
        self._wrist_pair = _AxisPair.of(g.axes[4], g.axes[5])  # Ra = axis 5, Rb = axis 6
        self._shoulder_pair = _AxisPair.of(g.axes[1], g.axes[0])  # Ra = axis 2, Rb = axis 1
        self._e3 = _floats(plane_basis(np.array(g.axes[2]))[0])  # ⟂ axis 3, for θ3
        # θ4: s and w relative to a point of axis 4, split along / across the axis
        a4, p4 = g.axes[3], g.points[3]
        s, w = _sub(g.shoulder, p4), _sub(g.wrist, p4)
        self._s4, self._w4 = s, w
        s_along = _dot(a4, s)
        s_perp = (s[0] - s_along * a4[0], s[1] - s_along * a4[1], s[2] - s_along * a4[2])
        self._q4_const = _dot(w, a4) * s_along  # w·s_par
        self._q4_cos = _dot(w, s_perp)  # coefficient of cos(−θ4)
        self._q4_sin = _dot(w, _cross(a4, s))  # coefficient of sin(−θ4)
        self._q4_amplitude = math.hypot(self._q4_cos, self._q4_sin)
        self._q4_phase = math.atan2(self._q4_sin, self._q4_cos)
        self._q4_lengths = _dot(s, s) + _dot(w, w)
        # |y − w|² (y as in _solve) for which θ4 has a value within its limits: cos(θ4 + phase)
        # is the ratio of _elbow, which falls as |y − w|² grows
        low, high = _cos_range(self._lo[3] + self._q4_phase, self._hi[3] + self._q4_phase)
        self._elbow_distance2 = tuple(
            self._q4_lengths - 2.0 * (self._q4_const + self._q4_amplitude * ratio)
            for ratio in (high, low)
        )
        self._p7_from_wrist = _sub(g.points[6], g.wrist)
        m = g.tool_rotation
        self._tool_rotation_t: Mat = (m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8])
        span = self._hi[6] - self._lo[6]
        self._q7_grids = [
            [self._lo[6] + (i + 0.5) * span / cells for i in range(cells)] for cells in _Q7_GRIDS
        ]

    # ------------------------------------------------------------ input checks
    def _pose(self, position, rotation) -> tuple[Vec, Mat]:
        """(position, row-major rotation) as floats; InputError when malformed."""
        p = np.asarray(position, dtype=float)
        r = np.asarray(rotation, dtype=float)
        if p.shape != (3,) or r.shape != (3, 3):
            raise InputError(
                f"a pose needs a 3-vector position [m] and a 3×3 rotation, got shapes "
                f"{p.shape} and {r.shape}"
            )
        p_list, r_list = p.tolist(), r.reshape(-1).tolist()
        if not math.isfinite(sum(p_list) + sum(r_list)):
            raise InputError(f"the pose must be finite, got {p_list} and {r_list}")
        return tuple(p_list), tuple(r_list)

    def _joints(self, q_ref) -> list[_Joint]:
        """Per joint: (reference, reference clipped into the limits, lower, upper, weight)."""
        q = np.asarray(q_ref, dtype=float)
        if q.shape != (7,):
            raise InputError(f"q_ref must be a vector of 7 joint values, got shape {q.shape}")
        ref = q.tolist()
        if not math.isfinite(sum(ref)):
            raise InputError(f"q_ref must be finite, got {ref}")
        return [(r, min(max(r, lo), hi), lo, hi, w) for r, (lo, hi, w) in zip(ref, self._limits)]

    # ------------------------------------------------------------ the closed form
    def _prepare(self, position: Vec, rotation: Mat) -> tuple[Vec, Mat]:
        """The θ7-independent part of a pose (world frame).

        Returns:
            ``M T⁻¹ s`` [m] (the shoulder centre seen from the tool frame, placed at the tool's
            zero pose) and ``R_T M_Rᵀ`` (row-major).
        """
        g = self.geometry
        r = rotation
        d = _sub(g.shoulder, position)
        local = (  # R_Tᵀ (s − p_T)
            r[0] * d[0] + r[3] * d[1] + r[6] * d[2],
            r[1] * d[0] + r[4] * d[1] + r[7] * d[2],
            r[2] * d[0] + r[5] * d[1] + r[8] * d[2],
        )
        moved = _matvec(g.tool_rotation, local)
        t = g.tool_translation
        seen = (moved[0] + t[0], moved[1] + t[1], moved[2] + t[2])
        return seen, _matmul(rotation, self._tool_rotation_t)

    def _solve(
        self, prepared: tuple[Vec, Mat], q7: float, joints: list[_Joint], prune: bool
    ) -> list[tuple[list[float], float]]:
        """The solutions within the limits for one θ7.

        Joint by joint (θ4, then θ5 and θ6, then the shoulder), each branch's value is replaced
        by its 2π-equivalent within the limits nearest the reference (the branch is dropped when
        there is none), and the weighted squared distance Σ wᵢ Δqᵢ² to the reference is summed.

        Args:
            prepared: :meth:`_prepare` of the pose.
            q7: θ7 [rad], within its limits.
            joints: :meth:`_joints` of the reference; free joints (singularities) take the
                reference values.
            prune: Only keep a solution nearer than every earlier one (branch and bound): the
                last entry is then the nearest.

        Returns:
            (configuration [rad], distance [rad²]) pairs.
        """
        g = self.geometry
        seen, rotation_tm = prepared
        a4, a5, a6, a7, p7 = g.axes[3], g.axes[4], g.axes[5], g.axes[6], g.points[6]
        # y = exp(S7 θ7) M T⁻¹ s: the shoulder centre as the wrist joints see it
        y = _rotate(_sub(seen, p7), a7, q7)
        v = (y[0] + p7[0] - g.wrist[0], y[1] + p7[1] - g.wrist[1], y[2] + p7[2] - g.wrist[2])
        rotation_p = None  # R_P, computed when a branch gets as far as the shoulder
        base = joints[6][4] * (q7 - joints[6][0]) ** 2
        bound = math.inf
        out: list[tuple[list[float], float]] = []
        # the wrist part of every branch first: (distance so far, θ4, θ5, θ6, cos and sin of −θ4)
        wrists = []
        free5, free6 = -joints[4][1], -joints[5][1]
        for raw4 in self._elbow(_dot(v, v)):
            c4 = joint_choice(raw4, joints[3])
            if c4 is None:
                continue
            q4, cost4 = c4[0], base + c4[1]
            cos4, sin4 = math.cos(q4), -math.sin(q4)  # rotations by −θ4
            u = _sub(_rotate_cs(self._s4, a4, cos4, sin4), self._w4)  # exp(−S4 θ4) s − w
            for t5, t6 in self._wrist_pair.solve(u, v, free5, free6):
                c5 = joint_choice(-t5, joints[4])
                if c5 is None:
                    continue
                c6 = joint_choice(-t6, joints[5])
                if c6 is not None:
                    wrists.append((cost4 + c5[1] + c6[1], q4, c5[0], c6[0], cos4, sin4))
        if prune:  # nearest first: its bound then cuts the most
            wrists.sort(key=itemgetter(0))
        for cost6, q4, q5, q6, cos4, sin4 in wrists:
            if prune and cost6 >= bound:
                break
            if rotation_p is None:
                rotation_p = _matmul(rotation_tm, _rotation_matrix(a7, -q7))
            # G = R_P R6(−θ6) R5(−θ5) R4(−θ4) = R1 R2 R3, applied to ω3 and e
            cos5, sin5, cos6, sin6 = math.cos(q5), -math.sin(q5), math.cos(q6), -math.sin(q6)
            g3 = _rotate_cs(_rotate_cs(g.axes[2], a4, cos4, sin4), a5, cos5, sin5)
            ge = _rotate_cs(_rotate_cs(self._e3, a4, cos4, sin4), a5, cos5, sin5)
            g3 = _matvec(rotation_p, _rotate_cs(g3, a6, cos6, sin6))
            ge = _matvec(rotation_p, _rotate_cs(ge, a6, cos6, sin6))
            for t2, t1 in self._shoulder_pair.solve(g.axes[2], g3, joints[1][1], joints[0][1]):
                c1, c2 = joint_choice(t1, joints[0]), joint_choice(t2, joints[1])
                if c1 is None or c2 is None:
                    continue
                cost2 = cost6 + c1[1] + c2[1]
                if prune and cost2 >= bound:
                    continue
                # R3(θ3) e = R2(−θ2) R1(−θ1) G e
                h = _rotate(_rotate(ge, g.axes[0], -t1), g.axes[1], -t2)
                t3 = _angle_about(g.axes[2], self._e3, h, joints[2][1])
                c3 = joint_choice(t3, joints[2])
                if c3 is None:
                    continue
                cost = cost2 + c3[1]
                if prune and cost >= bound:
                    continue
                out.append(([c1[0], c2[0], c3[0], q4, q5, q6, q7], cost))
                if prune:
                    bound = cost
        return out

    def _elbow_q7_intervals(self, prepared: tuple[Vec, Mat]) -> list[tuple[float, float]]:
        """The θ7 values [rad] within its limits for which θ4 has a solution within its limits.

        With d = ``M T⁻¹ s`` − p7 and c = p7 − w, |y − w|² = |Rot(ω7, θ7) d + c|²
        = K + 2 (A cos θ7 + B sin θ7) (Rodrigues); θ4 exists within its limits exactly when
        this lies in the range precomputed from those limits (see ``__init__``).

        Returns:
            Sorted disjoint intervals (possibly none: then no θ7 gives a solution).
        """
        a, c = self.geometry.axes[6], self._p7_from_wrist
        d = _sub(prepared[0], self.geometry.points[6])
        ad, ac = _dot(a, d), _dot(a, c)
        cos_part, sin_part = _dot(c, d) - ac * ad, _dot(c, _cross(a, d))
        mean = _dot(d, d) + _dot(c, c) + 2.0 * ac * ad
        amplitude = 2.0 * math.hypot(cos_part, sin_part)
        low, high = self._elbow_distance2
        lo7, hi7 = self._lo[6], self._hi[6]
        if amplitude < FREE_TOL:  # θ7 does not change the distance
            return [(lo7, hi7)] if low <= mean <= high else []
        c_low, c_high = (low - mean) / amplitude, (high - mean) / amplitude
        if c_low > 1.0 or c_high < -1.0:
            return []
        near = math.acos(min(c_high, 1.0))  # cos(θ7 − φ) ∈ [c_low, c_high]
        far = math.acos(max(c_low, -1.0))
        phi = math.atan2(sin_part, cos_part)
        return _intervals_within([(phi + near, phi + far), (phi - far, phi - near)], lo7, hi7)

    def _elbow(self, distance2: float) -> list[float]:
        """θ4 [rad] (up to two) with |exp(−S4 θ4) s − w|² = ``distance2`` [m²]."""
        # |R(φ)s − w|² = |s|² + |w|² − 2 w·R(φ)s, w·R(φ)s = w·s_par + A cos φ + B sin φ, φ = −θ4
        target = 0.5 * (self._q4_lengths - distance2) - self._q4_const
        ratio = target / self._q4_amplitude
        if abs(ratio) > 1.0 + CLAMP:
            return []
        spread = math.acos(min(max(ratio, -1.0), 1.0))
        if spread == 0.0:
            return [-self._q4_phase]
        return [-(self._q4_phase + spread), -(self._q4_phase - spread)]

    # ------------------------------------------------------------ public API
    def solutions_q7(self, position: np.ndarray, rotation: np.ndarray, q7: float) -> np.ndarray:
        """All solutions within the joint limits with the last joint at ``q7``.

        Each solution appears once, as its 2π-equivalent within the limits closest to
        mid-range. At a singularity a free joint takes its mid-range value.

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation (3×3) in the world frame.
            q7: The last joint's angle [rad]; outside its limits there is no solution.

        Returns:
            Joint configurations [rad], shape (k, 7), 0 ≤ k ≤ 8.
        """
        q7 = float(q7)
        prepared = self._prepare(*self._pose(position, rotation))
        if not self._lo[6] - LIMIT_TOL <= q7 <= self._hi[6] + LIMIT_TOL:
            return np.empty((0, 7))
        q7 = min(max(q7, self._lo[6]), self._hi[6])
        found: list[list[float]] = []
        for q, _ in self._solve(prepared, q7, self._mid_joints, prune=False):
            if not any(max(abs(a - b) for a, b in zip(q, other)) <= _SAME_TOL for other in found):
                found.append(q)
        return np.array(found).reshape(-1, 7)

    def kernel_constants(self) -> tuple[np.ndarray, ...]:
        """The geometry and precomputed terms the compiled solve reads
        (:func:`kinplan.ik.panda_kernel.nearest_for_q7`), as arrays."""
        g = self.geometry
        vectors = [g.points[6], g.wrist, self._s4, self._w4, self._e3, (0.0, 0.0, 0.0)]
        elbow = [self._q4_lengths, self._q4_const, self._q4_amplitude, self._q4_phase]
        pairs = [
            [*pair.a, *pair.b, pair.c, *pair.normal, pair.normal2]
            for pair in (self._wrist_pair, self._shoulder_pair)
        ]
        limits = [self.lower, self.upper, self.weights]
        return tuple(np.array(x, dtype=float) for x in (g.axes, vectors, elbow, pairs, limits))

    def _compiled_inputs(
        self, prepared: tuple[Vec, Mat], q_ref: np.ndarray
    ) -> tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray, np.ndarray] | None:
        """What the compiled solve of this pose needs (constants, ``M T⁻¹ s``, ``R_T M_Rᵀ``,
        the reference), or None when it is not available (then the Python solve runs)."""
        from kinplan.ik import panda_kernel  # numba loads on first use

        if not panda_kernel.available():
            return None
        if self._constants is None:
            self._constants = self.kernel_constants()
        seen, rotation_tm = prepared
        return (
            self._constants,
            np.array(seen),
            np.array(rotation_tm).reshape(3, 3),
            np.asarray(q_ref, dtype=float),
        )

    def _best(
        self,
        prepared: tuple[Vec, Mat],
        q7_values: list[float],
        joints: list[_Joint],
        compiled: tuple | None = None,
    ) -> list[float] | None:
        """The solution nearest the reference over the given θ7 values [rad], or None.
        ``compiled``: :meth:`_compiled_inputs` of the pose, for the compiled solve (the same
        arithmetic; the Python one without)."""
        best, best_cost = None, math.inf
        if compiled is not None:
            from kinplan.ik import panda_kernel

            out = np.empty(7)
            constants, seen, rotation_tm, q_ref = compiled
            for q7 in q7_values:
                cost = panda_kernel.nearest_for_q7(constants, seen, rotation_tm, q7, q_ref, out)
                if cost < best_cost:
                    best, best_cost = out.tolist(), cost
            return best
        for q7 in q7_values:
            found = self._solve(prepared, q7, joints, prune=True)
            if found and found[-1][1] < best_cost:
                best, best_cost = found[-1]
        return best

    def _q7_stages(self, q7_ref: float, intervals: list[tuple[float, float]], tried: set[float]):
        """θ7 values [rad] to try after ``tried``, stage by stage: ±steps around ``q7_ref``, then
        finer grids over the range, each value moved into the set where the elbow can reach
        (``intervals``, see :meth:`_elbow_q7_intervals`); values tried before are skipped."""
        stages = [[q7_ref + step, q7_ref - step] for step in _Q7_STEPS]
        for stage in stages + self._q7_grids:
            values = []
            for value in stage:
                value = _project(min(max(value, self._lo[6]), self._hi[6]), intervals)
                if value not in tried:
                    tried.add(value)
                    values.append(value)
            if values:
                yield values

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """The solution nearest ``q_ref`` (weighted distance Σ wᵢ Δqᵢ²), or None.

        θ7 is searched stage by stage; the nearest solution of the first stage that has one
        is returned. The search runs within the set of θ7 values for which θ4 exists within its
        limits (:meth:`_elbow_q7_intervals`, closed form; when it is empty there is no
        solution). Stages: ``q_ref[6]`` (clipped into its limits) when that set holds it, else
        the point a quarter of the way into the set's nearest interval; then the middle of that
        interval; then ``q_ref[6]`` ± 0.05, 0.1, 0.2, … rad, then grids of 16, 64, 256, 1024
        cells over the range, each value moved to the nearest point of the set. (On random
        pairs of targets and references, the middle of the interval has a solution twice as
        often as its edge.)

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation (3×3) in the world frame, or None (then None: a redundant
                arm's position-only IK is left to the numerical solver).
            q_ref: Reference configuration [rad], shape (7,).

        Returns:
            The configuration [rad], shape (7,), or None when the search finds no solution.
        """
        if rotation is None:
            return None
        joints = self._joints(q_ref)
        prepared = self._prepare(*self._pose(position, rotation))
        intervals = self._elbow_q7_intervals(prepared)
        if not intervals:
            return None
        q7_ref = joints[6][1]
        start, end = min(intervals, key=lambda ab: max(ab[0] - q7_ref, q7_ref - ab[1]))
        if start <= q7_ref <= end:
            first = q7_ref
        else:
            first = start + 0.25 * (end - start) if q7_ref < start else end - 0.25 * (end - start)
        compiled = self._compiled_inputs(prepared, q_ref)
        best = self._best(prepared, [first], joints, compiled)
        middle = 0.5 * (start + end)
        if best is None and middle != first:
            best = self._best(prepared, [middle], joints, compiled)
        if best is None:
            for stage in self._q7_stages(q7_ref, intervals, {first, middle}):
                best = self._best(prepared, stage, joints, compiled)
                if best is not None:
                    break
        return None if best is None else np.array(best)

    # ------------------------------------------------------------ many poses at once
    def nearest_many(
        self, positions: np.ndarray, rotations: np.ndarray, q_ref: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference, vectorised (inputs
        unchecked).

        The θ7 search runs stage by stage on all poses at once: each stage solves the closed
        form for every (pose, θ7 value) pair still open (:meth:`_solve_rows`) and closes the
        poses it solves, so a pose takes the first stage with a solution and, within it, the
        nearest one (the first θ7 value on ties), as :meth:`nearest`. (``nearest`` skips θ7
        values it tried before; they had no solution then, nor do they now.)

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 7).

        Returns:
            (q (N, 7) [rad], found (N,), left (N,)): ``left`` marks poses where some vector
            comes within :data:`_NEAR_FREE` of an axis it turns about (a free angle), which
            the caller solves with :meth:`nearest`; their other outputs are meaningless.
        """
        count = len(positions)
        q = np.zeros((count, 7))
        found = np.zeros(count, dtype=bool)
        left = np.zeros(count, dtype=bool)
        span = self._hi[6] - self._lo[6]
        if count == 0 or not math.isfinite(span):
            left[:] = count > 0
            return q, found, left
        refs = np.ascontiguousarray(np.asarray(q_ref, dtype=float).T)
        clipped = np.clip(refs, self.lower[:, None], self.upper[:, None])
        seen, rotation_tm = self._prepare_many(positions, rotations)
        starts, ends = self._elbow_q7_intervals_many(seen)
        q7_ref = clipped[6]
        distance = np.maximum(starts - q7_ref[:, None], q7_ref[:, None] - ends)
        nearest = np.argmin(np.nan_to_num(distance, nan=np.inf), axis=1)
        rows = np.arange(count)
        start, end = starts[rows, nearest], ends[rows, nearest]
        inside = (start <= q7_ref) & (q7_ref <= end)
        quarter = np.where(q7_ref < start, start + 0.25 * (end - start), end - 0.25 * (end - start))
        first = np.where(inside, q7_ref, quarter)
        middle = 0.5 * (start + end)
        lo7, hi7 = self._lo[6], self._hi[6]
        stages: list[np.ndarray] = [first[:, None], middle[:, None]]
        for step in _Q7_STEPS:
            stages.append(np.stack((q7_ref + step, q7_ref - step), axis=1))
        grids = [np.array(grid) for grid in self._q7_grids]
        pending = np.flatnonzero(np.isfinite(start))  # no interval: no solution
        tried = np.stack((first, middle), axis=1)[pending]  # θ7 values tried, per pending pose
        for index, stage in enumerate(stages + grids):
            if pending.size == 0:
                break
            if stage.ndim == 1:  # a grid: the same values for every pose
                values = np.broadcast_to(stage, (pending.size, stage.size))
            else:
                values = stage[pending]
            if index >= 2:
                values = _project_many(np.clip(values, lo7, hi7), starts[pending], ends[pending])
                # values tried before (in this stage or earlier) had no solution: skipped
                width = values.shape[1]
                same = np.any(values[:, :, None] == tried[:, None, :], axis=2)
                same |= np.any(
                    (values[:, :, None] == values[:, None, :]) & np.tri(width, k=-1, dtype=bool),
                    axis=2,
                )
                fresh = ~same
                tried = np.concatenate((tried, values), axis=1)
            else:
                fresh = np.ones(values.shape, dtype=bool)
            width = values.shape[1]
            cost = np.full(values.shape, np.inf)
            chosen = np.zeros(values.shape + (7,))
            row_singular = np.zeros(values.shape, dtype=bool)
            at, which = np.nonzero(fresh)
            if at.size:
                poses = pending[at]
                chosen[at, which], cost[at, which], row_singular[at, which] = self._solve_rows(
                    tuple(x[poses] for x in seen),
                    tuple(x[poses] for x in rotation_tm),
                    values[at, which],
                    refs[:, poses],
                    clipped[:, poses],
                )
            singular = row_singular.any(axis=1)
            best = np.argmin(cost, axis=1)  # ties: the first θ7 value, as _best
            solved = np.isfinite(cost[np.arange(len(best)), best]) & ~singular
            chosen = chosen[np.arange(len(best)), best]
            q[pending[solved]] = chosen[solved]
            found[pending[solved]] = True
            left[pending[singular]] = True
            tried = tried[~solved & ~singular]
            pending = pending[~solved & ~singular]
        return q, found, left

    def _prepare_many(self, positions: np.ndarray, rotations: np.ndarray):
        """:meth:`_prepare` of many poses: (``M T⁻¹ s`` as 3 arrays [m], ``R_T M_Rᵀ`` as 9
        arrays, row-major), each of shape (N,)."""
        g = self.geometry
        r = tuple(np.ascontiguousarray(rotations.reshape(-1, 9).T))
        p = tuple(np.ascontiguousarray(positions.T))
        d = (g.shoulder[0] - p[0], g.shoulder[1] - p[1], g.shoulder[2] - p[2])
        local = (
            r[0] * d[0] + r[3] * d[1] + r[6] * d[2],
            r[1] * d[0] + r[4] * d[1] + r[7] * d[2],
            r[2] * d[0] + r[5] * d[1] + r[8] * d[2],
        )
        moved = _matvec_many(g.tool_rotation, local)
        t = g.tool_translation
        seen = (moved[0] + t[0], moved[1] + t[1], moved[2] + t[2])
        return seen, _matmul_many(r, self._tool_rotation_t)

    def _elbow_q7_intervals_many(self, seen) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_elbow_q7_intervals` of many poses: (starts, ends), each (N, M) [rad], sorted
        and disjoint per row, NaN where a row has fewer than M intervals."""
        a, c = self.geometry.axes[6], self._p7_from_wrist
        d = _sub_many(seen, self.geometry.points[6])
        ad, ac = _dot_many(a, d), _dot_many(a, c)
        cos_part, sin_part = _dot_many(c, d) - ac * ad, _dot_many(c, _cross_many(a, d))
        mean = _dot_many(d, d) + _dot_many(c, c) + 2.0 * ac * ad
        # the transcendental functions of the math module, as _elbow_q7_intervals: the
        # intervals' ends must agree to the last bit (pieces that touch at ±π merge or not by it)
        amplitude = 2.0 * _map(math.hypot, cos_part, sin_part)
        low, high = self._elbow_distance2
        lo7, hi7 = self._lo[6], self._hi[6]
        with np.errstate(divide="ignore", invalid="ignore"):
            c_low, c_high = (low - mean) / amplitude, (high - mean) / amplitude
        near = _map(math.acos, np.clip(c_high, -1.0, 1.0))
        far = _map(math.acos, np.clip(c_low, -1.0, 1.0))
        phi = _map(math.atan2, sin_part, cos_part)
        pieces = [(phi + near, phi + far), (phi - far, phi - near)]
        # _intervals_within: each piece shifted by whole turns into [lo7, hi7]
        shifts = int((hi7 - lo7 + math.pi) // TAU) + 2
        found_a, found_b = [], []
        for piece_start, piece_end in pieces:
            k0 = np.ceil((lo7 - piece_end) / TAU)
            k_last = np.floor((hi7 - piece_start) / TAU)
            for extra in range(shifts):
                k = k0 + extra
                a_k = np.maximum(piece_start + k * TAU, lo7)
                b_k = np.minimum(piece_end + k * TAU, hi7)
                keep = (k <= k_last) & (a_k <= b_k)
                found_a.append(np.where(keep, a_k, np.inf))
                found_b.append(np.where(keep, b_k, np.inf))
        starts, ends = np.stack(found_a, axis=1), np.stack(found_b, axis=1)
        empty = ~((c_low <= 1.0) & (c_high >= -1.0))
        flat = amplitude < FREE_TOL  # θ7 does not change the distance
        whole = flat & (low <= mean) & (mean <= high)
        starts[empty | flat], ends[empty | flat] = np.inf, np.inf
        starts[whole, 0], ends[whole, 0] = lo7, hi7
        order = np.lexsort((ends, starts), axis=1)
        starts = np.take_along_axis(starts, order, axis=1)
        ends = np.take_along_axis(ends, order, axis=1)
        # merge as _intervals_within: a new interval where one starts past every end so far
        reach = np.maximum.accumulate(ends, axis=1)
        new = np.ones_like(starts, dtype=bool)
        new[:, 1:] = starts[:, 1:] > reach[:, :-1]
        new &= np.isfinite(starts)
        group = np.cumsum(new, axis=1) - 1
        merged_a = np.full(starts.shape, np.nan)
        merged_b = np.full(starts.shape, np.nan)
        rows = np.arange(len(starts))
        for j in range(starts.shape[1]):
            valid = np.isfinite(starts[:, j])
            r, gj = rows[valid], group[valid, j]
            merged_a[r, gj] = np.where(new[valid, j], starts[valid, j], merged_a[r, gj])
            merged_b[r, gj] = reach[valid, j]
        return merged_a, merged_b

    def _solve_rows(self, seen, rotation_tm, q7, refs, clipped):
        """:meth:`_solve` (the nearest solution) for many rows (pose, θ7) at once.

        Args:
            seen, rotation_tm: :meth:`_prepare_many` of each row's pose.
            q7: θ7 of each row [rad], within its limits, shape (R,).
            refs, clipped: References and references clipped into the limits (7, R).

        Returns:
            (q (R, 7) [rad], cost (R,) (inf: no solution within the limits), singular (R,)).
            Lanes run (θ4 branch, wrist branch, shoulder branch, row); cosines and sines of
            angles that come out of arccos or atan2 are taken from their arguments.
        """
        g = self.geometry
        a4, a5, a6, a7, p7 = g.axes[3], g.axes[4], g.axes[5], g.axes[6], g.points[6]
        limits = self._limits

        def choose(joint: int, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            lower, upper, weight = limits[joint]
            return joint_choice_many(values, refs[joint], clipped[joint], lower, upper, weight)

        with np.errstate(invalid="ignore", divide="ignore"):
            c7, s7 = np.cos(q7), np.sin(q7)
            y = _rotate_cs_many(_sub_many(seen, p7), a7, c7, s7)
            w = g.wrist
            v = (y[0] + p7[0] - w[0], y[1] + p7[1] - w[1], y[2] + p7[2] - w[2])
            base = limits[6][2] * (q7 - refs[6]) ** 2
            # θ4 (_elbow): two branches −(phase ± spread)
            ratio = (
                0.5 * (self._q4_lengths - _dot_many(v, v)) - self._q4_const
            ) / self._q4_amplitude
            ratio = np.where(np.abs(ratio) <= 1.0 + CLAMP, np.clip(ratio, -1.0, 1.0), np.nan)
            spread = np.arccos(ratio)
            sin_spread = np.sqrt(1.0 - ratio * ratio)
            phase = self._q4_phase
            q4, cost4 = choose(3, np.stack((-(phase + spread), -(phase - spread))))
            cost4 = base + cost4
            cp, sp = math.cos(phase), math.sin(phase)
            cos4 = np.stack((cp * ratio - sp * sin_spread, cp * ratio + sp * sin_spread))
            sin4 = np.stack((sp * ratio + cp * sin_spread, sp * ratio - cp * sin_spread))  # −sin
            u = _sub_many(_rotate_cs_many(self._s4, a4, cos4, sin4), self._w4)
            turned3 = _rotate_cs_many(g.axes[2], a4, cos4, sin4)
            turned_e = _rotate_cs_many(self._e3, a4, cos4, sin4)
            # θ5, θ6 (wrist pair): lanes (θ4 branch, wrist branch, row)
            (y5, x5), (y6, x6), ok, singular = self._wrist_pair.solve_many(u, v)
            q5, cost5 = choose(4, -np.arctan2(y5, x5))
            q6, cost6 = choose(5, -np.arctan2(y6, x6))
            cost6 = (cost4[:, None] + cost5) + cost6
            cost6 = np.where(ok, cost6, np.inf)
            n5, n6 = np.sqrt(x5 * x5 + y5 * y5), np.sqrt(x6 * x6 + y6 * y6)
            cos5, sin5, cos6, sin6 = x5 / n5, y5 / n5, x6 / n6, y6 / n6  # of −q5, −q6
            # the shoulder, only on the (θ4, wrist) lanes with a solution so far (compacted)
            count = len(q7)
            lanes = np.flatnonzero(np.isfinite(cost6).ravel())
            row = lanes % count
            pair = lanes // count  # 2·θ4 branch + wrist branch

            def pick(x, per_lane: bool = True):
                return x.reshape(-1)[lanes] if per_lane else x[row]

            cos5, sin5, cos6, sin6 = (pick(x) for x in (cos5, sin5, cos6, sin6))
            turned3 = tuple(x[pair >> 1, row] for x in turned3)
            turned_e = tuple(x[pair >> 1, row] for x in turned_e)
            # G = R_P R6(−θ6) R5(−θ5) R4(−θ4) = R1 R2 R3, applied to ω3 and e
            rotation_p = _matmul_many(
                tuple(pick(x, False) for x in rotation_tm),
                _rotation_matrix_cs(a7, c7[row], -s7[row]),
            )
            g3 = _matvec_many(
                rotation_p,
                _rotate_cs_many(_rotate_cs_many(turned3, a5, cos5, sin5), a6, cos6, sin6),
            )
            ge = _matvec_many(
                rotation_p,
                _rotate_cs_many(_rotate_cs_many(turned_e, a5, cos5, sin5), a6, cos6, sin6),
            )
            # θ1, θ2 (shoulder pair): (shoulder branch, lane)
            (y2, x2), (y1, x1), ok, near_free = self._shoulder_pair.solve_many(g.axes[2], g3)
            lane_refs, lane_clipped = refs[:, row], clipped[:, row]

            def choose_lanes(joint: int, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
                lower, upper, weight = limits[joint]
                return joint_choice_many(
                    values, lane_refs[joint], lane_clipped[joint], lower, upper, weight
                )

            q1, cost1 = choose_lanes(0, np.arctan2(y1, x1))
            q2, cost2 = choose_lanes(1, np.arctan2(y2, x2))
            cost2 = (pick(cost6) + cost1) + cost2
            cost2 = np.where(ok, cost2, np.inf)
            n1, n2 = np.sqrt(x1 * x1 + y1 * y1), np.sqrt(x2 * x2 + y2 * y2)
            # θ3: R3(θ3) e = R2(−θ2) R1(−θ1) G e
            h = _rotate_cs_many(
                _rotate_cs_many(ge, g.axes[0], x1 / n1, -y1 / n1), g.axes[1], x2 / n2, -y2 / n2
            )
            axis3, (ex, ey, ez) = g.axes[2], self._e3
            k = _dot_many(axis3, h)
            hx, hy, hz = h[0] - k * axis3[0], h[1] - k * axis3[1], h[2] - k * axis3[2]
            k = _dot_many(axis3, self._e3)
            ex, ey, ez = ex - k * axis3[0], ey - k * axis3[1], ez - k * axis3[2]
            near_free = near_free | (hx * hx + hy * hy + hz * hz < _NEAR_FREE**2)
            t3 = np.arctan2(
                _dot_many(axis3, _cross_many((ex, ey, ez), (hx, hy, hz))),
                ex * hx + ey * hy + ez * hz,
            )
            q3, cost3 = choose_lanes(2, t3)
            # back to (θ4, wrist, shoulder, row) lanes, inf where the wrist had no solution
            cost = np.full((8, count), np.inf)
            shoulder_q = np.zeros((3, 8, count))
            for branch in range(2):
                cost[2 * pair + branch, row] = cost2[branch] + cost3[branch]
                for j, values in enumerate((q1, q2, q3)):
                    shoulder_q[j, 2 * pair + branch, row] = values[branch]
            flagged = np.zeros(count, dtype=bool)
            flagged[row[np.any(near_free, axis=0)]] = True
        singular = np.any(singular.reshape(-1, count), axis=0) | flagged
        lane = np.argmin(cost, axis=0)  # ties: the first lane
        columns = np.arange(len(q7))
        out = np.empty((len(q7), 7))
        out[:, 0] = shoulder_q[0, lane, columns]
        out[:, 1] = shoulder_q[1, lane, columns]
        out[:, 2] = shoulder_q[2, lane, columns]
        out[:, 3] = q4[lane >> 2, columns]
        out[:, 4] = q5.reshape(4, -1)[lane >> 1, columns]
        out[:, 5] = q6.reshape(4, -1)[lane >> 1, columns]
        out[:, 6] = q7
        return out, cost[lane, columns], singular

    def nearest_batch(
        self, positions: np.ndarray, rotations: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray:
        """:meth:`nearest` sample by sample, each from the previous solution (the last one
        found; ``q_ref`` first). Rows of NaN where none is found. Shapes (N, 3), (N, 3, 3)."""
        if rotations is None:
            raise InputError(
                "the closed-form IK of this 7-joint arm needs the tool rotation; position-only "
                "targets are for the planar 2R (use Robot.ik instead)"
            )
        previous = np.asarray(q_ref, dtype=float)
        out = np.full((len(positions), 7), np.nan)
        for i, (position, rotation) in enumerate(zip(positions, rotations)):
            q = self.nearest(position, rotation, previous)
            if q is not None:
                out[i] = previous = q
        return out


# ---------------------------------------------------------------------------- factory
def panda_solver_for(robot: Robot, weights: np.ndarray | None = None) -> PandaIK | None:
    """The semi-analytic IK of a panda-type ``robot``, or None for any other arm (and for a
    panda-type arm with an unbounded, continuous joint: its numerical IK serves it).

    The structure is read from the Pinocchio model (:func:`panda_geometry`) and the solver is
    checked against Pinocchio's forward kinematics on random configurations.

    Args:
        robot: A :class:`kinplan.Robot`.
        weights: Joint weights of the distance by which :meth:`PandaIK.nearest` chooses.
    """
    geometry = panda_geometry(robot)
    if geometry is None:
        return None
    unbounded = ~(np.isfinite(robot.lower) & np.isfinite(robot.upper))
    if unbounded.any():  # the θ7 search and the mid-range references need finite limits
        names = ", ".join(n for n, u in zip(robot.joint_names, unbounded) if u)
        logger.debug("panda-type IK of %s not used: unbounded joints %s", robot.name, names)
        return None
    solver = PandaIK(geometry, robot.lower, robot.upper, weights)
    check = lambda pose, q: solver.solutions_q7(pose.translation, pose.rotation, q[6])  # noqa: E731
    if not self_check(robot, check):
        logger.debug("panda-type IK of %s disagrees with its forward kinematics", robot.name)
        return None
    return solver
