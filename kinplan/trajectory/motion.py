"""What a planned motion offers: the :class:`SampledMotion` protocol and the adapter to it.

Viewers (:mod:`kinplan.viewer`), plots (:mod:`kinplan.plot`) and exports (:mod:`kinplan.export`)
read every motion through one typed interface, :class:`SampledMotion`: the samples (``t``, ``q``,
``qd``, ``qdd``), the robot, the tool positions achieved, the Cartesian paths planned and how far
each was reached, the joint waypoints, the moves of a program and the events that stopped a plan.

* :class:`cartesian.CartesianPlan` and :class:`kinplan.program.ProgramPlan` provide it themselves;
* a joint :class:`~kinplan.trajectory.Trajectory` (or anything with ``duration`` and
  ``sample(t)``, :class:`JointTrajectory`) is sampled into a :class:`JointMotion` by
  :func:`sampled`;
* :func:`as_sampled_motion` takes any of them and raises :class:`~kinplan.errors.InputError`
  for anything else.

Imports go one way: this module knows neither :mod:`cartesian` nor :mod:`kinplan.program` (their
plans satisfy the protocols structurally), so both import it.

Frames and units: positions in the robot's base (world) frame [m], times [s], joints [rad or m].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, Protocol, runtime_checkable

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinplan.errors import InputError
from kinplan.trajectory import Trajectory, Waypoints, time_grid

if TYPE_CHECKING:
    from kinplan.cell import MotionCheck
    from kinplan.model.robot import Robot

__all__ = [
    "DEFAULT_DT",
    "JointMotion",
    "JointTrajectory",
    "MotionEvent",
    "MotionKind",
    "MotionLike",
    "MoveSpan",
    "PlannedPath",
    "SampledMotion",
    "ToolPath",
    "ToolTrack",
    "TrajectoryToolPath",
    "as_sampled_motion",
    "collision_check",
    "collision_time",
    "joint_rows",
    "no_waypoints",
    "pose_to_track",
    "sampled",
    "tool_track",
]

DEFAULT_DT = 0.01
"""Sampling period of a joint trajectory when none is given [s]."""

MotionKind = Literal["joint", "cartesian", "program"]
"""What made a motion: a joint trajectory (its tool path is exactly the planned one), a Cartesian
plan (an event's ``s`` is a fraction of its path) or a program plan (an event's ``s`` is the share
of the failed move)."""


# ----------------------------------------------------------------------------------------------
# The protocols
# ----------------------------------------------------------------------------------------------


class ToolPath(Protocol):
    """A tool path parametrised by its fraction s ∈ [0, 1] (:class:`cartesian.Path` is one)."""

    def position(self, s: np.ndarray) -> np.ndarray:
        """Tool positions at the path fractions ``s`` (k,), shape (k, 3) [m]."""
        ...


@runtime_checkable
class MotionEvent(Protocol):
    """Why a plan stopped (:class:`cartesian.Event` is one)."""

    @property
    def kind(self) -> str:
        """The status it causes (``"unreachable"``, ``"singular"``, ...)."""
        ...

    @property
    def t(self) -> float:
        """Time of the offending sample [s]."""
        ...

    @property
    def s(self) -> float:
        """Path fraction (Cartesian plan) or share of the move (program) where it happened."""
        ...

    @property
    def message(self) -> str:
        """What happened and where, one line."""
        ...


class MoveSpan(Protocol):
    """One move of a program (:class:`kinplan.program.MoveReport` is one)."""

    @property
    def number(self) -> int:
        """1-based move number."""
        ...

    @property
    def t0(self) -> float:
        """Start time [s]."""
        ...

    @property
    def t1(self) -> float:
        """End time [s] (where it stopped, for a failed move)."""
        ...

    @property
    def status(self) -> str:
        """``"ok"`` or why the move failed."""
        ...

    @property
    def label(self) -> str:
        """What the move is, e.g. ``"approach: lin to b"``."""
        ...


@dataclass(frozen=True)
class PlannedPath:
    """A tool path a motion was planned along, and how far along it the motion got.

    Attributes:
        path: The path (``position(s)`` for s ∈ [0, 1]).
        reached: Path fraction where the motion stopped (its first event's ``s``), 1.0 when the
            whole path was planned; clipped to [0, 1] (1.0 when not finite).
    """

    path: ToolPath
    reached: float = 1.0

    def __post_init__(self) -> None:
        reached = float(self.reached)
        object.__setattr__(
            self, "reached", min(max(reached, 0.0), 1.0) if math.isfinite(reached) else 1.0
        )


@runtime_checkable
class SampledMotion(Protocol):
    """A planned motion as samples, with what it was planned along and why it stopped.

    Provided by :class:`cartesian.CartesianPlan`, :class:`kinplan.program.ProgramPlan` and
    :class:`JointMotion` (a sampled joint trajectory, see :func:`sampled`). Arrays have one row
    per sample; a plan stopped by an event holds the samples achieved before it.
    """

    @property
    def kind(self) -> MotionKind:
        """What made it (see :data:`MotionKind`)."""
        ...

    @property
    def description(self) -> str:
        """What it is, a short phrase for captions (``"Cartesian path 0.300 m"``)."""
        ...

    @property
    def t(self) -> np.ndarray:
        """Sample times (N,) [s], non-decreasing."""
        ...

    @property
    def q(self) -> np.ndarray:
        """Joint positions (N, nq) [rad or m]."""
        ...

    @property
    def qd(self) -> np.ndarray:
        """Joint velocities (N, nq) [rad/s or m/s]."""
        ...

    @property
    def qdd(self) -> np.ndarray:
        """Joint accelerations (N, nq) [rad/s² or m/s²]."""
        ...

    @property
    def robot(self) -> Robot | None:
        """The robot it was planned for; None for a joint trajectory sampled without one."""
        ...

    @property
    def tool_positions(self) -> np.ndarray | None:
        """Tool positions achieved (N, 3) [m] (forward kinematics of ``q``); None without a
        robot."""
        ...

    @property
    def planned_paths(self) -> Sequence[PlannedPath]:
        """The tool paths it was planned along, in order, each with how far it was reached."""
        ...

    @property
    def waypoints(self) -> Waypoints:
        """Joint positions it was planned through, at their times (none for a Cartesian plan)."""
        ...

    @property
    def moves(self) -> Sequence[MoveSpan]:
        """The moves of a program, in time order; empty for a single motion."""
        ...

    @property
    def events(self) -> Sequence[MotionEvent]:
        """What stopped it, the first event first; empty when it is ok."""
        ...

    @property
    def ok(self) -> bool:
        """Whether the whole motion was planned without an event."""
        ...

    @property
    def status(self) -> str:
        """``"ok"`` or the kind of the first event."""
        ...


@runtime_checkable
class JointTrajectory(Protocol):
    """A joint motion evaluated at any time (:class:`~kinplan.trajectory.Trajectory` is one)."""

    @property
    def duration(self) -> float:
        """End time [s]; the motion starts at 0."""
        ...

    def sample(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint positions, velocities and accelerations at the times ``t``, (len(t), n) each."""
        ...


MotionLike = SampledMotion | JointTrajectory
"""What consumers take: a motion that provides :class:`SampledMotion`, or a joint trajectory."""


# ----------------------------------------------------------------------------------------------
# Joint trajectories as sampled motions
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class TrajectoryToolPath:
    """The tool path of a joint trajectory: s ↦ tool position at time s · duration.

    Attributes:
        trajectory: The joint motion.
        robot: The robot whose tool it moves.
    """

    trajectory: JointTrajectory
    robot: Robot

    def position(self, s: np.ndarray) -> np.ndarray:
        """Tool positions at the path fractions ``s`` (k,), shape (k, 3) [m]."""
        t = np.asarray(s, dtype=float) * float(self.trajectory.duration)
        q = joint_rows(self.robot, self.trajectory.sample(t)[0], "the trajectory's samples")
        return self.robot.tool_positions(q)


@dataclass(frozen=True, eq=False)
class JointMotion:
    """A joint trajectory sampled at a fixed period: a :class:`SampledMotion` that never fails.

    Build it with :func:`sampled`. Its planned path is the tool path of the trajectory itself
    (a :class:`TrajectoryToolPath`, exact at any s), when it has a robot.

    Attributes:
        trajectory: The joint motion sampled.
        t: Sample times (N,) [s].
        q: Joint positions (N, nq).
        qd: Joint velocities (N, nq).
        qdd: Joint accelerations (N, nq).
        robot: The robot, or None.
        tool_positions: Tool positions (N, 3) [m], or None without a robot.
        planned_paths: The trajectory's tool path (none without a robot).
        waypoints: The trajectory's waypoints (none for a trajectory that has none).
    """

    trajectory: JointTrajectory
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    robot: Robot | None
    tool_positions: np.ndarray | None
    planned_paths: tuple[PlannedPath, ...]
    waypoints: Waypoints

    @property
    def kind(self) -> MotionKind:
        return "joint"

    @property
    def description(self) -> str:
        return "joint trajectory"

    @property
    def moves(self) -> tuple[MoveSpan, ...]:
        return ()

    @property
    def events(self) -> tuple[MotionEvent, ...]:
        return ()

    @property
    def ok(self) -> bool:
        return True

    @property
    def status(self) -> str:
        return "ok"


def sampled(
    trajectory: JointTrajectory, robot: Robot | None = None, dt: float = DEFAULT_DT
) -> JointMotion:
    """A joint trajectory sampled every ``dt`` as a :class:`SampledMotion`.

    Args:
        trajectory: The joint motion (``duration`` and ``sample(t)``).
        robot: The robot it moves (for the tool positions and path); None for bare joints.
        dt: Sampling period [s]: samples at 0, dt, ..., the last exactly at the end.

    Returns:
        The sampled motion.

    Raises:
        InputError: the duration is not finite and ≥ 0, dt is not positive, or the samples do
            not fit the robot (joint count, NaN).
    """
    duration = float(trajectory.duration)
    if not (math.isfinite(duration) and duration >= 0.0):
        raise InputError(f"the trajectory's duration must be finite and ≥ 0 s, got {duration}")
    t = time_grid(duration, dt)
    q, qd, qdd = trajectory.sample(t)
    if robot is None:
        q = _finite_rows(q, len(t), None, "the trajectory's samples")
    else:
        q = joint_rows(robot, q, "the trajectory's samples")
    qd = _finite_rows(qd, len(t), q.shape[1], "the trajectory's velocities")
    qdd = _finite_rows(qdd, len(t), q.shape[1], "the trajectory's accelerations")
    if isinstance(trajectory, Trajectory):
        waypoints = trajectory.waypoints
    else:
        waypoints = no_waypoints(q.shape[1])
    path = () if robot is None else (PlannedPath(TrajectoryToolPath(trajectory, robot)),)
    return JointMotion(
        trajectory=trajectory,
        t=t,
        q=q,
        qd=qd,
        qdd=qdd,
        robot=robot,
        tool_positions=None if robot is None else robot.tool_positions(q),
        planned_paths=path,
        waypoints=waypoints,
    )


def as_sampled_motion(
    motion: object, robot: Robot | None = None, dt: float = DEFAULT_DT, *, use: str = "use"
) -> SampledMotion:
    """Any planned motion as a :class:`SampledMotion`.

    Args:
        motion: A plan that provides the protocol (:class:`cartesian.CartesianPlan`,
            :class:`kinplan.program.ProgramPlan`: returned as it is), or a joint trajectory
            (``duration`` and ``sample(t)``: sampled every ``dt`` by :func:`sampled`).
        robot: The robot that moves (for a joint trajectory's tool positions).
        dt: Sampling period of a joint trajectory [s].
        use: The verb of the error message (``"play"``, ``"plot"``).

    Raises:
        InputError: ``motion`` is neither; or as :func:`sampled`.
    """
    if isinstance(motion, SampledMotion):
        return motion
    if isinstance(motion, JointTrajectory):
        return sampled(motion, robot, dt)
    raise InputError(
        f"cannot {use} a {type(motion).__name__}: give a joint Trajectory (with duration and "
        "sample(t)), a CartesianPlan or a program plan (with t, q, qd, qdd, ...: "
        "kinplan.trajectory.motion.SampledMotion), e.g. kinplan.trajectory.cubic(...) or "
        "cartesian.follow(...)"
    )


def collision_check(motion: object) -> MotionCheck | None:
    """The failed work-cell check of a plan stopped by a collision, or None.

    A :class:`cartesian.CartesianPlan` has it as ``cell_check``, a program plan on its failed
    move (``moves[k].collision``); both are :class:`kinplan.cell.MotionCheck` objects.
    """
    check = getattr(motion, "cell_check", None)
    if check is not None and not check.ok:
        return check
    for move in getattr(motion, "moves", None) or []:
        if getattr(move, "collision", None) is not None:
            return move.collision
    return None


def collision_time(motion: object, check: MotionCheck) -> float:
    """When a plan stopped by a collision fails [s] (the plan's clock).

    A plan keeps the samples before the failing one (``check.index``), so the failure lies
    after its last sample: at the failing sample, or ``check.fraction`` of the way to it when
    the check found it between the two. The failing sample's time is the collision event's
    (a Cartesian plan or move); for a program's ``ptp`` move, one sampling period ``dt`` after
    the last sample (the move's own samples are not kept).

    Args:
        motion: The plan (``t``, ``events``; a program plan's ``moves`` and ``dt``).
        check: Its failed check (:func:`collision_check`).
    """
    times = np.asarray(getattr(motion, "t", ()), dtype=float).reshape(-1)
    last = float(times[-1]) if len(times) else 0.0
    sample = None
    for move in getattr(motion, "moves", None) or []:
        if getattr(move, "collision", None) is not check:
            continue
        plan = getattr(move, "cartesian_plan", None)
        if plan is not None and plan.events:  # a lin / circ move: its own clock from t0
            sample = float(move.t0) + float(plan.events[0].t)
        elif check.index == 0:  # a ptp failing where it starts: that is its one sample
            sample = last
        else:
            sample = last + float(getattr(motion, "dt", 0.0))
        break
    if sample is None:
        events = getattr(motion, "events", None) or []
        sample = float(events[0].t) if events else last
    sample = max(sample, last)
    if not len(times):
        return sample
    return last + (float(check.fraction) if check.between else 1.0) * (sample - last)


def no_waypoints(nq: int) -> Waypoints:
    """Waypoints of a motion planned through none: zero rows of ``nq`` joints."""
    return Waypoints(np.zeros(0), np.zeros((0, nq)))


def joint_rows(robot: Robot, values: ArrayLike, what: str) -> np.ndarray:
    """``values`` as a finite float array of shape (N, robot.nq) (a 1-D array for one joint).

    Raises:
        InputError: another joint count (naming the robot's joints), NaN or inf.
    """
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 1 and robot.nq == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[1] != robot.nq:
        raise InputError(
            f"{what} has shape {arr.shape}, but {robot.name} has {robot.nq} joints "
            f"({', '.join(robot.joint_names)}); plan the motion for this robot"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} holds NaN or infinite joint values")
    return arr


def _finite_rows(values: ArrayLike, rows: int, columns: int | None, what: str) -> np.ndarray:
    """``values`` as a finite float array of ``rows`` rows (and ``columns`` columns if given)."""
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or len(arr) != rows or (columns is not None and arr.shape[1] != columns):
        wanted = f"({rows}, {columns if columns is not None else 'n'})"
        raise InputError(f"{what} have shape {arr.shape}, expected {wanted}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} hold NaN or infinite values")
    return arr


# ----------------------------------------------------------------------------------------------
# Tool tracks
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class ToolTrack:
    """The tool along a sampled motion, base frame.

    Attributes:
        positions: Tool positions (N, 3) [m].
        quaternions: Tool orientations (N, 4), (x, y, z, w), sign-continuous.
        speed: Tool linear speed (N,) [m/s].
        jacobians: Tool Jacobians (N, 6, nq), world-aligned (:meth:`kinplan.Robot.jacobian`).
    """

    positions: np.ndarray
    quaternions: np.ndarray
    speed: np.ndarray
    jacobians: np.ndarray


def tool_track(robot: Robot, q: np.ndarray, qd: np.ndarray) -> ToolTrack:
    """Tool poses, speeds and Jacobians of joint samples (one kinematics pass per sample).

    Args:
        robot: The robot.
        q: Joint positions (N, nq) [rad or m].
        qd: Joint velocities (N, nq) [rad/s or m/s].
    """
    n = len(q)
    poses, jacobians = np.empty((n, 4, 4)), np.empty((n, 6, robot.nq))
    for k in range(n):
        pose, jacobians[k] = robot.pose_and_jacobian(q[k])
        poses[k] = pose.homogeneous
    positions, quaternions = pose_to_track(poses)
    speed = np.linalg.norm(np.einsum("nij,nj->ni", jacobians[:, :3], qd), axis=1)
    return ToolTrack(positions, quaternions, speed, jacobians)


def pose_to_track(matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions (F, 3) [m] and sign-continuous quaternions (F, 4) (x, y, z, w) of 4×4 poses.

    Consecutive quaternions have a non-negative dot product, so interpolating between them (an
    animation track, a CSV column) never takes the long way round.
    """
    matrices = np.asarray(matrices, dtype=float)
    if len(matrices) == 0:
        return np.zeros((0, 3)), np.zeros((0, 4))
    quaternions = np.array([pin.Quaternion(m[:3, :3]).normalized().coeffs() for m in matrices])
    flips = np.sum(quaternions[1:] * quaternions[:-1], axis=1) < 0
    signs = np.concatenate([[1.0], np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)])
    return matrices[:, :3, 3].copy(), quaternions.reshape(-1, 4) * signs[:, None]
