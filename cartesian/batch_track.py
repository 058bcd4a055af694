"""Vectorised path following for arms with a vectorised closed form (UR family, planar 2R).

:func:`track` solves every sample of a timed path at once where the per-sample loop of
:func:`cartesian.follow._track` would answer the same: the branch of the first sample (the
configuration the loop starts from, :meth:`~cartesian.tracker.Tracker.start`) kept along the
path by the closed form's branch index, each joint unwrapped to stay continuous, then the tool
Jacobians, manipulability, joint velocities q̇ = J⁻¹ẋ and accelerations of all samples as stacks.

It answers only for clean paths. A vectorised monitor looks at every sample for what the loop
checks (joint limits, singularities, jumps, joint speeds and accelerations, the work cell) and
for what would make the loop's Newton steps end elsewhere (a poor prediction, a solution near a
singularity of the closed form, a large step); any sample that raises a flag, or comes within a
safety margin of one, makes :func:`track` return None, and the loop plans the whole path. So
every failing or borderline plan is today's, event and message alike, and a clean one has the
loop's samples with q equal to the loop's within its IK tolerance (the closed form is exact,
the loop within ``tolerance`` of the path).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from cartesian.timing import PathTiming
from cartesian.tracker import Targets, Tracker
from kinplan.cell import MotionCheck
from kinplan.ik import URIK, Planar2RIK, frobenius_tolerance
from kinplan.ik.screws import wrap_angle
from kinplan.trajectory.sampling import joint_speeds

#: Private switch for tests and benchmarks: False makes :func:`track` decline every path, so
#: the per-sample loop plans it.
ENABLED = True

TAU = 2.0 * np.pi
#: The loop's answers lie within its IK tolerance of the exact solution only when that is tight:
#: looser tolerances [m, rad] are left to the loop.
MAX_TOLERANCE = 1e-6
#: Largest distance [rad] between the loop's first configuration and a closed-form branch for
#: that branch to be the loop's, and smallest distance to the next branch (else ambiguous).
SAME_BRANCH, OTHER_BRANCH = 1e-4, 1e-2
#: Margin [rad] kept from the joint limits.
LIMIT_MARGIN = 1e-4
#: Relative margin kept above the singularity threshold and the rank floor, and below the
#: joint speed and acceleration limits.
RELATIVE_MARGIN = 1e-3
#: Manipulability, as a multiple of the rank floor (10⁻⁶ of the arm's reference), under which a
#: path is left to the loop whatever the threshold: that close to a singularity the loop's IK
#: tolerance (its q within 1e-7 m of the exact one) moves the manipulability by far more than
#: RELATIVE_MARGIN, so only the loop can say what the loop would report.
NEAR_SINGULAR = 1e3
#: Share of the jump tolerance that the unexplained joint step and the error of the loop's
#: prediction may reach.
JUMP_SHARE = 0.5
#: Largest joint step between samples [rad]: beyond it, unwrapping is ambiguous.
MAX_STEP = 0.5 * np.pi
#: Margin [m] kept from the cell's clearance (obstacles) and from contact (self pairs).
CLEARANCE_MARGIN = 1e-4
#: Largest multiplier of the stacked LU (:func:`_factor`) in its one row order.
MAX_MULTIPLIER = 8.0


@dataclass
class BatchTrack:
    """Every sample of a clean path, as the per-sample loop would give them.

    Attributes:
        q: Joint positions (N, nq) [rad].
        qd: Joint velocities (N, nq) [rad/s].
        qdd: Joint accelerations (N, nq) [rad/s²].
        tool_positions: Tool positions (FK of q) (N, 3) [m].
        manipulability: Manipulability of each sample (N,).
        peak_speed_ratio: Largest joint speed over its scaled limit.
        check: The work-cell check of the motion, or None without a cell.
    """

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tool_positions: np.ndarray
    manipulability: np.ndarray
    peak_speed_ratio: float
    check: MotionCheck | None


def track(
    tracker: Tracker,
    targets: Targets,
    timing: PathTiming,
    xd: np.ndarray,
    xdd: np.ndarray,
    seed: np.ndarray,
) -> BatchTrack | None:
    """Every sample of a timed path at once, or None when the per-sample loop must plan it.

    Args:
        tracker: The plan's tracker (arm, tolerances, thresholds, limits, cell).
        targets: The path's targets at the samples (:func:`~cartesian.tracker.path_targets`).
        timing: The samples' times [s] and path fractions.
        xd: Task velocities ẋ (N, r) of the samples.
        xdd: Task accelerations ẍ (N, r) of the samples.
        seed: The configuration the plan starts from [rad].

    Returns:
        The samples of a clean path (status ok), or None: no vectorised closed form for the
        task, or some sample raises (or comes near) a flag.
    """
    solver = _branch_solver(tracker)
    kinematics = tracker.robot.batch_solver.kinematics if solver is not None else None
    if solver is None or kinematics is None:
        return None
    positions, rotations = targets.positions, targets.rotations
    q0 = _first_configuration(tracker, targets, seed)
    raw = None if q0 is None else _branch_solutions(solver, positions, rotations, q0)
    q = None if raw is None or q0 is None else _branch_path(raw, q0)
    if q is None or not within_limits(tracker, q):
        return None
    tool, tool_rotations, jacobians = kinematics.fk_jacobian_rows(q)  # rows: (…, N)
    if not _on_path(tracker, tool, tool_rotations, positions, rotations):
        return None
    task = jacobians if len(tracker.rows) == 6 else jacobians[tracker.rows]  # (nq, nq, N)
    factors = _factor(task)
    if factors is None:
        return None
    manipulability = np.abs(factors.determinant)
    if not regular(tracker, manipulability):
        return None
    qd = _solve(factors, np.ascontiguousarray(xd.T)).T
    if not _continuous(tracker, timing.t, q, qd, task[:, :, 0], xdd[0]):
        return None
    peak = speed_peak(tracker, timing.t, q, qd)
    if peak is None:
        return None
    # q̈ = J⁻¹(ẍ − J̇q̇): Tracker.accelerations for a square task of full rank
    angular = bool(tracker.rows.max() >= 3)  # a position task needs the linear rows alone
    drift = _drift(jacobians, np.ascontiguousarray(qd.T), angular)[tracker.rows]
    qdd = _solve(factors, xdd.T - drift).T
    if not within_accelerations(tracker, qdd):
        return None
    free, check = cell_check(tracker, q)
    if not free:
        return None
    contiguous = np.ascontiguousarray
    return BatchTrack(q, contiguous(qd), contiguous(qdd), contiguous(tool.T), manipulability,
                      peak, check)  # fmt: skip


def _branch_solver(tracker: Tracker) -> URIK | Planar2RIK | None:
    """The arm's closed form when it solves this task for many poses at once, one branch at a
    time (UR family, a full pose) or every branch (planar 2R, a position), and the task
    Jacobian is square and of full rank; else None."""
    if not ENABLED:
        return None
    if max(tracker.tolerance, tracker.rotation_tolerance) > MAX_TOLERANCE:
        return None
    robot = tracker.robot
    solver = robot.closed_form_ik
    if isinstance(solver, URIK):
        if tracker.position_only or not solver.branch_many_available:
            return None
    elif not (isinstance(solver, Planar2RIK) and tracker.position_only):
        return None
    if not len(tracker.rows) == robot.nq == tracker.rank:
        return None
    return solver


def _first_configuration(tracker: Tracker, targets: Targets, seed: np.ndarray) -> np.ndarray | None:
    """The loop's first sample [rad] (:meth:`Tracker.start` from ``seed``), when it meets the
    tolerances without Newton steps; else None."""
    rotations = targets.rotations
    position, rotation = targets.positions[0], None if rotations is None else rotations[0]
    q0 = tracker.start(position, rotation, seed)
    floats = None if rotation is None else rotation.reshape(9).tolist()
    evaluation = tracker.evaluate(q0, position.tolist(), floats)
    return q0 if tracker.within(evaluation) else None


def _branch_of(raw: np.ndarray, q0: np.ndarray) -> int | None:
    """The row of ``raw`` (S, nq) (one pose's branches [rad], NaN rows: none) that is ``q0``
    (up to whole turns), when exactly one is that near."""
    distance = np.abs(wrap_angle(raw - q0)).max(axis=1)
    distance[np.isnan(distance)] = np.inf  # rows without a solution
    order = np.argsort(distance)
    if not distance[order[0]] <= SAME_BRANCH or distance[order[1]] <= OTHER_BRANCH:
        return None
    return int(order[0])


def _branch_solutions(
    solver: URIK | Planar2RIK,
    positions: np.ndarray,
    rotations: np.ndarray | None,
    q0: np.ndarray,
) -> np.ndarray | None:
    """The solutions (N, nq) [rad] (any 2π representative) of every target on the branch of
    ``q0`` at the first target, or None where that branch is ambiguous, a target has no
    solution on it or lies near a singularity of the closed form.

    The first pose's branches come in plain floats (``pose_branches``); every target is then
    solved on that branch alone in one vectorised pass (``branch_many``).
    """
    first = solver.pose_branches(positions[0], None if rotations is None else rotations[0])
    branch = None if first is None else _branch_of(first, q0)
    if branch is None:
        return None
    raw, edge = solver.branch_many(positions, rotations, branch)
    if edge.any() or np.isnan(raw).any():
        return None
    return raw


def _branch_path(raw: np.ndarray, q0: np.ndarray) -> np.ndarray | None:
    """The solutions ``raw`` (N, nq) [rad] of one branch, each joint continuous from ``q0``
    (the first row is ``q0`` itself), or None where a joint steps more than
    :data:`MAX_STEP` between samples (unwrapping would be ambiguous)."""
    steps = wrap_angle(np.diff(raw, axis=0, prepend=q0[None]))
    if not np.abs(steps[1:]).max(initial=0.0) <= MAX_STEP:
        return None
    unwrapped = q0 + np.cumsum(steps, axis=0)
    q = raw + TAU * np.round((unwrapped - raw) / TAU)
    q[0] = q0
    return q


def within_limits(tracker: Tracker, q: np.ndarray) -> bool:
    """Whether every sample keeps :data:`LIMIT_MARGIN` from the joint limits."""
    robot = tracker.robot
    return bool(np.all(q >= robot.lower + LIMIT_MARGIN) and np.all(q <= robot.upper - LIMIT_MARGIN))


def _on_path(
    tracker: Tracker,
    tool: np.ndarray,
    tool_rotations: np.ndarray,
    positions: np.ndarray,
    rotations: np.ndarray | None,
) -> bool:
    """Whether the tool poses (FK as rows: positions (3, N) [m], rotations (9, N)) meet the
    plan's tolerances at every target."""
    error = tool - positions.T
    if not np.einsum("in,in->n", error, error).max() <= tracker.tolerance**2:
        return False
    if rotations is None:
        return True
    difference = tool_rotations - rotations.reshape(len(positions), 9).T
    frobenius2 = np.einsum("in,in->n", difference, difference)
    return bool(frobenius2.max() <= frobenius_tolerance(tracker.rotation_tolerance))


def regular(tracker: Tracker, manipulability: np.ndarray) -> bool:
    """Whether every sample's manipulability is clear of the singularity threshold by
    :data:`RELATIVE_MARGIN` and of the rank floor by :data:`NEAR_SINGULAR`
    (:meth:`Tracker.is_singular`)."""
    floor = max(
        tracker.singular_threshold * (1.0 + RELATIVE_MARGIN), tracker.rank_floor * NEAR_SINGULAR
    )
    return bool(manipulability.min() > floor)


def _continuous(
    tracker: Tracker,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    first_task: np.ndarray,
    first_xdd: np.ndarray,
) -> bool:
    """Whether the loop would find these samples with no jump: every joint step explained by
    the rates (the loop's jump test, within :data:`JUMP_SHARE` of its tolerance), and every
    prediction the loop starts its Newton steps from that near the solution.

    Args:
        t: Sample times [s]; q, qd: joint positions and velocities (N, nq).
        first_task: The first sample's task Jacobian (r, nq); first_xdd: its task
            acceleration (r,).
    """
    if len(t) < 2:
        return True
    bound = JUMP_SHARE * tracker.jump_tolerance
    h = np.diff(t)[:, None]
    unexplained = np.abs(np.diff(q, axis=0) - 0.5 * h * (qd[1:] + qd[:-1]))
    if not unexplained.max() <= bound:
        return False
    # the loop's predictions: Taylor at the second sample (q̈ = J⁻¹ẍ when starting at rest),
    # two-step Adams–Bashforth after (cartesian.tracker.adams_bashforth_weights)
    qdd_first = np.linalg.solve(first_task, first_xdd) if not qd[0].any() else 0.0
    guess = q[0] + qd[0] * h[0] + 0.5 * h[0] ** 2 * qdd_first
    if not np.abs(guess - q[1]).max() <= bound:
        return False
    ratio = 0.5 * h[1:] / h[:-1]
    guesses = q[1:-1] + qd[1:-1] * (h[1:] * (1.0 + ratio)) - qd[:-2] * (h[1:] * ratio)
    return bool(np.abs(guesses - q[2:]).max(initial=0.0) <= bound)


def within_accelerations(tracker: Tracker, qdd: np.ndarray) -> bool:
    """Whether every limited joint acceleration is below its limit by :data:`RELATIVE_MARGIN`."""
    limit = tracker.acceleration_limit
    if not np.isfinite(limit).any() or not len(qdd):
        return True
    return bool((np.abs(qdd) / limit).max() < 1.0 - RELATIVE_MARGIN)


def speed_peak(tracker: Tracker, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> float | None:
    """The largest joint speed over its scaled limit (the rates and the mean speeds between
    samples, :func:`kinplan.sampling.joint_speeds`), or None when it is not below the limits
    by :data:`RELATIVE_MARGIN`."""
    peak = float((joint_speeds(q, qd, t) / tracker.speed_limit).max(initial=0.0))
    return peak if peak < 1.0 - RELATIVE_MARGIN else None


def cell_check(tracker: Tracker, q: np.ndarray) -> tuple[bool, MotionCheck | None]:
    """(whether the motion is clear of the cell by :data:`CLEARANCE_MARGIN`, its work-cell
    check); (True, None) without a cell."""
    if tracker.cell is None:
        return True, None
    check = tracker.cell.check_motion(q, tracker.clearance)
    return clear(check, tracker.clearance), check


def clear(check: MotionCheck, clearance: float) -> bool:
    """Whether a cell check passed with :data:`CLEARANCE_MARGIN` to spare at every sample."""
    if check.index is not None:
        return False
    obstacle = float(np.min(check.obstacle_distances, initial=np.inf))
    own = float(np.min(check.self_distances, initial=np.inf))
    return obstacle > clearance + CLEARANCE_MARGIN and own > CLEARANCE_MARGIN


# ---------------------------------------------------------------------------- stacked algebra
@dataclass
class Factors:
    """LU factors of a stack of square matrices as rows (n, n, N), one row order for all.

    Attributes:
        order: The row order (partial pivoting of the first matrix).
        lu: L (unit, below the diagonal) and U of the reordered matrices, (n, n, N).
        determinant: Their determinants (N,).
    """

    order: np.ndarray
    lu: np.ndarray
    determinant: np.ndarray


def _factor(matrices: np.ndarray) -> Factors | None:
    """LU factors of square matrices stored as rows (n, n, N), vectorised over N.

    Gaussian elimination in one row order for every matrix, the one partial pivoting gives the
    first (the matrices of a clean path change smoothly): with its two solves about three times
    faster than numpy's per-matrix LAPACK calls (det, solve, solve) for 6×6. None when a
    multiplier exceeds :data:`MAX_MULTIPLIER` somewhere (the order does not suit that matrix:
    the growth of rounding errors would not be bounded), or a pivot is zero.
    """
    n = len(matrices)
    order = _pivot_order(matrices[:, :, 0])
    lu = matrices[order]  # a copy
    with np.errstate(divide="ignore", invalid="ignore"):  # a zero pivot: inf or NaN, refused
        for k in range(n - 1):
            lu[k + 1 :, k] /= lu[k, k]
            lu[k + 1 :, k + 1 :] -= lu[k + 1 :, k, None] * lu[k, None, k + 1 :]
        multipliers = lu[_below_diagonal(n)]
        if not np.abs(multipliers).max(initial=0.0) <= MAX_MULTIPLIER:
            return None
    diagonal = np.arange(n)
    return Factors(order, lu, _permutation_sign(order) * np.prod(lu[diagonal, diagonal], axis=0))


@functools.cache
def _below_diagonal(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The indices of the entries below the diagonal of an n × n matrix (``np.tril_indices``)."""
    return np.tril_indices(n, -1)


def _permutation_sign(order: np.ndarray) -> float:
    """The sign (±1) of a permutation (the determinant of its permutation matrix): −1 to the
    number of inversions."""
    values = order.tolist()
    inversions = sum(a > b for i, a in enumerate(values) for b in values[i + 1 :])
    return -1.0 if inversions % 2 else 1.0


def _pivot_order(matrix: np.ndarray) -> np.ndarray:
    """The row order of partial pivoting (largest magnitude first, the first of equal ones) of
    one matrix (n, n), in plain floats (a few hundred operations: numpy's per-call cost would
    dominate)."""
    rows = np.asarray(matrix, dtype=float).tolist()
    n = len(rows)
    order = list(range(n))
    for k in range(n - 1):
        p = max(range(k, n), key=lambda i: abs(rows[i][k]))
        rows[k], rows[p] = rows[p], rows[k]
        order[k], order[p] = order[p], order[k]
        pivot_row = rows[k]
        if pivot_row[k] != 0.0:
            for i in range(k + 1, n):
                multiplier = rows[i][k] / pivot_row[k]
                rows[i] = [x - multiplier * y for x, y in zip(rows[i], pivot_row, strict=True)]
    return np.array(order)


def _solve(factors: Factors, b: np.ndarray) -> np.ndarray:
    """x with A x = b for every matrix A of ``factors``; b and x as rows (n, N)."""
    lu = factors.lu
    n = len(lu)
    x = b[factors.order]  # a copy
    for i in range(1, n):  # L y = P b
        x[i] -= np.einsum("kn,kn->n", lu[i, :i], x[:i])
    for i in range(n - 1, -1, -1):  # U x = y
        if i < n - 1:
            x[i] -= np.einsum("kn,kn->n", lu[i, i + 1 :], x[i + 1 :])
        x[i] /= lu[i, i]
    return x


def _drift(jacobians: np.ndarray, qd: np.ndarray, angular: bool = True) -> np.ndarray:
    """J̇q̇ (6, N) of serial-chain tool Jacobians (6, nq, N) at joint velocities (nq, N), as rows
    (its linear rows (3, N) alone unless ``angular``).

    :func:`kinplan.robot.jacobian_time_variation` times q̇ without forming J̇: with
    w_i, v_i the angular and linear rows of column i, ω_i = Σ_(j<i) q̇_j w_j and
    σ_i = Σ_(j≥i) q̇_j v_j, J̇q̇ = Σ_i [ω_i × q̇_i v_i + q̇_i w_i × σ_i ; ω_i × q̇_i w_i]
    [m/s², rad/s²].
    """
    v_qd = jacobians[:3] * qd  # (3, nq, N)
    w_qd = jacobians[3:] * qd
    # running sums over the columns (a loop over the few columns: numpy's cumsum along a
    # middle axis is slow)
    omega, sigma = np.empty_like(w_qd), np.empty_like(v_qd)
    omega[:, 0], sigma[:, -1] = 0.0, v_qd[:, -1]
    for i in range(1, w_qd.shape[1]):
        omega[:, i] = omega[:, i - 1] + w_qd[:, i - 1]
        sigma[:, -1 - i] = sigma[:, -i] + v_qd[:, -1 - i]
    linear = _summed_cross(omega, v_qd) + _summed_cross(w_qd, sigma)
    return np.concatenate((linear, _summed_cross(omega, w_qd))) if angular else linear


def _summed_cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Σ over the columns of the cross products of 3-vectors stored as rows (3, n, N): (3, N)."""
    return np.stack(
        (
            (a[1] * b[2] - a[2] * b[1]).sum(axis=0),
            (a[2] * b[0] - a[0] * b[2]).sum(axis=0),
            (a[0] * b[1] - a[1] * b[0]).sum(axis=0),
        )
    )
