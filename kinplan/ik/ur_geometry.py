"""The UR family's geometry, read from the model: :class:`URGeometry` (the arm at q = 0 in the
world frame) and :func:`ur_geometry` (the UR structure of six joint screws, or None).

The UR modules import only those before them: ``ur_geometry`` → :mod:`~kinplan.ik.ur_single`
(one pose in plain floats) → :mod:`~kinplan.ik.ur_many` (the same formulas over many poses) →
:mod:`~kinplan.ik.ur` (:class:`~kinplan.ik.ur.URIK`, the solver). The solver built on a geometry
is checked against Pinocchio's forward kinematics where it is built
(:func:`kinplan.ik.closed_form.analytic_solver_for`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinplan.ik.screws import STRUCTURE_TOL, Screws, parallel, perpendicular, plane_basis, skew


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


def axes_intersection(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray):
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
    centre = axes_intersection(p[4], u[4], p[5], u[5])
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
