"""Industrial 6R arms with a spherical wrist, read from their screw axes at q = 0:
:class:`WristGeometry` and :func:`wrist_geometry` (the structure, or the reason it does not fit).

The family (ABB IRB, KUKA KR, Fanuc, Yaskawa, Stäubli and any arm of the same structure, the
"OPW" arms and more): six revolute joints, axes 4, 5 and 6 meeting in one point (the wrist
centre ``c``), axes 2 and 3 parallel, axis 1 not parallel to axis 2. Offsets anywhere else
(shoulder offset between axes 1 and 2, elbow offset between axes 3 and 4, a lateral offset
along axis 2) are allowed, and the axes need not be perpendicular. Nothing is read from joint
or link names.

First of the spherical-wrist modules, which import only those before them:
``spherical_wrist_geometry`` → :mod:`~kinplan.ik.spherical_wrist_kernel` (one pose, compiled) →
:mod:`~kinplan.ik.spherical_wrist` (the solver, vectorised over poses).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinplan.ik.screws import STRUCTURE_TOL, Screws, line_meet, plane_basis, sine_between

#: Smallest sine of the angle between axes that must not be parallel (below: refused).
SKEW_TOL = 1e-6


@dataclass(frozen=True)
class WristGeometry:
    """A spherical-wrist arm at q = 0, in the world frame (vectors (3,), lengths [m]).

    Attributes:
        axes: Unit joint axes, shape (6, 3).
        points: A point on each axis, shape (6, 3) [m].
        centre: The wrist centre, where axes 4, 5, 6 meet [m].
        centre_in_tool: The wrist centre in the tool frame at q = 0 [m].
        tool_rotation: Tool rotation at q = 0.
        tool_position: Tool position at q = 0 [m].
        lateral: ``axes[1]·(centre − points[0])``: the wrist centre's coordinate along axis 2,
            which joints 2–6 keep (subproblem 4 for θ1) [m].
        e, f: Basis of the plane normal to axis 2, (e, f, axes[1]) right-handed.
        r23: Axis 2 → axis 3 in plane coordinates (e, f) [m], shape (2,).
        r3c: Axis 3 → wrist centre in plane coordinates [m], shape (2,).
        sign3: Direction of axis 3 relative to axis 2 (±1).
        x6: A unit vector across axis 6 (θ6 by subproblem 1 turns it).
    """

    axes: np.ndarray
    points: np.ndarray
    centre: np.ndarray
    centre_in_tool: np.ndarray
    tool_rotation: np.ndarray
    tool_position: np.ndarray
    lateral: float
    e: np.ndarray
    f: np.ndarray
    r23: np.ndarray
    r3c: np.ndarray
    sign3: float
    x6: np.ndarray

    def constants(self) -> np.ndarray:
        """The geometry packed for the compiled kernel: rows axes (0–5), points (6–11), centre
        (12), centre_in_tool (13), e (14), f (15), (lateral, sign3, 0) (16), (r23, 0) (17),
        (r3c, 0) (18), x6 (19), R_Mᵀ h6 (20), R_Mᵀ x6 (21); shape (22, 3)."""
        return np.vstack(
            [
                self.axes,
                self.points,
                self.centre,
                self.centre_in_tool,
                self.e,
                self.f,
                [self.lateral, self.sign3, 0.0],
                [*self.r23, 0.0],
                [*self.r3c, 0.0],
                self.x6,
                self.tool_rotation.T @ self.axes[5],
                self.tool_rotation.T @ self.x6,
            ]
        ).astype(float)


def wrist_geometry(screws: Screws) -> tuple[WristGeometry | None, str]:
    """The spherical-wrist structure of six revolute screws at q = 0.

    Args:
        screws: The arm's joint screws and tool pose at q = 0 (world frame).

    Returns:
        (geometry, "") when the arm fits, else (None, the reason it does not), e.g.
        ``"axes 4 and 5 do not intersect (2.0e-02 m apart)"``.
    """
    u, p = screws.directions, screws.points
    if len(u) != 6:
        return None, f"{len(u)} joints, not 6"
    if sine_between(u[3], u[4]) < SKEW_TOL or sine_between(u[4], u[5]) < SKEW_TOL:
        return None, "no spherical wrist: axes 4, 5 or 5, 6 are parallel"
    centre, gap = line_meet(p[3], u[3], p[4], u[4])
    if gap > STRUCTURE_TOL:
        return None, f"no spherical wrist: axes 4 and 5 do not intersect ({gap:.1e} m apart)"
    off = centre - p[5]
    miss = float(np.linalg.norm(off - (off @ u[5]) * u[5]))
    if miss > STRUCTURE_TOL:
        return (
            None,
            f"no spherical wrist: axis 6 misses the meeting of axes 4 and 5 by {miss:.1e} m",
        )
    if sine_between(u[1], u[2]) > STRUCTURE_TOL:
        return (
            None,
            "spherical wrist, but axes 2 and 3 are not parallel (not solved in closed form)",
        )
    if sine_between(u[0], u[1]) < SKEW_TOL:
        return None, "spherical wrist, but axes 1 and 2 are parallel"
    a = u[1]
    e, f = plane_basis(a)

    def in_plane(v: np.ndarray) -> np.ndarray:
        return np.array([v @ e, v @ f])

    r23, r3c = in_plane(p[2] - p[1]), in_plane(centre - p[2])
    if min(np.hypot(*r23), np.hypot(*r3c)) < STRUCTURE_TOL:
        return None, "spherical wrist, but the wrist centre or axis 3 lies on the axis before it"
    tool_rotation = screws.tool.rotation.copy()
    tool_position = screws.tool.translation.copy()
    geometry = WristGeometry(
        axes=u.copy(),
        points=p.copy(),
        centre=centre,
        centre_in_tool=tool_rotation.T @ (centre - tool_position),
        tool_rotation=tool_rotation,
        tool_position=tool_position,
        lateral=float(a @ (centre - p[0])),
        e=e,
        f=f,
        r23=r23,
        r3c=r3c,
        sign3=float(np.sign(u[2] @ a)),
        x6=plane_basis(u[5])[0],
    )
    return geometry, ""
