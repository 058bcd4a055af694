"""6R arms whose axes 4 and 5 meet but whose axis 6 misses that point, read from their screw
axes at q = 0: :class:`OffsetWristGeometry` and :func:`offset_wrist_geometry` (the structure,
or the reason it does not fit).

The family of IK-Geo's "1-D search" solvers (Elias & Wen 2022): six revolute joints, axes 4
and 5 meeting in one point ``c`` (not parallel), axis 6 anywhere (typically parallel to axis 4
at q = 0 and offset from ``c``, as rtb-data's IRB140 file, or a few tenths of a millimetre off
as Kinova's Gen3 6-DoF), and a first three joints that place ``c`` in closed form:

* **axes 2 ∥ 3** (:data:`PARALLEL`; axis 1 not parallel to axis 2): θ1 by subproblem 4, θ2, θ3
  by the planar elbow, as the spherical-wrist arms (shoulder, elbow and lateral offsets
  allowed);
* **axes 1 and 2 meet** (:data:`MEETING`; not parallel): θ3 by subproblem 3 (the distance from
  the meeting point ``o`` of axes 1 and 2 to ``c``), θ1, θ2 by subproblem 2. Kinova's Gen3
  6-DoF is of this kind: its axes 2 and 3 are 7.3e-6 rad from parallel (its URDF writes π as
  3.1416), too far for the first form's 1e-9 m.

Modules, each importing only those before it: ``wrist_offset_geometry`` →
:mod:`~kinplan.ik.wrist_offset_kernel` (one pose's search, compiled) →
:mod:`~kinplan.ik.wrist_offset` (the solver).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinplan.ik.screws import STRUCTURE_TOL, Screws, line_meet, plane_basis, sine_between

#: Smallest sine of the angle between axes that must not be parallel (below: refused).
SKEW_TOL = 1e-6

#: Position modes: how θ1, θ2, θ3 place the meeting point of axes 4 and 5.
PARALLEL = 0
MEETING = 1

#: Rows of :meth:`OffsetWristGeometry.constants`.
CONSTANT_ROWS = 36


@dataclass(frozen=True)
class OffsetWristGeometry:
    """A 6R arm with axes 4 and 5 meeting, at q = 0 in the world frame (vectors (3,), [m]).

    Attributes:
        axes: Unit joint axes, shape (6, 3).
        points: A point on each axis, shape (6, 3) [m].
        centre: ``c``, where axes 4 and 5 meet [m].
        miss: Distance from ``c`` to axis 6 [m] (0 for a spherical wrist).
        tool_rotation: Tool rotation ``R_M`` at q = 0.
        tool_position: Tool position ``p_M`` at q = 0 [m].
        mode: :data:`PARALLEL` (axes 2 ∥ 3) or :data:`MEETING` (axes 1 and 2 meet).
        origin: Where axes 1 and 2 meet [m] (:data:`MEETING`; else ``points[0]``).
    """

    axes: np.ndarray
    points: np.ndarray
    centre: np.ndarray
    miss: float
    tool_rotation: np.ndarray
    tool_position: np.ndarray
    mode: int
    origin: np.ndarray

    def tool(self) -> np.ndarray:
        """The tool pose at q = 0 as a 4×4 homogeneous matrix."""
        out = np.eye(4)
        out[:3, :3], out[:3, 3] = self.tool_rotation, self.tool_position
        return out

    def constants(self) -> np.ndarray:
        """The geometry packed for :mod:`~kinplan.ik.wrist_offset_kernel`, shape (36, 3).

        Rows: 0–5 axes h1…h6; 6–11 points p1…p6; 12 ``c``; 13–15 ``C0, C1, C2`` with
        ``R_Mᵀ(R(h6, −θ6)(c − p6) + p6 − p_M) = C0 + cos θ6 C1 + sin θ6 C2`` (the point c seen
        from the tool, for θ6); 16–18 ``D0, D1, D2``: ``R_Mᵀ R(h6, −θ6) h5`` likewise; 19–21
        ``F0, F1, F2``: ``R_Mᵀ R(h6, −θ6) x5`` likewise; 22 ``x5`` (a unit vector across
        axis 5); 23 (mode, h4·h5, 0); 24–33 the position stage (see :func:`_parallel_rows` and
        :func:`_meeting_rows`); 34, 35 unused (0).
        """
        h, p, c = self.axes, self.points, self.centre
        rt = self.tool_rotation.T
        x5 = plane_basis(h[4])[0]
        k = np.zeros((CONSTANT_ROWS, 3))
        k[0:6], k[6:12], k[12] = h, p, c

        def turning(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            along = (v @ h[5]) * h[5]
            across = v - along
            return rt @ along, rt @ across, -(rt @ np.cross(h[5], across))

        c0, c1, c2 = turning(c - p[5])
        k[13], k[14], k[15] = c0 + rt @ (p[5] - self.tool_position), c1, c2
        k[16:19] = turning(h[4])
        k[19:22] = turning(x5)
        k[22] = x5
        k[23] = (float(self.mode), float(h[3] @ h[4]), 0.0)
        k[24:34] = _parallel_rows(h, p, c) if self.mode == PARALLEL else _meeting_rows(self)
        return k


def _parallel_rows(h: np.ndarray, p: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Rows 24–33 for axes 2 ∥ 3: e, f (the plane normal to axis 2), (lateral, sign3, 0),
    (r23, 0), (r3c, 0), (l1, l2, 0), (cos, sin of the elbow's offset angle, 0), (h4·h2, 0, 0),
    ``u = h4 − (h4·h2) h2`` and ``h2 × u`` (so that ``R(h2, φ) h4 = (h4·h2) h2 + cos φ u +
    sin φ h2 × u``)."""
    a = h[1]
    e, f = plane_basis(a)
    r23 = np.array([(p[2] - p[1]) @ e, (p[2] - p[1]) @ f])
    r3c = np.array([(c - p[2]) @ e, (c - p[2]) @ f])
    offset = np.arctan2(r23[1], r23[0]) - np.arctan2(r3c[1], r3c[0])
    rows = np.zeros((10, 3))
    rows[0], rows[1] = e, f
    rows[2] = (float(a @ (c - p[0])), float(np.sign(h[2] @ a)), 0.0)
    rows[3, :2], rows[4, :2] = r23, r3c
    rows[5, :2] = (np.hypot(*r23), np.hypot(*r3c))
    rows[6, :2] = (np.cos(offset), np.sin(offset))
    rows[7, 0] = float(h[3] @ a)
    rows[8] = h[3] - rows[7, 0] * a
    rows[9] = np.cross(a, rows[8])
    return rows


def _meeting_rows(g: OffsetWristGeometry) -> np.ndarray:
    """Rows 24–33 for axes 1 and 2 meeting at ``o``: o, ``P = c − p3``, ``Q = o − p3``,
    (A, B, K)/r of subproblem 3 (``A cos θ3 + B sin θ3 = K − ‖c_T − o‖²/2``, r = √(A² + B²),
    not 0: the structure check keeps c and o off axis 3), (h1·h2, |h2 × h1|², 1/(2r)),
    ``h2 × h1``, then zeros."""
    h, p = g.axes, g.points
    big_p, big_q = g.centre - p[2], g.origin - p[2]
    across = big_p - (big_p @ h[2]) * h[2]
    rows = np.zeros((10, 3))
    rows[0], rows[1], rows[2] = g.origin, big_p, big_q
    a, b = float(big_q @ across), float(big_q @ np.cross(h[2], big_p))
    constant = 0.5 * float(big_p @ big_p + big_q @ big_q) - float((big_q @ h[2]) * (h[2] @ big_p))
    radius = float(np.hypot(a, b))
    rows[3] = (a / radius, b / radius, constant / radius)
    normal = np.cross(h[1], h[0])
    rows[4] = (float(h[0] @ h[1]), float(normal @ normal), 0.5 / radius)
    rows[5] = normal
    return rows


def _off_axis(point: np.ndarray, axis_point: np.ndarray, axis: np.ndarray) -> float:
    """Distance [m] from ``point`` to the line through ``axis_point`` along unit ``axis``."""
    off = point - axis_point
    return float(np.linalg.norm(off - (off @ axis) * axis))


def offset_wrist_geometry(screws: Screws) -> tuple[OffsetWristGeometry | None, str]:
    """The structure of six revolute screws at q = 0 for the 1-D search closed form.

    Args:
        screws: The arm's joint screws and tool pose at q = 0 (world frame).

    Returns:
        (geometry, "") when the arm fits, else (None, the reason it does not), e.g.
        ``"axes 4 and 5 do not intersect (2.0e-02 m apart)"``.
    """
    u, p = screws.directions, screws.points
    if len(u) != 6:
        return None, f"{len(u)} joints, not 6"
    if sine_between(u[3], u[4]) < SKEW_TOL:
        return None, "axes 4 and 5 are parallel"
    centre, gap = line_meet(p[3], u[3], p[4], u[4])
    if gap > STRUCTURE_TOL:
        return None, f"axes 4 and 5 do not intersect ({gap:.1e} m apart)"
    miss = _off_axis(centre, p[5], u[5])
    tool_rotation = screws.tool.rotation.copy()
    tool_position = screws.tool.translation.copy()

    def geometry(mode: int, origin: np.ndarray) -> OffsetWristGeometry:
        return OffsetWristGeometry(
            axes=u.copy(),
            points=p.copy(),
            centre=centre,
            miss=miss,
            tool_rotation=tool_rotation,
            tool_position=tool_position,
            mode=mode,
            origin=origin,
        )

    if sine_between(u[1], u[2]) <= STRUCTURE_TOL:
        if sine_between(u[0], u[1]) < SKEW_TOL:
            return None, "axes 1 and 2 are parallel"
        if min(_off_axis(p[2], p[1], u[1]), _off_axis(centre, p[2], u[2])) < STRUCTURE_TOL:
            return None, "axis 3, or the meeting of axes 4 and 5, lies on the axis before it"
        return geometry(PARALLEL, p[0].copy()), ""
    if sine_between(u[0], u[1]) < SKEW_TOL:
        return None, "axes 2 and 3 are not parallel and axes 1, 2 are parallel"
    origin, gap12 = line_meet(p[0], u[0], p[1], u[1])
    if gap12 > STRUCTURE_TOL:
        return None, "axes 2 and 3 are not parallel and axes 1 and 2 do not intersect"
    if min(_off_axis(centre, p[2], u[2]), _off_axis(origin, p[2], u[2])) < STRUCTURE_TOL:
        return None, "axis 3 passes through the meeting of axes 1, 2 or of axes 4, 5"
    return geometry(MEETING, origin), ""
