"""Closed-form IK of 6R arms with three parallel axes 2 ∥ 3 ∥ 4 and axes 1, 5, 6 anywhere (not
necessarily perpendicular or meeting): IK-Geo's "three parallel axes" solver (Elias & Wen 2022),
by Paden–Kahan subproblems with subproblem 6, up to eight solutions. Unitree's Z1, UR-like arms
whose wrist axes are skewed or miss each other, and any arm of the same structure.

The structure is read from the screw axes at q = 0
(:mod:`~kinplan.ik.three_parallel_geometry`); for each pose θ1 and θ5 come from two equations
that joints 2–4 cannot change (subproblem 6: the real roots of a quartic), θ6 by subproblem 1,
θ2, θ3 by subproblem 3 and θ4 from the remaining rotation about axis 2
(:mod:`~kinplan.ik.three_parallel_kernel`, compiled). Every solution is checked by forward
kinematics to 1e-9. Rows of :meth:`ThreeParallelIK._raw` are solutions in the order of the
quartic's roots, then elbow, not fixed branches: row r of one pose and row r of the next need
not be the same branch (the path following of
:meth:`~kinplan.ik.base.ClosedFormIK.nearest_batch` chooses by distance, so it does not rely
on it).
"""

from __future__ import annotations

import numpy as np

from kinplan.ik.kernel_closed_form import KernelClosedFormIK
from kinplan.ik.three_parallel_geometry import ThreeParallelGeometry


class ThreeParallelIK(KernelClosedFormIK):
    """Closed-form IK of a 6R arm with axes 2 ∥ 3 ∥ 4: up to 8 solutions.

    Args:
        geometry: The arm at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    #: What :attr:`kinplan.Robot.ik_solver` reports.
    description = (
        "closed form: three parallel axes 2 ∥ 3 ∥ 4 (IK-Geo), Paden–Kahan subproblems with "
        "subproblem 6"
    )

    def __init__(
        self,
        geometry: ThreeParallelGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        from kinplan.ik import three_parallel_kernel  # numba loads with the first solver

        super().__init__(geometry, three_parallel_kernel, lower, upper, weights)
