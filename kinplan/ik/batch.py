"""Inverse kinematics for many targets at once: what :meth:`kinplan.Robot.ik_batch` runs.

Three solvers, chosen per arm:

* **closed form, vectorised** (planar 2R, UR family, spherical wrist): per target the branch
  and the 2π-equivalents nearest its seed, the choice :meth:`kinplan.Robot.ik` makes. The UR
  family runs the single-pose formulas of ``URIK.nearest`` on arrays (:meth:`URIK.nearest_many`,
  in passes of :data:`UR_CHUNK` targets), the spherical-wrist arms their compiled kernel
  (:meth:`SphericalWristIK.nearest_many`); the targets that ``nearest`` leaves to the all-branch
  path near a singularity, and the planar 2R, list every branch in one numpy pass
  (``all_branches``) and keep the nearest. The solutions are checked by forward kinematics and
  polished by a few Newton steps where the rounding left them outside the tolerances, as
  :meth:`kinplan.Robot.ik` does;
* **closed form with a θ7 search** (panda-type arms): ``PandaIK.nearest``'s search stage by
  stage on all targets at once (:meth:`PandaIK.nearest_many`), targets near a free angle by
  ``nearest`` itself; checked the same way;
* **Levenberg–Marquardt over targets** (any other serial arm): the damped least-squares iteration
  of :class:`kinplan.ik.IKSolver` run on all unfinished targets at once, with numpy's batched
  solves; targets that stall restart from the same Halton configurations as
  :meth:`kinplan.Robot.ik`.

The arrays they work on (forward kinematics and Jacobians of many configurations, rotation
logarithms, the targets as arrays) are :mod:`kinplan.ik.batch_kinematics`.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np
import pinocchio as pin

from kinplan.ik import IKResult, IKSolver, frobenius_tolerance
from kinplan.ik.base import AnalyticIK, ClosedFormIK
from kinplan.ik.batch_kinematics import (
    TAU,
    BatchKinematics,
    JacobianArm,
    log3,
    nearest_equivalent,
    one_blas_thread,
    pose_errors,
)
from kinplan.ik.batch_threads import split_run, thread_count
from kinplan.ik.kernel_closed_form import KernelClosedFormIK
from kinplan.ik.numeric import (
    DAMPING_FLOOR,
    DAMPING_GAIN,
    MAX_STEP,
    POLISH_DAMPING_FLOOR,
    POLISH_ITERATIONS,
    POLISH_STALL_ITERATIONS,
    STALL_ITERATIONS,
    TURNS_PER_ATTEMPT,
    check_effort,
)
from kinplan.ik.panda import PandaIK
from kinplan.ik.spherical_wrist import SphericalWristIK
from kinplan.ik.ur import URIK

logger = logging.getLogger(__name__)


class SolvingArm(JacobianArm, Protocol):
    """An arm with its own IK solvers (a :class:`kinplan.Robot` is one): what the batch solver
    needs beyond :class:`~kinplan.model.arm.Arm` (it falls back to the arm's own :meth:`ik`)."""

    @property
    def closed_form_ik(self) -> AnalyticIK | None:
        """The arm's closed-form solver, or None."""
        ...

    @property
    def ik_solver(self) -> IKSolver:
        """The arm's numerical solver."""
        ...

    def ik(
        self,
        target: pin.SE3 | Sequence[float] | np.ndarray,
        q_seed: Sequence[float] | np.ndarray | None = None,
        position_only: bool = False,
        *,
        position_tolerance: float = 1e-6,
        rotation_tolerance: float = 1e-6,
        max_iterations: int = 40,
        max_restarts: int = 40,
    ) -> IKResult:
        """The configuration nearest ``q_seed`` that puts the tool at ``target``."""
        ...


#: Newton iterations that polish a closed-form solution the rounding left outside the
#: tolerances (as :meth:`kinplan.ik.IKSolver.solve` does).
_POLISH_ITERATIONS = 3
#: Targets solved per numpy pass (bounds the memory of the per-branch arrays: ~1 kB a target).
CHUNK = 16384
#: Targets of one pass of the vectorised UR closed form (within a CHUNK): its arrays then stay
#: in the CPU caches, and its BLAS products below BLAS_COLUMNS.
UR_CHUNK = 4096
#: Numerical restarts tried side by side per target when few targets are left: as many as
#: make about SIDE_BY_SIDE_ROWS rows, at most RESTARTS_AT_ONCE.
RESTARTS_AT_ONCE = 8
SIDE_BY_SIDE_ROWS = 1024


#: Closed forms whose compiled ``nearest_many`` solves many poses (q, branch, mask, left).
_NEAREST_MANY = (URIK, SphericalWristIK, KernelClosedFormIK)


class BatchSolver:
    """Batch IK of one robot (built by :meth:`kinplan.Robot.ik_batch` on first use).

    Args:
        robot: The arm.
    """

    def __init__(self, robot: SolvingArm) -> None:
        self.robot = robot
        self.kinematics = BatchKinematics.of(robot)
        closed_form = robot.closed_form_ik
        self.closed_form = closed_form
        #: The closed form lists every branch of many poses in one pass (planar 2R, UR family).
        self.vectorised = closed_form is not None and hasattr(closed_form, "all_branches")
        self.lower, self.upper = robot.lower, robot.upper
        self._restarts = robot.ik_solver.restart_configuration
        #: Whether a batch has run on threads (the first warms the solver's lazy caches up).
        self._warm = False

    def method(self, position_only: bool) -> str:
        """``"closed-form"``, ``"closed-form-loop"``, ``"levenberg-marquardt"`` or ``"loop"``."""
        closed = self.closed_form is not None and not (
            position_only and self.closed_form.needs_rotation
        )
        if closed and self.kinematics is not None:
            return "closed-form" if self.vectorised else "closed-form-loop"
        return "levenberg-marquardt" if self.kinematics is not None else "loop"

    def solve(
        self,
        positions: np.ndarray,
        rotations: np.ndarray | None,
        seeds: np.ndarray,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        max_restarts: int,
        rescue: bool = True,
        threads: int | None = 1,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Solve every target; see :meth:`kinplan.Robot.ik_batch` (inputs already checked,
        seeds within 2π of the limits). ``rescue=False`` leaves out the last numerical tries
        of targets every attempt failed (see :meth:`_rescue`). ``threads``: as
        :meth:`solve_with_branches`.

        Returns:
            (q (N, nq), success (N,)).
        """
        return self.solve_with_branches(
            positions, rotations, seeds, position_tolerance, rotation_tolerance,
            max_iterations, max_restarts, rescue, masks=False, threads=threads,
        )[:2]  # fmt: skip

    def solve_with_branches(
        self,
        positions: np.ndarray,
        rotations: np.ndarray | None,
        seeds: np.ndarray,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        max_restarts: int,
        rescue: bool = True,
        *,
        masks: bool = True,
        threads: int | None = 1,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solve`, and for closed forms that list branches (UR family, planar 2R) the
        branch of each solution and a bit mask of every branch that reaches the target within
        the limits (bit b for branch b); −1 and 0 for other solvers. ``masks=False``: masks
        not wanted (the UR kernel then skips the branches that cannot be nearest; they may
        come out 0). ``threads``: how many threads share the targets (None: the automatic
        choice of :func:`kinplan.ik.batch_threads.thread_count`); the answers are the same on
        any number of threads (q to the last bits of rounding). Arms without batch
        kinematics (a Python loop over :meth:`kinplan.Robot.ik`, whose Pinocchio data are
        shared) and numerical arms without the compiled solve (numpy's many small steps hold
        the GIL: a prismatic gantry ran no faster on two) run on one.

        Returns:
            (q (N, nq), success (N,), branch (N,) int8, mask (N,) uint16).

        Raises:
            InputError: ``max_iterations`` and ``max_restarts`` beyond the bounds of
                :func:`kinplan.ik.numeric.check_effort` (per target).
        """
        check_effort(max_iterations, max_restarts)
        count = len(positions)
        threads = thread_count(count, threads)
        method = self.method(rotations is None)
        numpy_steps = method == "levenberg-marquardt" and not self.robot.ik_solver.compiled
        if method == "loop" or numpy_steps:
            threads = 1  # Pinocchio's shared data; numpy's small steps hold the GIL

        def solve(part: slice) -> tuple[np.ndarray, ...]:
            return self._solve_with_branches(
                positions[part], None if rotations is None else rotations[part], seeds[part],
                position_tolerance, rotation_tolerance, max_iterations, max_restarts, rescue,
                masks,
            )  # fmt: skip

        with one_blas_thread():
            q, success, branches, found = split_run(solve, count, threads, not self._warm)
        self._warm = self._warm or threads > 1
        return q, success, branches, found

    def _solve_with_branches(
        self,
        positions: np.ndarray,
        rotations: np.ndarray | None,
        seeds: np.ndarray,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        max_restarts: int,
        rescue: bool,
        want_masks: bool = True,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        count = len(positions)
        method = self.method(rotations is None)
        q = np.empty_like(seeds)  # every method below writes every row of its part
        success = np.zeros(count, dtype=bool)
        branches = np.full(count, -1, dtype=np.int8)
        masks = np.zeros(count, dtype=np.uint16)
        tolerances = (position_tolerance, rotation_tolerance)
        for start in range(0, count, CHUNK):
            part = slice(start, min(start + CHUNK, count))
            rot = None if rotations is None else rotations[part]
            effort = (max_iterations, max_restarts, rescue)
            if method == "closed-form":
                q[part], success[part], branches[part], masks[part] = self._closed_form(
                    positions[part], rot, seeds[part], tolerances, want_masks
                )
            elif method == "closed-form-loop":
                q[part], success[part] = self._closed_form_loop(
                    positions[part], rot, seeds[part], tolerances
                )
            elif method == "levenberg-marquardt":
                q[part], success[part] = self._levenberg_marquardt(
                    positions[part], rot, seeds[part], tolerances, *effort
                )
            else:
                q[part], success[part] = self._loop(
                    positions[part], rot, seeds[part], tolerances, max_iterations, max_restarts
                )
            complete = getattr(self.closed_form, "complete", True)
            if method.startswith("closed-form") and rescue and not complete:
                left = np.flatnonzero(~success[part])  # as ik: the numerical solve (see complete)
                if left.size:
                    index = left + start
                    rot = None if rotations is None else rotations[index]
                    q[index], success[index] = self._levenberg_marquardt(
                        positions[index], rot, seeds[index], tolerances, *effort
                    )
        return q, success, branches, masks

    def _levenberg_marquardt(
        self, positions, rotations, seeds, tolerances, max_iterations, max_restarts, rescue
    ):
        """The numerical solve of every target (:meth:`_numerical`, then :meth:`_rescue` for the
        failures where it did not run): (q, success)."""
        q, success, done = self._numerical(
            positions, rotations, seeds, tolerances, max_iterations, max_restarts, rescue
        )
        left = np.flatnonzero(~success)
        if not done and rescue and max_restarts > 0 and left.size:
            rot = None if rotations is None else rotations[left]
            q[left], success[left] = self._rescue(
                positions[left], rot, q[left], seeds[left], tolerances, max_iterations
            )
        return q, success

    # ------------------------------------------------------------ closed forms
    def _closed_form(self, positions, rotations, seeds, tolerances, masks=True):
        solver = self.closed_form
        assert isinstance(solver, ClosedFormIK)  # vectorised: it lists every branch at once
        if rotations is not None and isinstance(solver, _NEAREST_MANY):
            # the single-pose formulas on arrays; near singularities, all branches (as ik)
            extra = {"masks": masks} if isinstance(solver, (URIK, KernelClosedFormIK)) else {}
            parts = [
                solver.nearest_many(positions[part], rotations[part], seeds[part], **extra)
                for part in (slice(k, k + UR_CHUNK) for k in range(0, len(positions), UR_CHUNK))
            ]
            q, branch, mask, left = (np.concatenate(x) for x in zip(*parts))
            rest = np.flatnonzero(left)
            if rest.size:
                q[rest], branch[rest], mask[rest] = self._all_branch_choice(
                    positions[rest], rotations[rest], seeds[rest]
                )
        else:
            q, branch, mask = self._all_branch_choice(positions, rotations, seeds)
        found = branch >= 0
        missing = np.flatnonzero(~found)  # no solution: the seed clipped into the limits
        if missing.size:
            q[missing] = np.clip(seeds[missing], self.lower, self.upper)
        q, success = self._verify(positions, rotations, q, found, tolerances)
        return q, success, branch.astype(np.int8), mask

    def _all_branch_choice(self, positions, rotations, seeds):
        """(q, branch (−1: none), mask) of the branch nearest each seed, from every branch of
        the closed form (:meth:`ClosedFormIK.all_branches`)."""
        solver = self.closed_form
        assert isinstance(solver, ClosedFormIK)  # vectorised: it lists every branch at once
        raw, _ = solver.all_branches(positions, rotations, seeds)  # (N, S, nq)
        candidates = nearest_equivalent(raw, seeds[:, None, :], self.lower, self.upper)
        distance = ((candidates - seeds[:, None, :]) ** 2) @ solver.weights
        distance = np.nan_to_num(distance, nan=np.inf)
        branch = np.argmin(distance, axis=1)  # ties: the lower branch index, as nearest()
        found = np.isfinite(distance[np.arange(len(branch)), branch])
        q = candidates[np.arange(len(branch)), branch]
        bits = np.isfinite(distance) << np.arange(distance.shape[1], dtype=np.uint16)
        mask = np.bitwise_or.reduce(bits.astype(np.uint16), axis=1)
        return q, np.where(found, branch, -1), mask

    def _closed_form_loop(self, positions, rotations, seeds, tolerances):
        solver = self.closed_form
        assert solver is not None  # "closed-form-loop": the arm has a closed form
        q = np.clip(seeds, self.lower, self.upper)
        found = np.zeros(len(positions), dtype=bool)
        loop: range | np.ndarray = range(len(positions))
        if rotations is not None and isinstance(solver, PandaIK):
            q_many, found, left = solver.nearest_many(positions, rotations, seeds)
            q[found] = q_many[found]
            loop = np.flatnonzero(left)  # near a free angle: nearest() decides
        for k in loop:
            rotation = None if rotations is None else rotations[k]
            solution = solver.nearest(positions[k], rotation, seeds[k])
            if solution is not None:
                q[k], found[k] = solution, True
        return self._verify(positions, rotations, q, found, tolerances)

    def _verify(self, positions, rotations, q, found, tolerances):
        """FK check of closed-form solutions; a few Newton steps where rounding left them just
        outside the tolerances."""
        position_tolerance, rotation_tolerance = tolerances
        assert self.kinematics is not None  # the closed-form methods need it (method())
        position2, frobenius2 = self.kinematics.errors(q, positions, rotations)
        good = (position2 <= position_tolerance**2) & (
            frobenius2 <= frobenius_tolerance(rotation_tolerance)
        )
        success = found & good
        retry = np.flatnonzero(found & ~good)
        if retry.size:
            rot = None if rotations is None else rotations[retry]
            q[retry], success[retry], _ = self._descend(
                positions[retry], rot, q[retry], tolerances, _POLISH_ITERATIONS
            )
        return q, success

    # ------------------------------------------------------------ numerical
    def _numerical(
        self, positions, rotations, seeds, tolerances, max_iterations, max_restarts, rescue
    ):
        """The seeded attempt, then the Halton restarts of :meth:`kinplan.ik.IKSolver.solve`
        for the targets still unsolved.

        Serial revolute arms run :meth:`kinplan.ik.IKSolver.compiled_solve_many`: the compiled
        solve of :meth:`kinplan.Robot.ik` target by target (attempts, restarts and, with
        ``rescue``, the rescue). Other arms (or without numba) run the steps on
        all targets at once with numpy: several restarts side by side when few targets are
        left (up to :data:`RESTARTS_AT_ONCE`, about :data:`SIDE_BY_SIDE_ROWS` rows), each
        target keeping its first converged restart in restart order (else its best one,
        earliest on ties): the answers of trying them one after the other, in fewer numpy
        passes.

        Returns:
            (q, success, done): ``done`` when nothing is left to try (the compiled solve ran
            the rescue, or ``rescue`` was False).
        """
        compiled = self.robot.ik_solver.compiled_solve_many(
            positions, rotations, seeds, tolerances[0], tolerances[1], max_iterations,
            max_restarts, rescue,
        )  # fmt: skip
        if compiled is not None:  # serial revolute arms: the compiled solve of ik, per target
            q, converged = compiled
            assert self.kinematics is not None  # the numerical method needs it (method())
            position2, frobenius2 = self.kinematics.errors(q, positions, rotations)
            success = converged & (position2 <= tolerances[0] ** 2)
            success &= frobenius2 <= frobenius_tolerance(tolerances[1])
            return q, success, True
        q, success, score = self._descend(positions, rotations, seeds, tolerances, max_iterations)
        attempt = 1
        while attempt <= max_restarts:
            left = np.flatnonzero(~success)
            if left.size == 0:
                break
            # side by side only when few are left (the others would mostly be wasted)
            width = min(RESTARTS_AT_ONCE, -(-SIDE_BY_SIDE_ROWS // left.size))
            width = max(1, min(width, max_restarts - attempt + 1))
            starts = np.array([self._restarts(attempt + k) for k in range(width)])
            rows = np.repeat(left, width)  # target-major: row j·width + k is restart k of j
            rot = None if rotations is None else rotations[rows]
            q_new, ok, new_score = self._descend(
                positions[rows], rot, np.tile(starts, (left.size, 1)), tolerances, max_iterations
            )
            ok, new_score = ok.reshape(-1, width), new_score.reshape(-1, width)
            q_new = q_new.reshape(left.size, width, -1)
            solved = ok.any(axis=1)
            first = np.argmax(ok, axis=1)  # the first converged restart
            for j in range(width):  # failures: the best score in restart order
                better = ~solved & (new_score[:, j] < score[left])
                q[left[better]] = q_new[better, j]
                score[left[better]] = new_score[better, j]
            q[left[solved]] = q_new[solved, first[solved]]
            success[left] = solved
            attempt += width
        return q, success, False

    def _rescue(self, positions, rotations, q_best, seeds, tolerances, max_iterations):
        """What :meth:`kinplan.ik.IKSolver.solve` tries when every attempt failed, on all such
        targets at once: polish the best attempt with Gauss–Newton-like steps; then solve from
        the seed ignoring the limits and turn the revolute joints by whole turns into them."""
        floor, patience = POLISH_DAMPING_FLOOR, POLISH_STALL_ITERATIONS
        long = POLISH_ITERATIONS * max_iterations
        q, success, _ = self._descend(
            positions, rotations, q_best, tolerances, long, floor=floor, patience=patience
        )
        left = np.flatnonzero(~success)
        if left.size == 0:
            return q, success
        rot = None if rotations is None else rotations[left]
        free, ok, _ = self._descend(
            positions[left], rot, seeds[left], tolerances, long, clamp=False
        )
        turns = np.ceil((self.lower - free) / TAU - 1e-12)
        assert self.kinematics is not None  # the numerical method needs it (method())
        free = free + TAU * np.where(self.kinematics.revolute & np.isfinite(turns), turns, 0.0)
        ok &= np.all((free >= self.lower) & (free <= self.upper), axis=1)
        turned = left[ok]
        if turned.size:
            rot = None if rotations is None else rotations[turned]
            polished, good, _ = self._descend(
                positions[turned], rot, free[ok], tolerances, max_iterations,
                floor=floor, patience=patience,
            )  # fmt: skip
            q[turned[good]], success[turned[good]] = polished[good], True
        return q, success

    def _descend(
        self,
        positions,
        rotations,
        q,
        tolerances,
        max_iterations,
        *,
        floor: float = DAMPING_FLOOR,
        patience: int = STALL_ITERATIONS,
        clamp: bool = True,
    ):
        """:meth:`kinplan.ik.IKSolver.descend` with ``turn`` (as an IK solve runs it) on all
        targets at once (``floor``: the damping λ₀; ``patience``: iterations without progress
        before a target stops; ``clamp=False`` ignores the limits).

        Returns:
            (q, converged, score) with score the position plus rotation error [m + rad] of q.
        """
        lower, upper = (self.lower, self.upper) if clamp else (-np.inf, np.inf)
        q = np.clip(np.array(q, dtype=float), lower, upper)
        count, nq = q.shape
        position_tolerance, rotation_tolerance = tolerances
        position_tolerance2 = position_tolerance**2
        frobenius_tolerance2 = frobenius_tolerance(rotation_tolerance)
        rows = 3 if rotations is None else 6
        converged = np.zeros(count, dtype=bool)
        score = np.full(count, np.inf)
        best_cost = np.full(count, np.inf)
        stalled = np.zeros(count, dtype=int)
        touching = np.ones(count, dtype=bool)  # q may sit on a limit: the active set is checked
        turns = np.zeros((count, nq), dtype=np.int64)  # of each joint into the limits
        active = np.arange(count)
        eye = np.eye(nq)
        kinematics = self.kinematics
        assert kinematics is not None  # the numerical method needs it (method())
        for it in range(max_iterations + 1):
            if active.size == 0:
                break
            qa = q[active]
            rot = None if rotations is None else rotations[active]
            reached, reached_rotations, J = kinematics.fk_jacobian(qa)
            position2, frobenius2 = pose_errors(positions[active], rot, reached, reached_rotations)
            done = (position2 <= position_tolerance2) & (frobenius2 <= frobenius_tolerance2)
            rotation_error = 2.0 * np.arcsin(np.minimum(np.sqrt(frobenius2) / math.sqrt(8.0), 1.0))
            score[active] = np.sqrt(position2) + rotation_error
            converged[active[done]] = True
            keep = ~done
            if it == max_iterations:
                break
            e = np.zeros((len(qa), 6))
            e[:, :3] = positions[active] - reached
            if rot is not None:
                er = log3(rot @ np.swapaxes(reached_rotations, 1, 2))
                e[:, 3:] = er
                rotation2 = np.sum(er**2, axis=1)
            else:
                rotation2 = np.zeros(len(qa))
            cost = 0.5 * (position2 + rotation2)
            improved = cost < 0.999 * best_cost[active]
            best_cost[active] = np.where(improved, cost, best_cost[active])
            stalled[active] = np.where(improved, 0, stalled[active] + 1)
            keep &= stalled[active] < patience
            J, e, qa, cost = J[keep, :rows], e[keep, :rows], qa[keep], cost[keep]
            active = active[keep]
            if active.size == 0:
                break
            Jt = np.swapaxes(J, 1, 2)
            A = Jt @ J + (DAMPING_GAIN * cost + floor)[:, None, None] * eye
            g = (Jt @ e[..., None])[..., 0]
            dq = np.linalg.solve(A, g[..., None])[..., 0]
            blocked = ((qa <= lower) & (dq < 0)) | ((qa >= upper) & (dq > 0))
            blocked &= touching[active][:, None]
            hit = np.flatnonzero(blocked.any(axis=1))
            if hit.size:  # active set: blocked joints leave the step
                free = (~blocked[hit]).astype(float)
                A_hit = A[hit] * (free[:, :, None] * free[:, None, :])
                A_hit += blocked[hit][:, :, None] * eye
                dq[hit] = np.linalg.solve(A_hit, (g[hit] * free)[..., None])[..., 0]
            step = np.abs(dq).max(axis=1)
            dq *= np.where(step > MAX_STEP, MAX_STEP / np.maximum(step, 1e-300), 1.0)[:, None]
            free_q = qa + dq
            if clamp:  # revolute joints beyond a limit turned into the limits where they fit
                beyond = kinematics.revolute & (turns[active] < TURNS_PER_ATTEMPT)
                beyond &= (free_q < lower) | (free_q > upper)  # never for an unbounded joint
                if beyond.any():
                    base = np.where(beyond, lower, 0.0)  # no inf - inf for the others
                    turned = base + np.mod(free_q - base, TAU)
                    beyond &= turned <= upper
                    free_q = np.where(beyond, turned, free_q)
                    turns[active] += beyond
            q[active] = np.clip(free_q, lower, upper)
            touching[active] = np.any(q[active] != free_q, axis=1)
        return q, converged, score

    def _loop(self, positions, rotations, seeds, tolerances, max_iterations, max_restarts):
        """:meth:`kinplan.Robot.ik` target after target (arms :class:`BatchKinematics` cannot
        represent)."""
        robot = self.robot
        q = np.empty((len(positions), robot.nq))
        success = np.zeros(len(positions), dtype=bool)
        for k in range(len(positions)):
            target = positions[k] if rotations is None else pin.SE3(rotations[k], positions[k])
            result = robot.ik(
                target,
                q_seed=seeds[k],
                position_only=rotations is None,
                position_tolerance=tolerances[0],
                rotation_tolerance=tolerances[1],
                max_iterations=max_iterations,
                max_restarts=max_restarts,
            )
            q[k], success[k] = result.q, result.success
        return q, success
