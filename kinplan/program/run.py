"""Planning a validated program, move after move: :func:`plan_program`, :func:`run_program`."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TypedDict

import numpy as np
import pinocchio as pin

from kinplan.program.build import MotionBuilder
from kinplan.program.errors import MoveError
from kinplan.program.plan import ProgramPlan
from kinplan.program.process import Signals, signal_events
from kinplan.program.schema import DEFAULT_DT, IoEvent, Move, Program
from kinplan.program.validate import load_program

__all__ = ["plan_program", "run_program"]


class _MoveOptions(TypedDict):
    duration: float | None
    speed: float | None
    profile: str
    label: str
    key: str | None
    max_acceleration: float | tuple[float, ...] | None


def plan_program(
    program: Program,
    dt: float = DEFAULT_DT,
    progress: Callable[[int, int, str], None] | None = None,
) -> ProgramPlan:
    """Plan every move of a program, each from the end state of the previous one.

    Args:
        program: A validated program (:func:`~kinplan.program.load_program`).
        dt: Sampling period [s].
        progress: Called as ``progress(done, total, label)`` before each move and at the end.

    Returns:
        The plan; ``ok`` is False when a move could not be done: ``reason`` says which move
        (number, label, key path) failed and where, and the plan holds the motion up to there.
    """
    robot = program.robot
    builder = MotionBuilder(
        robot, program.start, dt=dt, cell=program.cell, clearance=program.clearance,
        max_acceleration=program.max_acceleration,
    )  # fmt: skip
    total = len(program.moves)
    done = 0
    events: list[IoEvent] = []
    groups = _motions(program.moves)
    try:
        for number, group in enumerate(groups):
            if progress is not None:
                progress(done, total, group[0].label)
            events += _signals(program, group[0], builder.time)
            if len(group) > 1:
                _plan_blended(builder, program, group)
            else:
                following = groups[number + 1] if number + 1 < len(groups) else None
                _plan_move(builder, program, group[0], following)
            last = group[-1]
            events += _signals(program, last, builder.time, arrival=True)
            if last.dwell > 0:
                builder.dwell(last.dwell, label=f"dwell {last.dwell:g} s", key=f"{last.key}.dwell")
            done += len(group)
    except MoveError:
        pass
    if progress is not None:
        progress(total, total, "done")
    points = {name: p.tool_position(robot) for name, p in program.points.items()}
    plan = builder.finish(points=points, program=program)
    plan.io_events = events
    return plan


def _signals(program: Program, move: Move, t: float, arrival: bool = False) -> list[IoEvent]:
    """The outputs a move sets when it starts at program time ``t`` [s], or (``arrival``) the
    outputs its target point sets when the move has arrived there, at rest, at ``t``."""
    if arrival:
        point = program.points[move.target]
        signals, key = Signals(point.arc, point.io, point.job), f"points.{point.name}"
    else:
        signals, key = Signals(move.arc, move.io, move.job), move.key
    return signal_events(signals, t, move.index + 1, key, program.arc_output, program.job_output)


def _motions(moves: list[Move]) -> list[list[Move]]:
    """The moves grouped into motions: a lin/circ with ``blend`` joins the next move's motion."""
    groups: list[list[Move]] = []
    joining = False
    for move in moves:
        if joining:
            groups[-1].append(move)
        else:
            groups.append([move])
        joining = move.kind != "ptp" and move.blend is not None
    return groups


def _plan_blended(builder: MotionBuilder, program: Program, group: list[Move]) -> None:
    """Lines and arcs blended at their corners: one Cartesian motion, monitored as one."""
    robot = program.robot
    pieces = [
        (
            move.kind,
            program.points[move.target].goal(robot),
            None if move.via is None else program.points[move.via].goal(robot),
        )
        for move in group
    ]
    first = group[0]
    builder.seam(
        pieces,
        blend=[move.blend or 0.0 for move in group[:-1]],
        speed=first.speed,
        profile=first.profile,
        weave=first.weave,
        torch=first.torch,
        label=first.name or "blended " + " → ".join(f"{m.kind} {m.target}" for m in group),
        key=f"moves[{first.index}..{group[-1].index}]",
        kind="+".join(move.kind for move in group),
        max_acceleration=first.max_acceleration,
    )


def _seam_ahead(
    builder: MotionBuilder, program: Program, move: Move, group: list[Move] | None
) -> np.ndarray | None:
    """The start configuration [rad] :func:`cartesian.plan_seam` chose for the searched torch
    seam (roll free or tolerance bands) that follows the ptp ``move``, or None (no such seam
    next, or it cannot be planned: then the approach goes as taught)."""
    if group is None or move.kind != "ptp" or group[0].kind == "ptp":
        return None
    first = group[0]
    if first.torch is None or not first.torch.searched:
        return None
    robot = program.robot
    pieces = [
        (
            m.kind,
            program.points[m.target].goal(robot),
            None if m.via is None else program.points[m.via].goal(robot),
        )
        for m in group
    ]
    return builder.seam_start(
        pieces, program.points[move.target].goal(robot),
        blend=[m.blend or 0.0 for m in group[:-1]] if len(group) > 1 else 0.0,
        duration=first.duration, speed=first.speed, profile=first.profile, weave=first.weave,
        torch=first.torch, max_acceleration=first.max_acceleration,
    )  # fmt: skip


def _plan_move(
    builder: MotionBuilder, program: Program, move: Move, following: list[Move] | None = None
) -> None:
    robot = program.robot
    target = program.points[move.target]
    seam_q = _seam_ahead(builder, program, move, following)
    options: _MoveOptions = {
        "duration": move.duration,
        "speed": move.speed,
        "profile": move.profile,
        "label": move.label,
        "key": move.key,
        "max_acceleration": move.max_acceleration,
    }
    if move.kind == "ptp" and seam_q is not None and not move.through:  # to the seam's start
        if program.avoid if move.avoid is None else move.avoid:
            builder.ptp_around(
                seam_q, speed=move.speed, label=move.label, key=move.key,
                max_acceleration=move.max_acceleration,
            )  # fmt: skip
        else:
            builder.ptp_joints(seam_q, **options)
    elif move.kind == "ptp" and move.through:
        points = _joint_points(builder, program, [*move.through, move.target], move)
        if seam_q is not None:
            points[-1] = seam_q  # the seam's start configuration
        builder.ptp_through(
            points,
            duration=move.duration, speed=move.speed, profile=move.profile,
            blend=move.blend or 0.0, times=move.times, label=move.label, key=move.key,
            max_acceleration=move.max_acceleration,
        )  # fmt: skip
    elif move.kind == "ptp" and (program.avoid if move.avoid is None else move.avoid):
        (q_goal,) = _joint_points(builder, program, [move.target], move)
        builder.ptp_around(
            q_goal, speed=move.speed, label=move.label, key=move.key,
            max_acceleration=move.max_acceleration,
        )  # fmt: skip
    elif move.kind == "ptp":
        if target.joints is not None:
            builder.ptp_joints(target.joints, **options)
        else:
            builder.ptp(target.goal(robot), **options)
    elif move.kind == "lin":
        builder.lin(target.goal(robot), weave=move.weave, torch=move.torch, **options)
    else:
        assert move.via is not None  # a circ move has its via point (validated)
        via = program.points[move.via]
        builder.circ(
            target.goal(robot), via.goal(robot), weave=move.weave, torch=move.torch, **options
        )


def _joint_points(
    builder: MotionBuilder, program: Program, names: list[str], move: Move
) -> list[np.ndarray]:
    """Joint values of a ptp's points: joint points as taught, Cartesian ones by IK seeded from
    the previous point (so the motion stays on one branch)."""
    robot = program.robot
    seed = builder.q
    values = []
    for name in names:
        point = program.points[name]
        if point.joints is not None:
            q = point.joints
        else:
            goal = point.goal(robot)
            position_only = not isinstance(goal, pin.SE3)
            result = robot.ik(goal, q_seed=seed, position_only=position_only)
            if not result.success:
                builder.fail_move(
                    "ptp", move.label, move.key, status="ik",
                    why=f"ik: no inverse kinematics solution for point {name} within the joint "
                    f"limits (the closest found is {result.position_error:.4f} m away); move the "
                    "point",
                )  # fmt: skip
            q = result.q
        values.append(q)
        seed = q
    return values


def run_program(path: str | os.PathLike[str], dt: float = DEFAULT_DT) -> ProgramPlan:
    """:func:`~kinplan.program.load_program` then :func:`plan_program`.

    Args:
        path: The program file.
        dt: Sampling period [s].

    Returns:
        The plan (see :func:`plan_program`).

    Raises:
        ProgramError: the file is invalid.
    """
    return plan_program(load_program(path), dt=dt)
