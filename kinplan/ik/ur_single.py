"""The UR closed form of one pose in plain floats (numpy's per-call overhead would dominate
arrays of one pose): :class:`URFast`, the arm's constants read once from a
:class:`~kinplan.ik.ur_geometry.URGeometry`, and the steps of ``URIK.nearest`` and
``URIK.solutions`` (:class:`~kinplan.ik.ur.URIK`): θ1 (:func:`fast_shoulder`), θ5 and θ6
(:func:`fast_wrist`), the planar target (:func:`fast_plane_axes`, :func:`fast_planar_target`),
θ2–θ4 (:func:`fast_elbow`). Poses near a singularity raise :class:`~kinplan.ik.base.NeedsBatch`:
the vectorised path decides them.

Second of the UR modules, which import only those before them: :mod:`~kinplan.ik.ur_geometry` →
``ur_single`` → :mod:`~kinplan.ik.ur_many` → :mod:`~kinplan.ik.ur`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from kinplan.ik.base import NeedsBatch
from kinplan.ik.screws import CLAMP, TINY
from kinplan.ik.ur_geometry import URGeometry

#: The UR solver's logger, under the name it had before its modules were split.
logger = logging.getLogger("kinplan.ik.ur")

#: URIK's fast single-pose path leaves to the batch path every pose where a cosine ratio (of θ1
#: or of the elbow) is within this of ±1: there arccos is ill-conditioned (near a straight elbow
#: the two paths' roundings give answers ~1e-14 / √(1 − |cos|) rad apart), and the reachability
#: test sits at the rim.
FAST_EDGE = 1e-8

#: ... and every pose with |sin(θ5 − δ)| below this: near the wrist singularity θ4 and θ6 are
#: conditioned like 1e-14 / |sin(θ5 − δ)| (measured: 2e-11 rad apart at 1e-4, 9e-9 at 1e-6,
#: with the same FK error ~1e-15), and at the singularity θ6 is free.
FAST_WRIST = 1e-4

#: The fast path assumes exactly orthonormal shoulder (u1, a) and wrist (u5, u6) axes and a wrist
#: centre on axes 5 and 6; a geometry further from that than this [m, –] uses the batch path.
#: URDFs that write π/2 rounded (``rpy="1.570796327 0 0"``, airo-models' UR5e and UR3e) are
#: 2e-10 from orthonormal: their fast-path solutions then miss the pose by about that times
#: the reach (< 1e-9 m), far inside the IK tolerances (beyond them, Robot.ik polishes).
FAST_DEFECT = 1e-9
#: Below this defect the fast path is exact to rounding; above it (up to FAST_DEFECT)
#: :meth:`URIK.solutions <kinplan.ik.ur.URIK.solutions>`, which lists every branch to be
#: checked, takes the fast path only with each row Newton-polished on the URDF's screws (else
#: the vectorised path, exact for any axes); ``nearest`` takes the fast one as it is.
EXACT_DEFECT = 1e-12


@dataclass(frozen=True, slots=True)
class URFast:
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


def fast_defect(g: URGeometry) -> float:
    """How far ``g`` is from the orthonormal shoulder and wrist axes the fast path assumes
    (unit lengths, right angles, the wrist centre on axes 5 and 6) [m, –]."""
    centre = g.tool_position + g.tool_rotation @ g.centre_in_tool

    def off_axis(point: np.ndarray, axis: np.ndarray) -> float:
        offset = centre - point
        return float(np.linalg.norm(offset - (offset @ axis) * axis))

    return max(
        *(abs(float(np.linalg.norm(v)) - 1.0) for v in (g.u1, g.a, g.u5, g.u6, g.e, g.f)),
        *(
            abs(float(x @ y))
            for x, y in ((g.u1, g.a), (g.u5, g.u6), (g.e, g.a), (g.f, g.a), (g.e, g.f))
        ),
        off_axis(g.p5, g.u5),
        off_axis(g.p6, g.u6),
    )


def ur_fast_constants(g: URGeometry) -> URFast | None:
    """The single-pose constants of ``g``, or None when its axes are not orthonormal enough.

    The batch path rotates about the axes as given; the single-pose path expands the same
    rotations in the orthonormal frames of :class:`URFast`, exact only when u1 ⊥ a, u5 ⊥ u6 (all
    unit) and the wrist centre lies on axes 5 and 6. Any defect beyond ``FAST_DEFECT`` leaves
    every pose to the batch path.
    """
    u1, a, b1, u5, u6 = g.u1, g.a, g.b1, g.u5, g.u6
    centre = g.tool_position + g.tool_rotation @ g.centre_in_tool
    defect = fast_defect(g)
    if defect > FAST_DEFECT:
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

    return URFast(
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


def fast_shoulder(
    k: URFast, position: list[float], values: list[float]
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
        NeedsBatch: near the shoulder singularity (|d4| / radius within ``FAST_EDGE`` of 1).
    """
    ux, uy, uz, ax, ay, az, bx, by, bz = k.shoulder_axes
    px, py, pz = position
    along_u = values[9] + ux * px + uy * py + uz * pz - k.p1_along[0]
    x = values[10] + ax * px + ay * py + az * pz - k.p1_along[1]
    y = values[11] + bx * px + by * py + bz * pz - k.p1_along[2]
    ratio = k.shoulder_offset / max(math.hypot(x, y), TINY)
    if abs(ratio) > 1.0 - FAST_EDGE:
        if abs(ratio) > 1.0 + CLAMP + FAST_EDGE:
            return None
        raise NeedsBatch
    half, base = math.acos(ratio), math.atan2(y, x)
    return (base + half, base - half), (along_u, x, y)


def fast_wrist(
    k: URFast, c1: float, s1: float, values: list[float]
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
        NeedsBatch: near the wrist singularity (|sin(θ5 − δ)| < ``FAST_WRIST``).
    """
    b5 = c1 * values[3] + s1 * values[6]
    b6 = c1 * values[4] + s1 * values[7]
    b7 = c1 * values[5] + s1 * values[8]
    sine = math.hypot(b5, b7)
    if sine < FAST_WRIST:
        raise NeedsBatch
    half = math.atan2(sine, b6)
    a5, a6, a7 = k.a_wrist
    t5s, t6s = (k.delta5 + half, k.delta5 - half), []
    for t5 in t5s:
        c5, s5 = math.cos(t5), math.sin(t5)
        g5, g7 = c5 * a5, c5 * a7 - s5 * a6  # R5ᵀ a without its u6 component
        t6s.append(math.atan2(b7 * g5 - b5 * g7, b5 * g5 + b7 * g7))
    return t5s, (t6s[0], t6s[1])


def fast_plane_axes(
    k: URFast, c1: float, s1: float, centre: tuple[float, float, float], values: list[float]
) -> tuple[float, ...]:
    """What the planar step (:func:`fast_planar_target`) needs of θ1.

    Args:
        k: The arm's constants.
        c1, s1: cos θ1, sin θ1.
        centre: Shoulder coordinates of c − p1 [m] (from :func:`fast_shoulder`).
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


def fast_planar_target(
    k: URFast, plane: tuple[float, ...], t5: float, t6: float
) -> tuple[float, float, float]:
    """The planar motion joints 2–4 must make, as :meth:`URIK._planar_target`, for one branch.

    The motion is X = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹. Axes 5 and 6 pass through the wrist centre c, and
    T M⁻¹ takes c to its place at the target, so X(p4) − p2 = (p1 − p2) + Rot(u1, −θ1)(c_T − p1)
    + Rot(u1, −θ1) A Z with Z = Rot(u6, −θ6) Rot(u5, −θ5)(p4 − c). Its plane coordinates are
    the ``plane`` offsets plus Z·Aᵀ Rot(u1, θ1) e and Z·Aᵀ Rot(u1, θ1) f; X's rotation about
    ``a`` follows in the same way from the image of e.

    Args:
        k: The arm's constants.
        plane: :func:`fast_plane_axes` of the branch's θ1.
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


def fast_elbow(
    k: URFast, x: float, y: float, phi: float
) -> tuple[tuple[float, float, float], tuple[float, float, float]] | None:
    """θ2, θ3, θ4 [rad] of both elbow branches (signs +1, −1), as :meth:`URIK._joints_234`.

    Args:
        k: The arm's constants.
        x, y: Target of the axis-4 point relative to axis 2, plane (e, f) coordinates [m].
        phi: Rotation of the planar motion about ``a`` [rad].

    Returns:
        One (θ2, θ3, θ4) per elbow branch, or None when the elbow cannot reach.

    Raises:
        NeedsBatch: elbow (nearly) straight or folded, |cos ψ3| within ``FAST_EDGE`` of 1
        (this includes a target on axis 2, where θ2 would be free).
    """
    l23, l34 = k.l23, k.l34
    cosine = (x * x + y * y - l23**2 - l34**2) / (2.0 * l23 * l34)
    if abs(cosine) > 1.0 - FAST_EDGE:
        if abs(cosine) > 1.0 + CLAMP + FAST_EDGE:
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
