"""Closed-form IK of spherical-wrist 6R arms whose axes 2 and 3 are not parallel: IK-Geo's
spherical families (Elias & Wen 2022) with axes 1 and 2 meeting, axes 2 and 3 meeting, or
neither (subproblem 5, a quartic), up to eight solutions by Paden–Kahan subproblems.

The structure is read from the screw axes at q = 0
(:mod:`~kinplan.ik.spherical_general_geometry`); for each pose the first three joints place
the wrist centre (subproblems 3 and 2, or 5; :mod:`~kinplan.ik.spherical_general_positions`),
the wrist takes the rest of the rotation (subproblems 2 and 1) and every solution is checked
by forward kinematics to 1e-9 (:mod:`~kinplan.ik.spherical_general_kernel`, compiled). With
axes 1, 2 or axes 2, 3 meeting the rows of :meth:`GeneralWristIK._raw` are fixed branches
``4·first + 2·second + wrist``; in the general mode they are positions in the order of
subproblem 5's roots, then wrist, so row r of one pose and row r of the next need not be the
same branch (the path following of :meth:`~kinplan.ik.base.ClosedFormIK.nearest_batch`
chooses by distance, so it does not rely on it).
"""

from __future__ import annotations

import logging

import numpy as np

from kinplan.ik.kernel_closed_form import KernelClosedFormIK
from kinplan.ik.spherical_general_geometry import (
    GENERAL,
    MEETING_12,
    MEETING_23,
    GeneralWristGeometry,
)

logger = logging.getLogger(__name__)


class GeneralWristIK(KernelClosedFormIK):
    """Closed-form IK of a spherical-wrist 6R arm with axes 2 ∦ 3: up to 8 solutions.

    Args:
        geometry: The arm at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    #: What :attr:`kinplan.Robot.ik_solver` reports, by position mode.
    descriptions = {
        MEETING_12: "closed form: spherical wrist, axes 1 and 2 meet (IK-Geo), Paden–Kahan "
        "subproblems 3, 2, 1",
        MEETING_23: "closed form: spherical wrist, axes 2 and 3 meet (IK-Geo), Paden–Kahan "
        "subproblems 3, 2, 1",
        GENERAL: "closed form: spherical wrist, general shoulder (IK-Geo), subproblem 5 (a "
        "quartic), Paden–Kahan subproblems 2, 1",
    }
    #: The general mode's description (each solver's :attr:`description` is its mode's).
    description = descriptions[GENERAL]
    #: The kernel's ``raw_many`` takes the limits (θ4 at the wrist singularity).
    raw_takes_limits = True

    def __init__(
        self,
        geometry: GeneralWristGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        from kinplan.ik import spherical_general_kernel  # numba loads with the first solver

        super().__init__(geometry, spherical_general_kernel, lower, upper, weights)
        self.description = self.descriptions[geometry.mode]
