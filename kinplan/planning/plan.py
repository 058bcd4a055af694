"""What :func:`kinplan.free_motion` returns: :class:`MotionPlan`, its :class:`PlanEvent` and
its :class:`WaypointArray`.

A :class:`MotionPlan` is a :class:`kinplan.trajectory.motion.SampledMotion` (the viewer, plots and
exports
take it): its samples are those of its timed trajectory on the grid ``0, dt, …`` with the last
exactly at the end of the motion. A plan that failed stands still at its start (a trajectory of
zero duration, one sample) and carries one event that says why and what to do.

Frames and units: joint values [rad, or m for prismatic joints], times [s], distances [m],
positions in the robot's base (world) frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from kinplan.trajectory import Trajectory, time_grid
from kinplan.trajectory.motion import MotionKind, MoveSpan, PlannedPath, TrajectoryToolPath

if TYPE_CHECKING:
    from kinplan.model.robot import Robot

__all__ = ["STATUSES", "MotionPlan", "PlanEvent", "PlanStatus", "WaypointArray"]

PlanStatus = Literal["ok", "no_path", "start_in_collision", "goal_in_collision", "unreachable"]
"""Outcome of :func:`kinplan.free_motion`."""

STATUSES: tuple[str, ...] = (
    "ok",
    "no_path",
    "start_in_collision",
    "goal_in_collision",
    "unreachable",
)
"""Every :data:`PlanStatus`, ``"ok"`` first."""


@dataclass(frozen=True)
class PlanEvent:
    """Why a free motion could not be planned (a :class:`kinplan.trajectory.motion.MotionEvent`).

    Attributes:
        kind: The status it causes: ``"no_path"``, ``"start_in_collision"``,
            ``"goal_in_collision"`` or ``"unreachable"``.
        message: What happened, one line (the colliding pair and its distance, the pose that
            is out of reach, the time spent searching).
        remedy: What the caller can do about it.
        t: Time of the event [s] (0: a plan that fails never moves).
        s: Share of the motion where it happened [-] (0).
        bodies: The colliding pair (robot body first), when the event is a collision.
        distance: The pair's signed distance [m] (negative: penetration depth), or nan.
        q: The configuration concerned (the start, or the goal nearest the start), or None.
    """

    kind: str
    message: str
    remedy: str = ""
    t: float = 0.0
    s: float = 0.0
    bodies: tuple[str, str] | None = None
    distance: float = float("nan")
    q: np.ndarray | None = None

    def __str__(self) -> str:
        return f"{self.message}; {self.remedy}" if self.remedy else self.message


class WaypointArray(np.ndarray):
    """Joint waypoints (K, nq) [rad] that also carry the times the motion passes them.

    It is a read-only float array (``plan.waypoints[0]`` is the start, ``plan.waypoints[-1]``
    the goal reached) and a :class:`kinplan.trajectory.Waypoints` for the viewer and plots:
    ``times`` (K,) [s] and ``positions`` (K, nq) (the array itself).
    """

    times: np.ndarray

    def __new__(cls, positions: np.ndarray, times: np.ndarray) -> WaypointArray:
        array = np.array(positions, dtype=float).reshape(len(positions), -1).view(cls)
        array.times = np.array(times, dtype=float).reshape(-1)
        array.times.flags.writeable = False
        array.flags.writeable = False
        return array

    def __array_finalize__(self, obj: Any) -> None:
        self.times = getattr(obj, "times", np.zeros(0))

    @property
    def positions(self) -> np.ndarray:
        """The waypoints as a plain array (K, nq) [rad]."""
        return np.asarray(self)


@dataclass(frozen=True, eq=False)
class MotionPlan:
    """A collision-free joint motion from :func:`kinplan.free_motion`, or why there is none.

    Attributes:
        status: ``"ok"``, ``"no_path"``, ``"start_in_collision"``, ``"goal_in_collision"`` or
            ``"unreachable"``.
        trajectory: The timed motion (a :class:`kinplan.trajectory.Trajectory`, rest to rest,
            time-optimal along the waypoints' path within the velocity and acceleration
            limits); for a failed plan, standing still at the start (zero duration).
        waypoints: The joint waypoints (K, nq) [rad], start first and the goal reached last
            (only the start when the plan failed); also ``waypoints.times`` [s].
        planning_time: Wall-clock time of the whole call [s] (search, shortcuts, timing and
            the check of the timed motion).
        min_clearance: Smallest robot–obstacle distance along the timed motion [m] (at the
            samples of the final check, at most 0.15 rad of path apart, the blends finer); inf
            without obstacles, nan when the plan failed.
        t: Sample times (N,) [s] on the grid ``0, dt, …`` (the last at the end).
        q, qd, qdd: Joint positions, velocities, accelerations at the samples (N, nq).
        tool_positions: Tool positions at the samples (N, 3) [m], base frame.
        min_self_clearance: Smallest distance between the robot's own checked pairs [m].
        clearance: The margin the motion keeps from the obstacles [m].
        goal: The joint goal reached (for a pose goal: the IK solution chosen), or None.
        blend: Largest deviation of the timed path from a corner of the waypoints [rad]
            (0: it stops at every corner).
        events: Why it failed (one event), empty when ok.
        robot: The robot.
        dt: Sampling period of ``t``, ``q``, ``qd``, ``qdd`` [s].
        stats: Counters and times of the steps: ``goals`` (goal configurations),
            ``iterations``, ``nodes``, ``rejected`` (paths whose certification failed),
            ``edge_checks`` (segments certified), ``screened`` (configurations screened),
            ``timing_attempts`` (blends tried), and ``setup_s`` (arguments, start and goals),
            ``search_s`` (search and shortcuts), ``timing_s`` (timing and its check) [s].
    """

    status: str
    trajectory: Trajectory
    waypoints: WaypointArray
    planning_time: float
    min_clearance: float
    robot: Robot
    min_self_clearance: float = float("nan")
    clearance: float = 0.0
    goal: np.ndarray | None = None
    blend: float = 0.0
    events: tuple[PlanEvent, ...] = ()
    dt: float = 0.01
    stats: dict[str, float] = field(default_factory=dict)
    t: np.ndarray = field(init=False, repr=False)
    q: np.ndarray = field(init=False, repr=False)
    qd: np.ndarray = field(init=False, repr=False)
    qdd: np.ndarray = field(init=False, repr=False)
    tool_positions: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        t = time_grid(self.trajectory.duration, self.dt)
        q, qd, qdd = self.trajectory.sample(t)
        tool = self.robot.tool_positions(q)
        for name, value in (("t", t), ("q", q), ("qd", qd), ("qdd", qdd), ("tool_positions", tool)):
            value.flags.writeable = False
            object.__setattr__(self, name, value)

    # ---------------------------------------------------------------- SampledMotion
    @property
    def ok(self) -> bool:
        """Whether a collision-free motion was found."""
        return self.status == "ok"

    @property
    def kind(self) -> MotionKind:
        """A joint motion (its tool path is exactly the planned one)."""
        return "joint"

    @property
    def description(self) -> str:
        """A short phrase for captions."""
        if not self.ok:
            return f"free motion ({self.status})"
        return f"free motion through {len(self.waypoints)} waypoints"

    @property
    def planned_paths(self) -> tuple[PlannedPath, ...]:
        """The tool path of the timed motion (exact at any path fraction)."""
        return (PlannedPath(TrajectoryToolPath(self.trajectory, self.robot)),)

    @property
    def moves(self) -> tuple[MoveSpan, ...]:
        """None: a single motion."""
        return ()

    @property
    def duration(self) -> float:
        """Duration of the timed motion [s]."""
        return float(self.trajectory.duration)

    @property
    def path_length(self) -> float:
        """Joint path length of the waypoints' polyline [rad] (Euclidean over the joints)."""
        return float(np.sum(np.linalg.norm(np.diff(self.waypoints.positions, axis=0), axis=1)))

    def summary(self) -> str:
        """One line: the outcome, waypoints, duration and clearance, or the event."""
        if not self.ok:
            return f"{self.status}: {self.events[0]}"
        return (
            f"ok: {len(self.waypoints)} waypoints, {self.duration:.3f} s, joint path "
            f"{self.path_length:.3f} rad, min clearance {self.min_clearance * 1e3:.1f} mm, "
            f"planned in {self.planning_time * 1e3:.0f} ms"
        )
