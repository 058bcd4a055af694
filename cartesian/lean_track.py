"""A lean per-sample loop for arms without a vectorised closed form (panda, numerical arms).

:func:`track` runs the IK of :func:`cartesian.follow._track` sample by sample — the same
prediction (Taylor at the second sample, two-step Adams–Bashforth on q̇ after), the same
kinematics pass and acceptance test, the same Newton steps — but nothing else per sample: the
joint rates the next prediction needs come from one small solve on the sample's Jacobian (both
scaled rates the two next predictions use, in one right-hand side), and every monitoring
quantity — joint limits, manipulability, q̇ = J⁺ẋ, the jump test, joint speeds and
accelerations, the work cell — is computed after the loop, stacked over all samples.

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
    matvec,
    path_targets,
    pseudo_inverses,
)
from kinplan.robot import manipulability_of

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
    return _monitor(tracker, timing.t, *solved, xd, xdd)


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
) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[np.ndarray, list[int]]] | None:
    """The loop's IK of every sample: (q (N, nq), tool Jacobians (N, 6, nq), tool positions
    (N, 3), (task pseudo-inverses J⁺ (N, nq, r) of the compiled loop's samples, the samples
    solved in Python, whose rows are left to fill)); None as soon as a Newton pass fails (the
    loop's longer search and its events are the loop's to make). Runs of samples whose
    predictions meet the tolerances go to the compiled loop (:mod:`cartesian.lean_kernel`)
    when the arm has one."""
    n, nq = len(t), tracker.robot.nq
    positions, position_floats = targets.positions, targets.positions.tolist()
    rotations = [None] * n if targets.rotations is None else list(targets.rotations)
    rotation_floats = (
        [None] * n if targets.rotations is None else targets.rotations.reshape(n, 9).tolist()
    )
    steps = np.diff(t, prepend=0.0).tolist()  # h_k = t_k − t_(k−1) [s]
    # sample j's rates serve two predictions: a_(j+1) q̇_j at sample j + 1 and b_(j+2) q̇_j at
    # sample j + 2 (Adams–Bashforth weights): one solve with both scaled ẋ_j as columns
    weights = np.array(adams_bashforth_weights(np.diff(t))).reshape(-1, 2)
    scales = np.zeros((n, 2))
    scales[1 : n - 1, 0] = weights[2:, 0]
    scales[: n - 2, 1] = weights[2:, 1]
    columns = np.ascontiguousarray(xd[:, :, None] * scales[:, None, :])  # (n, r, 2)
    rates = _rates(tracker)
    evaluate, within, solve = tracker.evaluate, tracker.within, tracker.solve
    q = np.empty((n, nq))
    jacobians = np.empty((n, 6, nq))
    tools = np.empty((n, 3))
    pinvs = np.empty((n, nq, len(tracker.rows)))  # the compiled loop's; the others' after
    solved_here: list[int] = []  # the samples solved in Python
    ahead = np.zeros((n, nq))  # a_(j+1) q̇_j
    behind = np.zeros((n, nq))  # b_(j+2) q̇_j
    from cartesian import lean_kernel  # numba loads on first use, not with the package

    kernel = lean_kernel.kernel_for(tracker.robot, tracker.rows) if n > 2 else None
    qd_first = qdd_first = np.zeros(nq)
    k = 0
    while k < n:
        if kernel is not None and k >= 2:  # the samples whose predictions meet the tolerances
            k = lean_kernel.advance(
                kernel, k, q, ahead, behind, columns, positions, targets.rotations,
                tracker.tolerances2, jacobians, tools, pinvs,
            )  # fmt: skip
            if k == n:
                break
        if k == 0:
            guess = tracker.start(positions[0], rotations[0], seed)
        elif k == 1:  # Taylor, with q̈ = J⁺ẍ when starting at rest (as the loop)
            guess = q[0] + qd_first * steps[1] + (0.5 * steps[1] ** 2) * qdd_first
        else:
            guess = q[k - 1] + ahead[k - 1] + behind[k - 2]
        evaluation = evaluate(guess, position_floats[k], rotation_floats[k])
        if not within(evaluation):
            _, ok, _, _, _, evaluation = solve(
                guess, positions[k], rotations[k], evaluated=evaluation
            )
            if not ok:
                return None
        J = evaluation.jacobian
        q[k], jacobians[k], tools[k] = evaluation.q, J, evaluation.tool_position
        solved_here.append(k)
        if k == 0:  # the loop's own rates at the first sample (its test for rest is exact)
            tracker.factor(J)
            qd_first = tracker.rates(xd[0])
            if not qd_first.any():
                qdd_first = tracker.rates(xdd[0])
            ahead[0] = qd_first  # unused: sample 1 is predicted by Taylor
            behind[0] = qd_first * scales[0, 1]
        else:
            ahead[k], behind[k] = rates(J, columns[k])
        k += 1
    return q, jacobians, tools, (pinvs, solved_here)


def _monitor(
    tracker: Tracker,
    t: np.ndarray,
    q: np.ndarray,
    jacobians: np.ndarray,
    tool: np.ndarray,
    pseudo: tuple[np.ndarray, list[int]],
    xd: np.ndarray,
    xdd: np.ndarray,
) -> BatchTrack | None:
    """The loop's checks of every sample at once, each with its safety margin: the samples
    as a :class:`~cartesian.batch_track.BatchTrack`, or None when any is flagged or near it.
    ``pseudo``: the task pseudo-inverses (N, nq, r) the compiled loop computed, and the
    samples solved in Python (their rows are computed here, once the manipulability shows
    every sample regular)."""
    if not within_limits(tracker, q):
        return None
    task = jacobians if len(tracker.rows) == 6 else jacobians[:, tracker.rows]
    manipulability = np.asarray(manipulability_of(task, tracker.rank))
    if not regular(tracker, manipulability):  # before the rates: a singular J has none
        return None
    pinvs, solved_here = pseudo
    if solved_here:
        pinvs[solved_here] = pseudo_inverses(task[solved_here], tracker.rank)
    qd = matvec(pinvs, xd)
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
    return BatchTrack(q, qd, qdd, tool, manipulability, peak, check)


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
    rate = _rates(tracker)
    evaluate, within, solve = tracker.evaluate, tracker.within, tracker.solve
    pending = _points(tracker, path, s)[::-1]  # the next point to solve at the end
    solved_s: list[float] = []
    qs: list[np.ndarray] = []
    dqs: list[np.ndarray] = []
    jacobians: list[np.ndarray] = []
    q_prev: np.ndarray | None = None
    while pending:
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
