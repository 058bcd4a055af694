"""Closed-form IK of a planar 2R arm (two parallel revolute axes): both elbow branches."""

from __future__ import annotations

import logging
import math

import numpy as np

from kinplan.ik.base import ClosedFormIK, NeedsBatch
from kinplan.ik.screws import (
    CLAMP,
    FREE_TOL,
    PLANAR_TOL,
    SIGNS,
    STRUCTURE_TOL,
    TAU,
    Screws,
    joint_choice,
    parallel,
    plane_basis,
    wrap_angle,
)
from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)


def planar_2r(
    r1: np.ndarray,
    r2: np.ndarray,
    target: np.ndarray,
    fill: np.ndarray,
    signs: np.ndarray = SIGNS,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Both elbow solutions of a planar 2R chain (or the one of each sign in ``signs``).

    The tip is ``Rot(ψa)·(r1 + Rot(ψb)·r2)`` relative to joint A, with rotations counterclockwise
    in the plane's coordinates.

    Args:
        r1: Joint A to joint B at zero angles, plane coordinates [m], shape (2,).
        r2: Joint B to the tip at zero angles [m], shape (2,).
        target: Tip positions relative to joint A [m], shape (..., 2).
        fill: ψa [rad] used where the target is on joint A's axis (ψa free), shape (...).
        signs: The branches, as the sign of ψb − ψb(stretched): (+1, −1) both, (±1,) one.

    Returns:
        (ψa, ψb, reachable) each of shape (..., len(signs)) (elbow branch last) and ``free``
        (...): where ψa was taken from ``fill``.
    """
    l1, l2 = np.hypot(*r1), np.hypot(*r2)
    d2 = np.sum(target**2, axis=-1)
    cosine = (d2 - l1**2 - l2**2) / (2.0 * l1 * l2)
    reachable = np.broadcast_to(
        (np.abs(cosine) <= 1.0 + CLAMP)[..., None], cosine.shape + (len(signs),)
    )
    psi_b = signs * np.arccos(np.clip(cosine, -1.0, 1.0))[..., None]
    psi_b = psi_b + (np.arctan2(r1[1], r1[0]) - np.arctan2(r2[1], r2[0]))
    cb, sb = np.cos(psi_b), np.sin(psi_b)
    vx = r1[0] + cb * r2[0] - sb * r2[1]
    vy = r1[1] + sb * r2[0] + cb * r2[1]
    free = d2 < FREE_TOL**2
    psi_a = np.arctan2(target[..., 1], target[..., 0])[..., None] - np.arctan2(vy, vx)
    psi_a = np.where(free[..., None], fill[..., None], wrap_angle(psi_a))
    return psi_a, wrap_angle(psi_b), reachable, free


# ---------------------------------------------------------------------------- planar 2R
class Planar2RIK(ClosedFormIK):
    """Closed-form IK of a planar arm with two parallel revolute axes (both elbow branches).

    :meth:`nearest` of a position solves it in plain floats (:meth:`_nearest_fast`), with the
    answer of the vectorised path (:meth:`_nearest_batch_path`) to 1e-9 rad; a target with a
    rotation, on joint A's axis (θ1 free) or malformed takes the vectorised path itself.

    Args:
        screws: Joint axes and tool pose at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (2,).
        upper: Upper joint limits [rad], shape (2,).
        weights: Joint weights of the nearest-solution distance (default ones).

    Attributes:
        link_lengths: Distances [m] axis 1 → axis 2 and axis 2 → tool point, in the plane.
    """

    needs_rotation = False

    def __init__(
        self,
        screws: Screws,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        super().__init__(lower, upper, weights)
        self._axis = screws.directions[0]
        self._sign2 = float(np.sign(screws.directions[1] @ self._axis))
        self._e, self._f = plane_basis(self._axis)
        self._origin = screws.points[0]
        self._tool_point = screws.tool.translation.copy()
        self._tool_rotation = screws.tool.rotation.copy()
        self._r1 = self._in_plane(screws.points[1] - screws.points[0])
        self._r2 = self._in_plane(self._tool_point - screws.points[1])
        self.link_lengths = (float(np.hypot(*self._r1)), float(np.hypot(*self._r2)))
        # the single-pose path's constants as floats (the arithmetic of planar_2r)
        self._floats = (
            tuple(self._origin.tolist()),
            tuple(self._e.tolist()),
            tuple(self._f.tolist()),
            tuple(self._axis.tolist()),
            tuple(self._tool_point.tolist()),
            tuple(self._r1.tolist()),
            tuple(self._r2.tolist()),
            math.atan2(self._r1[1], self._r1[0]) - math.atan2(self._r2[1], self._r2[0]),
        )
        limits = (self.lower.tolist(), self.upper.tolist(), self.weights.tolist())
        self._joint_floats = tuple(zip(*limits, strict=True))  # per joint: lower, upper, weight

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        if rotation is None:
            try:
                return self._nearest_fast(position, q_ref)
            except NeedsBatch:
                pass
        return self._nearest_batch_path(position, rotation, q_ref)

    nearest.__doc__ = ClosedFormIK.nearest.__doc__

    def _nearest_batch_path(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """:meth:`nearest` computed by the vectorised machinery (:meth:`_raw` for N = 1): the
        reference of the single-pose path, and its fallback."""
        return ClosedFormIK.nearest(self, position, rotation, q_ref)

    def _nearest_fast(self, position: np.ndarray, q_ref: np.ndarray) -> np.ndarray | None:
        """:meth:`nearest` of a position in plain floats: :meth:`_fast_branches` and the choice
        :meth:`_pick` makes (equal distances go to the first branch).

        Raises:
            NeedsBatch: as :meth:`_fast_branches`, and for a malformed or non-finite ``q_ref``.
        """
        ref = np.asarray(q_ref, dtype=float)
        if ref.shape != (2,):
            raise NeedsBatch
        ref1, ref2 = ref.tolist()
        if not math.isfinite(ref1 + ref2):
            raise NeedsBatch
        (lower1, upper1, weight1), (lower2, upper2, weight2) = self._joint_floats
        joint1 = (ref1, min(max(ref1, lower1), upper1), lower1, upper1, weight1)
        joint2 = (ref2, min(max(ref2, lower2), upper2), lower2, upper2, weight2)
        best, best_cost = None, math.inf
        for q1, q2 in self._fast_branches(position):
            choice1, choice2 = joint_choice(q1, joint1), joint_choice(q2, joint2)
            if choice1 is not None and choice2 is not None and choice1[1] + choice2[1] < best_cost:
                best, best_cost = (choice1[0], choice2[0]), choice1[1] + choice2[1]
        return None if best is None else np.array(best)

    def _fast_branches(self, position: np.ndarray) -> list[tuple[float, float]]:
        """Both branches' (θ1, θ2) [rad] (wrapped into [−π, π]) of a position in plain floats:
        :func:`planar_2r` for one target, rows as :meth:`_raw`'s; empty when the position is out
        of reach or off the arm's plane.

        Raises:
            NeedsBatch: a malformed or non-finite position, or a target on joint A's axis (θ1
                free: the vectorised path takes it from a reference).
        """
        position = np.asarray(position, dtype=float)
        if position.shape != (3,):
            raise NeedsBatch
        px, py, pz = position.tolist()
        if not math.isfinite(px + py + pz):
            raise NeedsBatch
        origin, e, f, axis, tool, r1, r2, offset = self._floats
        dx, dy, dz = px - origin[0], py - origin[1], pz - origin[2]
        tx, ty = dx * e[0] + dy * e[1] + dz * e[2], dx * f[0] + dy * f[1] + dz * f[2]
        d2 = tx * tx + ty * ty
        if d2 < FREE_TOL**2:
            raise NeedsBatch
        off_plane = (px - tool[0]) * axis[0] + (py - tool[1]) * axis[1] + (pz - tool[2]) * axis[2]
        l1, l2 = self.link_lengths  # np.hypot, as planar_2r
        cosine = (d2 - l1**2 - l2**2) / (2.0 * l1 * l2)
        if not (abs(off_plane) <= PLANAR_TOL and abs(cosine) <= 1.0 + CLAMP):
            return []
        elbow = math.acos(min(max(cosine, -1.0), 1.0))
        target_angle = math.atan2(ty, tx)
        branches = []
        for psi_b in (elbow + offset, -elbow + offset):
            cb, sb = math.cos(psi_b), math.sin(psi_b)
            vx = r1[0] + cb * r2[0] - sb * r2[1]
            vy = r1[1] + sb * r2[0] + cb * r2[1]
            psi_a = target_angle - math.atan2(vy, vx)
            psi_a -= TAU * round(psi_a / TAU)
            psi_b -= TAU * round(psi_b / TAU)
            branches.append((psi_a, self._sign2 * psi_b))
        return branches

    # ------------------------------------------------------------ paths, one branch
    def pose_branches(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray | None:
        """Both branches of one position in plain floats (inputs unchecked): (2, 2) [rad], NaN
        rows for branches without a solution (row ``branch``, as :meth:`branch_many`); None for
        a rotation or a target on joint A's axis, where the vectorised path decides."""
        if rotation is not None:
            return None
        try:
            branches = self._fast_branches(position)
        except NeedsBatch:
            return None
        return np.array(branches) if branches else np.full((2, 2), np.nan)

    def branch_many(
        self, positions: np.ndarray, rotations: np.ndarray | None, branch: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """One branch of many targets in one vectorised pass (inputs unchecked): for followers
        that keep a branch along a path (:mod:`cartesian.batch_track`); :meth:`_raw`'s row
        ``branch`` (0: θ2 − θ2(stretched) ≥ 0 about joint A's axis, 1: ≤ 0).

        Returns:
            (q (N, 2) [rad], NaN rows where the branch has no solution; edge (N,) bool: targets
            on joint A's axis, where θ1 is free).
        """
        fill = np.zeros((len(positions), 2))
        raw, free = self._raw(positions, rotations, fill, SIGNS[branch : branch + 1])
        return raw[:, 0], free

    def _in_plane(self, v: np.ndarray) -> np.ndarray:
        return np.stack((v @ self._e, v @ self._f), axis=-1)

    def _raw(
        self,
        positions: np.ndarray,
        rotations: np.ndarray | None,
        fill: np.ndarray,
        signs: np.ndarray = SIGNS,
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`ClosedFormIK._raw`, of the branches ``signs`` (default both, see
        :func:`planar_2r`)."""
        target = self._in_plane(positions - self._origin)
        psi1, psi2, ok, free = planar_2r(self._r1, self._r2, target, fill[:, 0], signs)
        in_plane = np.abs((positions - self._tool_point) @ self._axis) <= PLANAR_TOL
        ok = ok & in_plane[:, None]
        if rotations is not None:
            angle, untilted = self._rotation_angle(rotations)
            # on the base axis θ1 is free for the position, but the orientation fixes it
            psi1 = np.where(free[:, None], wrap_angle(angle[:, None] - psi2), psi1)
            turn_error = np.abs(wrap_angle(angle[:, None] - psi1 - psi2))
            ok &= untilted[:, None] & (turn_error <= PLANAR_TOL)
        q = np.stack((psi1, self._sign2 * psi2), axis=-1)  # (N, branches, 2 joints)
        return np.where(ok[..., None], q, np.nan), free

    def _rotation_angle(self, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Angle [rad] (N,) with ``R = Rot(axis, angle)·R_tool(0)``, and whether R has that form."""
        relative = rotations @ self._tool_rotation.T
        untilted = np.linalg.norm(relative @ self._axis - self._axis, axis=-1) <= PLANAR_TOL
        turned = relative @ self._e
        return np.arctan2(turned @ self._f, turned @ self._e), untilted


def planar_2r_solver(robot: Arm, screws: Screws, weights: np.ndarray | None) -> Planar2RIK | None:
    u = screws.directions
    if not parallel(u[0], u[1]):
        return None
    solver = Planar2RIK(screws, robot.lower, robot.upper, weights)
    if min(solver.link_lengths) < STRUCTURE_TOL:
        return None
    return solver
