"""What URScript needs of a robot and how it writes numbers: :data:`UR_JOINT_NAMES`,
:func:`ur_arm_problem`, :func:`ur_robot`, :func:`script_number`, :func:`script_list`,
:func:`script_pose`, :func:`ascii_comment`, :func:`io_statement`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.errors import InputError
from kinplan.export.whole_motion import whole_motion
from kinplan.trajectory.motion import SampledMotion

if TYPE_CHECKING:
    from kinplan.model.robot import Robot

__all__ = [
    "UR_JOINT_NAMES",
    "ascii_comment",
    "io_statement",
    "script_list",
    "script_number",
    "script_pose",
    "ur_arm_problem",
    "ur_robot",
]


UR_JOINT_NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
"""Joints of a Universal Robots arm, base to wrist 3: the order of URScript joint vectors."""


def ur_arm_problem(robot: Robot) -> str:
    """Why ``robot`` is not a Universal Robots arm URScript can drive, or "" when it is one.

    A UR arm has exactly the six joints :data:`UR_JOINT_NAMES` in that order, possibly all
    with one common prefix (``left_shoulder_pan_joint``, ...).
    """
    joints = getattr(robot, "joint_names", None)
    if isinstance(joints, (str, bytes)) or not isinstance(joints, (Sequence, np.ndarray)):
        raise InputError(f"robot must be a kinplan.Robot, got {checks.describe(robot)}")
    names = list(joints)
    first = UR_JOINT_NAMES[0]
    if len(names) == len(UR_JOINT_NAMES) and names[0].endswith(first):
        prefix = names[0][: len(names[0]) - len(first)]
        if names == [prefix + name for name in UR_JOINT_NAMES]:
            return ""
    locked = robot.locked_joints
    held = f" and {', '.join(locked)} locked" if locked else ""
    return (
        "URScript export needs a Universal Robots arm (6 joints named shoulder_pan_joint … "
        f"wrist_3_joint); {robot.name} has {len(names)} joints ({', '.join(names)}){held}"
    )


def ur_robot(plan: SampledMotion, what: str) -> Robot:
    """The robot of a whole motion when it is a UR arm; InputError otherwise."""
    whole_motion(plan, what, limits=False)  # not a motion, or a failed plan: said first
    robot = plan.robot
    if robot is None:
        raise InputError(
            f"{what} needs the motion's robot (a UR arm): sample the trajectory with it, "
            "kinplan.motion.sampled(trajectory, robot)"
        )
    problem = ur_arm_problem(robot)
    if problem:
        raise InputError(f"{problem}; export write_joint_trajectory or write_csv instead")
    return robot


def script_number(value: float) -> str:
    """A float as URScript reads it: fixed point, 10 decimals at most, no exponent."""
    text = f"{value:.10f}".rstrip("0")
    text = text + "0" if text.endswith(".") else text
    return "0.0" if text == "-0.0" else text


def script_list(values: np.ndarray | Sequence[float]) -> str:
    """A vector as a URScript list ``[a, b, ...]``."""
    return "[" + ", ".join(script_number(float(v)) for v in np.asarray(values).tolist()) + "]"


def script_pose(pose: pin.SE3) -> str:
    """A pose as a URScript ``p[x, y, z, rx, ry, rz]``: position [m], rotation vector [rad]."""
    rotation = pin.log3(pose.rotation)
    return "p" + script_list(np.concatenate([pose.translation, rotation]))


def ascii_comment(text: str) -> str:
    """``text`` with anything outside printable ASCII replaced by ``?`` (a comment line)."""
    return "".join(c if " " <= c <= "~" else "?" for c in text)


def io_statement(event: Any, comment: bool = True) -> str:
    """The URScript statement of a program's I/O event (:class:`kinplan.program.IoEvent`),
    indented for the program's ``def``: ``write_output_integer_register(N, job)`` for a weld
    job written to an integer register, else ``set_standard_digital_out(N, True|False)``;
    with a comment naming it (``arc on``, ``weld job 3``, its key) and its time [s]."""
    output, value, kind, key = int(event.output), event.value, str(event.kind), str(event.key)
    job = getattr(event, "job", None)
    if getattr(event, "register", False):
        line = f"  write_output_integer_register({output}, {int(value)})"
        what = f"weld job {job}, {key}"
    else:
        line = f"  set_standard_digital_out({output}, {'True' if value else 'False'})"
        if kind == "arc":
            what = f"arc {'on' if value else 'off'}, {key}"
        elif kind == "job":
            what = f"weld job {job} bit, {key}"
        else:
            what = key
    if not comment:
        return line
    return ascii_comment(f"{line}  # {what}, t = {float(event.t):.3f} s")
