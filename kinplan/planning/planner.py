"""``kinplan.free_motion``: a collision-free, timed joint motion between two configurations or
to a tool pose, certified against the work cell all along.

The steps (each in its own module):

1. **Arguments** are checked here: sizes, NaN, limits, the time limit and the seed are misuse
   and raise :class:`~kinplan.errors.InputError`.
2. **Start and goals** (:mod:`kinplan.planning.goals`): the start must keep the clearance; a
   pose goal becomes every IK solution and its 2π-equivalents; the colliding ones are set aside
   (all of them colliding: ``goal_in_collision``, none: ``unreachable``).
3. **Search** (:mod:`kinplan.planning.search`): RRT-Connect, every edge certified by the cell's
   motion check (conservative advancement between the edge's ends).
4. **Shortcuts** (:mod:`kinplan.planning.shortcut`), every new edge certified.
5. **Timing** (:mod:`kinplan.planning.timing`): time-optimal along the waypoints within the
   joint velocity and acceleration limits, blends at the corners, and the timed motion's path
   checked again (smaller blends, then none, until it passes).
"""

from __future__ import annotations

import numbers
import time
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from kinplan import checks, trajectory
from kinplan.cell import PairDistance, WorkCell
from kinplan.errors import InputError
from kinplan.model.robot import Robot
from kinplan.planning.goals import GoalSet, goal_set, pose_goals
from kinplan.planning.plan import MotionPlan, PlanEvent, WaypointArray
from kinplan.planning.search import EdgeChecker, rrt_connect
from kinplan.planning.shortcut import shorten
from kinplan.planning.timing import DEFAULT_BLEND, timed_motion

__all__ = ["DEFAULT_RAMP_TIME", "FALLBACK_VELOCITY", "free_motion", "motion_limits"]

FALLBACK_VELOCITY = 1.0
"""Velocity limit of a joint whose URDF gives none (nor ``max_velocity``) [rad/s or m/s]."""

DEFAULT_RAMP_TIME = 0.5
"""Without an acceleration limit, a joint reaches its velocity limit in this time [s]."""

_LIMIT_SLACK = 1e-9  # [rad or m]: the start may lie this far outside its limits (rounding)


def free_motion(
    robot: Robot,
    start: Sequence[float] | np.ndarray,
    goal: Sequence[float] | np.ndarray | pin.SE3,
    cell: WorkCell,
    *,
    clearance: float = 0.0,
    time_limit: float = 1.0,
    seed: int = 0,
    max_velocity: float | Sequence[float] | np.ndarray | None = None,
    max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    blend: float = DEFAULT_BLEND,
    any_turn: bool = False,
) -> MotionPlan:
    """A collision-free timed joint motion from ``start`` to ``goal`` around the cell.

    Every straight segment of the search and of its shortcuts is certified by the cell's motion
    check (:meth:`kinplan.WorkCell.check_motion`: conservative advancement, so no shortfall
    below ``clearance`` deeper than 1e-6 m is missed between the checked configurations), and
    the timed motion's path, whose blends leave the certified segments, is checked again.

    Args:
        robot: The arm (the cell's robot, or one with the same joints).
        start: Start configuration (nq,) [rad, or m for prismatic joints], within the limits.
        goal: A joint configuration (nq,) within the limits, reached exactly; or a tool pose
            (``pin.SE3`` in the base frame): every IK solution within the limits, and every
            2π-equivalent of joints whose range exceeds 2π, is a goal, and the motion ends at
            whichever the search reaches (``plan.goal``).
        cell: The work cell (:class:`kinplan.WorkCell`) whose obstacles and self pairs the
            motion avoids.
        clearance: Margin from the obstacles the whole motion keeps [m] ≥ 0 (robot bodies and
            tool bodies against obstacles; the robot's own pairs: no contact).
        time_limit: Longest search [s] > 0 (shortcuts and timing come after it).
        seed: Seed of the search's random generator (an int ≥ 0): the same seed gives the
            same motion.
        max_velocity: Joint velocity limits [rad/s], one number or one per joint; default the
            robot's (1 rad/s where the URDF has none). Never above the robot's.
        max_acceleration: Joint acceleration limits [rad/s²], one number or one per joint;
            default the robot's, or the velocity limit reached in 0.5 s where it has none.
        blend: Largest deviation of the timed path from a corner [rad] ≥ 0 (0: stop at each
            corner); reduced automatically where a blend would collide.
        any_turn: For a joint goal: also accept every configuration that differs from it by
            whole turns of joints whose range exceeds 2π (the same arm pose with the joints
            wound otherwise; the motion ends at whichever the search reaches). A table under
            a UR arm splits its ±2π joint space into parts no motion joins, so a joint goal
            may be reachable only this way. Pose goals always take every equivalent.

    Returns:
        :class:`MotionPlan` with ``status`` ``"ok"``, ``"no_path"`` (nothing found within the
        time limit), ``"start_in_collision"``, ``"goal_in_collision"`` (naming the pair and
        its distance) or ``"unreachable"`` (no IK solution of a pose goal).

    Raises:
        InputError: ``robot`` or ``cell`` of the wrong type or not matching; ``start`` or a
            joint ``goal`` of the wrong size, NaN or outside the limits; a goal that is neither
            a joint vector nor an SE3; ``time_limit`` ≤ 0, NaN or not a number; ``seed`` not an
            integer ≥ 0; ``clearance`` < 0; limits that are not positive.
    """
    began = time.perf_counter()
    robot, start_q, cell = _checked_setting(robot, start, cell)
    clearance = checks.number(clearance, "clearance", minimum=0.0, unit="m")
    time_limit = checks.number(time_limit, "time_limit", positive=True, unit="s")
    seed = _checked_seed(seed)
    blend = checks.number(blend, "blend", minimum=0.0, unit="rad")
    any_turn = checks.flag(any_turn, "any_turn")
    velocity, acceleration = motion_limits(robot, max_velocity, max_acceleration)
    target = _checked_goal(robot, goal)
    rng = np.random.default_rng(seed)
    deadline = began + time_limit

    def failed(event: PlanEvent, stats: dict[str, float] | None = None) -> MotionPlan:
        return _failure(robot, start_q, clearance, began, event, stats or {})

    hits = cell.collisions(start_q, margin=clearance)
    if hits:
        return failed(_collision_event("start_in_collision", "the start", hits[0], start_q))
    is_pose = isinstance(target, pin.SE3)
    if isinstance(target, pin.SE3):
        solutions = pose_goals(robot, target, start_q, rng)
        if not len(solutions):
            return failed(_unreachable_event(robot, target, start_q))
    else:
        solutions = target[None]
    goals = goal_set(robot, cell, solutions, start_q, clearance, is_pose or any_turn)
    if not len(goals.free):
        return failed(_blocked_event(goals, target))
    checker = EdgeChecker(cell, clearance)
    lower, upper = _sampling_box(robot, start_q, goals.free)
    searched = time.perf_counter()

    def finish(points: np.ndarray, certified: np.ndarray) -> tuple[np.ndarray | None, int | None]:
        return shorten(points, certified, checker, rng)

    found = rrt_connect(start_q, goals.free, lower, upper, checker, rng, deadline, finish)
    stats: dict[str, float] = {
        "iterations": found.iterations,
        "nodes": found.nodes,
        "goals": len(goals.free),
        "rejected": found.rejected,
        "setup_s": searched - began,
        "search_s": time.perf_counter() - searched,  # with the shortcuts
    }
    if found.path is None:
        stats["edge_checks"] = checker.checks
        wound = [] if is_pose or any_turn else _wound(robot, start_q, goals.free[0])
        return failed(_no_path_event(time_limit, found.nodes, clearance, wound), stats)
    points = found.path
    stats["edge_checks"] = checker.checks
    stats["screened"] = checker.screen.tests
    timing = time.perf_counter()
    timed = timed_motion(cell, points, velocity, acceleration, clearance, blend)
    stats["timing_attempts"] = timed.attempts
    stats["timing_s"] = time.perf_counter() - timing
    if not timed.check.ok:  # not expected: the polyline's edges were certified one by one
        why = f"the timed motion failed its check: {timed.check.describe()}"
        return failed(PlanEvent("no_path", why, "report this as a bug; try another seed"), stats)
    waypoints = WaypointArray(points, _waypoint_times(timed.trajectory, points))
    return MotionPlan(
        status="ok",
        trajectory=timed.trajectory,
        waypoints=waypoints,
        planning_time=time.perf_counter() - began,
        min_clearance=timed.check.min_obstacle_clearance,
        min_self_clearance=timed.check.min_self_clearance,
        robot=robot,
        clearance=clearance,
        goal=points[-1].copy(),
        blend=timed.blend,
        stats=stats,
    )


# ------------------------------------------------------------------------------ arguments
def motion_limits(
    robot: Robot,
    max_velocity: float | Sequence[float] | np.ndarray | None,
    max_acceleration: float | Sequence[float] | np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray]:
    """The joint velocity [rad/s] and acceleration [rad/s²] limits of a free motion (nq,) each.

    Velocity: the robot's (:data:`FALLBACK_VELOCITY` where none), lowered to ``max_velocity``.
    Acceleration: the robot's, lowered to ``max_acceleration``; where neither limits a joint,
    its velocity limit reached in :data:`DEFAULT_RAMP_TIME`.

    Raises:
        InputError: a limit that is not one positive number or one per joint.
    """
    own = np.asarray(robot.velocity_limit, dtype=float)
    velocity = np.where(np.isfinite(own) & (own > 0), own, FALLBACK_VELOCITY)
    if max_velocity is not None:
        velocity = np.minimum(velocity, _limits(max_velocity, "max_velocity", robot, "rad/s"))
    acceleration = np.asarray(robot.acceleration_limit, dtype=float).copy()
    if max_acceleration is not None:
        given = _limits(max_acceleration, "max_acceleration", robot, "rad/s²")
        acceleration = np.minimum(acceleration, given)
    acceleration = np.where(np.isfinite(acceleration), acceleration, velocity / DEFAULT_RAMP_TIME)
    return velocity, acceleration


def _limits(value: object, name: str, robot: Robot, unit: str) -> np.ndarray:
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return np.full(robot.nq, checks.number(value, name, positive=True, unit=unit))
    array = checks.vector(value, name, robot.nq, unit)
    if np.any(array <= 0):
        raise InputError(f"{name} must be > 0 [{unit}] for every joint, got {array.tolist()}")
    return array


def _checked_setting(
    robot: object, start: object, cell: object
) -> tuple[Robot, np.ndarray, WorkCell]:
    if not isinstance(robot, Robot):
        raise InputError(
            f"free_motion: robot must be a kinplan.Robot (kinplan.load_robot(...)), got "
            f"{checks.describe(robot)}"
        )
    if not isinstance(cell, WorkCell):
        raise InputError(
            f"free_motion: cell must be a kinplan.WorkCell (kinplan.WorkCell(robot) with its "
            f"obstacles), got {checks.describe(cell)}"
        )
    if cell.robot is not robot and (
        cell.robot.nq != robot.nq or list(cell.robot.joint_names) != list(robot.joint_names)
    ):
        raise InputError(
            f"free_motion: the cell is built around {cell.robot.name} "
            f"({', '.join(cell.robot.joint_names)}), not {robot.name}; build the cell with "
            "WorkCell(robot) or cell.for_robot(robot)"
        )
    q = robot.check_q(start, "start")  # type: ignore[arg-type]
    _within_limits(robot, q, "start")
    return robot, q.copy(), cell


def _within_limits(robot: Robot, q: np.ndarray, what: str) -> None:
    outside = np.flatnonzero((q < robot.lower - _LIMIT_SLACK) | (q > robot.upper + _LIMIT_SLACK))
    if outside.size:
        j = int(outside[0])
        raise InputError(
            f"{what} is outside the joint limits: joint {j} ({robot.joint_names[j]}) = "
            f"{q[j]:.6g}, limits [{robot.lower[j]:.6g}, {robot.upper[j]:.6g}]; give a "
            f"configuration within the limits (robot.lower, robot.upper)"
        )


def _checked_seed(seed: object) -> int:
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or int(seed) < 0:
        raise InputError(
            f"seed must be an integer ≥ 0 (it seeds the search's random generator), got "
            f"{checks.describe(seed)}"
        )
    return int(seed)


def _checked_goal(robot: Robot, goal: object) -> np.ndarray | pin.SE3:
    if isinstance(goal, pin.SE3):
        if not (np.all(np.isfinite(goal.translation)) and np.all(np.isfinite(goal.rotation))):
            raise InputError("goal pose must be finite (an SE3 without NaN or inf)")
        return pin.SE3(goal)
    if goal is None or isinstance(goal, (str, bytes)):
        raise InputError(
            f"goal must be a joint vector of {robot.nq} values or a pin.SE3 tool pose, got "
            f"{checks.describe(goal)}"
        )
    q = robot.check_q(goal, "goal")  # type: ignore[arg-type]
    _within_limits(robot, q, "goal")
    return q.copy()


def _sampling_box(
    robot: Robot, start: np.ndarray, goals: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The joint limits, with unbounded joints sampled within 2π of the start and goals."""
    lower, upper = robot.lower.copy(), robot.upper.copy()
    ends = np.vstack([start, goals])
    tau = 2.0 * np.pi
    lower = np.where(np.isfinite(lower), lower, ends.min(axis=0) - tau)
    upper = np.where(np.isfinite(upper), upper, ends.max(axis=0) + tau)
    return lower, upper


def _waypoint_times(traj: trajectory.Trajectory, points: np.ndarray) -> np.ndarray:
    """When the timed motion passes nearest each waypoint [s] (the trajectory's own)."""
    times = np.asarray(traj.waypoints.times, dtype=float)
    if len(times) == len(points):
        return times
    return np.linspace(0.0, traj.duration, len(points))


# ------------------------------------------------------------------------------ failures
def _failure(
    robot: Robot,
    start: np.ndarray,
    clearance: float,
    began: float,
    event: PlanEvent,
    stats: dict[str, float],
) -> MotionPlan:
    """A plan standing still at the start, with the event that says why."""
    still = trajectory.time_optimal(np.vstack([start, start]), 1.0, 1.0)
    return MotionPlan(
        status=event.kind,
        trajectory=still,
        waypoints=WaypointArray(start[None], np.zeros(1)),
        planning_time=time.perf_counter() - began,
        min_clearance=float("nan"),
        robot=robot,
        clearance=clearance,
        events=(event,),
        stats=stats,
    )


def _pair_text(pair: PairDistance) -> str:
    a, b = pair.bodies
    if pair.distance < 0:
        return f"{a} and {b} penetrate by {-pair.distance * 1e3:.2f} mm"
    return f"{a} and {b} are {pair.distance * 1e3:.2f} mm apart"


def _collision_event(kind: str, what: str, pair: PairDistance, q: np.ndarray) -> PlanEvent:
    margin = " (closer than the clearance)" if pair.distance > 0 else ""
    return PlanEvent(
        kind=kind,
        message=f"{what} is in collision: {_pair_text(pair)}{margin}",
        remedy=(
            f"move {what} out of the obstacles (or lower the clearance); "
            "kinplan.WorkCell.collisions(q) lists every colliding pair"
        ),
        bodies=pair.bodies,
        distance=pair.distance,
        q=q.copy(),
    )


def _blocked_event(goals: GoalSet, target: np.ndarray | pin.SE3) -> PlanEvent:
    q, pair = goals.blocked[0]
    if not isinstance(target, pin.SE3):
        return _collision_event("goal_in_collision", "the goal", pair, q)
    count = goals.solutions
    event = _collision_event(
        "goal_in_collision", f"every IK solution of the goal pose ({count})", pair, q
    )
    return PlanEvent(
        kind=event.kind,
        message=event.message.replace("is in collision:", "is in collision; the first:"),
        remedy="move the goal pose away from the obstacles (or lower the clearance)",
        bodies=pair.bodies,
        distance=pair.distance,
        q=q.copy(),
    )


def _unreachable_event(robot: Robot, target: pin.SE3, start: np.ndarray) -> PlanEvent:
    where = "(" + ", ".join(f"{x:.4f}" for x in target.translation) + ") m"
    best = robot.ik(target, q_seed=start)
    why = (
        f"the closest tool pose within the joint limits is {best.position_error:.4f} m and "
        f"{best.rotation_error:.3f} rad away"
    )
    distance, reach = robot.shoulder_distance(target.translation), robot.reach()
    if distance > reach * (1 + 1e-12):
        why = f"it is {distance:.4f} m from the arm's first joint, which reaches {reach:.4f} m"
    return PlanEvent(
        kind="unreachable",
        message=f"the goal pose at {where} has no IK solution within the joint limits: {why}",
        remedy="move the goal pose within the arm's reach, or change its orientation",
        q=None,
    )


def _wound(robot: Robot, start: np.ndarray, goal: np.ndarray) -> list[str]:
    """Joints whose range exceeds 2π and that the goal turns by more than π from the start."""
    span = robot.upper - robot.lower
    far = (np.abs(goal - start) > np.pi) & (span > 2.0 * np.pi) & ~robot.prismatic
    return [robot.joint_names[j] for j in np.flatnonzero(far)]


def _no_path_event(time_limit: float, nodes: int, clearance: float, wound: list[str]) -> PlanEvent:
    margin = f" keeping {clearance * 1e3:g} mm clearance" if clearance > 0 else ""
    turns = ""
    if wound:
        turns = (
            f"; the goal turns {', '.join(wound)} by more than half a turn, which an obstacle "
            "may forbid: any_turn=True accepts the goal with those joints a whole turn off"
        )
    return PlanEvent(
        kind="no_path",
        message=(
            f"no collision-free motion found{margin} within the time limit of {time_limit:g} s "
            f"({nodes} configurations explored)"
        ),
        remedy=(
            "raise time_limit, try another seed, lower the clearance, or add a via point "
            "through the free space" + turns
        ),
    )
