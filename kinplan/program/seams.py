"""The Cartesian paths of a program's ``lin``, ``circ`` and ``seam`` moves: lines and arcs chained
from the tool pose (a goal given as a position keeps the orientation the tool has there),
corners blended, the torch held at welding angles and a weave across the seam
(:meth:`~kinplan.program.build.MotionBuilder.seam` follows them).

In :mod:`kinplan.program`, after :mod:`~kinplan.program.remedies` and before
:mod:`~kinplan.program.build`; of the program package it imports only
:mod:`~kinplan.program.checker` and :mod:`~kinplan.program.schema`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeAlias

import numpy as np
import pinocchio as pin

import cartesian
from kinplan.errors import KinplanError
from kinplan.program.checker import describe
from kinplan.program.schema import TorchSpec, WeaveSpec

__all__ = [
    "TORCH_START_TOLERANCE",
    "Goal",
    "SeamPiece",
    "goal_from",
    "seam_path",
    "start_turn",
    "torch_path",
    "weave_path",
]

Goal: TypeAlias = np.ndarray | Sequence[float] | pin.SE3
"""A Cartesian goal: a tool pose, or a tool position [m]."""
SeamPiece: TypeAlias = tuple[str, Goal, Goal | None]
"""One piece of a seam: (``"lin"``, goal, None) or (``"circ"``, goal, via)."""


TORCH_START_TOLERANCE = 1e-5
"""Largest angle between the tool and a torch seam's start orientation [rad]: an approach
orientation typed to 2 decimals of a degree (1e-4 rad off) is refused with the 6-decimal one
that joins; below it, the seam's first configuration must still join the current one within
:data:`~kinplan.program.JOIN_TOLERANCE` (else a ``jump`` that says the start pose is not quite
reached)."""


def goal_from(goal: Goal, here: pin.SE3) -> pin.SE3:
    """A Cartesian goal as a pose; a position keeps the orientation ``here``."""
    if isinstance(goal, pin.SE3):
        return goal.copy()
    position = np.asarray(goal, dtype=float)
    if position.shape != (3,) or not np.all(np.isfinite(position)):
        raise KinplanError(
            f"a Cartesian goal is a pin.SE3 or a finite position 3-vector [m], got "
            f"{describe(goal)}; use ptp_joints for joint values"
        )
    return pin.SE3(here.rotation.copy(), position)


def seam_path(
    pieces: Sequence[SeamPiece],
    blend: float | Sequence[float],
    tool_pose: pin.SE3,
    position_only: bool,
) -> cartesian.Path:
    """The pieces chained from the tool pose, corners blended (``position_only``: the arm's
    default, positions without orientation)."""
    if not pieces:
        raise KinplanError("a seam needs at least one piece (lin or circ)")
    start: pin.SE3 | np.ndarray = tool_pose
    paths: list[cartesian.Path] = []
    for kind, goal, via in pieces:
        here = start if isinstance(start, pin.SE3) else pin.SE3(np.eye(3), start)
        end = goal_from(goal, here)
        if position_only:
            start = here.translation.copy()
            end = end.translation.copy()
        if kind == "lin":
            paths.append(cartesian.Line(start, end))
        elif kind == "circ":
            if via is None:
                raise KinplanError("a circ piece needs its via point")
            middle = goal_from(via, here)
            middle = middle.translation.copy() if position_only else middle
            paths.append(cartesian.Arc(start, middle, end))
        else:
            raise KinplanError(f"a seam piece is lin or circ, got {kind!r}")
        start = end
    if len(paths) == 1:
        return paths[0]
    return cartesian.blend_corners(paths, blend)


def torch_path(path: cartesian.Path, torch: TorchSpec) -> cartesian.Path:
    """The seam held at the torch's angles (a free roll: the taught roll 0, which
    :func:`cartesian.plan_seam` then turns)."""
    roll = 0.0 if torch.roll is None else torch.roll
    return cartesian.TorchOrientation(
        path, torch.normal, torch.work_angle, torch.travel_angle, roll
    )


def weave_path(path: cartesian.Path, weave: WeaveSpec, travel_speed: float) -> cartesian.Path:
    """A ``weave:`` at a travel speed [m/s]: wavelength = speed / frequency, dwell in metres of
    travel = dwell time × speed."""
    return cartesian.Weave(
        path, weave.amplitude, travel_speed / weave.frequency, weave.pattern,
        dwell=weave.dwell * travel_speed, normal=weave.normal,
    )  # fmt: skip


def start_turn(path: cartesian.Path, pose: pin.SE3, position_only: bool) -> float:
    """Angle between a path's start orientation and the tool's [rad] (0 if not oriented)."""
    if position_only or not path.has_orientation:
        return 0.0
    return float(np.linalg.norm(pin.log3(pose.rotation.T @ path.start.rotation)))
