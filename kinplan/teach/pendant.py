"""A teach pendant in the terminal: jog the arm, record points and paths, write a program.

As in the lecture, the operator moves the arm to each point of the task with a pendant and tells
the controller to record the joint positions there. :class:`TeachPendant` holds the arm's
configuration and executes one line-based command at a time (so scripts and tests can drive it);
:func:`run_session` feeds it lines until ``q`` or the end of input, and :class:`PromptLines`
reads them from the terminal with line editing and history (Python's :mod:`readline`, where it
exists). The recorded points become a program (start = the configuration the session started
from, the points as joint values, a ``ptp`` to each in order) that ``kinplan run`` plans.

Continuous paths: between ``rec start [hz]`` and ``rec stop [tol_deg]`` every jog is captured as
a motion at the jog speed (:data:`DEFAULT_JOG_SPEED` of the joint velocity limits), sampled at
``hz``; ``rec stop`` fits a smooth joint spline, timed as recorded, through as few of the samples
as keep it within the tolerance of all of them at the recorded times (:func:`fit_spline`),
reports its deviation in joint space [rad] and at the tool [mm], and stores it as one
multi-point ``ptp`` move with ``profile: spline`` and the knots' recorded ``times``.

The commands are in :data:`HELP` (``help`` prints them, ``help <command>`` explains one from
:data:`COMMANDS`): jog a joint (``j 2 -5``), the tool along x/y/z [m] or about roll/pitch/yaw
[deg] (``z -0.01``, ``yaw+``), set the steps, record (``r a``, ``rec start``), ``q`` to finish.
Tool jogs solve IK seeded from the current configuration and refuse a jog that is unreachable,
beyond a joint limit, or that would flip the arm to another branch.
"""

from __future__ import annotations

import importlib
import logging
import math
import os
import re
import textwrap
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from types import ModuleType

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

import cartesian
from kinplan import checks, trajectory
from kinplan.errors import InputError, KinplanError
from kinplan.program.schema import FALLBACK_JOINT_SPEED, PTP_RAMP_TIME
from kinplan.robot import Robot
from kinplan.sampling import joint_speeds
from kinplan.trajectory import Trajectory

logger = logging.getLogger("kinplan.teach")

__all__ = [
    "COMMANDS",
    "DEFAULT_JOG_SPEED",
    "DEFAULT_PATH_TOLERANCE",
    "DEFAULT_RATE_HZ",
    "HELP",
    "HISTORY_ENV",
    "PromptLines",
    "RecordedPath",
    "Reply",
    "TeachPendant",
    "default_history_file",
    "fit_spline",
    "home_configuration",
    "run_session",
]

DEFAULT_LINEAR_STEP = 0.01
"""Default tool jog [m]."""
DEFAULT_ANGULAR_STEP_DEG = 5.0
"""Default joint and tool rotation jog [deg]."""
MAX_BRANCH_STEP = 0.5
"""Joint change a tool jog may cause, beyond its length [m] and angle [rad], before it counts as
a branch flip [rad] (jogs are also checked for continuity along the way)."""
MAX_LINEAR_JOG = 10.0
"""Longest tool jog or linear step the pendant accepts [m] (beyond the reach of any arm)."""
MAX_JOINT_JOG_DEG = 720.0
"""Largest joint jog the pendant accepts [deg] (two turns, for continuous joints)."""
MAX_ROTATION_JOG_DEG = 180.0
"""Largest tool rotation jog or angle step the pendant accepts [deg]."""

DEFAULT_RATE_HZ = 50.0
"""Sampling rate of a continuous-path recording (``rec start``) [Hz]."""
MAX_RATE_HZ = 1000.0
"""Highest sampling rate ``rec start`` accepts [Hz]."""
DEFAULT_PATH_TOLERANCE = 1e-3
"""Largest joint deviation of a recorded path's spline from the recording (``rec stop``) [rad]."""
MAX_PATH_TOLERANCE_DEG = 10.0
"""Largest tolerance ``rec stop`` accepts [deg]."""
DEFAULT_JOG_SPEED = 0.1
"""Jog speed, share of the joint velocity limits [-]: a recorded jog cruises at most at this
share of each joint's limit (joints without one at the programs' fallback speed) and reaches it
in the programs' ramp time (the acceleration limits, scaled alike, where the robot has them)."""
MAX_RECORDING_SAMPLES = 200_000
"""Most samples one recording keeps (over an hour at 50 Hz); ``rec stop`` and start again."""
HISTORY_ENV = "KINPLAN_HISTORY"
"""Environment variable naming the pendant's history file; empty disables the file."""
HISTORY_LENGTH = 1000
"""Lines kept in the history file."""

HELP = """\
j <i> <deg>           jog joint i (0-based index or name) by deg; j <i>+ / j <i>- use the step
x|y|z <m>             move the tool along a world axis by m; x+ / x- use the linear step
roll|pitch|yaw <deg>  rotate the tool about the world x|y|z axis through the tool point;
                      roll+ / roll- use the angle step (rx, ry, rz also work)
step <m>              set the linear step [m]
astep <deg>           set the angle step for joints and rotations [deg]
r [name]              record the current configuration (default names p1, p2, ...)
rec start [hz]        record a continuous path: the jogs that follow, sampled at hz (default 50)
rec stop [tol_deg]    end it: store a smooth spline timed as recorded, within tol_deg of the
                      recording (default 0.0573° = 1e-3 rad), and report its deviation
del <name>            forget a recorded point or path
list                  list the recorded points and paths
home                  go back to the start configuration
show                  show joints and tool pose
help [command]        this help, or a command's usage, units and aliases
q | quit | EOF        write the program and quit
abort                 quit without writing"""
"""The pendant's commands."""

COMMANDS = {
    "j": """\
j <joint> <deg>  |  j <joint>+  |  j <joint>-                        (also: joint)
Jog one joint by <deg> degrees (negative to go back, at most 720); + and - jog by the angle
step (astep). <joint> is a 0-based index or a joint name (show lists the joints). A jog beyond
the joint's limits is refused. Example: j 2 -5""",
    "x": """\
x|y|z <m>  |  x+  |  x-  |  y+  |  y-  |  z+  |  z-
Move the tool along the world x, y or z axis by <m> metres (at most 10) on a straight line,
keeping its orientation; + and - move by the linear step (step). The line is checked first: a
jog that leaves the workspace, meets a joint limit or a singularity, or would flip the arm to
another branch is refused with the reason. Example: z -0.01""",
    "roll": """\
roll|pitch|yaw <deg>  |  roll+  |  roll-  |  ...                  (also: rx, ry, rz)
Rotate the tool by <deg> degrees (at most 180) about the world x (roll), y (pitch) or z (yaw)
axis through the tool point; + and - rotate by the angle step (astep). Checked like x|y|z. Arms
that control the tool position only cannot rotate it. Example: yaw 15""",
    "step": """\
step <m>
Set the linear step of x+, y-, ... to <m> metres, a number > 0 and at most 10.
Example: step 0.005""",
    "astep": """\
astep <deg>
Set the angle step of j <i>+, roll-, ... to <deg> degrees, a number > 0 and at most 180.
Example: astep 1""",
    "r": """\
r [name]  |  rec [name]  |  record [name]
Record the current configuration as a point named <name> (letters, digits, _ and -, not first a
digit; default p1, p2, ...). The program moves to each point with a ptp move, in teaching order.
rec start [hz]
Record a continuous path: every jog that follows (and home) is captured as a motion at the jog
speed (10 % of the joint velocity limits) and sampled <hz> times a second (default 50, > 0, at
most 1000). The arm's configuration at rec start is the path's first point.
rec stop [tol_deg]
End the recording and store it as path1, path2, ...: a smooth joint spline (acceleration
continuous, at rest at both ends) that passes as few of the samples as keep every sample within
<tol_deg> degrees of it (default 0.0573° = 1e-3 rad, > 0, at most 10), each knot at the time it
was recorded, each sample compared with the spline at its recorded time. Reports the samples,
the knots kept and the largest deviation, in joint space [rad] and at the tool [mm]. The program
plays it as one ptp through the knots (profile: spline, times: the recorded times), as
recorded; slower only if the spline would exceed a joint velocity limit (the report says so).""",
    "del": """\
del <name>                                                          (also: delete)
Forget a recorded point or path (list shows them).""",
    "list": """\
list
List the recorded points (joints [deg], tool position [m]) and paths, in teaching order.""",
    "home": """\
home
Go back to the start configuration (a joint move; recorded while rec start is on).""",
    "show": """\
show
Show the joint values [deg] and the tool position [m] and orientation (roll, pitch, yaw [deg]).""",
    "help": """\
help [command]                                                      (also: ?)
List the commands, or explain one: its usage, units and aliases. Example: help rec""",
    "q": """\
q  |  quit  |  exit  |  end of input
Write the program and quit (a running recording is stopped first, as rec stop).""",
    "abort": """\
abort
Quit without writing the program (a running recording is dropped).""",
}
"""Help on each command (``help <command>``): usage, what it does, units, aliases."""

_HELP_ALIASES = {
    "joint": "j",
    "y": "x",
    "z": "x",
    "pitch": "roll",
    "yaw": "roll",
    "rx": "roll",
    "ry": "roll",
    "rz": "roll",
    "rec": "r",
    "record": "r",
    "delete": "del",
    "?": "help",
    "quit": "q",
    "exit": "q",
}
_COMPLETIONS = sorted({*COMMANDS, *_HELP_ALIASES, "start", "stop"})

_HOME_DEG = {
    "ur": [0.0, -90.0, 90.0, -90.0, -90.0, 0.0],
    "panda": [0.0, -45.0, 0.0, -135.0, 0.0, 90.0, 45.0],
}
_AXES = {"x": 0, "y": 1, "z": 2}
_ROTATIONS = {"roll": 0, "rx": 0, "pitch": 1, "ry": 1, "yaw": 2, "rz": 2}
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
_JOG = re.compile(r"^(?P<axis>[a-z]+)(?P<sign>[+-])$")
_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")
_SPEED_MARGIN = 1e-3
"""Extra share by which a recorded path's times are stretched when its spline would exceed a
joint velocity limit at the recorded times [-]."""
_SPEED_STEP = 0.0025
"""Time step at which a recorded path's spline is checked against the velocity limits [s] (a
quarter of the programs' default sampling period)."""
_FIT_ATTEMPTS = 4
"""Fits ``rec stop`` tries, each aiming tighter by what the last missed: the program reads the
knots rounded to 1e-6° and the times to 1e-6 s, which moves the spline by ~1e-8 rad."""
_LIMIT_TOLERANCE = 1e-9
"""How far a fitted spline may pass a joint limit at a sample before a knot is added there [rad]."""


def home_configuration(robot: Robot) -> np.ndarray:
    """A comfortable start for teaching [rad]: the UR "up" pose with the tool down, the panda's
    ready pose, 30° per joint for planar arms, else the neutral configuration.

    Raises:
        InputError: ``robot`` is not a :class:`kinplan.Robot`.
    """
    _check_robot(robot)
    for prefix, degrees in _HOME_DEG.items():
        if robot.name.startswith(prefix) and len(degrees) == robot.nq:
            return np.clip(np.radians(degrees), robot.lower, robot.upper)
    if robot.planar_reach() is not None:
        return np.clip(np.full(robot.nq, math.radians(30.0)), robot.lower, robot.upper)
    return robot.neutral()


@dataclass
class Reply:
    """What a command did.

    Attributes:
        text: Lines to show the operator.
        moved: Whether the configuration changed.
        done: Whether the session ends.
        write: Whether the program should be written (``q``; not ``abort``).
    """

    text: str
    moved: bool = False
    done: bool = False
    write: bool = False


@dataclass(frozen=True, eq=False)
class RecordedPath:
    """A continuous path recorded with ``rec start`` / ``rec stop`` and its fitted spline.

    Attributes:
        name: Its name in the session (``path1``, ...); its knots are the program's points
            ``<name>_0``, ``<name>_1``, ...
        rate_hz: Sampling rate of the recording [Hz].
        sample_times: Times of the recorded samples, from 0 [s], shape (N,).
        samples: The recorded configurations [rad], shape (N, n).
        knot_indices: The samples kept as the spline's knots, shape (k,), 0 first, N − 1 last.
        spline: The motion the program plays (:func:`kinplan.trajectory.cubic_via`): the
            clamped cubic spline through the knots as the program reads them (to 1e-6°), at rest
            at both ends, each knot at its recorded time (to 1e-6 s; all stretched alike only if
            the recorded timing would exceed a joint velocity limit). Its waypoints are the
            knots and their times in the program (see :attr:`times`).
        played_times: The time on :attr:`spline` of each sample [s], shape (N,): its recorded
            time (mapped linearly between the knots' times in the program).
        deviation: Largest |spline − recording| over the joints at each sample, both at the
            sample's time [rad], shape (N,).
        tool_deviation: Largest distance between the tool positions of the spline and of the
            recording at the samples' times [m].
        tolerance: The deviation the fit was asked to stay within [rad].
        speed_ratio: The spline's largest joint speed over its velocity limit when timed as
            recorded [-] (joints without a limit left out); above 1 the program plays it slower.
    """

    name: str
    rate_hz: float
    sample_times: np.ndarray
    samples: np.ndarray
    knot_indices: np.ndarray
    spline: Trajectory
    played_times: np.ndarray
    deviation: np.ndarray
    tool_deviation: float
    tolerance: float
    speed_ratio: float

    @property
    def duration(self) -> float:
        """Recorded duration [s]."""
        return float(self.sample_times[-1])

    @property
    def knot_times(self) -> np.ndarray:
        """Times of the knots in the recording [s], shape (k,)."""
        return self.sample_times[self.knot_indices]

    @property
    def knots(self) -> np.ndarray:
        """The knots' configurations as recorded [rad], shape (k, n)."""
        return self.samples[self.knot_indices]

    @property
    def times(self) -> np.ndarray:
        """The program's ``times:``: when the spline passes knots 1, ..., k − 1, from its start
        at knot 0 [s], shape (k − 1,) (the last is its duration)."""
        return self.spline.waypoints.times[1:]

    @property
    def slowed(self) -> bool:
        """Whether the program plays the path slower than recorded (velocity limits)."""
        return self.spline.duration > self.duration + 1e-6

    @property
    def max_deviation(self) -> float:
        """Largest joint deviation of the spline from the recording at the samples [rad]."""
        return float(self.deviation.max())

    def point_names(self) -> list[str]:
        """The program's names of the knots: ``<name>_0``, ``<name>_1``, ..."""
        return [f"{self.name}_{k}" for k in range(len(self.knot_indices))]


@dataclass
class _Recording:
    """A recording under way: samples on the grid k / rate_hz, the last at ``elapsed``."""

    rate_hz: float
    times: list[float]
    q: list[np.ndarray]
    elapsed: float = 0.0
    next_k: int = 1
    jogs: int = 0


class TeachPendant:
    """The state of a teach session and its commands.

    Args:
        robot: The arm.
        q_start: Start configuration [rad] (default :func:`home_configuration`).
        robot_source: How the program names the robot (a name or URDF path; default its name).
        linear_step: Tool jog step [m].
        angular_step_deg: Joint and rotation jog step [deg].
        jog_speed: Speed of the jogs a recording captures, share of the joint velocity limits,
            in (0, 1] [-].
        path_tolerance: Default largest deviation of a recorded path's spline from the
            recording (``rec stop`` without a tolerance) [rad].

    Attributes:
        q: Current configuration [rad].
        points: Recorded points: name → configuration [rad], in recording order.
        paths: Recorded continuous paths: name → :class:`RecordedPath`, in recording order.
    """

    def __init__(
        self,
        robot: Robot,
        q_start: np.ndarray | None = None,
        robot_source: str | None = None,
        linear_step: float = DEFAULT_LINEAR_STEP,
        angular_step_deg: float = DEFAULT_ANGULAR_STEP_DEG,
        jog_speed: float = DEFAULT_JOG_SPEED,
        path_tolerance: float = DEFAULT_PATH_TOLERANCE,
    ) -> None:
        _check_robot(robot)
        self.robot = robot
        start = home_configuration(robot) if q_start is None else robot.check_q(q_start, "q_start")
        if not robot.within_limits(start):
            raise InputError(
                f"q_start {np.round(np.degrees(start), 3).tolist()} deg is beyond the joint "
                f"limits of {robot.name}; give a start within them"
            )
        self.start = start.copy()
        self.q = start.copy()
        if robot_source is not None:
            robot_source = checks.text(robot_source, "robot_source (a robot name or URDF path)")
        self.robot_source = robot_source or robot.name
        self.linear_step = checks.number(
            linear_step, "linear_step", positive=True, maximum=MAX_LINEAR_JOG, unit="m"
        )
        self.angular_step = math.radians(
            checks.number(
                angular_step_deg,
                "angular_step_deg",
                positive=True,
                maximum=MAX_ROTATION_JOG_DEG,
                unit="deg",
            )
        )
        self.jog_speed = checks.number(
            jog_speed, "jog_speed (share of the joint velocity limits)", positive=True, maximum=1.0
        )
        self.path_tolerance = checks.number(
            path_tolerance,
            "path_tolerance",
            positive=True,
            maximum=math.radians(MAX_PATH_TOLERANCE_DEG),
            unit="rad",
        )
        limit = robot.velocity_limit
        limit = np.where(np.isfinite(limit), limit, FALLBACK_JOINT_SPEED)
        self._jog_velocity = limit * self.jog_speed
        known = robot.acceleration_limit
        self._jog_acceleration = np.where(
            np.isfinite(known), known * self.jog_speed, self._jog_velocity / PTP_RAMP_TIME
        )
        self.points: dict[str, np.ndarray] = {}
        self.paths: dict[str, RecordedPath] = {}
        self._order: list[tuple[str, str]] = []  # ("point" | "path", name), in teaching order
        self._recording: _Recording | None = None

    @property
    def recording(self) -> bool:
        """Whether a continuous path is being recorded (between ``rec start`` and ``rec stop``)."""
        return self._recording is not None

    # -- display -------------------------------------------------------------------------------
    def status(self) -> str:
        """Joint values [deg] and tool pose (position [m], roll/pitch/yaw [deg])."""
        joints = "  ".join(f"{j}:{math.degrees(v):8.2f}" for j, v in enumerate(self.q))
        pose = self.robot.fk(self.q)
        xyz = ", ".join(f"{v:.4f}" for v in pose.translation)
        text = f"joints [deg]  {joints}\ntool  xyz ({xyz}) m"
        if not self.robot.default_position_only():
            rpy = ", ".join(f"{v:.1f}" for v in np.degrees(pin.rpy.matrixToRpy(pose.rotation)))
            text += f"  rpy ({rpy}) deg"
        return text

    # -- commands ------------------------------------------------------------------------------
    def execute(self, line: str) -> Reply:
        """Run one command line; unknown or malformed commands get a message, never raise."""
        if not isinstance(line, str):
            return Reply(f"error: a command is a line of text, got {checks.describe(line)}")
        control = _control_message(line)
        if control:
            return Reply(f"error: {control}")
        words = line.split("#", 1)[0].split()
        if not words:
            return Reply("")
        command, arguments = words[0].lower(), words[1:]
        try:
            reply = self._dispatch(command, arguments)
        except (ValueError, KinplanError) as exc:
            return Reply(f"error: {exc}")
        recording = self._recording
        if reply.moved and recording is not None:
            reply.text += (
                f"\nrecording: {len(recording.times)} samples, {recording.elapsed:.2f} s "
                "(rec stop to store the path)"
            )
        return reply

    def _dispatch(self, command: str, arguments: list[str]) -> Reply:
        simple = {
            "show": lambda: Reply(self.status()),
            "list": self._list,
            "home": self._home,
            "q": self._finish,
            "quit": self._finish,
            "exit": self._finish,
            "abort": self._abort,
        }
        if command in simple and not arguments:
            return simple[command]()
        if command in ("help", "?"):
            return self._help(arguments)
        if command in ("j", "joint"):
            return self._jog_joint(arguments)
        if command in ("r", "rec", "record"):
            if arguments and arguments[0].lower() == "start":
                return self._start_recording(arguments[1:])
            if arguments and arguments[0].lower() == "stop":
                return self._stop_recording(arguments[1:])
            return self._record(arguments)
        if command in ("del", "delete"):
            return self._delete(arguments)
        if command == "step":
            return self._set_step(arguments, angular=False)
        if command == "astep":
            return self._set_step(arguments, angular=True)
        match = _JOG.match(command)
        axis, sign = (match["axis"], match["sign"]) if match else (command, "")
        if axis in _AXES or axis in _ROTATIONS:
            return self._jog_tool(axis, sign, arguments)
        if command in simple:
            raise ValueError(f"usage: {command} (no arguments); help {command} explains it")
        return Reply(f"error: unknown command {command!r}; type help for the commands")

    def _help(self, arguments: list[str]) -> Reply:
        if not arguments:
            return Reply(HELP)
        if len(arguments) > 1:
            raise ValueError("usage: help [command]")
        name = arguments[0].lower()
        key = _HELP_ALIASES.get(name, name)
        match = _JOG.match(key)
        if key not in COMMANDS and match:  # help x+, help yaw-, help j+
            key = _HELP_ALIASES.get(match["axis"], match["axis"])
        if key not in COMMANDS:
            raise ValueError(
                f"no command {arguments[0]!r}; help explains {', '.join(COMMANDS)} "
                "(and their aliases)"
            )
        return Reply(COMMANDS[key])

    def _jog_joint(self, arguments: list[str]) -> Reply:
        usage = "usage: j <index or name> <delta_deg>, or j <index>+ / j <index>-"
        if not arguments:
            raise ValueError(usage)
        target, sign = arguments[0], ""
        if target[-1] in "+-" and len(target) > 1:
            target, sign = target[:-1], target[-1]
        j = self._joint_index(target)
        if sign and len(arguments) == 1:
            delta = self.angular_step * (1.0 if sign == "+" else -1.0)
        elif len(arguments) == 2 and arguments[1] in ("+", "-"):
            delta = self.angular_step * (1.0 if arguments[1] == "+" else -1.0)
        elif len(arguments) == 2 and not sign:
            delta = math.radians(
                _number(arguments[1], "the jog", "degrees", maximum=MAX_JOINT_JOG_DEG)
            )
        else:
            raise ValueError(usage)
        q = self.q.copy()
        q[j] += delta
        robot = self.robot
        if not robot.within_limits(q):
            return Reply(
                f"refused: joint {j} ({robot.joint_names[j]}) would reach "
                f"{math.degrees(q[j]):.2f}°, beyond its limits "
                f"[{math.degrees(robot.lower[j]):.1f}°, {math.degrees(robot.upper[j]):.1f}°]"
            )
        return self._go(q)

    def _joint_index(self, text: str) -> int:
        names = self.robot.joint_names
        if text in names:
            return names.index(text)
        try:
            j = int(text)
        except ValueError:
            raise ValueError(
                f"no joint {text!r}; give an index 0..{len(names) - 1} or a name: "
                f"{', '.join(names)}"
            ) from None
        if not 0 <= j < len(names):
            raise ValueError(
                f"joint index {j} is out of range 0..{len(names) - 1} ({self.robot.name} has "
                f"{len(names)} joints)"
            )
        return j

    def _jog_tool(self, axis: str, sign: str, arguments: list[str]) -> Reply:
        rotate = axis in _ROTATIONS
        if sign and not arguments:
            step = self.angular_step if rotate else self.linear_step
            delta = step if sign == "+" else -step
        elif len(arguments) == 1 and not sign:
            if rotate:
                value = _number(arguments[0], "the jog", "degrees", maximum=MAX_ROTATION_JOG_DEG)
                delta = math.radians(value)
            else:
                delta = _number(arguments[0], "the jog", "metres", maximum=MAX_LINEAR_JOG)
        else:
            unit = "deg" if rotate else "m"
            raise ValueError(f"usage: {axis} <delta_{unit}>, or {axis}+ / {axis}-")
        robot = self.robot
        position_only = robot.default_position_only()
        if rotate and position_only:
            return Reply(
                f"refused: {robot.name} has {robot.nq} joints and controls the tool position "
                "only; jog x, y, z or the joints"
            )
        plane_normal = robot.model.jointPlacements[1].rotation[:, 2]
        if axis == "z" and robot.planar_reach() is not None and abs(plane_normal[2]) > 1 - 1e-9:
            return Reply(
                f"refused: {robot.name} is a planar arm and moves in its xy-plane; jog x, y or "
                "the joints"
            )
        pose = robot.fk(self.q)
        position, rotation = pose.translation.copy(), pose.rotation.copy()
        if rotate:
            axis_vector = np.zeros(3)
            axis_vector[_ROTATIONS[axis]] = 1.0
            rotation = pin.exp3(axis_vector * delta) @ rotation
        else:
            position[_AXES[axis]] += delta
        return self._move_tool(position, None if position_only else rotation)

    def _move_tool(self, position: np.ndarray, rotation: np.ndarray | None) -> Reply:
        """Move the tool on a straight line to the target, checked for reach, joint limits,
        branch flips and singularities along the way (IK warm-started from the current q)."""
        robot = self.robot
        start = robot.fk(self.q)
        where = ", ".join(f"{v:.4f}" for v in position)
        if rotation is None:
            path = cartesian.Line(start.translation, position)
        else:
            path = cartesian.Line(start, pin.SE3(rotation, position))
        check = cartesian.check_reachability(
            robot, path, q_seed=self.q, position_only=rotation is None
        )
        if not check.ok:
            event = check.events[0]
            advice = _pendant_advice(event, robot)
            distance, reach = robot.shoulder_distance(position), robot.reach()
            beyond = ""
            if distance > reach * (1.0 + 1e-9) and event.kind != "unreachable":
                beyond = (
                    f" (the jog ends {distance:.4f} m from the first joint, beyond the reach of "
                    f"{robot.name}, {reach:.4f} m)"
                )
                advice = _PENDANT_ADVICE["unreachable"]
            return Reply(
                f"refused: {event.kind} at {100 * event.s:.0f} % of the jog to ({where}) m: "
                f"{event.message}{beyond}" + (f"; {advice}" if advice else "")
            )
        along: tuple[np.ndarray, np.ndarray] | None = None
        if len(check.q):
            q = check.q[-1]
            along = (np.asarray(check.s, dtype=float), np.asarray(check.q, dtype=float))
        else:  # planar arms are checked analytically: solve the end point
            target = position if rotation is None else pin.SE3(rotation, position)
            result = robot.ik(target, q_seed=self.q, position_only=rotation is None)
            if not result.success:
                from cartesian.events import out_of_reach

                why = out_of_reach(robot, result, position)
                return Reply(
                    f"refused: ({where}) m cannot be reached from here: {why}; "
                    f"{_PENDANT_ADVICE['unreachable']}"
                )
            q = result.q
        change = np.abs(q - self.q)
        if change.max() > MAX_BRANCH_STEP + path.length + (path.slerp.angle if path.slerp else 0):
            j = int(np.argmax(change))
            return Reply(
                f"refused: reaching ({where}) m would swing joint {j} ({robot.joint_names[j]}) by "
                f"{math.degrees(change[j]):.1f}° (a branch flip); take a smaller step or jog the "
                "joints"
            )
        return self._go(np.array(q, dtype=float), along)

    def _go(self, q: np.ndarray, along: tuple[np.ndarray, np.ndarray] | None = None) -> Reply:
        """Move to ``q`` (captured by a running recording: along the joint path ``along``, path
        fractions and configurations, or joint-interpolated)."""
        if self._recording is not None:
            refusal = self._capture(q, along)
            if refusal:
                return Reply(refusal)
        self.q = q
        return Reply(self.status(), moved=True)

    def _set_step(self, arguments: list[str], angular: bool) -> Reply:
        usage = "usage: astep <deg>" if angular else "usage: step <m>"
        if len(arguments) != 1:
            raise ValueError(f"{usage} (a number > 0)")
        try:
            if angular:
                value = _number(
                    arguments[0],
                    "the angle step",
                    "degrees",
                    positive=True,
                    maximum=MAX_ROTATION_JOG_DEG,
                )
            else:
                value = _number(
                    arguments[0], "the linear step", "metres", positive=True, maximum=MAX_LINEAR_JOG
                )
        except ValueError as exc:
            raise ValueError(f"{usage}: {exc}") from None
        if angular:
            self.angular_step = math.radians(value)
            return Reply(f"angle step {value:g}°")
        self.linear_step = value
        return Reply(f"linear step {value:g} m")

    def _record(self, arguments: list[str]) -> Reply:
        if len(arguments) > 1:
            raise ValueError("usage: r [name], rec start [hz] or rec stop [tol_deg]")
        name = arguments[0] if arguments else self._next_name()
        if not _NAME.match(name):
            raise ValueError(
                f"point name {name!r}: use letters, digits, _ and -, not first a digit"
            )
        if name in self.points:
            return Reply(f"refused: a point {name!r} exists; give another name or del {name}")
        taken = self._path_point_owner(name)
        if taken:
            return Reply(f"refused: {name!r} is taken by the path {taken}; give another name")
        self.points[name] = self.q.copy()
        self._order.append(("point", name))
        xyz = ", ".join(f"{v:.4f}" for v in self.robot.fk(self.q).translation)
        return Reply(f"recorded {name} (tool at ({xyz}) m); {len(self.points)} points")

    def _path_point_owner(self, name: str) -> str | None:
        """The recorded path whose name or program point names include ``name``, if any."""
        for path in self.paths.values():
            if name == path.name or name in path.point_names():
                return path.name
        return None

    def _next_name(self) -> str:
        k = len(self.points) + 1
        while f"p{k}" in self.points or self._path_point_owner(f"p{k}"):
            k += 1
        return f"p{k}"

    # -- continuous paths ----------------------------------------------------------------------
    def _start_recording(self, arguments: list[str]) -> Reply:
        if len(arguments) > 1:
            raise ValueError("usage: rec start [hz]")
        if self._recording is not None:
            recording = self._recording
            return Reply(
                f"refused: already recording ({len(recording.times)} samples, "
                f"{recording.elapsed:.2f} s); rec stop first"
            )
        rate = DEFAULT_RATE_HZ
        if arguments:
            rate = _number(
                arguments[0], "the sampling rate", "Hz", positive=True, maximum=MAX_RATE_HZ
            )
        self._recording = _Recording(rate, [0.0], [self.q.copy()])
        return Reply(
            f"recording at {rate:g} Hz from here: jog the arm along the path (each jog as a "
            f"motion at {100 * self.jog_speed:g} % of the joint speed limits), then "
            "rec stop [tol_deg]"
        )

    def _capture(self, q: np.ndarray, along: tuple[np.ndarray, np.ndarray] | None) -> str:
        """Sample the motion from :attr:`q` to ``q`` into the recording; a refusal or ""."""
        recording = self._recording
        assert recording is not None
        s_path, q_path = _joint_path(self.q, q, along)
        law = _jog_time_law(s_path, q_path, self._jog_velocity, self._jog_acceleration)
        if law is None:  # nothing moves
            return ""
        end = recording.elapsed + law.duration
        last_k = math.floor(end * recording.rate_hz + 1e-9)
        count = last_k - recording.next_k + 1
        if len(recording.times) + count > MAX_RECORDING_SAMPLES:
            return (
                f"refused: this jog would take the recording past {MAX_RECORDING_SAMPLES} "
                f"samples, the most a path keeps; rec stop, then rec start again"
            )
        if count > 0:
            times = np.arange(recording.next_k, last_k + 1) / recording.rate_hz
            s = law.sample(times - recording.elapsed)[0][:, 0]
            sampled = np.column_stack(
                [np.interp(s, s_path, q_path[:, j]) for j in range(q_path.shape[1])]
            )
            recording.times.extend(times.tolist())
            recording.q.extend(sampled)
            recording.next_k = last_k + 1
        recording.elapsed = end
        recording.jogs += 1
        return ""

    def _stop_recording(self, arguments: list[str]) -> Reply:
        if len(arguments) > 1:
            raise ValueError("usage: rec stop [tol_deg]")
        recording = self._recording
        if recording is None:
            return Reply("refused: not recording; rec start [hz] starts a path")
        tolerance = self.path_tolerance
        if arguments:
            tolerance = math.radians(
                _number(
                    arguments[0],
                    "the tolerance",
                    "degrees",
                    positive=True,
                    maximum=MAX_PATH_TOLERANCE_DEG,
                )
            )
        self._recording = None
        if recording.jogs == 0:
            return Reply("recording stopped: the arm did not move, so no path was stored")
        times, samples = np.array(recording.times), np.array(recording.q)
        if recording.elapsed - times[-1] > 0.01 / recording.rate_hz:
            times, samples = np.append(times, recording.elapsed), np.vstack([samples, self.q])
        else:  # the last sample is at the end (at rest there): the exact end time and position
            times[-1], samples[-1] = recording.elapsed, self.q
        robot = self.robot
        aim = tolerance
        for _ in range(_FIT_ATTEMPTS):
            knots, _, _ = fit_spline(samples, times, aim, robot.lower, robot.upper)
            spline, ratio, joint = _program_spline(robot, times[knots], samples[knots])
            played = np.interp(times, times[knots], spline.waypoints.times)
            fitted = spline.sample(played)[0]
            deviation = np.abs(fitted - samples).max(axis=1)
            excess = float(deviation.max()) - tolerance
            if excess <= 0.0:
                break
            aim = max(aim - 2.0 * excess, 0.5 * aim)  # the rounding moved it past: aim tighter
        tool = max(
            float(np.linalg.norm(robot.fk(a).translation - robot.fk(b).translation))
            for a, b in zip(fitted, samples, strict=True)
        )
        name = self._next_path_name()
        path = RecordedPath(
            name,
            recording.rate_hz,
            times,
            samples,
            knots,
            spline,
            played,
            deviation,
            tool,
            tolerance,
            ratio,
        )
        self.paths[name] = path
        self._order.append(("path", name))
        slower = ""
        if path.slowed:
            slower = (
                f"; timed as recorded the spline would need {100 * ratio:.1f} % of the velocity "
                f"limit of joint {joint} ({robot.joint_names[joint]}), so the program plays it "
                f"in {spline.duration:.3f} s, not the recorded {path.duration:.3f} s"
            )
        return Reply(
            f"stored {name}: {len(times)} samples over {path.duration:.2f} s at "
            f"{recording.rate_hz:g} Hz -> spline through {len(knots)} knots at their recorded "
            f"times; max deviation {path.max_deviation:.2e} rad "
            f"({math.degrees(path.max_deviation):.4f}°) in joint space, {1000 * tool:.3f} mm at "
            f"the tool (tolerance {tolerance:.2e} rad){slower}"
        )

    def _next_path_name(self) -> str:
        k = len(self.paths) + 1
        while f"path{k}" in self.paths or any(
            name == f"path{k}" or name.startswith(f"path{k}_") for name in self.points
        ):
            k += 1
        return f"path{k}"

    def _finish(self) -> Reply:
        text = self._stop_recording([]).text if self._recording is not None else ""
        return Reply(text, done=True, write=True)

    def _abort(self) -> Reply:
        text = "recording dropped" if self._recording is not None else ""
        self._recording = None
        return Reply(text, done=True, write=False)

    # -- the list ------------------------------------------------------------------------------
    def _delete(self, arguments: list[str]) -> Reply:
        if len(arguments) != 1:
            raise ValueError("usage: del <name>")
        name = arguments[0]
        if name in self.points:
            del self.points[name]
            self._order.remove(("point", name))
        elif name in self.paths:
            del self.paths[name]
            self._order.remove(("path", name))
        else:
            known = ", ".join(name for _, name in self._order) or "none"
            return Reply(f"no point {name!r}; recorded: {known}")
        return Reply(f"deleted {name}")

    def _list(self) -> Reply:
        if not self._order:
            return Reply("nothing recorded yet (r [name] records a point, rec start a path)")
        lines = []
        for kind, name in self._order:
            if kind == "point":
                q = self.points[name]
                xyz = ", ".join(f"{v:.4f}" for v in self.robot.fk(q).translation)
                degrees = ", ".join(f"{v:.2f}" for v in np.degrees(q))
                lines.append(f"{name}: joints [{degrees}] deg, tool ({xyz}) m")
            else:
                path = self.paths[name]
                lines.append(
                    f"{name}: path of {len(path.samples)} samples over {path.duration:.2f} s, "
                    f"spline through {len(path.knot_indices)} knots, max deviation "
                    f"{path.max_deviation:.2e} rad ({1000 * path.tool_deviation:.3f} mm at the "
                    "tool)"
                )
        return Reply("\n".join(lines))

    def _home(self) -> Reply:
        return self._go(self.start.copy())

    # -- program -------------------------------------------------------------------------------
    def program_text(self, output: str | os.PathLike[str] | None = None) -> str:
        """The program as YAML: start, the recorded points and path knots as joints, then in
        teaching order a ``ptp`` to each point and, for each path, a ``ptp`` to its first knot
        when the arm is elsewhere, then one ``ptp`` from there through the other knots
        (``profile: spline``, ``times:`` those of :attr:`RecordedPath.times`: when it passes
        each, from its start; a path of two knots is the same motion as a ``ptp`` with
        ``profile: cubic`` and that ``duration``).

        Args:
            output: Where the program will be written; a URDF robot source is written relative
                to its folder.

        Raises:
            KinplanError: nothing recorded yet, or a path still being recorded.
            InputError: ``output`` is not a file path.
        """
        if output is not None:
            output = checks.file_path(output, "output (the program file)")
        if self._recording is not None:
            raise KinplanError("a path is being recorded; rec stop stores it before writing")
        if not self._order:
            raise KinplanError(
                "no point recorded (r [name]) and no path (rec start ... rec stop); record one "
                "before writing"
            )
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
        lines = [
            f"# Taught with `kinplan teach` on {stamp}.",
            "# Points are the recorded joint values; run with `kinplan run <this file>`.",
            f"robot: {_yaml_scalar(self._robot_entry(output))}",
            f"tip: {_yaml_scalar(self.robot.tip_frame)}",
            *self._locked_lines(),
            f"start: {{joints_deg: {_degrees(self.start)}}}",
            "points:",
        ]
        moves = []
        current = self.start
        for kind, name in self._order:
            if kind == "point":
                q = self.points[name]
                lines.append(f"  {name}: {{joints_deg: {_degrees(q)}}}  # tool at {self._at(q)}")
                moves.append(f"  - {{ptp: {name}}}")
                current = q
                continue
            path = self.paths[name]
            names = path.point_names()
            for point, q, t in zip(names, path.knots, path.knot_times, strict=True):
                lines.append(
                    f"  {point}: {{joints_deg: {_degrees(q)}}}  # {name}, recorded at "
                    f"t = {t:.4f} s, tool at {self._at(q)}"
                )
            if _degrees(path.knots[0]) != _degrees(current):  # the spline starts where the arm is
                moves.append(f"  - {{ptp: {names[0]}}}  # to the start of {name}")
            timing = "their recorded times"
            if path.slowed:
                timing += f" stretched to {path.spline.duration:.3f} s (velocity limits)"
            moves.append(
                f"  # {name}: recorded {len(path.samples)} samples at {path.rate_hz:g} Hz over "
                f"{path.duration:.3f} s; a spline from {names[0]} through"
            )
            moves.append(
                f"  # the knots at {timing}, within {path.max_deviation:.2e} rad "
                f"({1000 * path.tool_deviation:.3f} mm at the tool)"
            )
            times = _decimals(path.times)
            if len(names) == 2:  # the clamped cubic spline through two points: a cubic
                moves.append(
                    f"  - {{ptp: {names[1]}, name: {name}, profile: cubic, "
                    f"duration: {times[1:-1]}}}"
                )
            else:
                moves += _flow_list("  - ptp: ", names[1:])
                moves.append(f"    name: {name}")
                moves.append("    profile: spline")
                moves += _flow_list("    times: ", times[1:-1].split(", "))
            current = path.knots[-1]
        lines.append("moves:")
        lines += moves
        return "\n".join(lines) + "\n"

    def _at(self, q: np.ndarray) -> str:
        """The tool position at ``q``, for a comment [m]."""
        return "(" + ", ".join(f"{v:.4f}" for v in self.robot.fk(q).translation) + ") m"

    def _locked_lines(self) -> list[str]:
        """The program's ``locked_joints:`` line (none when no joint is locked)."""
        locked = self.robot.locked_joints
        if not locked:
            return []
        entries = ", ".join(
            f"{_yaml_scalar(name)}: {float(value)!r}" for name, value in locked.items()
        )
        return [f"locked_joints: {{{entries}}}  # [rad or m]"]

    def _robot_entry(self, output: str | os.PathLike[str] | None) -> str:
        source = self.robot_source
        path = Path(source)
        if output is None or not path.is_file():
            return source
        try:
            return os.path.relpath(path.resolve(), Path(output).resolve().parent)
        except ValueError:  # another drive (Windows)
            return str(path.resolve())

    def save(self, output: str | os.PathLike[str]) -> Path:
        """Write :meth:`program_text` to ``output`` (its folder is created).

        Raises:
            KinplanError: nothing recorded yet, a path still being recorded, or the file
                cannot be written.
            InputError: ``output`` is not a file path.
        """
        target = Path(checks.file_path(output, "output (the program file)"))
        text = self.program_text(target)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text, encoding="utf-8")
        except OSError as exc:
            raise KinplanError(f"cannot write the program {target}: {exc}") from exc
        logger.info("wrote %s", target)
        return target


_PENDANT_ADVICE = {
    "unreachable": "jog back toward the robot, or take a smaller step (step <m>)",
    "joint_limit": "jog that joint away from its limit (j <joint> <deg>), or go around another way",
    "jump": "take a smaller step (step <m> / astep <deg>), or jog the joints",
    "singular": "jog the joints out of the singular pose (e.g. bend the elbow or the wrist), or "
    "jog in another direction",
    "velocity_limit": "take a smaller step (step <m> / astep <deg>)",
    "collision": "jog away from the obstacle, or jog the joints around it",
}
"""What the operator can do about a refused tool jog, by event kind: pendant commands only (an
event's own ``remedy`` names arguments of :func:`cartesian.follow` the pendant does not have)."""


def fit_spline(
    samples: ArrayLike,
    times: ArrayLike,
    tolerance: float = DEFAULT_PATH_TOLERANCE,
    lower: ArrayLike | None = None,
    upper: ArrayLike | None = None,
) -> tuple[np.ndarray, Trajectory, np.ndarray]:
    """Few of the recorded samples as knots of a smooth spline, timed as recorded, within
    ``tolerance`` of them all.

    The spline is the one a program's ``ptp`` through several points with ``profile: spline``
    and ``times:`` plays (:func:`kinplan.trajectory.cubic_via`): the clamped cubic spline
    through the knots at their recorded times, at rest at both ends. It is compared with the
    recording at the recorded times (each sample with the spline at the same time), which also
    bounds each sample's distance to the spline's path.

    Knots are inserted greedily: from the first and last sample, each pass adds, between every
    two neighbouring knots, the sample where the spline is farthest from the recording, until no
    sample is farther than ``tolerance`` in any joint and (with limits) none is beyond them.
    Samples less than a tenth of the median time step after the previous candidate are not made
    knots (a sample just before the last one, say); they are still measured.

    Args:
        samples: Recorded configurations, in order, shape (N, n), N ≥ 2 [rad].
        times: Their times, strictly increasing, shape (N,) [s]; the spline's time 0 is
            ``times[0]``.
        tolerance: Largest deviation at a sample, > 0 [rad].
        lower: Joint lower limits, shape (n,) [rad] (−inf where none), or None.
        upper: Joint upper limits, shape (n,) [rad] (inf where none), or None.

    Returns:
        ``(knot_indices, spline, deviation)``: the samples kept as knots (sorted, 0 and N − 1
        included); the spline (its waypoints are the knots at ``times[knot_indices] −
        times[0]``); the largest joint deviation at each sample [rad], shape (N,).

    Raises:
        InputError: not numbers, bad shapes, NaN or inf, times that do not strictly increase,
            a tolerance that is not > 0, or only one of the limits.
    """
    points = checks.floats(samples, "samples", "an (N, n) array of configurations [rad]")
    if points.ndim == 1:
        points = points[:, None]
    if points.ndim != 2 or points.shape[0] < 2 or not np.all(np.isfinite(points)):
        raise InputError(
            f"samples must be a finite (N, n) array with N ≥ 2 [rad], got shape {points.shape}"
        )
    count, n = points.shape
    t = checks.floats(times, "times", "a 1-D array of sample times [s]")
    if t.shape != (count,) or not np.all(np.isfinite(t)):
        raise InputError(
            f"times must be {count} finite sample times [s], one per sample, got shape {t.shape}"
        )
    steps = np.diff(t)
    if np.any(steps < trajectory.MIN_DURATION) or t[-1] - t[0] > trajectory.MAX_DURATION:
        raise InputError("times must strictly increase (by at least 1e-9 s) [s]")
    tolerance = checks.number(tolerance, "tolerance", positive=True, unit="rad")
    if (lower is None) != (upper is None):
        raise InputError("give both lower and upper joint limits, or neither")
    limits = None
    if lower is not None and upper is not None:
        limits = (
            checks.vector(lower, "lower", n, unit="rad", infinite=True),
            checks.vector(upper, "upper", n, unit="rad", infinite=True),
        )
    candidate = _spaced(t, 0.1 * float(np.median(steps)))
    knots = np.array([0, count - 1])
    while True:
        spline = trajectory.cubic_via(points[knots], t[knots])
        fitted = spline.sample(t - t[0])[0]
        deviation = np.abs(fitted - points).max(axis=1)
        error = deviation.copy()
        if limits is not None:
            beyond = (fitted < limits[0] - _LIMIT_TOLERANCE) | (
                fitted > limits[1] + _LIMIT_TOLERANCE
            )
            error[beyond.any(axis=1)] = np.inf
        added = []
        for first, last in zip(knots[:-1], knots[1:], strict=True):
            inside = np.arange(first + 1, last)
            if not len(inside) or error[inside].max() <= tolerance:
                continue
            eligible = inside[candidate[inside]]
            if len(eligible):
                added.append(int(eligible[np.argmax(error[eligible])]))
        if not added:
            return knots, spline, deviation
        knots = np.union1d(knots, added)


def _spaced(times: np.ndarray, gap: float) -> np.ndarray:
    """Which samples may be knots: each at least ``gap`` [s] after the previous one (the last
    sample always, in place of a previous one closer than ``gap``)."""
    candidate = np.zeros(len(times), dtype=bool)
    last = 0
    candidate[0] = True
    for k in range(1, len(times)):
        if times[k] - times[last] >= gap:
            candidate[k] = True
            last = k
    if not candidate[-1]:
        if last:
            candidate[last] = False
        candidate[-1] = True
    return candidate


def _joint_path(
    q0: np.ndarray, q1: np.ndarray, along: tuple[np.ndarray, np.ndarray] | None
) -> tuple[np.ndarray, np.ndarray]:
    """The joint path of a jog from ``q0`` to ``q1`` as path fractions (m,) and configurations
    (m, n): ``along`` (a tool jog's IK solutions) with its ends set to q0 and q1, else a line."""
    if along is not None:
        s, q = along
        valid = (
            s.ndim == 1
            and len(s) >= 2
            and q.shape == (len(s), q0.size)
            and np.all(np.diff(s) > 0)
            and s[0] == 0.0
            and s[-1] == 1.0
        )
        if valid:
            q = q.copy()
            q[0], q[-1] = q0, q1
            return s, q
    return np.array([0.0, 1.0]), np.vstack([q0, q1])


def _jog_time_law(
    s: np.ndarray, q: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray
) -> Trajectory | None:
    """The jog's path fraction over time, rest to rest in minimum time with every joint within
    ``velocity`` [rad/s] and (along straight pieces) ``acceleration`` [rad/s²]; None when no
    joint moves."""
    rate = np.abs(np.diff(q, axis=0)) / np.diff(s)[:, None]  # |dq/ds| per piece [rad]
    peak = rate.max(axis=0)
    moving = peak > 1e-12
    if not moving.any():
        return None
    bounds = (trajectory.MIN_MAGNITUDE, trajectory.MAX_MAGNITUDE)
    s_velocity = float(np.clip(np.min(velocity[moving] / peak[moving]), *bounds))
    s_acceleration = float(np.clip(np.min(acceleration[moving] / peak[moving]), *bounds))
    return trajectory.trapezoid(0.0, 1.0, max_velocity=s_velocity, max_acceleration=s_acceleration)


def _check_robot(robot: object) -> None:
    if not isinstance(robot, Robot):
        raise InputError(
            f"robot must be a kinplan.Robot (from kinplan.load_robot), got {checks.describe(robot)}"
        )


def _number(
    text: str, what: str, unit: str, *, positive: bool = False, maximum: float | None = None
) -> float:
    """A number typed by the operator, in ``unit`` (ValueError with the reason otherwise).

    Args:
        text: What was typed.
        what: What the number is, for the message (``the jog``).
        unit: Its unit in words (``degrees``, ``metres``, ``Hz``).
        positive: Require > 0.
        maximum: Largest magnitude accepted.
    """
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"expected a number of {unit} for {what}, got {text!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number of {unit}, got {text!r}")
    if positive and value <= 0:
        raise ValueError(f"{what} must be > 0 {unit}, got {text!r}")
    if maximum is not None and abs(value) > maximum:
        limit = f"at most {maximum:g}" if positive else f"between -{maximum:g} and {maximum:g}"
        raise ValueError(f"{what} must be {limit} {unit}, got {text!r}")
    return value


def _control_message(line: str) -> str:
    """Why a line holding terminal escape sequences or control characters is not a command
    ("" for an ordinary line)."""
    if "\x1b" in line:
        start = line.index("\x1b")
        key = line[start : start + 3] if line[start + 1 : start + 2] in "[O" else line[start]
        return (
            f"{key!r} is a terminal key code (an arrow or function key), not a command: arrow "
            "keys edit and recall lines only when the pendant reads a terminal with Python's "
            "readline module; type the command instead"
        )
    found = _CONTROL.search(line)
    if found:
        return (
            f"the line holds the control character {found.group()!r}, not part of any command; "
            "type the command again"
        )
    return ""


def _pendant_advice(event, robot: Robot) -> str:
    """The pendant's advice for a refused jog's event (see :data:`_PENDANT_ADVICE`)."""
    advice = _PENDANT_ADVICE.get(event.kind, "")
    joint = getattr(event, "joint", None)
    if event.kind == "joint_limit" and joint in robot.joint_names:
        j = robot.joint_names.index(joint)
        advice = advice.replace("that joint", f"joint {j} ({joint})").replace("<joint>", str(j))
    return advice


def _degrees(q: np.ndarray) -> str:
    """Joint values as a YAML list of degrees, to 1e-6° (no "-0")."""
    return _decimals(np.degrees(q))


def _flow_list(start: str, items: list[str]) -> list[str]:
    """``start`` then ``items`` as a YAML flow list, wrapped to lines of 100 characters."""
    indent = " " * (len(start) + 1)
    chunks = textwrap.wrap(", ".join(items), 99 - len(indent), break_long_words=False)
    lines = [indent + chunk for chunk in chunks]
    lines[0] = start + "[" + chunks[0]
    lines[-1] += "]"
    return lines


def _decimals(values: np.ndarray) -> str:
    """Numbers as a YAML list, to 6 decimals (no trailing zeros, no "-0")."""
    texts = (f"{v:.6f}".rstrip("0").rstrip(".") for v in values)
    return "[" + ", ".join("0" if text == "-0" else text for text in texts) + "]"


def _as_read(values: np.ndarray) -> np.ndarray:
    """The numbers a program reads back from :func:`_decimals` (rounded to 6 decimals)."""
    return np.array([float(f"{v:.6f}") for v in values])


def _program_spline(
    robot: Robot, knot_times: np.ndarray, knots: np.ndarray
) -> tuple[Trajectory, float, int]:
    """The spline a program plays for a recorded path: the clamped cubic spline, at rest at both
    ends, through ``knots`` [rad] (k, n) as the program reads them (to 1e-6°) at their recorded
    times ``knot_times`` [s] (k,) from the first (to 1e-6 s), all stretched alike if the recorded
    timing would exceed a joint velocity limit.

    Returns:
        The spline, its largest joint speed over the velocity limit when timed as recorded [-]
        and the joint where that is.
    """
    positions = np.radians(np.array([_as_read(np.degrees(q)) for q in knots]))
    recorded = knot_times - knot_times[0]
    spline = trajectory.cubic_via(positions, _as_read(recorded))
    first, joint = _speed_ratio(robot, spline)
    ratio, stretch = first, 1.0
    for _ in range(10):  # one stretch is enough, but for rounding
        if ratio <= 1.0:
            break
        stretch *= ratio * (1.0 + _SPEED_MARGIN)
        spline = trajectory.cubic_via(positions, _as_read(recorded * stretch))
        ratio, _ = _speed_ratio(robot, spline)
    return spline, first, joint


def _speed_ratio(robot: Robot, spline: Trajectory) -> tuple[float, int]:
    """The largest joint speed of ``spline`` over its velocity limit [-] (sampled every
    :data:`_SPEED_STEP`, with the mean speeds between samples as the programs check it; joints
    without a limit left out, 0 when none has one) and the joint where that is."""
    limit = robot.velocity_limit
    if not np.isfinite(limit).any():
        return 0.0, 0
    t = spline.time_grid(_SPEED_STEP)
    q, qd, _ = spline.sample(t)
    share = joint_speeds(q, qd, t).max(axis=0) / limit  # 0 where the limit is inf
    joint = int(np.argmax(share))
    return float(share[joint]), joint


def _yaml_scalar(text: str) -> str:
    """``text`` as a YAML scalar (quoted when plain style would change its meaning)."""
    import yaml

    return yaml.safe_dump(text, default_style=None).splitlines()[0].removesuffix(" ...")


# -- reading the terminal ----------------------------------------------------------------------
def default_history_file() -> Path | None:
    """The pendant's history file: ``$KINPLAN_HISTORY`` (none when it is set but empty), else
    ``~/.kinplan_history``."""
    value = os.environ.get(HISTORY_ENV)
    if value is not None:
        return Path(value).expanduser() if value.strip() else None
    return Path("~/.kinplan_history").expanduser()


def _readline_module() -> ModuleType | None:
    """Python's readline module, or None where it is missing (Windows)."""
    try:
        return importlib.import_module("readline")
    except ImportError:
        return None


class PromptLines:
    """Lines typed at a prompt, with line editing, history and command completion where
    Python has :mod:`readline` (arrow keys, Ctrl-R; not on Windows, whose console edits lines
    itself).

    Each non-empty line is added to the session's history (not twice in a row); with a
    ``history_file`` the history is read from it at the start and written back by
    :meth:`close` (the last :data:`HISTORY_LENGTH` lines). Use it as a context manager::

        with PromptLines(history_file=default_history_file()) as lines:
            run_session(pendant, lines, print)

    Args:
        prompt: The prompt.
        history_file: Where the history is kept between sessions, or None (this session only).
        read: Reads one line after showing the prompt; raises EOFError at the end (default
            :func:`input`, which uses readline when it is loaded and input is a terminal).

    Attributes:
        readline: The readline module in use, or None.
    """

    def __init__(
        self,
        prompt: str = "teach> ",
        history_file: str | os.PathLike[str] | None = None,
        read: Callable[[str], str] = input,
    ) -> None:
        if not isinstance(prompt, str):
            raise InputError(f"prompt must be text, got {checks.describe(prompt)}")
        if not callable(read):
            raise InputError(f"read must be a function like input, got {checks.describe(read)}")
        self.prompt = prompt
        self.read = read
        self.history_file = (
            None
            if history_file is None
            else Path(checks.file_path(history_file, "history_file")).expanduser()
        )
        self.readline = _readline_module()
        self._completer: Callable[[str, int], str | None] | None = None
        self._closed = False
        readline = self.readline
        if readline is None:
            return
        readline.set_auto_history(False)  # lines are added by remember(), not twice
        self._completer = readline.get_completer()
        readline.set_completer(_complete)
        if "libedit" in (getattr(readline, "__doc__", "") or ""):
            readline.parse_and_bind("bind ^I rl_complete")
        else:
            readline.parse_and_bind("tab: complete")
        if self.history_file is not None and self.history_file.is_file():
            try:
                readline.read_history_file(str(self.history_file))
            except OSError as exc:
                logger.warning("cannot read the history %s: %s", self.history_file, exc)

    def __enter__(self) -> PromptLines:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def __iter__(self) -> Iterator[str]:
        while True:
            try:
                line = self.read(self.prompt)
            except EOFError:
                return
            self.remember(line)
            yield line

    def remember(self, line: str) -> None:
        """Add ``line`` to the history (not empty lines, key codes or a repeat of the last)."""
        readline = self.readline
        text = line.strip() if isinstance(line, str) else ""
        if readline is None or not text or _control_message(text):
            return
        length = readline.get_current_history_length()
        if length and readline.get_history_item(length) == text:
            return
        readline.add_history(text)

    def close(self) -> None:
        """Write the history file (if any) and give back readline's previous completer."""
        readline = self.readline
        if self._closed or readline is None:
            return
        self._closed = True
        readline.set_completer(self._completer)
        readline.set_auto_history(True)
        if self.history_file is None:
            return
        try:
            self.history_file.parent.mkdir(parents=True, exist_ok=True)
            readline.set_history_length(HISTORY_LENGTH)
            readline.write_history_file(str(self.history_file))
        except OSError as exc:
            logger.warning("cannot write the history %s: %s", self.history_file, exc)


def _complete(text: str, state: int) -> str | None:
    """readline completer: the pendant's command words starting with ``text``."""
    matches = [word for word in _COMPLETIONS if word.startswith(text.lower())]
    return matches[state] if state < len(matches) else None


def run_session(
    pendant: TeachPendant,
    lines: Iterable[str],
    output: Callable[[str], None],
    on_move: Callable[[np.ndarray], None] | None = None,
    echo: bool = False,
) -> bool:
    """Feed command lines to the pendant until ``q``/``abort`` or the end of the input.

    The end of the input acts as ``q``: a running recording is stopped and stored.

    Args:
        pendant: The pendant.
        lines: Command lines (e.g. ``sys.stdin``, a :class:`PromptLines` or a list of strings).
        output: Called with the text to show after each command.
        on_move: Called with the new configuration after each move (e.g. a live viewer).
        echo: Show each command before its reply (for scripted input).

    Returns:
        True when the program should be written (``q`` or end of input), False on ``abort``.

    Raises:
        InputError: ``pendant`` is not a :class:`TeachPendant`, ``lines`` not iterable,
            ``output`` or ``on_move`` not callable.
    """
    if not isinstance(pendant, TeachPendant):
        raise InputError(f"pendant must be a TeachPendant, got {checks.describe(pendant)}")
    try:
        if isinstance(lines, (str, bytes)):
            raise TypeError
        lines = iter(lines)
    except TypeError:
        raise InputError(
            f"lines must be an iterable of command lines (a list or a file), got "
            f"{checks.describe(lines)}"
        ) from None
    if not callable(output) or (on_move is not None and not callable(on_move)):
        raise InputError("output and on_move must be functions (on_move may be None)")
    echo = checks.flag(echo, "echo")
    for line in lines:
        if echo and isinstance(line, str) and line.strip():
            output(f"teach> {line.rstrip()}")
        reply = pendant.execute(line)
        if reply.text:
            output(reply.text)
        if reply.moved and on_move is not None:
            on_move(pendant.q)
        if reply.done:
            return reply.write
    reply = pendant.execute("q")  # the end of the input: as q
    if reply.text:
        output(reply.text)
    return True
