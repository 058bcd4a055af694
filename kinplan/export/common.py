"""Helpers the exports share: a motion's checked samples, its joint names, its tool along the
motion, writing a text file, and the ``kinplan.export`` logger.

Imports nothing else of :mod:`kinplan.export` (the bottom of its chain).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from kinplan import checks
from kinplan.errors import InputError, KinplanError
from kinplan.trajectory.motion import SampledMotion, ToolTrack, tool_track

logger = logging.getLogger("kinplan.export")
"""The exports' logger (one name for the package: ``kinplan.export``)."""

__all__ = [
    "checked_joint_names",
    "logger",
    "motion_samples",
    "name_list",
    "plan_tool_track",
    "write_text",
]


def motion_samples(
    plan: SampledMotion, what: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The samples (t, q, qd, qdd) of a motion, finite and consistent; InputError otherwise."""
    if not isinstance(plan, SampledMotion):
        raise InputError(
            f"{what} takes a planned motion (kinplan.motion.SampledMotion: a program or Cartesian "
            f"plan, or kinplan.motion.sampled(trajectory, robot)), got {type(plan).__name__}"
        )
    t = checks.vector(plan.t, "the plan's times", unit="s")
    if len(t) == 0:
        return t, np.zeros((0, 0)), np.zeros((0, 0)), np.zeros((0, 0))
    q = checks.rows(plan.q, "the plan's positions", np.shape(plan.q)[-1])
    qd = checks.rows(plan.qd, "the plan's velocities", q.shape[1])
    qdd = checks.rows(plan.qdd, "the plan's accelerations", q.shape[1])
    if not len(q) == len(qd) == len(qdd) == len(t):
        raise InputError(
            f"{what}: the plan has {len(t)} times but {len(q)}, {len(qd)}, {len(qdd)} rows of "
            "positions, velocities, accelerations"
        )
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        k = int(np.argmax(steps <= 0.0))
        raise InputError(
            f"{what}: the plan's times must increase, but sample {k + 1} is at {t[k + 1]!r} s "
            f"after {t[k]!r} s"
        )
    if plan.robot is not None and q.shape[1] != plan.robot.nq:
        raise InputError(
            f"{what}: the plan has {q.shape[1]} joints, its robot {plan.robot.name} {plan.robot.nq}"
        )
    return t, q, qd, qdd


def checked_joint_names(
    plan: SampledMotion, joint_names: Sequence[str] | None, n: int
) -> list[str]:
    """``joint_names`` checked as one name per joint (``n``), default the robot's; InputError
    otherwise (no names for a motion without a robot)."""
    if joint_names is None:
        if plan.robot is None:
            raise InputError(
                "joint_names is needed for a motion without a robot: give one name per joint"
            )
        return list(plan.robot.joint_names)
    names = name_list(joint_names, "joint_names", n)
    if len(names) != n:
        raise InputError(f"joint_names must hold {n} names (one per joint), got {len(names)}")
    return names


def name_list(names: object, what: str, n: int | None = None) -> list[str]:
    """``names`` as a list of non-empty strings; InputError otherwise."""
    count = "names" if n is None else f"{n} names"
    if isinstance(names, (str, bytes)) or not isinstance(names, (Sequence, np.ndarray)):
        raise InputError(f"{what} must be a list of {count}, got {checks.describe(names)}")
    return [checks.text(name, f"{what}[...]") for name in names]


def plan_tool_track(plan: SampledMotion, what: str) -> ToolTrack:
    """The tool along ``plan`` from its robot's kinematics; InputError without a robot."""
    if not isinstance(plan, SampledMotion):
        raise InputError(
            f"{what} takes a planned motion (kinplan.motion.SampledMotion: a program or Cartesian "
            f"plan, or kinplan.motion.sampled(trajectory, robot)), got {type(plan).__name__}"
        )
    if plan.robot is None:
        raise InputError(
            f"{what} needs the motion's robot for the tool poses: sample the trajectory with it, "
            "kinplan.motion.sampled(trajectory, robot)"
        )
    return tool_track(plan.robot, plan.q, plan.qd)


def write_text(target: Path, text: str, what: str) -> None:
    """Write ``text`` to ``target`` (its folder created) and log it; KinplanError naming
    ``what`` when it cannot be written."""
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise KinplanError(f"cannot write the {what} file {target}: {exc}") from exc
    logger.info("wrote %s (%d bytes)", target, len(text))
