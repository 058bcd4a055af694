"""Closed-form IK of the UR family (Hawkins 2013, in screw form): eight solutions, vectorised
over poses, with a plain-float path for single poses.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from kinplan.ik.base import ClosedFormIK, NeedsBatch
from kinplan.ik.planar import planar_2r
from kinplan.ik.screws import (
    CLAMP,
    FREE_TOL,
    SIGNS,
    STRUCTURE_TOL,
    TINY,
    Screws,
    joint_choice,
    joint_choice_many,
    parallel,
    perpendicular,
    plane_basis,
    rotate_about,
    rotate_about_line,
    rotate_by,
    skew,
    wrap_angle,
)

logger = logging.getLogger(__name__)

#: URIK's fast single-pose path leaves to the batch path every pose where a cosine ratio (of θ1
#: or of the elbow) is within this of ±1: there arccos is ill-conditioned (near a straight elbow
#: the two paths' roundings give answers ~1e-14 / √(1 − |cos|) rad apart), and the reachability
#: test sits at the rim.
_FAST_EDGE = 1e-8

#: ... and every pose with |sin(θ5 − δ)| below this: near the wrist singularity θ4 and θ6 are
#: conditioned like 1e-14 / |sin(θ5 − δ)| (measured: 2e-11 rad apart at 1e-4, 9e-9 at 1e-6,
#: with the same FK error ~1e-15), and at the singularity θ6 is free.
_FAST_WRIST = 1e-4

#: The fast path assumes exactly orthonormal shoulder (u1, a) and wrist (u5, u6) axes and a wrist
#: centre on axes 5 and 6; a geometry further from that than this [m, –] uses the batch path.
_FAST_DEFECT = 1e-12


# ---------------------------------------------------------------------------- UR family
@dataclass(frozen=True)
class URGeometry:
    """A UR-type arm at q = 0 in the world frame (vectors (3,), lengths [m]).

    Attributes:
        u1, u5, u6: Unit axes of joints 1, 5, 6.
        cross1, cross5, cross6: ``skew(u).T`` of those axes (``v @ cross = u × v``).
        p1, p2, p4, p5, p6: Points on axes 1, 2, 4, 5, 6.
        a: Unit axis of joint 2; axes 3 and 4 are ``signs[1] * a`` and ``signs[2] * a``.
        signs: Directions (±1) of axes 2, 3, 4 relative to ``a``.
        b1: ``u1 × a``; ``n(θ1) = cos θ1·a + sin θ1·b1`` is axis 2's direction at θ1.
        e, f: Basis of the plane of joints 2–4, with (e, f, a) right-handed.
        r23, r34: Axis 2 → axis 3 and axis 3 → axis 4 in plane coordinates (e, f) [m].
        shoulder_offset: ``a·(c − p1)`` at q = 0, kept by joints 2–6 [m].
        delta5: θ5 at which axis 6 is parallel to ``a`` (wrist singularity) [rad].
        u5_cross_a: ``u5 × a``.
        centre_in_tool: Wrist centre (axes 5 ∩ 6) in the tool frame [m].
        tool_rotation: Tool rotation at q = 0.
        tool_position: Tool position at q = 0 [m].
    """

    u1: np.ndarray
    u5: np.ndarray
    u6: np.ndarray
    cross1: np.ndarray
    cross5: np.ndarray
    cross6: np.ndarray
    p1: np.ndarray
    p2: np.ndarray
    p4: np.ndarray
    p5: np.ndarray
    p6: np.ndarray
    a: np.ndarray
    signs: np.ndarray
    b1: np.ndarray
    e: np.ndarray
    f: np.ndarray
    r23: np.ndarray
    r34: np.ndarray
    shoulder_offset: float
    delta5: float
    u5_cross_a: np.ndarray
    centre_in_tool: np.ndarray
    tool_rotation: np.ndarray
    tool_position: np.ndarray


def _axes_intersection(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray):
    """Intersection of two perpendicular lines (p, u) and (q, v), or None if they miss."""
    on_first = p + ((q - p) @ u) * u
    on_second = q + ((p - q) @ v) * v
    if np.linalg.norm(on_first - on_second) > STRUCTURE_TOL:
        return None
    return 0.5 * (on_first + on_second)


def ur_geometry(screws: Screws) -> URGeometry | None:
    """The UR structure of six revolute screws at q = 0, or None if they do not have it.

    Required: axis 1 ⊥ axis 2; axes 2, 3, 4 parallel (distinct, so both planar links have a
    length); axis 5 ⊥ axis 4; axes 5 and 6 intersect at right angles; the wrist centre is offset
    from the plane of axes 1 and 2 along ``a`` (the UR shoulder offset d4 ≠ 0).
    """
    u, p = screws.directions, screws.points
    a = u[1]
    structure = (
        perpendicular(u[0], a)
        and parallel(u[2], a)
        and parallel(u[3], a)
        and perpendicular(u[4], a)
        and perpendicular(u[5], u[4])
    )
    if not structure:
        return None
    centre = _axes_intersection(p[4], u[4], p[5], u[5])
    if centre is None:
        return None
    e, f = plane_basis(a)

    def in_plane(v: np.ndarray) -> np.ndarray:
        return np.array([v @ e, v @ f])

    r23, r34 = in_plane(p[2] - p[1]), in_plane(p[3] - p[2])
    if min(np.hypot(*r23), np.hypot(*r34)) < STRUCTURE_TOL:
        return None
    shoulder_offset = float(a @ (centre - p[0]))
    if abs(shoulder_offset) < STRUCTURE_TOL:  # θ1 would be free on axis 1: not the UR form
        return None
    tool_rotation = screws.tool.rotation.copy()
    tool_position = screws.tool.translation.copy()
    return URGeometry(
        u1=u[0],
        u5=u[4],
        u6=u[5],
        cross1=skew(u[0]).T,
        cross5=skew(u[4]).T,
        cross6=skew(u[5]).T,
        p1=p[0],
        p2=p[1],
        p4=p[3],
        p5=p[4],
        p6=p[5],
        a=a,
        signs=np.sign(u[1:4] @ a),
        b1=np.cross(u[0], a),
        e=e,
        f=f,
        r23=r23,
        r34=r34,
        shoulder_offset=shoulder_offset,
        delta5=float(np.arctan2(a @ np.cross(u[4], u[5]), a @ u[5])),
        u5_cross_a=np.cross(u[4], a),
        centre_in_tool=tool_rotation.T @ (centre - tool_position),
        tool_rotation=tool_rotation,
        tool_position=tool_position,
    )


# ---------------------------------------------------------------------------- UR fast single pose
@dataclass(frozen=True, slots=True)
class _URFast:
    """Constants of URIK's single-pose path in plain floats, read once from a :class:`URGeometry`.

    Two orthonormal frames of the arm at q = 0 carry the computation: the **shoulder frame**
    (u1, a, b1) and the **wrist frame** (u5, u6, w = u5 × u6), "coordinates" below being the
    components along their axes. For a target (R, P) let A = R·R_Mᵀ (R_M: tool rotation at q = 0).

    Attributes:
        matrix: (12, 9); ``matrix @ R.ravel()`` gives the wrist coordinates of Aᵀu1, Aᵀa, Aᵀb1
            (values 0–8) and the shoulder coordinates of R·c_tool (9–11) [m], c_tool being the
            wrist centre in the tool frame.
        shoulder_axes: u1, a, b1 in world coordinates (9 floats).
        p1_along: Shoulder coordinates of ``p1`` (a point on axis 1) [m].
        shoulder_offset: ``a·(c − p1)`` kept by joints 2–6 [m].
        delta5: θ5 at the wrist singularity [rad].
        a_wrist: Wrist coordinates of ``a``.
        d_wrist: Wrist coordinates of ``p4 − c`` (axis-4 point relative to the wrist centre) [m].
        e_wrist: Wrist coordinates of the plane axis ``e``.
        e_shoulder, f_shoulder: (u1, b1) coordinates of the plane axes ``e``, ``f``.
        plane_offset: ``(p1 − p2)·e``, ``(p1 − p2)·f`` [m].
        r23, r34: Planar links in (e, f) coordinates [m].
        l23, l34: Their lengths [m].
        elbow_offset: ``atan2(r23) − atan2(r34)`` [rad].
        signs: Directions (±1) of axes 2, 3, 4 relative to ``a``.
    """

    matrix: np.ndarray
    shoulder_axes: tuple[float, ...]
    p1_along: tuple[float, float, float]
    shoulder_offset: float
    delta5: float
    a_wrist: tuple[float, float, float]
    d_wrist: tuple[float, float, float]
    e_wrist: tuple[float, float, float]
    e_shoulder: tuple[float, float]
    f_shoulder: tuple[float, float]
    plane_offset: tuple[float, float]
    r23: tuple[float, float]
    r34: tuple[float, float]
    l23: float
    l34: float
    elbow_offset: float
    signs: tuple[float, float, float]


def _ur_fast_constants(g: URGeometry) -> _URFast | None:
    """The single-pose constants of ``g``, or None when its axes are not orthonormal enough.

    The batch path rotates about the axes as given; the single-pose path expands the same
    rotations in the orthonormal frames of :class:`_URFast`, exact only when u1 ⊥ a, u5 ⊥ u6 (all
    unit) and the wrist centre lies on axes 5 and 6. Any defect beyond ``_FAST_DEFECT`` leaves
    every pose to the batch path.
    """
    u1, a, b1, u5, u6 = g.u1, g.a, g.b1, g.u5, g.u6
    centre = g.tool_position + g.tool_rotation @ g.centre_in_tool

    def off_axis(point: np.ndarray, axis: np.ndarray) -> float:
        offset = centre - point
        return float(np.linalg.norm(offset - (offset @ axis) * axis))

    defect = max(
        *(abs(float(np.linalg.norm(v)) - 1.0) for v in (u1, a, u5, u6, g.e, g.f)),
        *(abs(float(x @ y)) for x, y in ((u1, a), (u5, u6), (g.e, a), (g.f, a), (g.e, g.f))),
        off_axis(g.p5, u5),
        off_axis(g.p6, u6),
    )
    if defect > _FAST_DEFECT:
        logger.debug("UR geometry %.1e from orthonormal: single poses use the batch path", defect)
        return None
    shoulder = np.stack((u1, a, b1))  # rows: the frame's axes in world coordinates
    wrist = np.stack((u5, u6, np.cross(u5, u6)))
    to_wrist = wrist @ g.tool_rotation  # wrist coordinates of R_M v, for v in world coordinates
    # row (j, i), column (l, k): (to_wrist)_ik · shoulder_jl, so the row is (to_wrist Rᵀ s_j)_i
    rotated_axes = np.einsum("ik,jl->jilk", to_wrist, shoulder).reshape(9, 9)
    rotated_centre = np.einsum("jl,k->jlk", shoulder, g.centre_in_tool).reshape(3, 9)
    plane_offset = g.p1 - g.p2

    def floats(v: np.ndarray) -> tuple[float, ...]:
        return tuple(float(x) for x in v)

    def vec2(v: np.ndarray) -> tuple[float, float]:
        x, y = floats(v)
        return x, y

    def vec3(v: np.ndarray) -> tuple[float, float, float]:
        x, y, z = floats(v)
        return x, y, z

    return _URFast(
        matrix=np.ascontiguousarray(np.vstack((rotated_axes, rotated_centre))),
        shoulder_axes=floats(shoulder.ravel()),
        p1_along=vec3(shoulder @ g.p1),
        shoulder_offset=float(g.shoulder_offset),
        delta5=float(g.delta5),
        a_wrist=vec3(wrist @ a),
        d_wrist=vec3(wrist @ (g.p4 - centre)),
        e_wrist=vec3(wrist @ g.e),
        e_shoulder=(float(g.e @ u1), float(g.e @ b1)),
        f_shoulder=(float(g.f @ u1), float(g.f @ b1)),
        plane_offset=(float(plane_offset @ g.e), float(plane_offset @ g.f)),
        r23=vec2(g.r23),
        r34=vec2(g.r34),
        l23=float(np.hypot(*g.r23)),
        l34=float(np.hypot(*g.r34)),
        elbow_offset=float(np.arctan2(g.r23[1], g.r23[0]) - np.arctan2(g.r34[1], g.r34[0])),
        signs=vec3(g.signs),
    )


def _fast_shoulder(
    k: _URFast, position: list[float], values: list[float]
) -> tuple[tuple[float, float], tuple[float, float, float]] | None:
    """θ1 [rad] of both shoulder branches (as :meth:`URIK._shoulder`), for one pose.

    Args:
        k: The arm's constants.
        position: Tool position P in the world frame [m].
        values: ``k.matrix @ R.ravel()``.

    Returns:
        ((θ1 for sign +1, θ1 for sign −1), shoulder coordinates (along u1, a, b1) of c − p1 [m],
        c the wrist centre at the target), or None when no θ1 keeps the shoulder offset.

    Raises:
        NeedsBatch: near the shoulder singularity (|d4| / radius within ``_FAST_EDGE`` of 1).
    """
    ux, uy, uz, ax, ay, az, bx, by, bz = k.shoulder_axes
    px, py, pz = position
    along_u = values[9] + ux * px + uy * py + uz * pz - k.p1_along[0]
    x = values[10] + ax * px + ay * py + az * pz - k.p1_along[1]
    y = values[11] + bx * px + by * py + bz * pz - k.p1_along[2]
    ratio = k.shoulder_offset / max(math.hypot(x, y), TINY)
    if abs(ratio) > 1.0 - _FAST_EDGE:
        if abs(ratio) > 1.0 + CLAMP + _FAST_EDGE:
            return None
        raise NeedsBatch
    half, base = math.acos(ratio), math.atan2(y, x)
    return (base + half, base - half), (along_u, x, y)


def _fast_wrist(
    k: _URFast, c1: float, s1: float, values: list[float]
) -> tuple[tuple[float, float], tuple[float, float]]:
    """θ5, θ6 [rad] of both wrist branches (signs +1, −1) for one θ1, as :meth:`URIK._wrist`.

    In wrist coordinates b = Aᵀ n(θ1) = cos θ1·Aᵀa + sin θ1·Aᵀb1: its u6 component is
    cos(θ5 − δ), the length of the rest |sin(θ5 − δ)|; θ6 is the angle about u6 from the part
    of R5ᵀa perpendicular to u6 to that of b.

    Args:
        k: The arm's constants.
        c1, s1: cos θ1, sin θ1.
        values: ``k.matrix @ R.ravel()``.

    Raises:
        NeedsBatch: near the wrist singularity (|sin(θ5 − δ)| < ``_FAST_WRIST``).
    """
    b5 = c1 * values[3] + s1 * values[6]
    b6 = c1 * values[4] + s1 * values[7]
    b7 = c1 * values[5] + s1 * values[8]
    sine = math.hypot(b5, b7)
    if sine < _FAST_WRIST:
        raise NeedsBatch
    half = math.atan2(sine, b6)
    a5, a6, a7 = k.a_wrist
    t5s, t6s = (k.delta5 + half, k.delta5 - half), []
    for t5 in t5s:
        c5, s5 = math.cos(t5), math.sin(t5)
        g5, g7 = c5 * a5, c5 * a7 - s5 * a6  # R5ᵀ a without its u6 component
        t6s.append(math.atan2(b7 * g5 - b5 * g7, b5 * g5 + b7 * g7))
    return t5s, (t6s[0], t6s[1])


def _fast_plane_axes(
    k: _URFast, c1: float, s1: float, centre: tuple[float, float, float], values: list[float]
) -> tuple[float, ...]:
    """What the planar step (:func:`_fast_planar_target`) needs of θ1.

    Args:
        k: The arm's constants.
        c1, s1: cos θ1, sin θ1.
        centre: Shoulder coordinates of c − p1 [m] (from :func:`_fast_shoulder`).
        values: ``k.matrix @ R.ravel()``.

    Returns:
        8 floats: the wrist coordinates of Aᵀ Rot(u1, θ1) e (3) and of Aᵀ Rot(u1, θ1) f (3), and
        the plane (e, f) coordinates relative to axis 2 [m] of where Rot(u1, −θ1) about axis 1
        takes the wrist centre c (2).
    """
    # Aᵀ Rot(u1, θ1) b1 = cos θ1·Aᵀb1 − sin θ1·Aᵀa, in wrist coordinates
    m5 = c1 * values[6] - s1 * values[3]
    m6 = c1 * values[7] - s1 * values[4]
    m7 = c1 * values[8] - s1 * values[5]
    (eu, eb), (fu, fb) = k.e_shoulder, k.f_shoulder
    along_u, x, y = centre
    turned_b1 = c1 * y - s1 * x  # (c − p1)·Rot(u1, θ1) b1
    return (
        eu * values[0] + eb * m5,
        eu * values[1] + eb * m6,
        eu * values[2] + eb * m7,
        fu * values[0] + fb * m5,
        fu * values[1] + fb * m6,
        fu * values[2] + fb * m7,
        k.plane_offset[0] + eu * along_u + eb * turned_b1,
        k.plane_offset[1] + fu * along_u + fb * turned_b1,
    )


def _fast_planar_target(
    k: _URFast, plane: tuple[float, ...], t5: float, t6: float
) -> tuple[float, float, float]:
    """The planar motion joints 2–4 must make, as :meth:`URIK._planar_target`, for one branch.

    The motion is X = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹. Axes 5 and 6 pass through the wrist centre c, and
    T M⁻¹ takes c to its place at the target, so X(p4) − p2 = (p1 − p2) + Rot(u1, −θ1)(c_T − p1)
    + Rot(u1, −θ1) A Z with Z = Rot(u6, −θ6) Rot(u5, −θ5)(p4 − c). Its plane coordinates are
    the ``plane`` offsets plus Z·Aᵀ Rot(u1, θ1) e and Z·Aᵀ Rot(u1, θ1) f; X's rotation about
    ``a`` follows in the same way from the image of e.

    Args:
        k: The arm's constants.
        plane: :func:`_fast_plane_axes` of the branch's θ1.
        t5, t6: θ5, θ6 [rad].

    Returns:
        (x, y, φ): where the motion takes the point of axis 4, in plane (e, f) coordinates
        relative to axis 2 [m], and its rotation about ``a`` [rad].
    """
    ge5, ge6, ge7, gf5, gf6, gf7, offset_e, offset_f = plane
    c5, s5, c6, s6 = math.cos(t5), math.sin(t5), math.cos(t6), math.sin(t6)
    d5, d6, d7 = k.d_wrist
    # Rot(u6, −θ6) Rot(u5, −θ5) (p4 − c), then the same for e, in wrist coordinates
    x6, x7 = c5 * d6 + s5 * d7, c5 * d7 - s5 * d6
    z5, z7 = c6 * d5 - s6 * x7, s6 * d5 + c6 * x7
    e5, e6, e7 = k.e_wrist
    y6, y7 = c5 * e6 + s5 * e7, c5 * e7 - s5 * e6
    v5, v7 = c6 * e5 - s6 * y7, s6 * e5 + c6 * y7
    return (
        offset_e + z5 * ge5 + x6 * ge6 + z7 * ge7,
        offset_f + z5 * gf5 + x6 * gf6 + z7 * gf7,
        math.atan2(v5 * gf5 + y6 * gf6 + v7 * gf7, v5 * ge5 + y6 * ge6 + v7 * ge7),
    )


def _fast_elbow(
    k: _URFast, x: float, y: float, phi: float
) -> tuple[tuple[float, float, float], tuple[float, float, float]] | None:
    """θ2, θ3, θ4 [rad] of both elbow branches (signs +1, −1), as :meth:`URIK._joints_234`.

    Args:
        k: The arm's constants.
        x, y: Target of the axis-4 point relative to axis 2, plane (e, f) coordinates [m].
        phi: Rotation of the planar motion about ``a`` [rad].

    Returns:
        One (θ2, θ3, θ4) per elbow branch, or None when the elbow cannot reach.

    Raises:
        NeedsBatch: elbow (nearly) straight or folded, |cos ψ3| within ``_FAST_EDGE`` of 1
        (this includes a target on axis 2, where θ2 would be free).
    """
    l23, l34 = k.l23, k.l34
    cosine = (x * x + y * y - l23**2 - l34**2) / (2.0 * l23 * l34)
    if abs(cosine) > 1.0 - _FAST_EDGE:
        if abs(cosine) > 1.0 + CLAMP + _FAST_EDGE:
            return None
        raise NeedsBatch
    bend = math.acos(cosine)
    (r1x, r1y), (r2x, r2y) = k.r23, k.r34
    direction = math.atan2(y, x)
    sign2, sign3, sign4 = k.signs
    branches = []
    for psi3 in (bend + k.elbow_offset, -bend + k.elbow_offset):
        cb, sb = math.cos(psi3), math.sin(psi3)
        psi2 = direction - math.atan2(r1y + sb * r2x + cb * r2y, r1x + cb * r2x - sb * r2y)
        branches.append((sign2 * psi2, sign3 * psi3, sign4 * (phi - psi2 - psi3)))
    return branches[0], branches[1]


# ---------------------------------------------------------------------------- UR fast, many poses
def _pair(first: np.ndarray, second: np.ndarray, axis: int) -> np.ndarray:
    """``first`` and ``second`` (same shape) stacked as index 0 and 1 of a new ``axis``."""
    return np.stack((first, second), axis=axis)


def _shoulder_terms(
    k: _URFast, positions: np.ndarray, rotations: np.ndarray
) -> tuple[np.ndarray, ...]:
    """The terms of many poses that θ1 comes from: the rotation and position terms (12, N),
    the wrist centre along the shoulder axis and across it (x, y), its distance from the axis
    (radius) and the shoulder offset over it (ratio, |ratio| > 1: no θ1); each (N,)."""
    n = len(positions)
    values = k.matrix @ rotations.reshape(n, 9).T  # (12, N)
    along = np.reshape(k.shoulder_axes, (3, 3)) @ positions.T  # (3, N)
    along_u = values[9] + along[0] - k.p1_along[0]
    x = values[10] + along[1] - k.p1_along[1]
    y = values[11] + along[2] - k.p1_along[2]
    radius = np.maximum(np.sqrt(x * x + y * y), TINY)
    return values, along_u, x, y, radius, k.shoulder_offset / radius


def _planar_targets(
    k: _URFast,
    values: np.ndarray,
    shoulder: tuple[np.ndarray, ...],
    wrist: tuple[np.ndarray, ...],
    expand: Callable[[np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The target of the planar joints 2–4 and the angle φ = ψ2 + ψ3 + ψ4 they must sum to,
    on arrays (the formulas of :func:`_fast_plane_axes` and :func:`_fast_planar_target`).

    Args:
        k: The arm's constants.
        values: The pose's rotation and position terms, (12, N).
        shoulder: (cos θ1, sin θ1, x, y, along u) of each shoulder solution.
        wrist: (cos θ5, sin θ5, cos θ6, sin θ6) of each wrist solution.
        expand: Makes a per-shoulder array broadcast against the wrist arrays (an axis for
            the wrist branches when both are solved, the identity for one branch).

    Returns:
        (target x, target y, φ), in the wrist arrays' shape.
    """
    c1, s1, x, y, along_u = shoulder
    c5, s5, c6, s6 = wrist
    m5 = c1 * values[6] - s1 * values[3]
    m6 = c1 * values[7] - s1 * values[4]
    m7 = c1 * values[8] - s1 * values[5]
    (eu, eb), (fu, fb) = k.e_shoulder, k.f_shoulder
    ge5, ge6, ge7 = (eu * values[j] + eb * mj for j, mj in enumerate((m5, m6, m7)))
    gf5, gf6, gf7 = (fu * values[j] + fb * mj for j, mj in enumerate((m5, m6, m7)))
    turned = c1 * y - s1 * x
    offset_e = (k.plane_offset[0] + eu * along_u) + eb * turned
    offset_f = (k.plane_offset[1] + fu * along_u) + fb * turned
    d5, d6, d7 = k.d_wrist
    x6, x7 = c5 * d6 + s5 * d7, c5 * d7 - s5 * d6
    z5, z7 = c6 * d5 - s6 * x7, s6 * d5 + c6 * x7
    e5, e6, e7 = k.e_wrist
    y6, y7 = c5 * e6 + s5 * e7, c5 * e7 - s5 * e6
    v5, v7 = c6 * e5 - s6 * y7, s6 * e5 + c6 * y7
    ge5, ge6, ge7, gf5, gf6, gf7 = (expand(g) for g in (ge5, ge6, ge7, gf5, gf6, gf7))
    target_x = expand(offset_e) + z5 * ge5 + x6 * ge6 + z7 * ge7
    target_y = expand(offset_f) + z5 * gf5 + x6 * gf6 + z7 * gf7
    phi = np.arctan2(v5 * gf5 + y6 * gf6 + v7 * gf7, v5 * ge5 + y6 * ge6 + v7 * ge7)
    return target_x, target_y, phi


def _fast_nearest_many(
    k: _URFast,
    joints: tuple[tuple[float, float, float], ...],
    positions: np.ndarray,
    rotations: np.ndarray,
    refs: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:meth:`URIK._nearest_fast` of many poses at once: the same formulas on arrays.

    Arrays run branch-major: (2, N) per shoulder branch, (2, 2, N) per (shoulder, wrist) pair,
    (2, 2, 2, N) per branch, so each step is a few numpy passes over contiguous rows. The
    cosine and sine of an angle that comes out of atan2 or arccos are taken from its arguments
    (no trigonometric call): atan2 and arccos are the only transcendental passes.

    Args:
        k: The arm's constants.
        joints: Per joint (lower, upper, weight).
        positions: Tool positions (N, 3) [m]; rotations: tool rotations (N, 3, 3).
        refs: References (6, N) [rad], one column per pose.

    Returns:
        (q (N, 6) [rad], branch (N,) int (−1: none within the limits), mask (N,) uint16 with
        bit b set when branch b has a solution within the limits, left (N,) bool: the poses
        :meth:`URIK.nearest` leaves to the batch path (near a singularity), whose other
        outputs are meaningless).
    """
    n = len(positions)
    values, along_u, x, y, radius, ratio = _shoulder_terms(k, positions, rotations)
    size = np.abs(ratio)
    no_shoulder = size > 1.0 + CLAMP + _FAST_EDGE
    left = (size > 1.0 - _FAST_EDGE) & ~no_shoulder
    np.copyto(ratio, np.nan, where=no_shoulder)  # NaN lanes: no solution, no tie to decide
    np.clip(ratio, -1.0, 1.0, out=ratio)
    # θ1 = base ± half: base = atan2(y, x), cos(half) = ratio
    base, half = np.arctan2(y, x), np.arccos(ratio)
    t1 = _pair(base + half, base - half, 0)  # (2, N)
    cos_base, sin_base = x / radius, y / radius
    sin_half = np.sqrt(np.maximum(1.0 - ratio * ratio, 0.0))
    p, m = cos_base * ratio, sin_base * sin_half
    c1 = _pair(p - m, p + m, 0)
    p, m = sin_base * ratio, cos_base * sin_half
    s1 = _pair(p + m, p - m, 0)
    # wrist (_fast_wrist): θ5 = δ ± half5, cos/sin of half5 from its atan2 arguments
    b5 = c1 * values[3] + s1 * values[6]
    b6 = c1 * values[4] + s1 * values[7]
    b7 = c1 * values[5] + s1 * values[8]
    sine = np.sqrt(b5 * b5 + b7 * b7)
    left |= np.any(sine < _FAST_WRIST, axis=0) & ~no_shoulder
    half5 = np.arctan2(sine, b6)
    t5 = _pair(k.delta5 + half5, k.delta5 - half5, 1)  # (2, 2, N)
    norm = np.maximum(np.sqrt(sine * sine + b6 * b6), TINY)
    cos_half5, sin_half5 = b6 / norm, sine / norm
    cos_d, sin_d = math.cos(k.delta5), math.sin(k.delta5)
    p, m = cos_d * cos_half5, sin_d * sin_half5
    c5 = _pair(p - m, p + m, 1)
    p, m = sin_d * cos_half5, cos_d * sin_half5
    s5 = _pair(p + m, p - m, 1)
    a5, a6, a7 = k.a_wrist
    g5, g7 = c5 * a5, c5 * a7 - s5 * a6
    b5, b7 = b5[:, None], b7[:, None]
    sin6, cos6 = b7 * g5 - b5 * g7, b5 * g5 + b7 * g7
    t6 = np.arctan2(sin6, cos6)
    norm = np.maximum(np.sqrt(sin6 * sin6 + cos6 * cos6), TINY)
    c6, s6 = cos6 / norm, sin6 / norm
    # _fast_plane_axes per shoulder branch, _fast_planar_target per (shoulder, wrist) pair
    target_x, target_y, phi = _planar_targets(
        k, values, (c1, s1, x, y, along_u), (c5, s5, c6, s6), lambda a: a[:, None]
    )
    # _fast_elbow: ψ3 = offset ± bend; ψ2 = atan2(target) − atan2(v), v = r23 + Rot(ψ3) r34,
    # taken as one atan2
    l23, l34 = k.l23, k.l34
    cosine = (target_x * target_x + target_y * target_y - (l23 * l23 + l34 * l34)) / (
        2.0 * l23 * l34
    )
    size = np.abs(cosine)
    no_elbow = size > 1.0 + CLAMP + _FAST_EDGE  # (2, 2, N)
    near_edge = (size > 1.0 - _FAST_EDGE) & ~no_elbow
    left |= np.any(near_edge.reshape(4, n), axis=0) & ~no_shoulder
    np.copyto(cosine, np.nan, where=no_elbow)
    np.clip(cosine, -1.0, 1.0, out=cosine)
    bend = np.arccos(cosine)
    sin_bend = np.sqrt(np.maximum(1.0 - cosine * cosine, 0.0))
    offset = k.elbow_offset
    psi3 = _pair(offset + bend, offset - bend, 2)  # (2, 2, 2, N)
    (r1x, r1y), (r2x, r2y) = k.r23, k.r34
    co, so = math.cos(offset), math.sin(offset)
    ax, ay = co * r2x - so * r2y, so * r2x + co * r2y  # Rot(offset) r34
    # v = r23 + cos(bend)·(ax, ay) ± sin(bend)·(−ay, ax) for ψ3 = offset ± bend
    vx, vy = r1x + ax * cosine, r1y + ay * cosine
    dx, dy = ay * sin_bend, ax * sin_bend
    # ψ2 = atan2(v × target, v · target) with v = (vx ∓ dx, vy ± dy)
    cross0, cross1 = vx * target_y - vy * target_x, dx * target_y + dy * target_x
    dot0, dot1 = vx * target_x + vy * target_y, dy * target_y - dx * target_x
    psi2 = np.arctan2(
        _pair(cross0 - cross1, cross0 + cross1, 2), _pair(dot0 + dot1, dot0 - dot1, 2)
    )
    sign2, sign3, sign4 = k.signs
    t4 = phi[:, :, None] - psi2 - psi3
    # the nearest branch (_nearest_fast): per joint the equivalent nearest the reference
    ref_clipped = np.clip(refs, [[j[0]] for j in joints], [[j[1]] for j in joints])

    def choose(joint: int, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lower, upper, weight = joints[joint]
        return joint_choice_many(values, refs[joint], ref_clipped[joint], lower, upper, weight)

    q1, cost1 = choose(0, t1)
    q5, cost5 = choose(4, t5)
    q6, cost6 = choose(5, t6)
    head = (cost1[:, None] + cost5) + cost6  # the order of _nearest_fast's sums
    q2, cost2 = choose(1, sign2 * psi2)
    q3, cost3 = choose(2, sign3 * psi3)
    q4, cost4 = choose(3, sign4 * t4)
    cost = (((head[:, :, None] + cost2) + cost3) + cost4).reshape(8, n)
    branch = np.argmin(cost, axis=0)  # ties: the lower branch index, as _nearest_fast
    columns = np.arange(n)
    found = cost[branch, columns] < np.inf
    mask = np.zeros(n, dtype=np.uint16)
    for b in range(8):
        mask |= (cost[b] < np.inf).astype(np.uint16) << b
    q = np.empty((n, 6))
    pair = branch >> 1
    q[:, 0] = q1[branch >> 2, columns]
    q[:, 1] = q2.reshape(8, n)[branch, columns]
    q[:, 2] = q3.reshape(8, n)[branch, columns]
    q[:, 3] = q4.reshape(8, n)[branch, columns]
    q[:, 4] = q5.reshape(4, n)[pair, columns]
    q[:, 5] = q6.reshape(4, n)[pair, columns]
    return q, np.where(found, branch, -1), mask, left


def _fast_branch_many(
    k: _URFast, positions: np.ndarray, rotations: np.ndarray, branch: np.ndarray | int
) -> tuple[np.ndarray, np.ndarray]:
    """One branch of many poses: the formulas of :func:`_fast_nearest_many` for a single
    (shoulder, wrist, elbow) sign triple per pose, with no nearest-branch choice.

    Args:
        k: The arm's constants.
        positions: Tool positions (N, 3) [m]; rotations: tool rotations (N, 3, 3).
        branch: Branch index ``4·shoulder + 2·wrist + elbow`` (as :class:`URIK`), one for all
            poses or one per pose (N,).

    Returns:
        (q (N, 6) [rad], raw angles (any 2π representative), NaN rows where the branch has no
        solution; edge (N,) bool: the poses :meth:`URIK.nearest` leaves to the batch path near
        a singularity on this branch, whose q is ill-conditioned).
    """
    n = len(positions)
    branch = np.asarray(branch)
    sign1 = 1.0 - 2.0 * (branch >> 2)  # +1: θ1 = base + half, −1: base − half
    sign5 = 1.0 - 2.0 * ((branch >> 1) & 1)
    sign3 = 1.0 - 2.0 * (branch & 1)
    values, along_u, x, y, radius, ratio = _shoulder_terms(k, positions, rotations)
    size = np.abs(ratio)
    no_shoulder = size > 1.0 + CLAMP + _FAST_EDGE
    edge = size > 1.0 - _FAST_EDGE
    np.copyto(ratio, np.nan, where=no_shoulder)
    np.clip(ratio, -1.0, 1.0, out=ratio)
    t1 = np.arctan2(y, x) + sign1 * np.arccos(ratio)
    cos_base, sin_base = x / radius, y / radius
    sin_half = sign1 * np.sqrt(np.maximum(1.0 - ratio * ratio, 0.0))
    c1 = cos_base * ratio - sin_base * sin_half
    s1 = sin_base * ratio + cos_base * sin_half
    # wrist: θ5 = δ ± half5
    b5 = c1 * values[3] + s1 * values[6]
    b6 = c1 * values[4] + s1 * values[7]
    b7 = c1 * values[5] + s1 * values[8]
    sine = np.sqrt(b5 * b5 + b7 * b7)
    edge |= sine < _FAST_WRIST
    t5 = k.delta5 + sign5 * np.arctan2(sine, b6)
    norm = np.maximum(np.sqrt(sine * sine + b6 * b6), TINY)
    cos_half5, sin_half5 = b6 / norm, sign5 * sine / norm
    cos_d, sin_d = math.cos(k.delta5), math.sin(k.delta5)
    c5 = cos_d * cos_half5 - sin_d * sin_half5
    s5 = sin_d * cos_half5 + cos_d * sin_half5
    a5, a6, a7 = k.a_wrist
    g5, g7 = c5 * a5, c5 * a7 - s5 * a6
    sin6, cos6 = b7 * g5 - b5 * g7, b5 * g5 + b7 * g7
    t6 = np.arctan2(sin6, cos6)
    norm = np.maximum(np.sqrt(sin6 * sin6 + cos6 * cos6), TINY)
    c6, s6 = cos6 / norm, sin6 / norm
    # the plane of joints 2–4 and the planar target
    target_x, target_y, phi = _planar_targets(
        k, values, (c1, s1, x, y, along_u), (c5, s5, c6, s6), lambda a: a
    )
    # the elbow: ψ3 = offset ± bend, ψ2 = atan2(v × target, v · target), v = r23 + Rot(ψ3) r34
    l23, l34 = k.l23, k.l34
    cosine = (target_x * target_x + target_y * target_y - (l23 * l23 + l34 * l34)) / (
        2.0 * l23 * l34
    )
    size = np.abs(cosine)
    no_elbow = size > 1.0 + CLAMP + _FAST_EDGE
    edge |= size > 1.0 - _FAST_EDGE
    np.copyto(cosine, np.nan, where=no_elbow)
    np.clip(cosine, -1.0, 1.0, out=cosine)
    psi3 = k.elbow_offset + sign3 * np.arccos(cosine)
    sin_bend = sign3 * np.sqrt(np.maximum(1.0 - cosine * cosine, 0.0))
    (r1x, r1y), (r2x, r2y) = k.r23, k.r34
    co, so = math.cos(k.elbow_offset), math.sin(k.elbow_offset)
    ax, ay = co * r2x - so * r2y, so * r2x + co * r2y  # Rot(offset) r34
    vx, vy = r1x + ax * cosine - ay * sin_bend, r1y + ay * cosine + ax * sin_bend
    psi2 = np.arctan2(vx * target_y - vy * target_x, vx * target_x + vy * target_y)
    sign2, sign3_axis, sign4 = k.signs
    q = np.empty((n, 6))
    q[:, 0], q[:, 1], q[:, 2] = t1, sign2 * psi2, sign3_axis * psi3
    q[:, 3], q[:, 4], q[:, 5] = sign4 * (phi - psi2 - psi3), t5, t6
    return q, edge & ~no_shoulder


class URIK(ClosedFormIK):
    """Closed-form IK of a UR-type arm: up to 8 solutions (shoulder × wrist × elbow).

    Branch index ``4·shoulder + 2·wrist + elbow``. At the wrist singularity (axis 6 parallel to
    axes 2–4) θ6 is free: it keeps the reference value, or the nearest value the elbow can
    follow when the reference's is out of its reach. At the shoulder singularity (wrist centre
    at distance |d4| from axis 1) the two shoulder branches coincide, and with a straight elbow
    the two elbow branches.

    :meth:`nearest` and :meth:`solutions` solve a single pose in plain floats
    (:meth:`_fast_raw`, :meth:`_nearest_fast`), with the answer of the vectorised path
    (:meth:`_nearest_batch_path`) to 1e-9 rad; near singularities, for a geometry whose axes
    are not orthonormal to ``_FAST_DEFECT`` and for negative weights they use the vectorised
    path itself. Limits and weights are read once, at construction.

    Args:
        geometry: The arm at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    def __init__(
        self,
        geometry: URGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        super().__init__(lower, upper, weights)
        self.geometry = geometry
        self._fast = _ur_fast_constants(geometry)
        self._limits = (tuple(self.lower.tolist()), tuple(self.upper.tolist()))
        self._weight_floats = tuple(self.weights.tolist())
        if min(self._weight_floats) < 0.0:  # the fast path's pruning needs a growing distance
            self._fast = None

    # ------------------------------------------------------------ single pose, plain floats
    def solutions(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        if self._fast is not None:
            try:
                raw = self._fast_all_branches(position, rotation)
            except NeedsBatch:
                pass
            else:
                return self._distinct(raw)
        return super().solutions(position, rotation)

    solutions.__doc__ = ClosedFormIK.solutions.__doc__

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        if self._fast is not None:
            try:
                return self._nearest_fast(position, rotation, q_ref)
            except NeedsBatch:
                pass
        return self._nearest_batch_path(position, rotation, q_ref)

    nearest.__doc__ = ClosedFormIK.nearest.__doc__

    def nearest_many(
        self, positions: np.ndarray, rotations: np.ndarray, q_ref: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference, in one vectorised pass
        (the single-pose formulas on arrays; inputs unchecked).

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 6).

        Returns:
            (q (N, 6) [rad], branch (N,) int (−1: no solution within the limits), mask (N,)
            uint16 of the branches with a solution within the limits (bit ``branch``), left
            (N,) bool). ``left`` marks the poses :meth:`nearest` leaves to the vectorised
            all-branch path (near a singularity, or every pose when the geometry has no
            single-pose path); their other outputs are meaningless.
        """
        count = len(positions)
        if self._fast is None:
            left = np.ones(count, dtype=bool)
            return np.zeros((count, 6)), np.full(count, -1), np.zeros(count, np.uint16), left
        joints = tuple(zip(*self._limits, self._weight_floats))
        refs = np.ascontiguousarray(np.asarray(q_ref, dtype=float).T)
        with np.errstate(invalid="ignore", divide="ignore"):  # NaN lanes: no solution
            return _fast_nearest_many(self._fast, joints, positions, rotations, refs)

    @property
    def branch_many_available(self) -> bool:
        """Whether :meth:`branch_many` and :meth:`pose_branches` answer (the geometry has the
        single-pose path: orthonormal axes, weights ≥ 0)."""
        return self._fast is not None

    def pose_branches(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray | None:
        """Every branch of one pose in plain floats (inputs unchecked): (8, 6) [rad], any 2π
        representative, NaN rows for branches without a solution (row ``branch``, as
        :meth:`branch_many`); None near a singularity, where the single-pose formulas leave the
        pose to the batch path, and without a rotation."""
        try:
            return self._fast_all_branches(position, rotation)
        except NeedsBatch:
            return None

    def branch_many(
        self, positions: np.ndarray, rotations: np.ndarray | None, branch: np.ndarray | int
    ) -> tuple[np.ndarray, np.ndarray]:
        """One branch of many poses in one vectorised pass (inputs unchecked): for followers
        that keep a branch along a path (:mod:`cartesian.batch_track`).

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            branch: Branch index ``4·shoulder + 2·wrist + elbow``, one or one per pose (N,).

        Returns:
            (q (N, 6) [rad], any 2π representative, NaN rows where the branch has no solution;
            edge (N,) bool: poses near a singularity of the branch, where q is ill-conditioned
            — every pose when the geometry has no single-pose path, see
            :attr:`branch_many_available`, or without rotations).
        """
        if self._fast is None or rotations is None:
            count = len(positions)
            return np.full((count, 6), np.nan), np.ones(count, dtype=bool)
        with np.errstate(invalid="ignore", divide="ignore"):  # NaN lanes: no solution
            return _fast_branch_many(self._fast, positions, rotations, branch)

    def _nearest_batch_path(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """:meth:`nearest` computed by the vectorised machinery (:meth:`_raw` for N = 1).

        The reference of the single-pose path, and its fallback near singularities.
        """
        return ClosedFormIK.nearest(self, position, rotation, q_ref)

    def _fast_pose(
        self, position: np.ndarray, rotation: np.ndarray | None
    ) -> tuple[list[float], list[float]]:
        """The target as floats: (P [m], ``matrix @ R.ravel()``, see :class:`_URFast`).

        Raises:
            NeedsBatch: for a malformed or non-finite target (the batch path reports it).
        """
        if rotation is None:
            raise NeedsBatch
        position = np.asarray(position, dtype=float)
        rotation = np.asarray(rotation, dtype=float)
        if position.shape != (3,) or rotation.shape != (3, 3):
            raise NeedsBatch
        if self._fast is None:
            raise NeedsBatch
        position_list = position.tolist()
        values = self._fast.matrix.dot(rotation.reshape(9)).tolist()
        # a NaN or inf anywhere in R reaches some value (the matrix has no zero column)
        if not math.isfinite(sum(position_list) + sum(values)):
            raise NeedsBatch
        return position_list, values

    def _fast_raw(self, position: list[float], values: list[float]) -> list[tuple]:
        """θ1, θ5, θ6 of every branch of one pose, and what its planar step needs.

        The formulas of :meth:`_raw` in plain floats, expanded in the frames of :class:`_URFast`.
        The planar step (:func:`_fast_planar_target`, :func:`_fast_elbow`) is left to the
        caller, which may skip branches it does not need.

        Args:
            position: Tool position in the world frame [m].
            values: ``self._fast.matrix @ R.ravel()`` of the tool rotation R (world frame).

        Returns:
            Per shoulder branch (sign +1, then −1): (θ1, per wrist branch (+1, then −1):
            (θ5, θ6, plane)) with ``plane`` from :func:`_fast_plane_axes`. Angles [rad], any 2π
            representative. Empty when no θ1 exists.

        Raises:
            NeedsBatch: near the shoulder or wrist singularity (see ``_FAST_EDGE``,
                ``_FAST_WRIST``), where the batch path decides.
        """
        k = self._fast
        if k is None:
            raise NeedsBatch
        shoulder = _fast_shoulder(k, position, values)
        if shoulder is None:
            return []
        branches = []
        for t1 in shoulder[0]:
            c1, s1 = math.cos(t1), math.sin(t1)
            t5s, t6s = _fast_wrist(k, c1, s1, values)
            plane = _fast_plane_axes(k, c1, s1, shoulder[1], values)
            branches.append((t1, ((t5s[0], t6s[0], plane), (t5s[1], t6s[1], plane))))
        return branches

    def _fast_all_branches(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        """:meth:`_raw` of one pose (N = 1, no free joint) in plain floats: (8, 6) [rad], NaN rows
        for branches without a solution. Raises NeedsBatch as :meth:`_fast_raw`."""
        k = self._fast
        if k is None:
            raise NeedsBatch
        raw = np.full((8, 6), np.nan)
        for shoulder, (t1, wrists) in enumerate(
            self._fast_raw(*self._fast_pose(position, rotation))
        ):
            for wrist, (t5, t6, plane) in enumerate(wrists):
                elbow = _fast_elbow(k, *_fast_planar_target(k, plane, t5, t6))
                for branch, (t2, t3, t4) in enumerate(elbow or ()):
                    raw[4 * shoulder + 2 * wrist + branch] = (t1, t2, t3, t4, t5, t6)
        return raw

    def _nearest_fast(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """:meth:`nearest` in plain floats: the choice :meth:`_pick` makes on :meth:`_raw`.

        Branch and bound: the branches' (θ1, θ5, θ6) parts of the distance are computed first,
        and the planar step only for the (shoulder, wrist) pairs, in increasing order of that
        part, that can still beat the best branch found (the weights are ≥ 0). Equal distances
        go to the lower branch index, as in :meth:`_pick`.

        Raises:
            NeedsBatch: for the poses and inputs :meth:`_fast_raw` and :meth:`_fast_pose` leave
                to the batch path, and for a malformed or non-finite ``q_ref``.
        """
        ref = np.asarray(q_ref, dtype=float)
        if ref.shape != (6,):
            raise NeedsBatch
        ref = ref.tolist()
        if not math.isfinite(sum(ref)):
            raise NeedsBatch
        branches = self._fast_raw(*self._fast_pose(position, rotation))
        # per joint: (reference, reference clipped into the limits, lower, upper, weight)
        j1, j2, j3, j4, j5, j6 = (
            (r, min(max(r, lo), hi), lo, hi, w)
            for r, lo, hi, w in zip(ref, *self._limits, self._weight_floats)
        )
        heads = []  # (distance of θ1, θ5, θ6; pair index 2·shoulder + wrist; their values; ...)
        for shoulder, (t1, wrists) in enumerate(branches):
            choice1 = joint_choice(t1, j1)
            if choice1 is None:
                continue
            for wrist, (t5, t6, plane) in enumerate(wrists):
                choice5, choice6 = joint_choice(t5, j5), joint_choice(t6, j6)
                if choice5 is not None and choice6 is not None:
                    head = choice1[1] + choice5[1] + choice6[1]
                    pair = 2 * shoulder + wrist
                    heads.append((head, pair, choice1[0], choice5[0], choice6[0], t5, t6, plane))
        heads.sort()  # by distance, then pair index (never compares further)
        k = self._fast
        if k is None:
            raise NeedsBatch
        best, best_cost, best_index = None, math.inf, 8
        for head, pair, q1, q5, q6, t5, t6, plane in heads:
            if head > best_cost:
                break
            elbow = _fast_elbow(k, *_fast_planar_target(k, plane, t5, t6))
            for branch, (t2, t3, t4) in enumerate(elbow or ()):
                choice2 = joint_choice(t2, j2)
                if choice2 is None or head + choice2[1] > best_cost:
                    continue
                choice3, choice4 = joint_choice(t3, j3), joint_choice(t4, j4)
                if choice3 is None or choice4 is None:
                    continue
                cost = head + choice2[1] + choice3[1] + choice4[1]
                index = 2 * pair + branch
                if cost < best_cost or (cost == best_cost and index < best_index):
                    best, best_cost, best_index = (
                        (q1, choice2[0], choice3[0], choice4[0], q5, q6),
                        cost,
                        index,
                    )
        return None if best is None else np.array(best)

    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        assert rotations is not None  # needs_rotation: _check_poses refused None
        g = self.geometry
        count = len(positions)
        t1, shoulder_ok = self._shoulder(positions, rotations)  # (N, 2)
        n = np.cos(t1)[..., None] * g.a + np.sin(t1)[..., None] * g.b1  # axis 2 at θ1, (N, 2, 3)
        t1 = t1[:, :, None]
        t5, t6, free6 = self._wrist(rotations, n, fill[:, 5])  # (N, 2, 2)
        if free6.any():
            feasible = self._feasible_theta6(positions, rotations, t1, t5, fill[:, 5])
            t6 = np.where(free6, feasible, t6)
        target, phi = self._planar_target(positions, rotations, t1, t5, t6)
        t2, t3, t4, elbow_ok, free2 = self._joints_234(target, phi, fill[:, 1])
        shape = (count, 2, 2, 2)
        q = np.stack(
            [
                np.broadcast_to(t1[..., None], shape),
                t2,
                t3,
                t4,
                np.broadcast_to(t5[..., None], shape),
                np.broadcast_to(t6[..., None], shape),
            ],
            axis=-1,
        )
        ok = shoulder_ok[:, :, None, None] & elbow_ok
        raw = np.where(ok[..., None], q, np.nan).reshape(count, 8, 6)
        singular = np.any(free6.reshape(count, -1), axis=1) | np.any(
            free2.reshape(count, -1), axis=1
        )
        return raw, singular

    def _shoulder(
        self, positions: np.ndarray, rotations: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """θ1 (N, 2) from ``n(θ1)·(c − p1) = shoulder_offset``, and whether it is reachable."""
        g = self.geometry
        centre = positions + rotations @ g.centre_in_tool
        x, y = (centre - g.p1) @ g.a, (centre - g.p1) @ g.b1
        radius = np.hypot(x, y)
        ratio = g.shoulder_offset / np.maximum(radius, np.finfo(float).tiny)
        reachable = np.abs(ratio) <= 1.0 + CLAMP
        half = np.arccos(np.clip(ratio, -1.0, 1.0))
        t1 = wrap_angle(np.arctan2(y, x)[:, None] + SIGNS * half[:, None])
        return t1, np.broadcast_to(reachable[:, None], t1.shape)

    def _wrist(
        self, rotations: np.ndarray, n: np.ndarray, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """θ5, θ6 (N, 2, 2) (shoulder, wrist) from the tool axes; free (N, 2, 2) where θ6 = fill.

        With R = R1 R234 R5 R6 R_M (rotations about the q = 0 axes) and R234 about ``a``:
        ``n·z6 = a·R5 u6 = cos(θ5 − δ)``, and ``R6ᵀ R5ᵀ a = R_M Rᵀ n`` fixes θ6. The angles come
        from atan2 of components perpendicular to u6 (not arccos), so they stay accurate near
        the wrist singularity sin(θ5 − δ) = 0.
        """
        g = self.geometry
        b = np.einsum("nji,nsj->nsi", rotations, n) @ g.tool_rotation.T  # R_M Rᵀ n, (N, 2, 3)
        cosine = b @ g.u6  # n·z6
        b_perp = b - cosine[..., None] * g.u6
        sine = np.linalg.norm(b_perp, axis=-1)  # |sin(θ5 − δ)|
        t5 = g.delta5 + SIGNS * np.arctan2(sine, cosine)[..., None]
        r5t_a = np.cos(t5)[..., None] * g.a - np.sin(t5)[..., None] * g.u5_cross_a  # R5ᵀ a
        g_perp = r5t_a - (r5t_a @ g.u6)[..., None] * g.u6
        b_perp = b_perp[:, :, None, :]
        sin6 = np.sum((b_perp @ g.cross6) * g_perp, axis=-1)  # u6·(b⊥ × g⊥)
        cos6 = np.sum(b_perp * g_perp, axis=-1)
        free = np.broadcast_to((sine < FREE_TOL)[..., None], t5.shape)
        t6 = np.where(free, fill[:, None, None], np.arctan2(sin6, cos6))
        return wrap_angle(t5), t6, free

    def _planar_target(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        t1: np.ndarray,
        t5: np.ndarray,
        t6: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The planar motion X = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹ that joints 2–4 must make (X = e2 e3 e4).

        Args:
            positions, rotations: Targets (N, 3), (N, 3, 3).
            t1: θ1, shape (N, 2, 1); t5, t6: θ5, θ6, shape (N, 2, 2) [rad].

        Returns:
            (target, φ): where X moves the point of axis 4, relative to axis 2 in the plane's
            (e, f) coordinates [m], shape (N, 2, 2, 2); X's rotation about ``a`` [rad] (N, 2, 2).
        """
        g = self.geometry
        point = rotate_about_line(g.p4, g.p5, g.u5, -t5, g.cross5)
        point = rotate_about_line(point, g.p6, g.u6, -t6, g.cross6)
        point = rotate_by(rotations, (point - g.tool_position) @ g.tool_rotation)
        point = rotate_about_line(point + positions[:, None, None], g.p1, g.u1, -t1, g.cross1)
        turned = rotate_about(rotate_about(g.e, g.u5, -t5, g.cross5), g.u6, -t6, g.cross6)
        turned = rotate_by(rotations, turned @ g.tool_rotation)
        turned = rotate_about(turned, g.u1, -t1, g.cross1)
        relative = point - g.p2
        target = np.stack((relative @ g.e, relative @ g.f), axis=-1)
        return target, np.arctan2(turned @ g.f, turned @ g.e)

    def _feasible_theta6(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        t1: np.ndarray,
        t5: np.ndarray,
        fill: np.ndarray,
    ) -> np.ndarray:
        """θ6 [rad] (N, 2, 2) for the wrist singularity, where θ6 is free.

        Joints 2, 3, 4 and 6 are then all parallel: θ6 can take any value the elbow can
        follow. The 2R target moves on a circle with θ6, |target|² = k + A·cos(θ6 − β); the
        elbow reaches it for |l2 − l3| ≤ |target| ≤ l2 + l3, an arc of θ6. Returns ``fill`` when
        it lies on that arc, else the nearest end of the arc (where the elbow is straight or
        folded; if the arc is empty, the 2R step then finds the pose unreachable).
        """
        g = self.geometry
        at = [
            self._planar_target(positions, rotations, t1, t5, np.full(t5.shape, angle))[0]
            for angle in (0.0, 0.5 * np.pi, np.pi)
        ]
        centre = 0.5 * (at[0] + at[2])
        u, v = 0.5 * (at[0] - at[2]), at[1] - centre
        k = np.sum(centre**2, axis=-1) + np.sum(u**2, axis=-1)
        b_cos, b_sin = 2.0 * np.sum(centre * u, axis=-1), 2.0 * np.sum(centre * v, axis=-1)
        amplitude, beta = np.hypot(b_cos, b_sin), np.arctan2(b_sin, b_cos)
        l2, l3 = np.hypot(*g.r23), np.hypot(*g.r34)
        safe = np.maximum(amplitude, np.finfo(float).tiny)
        # within reach for min_offset ≤ |θ6 − β| ≤ max_offset (not too far, not too close)
        min_offset = np.arccos(np.clip(((l2 + l3) ** 2 - k) / safe, -1.0, 1.0))
        max_offset = np.arccos(np.clip(((l2 - l3) ** 2 - k) / safe, -1.0, 1.0))
        offset = wrap_angle(fill[:, None, None] - beta)
        magnitude = np.clip(np.abs(offset), min_offset, max_offset)
        clamped = beta + np.where(offset >= 0.0, magnitude, -magnitude)
        keep = (magnitude == np.abs(offset)) | (amplitude == 0.0)
        return np.where(keep, fill[:, None, None], clamped)

    def _joints_234(
        self, target: np.ndarray, phi: np.ndarray, fill: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """θ2, θ3, θ4 (N, 2, 2, 2) from the planar motion: a 2R problem for joints 2 and 3, then
        θ4 from ψ2 + ψ3 + ψ4 = φ (ψk = ±θk, the axis signs).

        Returns:
            (θ2, θ3, θ4, reachable, free) with ``free`` where θ2 = fill (axis 4 on axis 2).
        """
        g = self.geometry
        fill_psi2 = np.broadcast_to((g.signs[0] * fill)[:, None, None], phi.shape)
        psi2, psi3, reachable, free = planar_2r(g.r23, g.r34, target, fill_psi2)
        psi4 = wrap_angle(phi[..., None] - psi2 - psi3)
        return g.signs[0] * psi2, g.signs[1] * psi3, g.signs[2] * psi4, reachable, free
