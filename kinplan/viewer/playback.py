"""A motion sampled for playback: key frames, the paths to draw and the caption.

:func:`playback` reads any motion through :func:`kinplan.motion.as_sampled_motion` and gives a
:class:`Playback`: the robot's joint positions at ``fps`` key frames per second of real time
(a joint trajectory evaluated at them, a plan's samples interpolated), the tool paths planned
(the part reached and the part not reached), the tool trace a plan achieved, the waypoints, the
last good configuration of a plan stopped by an event, the failing instant of a plan stopped by
a collision in a work cell (:class:`Collision`: the playback ends there, at the colliding
configuration), and the caption. :func:`marker_points` reads the taught points to mark.

Frames and units: positions in the robot's base (world) frame [m], times [s], joints [rad or m].
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinplan.checks import describe, floats
from kinplan.errors import InputError
from kinplan.trajectory import time_grid
from kinplan.trajectory.motion import (
    MotionLike,
    SampledMotion,
    ToolPath,
    as_sampled_motion,
    collision_check,
    collision_time,
    joint_rows,
)

if TYPE_CHECKING:
    from kinplan.model.robot import Robot

__all__ = [
    "DEFAULT_FPS",
    "PATH_SAMPLES",
    "Collision",
    "Markers",
    "Playback",
    "arc_intervals",
    "marker_points",
    "playback",
    "positive",
    "seam_rolls",
]

logger = logging.getLogger(__name__)

DEFAULT_FPS = 30.0
"""Key frames per second of the animation [1/s]; the browser interpolates between them."""

PATH_SAMPLES = 400
"""Points drawn along a whole tool path (a share of them for a part of it)."""

Markers = Sequence[pin.SE3 | ArrayLike] | Mapping[str, pin.SE3 | ArrayLike] | None
"""Points to mark [m], base frame: 3-vectors (or SE3 / 4×4 poses), in a list or by name."""


@dataclass(frozen=True)
class Collision:
    """Where a plan stopped by a collision in a work cell fails, on the playback's clock.

    Attributes:
        t: The failing instant [s] from the playback's start: the failing sample, or the
            configuration between two samples where the work-cell check found the failure.
        q: The configuration there (nq,) (:attr:`kinplan.cell.MotionCheck.q`).
        bodies: The two bodies (robot link or tool body, then the other link or the obstacle).
        point: Midway between the pair's nearest (or deepest) points, world frame [m], or None.
    """

    t: float
    q: np.ndarray
    bodies: tuple[str, str]
    point: np.ndarray | None = None


@dataclass
class Playback:
    """A motion sampled for display (all positions in the base frame [m]).

    Attributes:
        t: Key times (F,) [s], from 0.
        q: Joint positions at the key times (F, nq).
        planned: Tool paths to draw (M, 3) each, blue.
        achieved: Tool positions a plan reached (K, 3), green; None for a joint trajectory.
        failed: Parts of the planned paths not reached (L, 3) each, red.
        last_good: Joint positions of the last good sample of a plan stopped by an event.
        via: Tool positions at the waypoints (V, 3).
        caption: What the motion is, and where and why it failed (the first line in bold).
        collision: The failing instant of a plan stopped by a collision (the last key frame,
            at the colliding configuration), or None.
        moves: (start time [s], "number. label") of each move of a program, in time order
            (shown in the playback bar); empty for a single motion.
        roll: The torch roll :func:`cartesian.plan_seam` chose, per seam: (times [s] on the
            playback's clock, roll [deg] about the torch axis relative to the taught torch)
            (shown in the playback bar and the caption); empty when no roll was searched.
        arc: (on, off) times [s] on the playback's clock of each interval the arc is on (a
            program's ``arc:`` / ``weld:`` events, :func:`arc_intervals`): the playback bar
            shows "arc on" and the torch tip glows then; empty without an arc.
    """

    t: np.ndarray
    q: np.ndarray
    planned: list[np.ndarray] = field(default_factory=list)
    achieved: np.ndarray | None = None
    failed: list[np.ndarray] = field(default_factory=list)
    last_good: np.ndarray | None = None
    via: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    caption: list[str] = field(default_factory=list)
    collision: Collision | None = None
    moves: list[tuple[float, str]] = field(default_factory=list)
    roll: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    arc: list[tuple[float, float]] = field(default_factory=list)

    @property
    def duration(self) -> float:
        """Duration of the playback [s]."""
        return float(self.t[-1])

    def points(self) -> list[np.ndarray]:
        """Every drawn point, shape (n, 3) each (for framing the camera)."""
        extra = [self.achieved] if self.achieved is not None else []
        return [*self.planned, *self.failed, *extra, self.via]


MAX_FPS = 1000.0
"""Most key frames per second of an animation [1/s] (a screen shows 60 to 240)."""


def positive(name: str, value: object, maximum: float | None = None) -> float:
    """``value`` as a positive finite float (at most ``maximum`` when given).

    Raises:
        InputError: naming ``name``, for anything else (booleans, text, 0, NaN, inf, beyond
            the maximum).
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{name} must be a positive number, got {describe(value)}")
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive number, got {value!r}")
    if maximum is not None and value > maximum:
        raise InputError(f"{name} must be at most {maximum:g}, got {value!r}")
    return float(value)


def playback(robot: Robot, motion: MotionLike, fps: float) -> Playback:
    """Sample ``motion`` for playback at ``fps`` key frames per second.

    Args:
        robot: The robot that moves.
        motion: A joint trajectory, a Cartesian plan or a program plan of this robot
            (:func:`kinplan.motion.as_sampled_motion`).
        fps: Key frames per second [1/s].

    Raises:
        InputError: not a motion, or not one of this robot (joint count, NaN, times).
    """
    fps = positive("fps", fps, MAX_FPS)
    sampled = as_sampled_motion(motion, robot, 1.0 / fps, use="play")
    joint = sampled.kind == "joint"
    times = np.asarray(sampled.t, dtype=float).reshape(-1)
    q = joint_rows(robot, sampled.q, "the trajectory's samples" if joint else "the plan's q")
    if len(q) > len(times):
        raise InputError(f"the plan has {len(q)} rows of q but only {len(times)} times t")
    times = times[: len(q)]
    if len(times) and (not np.all(np.isfinite(times)) or np.any(np.diff(times) < 0)):
        raise InputError("the plan's times t must be finite and non-decreasing")
    collision = _collision(motion, robot, times)
    if len(q) == 0 and collision is not None:  # failed at its first sample: show it there
        t, frames = np.zeros(1), collision.q[None, :]
    elif len(q) == 0:
        logger.warning("the plan has no achieved sample; showing the robot at its neutral pose")
        t, frames = np.zeros(1), robot.neutral()[None, :]
    else:
        t, frames = _key_frames(times, q, fps)
        if collision is not None and collision.t > t[-1] + 1e-9:  # the colliding instant
            t, frames = np.append(t, collision.t), np.vstack([frames, collision.q])
    achieved = None
    if not joint and len(q):  # a plan: the tool positions it reached
        achieved = sampled.tool_positions
        if achieved is None:
            achieved = robot.tool_positions(q[:: max(1, len(q) // 2000)])
    planned, failed = [], []
    for piece in sampled.planned_paths:
        planned.append(_path_points(piece.path, 0.0, piece.reached))
        failed.append(_path_points(piece.path, piece.reached, 1.0))
    if not any(p is not None for p in planned) and achieved is not None:
        planned = [achieved]  # no Cartesian path: the joint motion's tool path
    start = float(times[0]) if len(times) else 0.0
    rolls = [(times_ - start, degrees) for times_, degrees in seam_rolls(motion)]
    caption = _caption(robot, sampled, float(t[-1]), None if collision is None else collision.t)
    if rolls:
        low = min(float(d.min()) for _, d in rolls)
        high = max(float(d.max()) for _, d in rolls)
        caption.append(
            f"torch roll {low:.0f}° … {high:.0f}° along the seam{'s' if len(rolls) > 1 else ''} "
            "(plan_seam; the bar shows it at the current time)".replace("-", "−")
        )
    arcs = [(on - start, off - start) for on, off in arc_intervals(motion)]
    if arcs:
        spans = ", ".join(f"{on:.2f}–{off:.2f} s" for on, off in arcs)
        caption.append(f"arc on {spans} (the bar shows it; the torch tip glows)")
    return Playback(
        t=t,
        q=frames,
        planned=[p for p in planned if p is not None],
        achieved=achieved,
        failed=[p for p in failed if p is not None],
        last_good=q[-1] if (not sampled.ok and len(q)) else None,
        via=_via_points(robot, sampled),
        caption=caption,
        collision=collision,
        moves=[
            (float(m.t0), f"{getattr(m, 'numbers', m.number)}. {m.label}") for m in sampled.moves
        ],
        roll=rolls,
        arc=arcs,
    )


def arc_intervals(motion: object) -> list[tuple[float, float]]:
    """(on, off) program times [s] of each interval a program plan's arc is on, from its
    ``io_events`` of kind ``"arc"`` in time order (``arc: on|off``, ``weld: {job: N}``); an
    arc still on at the plan's end (a failed plan) lasts to its last sample. Empty for a motion
    without ``io_events``."""
    events = sorted(getattr(motion, "io_events", None) or [], key=lambda e: float(e.t))
    times = getattr(motion, "t", None)
    end = float(np.asarray(times, dtype=float)[-1]) if times is not None and len(times) else None
    intervals: list[tuple[float, float]] = []
    on: float | None = None
    for event in events:
        if event.kind != "arc":
            continue
        if event.value and on is None:
            on = float(event.t)
        elif not event.value and on is not None:
            intervals.append((on, float(event.t)))
            on = None
    if on is not None and end is not None and end > on:
        intervals.append((on, end))
    return intervals


def seam_rolls(motion: object) -> list[tuple[np.ndarray, np.ndarray]]:
    """(times [s], torch roll [deg]) of every seam whose roll :func:`cartesian.plan_seam`
    chose: a Cartesian plan's own ``roll`` (at its samples' times), or a program plan's moves'
    (their plans' times shifted by each move's start); empty when there is none."""
    roll = getattr(motion, "roll", None)
    times = getattr(motion, "t", None)
    if roll is not None and times is not None and 0 < len(roll) <= len(times):
        return [
            (np.asarray(times, dtype=float)[: len(roll)], np.degrees(np.asarray(roll, dtype=float)))
        ]
    pieces = []
    for move in getattr(motion, "moves", None) or []:
        seam = getattr(move, "cartesian_plan", None)
        roll = getattr(seam, "roll", None)
        if seam is not None and roll is not None and len(roll):
            t = float(move.t0) + np.asarray(seam.t, dtype=float)[: len(roll)]
            pieces.append((t, np.degrees(np.asarray(roll, dtype=float))))
    return pieces


def _collision(motion: object, robot: Robot, times: np.ndarray) -> Collision | None:
    """The failing instant of a plan stopped by a collision, on the playback's clock
    (:func:`kinplan.motion.collision_time`)."""
    check = collision_check(motion)
    if check is None or check.q is None or check.index is None or check.bodies is None:
        return None
    q = joint_rows(robot, np.asarray(check.q)[None, :], "the collision's configuration")[0]
    point = None if check.point is None else np.asarray(check.point, dtype=float)
    start = float(times[0]) if len(times) else 0.0
    return Collision(collision_time(motion, check) - start, q, check.bodies, point)


def _key_frames(times: np.ndarray, q: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Key times 0, 1/fps, ..., the last exactly at the end [s], and the joints there: the
    samples themselves when they are the key frames, else interpolated between them."""
    t = time_grid(float(times[-1] - times[0]), 1.0 / fps)
    if len(t) == len(times) and np.array_equal(t + times[0], times):
        return t, q
    frames = np.column_stack([np.interp(t + times[0], times, q[:, j]) for j in range(q.shape[1])])
    return t, frames


def _via_points(robot: Robot, motion: SampledMotion) -> np.ndarray:
    """Tool positions at the motion's waypoints, shape (V, 3) [m]."""
    positions = motion.waypoints.positions
    if len(positions) == 0:
        return np.zeros((0, 3))
    return robot.tool_positions(joint_rows(robot, positions, "the waypoints"))


def _path_points(path: ToolPath, s0: float, s1: float) -> np.ndarray | None:
    """Points of ``path`` for path fractions from s0 to s1, shape (n, 3) [m]; None if empty."""
    if s1 <= s0:
        return None
    count = max(2, int(round(PATH_SAMPLES * (s1 - s0))))
    points = np.asarray(path.position(np.linspace(s0, s1, count)), dtype=float)
    if points.shape != (count, 3) or not np.all(np.isfinite(points)):
        raise InputError(
            f"path.position(s) must return finite (len(s), 3) points, got {points.shape}"
        )
    return points


def _caption(
    robot: Robot, motion: SampledMotion, duration: float, collision_t: float | None = None
) -> list[str]:
    """Caption lines: what the motion is, and where and why it failed.

    A collision's time is the instant the playback turns the bodies red (``collision_t``, on
    the playback's clock: between the plan's last sample and the failing one), rounded up to
    the millisecond, so that seeking to the printed time (``#t=``) shows them red.
    """
    if motion.ok:
        return [f"{robot.name} · {motion.description} · {duration:.2f} s"]
    event = motion.events[0] if motion.events else None
    status = motion.status or (event.kind if event is not None else "") or "failed"
    where = ""
    if event is not None:
        of = "of the move" if motion.kind == "program" else "of the path"
        when = f"{float(event.t):.2f}"
        if collision_t is not None:
            when = f"{math.ceil(float(collision_t) * 1000.0 - 1e-6) / 1000.0:.3f}"
        where = f" at {100 * float(event.s):.0f} % {of} (t = {when} s)"
    lines = [f"{robot.name} · {motion.description} · {status}{where}"]
    if event is not None and event.message:
        lines.append(str(event.message))
    return lines


def marker_points(markers: Markers) -> list[tuple[str, np.ndarray]]:
    """Named positions [m] from a list of points or a dict name -> point (SE3, 4×4 or 3-vector).

    Raises:
        InputError: a marker that is not a finite position or pose.
    """
    if markers is None:
        return []
    if isinstance(markers, (str, bytes)) or not isinstance(markers, (Mapping, Iterable)):
        raise InputError(
            "markers must be a list of positions [m] (3-vectors, SE3 or 4×4 poses) or a dict "
            f"name -> position, got {describe(markers)}"
        )
    if isinstance(markers, Mapping):
        items: Iterable[tuple[object, object]] = markers.items()
    elif isinstance(markers, np.ndarray) and markers.ndim == 1:
        items = [("p0", markers)]
    else:
        items = ((f"p{k}", value) for k, value in enumerate(markers))
    points = []
    for name, value in items:
        wanted = "a position 3-vector [m] (or an SE3 / 4×4 pose)"
        if isinstance(value, pin.SE3):
            position = np.array(value.translation)
        else:
            arr = floats(value, f"marker {name!r}", wanted)
            position = arr[:3, 3] if arr.shape == (4, 4) else arr
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise InputError(f"marker {name!r} must be {wanted}, got {describe(value)}")
        points.append((str(name).replace("/", "_"), position))
    return points
