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

import logging

import numpy as np

from kinplan.ik.base import ClosedFormIK
from kinplan.ik.three_parallel_geometry import ThreeParallelGeometry

logger = logging.getLogger(__name__)


class ThreeParallelIK(ClosedFormIK):
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
        super().__init__(lower, upper, weights)
        self.geometry = geometry
        self._constants = np.ascontiguousarray(geometry.constants())
        self._tool = np.ascontiguousarray(geometry.tool())
        self._limits = np.ascontiguousarray(np.vstack([self.lower, self.upper, self.weights]))
        from kinplan.ik import three_parallel_kernel  # numba loads with the first solver

        self._kernel = three_parallel_kernel
        self.slots = three_parallel_kernel.SLOTS

    # ------------------------------------------------------------ every solution
    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        assert rotations is not None  # needs_rotation: _check_poses refused None
        count = len(positions)
        raw = np.empty((count, self.slots, 6))
        singular = np.empty(count, dtype=bool)
        self._kernel.raw_many(
            self._constants,
            self._tool,
            np.ascontiguousarray(positions, dtype=float),
            np.ascontiguousarray(rotations, dtype=float),
            np.ascontiguousarray(np.broadcast_to(fill, (count, 6)), dtype=float),
            raw,
            singular,
        )
        return raw, singular

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        if rotation is not None:
            position = np.asarray(position, dtype=float)
            rotation = np.asarray(rotation, dtype=float)
            q_ref = np.asarray(q_ref, dtype=float)
            if position.shape == (3,) and rotation.shape == (3, 3) and q_ref.shape == (6,):
                out = np.empty(6)
                row = self._kernel.nearest(
                    self._constants, self._tool, self._limits, position, rotation, q_ref, out
                )
                if row != self._kernel.NOT_FINITE:  # else the checks below say what is wrong
                    return None if row < 0 else out
        return super().nearest(position, rotation, q_ref)

    nearest.__doc__ = ClosedFormIK.nearest.__doc__

    def nearest_many(
        self, positions: np.ndarray, rotations: np.ndarray, q_ref: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference (inputs unchecked), as
        :meth:`kinplan.ik.spherical_wrist.SphericalWristIK.nearest_many` returns it.

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 6).

        Returns:
            (q (N, 6) [rad], row (N,) int (−1: none within the limits), mask (N,) uint16 of
            the rows within the limits, left (N,) bool: all False, every pose is solved).
        """
        count = len(positions)
        q = np.empty((count, 6))
        row = np.empty(count, dtype=np.int64)
        mask = np.empty(count, dtype=np.uint16)
        self._kernel.nearest_many(
            self._constants,
            self._tool,
            self._limits,
            np.ascontiguousarray(positions, dtype=float),
            np.ascontiguousarray(rotations, dtype=float),
            np.ascontiguousarray(q_ref, dtype=float),
            q,
            row,
            mask,
        )
        return q, row, mask, np.zeros(count, dtype=bool)
