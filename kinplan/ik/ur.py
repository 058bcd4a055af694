"""Closed-form IK of the UR family (Hawkins 2013, in screw form): eight solutions, vectorised
over poses, with a plain-float path for single poses.

:class:`URIK` is the solver. Its parts live in the modules before it, each importing only those
before it: :mod:`~kinplan.ik.ur_geometry` (:class:`URGeometry` and :func:`ur_geometry`, the arm
read from the model) → :mod:`~kinplan.ik.ur_single` (one pose in plain floats) →
:mod:`~kinplan.ik.ur_many` (the same formulas over many poses) → ``ur``. Every name this module
had before that split is still importable from it, the helpers under their former private names
(bound below), which are also the names :class:`URIK` calls them by. The fast path also runs
compiled (numba): :mod:`~kinplan.ik.ur_kernel`.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from kinplan.ik.base import ClosedFormIK, NeedsBatch
from kinplan.ik.planar import planar_2r
from kinplan.ik.screws import (
    CLAMP,
    FREE_TOL,
    SIGNS,
    joint_choice,
    rotate_about,
    rotate_about_line,
    rotate_by,
    wrap_angle,
)
from kinplan.ik.screws import STRUCTURE_TOL as STRUCTURE_TOL
from kinplan.ik.screws import TINY as TINY
from kinplan.ik.screws import Screws as Screws
from kinplan.ik.screws import joint_choice_many as joint_choice_many
from kinplan.ik.screws import parallel as parallel
from kinplan.ik.screws import perpendicular as perpendicular
from kinplan.ik.screws import plane_basis as plane_basis
from kinplan.ik.screws import skew as skew
from kinplan.ik.ur_geometry import URGeometry, axes_intersection
from kinplan.ik.ur_geometry import ur_geometry as ur_geometry
from kinplan.ik.ur_many import (
    fast_branch_many,
    fast_nearest_many,
    planar_targets,
    shoulder_terms,
    stack_pair,
)
from kinplan.ik.ur_single import (
    EXACT_DEFECT,
    FAST_DEFECT,
    FAST_EDGE,
    FAST_WRIST,
    URFast,
    fast_defect,
    fast_elbow,
    fast_planar_target,
    fast_plane_axes,
    fast_shoulder,
    fast_wrist,
    ur_fast_constants,
)

#: The single-pose constants (:func:`~kinplan.ik.ur_single.ur_fast_constants`) log here.
logger = logging.getLogger(__name__)

# The former names of the helpers, before the split (URIK below calls them by these).
_axes_intersection = axes_intersection
_FAST_EDGE, _FAST_WRIST, _FAST_DEFECT = FAST_EDGE, FAST_WRIST, FAST_DEFECT
_URFast = URFast
_ur_fast_constants = ur_fast_constants
_fast_shoulder = fast_shoulder
_fast_wrist = fast_wrist
_fast_plane_axes = fast_plane_axes
_fast_planar_target = fast_planar_target
_fast_elbow = fast_elbow
_pair = stack_pair
_shoulder_terms = shoulder_terms
_planar_targets = planar_targets
_fast_nearest_many = fast_nearest_many
_fast_branch_many = fast_branch_many


class URIK(ClosedFormIK):
    """Closed-form IK of a UR-type arm: up to 8 solutions (shoulder × wrist × elbow).

    Branch index ``4·shoulder + 2·wrist + elbow``. At the wrist singularity (axis 6 parallel to
    axes 2–4) θ6 is free: it keeps the reference value, or the nearest value the elbow can
    follow when the reference's is out of its reach. At the shoulder singularity (wrist centre
    at distance |d4| from axis 1) the two shoulder branches coincide, and with a straight elbow
    the two elbow branches.

    :meth:`nearest` and :meth:`solutions` solve a single pose in plain floats
    (:meth:`_fast_raw`, :meth:`_nearest_fast`), with the answer of the vectorised path
    (:meth:`_nearest_batch_path`) to 1e-9 rad; near singularities, for a geometry whose axes
    are not orthonormal to ``_FAST_DEFECT`` and for negative weights they use the vectorised
    path itself. Between EXACT_DEFECT and FAST_DEFECT (π/2 written rounded), given the URDF's
    screws, :meth:`solutions` polishes the fast path's rows by Newton's method on them
    (:meth:`_polished`), the vectorised path where a polish is not certified. Limits and
    weights are read once, at construction. With numba (and not ``KINPLAN_JIT=0``)
    :meth:`nearest`, :meth:`nearest_many`, :meth:`branch_many` and :meth:`solutions` run the
    same formulas compiled (:mod:`~kinplan.ik.ur_kernel`: the same answers to ~1e-15 rad, the
    same branches and left poses); the plain-float and numpy code is then the fallback.

    Args:
        geometry: The arm at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    def __init__(
        self,
        geometry: URGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
        screws: Screws | None = None,
    ) -> None:
        super().__init__(lower, upper, weights)
        self.geometry = geometry
        #: The URDF's joint screws and tool pose at q = 0 (world frame), when given: a
        #: geometry within FAST_DEFECT of orthonormal then lists its solutions by the fast path,
        #: each Newton-polished on them (:meth:`_polished`).
        self._screws = None
        if screws is not None:
            self._screws = (
                np.ascontiguousarray(screws.directions, dtype=float),
                np.ascontiguousarray(screws.points, dtype=float),
                np.ascontiguousarray(screws.tool.homogeneous, dtype=float),
            )
        self._fast = _ur_fast_constants(geometry)
        #: The fast path is exact (else ``nearest`` takes it, and ``solutions`` only polished
        #: on the URDF's screws, see EXACT_DEFECT).
        self._fast_exact = fast_defect(geometry) <= EXACT_DEFECT
        self._limits = (tuple(self.lower.tolist()), tuple(self.upper.tolist()))
        self._weight_floats = tuple(self.weights.tolist())
        if min(self._weight_floats) < 0.0:  # the fast path's pruning needs a growing distance
            self._fast = None
        from kinplan.ik import ur_kernel  # numba loads with the first solver

        self._kernel = ur_kernel
        #: The fast path runs compiled (:mod:`~kinplan.ik.ur_kernel`), with its packed constants.
        self._compiled = self._fast is not None and ur_kernel.available()
        if self._fast is not None:
            self._constants = ur_kernel.constants(self._fast)
        self._limit_rows = np.ascontiguousarray(np.vstack([self.lower, self.upper, self.weights]))

    # ------------------------------------------------------------ single pose, plain floats
    def solutions(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        fast = self._fast is not None and (self._fast_exact or self._screws is not None)
        if fast and self._compiled and rotation is not None:
            position = np.asarray(position, dtype=float)
            rotation = np.asarray(rotation, dtype=float)
            if position.shape == (3,) and rotation.shape == (3, 3):
                return self._compiled_solutions(position, rotation)
        if fast:
            try:
                raw = self._fast_all_branches(position, rotation)
            except NeedsBatch:
                pass
            else:
                if self._fast_exact or self._polished(raw, position, rotation):
                    return self._distinct(raw)
        return super().solutions(position, rotation)

    solutions.__doc__ = ClosedFormIK.solutions.__doc__

    def _compiled_solutions(self, position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
        """:meth:`solutions` by the compiled fast path (:func:`~kinplan.ik.ur_kernel.branches`,
        the rows of :meth:`_fast_all_branches`), polished on the URDF's screws when the
        geometry is not exactly orthonormal; the vectorised path near a singularity, for a NaN
        or inf (it reports it) and where a polish is not certified."""
        assert self._fast is not None  # only with the fast path
        terms = self._fast.matrix.dot(rotation.reshape(9))
        if self._fast_exact:
            found = self._kernel.solutions(
                self._constants, terms, position, self._middle, self.lower, self.upper
            )
            if found is not None:
                return found
        else:
            raw = np.empty((8, 6))
            if self._kernel.branches(self._constants, terms, position, raw) == 0 and (
                self._polished(raw, position, rotation)
            ):
                return self._distinct(raw)
        return ClosedFormIK.solutions(self, position, rotation)

    def _polished(self, raw: np.ndarray, position: np.ndarray, rotation: np.ndarray | None) -> bool:
        """Each row of ``raw`` (8, 6) [rad] (NaN: no solution) polished in place by Newton's
        method on the URDF's screws (:func:`kinplan.ik.near_wrist_kernel.polish`: first step
        ≤ 1e-2 rad, each next ≤ 1e-2 of the one before, residual ≤ 1e-12 m and rad); whether
        every row was. The fast path assumes orthonormal axes; a geometry up to FAST_DEFECT
        from them (π/2 written rounded) misses the pose by ~1e-10, which one step removes."""
        from kinplan.ik import near_wrist_kernel  # numba loads with the first solver

        if self._screws is None or rotation is None or not near_wrist_kernel.available():
            return False

        directions, points, tool = self._screws
        position = np.ascontiguousarray(position, dtype=float)
        rotation = np.ascontiguousarray(rotation, dtype=float)
        return bool(
            near_wrist_kernel.polish_rows(raw, position, rotation, directions, points, tool)
        )

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        if self._compiled and self._fast is not None and rotation is not None:
            position = np.asarray(position, dtype=float)
            rotation = np.asarray(rotation, dtype=float)
            q_ref = np.asarray(q_ref, dtype=float)
            if position.shape == (3,) and rotation.shape == (3, 3) and q_ref.shape == (6,):
                out = np.empty(6)
                terms = self._fast.matrix.dot(rotation.reshape(9))  # as _fast_pose takes them
                branch = self._kernel.nearest(
                    self._constants, self._limit_rows, terms, position, q_ref, out
                )
                if branch >= -1:  # else near a singularity or not finite: the batch path
                    return None if branch < 0 else out
                return self._nearest_batch_path(position, rotation, q_ref)
        if self._fast is not None:
            try:
                return self._nearest_fast(position, rotation, q_ref)
            except NeedsBatch:
                pass
        return self._nearest_batch_path(position, rotation, q_ref)

    nearest.__doc__ = ClosedFormIK.nearest.__doc__

    def nearest_many(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        q_ref: np.ndarray,
        masks: bool = True,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference, in one vectorised pass
        (the single-pose formulas on arrays, or compiled; inputs unchecked).

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 6).
            masks: False: the masks are not wanted; compiled, they are then 0 and the
                branches that cannot be nearest are not solved (the same q, branch, left).

        Returns:
            (q (N, 6) [rad], branch (N,) int (−1: no solution within the limits), mask (N,)
            uint16 of the branches with a solution within the limits (bit ``branch``), left
            (N,) bool). ``left`` marks the poses :meth:`nearest` leaves to the vectorised
            all-branch path (near a singularity, or every pose when the geometry has no
            single-pose path); their other outputs are meaningless.
        """
        count = len(positions)
        if self._fast is None:
            left = np.ones(count, dtype=bool)
            return np.zeros((count, 6)), np.full(count, -1), np.zeros(count, np.uint16), left
        if self._compiled:
            q = np.empty((count, 6))
            branch = np.empty(count, dtype=np.int64)
            mask = np.empty(count, dtype=np.uint16)
            left = np.empty(count, dtype=bool)
            terms, along = self._terms(positions, rotations)
            refs = np.ascontiguousarray(q_ref, dtype=float)
            self._kernel.nearest_many(
                self._constants, self._limit_rows, terms, along, refs, q, branch, mask, left, masks
            )
            return q, branch, mask, left
        joints = tuple(zip(*self._limits, self._weight_floats))
        refs = np.ascontiguousarray(np.asarray(q_ref, dtype=float).T)
        with np.errstate(invalid="ignore", divide="ignore"):  # NaN lanes: no solution
            return _fast_nearest_many(self._fast, joints, positions, rotations, refs)

    @property
    def branch_many_available(self) -> bool:
        """Whether :meth:`branch_many` and :meth:`pose_branches` answer (the geometry has the
        single-pose path: orthonormal axes, weights ≥ 0)."""
        return self._fast is not None

    def pose_branches(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray | None:
        """Every branch of one pose in plain floats (inputs unchecked): (8, 6) [rad], any 2π
        representative, NaN rows for branches without a solution (row ``branch``, as
        :meth:`branch_many`); None near a singularity, where the single-pose formulas leave the
        pose to the batch path, and without a rotation."""
        try:
            return self._fast_all_branches(position, rotation)
        except NeedsBatch:
            return None

    def branch_many(
        self, positions: np.ndarray, rotations: np.ndarray | None, branch: np.ndarray | int
    ) -> tuple[np.ndarray, np.ndarray]:
        """One branch of many poses in one vectorised pass (inputs unchecked): for followers
        that keep a branch along a path (:mod:`cartesian.batch_track`).

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            branch: Branch index ``4·shoulder + 2·wrist + elbow``, one or one per pose (N,).

        Returns:
            (q (N, 6) [rad], any 2π representative, NaN rows where the branch has no solution;
            edge (N,) bool: poses near a singularity of the branch, where q is ill-conditioned
            — every pose when the geometry has no single-pose path, see
            :attr:`branch_many_available`, or without rotations).
        """
        if self._fast is None or rotations is None:
            count = len(positions)
            return np.full((count, 6), np.nan), np.ones(count, dtype=bool)
        if self._compiled:
            count = len(positions)
            q, edge = np.empty((count, 6)), np.empty(count, dtype=bool)
            terms, along = self._terms(positions, rotations)
            branches = np.ascontiguousarray(np.broadcast_to(np.asarray(branch, np.int64), count))
            self._kernel.branch_many(self._constants, terms, along, branches, q, edge)
            return q, edge
        with np.errstate(invalid="ignore", divide="ignore"):  # NaN lanes: no solution
            return _fast_branch_many(self._fast, positions, rotations, branch)

    def _terms(self, positions: np.ndarray, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The products the compiled kernel reads, taken in numpy as the array path's
        :func:`~kinplan.ik.ur_many.shoulder_terms` takes them (so the same roundings):
        ``URFast.matrix @ R.ravel()`` per pose (12, N) and the shoulder axes' coordinates of
        the positions (3, N) [m]."""
        k = self._fast
        assert k is not None  # only with the fast path
        n = len(positions)
        terms = k.matrix @ rotations.reshape(n, 9).T
        along = np.reshape(k.shoulder_axes, (3, 3)) @ positions.T
        return terms, along

    def _nearest_batch_path(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """:meth:`nearest` computed by the vectorised machinery (:meth:`_raw` for N = 1).

        The reference of the single-pose path, and its fallback near singularities.
        """
        return ClosedFormIK.nearest(self, position, rotation, q_ref)

    def _fast_pose(
        self, position: np.ndarray, rotation: np.ndarray | None
    ) -> tuple[list[float], list[float]]:
        """The target as floats: (P [m], ``matrix @ R.ravel()``, see :class:`_URFast`).

        Raises:
            NeedsBatch: for a malformed or non-finite target (the batch path reports it).
        """
        if rotation is None:
            raise NeedsBatch
        position = np.asarray(position, dtype=float)
        rotation = np.asarray(rotation, dtype=float)
        if position.shape != (3,) or rotation.shape != (3, 3):
            raise NeedsBatch
        if self._fast is None:
            raise NeedsBatch
        position_list = position.tolist()
        values = self._fast.matrix.dot(rotation.reshape(9)).tolist()
        # a NaN or inf anywhere in R reaches some value (the matrix has no zero column)
        if not math.isfinite(sum(position_list) + sum(values)):
            raise NeedsBatch
        return position_list, values

    def _fast_raw(self, position: list[float], values: list[float]) -> list[tuple]:
        """θ1, θ5, θ6 of every branch of one pose, and what its planar step needs.

        The formulas of :meth:`_raw` in plain floats, expanded in the frames of :class:`_URFast`.
        The planar step (:func:`_fast_planar_target`, :func:`_fast_elbow`) is left to the
        caller, which may skip branches it does not need.

        Args:
            position: Tool position in the world frame [m].
            values: ``self._fast.matrix @ R.ravel()`` of the tool rotation R (world frame).

        Returns:
            Per shoulder branch (sign +1, then −1): (θ1, per wrist branch (+1, then −1):
            (θ5, θ6, plane)) with ``plane`` from :func:`_fast_plane_axes`. Angles [rad], any 2π
            representative. Empty when no θ1 exists.

        Raises:
            NeedsBatch: near the shoulder or wrist singularity (see ``_FAST_EDGE``,
                ``_FAST_WRIST``), where the batch path decides.
        """
        k = self._fast
        if k is None:
            raise NeedsBatch
        shoulder = _fast_shoulder(k, position, values)
        if shoulder is None:
            return []
        branches = []
        for t1 in shoulder[0]:
            c1, s1 = math.cos(t1), math.sin(t1)
            t5s, t6s = _fast_wrist(k, c1, s1, values)
            plane = _fast_plane_axes(k, c1, s1, shoulder[1], values)
            branches.append((t1, ((t5s[0], t6s[0], plane), (t5s[1], t6s[1], plane))))
        return branches

    def _fast_all_branches(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        """:meth:`_raw` of one pose (N = 1, no free joint) in plain floats: (8, 6) [rad], NaN rows
        for branches without a solution. Raises NeedsBatch as :meth:`_fast_raw`."""
        k = self._fast
        if k is None:
            raise NeedsBatch
        raw = np.full((8, 6), np.nan)
        for shoulder, (t1, wrists) in enumerate(
            self._fast_raw(*self._fast_pose(position, rotation))
        ):
            for wrist, (t5, t6, plane) in enumerate(wrists):
                elbow = _fast_elbow(k, *_fast_planar_target(k, plane, t5, t6))
                for branch, (t2, t3, t4) in enumerate(elbow or ()):
                    raw[4 * shoulder + 2 * wrist + branch] = (t1, t2, t3, t4, t5, t6)
        return raw

    def _nearest_fast(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """:meth:`nearest` in plain floats: the choice :meth:`_pick` makes on :meth:`_raw`.

        Branch and bound: the branches' (θ1, θ5, θ6) parts of the distance are computed first,
        and the planar step only for the (shoulder, wrist) pairs, in increasing order of that
        part, that can still beat the best branch found (the weights are ≥ 0). Equal distances
        go to the lower branch index, as in :meth:`_pick`.

        Raises:
            NeedsBatch: for the poses and inputs :meth:`_fast_raw` and :meth:`_fast_pose` leave
                to the batch path, and for a malformed or non-finite ``q_ref``.
        """
        ref = np.asarray(q_ref, dtype=float)
        if ref.shape != (6,):
            raise NeedsBatch
        ref = ref.tolist()
        if not math.isfinite(sum(ref)):
            raise NeedsBatch
        branches = self._fast_raw(*self._fast_pose(position, rotation))
        # per joint: (reference, reference clipped into the limits, lower, upper, weight)
        j1, j2, j3, j4, j5, j6 = (
            (r, min(max(r, lo), hi), lo, hi, w)
            for r, lo, hi, w in zip(ref, *self._limits, self._weight_floats)
        )
        heads = []  # (distance of θ1, θ5, θ6; pair index 2·shoulder + wrist; their values; ...)
        for shoulder, (t1, wrists) in enumerate(branches):
            choice1 = joint_choice(t1, j1)
            if choice1 is None:
                continue
            for wrist, (t5, t6, plane) in enumerate(wrists):
                choice5, choice6 = joint_choice(t5, j5), joint_choice(t6, j6)
                if choice5 is not None and choice6 is not None:
                    head = choice1[1] + choice5[1] + choice6[1]
                    pair = 2 * shoulder + wrist
                    heads.append((head, pair, choice1[0], choice5[0], choice6[0], t5, t6, plane))
        heads.sort()  # by distance, then pair index (never compares further)
        k = self._fast
        if k is None:
            raise NeedsBatch
        best, best_cost, best_index = None, math.inf, 8
        for head, pair, q1, q5, q6, t5, t6, plane in heads:
            if head > best_cost:
                break
            elbow = _fast_elbow(k, *_fast_planar_target(k, plane, t5, t6))
            for branch, (t2, t3, t4) in enumerate(elbow or ()):
                choice2 = joint_choice(t2, j2)
                if choice2 is None or head + choice2[1] > best_cost:
                    continue
                choice3, choice4 = joint_choice(t3, j3), joint_choice(t4, j4)
                if choice3 is None or choice4 is None:
                    continue
                cost = head + choice2[1] + choice3[1] + choice4[1]
                index = 2 * pair + branch
                if cost < best_cost or (cost == best_cost and index < best_index):
                    best, best_cost, best_index = (
                        (q1, choice2[0], choice3[0], choice4[0], q5, q6),
                        cost,
                        index,
                    )
        return None if best is None else np.array(best)

    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        assert rotations is not None  # needs_rotation: _check_poses refused None
        g = self.geometry
        count = len(positions)
        t1, shoulder_ok = self._shoulder(positions, rotations)  # (N, 2)
        n = np.cos(t1)[..., None] * g.a + np.sin(t1)[..., None] * g.b1  # axis 2 at θ1, (N, 2, 3)
        t1 = t1[:, :, None]
        t5, t6, free6 = self._wrist(rotations, n, fill[:, 5])  # (N, 2, 2)
        if free6.any():
            feasible = self._feasible_theta6(positions, rotations, t1, t5, fill[:, 5])
            t6 = np.where(free6, feasible, t6)
        target, phi = self._planar_target(positions, rotations, t1, t5, t6)
        t2, t3, t4, elbow_ok, free2 = self._joints_234(target, phi, fill[:, 1])
        shape = (count, 2, 2, 2)
        q = np.stack(
            [
                np.broadcast_to(t1[..., None], shape),
                t2,
                t3,
                t4,
                np.broadcast_to(t5[..., None], shape),
                np.broadcast_to(t6[..., None], shape),
            ],
            axis=-1,
        )
        ok = shoulder_ok[:, :, None, None] & elbow_ok
        raw = np.where(ok[..., None], q, np.nan).reshape(count, 8, 6)
        singular = np.any(free6.reshape(count, -1), axis=1) | np.any(
            free2.reshape(count, -1), axis=1
        )
        return raw, singular

    def _shoulder(
        self, positions: np.ndarray, rotations: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """θ1 (N, 2) from ``n(θ1)·(c − p1) = shoulder_offset``, and whether it is reachable."""
        g = self.geometry
        centre = positions + rotations @ g.centre_in_tool
        x, y = (centre - g.p1) @ g.a, (centre - g.p1) @ g.b1
        radius = np.hypot(x, y)
        ratio = g.shoulder_offset / np.maximum(radius, np.finfo(float).tiny)
        reachable = np.abs(ratio) <= 1.0 + CLAMP
        half = np.arccos(np.clip(ratio, -1.0, 1.0))
        t1 = wrap_angle(np.arctan2(y, x)[:, None] + SIGNS * half[:, None])
        return t1, np.broadcast_to(reachable[:, None], t1.shape)

    def _wrist(
        self, rotations: np.ndarray, n: np.ndarray, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """θ5, θ6 (N, 2, 2) (shoulder, wrist) from the tool axes; free (N, 2, 2) where θ6 = fill.

        With R = R1 R234 R5 R6 R_M (rotations about the q = 0 axes) and R234 about ``a``:
        ``n·z6 = a·R5 u6 = cos(θ5 − δ)``, and ``R6ᵀ R5ᵀ a = R_M Rᵀ n`` fixes θ6. The angles come
        from atan2 of components perpendicular to u6 (not arccos), so they stay accurate near
        the wrist singularity sin(θ5 − δ) = 0.
        """
        g = self.geometry
        b = np.einsum("nji,nsj->nsi", rotations, n) @ g.tool_rotation.T  # R_M Rᵀ n, (N, 2, 3)
        cosine = b @ g.u6  # n·z6
        b_perp = b - cosine[..., None] * g.u6
        sine = np.linalg.norm(b_perp, axis=-1)  # |sin(θ5 − δ)|
        t5 = g.delta5 + SIGNS * np.arctan2(sine, cosine)[..., None]
        r5t_a = np.cos(t5)[..., None] * g.a - np.sin(t5)[..., None] * g.u5_cross_a  # R5ᵀ a
        g_perp = r5t_a - (r5t_a @ g.u6)[..., None] * g.u6
        b_perp = b_perp[:, :, None, :]
        sin6 = np.sum((b_perp @ g.cross6) * g_perp, axis=-1)  # u6·(b⊥ × g⊥)
        cos6 = np.sum(b_perp * g_perp, axis=-1)
        free = np.broadcast_to((sine < FREE_TOL)[..., None], t5.shape)
        t6 = np.where(free, fill[:, None, None], np.arctan2(sin6, cos6))
        return wrap_angle(t5), t6, free

    def _planar_target(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        t1: np.ndarray,
        t5: np.ndarray,
        t6: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The planar motion X = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹ that joints 2–4 must make (X = e2 e3 e4).

        Args:
            positions, rotations: Targets (N, 3), (N, 3, 3).
            t1: θ1, shape (N, 2, 1); t5, t6: θ5, θ6, shape (N, 2, 2) [rad].

        Returns:
            (target, φ): where X moves the point of axis 4, relative to axis 2 in the plane's
            (e, f) coordinates [m], shape (N, 2, 2, 2); X's rotation about ``a`` [rad] (N, 2, 2).
        """
        g = self.geometry
        point = rotate_about_line(g.p4, g.p5, g.u5, -t5, g.cross5)
        point = rotate_about_line(point, g.p6, g.u6, -t6, g.cross6)
        point = rotate_by(rotations, (point - g.tool_position) @ g.tool_rotation)
        point = rotate_about_line(point + positions[:, None, None], g.p1, g.u1, -t1, g.cross1)
        turned = rotate_about(rotate_about(g.e, g.u5, -t5, g.cross5), g.u6, -t6, g.cross6)
        turned = rotate_by(rotations, turned @ g.tool_rotation)
        turned = rotate_about(turned, g.u1, -t1, g.cross1)
        relative = point - g.p2
        target = np.stack((relative @ g.e, relative @ g.f), axis=-1)
        return target, np.arctan2(turned @ g.f, turned @ g.e)

    def _feasible_theta6(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        t1: np.ndarray,
        t5: np.ndarray,
        fill: np.ndarray,
    ) -> np.ndarray:
        """θ6 [rad] (N, 2, 2) for the wrist singularity, where θ6 is free.

        Joints 2, 3, 4 and 6 are then all parallel: θ6 can take any value the elbow can
        follow. The 2R target moves on a circle with θ6, |target|² = k + A·cos(θ6 − β); the
        elbow reaches it for |l2 − l3| ≤ |target| ≤ l2 + l3, an arc of θ6. Returns ``fill`` when
        it lies on that arc, else the nearest end of the arc (where the elbow is straight or
        folded; if the arc is empty, the 2R step then finds the pose unreachable).
        """
        g = self.geometry
        at = [
            self._planar_target(positions, rotations, t1, t5, np.full(t5.shape, angle))[0]
            for angle in (0.0, 0.5 * np.pi, np.pi)
        ]
        centre = 0.5 * (at[0] + at[2])
        u, v = 0.5 * (at[0] - at[2]), at[1] - centre
        k = np.sum(centre**2, axis=-1) + np.sum(u**2, axis=-1)
        b_cos, b_sin = 2.0 * np.sum(centre * u, axis=-1), 2.0 * np.sum(centre * v, axis=-1)
        amplitude, beta = np.hypot(b_cos, b_sin), np.arctan2(b_sin, b_cos)
        l2, l3 = np.hypot(*g.r23), np.hypot(*g.r34)
        safe = np.maximum(amplitude, np.finfo(float).tiny)
        # within reach for min_offset ≤ |θ6 − β| ≤ max_offset (not too far, not too close)
        min_offset = np.arccos(np.clip(((l2 + l3) ** 2 - k) / safe, -1.0, 1.0))
        max_offset = np.arccos(np.clip(((l2 - l3) ** 2 - k) / safe, -1.0, 1.0))
        offset = wrap_angle(fill[:, None, None] - beta)
        magnitude = np.clip(np.abs(offset), min_offset, max_offset)
        clamped = beta + np.where(offset >= 0.0, magnitude, -magnitude)
        keep = (magnitude == np.abs(offset)) | (amplitude == 0.0)
        return np.where(keep, fill[:, None, None], clamped)

    def _joints_234(
        self, target: np.ndarray, phi: np.ndarray, fill: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """θ2, θ3, θ4 (N, 2, 2, 2) from the planar motion: a 2R problem for joints 2 and 3, then
        θ4 from ψ2 + ψ3 + ψ4 = φ (ψk = ±θk, the axis signs).

        Returns:
            (θ2, θ3, θ4, reachable, free) with ``free`` where θ2 = fill (axis 4 on axis 2).
        """
        g = self.geometry
        fill_psi2 = np.broadcast_to((g.signs[0] * fill)[:, None, None], phi.shape)
        psi2, psi3, reachable, free = planar_2r(g.r23, g.r34, target, fill_psi2)
        psi4 = wrap_angle(phi[..., None] - psi2 - psi3)
        return g.signs[0] * psi2, g.signs[1] * psi3, g.signs[2] * psi4, reachable, free
