"""Closed-form IK for 6R arms whose URDF rounds a spherical wrist (compas-fab's ABB IRB4600,
Doosan's A0509 and A0912, a Denso VS060: axes 4, 5, 6 missing one point by 0.2–25 µm):
the spherical-wrist closed form on the idealised arm
(:mod:`~kinplan.ik.near_wrist_geometry`), each solution polished by Newton's method on the
URDF's screws and certified, the exact 1-D search where it is not
(:mod:`~kinplan.ik.near_wrist_kernel`). Every solution is the URDF's own, to 1e-12.
"""

from __future__ import annotations

import numpy as np

from kinplan.ik.base import ClosedFormIK
from kinplan.ik.kernel_closed_form import KernelClosedFormIK
from kinplan.ik.near_wrist_geometry import NearWristGeometry


class NearWristIK(KernelClosedFormIK):
    """Closed-form IK of a 6R arm within a rounding of a spherical wrist with axes 2 ∥ 3.

    Args:
        geometry: The arm and its idealised spherical wrist at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    #: Poses near a singularity or a boundary of reach go to the 1-D search, which may step
    #: over roots, or, on arms without one, to the numerical solve: ``ik`` and ``ik_batch``
    #: solve a target this finds no solution for numerically.
    complete = False
    #: The kernel's ``raw_many`` takes the limits (for the idealised arm's free wrist).
    raw_takes_limits = True

    def __init__(
        self,
        geometry: NearWristGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        from kinplan.ik import near_wrist_kernel  # numba loads with the first solver

        ClosedFormIK.__init__(self, lower, upper, weights)
        self.geometry = geometry
        self._constants = geometry.constants()  # type: ignore[assignment]
        self._tool = geometry.tool()  # type: ignore[assignment]
        self._limits = np.ascontiguousarray(np.vstack([self.lower, self.upper, self.weights]))
        self._kernel = near_wrist_kernel
        self.slots = near_wrist_kernel.SLOTS
        self.answers_every_pose = geometry.exact is not None
        fallback = "the 1-D search" if geometry.exact is not None else "the numerical solve"
        self.description = (
            f"closed form: spherical wrist as rounded in the URDF (axes 4, 5, 6 meet within "
            f"{geometry.shift:.1e} m, axes 2 ∥ 3 within {geometry.turn:.1e} rad), Paden–Kahan "
            f"subproblems, Newton-polished; {fallback} near singularities"
        )
