"""What a refused seam plan says: where no torch orientation within the tolerances works, or
where the candidates cannot be joined, and why (:func:`empty_stretch`, :func:`blocked_event`),
as a plan without samples (:func:`refused`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from cartesian.events import Event, Status
from cartesian.paths import Path
from cartesian.plan import CartesianPlan
from cartesian.seam_ladder import Blocked, Ladder
from kinplan.model.robot import Robot

__all__ = ["blocked_event", "empty_stretch", "refused"]

#: Share of a joint's speed limit a waypoint-to-waypoint change may use (the smooth law
#: between waypoints moves faster than their average): the ladder's speed caps.
SPEED_MARGIN = 0.7


def _range(s: np.ndarray, first: int, last: int) -> str:
    return f"s {s[first]:.2f}–{s[last]:.2f}" if last > first else f"s {s[first]:.2f}"


def empty_stretch(ladder: Ladder, s: np.ndarray, has_start: bool, names: list[str]) -> Event | None:
    """The event of the first stretch of waypoints without any candidate, or None."""
    c = ladder.candidates
    empty = np.logical_not(c.valid.reshape(len(s), -1).any(axis=1))
    if has_start:
        empty[0] = False
    if not empty.any():
        return None
    first = int(np.flatnonzero(empty)[0])
    last = first
    while last + 1 < len(s) and empty[last + 1]:
        last += 1
    part = slice(first, last + 1)
    counts = c.counts
    what = "every roll" if c.roll.size > 1 else "the roll"
    if c.tilt.any():
        what += " and tilt within the tolerances"
    joints = _joint_names(names, counts["limit_joint"][part].sum(axis=0))
    if counts["solved"][part].sum() == 0:
        kind = Status.UNREACHABLE
        why = (
            f"no IK solution within the joint limits for {what}"
            if c.limited_ik
            else f"no IK solution for {what} (out of the arm's reach)"
        )
    elif counts["limits"][part].sum() == 0:
        kind, why = Status.JOINT_LIMIT, f"{what} puts {joints} beyond its limits"
    elif counts["singular"][part].sum() == 0:
        kind, why = Status.SINGULAR, f"{what} puts the arm at a singularity"
    else:
        bodies = ", ".join(f"{a} into {b}" for a, b in list(c.pairs)[:2])
        kind, why = Status.COLLISION, f"{what} puts {bodies or 'the robot into the cell'}"
    remedy = "widen work_tolerance / travel_tolerance, "
    remedy += "" if c.roll.size > 1 else "free the roll (roll='free'), "
    remedy += "or move the seam or the robot's base"
    return Event(
        kind, 0.0, float(s[first]), 0, f"{_range(s, first, last)}: {why}", remedy=remedy
    )  # fmt: skip


def _joint_names(names: list[str], counts: np.ndarray) -> str:
    """The joints that most often put the solutions beyond their limits."""
    top: list[int] = (
        np.flatnonzero(counts >= 0.5 * counts.max()).tolist() if counts.max() > 0 else []
    )
    labels = [names[j] for j in top]
    return " or ".join(labels) if labels else "a joint"


def blocked_event(robot: Robot, blocked: Blocked, s: np.ndarray, timing: Any) -> Event:
    k = blocked.step
    name = robot.joint_names[blocked.joint]
    where = f"between s {s[k - 1]:.2f} and {s[k]:.2f}"
    if blocked.kind == "velocity_limit":
        kind = Status.VELOCITY_LIMIT
        why = (
            f"every continuation needs {name} at {blocked.ratio / SPEED_MARGIN:.2f}× or more of "
            "its speed limit at the seam's speed"
        )
        remedy = "lower the speed, retime=True, or widen the tolerances"
    elif blocked.kind == "joint_limit":
        kind = Status.JOINT_LIMIT
        why = f"every continuation winds {name} beyond its limits"
        remedy = "free the roll, widen the tolerances, or split the seam"
    else:
        kind = Status.JUMP
        why = (
            f"configurations exist on both sides, but none joins them without a branch flip "
            f"({name} would jump)"
        )
        remedy = "widen the tolerances, free the roll, or split the seam there"
    t = float(np.interp(s[k], timing.s, timing.t))
    return Event(kind, t, float(s[k]), 0, f"{where}: {why}", remedy=remedy)


def refused(robot: Robot, path: Path, event: Event, singular_threshold: float) -> CartesianPlan:
    """A plan without samples, stopped by ``event`` (the search found no way)."""
    nq = robot.nq
    event.position = path.position(np.array([event.s]))[0]
    plan = CartesianPlan(
        t=np.zeros(0), q=np.zeros((0, nq)), qd=np.zeros((0, nq)), qdd=np.zeros((0, nq)),
        s=np.zeros(0), ok=False, status=event.kind, fraction=0.0, events=[event],
        max_deviation=0.0, min_manipulability=0.0, duration=0.0, path=path,
        position_only=False, singular_threshold=singular_threshold,
        tool_positions=np.zeros((0, 3)), manipulability=np.zeros(0), robot=robot,
    )  # fmt: skip
    plan.roll, plan.tilt = np.zeros(0), np.zeros((0, 2))
    return plan
