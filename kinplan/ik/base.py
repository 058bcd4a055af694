"""What every closed-form IK solver offers (:class:`AnalyticIK`), their common base class
(:class:`ClosedFormIK`: nearest solution, batches along a path) and :func:`self_check`
against the robot's forward kinematics.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Protocol

import numpy as np
import pinocchio as pin

from kinplan.errors import InputError
from kinplan.ik.screws import (
    DISTINCT_TOL,
    LIMIT_TOL,
    TAU,
    compose_scan,
    wrap_angle,
    wrap_near,
)
from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)


class AnalyticIK(Protocol):
    """Closed-form IK of one robot, as :meth:`kinplan.Robot.ik` uses it; poses are in the
    robot's base (world) frame. (The planar 2R and UR solvers also list all solutions with
    ``solutions``, the panda's for a given θ7 with ``solutions_q7``.)"""

    nq: int
    #: Whether a target needs a rotation (False: position targets are solved too).
    needs_rotation: bool

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """The solution nearest ``q_ref`` (2π equivalents within limits considered), or None."""
        ...

    def nearest_batch(
        self, positions: np.ndarray, rotations: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray:
        """Solutions along a path, each nearest the previous one; NaN rows where none."""
        ...


class NeedsBatch(Exception):
    """Raised by a closed form's single-pose path in plain floats (UR family, planar 2R) for a
    pose or input it leaves to the vectorised path (near a singularity, malformed input)."""


# ---------------------------------------------------------------------------- common machinery
class ClosedFormIK:
    """Limits, 2π equivalents, nearest-solution choice and branch following for closed forms.

    Subclasses provide :meth:`_raw`: every branch's solution for a batch of poses.

    Args:
        lower: Lower joint limits [rad], shape (nq,).
        upper: Upper joint limits [rad], shape (nq,).
        weights: Joint weights of the distance Σ wᵢ Δqᵢ² used to pick the nearest solution.
    """

    #: Whether a target must have a rotation.
    needs_rotation: bool = True
    #: Whether the solver finds every solution of every pose it is given (up to its
    #: singularities' free angles). False for a search that may step over roots (the 1-D search
    #: of :mod:`kinplan.ik.wrist_offset`): ``Robot.ik_batch`` then gives a target it finds no
    #: solution for the numerical solve, as ``Robot.ik`` does.
    complete: bool = True
    #: Whether every pose gets its solutions (False: some are left to the numerical solve
    #: with none listed, as :class:`~kinplan.ik.near_wrist.NearWristIK` without the 1-D search
    #: leaves poses near singularities).
    answers_every_pose: bool = True

    def __init__(
        self, lower: np.ndarray, upper: np.ndarray, weights: np.ndarray | None = None
    ) -> None:
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.nq = len(self.lower)
        self.weights = np.ones(self.nq) if weights is None else np.asarray(weights, dtype=float)
        bounded = np.isfinite(self.lower) & np.isfinite(self.upper)
        # mid-range; 0 for an unbounded (continuous) joint, whose limits are ±inf
        self._middle = 0.5 * (
            np.where(bounded, self.lower, 0.0) + np.where(bounded, self.upper, 0.0)
        )
        self._neutral = np.clip(np.zeros(self.nq), self.lower, self.upper)

    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Every branch's solution.

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3), or None.
            fill: Reference values [rad] for joints that are free at a singularity, (N, nq).

        Returns:
            ``raw`` (N, S, nq): angles [rad] (any 2π representative), NaN rows for branches
            without a solution; ``singular`` (N,): where some branch's free joint came from
            ``fill`` (which does not change with ``fill``).
        """
        raise NotImplementedError

    def all_branches(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Every branch's solution of many poses in one vectorised pass (inputs unchecked):
        :meth:`_raw`, for batch solvers (:meth:`kinplan.Robot.ik_batch`).

        Returns:
            ``raw`` (N, S, nq) [rad], NaN rows for branches without a solution, and
            ``singular`` (N,), as :meth:`_raw`.
        """
        return self._raw(positions, rotations, fill)

    # ------------------------------------------------------------ input checks
    def _check_q(self, q: np.ndarray, what: str) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.nq,) or not np.all(np.isfinite(q)):
            raise InputError(f"{what} must be a finite vector of {self.nq} joint values, got {q}")
        return q

    def _check_poses(
        self, positions: np.ndarray, rotations: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray | None]:
        positions = np.asarray(positions, dtype=float)
        if positions.ndim != 2 or positions.shape[1] != 3 or not np.all(np.isfinite(positions)):
            raise InputError(f"positions must be finite, of shape (N, 3), got {positions.shape}")
        if rotations is None:
            if self.needs_rotation:
                raise InputError(
                    f"the closed-form IK of this {self.nq}-joint arm needs the tool rotation; "
                    "position-only targets are for the planar 2R (use Arm.ik instead)"
                )
            return positions, None
        rotations = np.asarray(rotations, dtype=float)
        if rotations.shape != (len(positions), 3, 3) or not np.all(np.isfinite(rotations)):
            raise InputError(
                f"rotations must be finite, of shape ({len(positions)}, 3, 3), "
                f"got {rotations.shape}"
            )
        return positions, rotations

    def _one_pose(
        self, position: np.ndarray, rotation: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray | None]:
        position = np.asarray(position, dtype=float)
        if position.shape != (3,):
            raise InputError(f"position must be a 3-vector [m], got shape {position.shape}")
        rotations = None if rotation is None else np.asarray(rotation, dtype=float)[None]
        return self._check_poses(position[None], rotations)

    # ------------------------------------------------------------ choices
    def _valid(self, raw: np.ndarray) -> np.ndarray:
        """(N, S): branches with a solution that has an equivalent within the limits."""
        return np.all(np.isfinite(wrap_near(raw, self._middle, self.lower, self.upper)), axis=-1)

    def _distance(self, delta: np.ndarray) -> np.ndarray:
        """Weighted squared joint distance Σ wᵢ Δqᵢ² over the last axis [rad²]."""
        return (delta**2) @ self.weights

    def _pick(self, raw: np.ndarray, q_ref: np.ndarray) -> tuple[int, np.ndarray] | None:
        """(branch, q) of the branch in ``raw`` (S, nq) nearest ``q_ref``, within limits."""
        candidates = wrap_near(raw, q_ref, self.lower, self.upper)
        distance = np.nan_to_num(self._distance(candidates - q_ref), nan=np.inf)
        branch = int(np.argmin(distance))
        if not np.isfinite(distance[branch]):
            return None
        return branch, candidates[branch]

    # ------------------------------------------------------------ public API
    def solutions(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        """All solutions within the joint limits.

        Each geometric solution appears once, as its 2π-equivalent within the limits closest to
        mid-range; solutions that coincide (at singularities) are listed once. A joint that is
        free at a singularity takes its neutral value (0 moved into the limits) when it can.

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation in the world frame (3×3), or None for position only (only
                for arms that can ignore the orientation, the planar 2R).

        Returns:
            Joint configurations [rad], shape (k, nq), k ≥ 0 (0: unreachable).
        """
        positions, rotations = self._one_pose(position, rotation)
        raw, _ = self._raw(positions, rotations, self._neutral[None])
        return self._distinct(raw[0])

    def _distinct(self, raw: np.ndarray) -> np.ndarray:
        """The rows of ``raw`` (S, nq) that have an equivalent within the limits, each once, as
        the equivalent nearest mid-range."""
        from kinplan.ik import spherical_wrist_kernel  # numba loads with the first call

        if spherical_wrist_kernel.available():
            out = np.empty(raw.shape)
            kept = spherical_wrist_kernel.distinct(
                np.ascontiguousarray(raw, dtype=float), self._middle, self.lower, self.upper, out
            )
            return out[:kept]
        canonical = wrap_near(raw, self._middle, self.lower, self.upper)
        found = canonical[np.all(np.isfinite(canonical), axis=1)]
        gap = np.abs(wrap_angle(found[:, None, :] - found[None, :, :])).max(axis=-1)
        repeated = np.triu(gap <= DISTINCT_TOL, k=1).any(axis=0)  # equal to an earlier row
        return found[~repeated]

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """The solution nearest ``q_ref``.

        Per joint, the 2π-equivalent within the limits nearest ``q_ref`` is considered; among
        the branches, the one of least weighted distance Σ wᵢ Δqᵢ². At a singularity the free
        joint keeps its ``q_ref`` value when it can (θ6 at the UR wrist singularity).

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation (3×3) in the world frame, or None (planar 2R only).
            q_ref: Reference configuration [rad], shape (nq,).

        Returns:
            The configuration [rad], shape (nq,), or None when no solution is within limits.
        """
        q_ref = self._check_q(q_ref, "q_ref")
        positions, rotations = self._one_pose(position, rotation)
        raw, _ = self._raw(positions, rotations, q_ref[None])
        picked = self._pick(raw[0], q_ref)
        return None if picked is None else picked[1]

    def nearest_batch(
        self, positions: np.ndarray, rotations: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray:
        """Follow a branch along a sequence of poses, each sample nearest the previous one.

        Equal to calling :meth:`nearest` sample by sample with the previous solution (the last
        one found, after samples without solution; ``q_ref`` for the first), but vectorised: the
        branch transitions of consecutive samples are composed by a doubling scan. Two events
        cut the scan and restart it: a sample whose continuous joint value would leave the
        limits (the per-sample rule then picks another 2π-equivalent or branch), and an exactly
        singular sample (its free joint depends on the previous sample), solved on its own.
        The cost grows with the number of such events.

        Args:
            positions: Tool positions in the base (world) frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3), or None (2R only).
            q_ref: Configuration before the first sample [rad], shape (nq,).

        Returns:
            Joint configurations [rad], shape (N, nq); rows of NaN where no solution exists.
        """
        ref = self._check_q(q_ref, "q_ref")
        positions, rotations = self._check_poses(positions, rotations)
        count = len(positions)
        raw, singular = self._raw(positions, rotations, np.tile(ref, (count, 1)))
        valid = self._valid(raw)
        cuts = np.append(np.flatnonzero(singular), count)
        out = np.full((count, self.nq), np.nan)
        start = 0
        while start < count:
            if singular[start]:
                rotation = None if rotations is None else rotations[start]
                q = self.nearest(positions[start], rotation, ref)
                out[start] = np.nan if q is None else q
                stop = 1
            else:
                end = cuts[np.searchsorted(cuts, start)]  # the next singular sample
                segment, stop = self._follow(raw[start:end], valid[start:end], ref)
                out[start : start + stop] = segment[:stop]
            found = np.flatnonzero(~np.isnan(out[start : start + stop, 0]))
            if found.size:
                ref = out[start + found[-1]]
            start += stop
        return out

    def _follow(
        self, raw: np.ndarray, valid: np.ndarray, ref: np.ndarray
    ) -> tuple[np.ndarray, int]:
        """Follow the branches from ``ref`` until a joint would leave its limits.

        Args:
            raw: (M, S, nq) solutions of the samples.
            valid: (M, S) branches with a solution within limits.
            ref: Configuration before sample 0.

        Returns:
            (q, stop): q (M, nq) is exact for rows < ``stop`` (NaN rows where no solution);
            at row ``stop`` the continuous value leaves the limits (``stop == M``: never).
        """
        q_out = np.full((len(raw), self.nq), np.nan)
        samples = np.flatnonzero(valid.any(axis=1))
        if samples.size == 0:
            return q_out, len(raw)
        sub, sub_valid = raw[samples], valid[samples]
        picked = self._pick(sub[0], ref)
        assert picked is not None  # sub[0] has a branch within the limits (``valid``)
        first_branch, first_q = picked
        branches = self._branch_sequence(sub, sub_valid, first_branch)
        chosen = sub[np.arange(len(sub)), branches]
        steps = wrap_angle(np.diff(chosen, axis=0))
        unwrapped = first_q + np.concatenate((np.zeros((1, self.nq)), np.cumsum(steps, axis=0)))
        q = chosen + TAU * np.round((unwrapped - chosen) / TAU)
        q[0] = first_q
        inside = np.all((q >= self.lower - LIMIT_TOL) & (q <= self.upper + LIMIT_TOL), axis=1)
        outside = np.flatnonzero(~inside)
        good = outside[0] if outside.size else len(samples)
        q_out[samples[:good]] = np.clip(q[:good], self.lower, self.upper)
        return q_out, (int(samples[good]) if outside.size else len(raw))

    def _branch_sequence(self, raw: np.ndarray, valid: np.ndarray, first: int) -> np.ndarray:
        """Branch index per sample, each the valid branch nearest the previous sample's."""
        if len(raw) == 1:
            return np.array([first])
        cost = np.zeros((len(raw) - 1, raw.shape[1], raw.shape[1]))
        for j in range(self.nq):  # (previous branch, next branch) per joint, summed
            delta = wrap_angle(raw[1:, None, :, j] - raw[:-1, :, None, j])
            cost += self.weights[j] * delta**2
        cost = np.where(valid[1:, None, :], np.nan_to_num(cost, nan=np.inf), np.inf)
        maps = np.concatenate((np.zeros((1, raw.shape[1]), int), np.argmin(cost, axis=2)))
        return compose_scan(maps)[:, first]


# ---------------------------------------------------------------------------- factory
def self_check(
    robot: Arm,
    solutions_for: Callable[[pin.SE3, np.ndarray], np.ndarray],
    samples: int = 8,
    answers_every_pose: bool = True,
) -> bool:
    """Whether a closed form reproduces random configurations of ``robot`` (Pinocchio FK).

    Args:
        robot: The arm.
        solutions_for: ``(pose, q) -> (k, nq)`` solutions of the tool pose of q (q may be used
            for a free parameter, e.g. the panda's θ7).
        samples: Random configurations checked.
        answers_every_pose: False for a solver that leaves some poses to the numerical solve
            (no solution listed): such poses are not counted, but at least half the samples
            must be answered.
    """
    rng = np.random.default_rng(12345)
    answered = 0
    for _ in range(samples):
        q = robot.random_configuration(rng)
        pose = robot.fk(q)
        found = solutions_for(pose, q)
        if len(found) == 0 and not answers_every_pose:
            continue
        answered += 1
        if not any(np.max(np.abs(wrap_angle(s - q))) < 1e-7 for s in found):
            return False
        for s in found:
            reached = robot.fk(s)
            if np.linalg.norm(reached.translation - pose.translation) > 1e-8:
                return False
            if np.linalg.norm(pin.log3(reached.rotation.T @ pose.rotation)) > 1e-8:
                return False
    return 2 * answered >= samples
