"""A lean per-sample loop for arms without a vectorised closed form (panda, numerical arms).

:func:`track` runs the IK of :func:`cartesian.follow._track` sample by sample — the same
prediction (Taylor at the second sample, two-step Adams–Bashforth on q̇ after), the same
kinematics pass and acceptance test, the same Newton steps — but nothing else per sample: the
joint rates q̇ = J⁺ẋ the next prediction needs come from one small solve on the sample's
Jacobian, and every other monitoring quantity — joint limits, manipulability, the jump test,
joint speeds and accelerations, the work cell — is computed after the loop, stacked over all
samples. On serial arms of revolute joints, runs of samples (and of a trace's points) are
solved in compiled code (:mod:`cartesian.lean_kernel`); the points it leaves are solved here.

Like :mod:`cartesian.batch_track` it answers only for clean paths: a sample whose Newton steps
fail, or that raises a flag or comes within the same safety margins of one
(:data:`~cartesian.batch_track.LIMIT_MARGIN`, :data:`~cartesian.batch_track.RELATIVE_MARGIN`,
:data:`~cartesian.batch_track.JUMP_SHARE`, :data:`~cartesian.batch_track.CLEARANCE_MARGIN`),
makes :func:`track` return None, and the full loop plans the whole path: every failing or
borderline plan is today's, event and message alike. A clean one has the loop's samples, and
q equal to the loop's within its IK tolerance (the same equations solved from the same
predictions, up to the rounding of the rates).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import eigenpy
import numpy as np

from cartesian.batch_track import (
    JUMP_SHARE,
    BatchTrack,
    cell_check,
    regular,
    speed_peak,
    within_accelerations,
    within_limits,
)
from cartesian.paths import Path
from cartesian.timing import PathTiming
from cartesian.tracker import (
    Targets,
    Tracker,
    adams_bashforth_weights,
    path_targets,
    pseudo_inverses,
)
from kinplan.model.robot import manipulability_of

if TYPE_CHECKING:
    from cartesian.lean_kernel import Run

#: Private switch for tests and benchmarks: False makes :func:`track` decline every path, so
#: the full per-sample loop plans it.
ENABLED = True


def track(
    tracker: Tracker,
    targets: Targets,
    timing: PathTiming,
    xd: np.ndarray,
    xdd: np.ndarray,
    seed: np.ndarray,
) -> BatchTrack | None:
    """Every sample of a timed path by the lean loop, or None when the full loop must plan it.

    Args:
        tracker: The plan's tracker (arm, tolerances, thresholds, limits, cell).
        targets: The path's targets at the samples (:func:`~cartesian.tracker.path_targets`).
        timing: The samples' times [s] and path fractions.
        xd: Task velocities ẋ (N, r) of the samples.
        xdd: Task accelerations ẍ (N, r) of the samples.
        seed: The configuration the plan starts from [rad].

    Returns:
        The samples of a clean path (status ok), or None: a task of deficient rank, a Newton
        pass that fails, or some sample raises (or comes near) a flag.
    """
    if not ENABLED or not _full_rank(tracker):
        return None
    solved = _solve_path(tracker, targets, timing.t, xd, xdd, seed)
    if solved is None:
        return None
    return _monitor(tracker, *solved, xd, xdd)


def _full_rank(tracker: Tracker) -> bool:
    """Whether the task Jacobian has full rank at a generic configuration (else the loop's
    pseudo-inverse by SVD: left to it)."""
    return tracker.rank == min(len(tracker.rows), tracker.robot.nq)


def _solve_path(
    tracker: Tracker,
    targets: Targets,
    t: np.ndarray,
    xd: np.ndarray,
    xdd: np.ndarray,
    seed: np.ndarray,
) -> tuple[Run, list[int]] | None:
    """The loop's IK of every sample, as a :class:`~cartesian.lean_kernel.Run` (q, rates
    q̇ = J⁺ẋ, tool Jacobians and positions; the task pseudo-inverses of the samples the
    compiled loop solved) and the samples solved here in Python; None as soon as a Newton
    pass fails (the loop's longer search and its events are the loop's to make).

    Runs of samples go to the compiled loop (:mod:`cartesian.lean_kernel`) when the arm has
    one; the first two samples (the start and the Taylor step), and any sample the compiled
    loop leaves, are solved here.
    """
    from cartesian import lean_kernel  # numba loads on first use, not with the package

    n, nq = len(t), tracker.robot.nq
    run = lean_kernel.Run.empty(t, xd, targets.positions, targets.rotations, nq)
    position_floats = targets.positions.tolist()
    rotations = [None] * n if targets.rotations is None else list(targets.rotations)
    rotation_floats = (
        [None] * n if targets.rotations is None else targets.rotations.reshape(n, 9).tolist()
    )
    steps = np.diff(t, prepend=0.0).tolist()  # h_k = t_k − t_(k−1) [s]
    weights = adams_bashforth_weights(np.diff(t))
    rate = _rates(tracker)
    evaluate, within, solve = tracker.evaluate, tracker.within, tracker.solve
    kernel = lean_kernel.kernel_for(tracker.robot, tracker.rows) if n > 2 else None
    tolerances = (tracker.tolerance, tracker.rotation_tolerance)
    q, rates = run.q, run.rates
    qdd_first = np.zeros(nq)
    solved_here: list[int] = []
    k = 0
    while k < n:
        if kernel is not None and k >= 2:
            k = lean_kernel.advance(kernel, run, k, tolerances)
            if k == n:
                break
        if k == 0:
            guess = tracker.start(targets.positions[0], rotations[0], seed)
        elif k == 1:  # Taylor, with q̈ = J⁺ẍ when starting at rest (as the loop)
            guess = q[0] + rates[0] * steps[1] + (0.5 * steps[1] ** 2) * qdd_first
        else:  # two-step Adams–Bashforth on q̇ (as the loop)
            a, b = weights[k]
            guess = q[k - 1] + rates[k - 1] * a + rates[k - 2] * b
        evaluation = evaluate(guess, position_floats[k], rotation_floats[k])
        if not within(evaluation):
            _, ok, _, _, _, evaluation = solve(
                guess, targets.positions[k], rotations[k], evaluated=evaluation
            )
            if not ok:
                return None
        J = evaluation.jacobian
        q[k], run.jacobians[k], run.tools[k] = evaluation.q, J, evaluation.tool_position
        if k == 0:  # the loop's own rates at the first sample (its test for rest is exact)
            tracker.factor(J)
            rates[0] = tracker.rates(xd[0])
            if not rates[0].any():
                qdd_first = tracker.rates(xdd[0])
        else:
            rates[k] = rate(J, xd[k])
        solved_here.append(k)
        k += 1
    return run, solved_here


def _monitor(
    tracker: Tracker,
    run: Run,
    solved_here: list[int],
    xd: np.ndarray,
    xdd: np.ndarray,
) -> BatchTrack | None:
    """The loop's checks of every sample at once, each with its safety margin: the samples
    as a :class:`~cartesian.batch_track.BatchTrack`, or None when any is flagged or near it.
    The task pseudo-inverses of the samples ``solved_here`` (in Python) are computed here,
    once the manipulability shows every sample regular."""
    t, q, qd, jacobians = run.grid, run.q, run.rates, run.jacobians
    if not within_limits(tracker, q):
        return None
    task = jacobians if len(tracker.rows) == 6 else jacobians[:, tracker.rows]
    manipulability = np.asarray(manipulability_of(task, tracker.rank))
    if not regular(tracker, manipulability):  # before the pseudo-inverses: a singular J has none
        return None
    pinvs = run.pinvs
    if solved_here:
        pinvs[solved_here] = pseudo_inverses(task[solved_here], tracker.rank)
    if len(t) > 1:  # the loop's jump test (at every sample, not only the corrected ones)
        h = np.diff(t)[:, None]
        unexplained = np.abs(np.diff(q, axis=0) - 0.5 * h * (qd[1:] + qd[:-1]))
        if not unexplained.max() <= JUMP_SHARE * tracker.jump_tolerance:
            return None
    peak = speed_peak(tracker, t, q, qd)
    if peak is None:
        return None
    qdd = tracker.accelerations(q, jacobians, qd, xdd, pinvs)
    if not within_accelerations(tracker, qdd):
        return None
    free, check = cell_check(tracker, q)
    if not free:
        return None
    return BatchTrack(q, qd, qdd, run.tools, manipulability, peak, check)


# ---------------------------------------------------------------------------- geometric trace
def trace(
    tracker: Tracker,
    path: Path,
    s: np.ndarray,
    seed: np.ndarray,
    max_step: float,
    min_interval: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The geometric trace of :func:`cartesian.geometry.trace_geometry` by the lean loop, or
    None when the exact trace must make it.

    The same points (the fractions ``s``, bisected where a joint steps more than ``max_step``
    [rad] or the Newton steps fail, down to intervals of ``min_interval``), the same
    predictions and Newton steps; per point only the rates dq/ds = J⁺ dx/ds the next prediction
    needs (the arithmetic of :meth:`~cartesian.tracker.Tracker.rates`). Joint limits,
    singularities and jumps are checked after, stacked, with the margins of :func:`track`.

    Returns:
        (fractions (M,), q (M, nq), dq/ds (M, nq), tool Jacobians (M, 6, nq)) of a path with no
        event, or None: a task of deficient rank, a point the Newton steps cannot reach, or a
        point flagged or near a flag.
    """
    if not ENABLED or not _full_rank(tracker):
        return None
    from cartesian import lean_kernel  # numba loads on first use, not with the package

    kernel = lean_kernel.kernel_for(tracker.robot, tracker.rows)
    rate = _rates(tracker)
    evaluate, within, solve = tracker.evaluate, tracker.within, tracker.solve
    pending = _points(tracker, path, s)[::-1]  # the next point to solve at the end
    solved_s: list[float] = []
    qs: list[np.ndarray] = []
    dqs: list[np.ndarray] = []
    jacobians: list[np.ndarray] = []
    q_prev: np.ndarray | None = None
    stuck_at = -1  # the compiled loop could not solve the next point with this many solved
    while pending:
        if kernel is not None and len(qs) >= 2 and len(qs) != stuck_at:
            # the pending points, compiled, while each is clean (a point it leaves, and the
            # bisections there, are solved here before it is tried again)
            run = _pending_run(tracker, pending, solved_s, qs, dqs)
            done = lean_kernel.advance(
                kernel, run, 2, (tracker.tolerance, tracker.rotation_tolerance), max_step
            )
            if done == 2:
                stuck_at = len(qs)
            for j in range(2, done):
                pending.pop()
                solved_s.append(float(run.grid[j]))
                qs.append(run.q[j])
                dqs.append(run.rates[j])
                jacobians.append(run.jacobians[j])
            if not pending:
                break
            q_prev = qs[-1]
        sk, position, rotation, dx, floats = pending[-1]
        if q_prev is None:
            guess = tracker.start(position, rotation, seed)
        elif len(dqs) > 1:  # second order: the rate's change over the last step
            h, h_prev = sk - solved_s[-1], solved_s[-1] - solved_s[-2]
            guess = q_prev + dqs[-1] * h + (0.5 * h * h / h_prev) * (dqs[-1] - dqs[-2])
        else:
            guess = q_prev + dqs[-1] * (sk - solved_s[-1])
        evaluation, ok = evaluate(guess, *floats), True
        if not within(evaluation):
            *_, evaluation = solve(guess, position, rotation, evaluated=evaluation)
            ok = within(evaluation)
        q = evaluation.q
        if q_prev is not None and sk - solved_s[-1] > min_interval:
            if not ok or abs(q - q_prev).max() > max_step:
                if not np.isfinite(guess).all():  # rates past a singularity: the exact trace's
                    return None
                pending += _points(tracker, path, np.array([0.5 * (sk + solved_s[-1])]))
                continue
        if not ok:  # the exact trace's longer search, and its events
            return None
        J = evaluation.jacobian
        pending.pop()
        solved_s.append(sk)
        qs.append(q)
        dqs.append(rate(J, dx))
        jacobians.append(J)
        q_prev = q
    nq = tracker.robot.nq
    fractions = np.array(solved_s)
    q_out, dq_out = np.array(qs).reshape(-1, nq), np.array(dqs).reshape(-1, nq)
    stack = np.array(jacobians).reshape(-1, 6, nq)
    if not within_limits(tracker, q_out):
        return None
    task = stack if len(tracker.rows) == 6 else stack[:, tracker.rows]
    if not regular(tracker, np.asarray(manipulability_of(task, tracker.rank))):
        return None
    h = np.diff(fractions)[:, None]
    unexplained = np.abs(np.diff(q_out, axis=0) - 0.5 * h * (dq_out[1:] + dq_out[:-1]))
    if not unexplained.max(initial=0.0) <= JUMP_SHARE * tracker.jump_tolerance:
        return None
    return fractions, q_out, dq_out, stack


def _pending_run(
    tracker: Tracker,
    pending: list[tuple],
    solved_s: list[float],
    qs: list[np.ndarray],
    dqs: list[np.ndarray],
) -> Run:
    """The pending points of a trace (in order), after its last two solved ones, as a
    :class:`~cartesian.lean_kernel.Run` for the compiled loop (rows 0 and 1: those two)."""
    from cartesian.lean_kernel import Run

    points = pending[::-1]
    nq = tracker.robot.nq
    grid = np.array([solved_s[-2], solved_s[-1], *(point[0] for point in points)])
    positions = np.array([point[1] for point in points]).reshape(-1, 3)
    velocities = np.array([point[3] for point in points]).reshape(len(points), -1)
    rotations = None
    if points[0][2] is not None:
        rotations = np.concatenate([np.zeros((2, 3, 3)), [point[2] for point in points]])
    run = Run.empty(
        grid,
        np.concatenate([np.zeros((2, velocities.shape[1])), velocities]),
        np.concatenate([np.zeros((2, 3)), positions]),
        rotations,
        nq,
    )
    run.q[:2] = qs[-2:]
    run.rates[:2] = dqs[-2:]
    return run


def _points(tracker: Tracker, path: Path, s: np.ndarray) -> list[tuple]:
    """(s, position, rotation or None, dx/ds, (position, rotation) as floats) of each path
    fraction in ``s``."""
    targets = path_targets(path, s, tracker.position_only, tracker.rows)
    n = len(s)
    rotations = [None] * n if targets.rotations is None else list(targets.rotations)
    floats = zip(
        targets.positions.tolist(),
        [None] * n if targets.rotations is None else targets.rotations.reshape(n, 9).tolist(),
    )
    return list(zip(s.tolist(), targets.positions, rotations, targets.rate, floats))


def _rates(tracker: Tracker):
    """rate(J, b) -> J⁺ b for a tool Jacobian J (6, nq) and a task vector b (r,), or (J⁺ B)ᵀ
    (k, nq) for k task vectors B (r, k): the solution (square task), least squares (tall) or
    minimum norm (wide), from one LU factorisation of J or of its smaller Gram matrix — the
    arithmetic of :meth:`~cartesian.tracker.Tracker.factor` and
    :meth:`~cartesian.tracker.Tracker.rates` without the manipulability."""
    rows = tracker.rows
    every = len(rows) == 6
    wide = len(rows) < tracker.robot.nq
    square = len(rows) == tracker.robot.nq
    lu = eigenpy.PartialPivLU

    def rate(J: np.ndarray, b: np.ndarray) -> np.ndarray:
        task = J if every else J[rows]
        if wide:
            y = lu(task.dot(task.T)).solve(b)
            return (y if b.ndim == 1 else y.T).dot(task)
        if square:
            x = lu(task).solve(b)
        else:
            x = lu(task.T.dot(task)).solve(b.dot(task) if b.ndim == 1 else task.T.dot(b))
        return x if b.ndim == 1 else x.T

    return rate
