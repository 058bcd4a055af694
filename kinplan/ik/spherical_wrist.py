"""Closed-form IK of 6R arms with a spherical wrist (ABB, KUKA, Fanuc, Yaskawa, Stäubli, ...):
up to eight solutions by Paden–Kahan subproblems, read from the screw axes at q = 0.

With ``T(q) = e1 ⋯ e6 M`` (products of exponentials of the joint screws, world frame) and the
wrist centre ``c`` on axes 4, 5, 6 (:mod:`~kinplan.ik.spherical_wrist_geometry`), joints 4–6
leave ``c`` in place, so the target's wrist centre ``c_T = p_T + R_T·c_tool`` is
``e1 e2 e3 c``. Following IK-Geo (Elias & Wen 2022):

1. **θ1 by subproblem 4.** Rotations about axes 2 ∥ 3 keep the component along axis 2:
   ``h2·R(h1, −θ1)(c_T − p1) = h2·(c − p1)`` (two shoulder branches; free when ``c_T`` is on
   axis 1 and the arm has no lateral offset, then θ1 is the reference's);
2. **θ2, θ3 by subproblem 3**, which for parallel axes is the planar 2R elbow in the plane
   normal to axis 2 (:func:`~kinplan.ik.planar.planar_2r`; two elbow branches);
3. **θ4, θ5 by subproblem 2**: with ``W = (R1 R2 R3)ᵀ R_T R_Mᵀ = R4 R5 R6``,
   ``R4 R5 h6 = W h6`` (two wrist branches; at the wrist singularity, W h6 on axis 4, θ4 is
   free and keeps the reference's value);
4. **θ6 by subproblem 1** from the rest of W.

Branch index ``4·shoulder + 2·elbow + wrist``. :class:`SphericalWristIK` lists every branch of
many poses in one numpy pass (:meth:`_raw`); single poses and ``ik_batch`` run the same
formulas compiled (:mod:`~kinplan.ik.spherical_wrist_kernel`) when numba is available.
"""

from __future__ import annotations

import logging

import numpy as np

from kinplan.ik.base import ClosedFormIK
from kinplan.ik.planar import planar_2r
from kinplan.ik.screws import rotate_about, wrap_angle
from kinplan.ik.spherical_wrist_geometry import WristGeometry
from kinplan.ik.subproblems import sp1, sp2, sp4

logger = logging.getLogger(__name__)


class SphericalWristIK(ClosedFormIK):
    """Closed-form IK of a spherical-wrist 6R arm with axes 2 ∥ 3: up to 8 solutions.

    Args:
        geometry: The arm at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    #: What :attr:`kinplan.Robot.ik_solver` reports for arms of this family.
    description = (
        "closed form: spherical wrist (axes 4, 5, 6 meet; axes 2 ∥ 3), Paden–Kahan subproblems"
    )

    def __init__(
        self,
        geometry: WristGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        super().__init__(lower, upper, weights)
        self.geometry = geometry
        self._x6 = geometry.x6  # a unit vector across axis 6
        self._constants = geometry.constants()
        self._limits = np.ascontiguousarray(np.vstack([self.lower, self.upper, self.weights]))
        from kinplan.ik import spherical_wrist_kernel  # numba loads with the first solver

        self._kernel = spherical_wrist_kernel
        self._compiled = spherical_wrist_kernel.available()

    # ------------------------------------------------------------ all branches, vectorised
    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        assert rotations is not None  # needs_rotation: _check_poses refused None
        g = self.geometry
        h, p = g.axes, g.points
        count = len(positions)
        centre = positions + rotations @ g.centre_in_tool
        v = centre - p[0]
        # 1. θ1 (subproblem 4 for −θ1), (N, 2)
        minus1, ok1, free1 = sp4(h[1], h[0], v, g.lateral)
        t1 = np.where(free1[:, None], fill[:, :1], -minus1)
        # 2. θ2, θ3: the planar elbow, (N, 2, 2)
        seen = p[0] - p[1] + rotate_about(v[:, None, :], h[0], -t1)  # c_T after e1⁻¹, from p2
        target = np.stack((seen @ g.e, seen @ g.f), axis=-1)
        fill2 = np.broadcast_to(fill[:, 1:2], t1.shape)
        t2, psi3, reach, free2 = planar_2r(g.r23, g.r3c, target, fill2)
        t3 = g.sign3 * psi3
        t1 = np.broadcast_to(t1[:, :, None], t2.shape)
        # 3. the wrist: W h6 and W x6 with W = (R1 R2 R3)ᵀ R_T R_Mᵀ, (N, 2, 2, 2, 3)
        tool_axes = np.stack((h[5], self._x6)) @ g.tool_rotation  # R_Mᵀ h6, R_Mᵀ x6
        vectors = np.einsum("nij,kj->nki", rotations, tool_axes)[:, None, None]  # (N,1,1,2,3)
        for axis, angle in ((h[0], t1), (h[1], t2), (h[2], t3)):
            vectors = rotate_about(vectors, axis, -angle[..., None])
        w6, wx = vectors[..., 0, :], vectors[..., 1, :]
        t5, minus4, ok2, free4 = sp2(h[4], h[3], np.broadcast_to(h[5], w6.shape), w6)
        t4 = np.where(free4[..., None], 0.0, -minus4)  # (N, 2, 2, 2)
        # 4. θ6: R(h6, θ6) x6 = R5ᵀ R4ᵀ W x6
        z = rotate_about(wx[..., None, :], h[3], -t4)
        z = rotate_about(z, h[4], -t5)
        t6, _ = sp1(h[5], self._x6, z)
        if free4.any():  # the wrist singularity: θ4 + σ·θ6 fixed, θ4 chosen
            self._free_wrist(t4, t6, w6 @ h[3], free4, fill[:, 3])
        shape = t4.shape
        q = np.stack(
            [
                np.broadcast_to(t1[..., None], shape),
                np.broadcast_to(t2[..., None], shape),
                np.broadcast_to(t3[..., None], shape),
                t4,
                t5,
                t6,
            ],
            axis=-1,
        )
        ok = ok1[:, :, None, None] & reach[..., None] & ok2
        raw = np.where(ok[..., None], wrap_angle(q), np.nan).reshape(count, 8, 6)
        singular = free1 | free2.reshape(count, -1).any(axis=1) | free4.reshape(count, -1).any(1)
        return raw, singular

    def _free_wrist(
        self,
        t4: np.ndarray,
        t6: np.ndarray,
        along4: np.ndarray,
        free4: np.ndarray,
        fill4: np.ndarray,
    ) -> None:
        """θ4, θ6 of the branches at the wrist singularity, in place (see
        :func:`~kinplan.ik.spherical_wrist_kernel.free_wrist`; a loop: such poses are rare).

        Args:
            t4, t6: (N, 2, 2, 2) [rad]; where free, θ4 = 0 and θ6 the matching value.
            along4: ``W h6 · h4`` (N, 2, 2) (its sign is σ).
            free4: (N, 2, 2) where the wrist is singular.
            fill4: θ4 of the references [rad] (N,).
        """
        lo, hi = self.lower, self.upper
        for index in zip(*np.nonzero(free4)):
            sigma = 1.0 if along4[index] >= 0.0 else -1.0
            for wrist in range(2):
                at = (*index, wrist)
                theta4 = self._kernel.free_wrist(
                    float(t6[at]), sigma, float(fill4[index[0]]), lo[3], hi[3], lo[5], hi[5]
                )
                t4[at] = theta4
                t6[at] -= sigma * theta4

    # ------------------------------------------------------------ compiled paths
    def solutions(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        if self._compiled and rotation is not None:
            position = np.asarray(position, dtype=float)
            rotation = np.asarray(rotation, dtype=float)
            if position.shape == (3,) and rotation.shape == (3, 3):
                found = self._kernel.solutions(
                    self._constants, self._limits, self._middle, position, rotation,
                    self._neutral,
                )  # fmt: skip
                if found is not None:  # else the checks below say what is wrong
                    return found
        return super().solutions(position, rotation)

    solutions.__doc__ = ClosedFormIK.solutions.__doc__

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        if self._compiled and rotation is not None:
            position = np.asarray(position, dtype=float)
            rotation = np.asarray(rotation, dtype=float)
            q_ref = np.asarray(q_ref, dtype=float)
            if position.shape == (3,) and rotation.shape == (3, 3) and q_ref.shape == (6,):
                out = np.empty(6)
                branch = self._kernel.nearest(
                    self._constants, self._limits, position, rotation, q_ref, out
                )
                if branch != self._kernel.NOT_FINITE:  # else the checks below say what is wrong
                    return None if branch < 0 else out
        return super().nearest(position, rotation, q_ref)

    nearest.__doc__ = ClosedFormIK.nearest.__doc__

    def nearest_many(
        self, positions: np.ndarray, rotations: np.ndarray, q_ref: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference (inputs unchecked), as
        :meth:`kinplan.ik.ur.URIK.nearest_many` returns it.

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 6).

        Returns:
            (q (N, 6) [rad], branch (N,) int (−1: none within the limits), mask (N,) uint16 of
            the branches within the limits, left (N,) bool: poses for the all-branch path —
            every pose when the compiled kernel is not available).
        """
        count = len(positions)
        if not self._compiled:
            left = np.ones(count, dtype=bool)
            return np.zeros((count, 6)), np.full(count, -1), np.zeros(count, np.uint16), left
        q = np.empty((count, 6))
        branch = np.empty(count, dtype=np.int64)
        mask = np.empty(count, dtype=np.uint16)
        self._kernel.nearest_many(
            self._constants,
            self._limits,
            np.ascontiguousarray(positions, dtype=float),
            np.ascontiguousarray(rotations, dtype=float),
            np.ascontiguousarray(q_ref, dtype=float),
            q,
            branch,
            mask,
        )
        return q, branch, mask, np.zeros(count, dtype=bool)
