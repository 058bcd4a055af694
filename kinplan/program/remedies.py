"""How a failed move of a program is worded: where it failed and what the program's author can
do about it (the reasons :class:`~kinplan.program.build.MotionBuilder` records and raises).

In :mod:`kinplan.program`, after :mod:`~kinplan.program.record` and before
:mod:`~kinplan.program.seams` and :mod:`~kinplan.program.build`; of the program package it
imports only :mod:`~kinplan.program.schema`.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

import cartesian
from kinplan.ik import IKResult
from kinplan.program.schema import JOIN_TOLERANCE, MAX_SAMPLES
from kinplan.trajectory._profiles import round_up

__all__ = [
    "SMALL_GAP",
    "ik_reason",
    "jump_reason",
    "program_remedy",
    "ptp_collision_reason",
    "start_gap_reason",
    "start_turn_reason",
    "too_many_samples_reason",
    "torch_start_reason",
    "trajectory_remedy",
    "where",
]

SMALL_GAP = 1e-2
"""A join gap below this [rad] is a start pose not quite reached, not another branch."""


def where(position: np.ndarray) -> str:
    text = ", ".join(f"{x:.3f}" for x in position).replace("-0.000", "0.000")
    return f"({text}) m"


def program_remedy(plan: cartesian.CartesianPlan) -> str:
    """What the author of a program can do about a failed move's first event (the event's own
    remedy names :func:`cartesian.follow`'s arguments)."""
    event = plan.events[0]
    if event.kind == "acceleration_limit":  # follow's own words, without its retime= option
        return event.remedy.split(", or retime")[0]
    if event.kind == "velocity_limit":
        factor = plan.peak_speed_ratio
        return (
            f"slow this move down by a factor of at least {factor:.3g} (a lower speed or a longer "
            "duration on the move)"
        )
    if event.kind in ("joint_limit", "jump"):
        return (
            "reach the move's start in another configuration (a ptp to joint values before it), "
            "or move its points"
        )
    if event.kind == "unreachable":
        return "move the move's points into the arm's workspace"
    if event.kind == "collision":
        check = plan.cell_check
        if check is not None and check.kind == "self":  # no obstacle is involved
            return (
                "the arm would hit itself: move the move's points, or reach the move's start in "
                "another configuration (a ptp to joint values before it)"
            )
        return (
            "move the move's points or the obstacle (obstacles:), or reach the move's start in "
            "another configuration (a ptp to joint values before it)"
        )
    return event.remedy


def ik_reason(position: np.ndarray, result: IKResult) -> str:
    """A ptp goal at ``position`` [m] without an IK solution (``result`` the closest found)."""
    return (
        f"ik: no inverse kinematics solution for {where(position)} within the joint "
        f"limits (the closest found is {result.position_error:.4f} m, "
        f"{result.rotation_error:.3f} rad away); move the point"
    )


def trajectory_remedy(scale: float) -> str:
    """What to do about a given joint trajectory outside the limits: slow it down by ``scale``
    (rounded up), or keep it within the joint limits when no time scale helps (inf)."""
    remedy = "keep it within the joint limits"
    if math.isfinite(scale):
        factor = round_up(scale * (1.0 + 1e-9), 4)
        remedy = f"slow it down by a factor of at least {factor:g} (its time scaled)"
    return remedy


def ptp_collision_reason(kind: str | None, s: float, message: str) -> str:
    """A ptp move that collides at ``s`` (share of the move), ``kind`` ``self`` or ``obstacle``
    (its collision event's ``message``)."""
    fix = (
        "move a point of the move, or go through joint values that keep the arm "
        "clear of itself (a ptp through several points)"
        if kind == "self"
        else "move a point of the move, add a via point around the obstacle, use lin moves, or "
        "give the move avoid: true (plans it around the obstacles)"
    )
    return f"collision at s = {s:.2f}: {message}; {fix}"


def too_many_samples_reason(what: str, dt: float, total: float) -> str:
    """A move (``what``) that would take the program to ``total`` samples at period ``dt`` [s],
    more than :data:`~kinplan.program.schema.MAX_SAMPLES`."""
    return (
        f"invalid: {what} at dt = {dt:g} s would take the program to {total:.3g} "
        f"samples (at most {MAX_SAMPLES:,}); shorten it or plan with a larger dt"
    )


def start_gap_reason(start: np.ndarray, here: np.ndarray, gap: float) -> str:
    """A path that starts at ``start``, ``gap`` [m] from the tool at ``here`` [m]."""
    return (
        f"invalid: the path starts at {where(start)}, {gap:.4f} m away "
        f"from the tool at {where(here)}; move there first (ptp or lin)"
    )


def start_turn_reason(turn: float) -> str:
    """A path that starts with the tool turned by ``turn`` [rad] from its current orientation."""
    return (
        f"invalid: the path starts with a tool orientation {turn:.3f} rad away from the "
        "current one; reorient first (ptp or lin to the path's start pose)"
    )


def jump_reason(gap: float, offset: float | None, turn: float) -> str:
    """A path whose first configuration is ``gap`` [rad] from the current one: on another branch
    (``offset`` None), or the tool ``offset`` [m] and ``turn`` [rad] from the path's start pose
    (a gap below :data:`SMALL_GAP`)."""
    if offset is None:
        return (
            "jump: the path's first configuration is on another branch than the current "
            "one; move to the path start with a lin move first"
        )
    return (
        f"jump: the path's first configuration is {gap:.3g} rad from the current one "
        f"(at most {JOIN_TOLERANCE:g} rad): the tool is {offset:.3g} m and "
        f"{turn:.3g} rad from the path's start pose; reach that pose exactly first "
        "(its xyz and orientation, e.g. with a lin move to it)"
    )


def torch_start_reason(start: pin.SE3, turn: float) -> str:
    """A torch seam whose ``start`` pose is ``turn`` [rad] from the tool's orientation, printing
    the orientation with the digits that make pasting it work."""
    rpy = np.degrees(pin.rpy.matrixToRpy(start.rotation))
    text = ", ".join(f"{a:.6f}" for a in rpy).replace("-0.000000", "0.000000")
    return (
        f"invalid: the torch angles put the tool at rpy_deg [{text}] at the seam start, "
        f"{np.degrees(turn):.3g}° away from the tool's orientation; reach the seam start "
        f"with that orientation first (rpy_deg: [{text}] on the approach point)"
    )
