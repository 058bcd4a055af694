"""Closed-form IK with a 1-D search for 6R arms whose axes 4 and 5 meet while axis 6 misses
that point (IK-Geo's "1-D search" family, Elias & Wen 2022): rtb-data's ABB IRB140 (axis 6
2 cm off), Kinova's Gen3 6-DoF (0.35 mm off) and any arm of the same structure.

The structure is read from the screw axes at q = 0
(:mod:`~kinplan.ik.wrist_offset_geometry`); for each pose a search over θ6 finds every zero of
the four branch residuals ``f_b(θ6) = h4·(W h5) − h4·h5`` (θ1–θ3 by Paden–Kahan subproblems for
each θ6, θ4, θ5 by subproblem 1 at a root; :mod:`~kinplan.ik.wrist_offset_kernel`): up to
:data:`~kinplan.ik.wrist_offset_kernel.SLOTS` solutions, each checked by forward kinematics to
1e-9. Rows of :meth:`OffsetWristIK._raw` are solutions sorted by branch and θ6, not fixed
branches: row r of one pose and row r of the next need not be the same branch (the path
following of :meth:`~kinplan.ik.base.ClosedFormIK.nearest_batch` chooses by distance, so it
does not rely on it).
"""

from __future__ import annotations

import numpy as np

from kinplan.ik.kernel_closed_form import KernelClosedFormIK
from kinplan.ik.wrist_offset_geometry import PARALLEL, OffsetWristGeometry


class OffsetWristIK(KernelClosedFormIK):
    """Closed-form IK with a search over θ6 for 6R arms with axes 4, 5 meeting and axis 6
    offset: up to 16 solutions.

    Args:
        geometry: The arm at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    #: What :attr:`kinplan.Robot.ik_solver` reports for arms with axes 2 ∥ 3.
    description = (
        "closed form with a 1-D search: axes 4 and 5 meet, axes 2 ∥ 3, axis 6 offset "
        "(IK-Geo), Paden–Kahan subproblems"
    )
    #: A root the search's samples do not resolve can be missed (none of 128,000 random
    #: configurations of the family's 64 catalogue and corpus arms, 1 of 640,000 on two other
    #: seeds: a double root beside another, a Yaskawa HC20SDTP): a target without a solution
    #: goes on to the numerical solve, in ``ik`` and ``ik_batch``.
    complete = False
    #: The same for arms whose axes 1 and 2 meet (axes 2, 3 not parallel).
    description_meeting = (
        "closed form with a 1-D search: axes 4 and 5 meet, axes 1 and 2 meet, axis 6 offset "
        "(IK-Geo), Paden–Kahan subproblems"
    )

    def __init__(
        self,
        geometry: OffsetWristGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        from kinplan.ik import wrist_offset_kernel  # numba loads with the first solver

        super().__init__(geometry, wrist_offset_kernel, lower, upper, weights)
        if geometry.mode != PARALLEL:
            self.description = self.description_meeting
