"""The goal configurations of a free motion: a joint goal, or every IK solution of a pose.

A pose goal (``pin.SE3`` in the base frame) becomes every joint configuration that puts the tool
there within the limits: the closed form's solutions where the arm has one (UR family and planar
2R: all branches; panda-type arms: all branches for θ7 on a grid over its range and at the
start's θ7), else Levenberg–Marquardt solutions from many deterministic seeds (the start, the
neutral configuration, then seeded random configurations), kept when distinct. Each solution is
then taken with every 2π-equivalent of its revolute joints that lies within their limits (joints
whose range exceeds 2π: a UR's ±2π joints give up to 2⁶ equivalents), nearest the start first.
Equivalents share their geometry, so one collision check per solution decides for all of them.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinplan.cell import PairDistance, WorkCell
from kinplan.model.robot import Robot

__all__ = ["MAX_GOALS", "GoalSet", "equivalents", "goal_set", "pose_goals"]

MAX_GOALS = 256
"""Most goal configurations the search grows its goal tree from (nearest the start kept)."""

_TAU = 2.0 * math.pi
_POSE_TOLERANCE = 1e-6  # [m] and [rad]: a solution must reach the pose this well
_THETA7_VALUES = 12  # panda-type arms: θ7 grid over its range
_NUMERIC_SEEDS = 24  # arms without a closed form: IK attempts from distinct seeds
_DISTINCT = 1e-6  # [rad]: solutions closer than this are one


@dataclass(frozen=True)
class GoalSet:
    """The goal configurations of a search, and why there may be none.

    Attributes:
        free: Collision-free goal configurations (G, nq) [rad], nearest the start first.
        solutions: Distinct geometric solutions found (before equivalents and collisions).
        blocked: For each solution in collision, its nearest failing pair (deepest first).
    """

    free: np.ndarray
    solutions: int
    blocked: tuple[tuple[np.ndarray, PairDistance], ...]


def equivalents(robot: Robot, q: np.ndarray, near: np.ndarray) -> np.ndarray:
    """``q`` and every configuration that differs by whole turns of revolute joints within the
    limits (joints whose range exceeds 2π), nearest ``near`` first (Euclidean) [rad], (E, nq).

    Unbounded (continuous) joints take the one value nearest ``near``.
    """
    options: list[list[float]] = []
    for j in range(robot.nq):
        value, lower, upper = float(q[j]), float(robot.lower[j]), float(robot.upper[j])
        if robot.prismatic[j]:
            options.append([value])
        elif not (math.isfinite(lower) and math.isfinite(upper)):
            options.append([value - _TAU * round((value - float(near[j])) / _TAU)])
        elif upper - lower > _TAU:
            first = value - _TAU * math.floor((value - lower) / _TAU)
            options.append([v for v in np.arange(first, upper + 1e-9, _TAU).tolist()])
        else:
            options.append([value])
    combos = np.array(list(itertools.product(*options)), dtype=float)
    combos = np.clip(combos, robot.lower, robot.upper)
    order = np.argsort(np.linalg.norm(combos - near, axis=1), kind="stable")
    return combos[order]


def pose_goals(
    robot: Robot, target: pin.SE3, start: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """Distinct IK solutions of ``target`` within the limits (S, nq) [rad] (S = 0: none).

    Args:
        robot: The arm.
        target: Tool pose in the base (world) frame.
        start: The start configuration (a seed, and the θ7 of panda-type arms).
        rng: Random generator for the seeds of numerical IK (deterministic per seed).
    """
    position, rotation = np.asarray(target.translation), np.asarray(target.rotation)
    solver = robot.closed_form_ik
    found: list[np.ndarray] = []
    if solver is not None and hasattr(solver, "solutions"):
        found.extend(np.asarray(solver.solutions(position, rotation), dtype=float))
    elif solver is not None and hasattr(solver, "solutions_q7"):
        lower, upper = float(robot.lower[-1]), float(robot.upper[-1])
        grid = np.linspace(lower, upper, _THETA7_VALUES + 2)[1:-1].tolist()
        for q7 in [float(np.clip(start[-1], lower, upper)), *grid]:
            found.extend(np.asarray(solver.solutions_q7(position, rotation, q7), dtype=float))
    else:
        seeds = [start, robot.neutral()]
        seeds += [robot.random_configuration(rng) for _ in range(_NUMERIC_SEEDS - 2)]
        for seed in seeds:
            result = robot.ik(target, q_seed=seed, max_restarts=0 if len(found) else 8)
            if result.success:
                found.append(np.asarray(result.q, dtype=float))
    kept: list[np.ndarray] = []
    for q in found:
        if q.shape != (robot.nq,) or not np.all(np.isfinite(q)):
            continue
        q = np.clip(q, robot.lower, robot.upper)
        if not _reaches(robot, q, target):
            continue
        if any(np.max(np.abs(q - other)) < _DISTINCT for other in kept):
            continue
        kept.append(q)
    return np.array(kept, dtype=float).reshape(-1, robot.nq)


def goal_set(
    robot: Robot,
    cell: WorkCell,
    solutions: np.ndarray,
    start: np.ndarray,
    clearance: float,
    turns: bool = True,
) -> GoalSet:
    """The collision-free goals among ``solutions`` (and their 2π-equivalents).

    Args:
        robot: The arm (the cell's).
        cell: The work cell.
        solutions: Goal configurations (S, nq) [rad].
        start: The start (equivalents nearest it first).
        clearance: Margin from the obstacles [m].
        turns: Add every 2π-equivalent within the limits (pose goals); else the solutions
            exactly (a joint goal).
    """
    free: list[np.ndarray] = []
    blocked: list[tuple[np.ndarray, PairDistance]] = []
    for q in solutions:
        hits = cell.collisions(q, margin=clearance)
        if hits:
            blocked.append((q, hits[0]))
            continue
        free.extend(equivalents(robot, q, start) if turns else [q])
    goals = np.array(free, dtype=float).reshape(-1, robot.nq)
    order = np.argsort(np.linalg.norm(goals - start, axis=1), kind="stable")
    return GoalSet(goals[order][:MAX_GOALS], len(solutions), tuple(blocked))


def _reaches(robot: Robot, q: np.ndarray, target: pin.SE3) -> bool:
    """Whether the tool is at ``target`` at ``q`` (position and rotation within 1e-6)."""
    pose = robot.fk(q)
    if np.linalg.norm(pose.translation - target.translation) > _POSE_TOLERANCE:
        return False
    error = pin.log3(pose.rotation.T @ target.rotation)
    return bool(np.linalg.norm(error) <= _POSE_TOLERANCE)
