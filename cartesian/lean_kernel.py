"""The lean loop's per-point work compiled (numba), for serial arms of revolute joints.

:mod:`cartesian.lean_track` predicts each point's configuration from the two before it
(Adams–Bashforth on the joint rates), corrects it by Newton steps when the tool misses the
tolerances there, and keeps the point's joint rates for the next predictions — sample by
sample in time for a plan, point by point in the path fraction for a geometric trace. In Python
that is a kinematics pass through Pinocchio and a small solve per point, about 12 µs on a
7-joint arm: the loop, not the arithmetic, is the cost, and no numpy formulation removes it
(each point depends on the one before). :func:`advance` runs those points in compiled code:
the kinematics as a product of exponentials of the joint screws at q = 0
(:func:`kinplan.ik.screws.screws_at_zero`, checked against Pinocchio's tool pose and Jacobian
before use), the Newton steps of :meth:`cartesian.tracker.Tracker.solve` (those of
:meth:`kinplan.ik.IKSolver.descend` without limits), the rates and task pseudo-inverses by a
small LU. It stops at the first point it cannot solve cleanly — failed Newton steps, a joint
step beyond a trace's bisection threshold, a rotation error beyond a quarter turn — which the
Python loop then solves (with its events, bisections and fallbacks), and is called again after
it.

These are the Python loop's equations in another rounding; plans and traces agree with the
Python loop's within its IK tolerance (``tests/cartesian/test_lean_kernel.py``).

numba is imported with this module, which :mod:`cartesian.lean_track` imports on first use;
without it (or with :data:`ENABLED` False, or the environment variable ``KINPLAN_JIT=0``)
:func:`kernel_for` returns None and the Python loop solves every point. Compiled functions are
cached on disk (numba's ``cache=True``: next to this module, or in the user's cache directory
when the package folder is read-only).
"""

from __future__ import annotations

import math
import os
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from cartesian.tracker import NEWTON_ITERATIONS
from kinplan.compiled import jit, numba, product
from kinplan.compiled import screw_kinematics as kinematics
from kinplan.ik.numeric import (
    DAMPING_FLOOR,
    DAMPING_GAIN,
    MAX_STEP,
    STALL_ITERATIONS,
    frobenius_tolerance,
)
from kinplan.ik.screws import screws_at_zero

if TYPE_CHECKING:
    from kinplan.model.robot import Robot

#: Private switch for tests and benchmarks: False makes :func:`kernel_for` return None (the
#: Python loop runs every sample).
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"

#: Largest difference between the screw kinematics and Pinocchio's tool pose and Jacobian
#: (entries, [m] or [-]) on the check configurations for the kernel to be used (both are
#: exact up to rounding: ~1e-15).
AGREEMENT = 1e-12

#: The rotations passed for a position-only task (never read).
_NO_ROTATIONS = np.zeros((1, 3, 3))

#: Newton steps of :meth:`cartesian.tracker.Tracker.solve` (IKSolver.descend's constants and
#: the tracker's 12 iterations): damping gain, damping floor, step cap, iterations, patience.
_NEWTON = np.array(
    [DAMPING_GAIN, DAMPING_FLOOR, MAX_STEP, float(NEWTON_ITERATIONS), float(STALL_ITERATIONS)]
)

#: Task shapes: wide (fewer task rows than joints: minimum-norm rates), square, tall.
WIDE, SQUARE, TALL = -1, 0, 1


#: The checked screws of each robot seen (or None), kept while the robot lives.
_SCREWS: weakref.WeakKeyDictionary[Robot, tuple[np.ndarray, np.ndarray, np.ndarray] | None] = (
    weakref.WeakKeyDictionary()
)


@dataclass(frozen=True)
class Kernel:
    """The compiled loop of one arm and task.

    Attributes:
        directions: Unit joint axes at q = 0 (nq, 3), world frame.
        points: A point of each axis at q = 0 (nq, 3) [m].
        tool: Tool pose at q = 0 (4, 4).
        rows: The task rows of the 6-D tool twist (r,).
        shape: :data:`WIDE`, :data:`SQUARE` or :data:`TALL`.
    """

    directions: np.ndarray
    points: np.ndarray
    tool: np.ndarray
    rows: np.ndarray
    shape: int


def kernel_for(robot: Robot, rows: np.ndarray) -> Kernel | None:
    """The compiled loop for ``robot`` and the task ``rows`` of the tool twist (a tracker's
    ``rows``), or None (numba missing or switched off, an arm that is not a serial chain of
    revolute joints, or screws that disagree with Pinocchio)."""
    if not ENABLED:
        return None
    if robot not in _SCREWS:
        _SCREWS[robot] = checked_screws(robot)
    cached = _SCREWS[robot]
    if cached is None:
        return None
    rows = np.asarray(rows, dtype=np.int64)
    shape = (len(rows) > robot.nq) - (len(rows) < robot.nq)
    return Kernel(*cached, rows, shape)


def checked_screws(robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(directions (nq, 3), points (nq, 3) [m], tool pose at q = 0 (4, 4)) of the arm's joint
    screws in the world frame, when :func:`kinematics` with them matches Pinocchio's tool pose
    and Jacobian within :data:`AGREEMENT` on three seeded random configurations; else None
    (not a serial chain of revolute joints, or numba missing)."""
    screws = screws_at_zero(robot)
    if screws is None:
        return None
    directions = np.ascontiguousarray(screws.directions, dtype=float)
    points = np.ascontiguousarray(screws.points, dtype=float)
    tool = np.ascontiguousarray(screws.tool.homogeneous, dtype=float)
    if numba is None:
        return None
    rng = np.random.default_rng(0)
    low = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    high = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    for q in rng.uniform(low, high, size=(3, robot.nq)):
        pose, jacobian = np.empty((4, 4)), np.empty((6, robot.nq))
        kinematics(q, directions, points, tool, pose, jacobian)
        if not (
            np.abs(pose - robot.fk(q).homogeneous).max() <= AGREEMENT
            and np.abs(jacobian - robot.jacobian(q)).max() <= AGREEMENT
        ):
            return None
    return directions, points, tool


@dataclass
class Run:
    """The arrays one run of the compiled loop reads and writes, N points along a path.

    Attributes:
        grid: The points' times [s] or path fractions (N,).
        velocities: Task velocities per unit of the grid (N, r).
        positions: Target tool positions (N, 3) [m].
        rotations: Target tool rotations (N, 3, 3), or None (position only).
        q: Configurations (N, nq) [rad].
        rates: Joint rates J⁺ v per unit of the grid (N, nq).
        jacobians: Tool Jacobians (N, 6, nq).
        tools: Tool positions (N, 3) [m].
        pinvs: Pseudo-inverses J⁺ (N, nq, r) of the task rows.
    """

    grid: np.ndarray
    velocities: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray | None
    q: np.ndarray
    rates: np.ndarray
    jacobians: np.ndarray
    tools: np.ndarray
    pinvs: np.ndarray

    @classmethod
    def empty(
        cls,
        grid: np.ndarray,
        velocities: np.ndarray,
        positions: np.ndarray,
        rotations: np.ndarray | None,
        nq: int,
    ) -> Run:
        """A run over the given points with its outputs allocated (rows not yet solved)."""
        n, r = velocities.shape
        return cls(
            np.ascontiguousarray(grid, dtype=float),
            np.ascontiguousarray(velocities, dtype=float),
            np.ascontiguousarray(positions, dtype=float),
            None if rotations is None else np.ascontiguousarray(rotations, dtype=float),
            np.empty((n, nq)), np.empty((n, nq)), np.empty((n, 6, nq)), np.empty((n, 3)),
            np.empty((n, nq, r)),
        )  # fmt: skip


def advance(
    kernel: Kernel,
    run: Run,
    k: int,
    tolerances: tuple[float, float],
    max_step: float = math.inf,
) -> int:
    """Points k, k + 1, … of the lean loop, compiled, while each is solved cleanly.

    Point j's guess is the two-step Adams–Bashforth prediction
    ``q[j−1] + h (1 + ρ) rates[j−1] − h ρ rates[j−2]`` (h = grid[j] − grid[j−1],
    ρ = h / (2 (grid[j−1] − grid[j−2]))); when the tool there misses the tolerances, the
    Newton steps of :meth:`cartesian.tracker.Tracker.solve` follow (those of
    :meth:`kinplan.ik.IKSolver.descend` without limits: damped least squares, the same gain,
    floor, step cap, stall test and iteration count). A solved point gets its q, tool
    Jacobian, tool position, task pseudo-inverse and rates. Needs k ≥ 2 (two points before
    it solved).

    Args:
        kernel: :func:`kernel_for` of the arm and task.
        run: The points (rows before k solved); rows from k on are written.
        k: The first point to solve.
        tolerances: (position [m], rotation [rad]) tolerances of the tracker.
        max_step: Largest joint step [rad] from the point before (a geometric trace's
            bisection threshold); the default: none.

    Returns:
        N when every point from k on is solved, else the first point the caller must solve
        itself: its Newton steps failed, its joint step exceeds ``max_step``, its guess is not
        finite, or its rotation error is beyond a quarter turn (left to Pinocchio's log). Its
        row of ``q`` holds the last iterate (the guess when no Newton step was taken).
    """
    position_tolerance, rotation_tolerance = tolerances
    return int(
        _advance(
            k, run.grid, run.velocities, run.positions,
            _NO_ROTATIONS if run.rotations is None else run.rotations, run.rotations is not None,
            run.q, run.rates, run.jacobians, run.tools, run.pinvs,
            position_tolerance**2, frobenius_tolerance(rotation_tolerance), max_step,
            kernel.directions, kernel.points, kernel.tool, kernel.rows, kernel.shape,
            _NEWTON,
        )
    )  # fmt: skip


# ---------------------------------------------------------------------------- compiled code
@jit
def lu_solve(a, b):
    """x with a x = b for a square ``a`` (m, m) and ``b`` (m, k), by Gaussian elimination with
    partial pivoting (copies; a singular pivot gives inf/NaN, caught by the caller's checks)."""
    m = a.shape[0]
    a = a.copy()
    b = b.copy()
    for col in range(m):
        pivot = col
        for row in range(col + 1, m):
            if abs(a[row, col]) > abs(a[pivot, col]):
                pivot = row
        if pivot != col:
            for j in range(m):
                a[col, j], a[pivot, j] = a[pivot, j], a[col, j]
            for j in range(b.shape[1]):
                b[col, j], b[pivot, j] = b[pivot, j], b[col, j]
        for row in range(col + 1, m):
            factor = a[row, col] / a[col, col]
            for j in range(col, m):
                a[row, j] -= factor * a[col, j]
            for j in range(b.shape[1]):
                b[row, j] -= factor * b[col, j]
    for col in range(m - 1, -1, -1):
        for j in range(b.shape[1]):
            total = b[col, j]
            for i in range(col + 1, m):
                total -= a[col, i] * b[i, j]
            b[col, j] = total / a[col, col]
    return b


@jit
def _rotation_error(target, pose, error) -> bool:
    """log(R* Rᵀ) (the rotation vector [rad] taking the tool's rotation R to the target's,
    world frame, as ``pin.log3``) into ``error[3:]``; False when the angle exceeds a quarter
    turn (then the caller leaves the point to Pinocchio)."""
    m = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            m[i, j] = (
                target[i, 0] * pose[j, 0] + target[i, 1] * pose[j, 1] + target[i, 2] * pose[j, 2]
            )
    vx = 0.5 * (m[2, 1] - m[1, 2])
    vy = 0.5 * (m[0, 2] - m[2, 0])
    vz = 0.5 * (m[1, 0] - m[0, 1])
    cosine = 0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0)
    if not cosine > 0.0:
        return False
    sine = np.sqrt(vx * vx + vy * vy + vz * vz)
    angle = np.arctan2(sine, cosine)
    factor = angle / sine if sine > 1e-8 else 1.0 + angle * angle / 6.0  # θ / sin θ
    error[3] = factor * vx
    error[4] = factor * vy
    error[5] = factor * vz
    return True


@jit
def _pseudo_inverse(task, shape, identity):
    """J⁺ of the task rows: Jᵀ (J Jᵀ)⁻¹ (wide), J⁻¹ (square) or (JᵀJ)⁻¹ Jᵀ (tall)."""
    if shape < 0:
        return product(task.T, lu_solve(product(task, task.T), identity))
    if shape == 0:
        return lu_solve(task, identity)
    return lu_solve(product(task.T, task), task.T)


@jit
def _advance(
    k, grid, velocities, positions, rotations, with_rotation, q, rates, jacobians, tools,
    pinvs, position2, frobenius2, max_step, directions, points, tool, rows, shape, newton,
):  # fmt: skip
    """:func:`advance`'s loop (compiled). ``newton``: (damping gain, damping floor, step cap
    [rad], iterations, stall iterations) of the Newton steps."""
    n, nq = q.shape
    r = rows.shape[0]
    gain, floor, step_cap = newton[0], newton[1], newton[2]
    iterations, patience = int(newton[3]), int(newton[4])
    error_rows = 6 if with_rotation else 3
    pose = np.empty((4, 4))
    jacobian = np.empty((6, nq))
    task = np.empty((r, nq))
    identity = np.eye(r)
    error = np.zeros(6)
    normal = np.empty((nq, nq))
    gradient = np.empty((nq, 1))
    while k < n:
        h = grid[k] - grid[k - 1]
        ratio = 0.5 * h / (grid[k - 1] - grid[k - 2])
        current = q[k - 1] + (h * (1.0 + ratio)) * rates[k - 1] - (h * ratio) * rates[k - 2]
        q[k] = current
        if not np.isfinite(current).all():
            return k
        best_cost = np.inf
        stalled = 0
        for iteration in range(iterations + 1):
            kinematics(current, directions, points, tool, pose, jacobian)
            error[0] = positions[k, 0] - pose[0, 3]
            error[1] = positions[k, 1] - pose[1, 3]
            error[2] = positions[k, 2] - pose[2, 3]
            position_error2 = error[0] ** 2 + error[1] ** 2 + error[2] ** 2
            squares = 0.0
            if with_rotation:
                for i in range(3):
                    for j in range(3):
                        squares += (rotations[k, i, j] - pose[i, j]) ** 2
            if position_error2 <= position2 and squares <= frobenius2:
                break
            if iteration == iterations:
                return k
            rotation_error2 = 0.0
            if with_rotation:
                if not _rotation_error(rotations[k], pose, error):
                    return k
                rotation_error2 = error[3] ** 2 + error[4] ** 2 + error[5] ** 2
            cost = 0.5 * (position_error2 + rotation_error2)
            if cost < 0.999 * best_cost:
                best_cost = cost
                stalled = 0
            else:
                stalled += 1
                if stalled >= patience:
                    return k
            damping = gain * cost + floor
            for a in range(nq):  # JᵀJ + λI and Jᵀe over the error rows
                for b in range(nq):
                    total = 0.0
                    for m in range(error_rows):
                        total += jacobian[m, a] * jacobian[m, b]
                    normal[a, b] = total
                normal[a, a] += damping
                total = 0.0
                for m in range(error_rows):
                    total += jacobian[m, a] * error[m]
                gradient[a, 0] = total
            step = lu_solve(normal, gradient)[:, 0]
            largest = np.abs(step).max()
            if largest > step_cap:
                step = step * (step_cap / largest)
            current = current + step
        q[k] = current
        if np.abs(current - q[k - 1]).max() > max_step:
            return k
        jacobians[k] = jacobian
        tools[k] = pose[:3, 3]
        for i in range(r):
            task[i] = jacobian[rows[i]]
        pinv = _pseudo_inverse(task, shape, identity)
        pinvs[k] = pinv
        for a in range(nq):
            total = 0.0
            for m in range(r):
                total += pinv[a, m] * velocities[k, m]
            rates[k, a] = total
        k += 1
    return n
