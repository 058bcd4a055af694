"""Planning a validated program, move after move: :func:`plan_program`, :func:`run_program`."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TypedDict

from kinplan.program.build import MotionBuilder
from kinplan.program.errors import MoveError
from kinplan.program.plan import ProgramPlan
from kinplan.program.schema import DEFAULT_DT, Move, Program
from kinplan.program.validate import load_program

__all__ = ["plan_program", "run_program"]


class _MoveOptions(TypedDict):
    duration: float | None
    speed: float | None
    profile: str
    label: str
    key: str | None


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
        robot, program.start, dt=dt, cell=program.cell, clearance=program.clearance
    )
    total = len(program.moves)
    try:
        for done, move in enumerate(program.moves):
            if progress is not None:
                progress(done, total, move.label)
            _plan_move(builder, program, move)
    except MoveError:
        pass
    if progress is not None:
        progress(total, total, "done")
    points = {name: p.tool_position(robot) for name, p in program.points.items()}
    return builder.finish(points=points, program=program)


def _plan_move(builder: MotionBuilder, program: Program, move: Move) -> None:
    robot = program.robot
    target = program.points[move.target]
    options: _MoveOptions = {
        "duration": move.duration,
        "speed": move.speed,
        "profile": move.profile,
        "label": move.label,
        "key": move.key,
    }
    if move.kind == "ptp":
        if target.joints is not None:
            builder.ptp_joints(target.joints, **options)
        else:
            builder.ptp(target.goal(robot), **options)
    elif move.kind == "lin":
        builder.lin(target.goal(robot), **options)
    else:
        assert move.via is not None  # a circ move has its via point (validated)
        via = program.points[move.via]
        builder.circ(target.goal(robot), via.goal(robot), **options)


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
