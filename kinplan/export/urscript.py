"""URScript for a Universal Robots arm: :func:`urscript` / :func:`write_urscript`, a program that
goes to the start with ``movej`` and replays the motion with one ``servoj`` per controller
period (:func:`kinplan.export.servo.servo_samples`); :func:`ur_arm_problem` says whether a robot
is a UR arm.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from kinplan import checks
from kinplan.errors import InputError
from kinplan.export.common import write_text
from kinplan.export.servo import DEFAULT_SERVO_PERIOD, servo_targets
from kinplan.export.whole_motion import whole_motion
from kinplan.motion import SampledMotion

if TYPE_CHECKING:
    from kinplan.robot import Robot

__all__ = ["UR_JOINT_NAMES", "ur_arm_problem", "urscript", "write_urscript"]


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


def urscript(
    plan: SampledMotion,
    *,
    period: float = DEFAULT_SERVO_PERIOD,
    lookahead_time: float = 0.1,
    gain: float = 300.0,
    start_speed: float = 0.5,
    start_acceleration: float = 1.0,
) -> str:
    """A URScript program that replays a whole motion on a Universal Robots arm.

    The program ``kinplan_motion`` goes to the motion's start with ``movej``, then commands one
    ``servoj`` target per ``period``, the targets of :func:`servo_samples` (``t = k · period``,
    the first the start, the last exactly the end), then holds the end for
    2 · ``lookahead_time`` (rounded up to whole periods) so the arm settles on it (``servoj``
    lags its targets by up to the lookahead time). A header comment names the robot, the
    duration, the number of samples and the kinplan version. Joint vectors are in radians,
    base to wrist 3, written in fixed point with 10 decimals (URScript has no exponent
    notation). The URDF's joint zeros must be the controller's (true for the Universal
    Robots descriptions).

    Args:
        plan: A whole motion of a UR arm (:class:`~kinplan.motion.SampledMotion` that is ok,
            with its robot).
        period: Period of the ``servoj`` stream [s] (the controller's: 0.008 for a CB3,
            0.002 for an e-Series).
        lookahead_time: ``servoj`` lookahead time [s], 0.03 to 0.2.
        gain: ``servoj`` proportional gain [-], 100 to 2000.
        start_speed: Joint speed of the ``movej`` to the start [rad/s], > 0.
        start_acceleration: Joint acceleration of the ``movej`` to the start [rad/s²], > 0.

    Returns:
        The program text (ASCII), ending with a call of ``kinplan_motion()``.

    Raises:
        InputError: not a motion, a failed plan (a controller must not run a partial motion),
            no robot or not a UR arm, or a parameter out of its range.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`).
    """
    from kinplan import __version__

    lookahead = checks.number(lookahead_time, "lookahead_time", minimum=0.03, maximum=0.2, unit="s")
    servo_gain = checks.number(gain, "gain", minimum=100.0, maximum=2000.0)
    speed = checks.number(start_speed, "start_speed", positive=True, unit="rad/s")
    acceleration = checks.number(
        start_acceleration, "start_acceleration", positive=True, unit="rad/s²"
    )
    robot = _ur_robot(plan, "urscript")
    times, targets = servo_targets(plan, period, "urscript")
    step = float(period)
    hold = math.ceil(2.0 * lookahead / step - 1e-9)
    servo = f"t={_script_number(step)}, lookahead_time={_script_number(lookahead)}, " + (
        f"gain={_script_number(servo_gain)}"
    )
    header = [
        f"# kinplan {__version__}: {plan.description} of {robot.name} (Universal Robots arm)",
        f"# duration {times[-1]:.6f} s; {len(plan.t)} plan samples; {len(times)} servoj targets "
        f"every {step:g} s (t = k * {step:g} s, the last at the end), then the end held "
        f"{hold} periods",
        f"# joints [rad]: {', '.join(robot.joint_names)}",
        "# Check the motion in the cell (kinplan run ... --html) before running it.",
    ]
    lines = [_ascii(line) for line in header]
    lines += [
        "def kinplan_motion():",
        f"  movej({_script_list(targets[0])}, a={_script_number(acceleration)}, "
        f"v={_script_number(speed)})",
    ]
    lines += [f"  servoj({_script_list(q)}, {servo})" for q in targets]
    lines += [
        f"  kinplan_end = {_script_list(targets[-1])}",
        "  kinplan_hold = 0",
        f"  while kinplan_hold < {hold}:",
        f"    servoj(kinplan_end, {servo})",
        "    kinplan_hold = kinplan_hold + 1",
        "  end",
        "end",
        "kinplan_motion()",
    ]
    return "\n".join(lines) + "\n"


def write_urscript(
    path: str | os.PathLike[str],
    plan: SampledMotion,
    *,
    period: float = DEFAULT_SERVO_PERIOD,
    lookahead_time: float = 0.1,
    gain: float = 300.0,
    start_speed: float = 0.5,
    start_acceleration: float = 1.0,
) -> Path:
    """Write :func:`urscript` of a whole motion of a UR arm to a file (usually ``.script``).

    Args:
        path: File to write (its folder is created).
        plan: A whole motion of a UR arm, with its robot.
        period: Period of the ``servoj`` stream [s].
        lookahead_time: ``servoj`` lookahead time [s], 0.03 to 0.2.
        gain: ``servoj`` proportional gain [-], 100 to 2000.
        start_speed: Joint speed of the ``movej`` to the start [rad/s].
        start_acceleration: Joint acceleration of the ``movej`` to the start [rad/s²].

    Returns:
        The written path.

    Raises:
        InputError: as :func:`urscript`.
        KinplanError: the file cannot be written.
    """
    target = Path(checks.file_path(path, "path"))
    text = urscript(
        plan,
        period=period,
        lookahead_time=lookahead_time,
        gain=gain,
        start_speed=start_speed,
        start_acceleration=start_acceleration,
    )
    write_text(target, text, "URScript")
    return target


def _ur_robot(plan: SampledMotion, what: str) -> Robot:
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


def _script_number(value: float) -> str:
    """A float as URScript reads it: fixed point, 10 decimals at most, no exponent."""
    text = f"{value:.10f}".rstrip("0")
    text = text + "0" if text.endswith(".") else text
    return "0.0" if text == "-0.0" else text


def _script_list(values: np.ndarray) -> str:
    return "[" + ", ".join(_script_number(v) for v in values.tolist()) + "]"


def _ascii(text: str) -> str:
    """``text`` with anything outside printable ASCII replaced by ``?`` (a comment line)."""
    return "".join(c if " " <= c <= "~" else "?" for c in text)
