"""6R arms with three parallel axes 2 ∥ 3 ∥ 4 and axes 1, 5, 6 anywhere, read from their screw
axes at q = 0: :class:`ThreeParallelGeometry` and :func:`three_parallel_geometry` (the
structure, or the reason it does not fit).

The family of IK-Geo's "three parallel axes" solver (Elias & Wen 2022): six revolute joints,
axes 2, 3, 4 parallel and distinct lines (both planar links have a length); axis 1 not parallel
to them, axis 5 not parallel to them, axes 5 and 6 not the same line. Axes 1, 5, 6 need not be
perpendicular to anything, nor meet. The UR arms are of this family (the UR closed form, which
also needs axis 1 ⊥ 2, 5 ⊥ 4, 5 ⊥ 6 and axes 5, 6 meeting, serves them first); so are Unitree's
Z1 (no shoulder offset) and UR-like arms whose wrist axes are skewed or miss each other.

Why those refusals: joints 2–4 keep the component along axis 2 of every point and of the
vector h2, which gives two equations in θ1 and θ5 alone (see
:mod:`~kinplan.ik.three_parallel_kernel`). With axis 1 ∥ axis 2 neither involves θ1; with axis
5 ∥ axis 2, or axes 5 and 6 one line, neither involves θ5: the arm then has a continuum of
solutions for every pose (or none), not a closed form.

Modules, each importing only those before it: ``three_parallel_geometry`` →
:mod:`~kinplan.ik.three_parallel_quartic` (real roots of a quartic, compiled) →
:mod:`~kinplan.ik.three_parallel_kernel` (one pose's solutions, compiled) →
:mod:`~kinplan.ik.three_parallel` (the solver).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinplan.ik.screws import STRUCTURE_TOL, Screws, plane_basis, sine_between

#: Smallest sine of the angle between axes that must not be parallel (below: refused).
SKEW_TOL = 1e-6

#: Rows of :meth:`ThreeParallelGeometry.constants`.
CONSTANT_ROWS = 26


@dataclass(frozen=True)
class ThreeParallelGeometry:
    """A 6R arm with axes 2 ∥ 3 ∥ 4, at q = 0 in the world frame (vectors (3,), lengths [m]).

    Attributes:
        axes: Unit joint axes, shape (6, 3) (axes 3, 4 are ``signs[0]``, ``signs[1]`` times
            axis 2, up to the structure tolerance).
        points: A point on each axis, shape (6, 3) [m]; ``points[5]`` is the point of axis 6
            nearest axis 5 (where they meet, if they do).
        signs: Directions (±1) of axes 3 and 4 relative to axis 2, shape (2,).
        e, f: Basis of the plane normal to axis 2, (e, f, axes[1]) right-handed.
        r23: Axis 2 → axis 3 in plane coordinates (e, f) [m], shape (2,).
        r34: Axis 3 → axis 4 in plane coordinates [m], shape (2,).
        tool_rotation: Tool rotation ``R_M`` at q = 0.
        tool_position: Tool position ``p_M`` at q = 0 [m].
    """

    axes: np.ndarray
    points: np.ndarray
    signs: np.ndarray
    e: np.ndarray
    f: np.ndarray
    r23: np.ndarray
    r34: np.ndarray
    tool_rotation: np.ndarray
    tool_position: np.ndarray

    def tool(self) -> np.ndarray:
        """The tool pose at q = 0 as a 4×4 homogeneous matrix."""
        out = np.eye(4)
        out[:3, :3], out[:3, 3] = self.tool_rotation, self.tool_position
        return out

    def constants(self) -> np.ndarray:
        """The geometry packed for :mod:`~kinplan.ik.three_parallel_kernel`, shape (26, 3).

        Rows: 0–5 axes h1…h6; 6–11 points p1…p6; 12 e; 13 f; 14 (σ3, σ4, 0), the signs of
        axes 3, 4 along h2; 15 (r23, 0); 16 (r34, 0); 17 (l1, l2, 0) = (|r23|, |r34|, 0);
        18 (cos, sin of ``∠r34 − ∠r23``, 0), so that ``|r23 + R(ψ) r34|² = l1² + l2² +
        2 l1 l2 cos(ψ + ∠r34 − ∠r23)``; 19 (γA, δA, κA) with ``h2·(R5(p6 − p5) + p5) =
        γA cos θ5 + δA sin θ5 + κA`` [m]; 20 (γC, δC, κC) with ``h2·R5 h6 = γC cos θ5 +
        δC sin θ5 + κC``; 21 ``m = h2 − (h2·h1) h1`` and 22 ``g = h2 × h1``, so that
        ``h2·R1ᵀ v = cos θ1 m·v − sin θ1 g·v + (h2·h1)(h1·v)``; 23 (h2·h1, h2·p1 [m], 0);
        24 ``R_Mᵀ(p6 − p_M)`` (p6 seen from the tool) [m]; 25 ``R_Mᵀ h6``.
        """
        h, p = self.axes, self.points
        a = h[1]
        k = np.zeros((CONSTANT_ROWS, 3))
        k[0:6], k[6:12] = h, p
        k[12], k[13] = self.e, self.f
        k[14, :2] = self.signs
        k[15, :2], k[16, :2] = self.r23, self.r34
        l1, l2 = float(np.hypot(*self.r23)), float(np.hypot(*self.r34))
        offset = np.arctan2(self.r34[1], self.r34[0]) - np.arctan2(self.r23[1], self.r23[0])
        k[17, :2] = (l1, l2)
        k[18, :2] = (np.cos(offset), np.sin(offset))
        k[19] = _turning_about(h[4], a, p[5] - p[4])
        k[19, 2] += float(a @ p[4])
        k[20] = _turning_about(h[4], a, h[5])
        k[21] = a - float(a @ h[0]) * h[0]
        k[22] = np.cross(a, h[0])
        k[23, :2] = (float(a @ h[0]), float(a @ p[0]))
        rt = self.tool_rotation.T
        k[24] = rt @ (p[5] - self.tool_position)
        k[25] = rt @ h[5]
        return k


def _turning_about(axis: np.ndarray, a: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(γ, δ, κ) with ``a·R(axis, θ) u = γ cos θ + δ sin θ + κ`` (Rodrigues)."""
    along = float(axis @ u)
    return np.array(
        [
            float(a @ u) - float(a @ axis) * along,
            float(a @ np.cross(axis, u)),
            float(a @ axis) * along,
        ]
    )


def _off_axis(point: np.ndarray, axis_point: np.ndarray, axis: np.ndarray) -> float:
    """Distance [m] from ``point`` to the line through ``axis_point`` along unit ``axis``."""
    off = point - axis_point
    return float(np.linalg.norm(off - (off @ axis) * axis))


def _nearest_on(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The point of the line (q, v) nearest the line (p, u) (unit directions; for parallel
    lines, the foot of p)."""
    b = float(u @ v)
    w = p - q
    denominator = 1.0 - b * b
    if denominator < SKEW_TOL**2:
        return q + float(w @ v) * v
    t = (float(v @ w) - b * float(u @ w)) / denominator
    return q + t * v


def three_parallel_geometry(screws: Screws) -> tuple[ThreeParallelGeometry | None, str]:
    """The three-parallel-axes structure of six revolute screws at q = 0.

    Args:
        screws: The arm's joint screws and tool pose at q = 0 (world frame).

    Returns:
        (geometry, "") when the arm fits, else (None, the reason it does not), e.g.
        ``"axes 2 and 4 are not parallel (sin 1.0e+00)"``.
    """
    u, p = screws.directions, screws.points
    if len(u) != 6:
        return None, f"{len(u)} joints, not 6"
    a = u[1]
    for j in (2, 3):
        sine = sine_between(a, u[j])
        if sine > STRUCTURE_TOL:
            return None, f"axes 2 and {j + 1} are not parallel (sin {sine:.1e})"
    if _off_axis(p[2], p[1], a) < STRUCTURE_TOL or _off_axis(p[3], p[2], a) < STRUCTURE_TOL:
        return None, "axes 2 ∥ 3 ∥ 4, but axis 3 is the same line as axis 2 or axis 4"
    if sine_between(u[0], a) < SKEW_TOL:
        return None, "axes 2 ∥ 3 ∥ 4, but axis 1 is parallel to them (four parallel axes)"
    if sine_between(u[4], a) < SKEW_TOL:
        return None, "axes 2 ∥ 3 ∥ 4, but axis 5 is parallel to them (four parallel axes)"
    if sine_between(u[4], u[5]) < SKEW_TOL and _off_axis(p[5], p[4], u[4]) < STRUCTURE_TOL:
        return None, "axes 2 ∥ 3 ∥ 4, but axes 5 and 6 are the same line"
    points = p.copy()
    points[5] = _nearest_on(p[4], u[4], p[5], u[5])
    e, f = plane_basis(a)

    def in_plane(v: np.ndarray) -> np.ndarray:
        return np.array([v @ e, v @ f])

    tool_rotation = screws.tool.rotation.copy()
    tool_position = screws.tool.translation.copy()
    geometry = ThreeParallelGeometry(
        axes=u.copy(),
        points=points,
        signs=np.sign(u[2:4] @ a),
        e=e,
        f=f,
        r23=in_plane(p[2] - p[1]),
        r34=in_plane(p[3] - p[2]),
        tool_rotation=tool_rotation,
        tool_position=tool_position,
    )
    return geometry, ""
