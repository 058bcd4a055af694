"""Spherical-wrist 6R arms whose axes 2 and 3 are not parallel, read from their screw axes at
q = 0: :class:`GeneralWristGeometry` and :func:`general_wrist_geometry` (the structure, or the
reason it does not fit).

IK-Geo's spherical families beyond axes 2 ∥ 3 (Elias & Wen 2022, "IK-Geo: unified robot
inverse kinematics using subproblem decomposition"): six revolute joints, axes 4, 5 and 6
meeting in one point (the wrist centre ``c``), axes 2 and 3 not parallel. Joints 4–6 leave
``c`` in place, so the first three joints place it, ``e1 e2 e3 c = c_T``, in one of three
ways:

* **axes 1 and 2 meet** at ``o`` (:data:`MEETING_12`, IK-Geo's "spherical_two_intersecting"):
  e1, e2 fix o, so ``|e3 c − o| = |c_T − o|`` gives θ3 by subproblem 3 (two), then θ1, θ2 by
  subproblem 2 (two);
* **axes 2 and 3 meet** at ``o`` (:data:`MEETING_23`): ``|e1⁻¹ c_T − o| = |c − o|`` gives θ1 by
  subproblem 3, then θ2, θ3 by subproblem 2;
* **general** (:data:`GENERAL`, no such pair): θ1, θ2, θ3 by subproblem 5 (a quartic), up to
  four position solutions.

Offsets anywhere else are allowed and the axes need not be perpendicular; nothing is read from
joint or link names. Arms with axes 2 ∥ 3 belong to
:mod:`~kinplan.ik.spherical_wrist_geometry`.

First of the modules of this family, which import only those before them:
``spherical_general_geometry`` → :mod:`~kinplan.ik.spherical_general_quartic` (subproblem 5's
real roots) → :mod:`~kinplan.ik.spherical_general_positions` (θ1–θ3) →
:mod:`~kinplan.ik.spherical_general_kernel` (one pose: the wrist, the FK check, the nearest
solution) → :mod:`~kinplan.ik.spherical_general` (the solver); the three in the middle are
compiled (numba).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinplan.ik.screws import STRUCTURE_TOL, Screws, line_meet, plane_basis, sine_between

#: Smallest sine of the angle between axes that must not be parallel (below: refused).
SKEW_TOL = 1e-6

#: Smallest sine of the angle between the meeting axes of the meeting modes: subproblem 2's
#: cones about nearly parallel axes meet at a grazing angle (measured on synthetic arms, 4,000
#: random poses each: at 1e-3 one generating configuration in 12,000 found to 1e-5 rad only,
#: not 1e-7; at 1e-4 up to 16 in 4,000; at 1e-5 some not at all; below: refused).
MEETING_SKEW = 1e-3

#: Smallest sine between axes 1 and 2 for subproblem 5 (measured: no loss down to 1e-5).
GENERAL_SKEW = 1e-5

#: Subproblem 5 needs axes 1, 2 or axes 2, 3 apart by this much, relative to the arm's size
#: (:func:`arm_size`): where both pairs nearly meet, the quartic's four roots crowd together
#: (measured on synthetic arms: none lost with both pairs 3e-3 of the size apart, 0.4 % at
#: 1e-3; one pair nearly meeting, even 3e-9 m apart, loses none).
GENERAL_GAP = 1e-2

#: Position modes: how θ1, θ2, θ3 place the wrist centre.
MEETING_12 = 0
MEETING_23 = 1
GENERAL = 2

#: Rows of :meth:`GeneralWristGeometry.constants`.
CONSTANT_ROWS = 24

#: The reason :func:`~kinplan.ik.spherical_wrist_geometry.wrist_geometry` gives for the arms
#: of this family (the closed forms try this family after it).
NOT_PARALLEL = "spherical wrist, but axes 2 and 3 are not parallel (not solved in closed form)"


@dataclass(frozen=True)
class GeneralWristGeometry:
    """A spherical-wrist 6R arm with axes 2 ∦ 3 at q = 0, in the world frame (vectors (3,),
    lengths [m]).

    Attributes:
        axes: Unit joint axes, shape (6, 3).
        points: A point on each axis, shape (6, 3) [m].
        centre: The wrist centre ``c``, where axes 4, 5, 6 meet [m].
        tool_rotation: Tool rotation ``R_M`` at q = 0.
        tool_position: Tool position ``p_M`` at q = 0 [m].
        mode: :data:`MEETING_12`, :data:`MEETING_23` or :data:`GENERAL`.
        origin: Where the meeting axes meet [m]; for :data:`GENERAL` the point of axis 2
            nearest axis 1 (the origin of subproblem 5's vectors).
        x6: A unit vector across axis 6 (θ6 by subproblem 1 turns it).
    """

    axes: np.ndarray
    points: np.ndarray
    centre: np.ndarray
    tool_rotation: np.ndarray
    tool_position: np.ndarray
    mode: int
    origin: np.ndarray
    x6: np.ndarray

    def tool(self) -> np.ndarray:
        """The tool pose at q = 0 as a 4×4 homogeneous matrix."""
        out = np.eye(4)
        out[:3, :3], out[:3, 3] = self.tool_rotation, self.tool_position
        return out

    def constants(self) -> np.ndarray:
        """The geometry packed for :mod:`~kinplan.ik.spherical_general_kernel`, shape (24, 3).

        Rows: 0–5 axes h1…h6; 6–11 points p1…p6; 12 ``c``; 13 ``c`` in the tool frame at
        q = 0, ``R_Mᵀ(c − p_M)``; 14 ``R_Mᵀ h6``; 15 ``R_Mᵀ x6``; 16 ``x6``; 17 (mode, h5·h4,
        |h5 × h4|²); 18 ``h5 × h4``; 19 ``o`` (:attr:`origin`); 20–22 circle 3 of subproblem 5
        (:data:`GENERAL` only, else 0): its centre ``C3 = p3 − o + h3 h3ᵀ(c − p3)``, ``w3 =
        (c − p3)`` across h3 and ``h3 × w3`` (so that ``e3 c − o = C3 + cos θ3 w3 + sin θ3
        h3 × w3``); 23 (L, lo, hi): the arm's size L [m] (scale of the tolerances) and the
        range [lo, hi] of ``h4·R5 h6`` over θ5 (the wrist's reach).
        """
        h, p, c = self.axes, self.points, self.centre
        rt = self.tool_rotation.T
        k = np.zeros((CONSTANT_ROWS, 3))
        k[0:6], k[6:12], k[12] = h, p, c
        k[13] = rt @ (c - self.tool_position)
        k[14], k[15], k[16] = rt @ h[5], rt @ self.x6, self.x6
        normal = np.cross(h[4], h[3])
        k[17] = (float(self.mode), float(h[4] @ h[3]), float(normal @ normal))
        k[18], k[19] = normal, self.origin
        if self.mode == GENERAL:
            off = c - p[2]
            along = (off @ h[2]) * h[2]
            k[20] = p[2] - self.origin + along
            k[21] = off - along
            k[22] = np.cross(h[2], k[21])
        c45, c56 = float(h[3] @ h[4]), float(h[5] @ h[4])
        reach = np.linalg.norm(h[3] - c45 * h[4]) * np.linalg.norm(h[5] - c56 * h[4])
        k[23] = (arm_size(self.points, c, self.tool_position), c45 * c56 - reach,
                 c45 * c56 + reach)  # fmt: skip
        return k


def arm_size(points: np.ndarray, centre: np.ndarray, tool_position: np.ndarray) -> float:
    """A length of the arm [m]: the longest distance between the first three axes' points, the
    wrist centre and the tool at q = 0 (at least 1e-3 m), the scale of relative tolerances."""
    cloud = np.vstack([points[:3], centre, tool_position])
    spread = np.linalg.norm(cloud[:, None, :] - cloud[None, :, :], axis=-1).max()
    return float(max(spread, 1e-3))


def _off_axis(point: np.ndarray, axis_point: np.ndarray, axis: np.ndarray) -> float:
    """Distance [m] from ``point`` to the line through ``axis_point`` along unit ``axis``."""
    off = point - axis_point
    return float(np.linalg.norm(off - (off @ axis) * axis))


def _nearest_on(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The point of the line (q, v) nearest the non-parallel line (p, u) (unit directions)."""
    w = p - q
    b = float(u @ v)
    d, e = float(u @ w), float(v @ w)
    return q + (e - b * d) / (1.0 - b * b) * v


def _spherical_wrist(u: np.ndarray, p: np.ndarray) -> tuple[np.ndarray | None, str]:
    """The wrist centre where axes 4, 5, 6 meet, or (None, why not)."""
    if sine_between(u[3], u[4]) < SKEW_TOL or sine_between(u[4], u[5]) < SKEW_TOL:
        return None, "no spherical wrist: axes 4, 5 or 5, 6 are parallel"
    centre, gap = line_meet(p[3], u[3], p[4], u[4])
    if gap > STRUCTURE_TOL:
        return None, f"no spherical wrist: axes 4 and 5 do not intersect ({gap:.1e} m apart)"
    miss = _off_axis(centre, p[5], u[5])
    if miss > STRUCTURE_TOL:
        return None, (
            f"no spherical wrist: axis 6 misses the meeting of axes 4 and 5 by {miss:.1e} m"
        )
    return centre, ""


def general_wrist_geometry(screws: Screws) -> tuple[GeneralWristGeometry | None, str]:
    """The structure of six revolute screws at q = 0 for this family.

    Args:
        screws: The arm's joint screws and tool pose at q = 0 (world frame).

    Returns:
        (geometry, "") when the arm fits, else (None, the reason it does not), e.g.
        ``"axes 2 ∥ 3: the spherical wrist with axes 2 ∥ 3 serves this arm"``.
    """
    u, p = screws.directions, screws.points
    if len(u) != 6:
        return None, f"{len(u)} joints, not 6"
    centre, why = _spherical_wrist(u, p)
    if centre is None:
        return None, why
    sine23 = sine_between(u[1], u[2])
    if sine23 <= STRUCTURE_TOL:
        return None, "axes 2 ∥ 3: the spherical wrist with axes 2 ∥ 3 serves this arm"
    if sine23 < SKEW_TOL:
        return None, f"axes 2 and 3 are {sine23:.1e} rad from parallel: neither parallel nor apart"
    if _off_axis(centre, p[2], u[2]) < STRUCTURE_TOL:
        return None, "the wrist centre lies on axis 3"
    tool_rotation = screws.tool.rotation.copy()
    tool_position = screws.tool.translation.copy()

    def geometry(mode: int, origin: np.ndarray) -> GeneralWristGeometry:
        return GeneralWristGeometry(
            axes=u.copy(),
            points=p.copy(),
            centre=centre,
            tool_rotation=tool_rotation,
            tool_position=tool_position,
            mode=mode,
            origin=origin,
            x6=plane_basis(u[5])[0],
        )

    size = arm_size(p, centre, tool_position)
    sine12 = sine_between(u[0], u[1])
    gap12 = gap23 = np.inf
    if sine12 >= SKEW_TOL:
        origin, gap12 = line_meet(p[0], u[0], p[1], u[1])
        if gap12 <= STRUCTURE_TOL:
            if sine12 < MEETING_SKEW:
                return None, f"axes 1 and 2 meet at {sine12:.1e} rad: nearly parallel"
            if _off_axis(origin, p[2], u[2]) < STRUCTURE_TOL:
                return None, "axes 1, 2 and 3 meet in one point"
            return geometry(MEETING_12, origin), ""
    origin, gap23 = line_meet(p[1], u[1], p[2], u[2])
    if gap23 <= STRUCTURE_TOL:
        if sine23 < MEETING_SKEW:
            return None, f"axes 2 and 3 meet at {sine23:.1e} rad: nearly parallel"
        if _off_axis(origin, p[0], u[0]) < STRUCTURE_TOL:
            return None, "axis 1 passes through the meeting of axes 2 and 3"
        if np.linalg.norm(centre - origin) < STRUCTURE_TOL:
            return None, "the wrist centre is where axes 2 and 3 meet"
        return geometry(MEETING_23, origin), ""
    if sine12 < GENERAL_SKEW:
        return None, (
            f"axes 2 and 3 apart, but axes 1 and 2 are parallel or nearly so ({sine12:.1e} "
            "rad; not solved in closed form)"
        )
    if max(gap12, gap23) < GENERAL_GAP * size:
        return None, (
            f"axes 1, 2 ({gap12:.1e} m) and axes 2, 3 ({gap23:.1e} m) both nearly meet: "
            "subproblem 5 is ill-conditioned there"
        )
    return geometry(GENERAL, _nearest_on(p[0], u[0], p[1], u[1])), ""
