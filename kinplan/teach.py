"""A teach pendant in the terminal: jog the arm, record points, write a program.

As in the lecture, the operator moves the arm to each point of the task with a pendant and tells
the controller to record the joint positions there. :class:`TeachPendant` holds the arm's
configuration and executes one line-based command at a time (so scripts and tests can drive it);
:func:`run_session` feeds it lines until ``q`` or the end of input. The recorded points become a
program (start = the configuration the session started from, the points as joint values, a
``ptp`` to each in order) that ``kinplan run`` plans.

The commands are in :data:`HELP` (``help`` prints them): jog a joint (``j 2 -5``), the tool along
x/y/z [m] or about roll/pitch/yaw [deg] (``z -0.01``, ``yaw+``), set the steps, record (``r a``),
``q`` to finish. Tool jogs solve IK seeded from the current configuration and refuse a jog that
is unreachable, beyond a joint limit, or that would flip the arm to another branch.
"""

from __future__ import annotations

import logging
import math
import os
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pinocchio as pin

import cartesian
from kinplan import checks
from kinplan.errors import InputError, KinplanError
from kinplan.robot import Robot

logger = logging.getLogger(__name__)

__all__ = ["HELP", "Reply", "TeachPendant", "home_configuration", "run_session"]

HELP = """\
j <i> <deg>           jog joint i (0-based index or name) by deg; j <i>+ / j <i>- use the step
x|y|z <m>             move the tool along a world axis by m; x+ / x- use the linear step
roll|pitch|yaw <deg>  rotate the tool about the world x|y|z axis through the tool point;
                      roll+ / roll- use the angle step (rx, ry, rz also work)
step <m>              set the linear step [m]
astep <deg>           set the angle step for joints and rotations [deg]
r [name]              record the current configuration (default names p1, p2, ...)
del <name>            forget a recorded point
list                  list the recorded points
home                  go back to the start configuration
show                  show joints and tool pose
help                  this help
q | quit | EOF        write the program and quit
abort                 quit without writing"""
"""The pendant's commands."""

DEFAULT_LINEAR_STEP = 0.01
"""Default tool jog [m]."""
DEFAULT_ANGULAR_STEP_DEG = 5.0
"""Default joint and tool rotation jog [deg]."""
MAX_BRANCH_STEP = 0.5
"""Joint change a tool jog may cause, beyond its length [m] and angle [rad], before it counts as
a branch flip [rad] (jogs are also checked for continuity along the way)."""

_HOME_DEG = {
    "ur": [0.0, -90.0, 90.0, -90.0, -90.0, 0.0],
    "panda": [0.0, -45.0, 0.0, -135.0, 0.0, 90.0, 45.0],
}
_AXES = {"x": 0, "y": 1, "z": 2}
_ROTATIONS = {"roll": 0, "rx": 0, "pitch": 1, "ry": 1, "yaw": 2, "rz": 2}
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
_JOG = re.compile(r"^(?P<axis>[a-z]+)(?P<sign>[+-])$")


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


class TeachPendant:
    """The state of a teach session and its commands.

    Args:
        robot: The arm.
        q_start: Start configuration [rad] (default :func:`home_configuration`).
        robot_source: How the program names the robot (a name or URDF path; default its name).
        linear_step: Tool jog step [m].
        angular_step_deg: Joint and rotation jog step [deg].

    Attributes:
        q: Current configuration [rad].
        points: Recorded points: name → configuration [rad], in recording order.
    """

    def __init__(
        self,
        robot: Robot,
        q_start: np.ndarray | None = None,
        robot_source: str | None = None,
        linear_step: float = DEFAULT_LINEAR_STEP,
        angular_step_deg: float = DEFAULT_ANGULAR_STEP_DEG,
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
        self.linear_step = checks.number(linear_step, "linear_step", positive=True, unit="m")
        self.angular_step = math.radians(
            checks.number(angular_step_deg, "angular_step_deg", positive=True, unit="deg")
        )
        self.points: dict[str, np.ndarray] = {}

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
        words = line.split("#", 1)[0].split()
        if not words:
            return Reply("")
        command, arguments = words[0].lower(), words[1:]
        try:
            return self._dispatch(command, arguments)
        except (ValueError, KinplanError) as exc:
            return Reply(f"error: {exc}")

    def _dispatch(self, command: str, arguments: list[str]) -> Reply:
        simple = {
            "help": lambda: Reply(HELP),
            "?": lambda: Reply(HELP),
            "show": lambda: Reply(self.status()),
            "list": self._list,
            "home": self._home,
            "q": lambda: Reply("", done=True, write=True),
            "quit": lambda: Reply("", done=True, write=True),
            "exit": lambda: Reply("", done=True, write=True),
            "abort": lambda: Reply("", done=True, write=False),
        }
        if command in simple and not arguments:
            return simple[command]()
        if command in ("j", "joint"):
            return self._jog_joint(arguments)
        if command in ("r", "rec", "record"):
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
        return Reply(f"error: unknown command {command!r}; type help for the commands")

    def _jog_joint(self, arguments: list[str]) -> Reply:
        if not arguments:
            raise ValueError("usage: j <index or name> <delta_deg>, or j <index>+ / j <index>-")
        target, sign = arguments[0], ""
        if target[-1] in "+-" and len(target) > 1:
            target, sign = target[:-1], target[-1]
        j = self._joint_index(target)
        if sign and len(arguments) == 1:
            delta = self.angular_step * (1.0 if sign == "+" else -1.0)
        elif len(arguments) == 2 and arguments[1] in ("+", "-"):
            delta = self.angular_step * (1.0 if arguments[1] == "+" else -1.0)
        elif len(arguments) == 2 and not sign:
            delta = math.radians(_finite(arguments[1], "the joint jog [deg]"))
        else:
            raise ValueError("usage: j <index or name> <delta_deg>, or j <index>+ / j <index>-")
        q = self.q.copy()
        q[j] += delta
        robot = self.robot
        if not robot.within_limits(q):
            return Reply(
                f"refused: joint {j} ({robot.joint_names[j]}) would reach "
                f"{math.degrees(q[j]):.2f}°, beyond its limits "
                f"[{math.degrees(robot.lower[j]):.1f}°, {math.degrees(robot.upper[j]):.1f}°]"
            )
        self.q = q
        return Reply(self.status(), moved=True)

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
            raise ValueError(f"joint index {j} is out of range 0..{len(names) - 1}")
        return j

    def _jog_tool(self, axis: str, sign: str, arguments: list[str]) -> Reply:
        rotate = axis in _ROTATIONS
        if sign and not arguments:
            step = self.angular_step if rotate else self.linear_step
            delta = step if sign == "+" else -step
        elif len(arguments) == 1 and not sign:
            value = _finite(arguments[0], "the jog [deg]" if rotate else "the jog [m]")
            delta = math.radians(value) if rotate else value
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
        if len(check.q):
            q = check.q[-1]
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
        self.q = np.array(q)
        return Reply(self.status(), moved=True)

    def _set_step(self, arguments: list[str], angular: bool) -> Reply:
        usage = f"usage: {'astep <deg>' if angular else 'step <m>'} (a number > 0)"
        if len(arguments) != 1:
            raise ValueError(usage)
        value = _finite(arguments[0], "the step")
        if value <= 0:
            raise ValueError(usage)
        if angular:
            self.angular_step = math.radians(value)
            return Reply(f"angle step {value:g}°")
        self.linear_step = value
        return Reply(f"linear step {value:g} m")

    def _record(self, arguments: list[str]) -> Reply:
        if len(arguments) > 1:
            raise ValueError("usage: r [name]")
        name = arguments[0] if arguments else self._next_name()
        if not _NAME.match(name):
            raise ValueError(
                f"point name {name!r}: use letters, digits, _ and -, not first a digit"
            )
        if name in self.points:
            return Reply(f"refused: a point {name!r} exists; give another name or del {name}")
        self.points[name] = self.q.copy()
        xyz = ", ".join(f"{v:.4f}" for v in self.robot.fk(self.q).translation)
        return Reply(f"recorded {name} (tool at ({xyz}) m); {len(self.points)} points")

    def _next_name(self) -> str:
        k = len(self.points) + 1
        while f"p{k}" in self.points:
            k += 1
        return f"p{k}"

    def _delete(self, arguments: list[str]) -> Reply:
        if len(arguments) != 1:
            raise ValueError("usage: del <name>")
        if self.points.pop(arguments[0], None) is None:
            return Reply(f"no point {arguments[0]!r}; recorded: {', '.join(self.points) or 'none'}")
        return Reply(f"deleted {arguments[0]}")

    def _list(self) -> Reply:
        if not self.points:
            return Reply("no points recorded yet (r [name] records one)")
        lines = []
        for name, q in self.points.items():
            xyz = ", ".join(f"{v:.4f}" for v in self.robot.fk(q).translation)
            degrees = ", ".join(f"{v:.2f}" for v in np.degrees(q))
            lines.append(f"{name}: joints [{degrees}] deg, tool ({xyz}) m")
        return Reply("\n".join(lines))

    def _home(self) -> Reply:
        self.q = self.start.copy()
        return Reply(self.status(), moved=True)

    # -- program -------------------------------------------------------------------------------
    def program_text(self, output: str | os.PathLike[str] | None = None) -> str:
        """The program as YAML: start, the recorded points as joints, a ptp to each in order.

        Args:
            output: Where the program will be written; a URDF robot source is written relative
                to its folder.

        Raises:
            KinplanError: no point recorded yet.
            InputError: ``output`` is not a file path.
        """
        if output is not None:
            output = checks.file_path(output, "output (the program file)")
        if not self.points:
            raise KinplanError("no point recorded; record one with r [name] before writing")
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
        for name, q in self.points.items():
            xyz = ", ".join(f"{v:.4f}" for v in self.robot.fk(q).translation)
            lines.append(f"  {name}: {{joints_deg: {_degrees(q)}}}  # tool at ({xyz}) m")
        lines.append("moves:")
        lines += [f"  - {{ptp: {name}}}" for name in self.points]
        return "\n".join(lines) + "\n"

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
            KinplanError: no point recorded yet, or the file cannot be written.
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


def _check_robot(robot: object) -> None:
    if not isinstance(robot, Robot):
        raise InputError(
            f"robot must be a kinplan.Robot (from kinplan.load_robot), got {checks.describe(robot)}"
        )


def _finite(text: str, what: str) -> float:
    """A finite number typed by the operator (ValueError with a message otherwise)."""
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{what} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number, got {text!r}")
    return value


def _pendant_advice(event, robot: Robot) -> str:
    """The pendant's advice for a refused jog's event (see :data:`_PENDANT_ADVICE`)."""
    advice = _PENDANT_ADVICE.get(event.kind, "")
    joint = getattr(event, "joint", None)
    if event.kind == "joint_limit" and joint in robot.joint_names:
        j = robot.joint_names.index(joint)
        advice = advice.replace("that joint", f"joint {j} ({joint})").replace("<joint>", str(j))
    return advice


def _degrees(q: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.6f}".rstrip("0").rstrip(".") for v in np.degrees(q)) + "]"


def _yaml_scalar(text: str) -> str:
    """``text`` as a YAML scalar (quoted when plain style would change its meaning)."""
    import yaml

    return yaml.safe_dump(text, default_style=None).splitlines()[0].removesuffix(" ...")


def run_session(
    pendant: TeachPendant,
    lines: Iterable[str],
    output: Callable[[str], None],
    on_move: Callable[[np.ndarray], None] | None = None,
    echo: bool = False,
) -> bool:
    """Feed command lines to the pendant until ``q``/``abort`` or the end of the input.

    Args:
        pendant: The pendant.
        lines: Command lines (e.g. ``sys.stdin`` or a list of strings).
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
    return True
