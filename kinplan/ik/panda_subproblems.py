"""The Paden–Kahan subproblems of the panda's closed form: the angle about one axis that takes
a vector towards another (:func:`angle_about`, subproblem 1) and the rotations about two axes
that take one vector onto another (:class:`AxisPair`, subproblem 2, on floats and on arrays).

Second of the panda modules, which import only those before them:
:mod:`~kinplan.ik.panda_geometry` → ``panda_subproblems`` → :mod:`~kinplan.ik.panda_intervals` →
:mod:`~kinplan.ik.panda_batch` → :mod:`~kinplan.ik.panda`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinplan.ik.panda_geometry import Vec, cross, dot
from kinplan.ik.screws import CLAMP, FREE_TOL

#: The batch path (:meth:`PandaIK.nearest_many`) leaves to :meth:`PandaIK.nearest` every pose
#: where a vector comes within this [m or –] of a rotation axis it is turned about (the
#: single-pose path takes the reference's angle below ``FREE_TOL``).
NEAR_FREE = 1e-9


# ---------------------------------------------------------------------------- subproblems
def angle_about(axis: Vec, a: Vec, b: Vec, free: float) -> float:
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
class AxisPair:
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
    def of(cls, a: Vec, b: Vec) -> AxisPair:
        normal = cross(a, b)
        return cls(a, b, dot(a, b), normal, dot(normal, normal))

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
            :data:`NEAR_FREE` of its axis (then :meth:`solve` may take the free values: the
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
        near_free = px * px + py * py + pz * pz < NEAR_FREE**2
        px, py, pz = vx - kb * bx, vy - kb * by, vz - kb * bz
        near_free = near_free | (px * px + py * py + pz * pz < NEAR_FREE**2)
        g = np.stack(np.broadcast_arrays(gamma, -gamma), axis=-2)

        def expand(x):  # a lane axis for the two solutions
            return np.expand_dims(x, -2) if np.ndim(x) else x

        a_parts = (expand(sin_a) + g * expand(sin_a_g), expand(cos_a) + g * expand(un))
        b_parts = (expand(sin_b) + g * expand(sin_b_g), expand(cos_b) + g * expand(vn))
        return a_parts, b_parts, expand(ok), expand(near_free)
