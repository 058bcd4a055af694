"""Motion programs: a YAML file of taught points and moves, validated and planned.

A program names a robot, a start configuration, taught points and a list of moves::

    robot: ur5                 # a load_robot source; a URDF path is relative to this file
    tip: tool0                 # optional
    start: {joints_deg: [0, -90, 90, -90, -90, 0]}
    points:                    # joints / joints_deg, or xyz [m] (+ rpy_deg or quat_xyzw)
      a: {xyz: [0.40, -0.10, 0.20], rpy_deg: [180, 0, 90]}
      b: {xyz: [0.40,  0.10, 0.20], rpy_deg: [180, 0, 90]}
      c: {xyz: [0.50,  0.00, 0.20], rpy_deg: [180, 0, 90]}
    moves:                     # ptp: joint-interpolated; lin: straight line; circ: arc via a point
      - {ptp: a, duration: 2.0}
      - {lin: b, speed: 0.02}
      - {circ: a, via: c, speed: 0.02}

Moves and their options:

- ``ptp``: joint-interpolated. By default a coordinated minimum-time trapezoid: every joint
  cruises within ``speed`` × its velocity limit (``speed`` is a fraction in (0, 1], default
  :data:`DEFAULT_PTP_SPEED`) and reaches its cruise speed in :data:`PTP_RAMP_TIME`; with a
  ``duration`` [s] the move takes that long (and must stay within the velocity limits).
  ``profile``: ``trapezoid`` (default), ``quintic``, ``cubic``, ``scurve`` (jerk-limited, jerk
  ramps of :data:`PTP_JERK_TIME`) or ``time_optimal`` (fastest within the velocity and
  acceleration limits); ``scurve`` and ``time_optimal`` use the robot's acceleration limits
  where it has them (else the :data:`PTP_RAMP_TIME` ramp), and with a ``duration`` the full
  limits, refusing a duration they cannot meet with the minimum it needs. A ``ptp`` to a
  Cartesian point solves IK seeded from the current configuration, so the arm stays on its
  branch.
- ``lin``: the tool moves on a straight line from its current pose, at a tool ``speed`` [m/s]
  (default :data:`DEFAULT_TOOL_SPEED`) or in a ``duration`` [s], with the 1-D ``profile``.
- ``circ``: the tool moves on the arc through ``via`` to the target, as ``lin``.

A Cartesian point given by ``xyz`` alone keeps the tool orientation the move starts with (arms
with 6 or more joints) or is position-only (arms with fewer). Every move starts from the end
state of the previous one.

Optional robot keys, passed to :func:`kinplan.load_robot`: ``locked_joints: {name: value}``
[rad, or m for a prismatic joint], ``limits: {joint: {lower, upper, velocity, acceleration}}``
(any subset) [rad or m, per s, per s²], ``package_dirs: [folder, ...]`` (mesh folders,
relative to the program file) and ``base_pose: {xyz: [..], rpy_deg: [..] | quat_xyzw: [..]}``
(the robot's root in the world, in which the points are given).

:func:`load_program` reads and validates a whole file and raises one :class:`ProgramError`
listing every problem with its key path (``moves[2].lin``) and YAML line; :func:`plan_program`
plans it into a :class:`ProgramPlan`. A move that cannot be done stops planning: the plan has
``ok = False`` and a one-line ``reason`` naming the move and where it failed; it holds the motion
up to the failure for inspection. :class:`MotionBuilder` chains the same moves from Python, and
also follows any :class:`cartesian.Path` (a weld seam made of lines and arcs, say).
"""

from __future__ import annotations

import logging
import math
import os
import re
import reprlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin
import yaml

import cartesian
from kinplan import checks, trajectory
from kinplan._profiles import PROFILES, PTP_PROFILES, REST_TO_REST_PEAKS, quintic_coefficients
from kinplan.errors import InfeasibleError, InputError, KinplanError
from kinplan.motion import MotionKind, PlannedPath, pose_to_track
from kinplan.robot import Robot, load_robot, manipulability_of
from kinplan.sampling import joint_speeds, motion_step
from kinplan.sources import bundled_robots, known_names
from kinplan.trajectory import Segment, Trajectory, Waypoints
from kinplan.urdf_model import LIMIT_KEYS

logger = logging.getLogger(__name__)

__all__ = [
    "DEFAULT_DT",
    "DEFAULT_PTP_SPEED",
    "DEFAULT_TOOL_SPEED",
    "Issue",
    "Move",
    "MoveError",
    "MoveReport",
    "MotionBuilder",
    "PROFILES",
    "PTP_JERK_TIME",
    "PTP_RAMP_TIME",
    "Point",
    "Program",
    "ProgramError",
    "ProgramPlan",
    "load_program",
    "parse_program",
    "plan_program",
    "run_program",
]

MOVE_KINDS = ("ptp", "lin", "circ")
DEFAULT_DT = 0.01
"""Sampling period of planned programs [s]."""
DEFAULT_PTP_SPEED = 0.5
"""Cruise speed of a ``ptp`` move without ``speed``/``duration``, share of the joint limits [-]."""
PTP_RAMP_TIME = 0.5
"""Time a ``ptp`` joint takes to reach its cruise speed (sets the joint acceleration) [s]."""
PTP_JERK_TIME = 0.1
"""Time an ``scurve`` ``ptp`` joint takes to build up its acceleration (sets the jerk) [s]."""
FALLBACK_JOINT_SPEED = 1.0
"""Velocity limit assumed for joints whose URDF gives none [rad/s]."""
DEFAULT_TOOL_SPEED = 0.05
"""Tool cruise speed of ``lin``/``circ`` moves without ``speed``/``duration`` [m/s]."""
JOIN_TOLERANCE = 1e-6
"""Largest joint gap accepted where a Cartesian move starts from the previous end [rad]."""
MAX_COORDINATE = 1e6
"""Largest |x|, |y|, |z| of a taught tool position [m]: anything beyond is a typo in a program
(and out of reach of any arm)."""

_TOP_KEYS = (
    "robot",
    "tip",
    "locked_joints",
    "limits",
    "package_dirs",
    "base_pose",
    "start",
    "points",
    "moves",
    "description",
)
_POSE_KEYS = ("xyz", "rpy_deg", "quat_xyzw")
_INVALID = object()
"""What a robot option's validator returns when it reported a problem."""
_POINT_KEYS = ("joints", "joints_deg", "xyz", "rpy_deg", "quat_xyzw")
_MOVE_OPTIONS = ("via", "duration", "speed", "profile", "name")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\-]*$")

KeyPath = tuple[str | int, ...]


# ----------------------------------------------------------------------------------------------
# Errors
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Issue:
    """One problem of a program file.

    Attributes:
        path: Key path, e.g. ``moves[2].lin`` (``program`` for the file as a whole).
        message: What is wrong and what is expected.
        line: 1-based line of the YAML file, when known.
    """

    path: str
    message: str
    line: int | None = None

    def __str__(self) -> str:
        where = f"{self.path} (line {self.line})" if self.line else self.path
        return f"{where}: {self.message}"


class ProgramError(KinplanError):
    """A program file is invalid; :attr:`issues` lists every problem found.

    ``str(error)`` is a header line followed by one indented line per issue; :meth:`one_line`
    puts them on a single line (for command-line error messages).
    """

    def __init__(self, source: str, issues: Sequence[Issue]):
        self.source = source
        self.issues = list(issues)
        count = len(self.issues)
        self.header = f"{source}: {count} error{'s' if count != 1 else ''} in the program"
        super().__init__("\n".join([self.header + ":"] + [f"  - {issue}" for issue in issues]))

    def one_line(self) -> str:
        """The header and every issue on one line, issues separated by `` | ``."""
        return f"{self.header}: " + " | ".join(str(issue) for issue in self.issues)


class MoveError(KinplanError):
    """A move cannot be done; the message is one line naming the move and where it failed.

    Attributes:
        report: The failed move's report.
    """

    def __init__(self, message: str, report: MoveReport):
        super().__init__(message)
        self.report = report


# ----------------------------------------------------------------------------------------------
# Program contents
# ----------------------------------------------------------------------------------------------


@dataclass
class Point:
    """A taught point: joint values, or a tool position with an optional orientation.

    Attributes:
        name: Point name.
        joints: Joint values [rad], shape (nq,), or None for a Cartesian point.
        position: Tool position [m], shape (3,), or None for a joint point.
        rotation: Tool rotation (3×3) or None (keep the move's start orientation / position only).
        key: Key path in the program (``points.a``).
    """

    name: str
    joints: np.ndarray | None = None
    position: np.ndarray | None = None
    rotation: np.ndarray | None = None
    key: str = ""

    def tool_position(self, robot: Robot) -> np.ndarray:
        """Tool position of the point [m] (by forward kinematics for a joint point)."""
        if self.joints is not None:
            return np.array(robot.fk(self.joints).translation)
        return np.array(self.position)

    def goal(self, robot: Robot) -> np.ndarray | pin.SE3:
        """The point as a Cartesian goal: a pose, or a position [m] when no orientation is
        given (a joint point's pose by forward kinematics)."""
        if self.joints is not None:
            return robot.fk(self.joints)
        if self.rotation is None:
            return self.position.copy()
        return pin.SE3(self.rotation, self.position)


@dataclass
class Move:
    """One move of a program.

    Attributes:
        index: Position in the ``moves`` list (0-based).
        kind: ``ptp``, ``lin`` or ``circ``.
        target: Name of the target point.
        via: Name of the via point (``circ`` only).
        duration: Requested duration [s] or None.
        speed: Tool speed [m/s] (lin, circ) or share of the joint velocity limits (ptp), or None.
        profile: ``trapezoid``, ``quintic`` or ``cubic``.
        name: Optional label given in the file.
    """

    index: int
    kind: str
    target: str
    via: str | None = None
    duration: float | None = None
    speed: float | None = None
    profile: str = "trapezoid"
    name: str | None = None

    @property
    def key(self) -> str:
        """Key path in the program, e.g. ``moves[2]``."""
        return f"moves[{self.index}]"

    @property
    def label(self) -> str:
        """Short description, e.g. ``lin to b`` or ``circ to a via c``."""
        text = f"{self.kind} to {self.target}"
        if self.via is not None:
            text += f" via {self.via}"
        return f"{self.name}: {text}" if self.name else text


@dataclass
class Program:
    """A validated program, ready to plan.

    Attributes:
        source: File name (or ``<string>``).
        robot: The loaded robot.
        robot_source: The ``robot`` entry as written.
        start: Start configuration [rad], shape (nq,).
        points: Taught points by name, in file order.
        moves: The moves, in order.
        description: Free text from the file.
        warnings: Non-fatal remarks (e.g. an orientation ignored by a planar arm).
    """

    source: str
    robot: Robot
    robot_source: str
    start: np.ndarray
    points: dict[str, Point]
    moves: list[Move]
    description: str = ""
    warnings: list[str] = field(default_factory=list)


# ----------------------------------------------------------------------------------------------
# Reading and validation
# ----------------------------------------------------------------------------------------------


class _ProgramLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 floats.

    YAML 1.1 (PyYAML's default) only reads a float with a dot and a signed exponent, so
    ``speed: 1e9`` or ``1.0e9`` would be a string; YAML 1.2's core schema reads ``1e9``,
    ``1.0e9``, ``.5`` and ``-2E-3`` as floats, as programs mean them.
    """


_ProgramLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"^[-+]?(?:(?:[0-9][0-9_]*)?\.[0-9_]+(?:[eE][-+]?[0-9]+)?"  # .5, 1.5, 1.5e9
        r"|[0-9][0-9_]*\.(?:[eE][-+]?[0-9]+)?"  # 1., 1.e9
        r"|[0-9][0-9_]*[eE][-+]?[0-9]+)$"  # 1e9, 2E-3
    ),
    list("-+0123456789."),
)


def load_program(path: str | os.PathLike[str]) -> Program:
    """Read and validate a program file.

    Args:
        path: The YAML file (UTF-8); a URDF path in it is relative to the file's folder.

    Raises:
        ProgramError: the file is missing, unreadable, not UTF-8 text, not YAML, or invalid
            (every problem is listed with its key path and line).
        InputError: ``path`` is not a file path (str or os.PathLike).
    """
    file = Path(checks.file_path(path, "path (the program file)"))
    try:
        raw = file.read_bytes()
    except OSError as exc:
        reason = exc.strerror or str(exc)
        issue = Issue("program", f"cannot read the file: {reason}")
        raise ProgramError(str(file), [issue]) from exc
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        issue = Issue(
            "program",
            f"the file is not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset {exc.start}); "
            "save it with UTF-8 encoding",
            line,
        )
        raise ProgramError(str(file), [issue]) from None
    return parse_program(text, base_dir=file.parent, source=str(file))


def parse_program(
    text: str,
    base_dir: str | os.PathLike[str] | None = None,
    source: str = "<string>",
) -> Program:
    """Parse and validate the YAML text of a program.

    Args:
        text: The program.
        base_dir: Folder that relative URDF paths are taken from (default: current directory).
        source: Name used in messages.

    Raises:
        ProgramError: listing every problem found.
        InputError: ``text`` is not a string, ``base_dir`` not a path, ``source`` not a string.
    """
    source = checks.text(source, "source (the program's name in messages)")
    if not isinstance(text, str):
        raise InputError(f"text must be the program's YAML text (a str), got {_describe(text)}")
    if base_dir is not None:
        base_dir = checks.file_path(base_dir, "base_dir (the folder of relative URDF paths)")
    try:
        node = yaml.compose(text, Loader=_ProgramLoader)
        data = yaml.load(text, Loader=_ProgramLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark is not None else None
        problem = getattr(exc, "problem", None) or (str(exc).splitlines() or ["?"])[0]
        raise ProgramError(source, [Issue("program", f"not valid YAML: {problem}", line)]) from exc
    except RecursionError:
        issue = Issue("program", "nested too deeply to read; flatten the lists and mappings")
        raise ProgramError(source, [issue]) from None
    lines: dict[KeyPath, int] = {}
    duplicates: list[tuple[KeyPath, str, int]] = []
    if node is not None:
        _index_lines(node, (), lines, duplicates, set())
    validator = _Validator(lines, Path(base_dir) if base_dir is not None else Path.cwd())
    for path, key, line in duplicates:
        validator.issues.append(
            Issue(_format_path(path), f"duplicate key {key!r}; each key may appear once", line)
        )
    program = validator.program(data, source)
    if validator.issues or program is None:
        issues = sorted(validator.issues, key=lambda issue: issue.line or math.inf)
        raise ProgramError(source, issues)
    return program


def _index_lines(
    node: yaml.Node, path: KeyPath, lines: dict[KeyPath, int], duplicates: list, visited: set
) -> None:
    """Record the 1-based line of every key path of the YAML node tree (and duplicate keys).

    A node reached again through an alias (``*name``) is not walked twice: aliases can make the
    tree cyclic or exponentially large.
    """
    lines[path] = node.start_mark.line + 1
    if id(node) in visited:
        return
    visited.add(id(node))
    if isinstance(node, yaml.MappingNode):
        seen = set()
        for key_node, value_node in node.value:
            key = str(key_node.value) if isinstance(key_node, yaml.ScalarNode) else "<complex key>"
            if key in seen:
                duplicates.append((path + (key,), key, key_node.start_mark.line + 1))
            seen.add(key)
            _index_lines(value_node, path + (key,), lines, duplicates, visited)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _index_lines(item, path + (i,), lines, duplicates, visited)


def _format_path(path: KeyPath) -> str:
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "program"


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxdict, _REPR.maxstring, _REPR.maxother = 3, 6, 4, 40, 40


def _to_float(value: float) -> float:
    """A YAML number as a float (an integer beyond the float range is inf)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def _describe(value: object) -> str:
    """A short repr (bounded in depth and length: a value may be a huge aliased structure)."""
    text = " ".join(_REPR.repr(value).split())
    return text if len(text) <= 60 else text[:57] + "..."


class _Validator:
    """Walks the parsed YAML, collecting every issue with its key path and line."""

    def __init__(self, lines: dict[KeyPath, int], base_dir: Path):
        self.lines = lines
        self.base_dir = base_dir
        self.issues: list[Issue] = []
        self.warnings: list[str] = []
        self.robot: Robot | None = None

    # -- reporting ---------------------------------------------------------------------------
    def line(self, path: KeyPath) -> int | None:
        while path not in self.lines and path:
            path = path[:-1]
        return self.lines.get(path)

    def error(self, path: KeyPath, message: str) -> None:
        self.issues.append(Issue(_format_path(path), message, self.line(path)))

    def warn(self, path: KeyPath, message: str) -> None:
        self.warnings.append(f"{_format_path(path)}: {message}")

    # -- values --------------------------------------------------------------------------------
    def numbers(
        self,
        value: object,
        path: KeyPath,
        count: int | None,
        what: str,
        bound: float = math.inf,
    ) -> np.ndarray:
        """A list of ``count`` finite numbers (each within ±``bound``), or None (after
        reporting) if it is not one."""
        expected = f"a list of {count} numbers" if count else "a list of numbers"
        if not isinstance(value, list) or not all(_is_number(v) for v in value):
            self.error(path, f"expected {expected} ({what}), got {_describe(value)}")
            return None
        if count is not None and len(value) != count:
            self.error(path, f"expected {count} numbers ({what}), got {len(value)}")
            return None
        try:
            array = np.array(value, dtype=float)
        except OverflowError:  # an integer beyond the float range
            array = np.full(len(value), math.inf)
        if not np.all(np.isfinite(array)):
            self.error(path, f"expected finite numbers ({what}), got {_describe(value)}")
            return None
        if np.any(np.abs(array) > bound):
            self.error(path, f"expected numbers within ±{bound:g} ({what}), got {_describe(value)}")
            return None
        return array

    def positive(self, value: object, path: KeyPath, what: str) -> float | None:
        if not _is_number(value) or not math.isfinite(_to_float(value)) or value <= 0:
            self.error(path, f"expected a number > 0 ({what}), got {_describe(value)}")
            return None
        return _to_float(value)

    def joints(self, spec: Mapping, path: KeyPath) -> np.ndarray | None:
        """Joint values [rad] from ``joints`` or ``joints_deg``, checked against the limits."""
        robot = self.robot
        nq = robot.nq if robot else None
        names = f" of {robot.name}: {', '.join(robot.joint_names)}" if robot else ""
        in_degrees = "joints_deg" in spec
        key = "joints_deg" if in_degrees else "joints"
        unit = "deg" if in_degrees else "rad"
        values = self.numbers(spec[key], path + (key,), nq, f"joint values [{unit}]{names}")
        if values is None:
            return None
        q = np.radians(values) if in_degrees else values
        if robot is not None:
            scale = np.degrees if in_degrees else (lambda x: x)
            beyond = np.flatnonzero((q < robot.lower - 1e-9) | (q > robot.upper + 1e-9))
            for j in beyond:
                self.error(
                    path + (key,),
                    f"joint {j} ({robot.joint_names[j]}) = {values[j]:g} {unit} is beyond its "
                    f"limits [{scale(robot.lower[j]):.6g}, {scale(robot.upper[j]):.6g}] {unit}",
                )
            if beyond.size:
                return None  # reported; not used as an IK seed either
        return q

    # -- sections ------------------------------------------------------------------------------
    def program(self, data: object, source: str) -> Program | None:
        if not isinstance(data, dict):
            self.error(
                (),
                "expected a mapping with robot, start, points and moves at the top level, got "
                f"{_describe(data)}",
            )
            return None
        for key in data:
            if str(key) not in _TOP_KEYS:
                self.error(
                    (str(key),), f"unknown key {key!r}; expected keys: {', '.join(_TOP_KEYS)}"
                )
        robot_source = self.load_robot(data)
        start = self.start(data)
        points = self.points(data.get("points"), start)
        moves = self.moves(data.get("moves"), points)
        description = data.get("description", "")
        if not isinstance(description, str):
            self.error(("description",), f"expected text, got {_describe(description)}")
        if self.issues or self.robot is None or start is None:
            return None
        program = Program(
            source=source,
            robot=self.robot,
            robot_source=robot_source,
            start=start,
            points=points,
            moves=moves,
            description=description or "",
            warnings=self.warnings,
        )
        return program

    def load_robot(self, data: dict) -> str:
        source = data.get("robot")
        tip = data.get("tip")
        if tip is not None and not isinstance(tip, str):
            self.error(("tip",), f"expected a frame or link name, got {_describe(tip)}")
            tip = None
        if source is None:
            self.error(
                ("robot",),
                f"missing; give a robot name ({', '.join(known_names())}) or a URDF path",
            )
            return ""
        if not isinstance(source, str):
            self.error(("robot",), f"expected a robot name or URDF path, got {_describe(source)}")
            return ""
        options = {
            "locked_joints": self.locked_joints(data.get("locked_joints")),
            "limits": self.limits(data.get("limits")),
            "package_dirs": self.package_dirs(data.get("package_dirs")),
            "base_pose": self.base_pose(data.get("base_pose")),
        }
        if any(value is _INVALID for value in options.values()):
            return source  # reported; the robot would not be the one the program means
        try:
            self.robot = _load_robot(resolve_robot_source(source, self.base_dir), tip, **options)
        except KinplanError as exc:
            self.error(self.robot_error_path(str(exc), type(exc).__name__, data), str(exc))
        return source

    @staticmethod
    def robot_error_path(message: str, kind: str, data: dict) -> KeyPath:
        """The key a loading error is about: a joint of ``locked_joints:`` or ``limits:`` (its
        message starts with the key), ``tip`` (a frame error) or ``robot``."""
        for key in ("locked_joints", "limits", "base_pose", "package_dirs"):
            if message.startswith(key):
                entries = data.get(key)
                named = re.search(r"(?:no joint |\[)'([^']*)'", message)
                if isinstance(entries, dict) and named and named.group(1) in entries:
                    return (key, named.group(1))
                return (key,)
        return ("tip",) if "frame" in kind.lower() else ("robot",)

    # -- robot options -------------------------------------------------------------------------
    def locked_joints(self, spec: object) -> dict[str, float] | None | object:
        """``locked_joints: {name: value}`` [rad, or m for a prismatic joint]."""
        if spec is None:
            return None
        path: KeyPath = ("locked_joints",)
        if not isinstance(spec, dict) or not spec:
            self.error(
                path,
                "expected a mapping {joint name: value} (rad, or m for a prismatic joint), got "
                f"{_describe(spec)}",
            )
            return _INVALID
        locked: dict[str, float] = {}
        ok = True
        for name, value in spec.items():
            if not _is_number(value) or not math.isfinite(_to_float(value)):
                self.error(
                    path + (str(name),),
                    "expected the joint's value, a finite number (rad, or m for a prismatic "
                    f"joint), got {_describe(value)}",
                )
                ok = False
            else:
                locked[str(name)] = _to_float(value)
        return locked if ok else _INVALID

    def limits(self, spec: object) -> dict[str, dict[str, float]] | None | object:
        """``limits: {joint: {lower, upper, velocity, acceleration}}`` (any subset) [rad or m,
        /s, /s²]."""
        if spec is None:
            return None
        path: KeyPath = ("limits",)
        keys = ", ".join(LIMIT_KEYS)
        if not isinstance(spec, dict) or not spec:
            self.error(
                path, f"expected a mapping {{joint name: {{{keys}}}}}, got {_describe(spec)}"
            )
            return _INVALID
        limits: dict[str, dict[str, float]] = {}
        ok = True
        for name, entry in spec.items():
            where = path + (str(name),)
            if not isinstance(entry, dict) or not entry:
                self.error(
                    where,
                    f"expected a mapping with any of {keys} (rad or m; velocity per s, "
                    f"acceleration per s²), got {_describe(entry)}",
                )
                ok = False
                continue
            values: dict[str, float] = {}
            for key, value in entry.items():
                if key not in LIMIT_KEYS:
                    self.error(where + (str(key),), f"unknown key {key!r}; expected {keys}")
                    ok = False
                elif key in ("velocity", "acceleration"):
                    unit = "rad/s or m/s" if key == "velocity" else "rad/s² or m/s²"
                    number = self.positive(value, where + (key,), f"{key} limit [{unit}]")
                    ok = ok and number is not None
                    if number is not None:
                        values[key] = number
                elif not _is_number(value) or not math.isfinite(_to_float(value)):
                    self.error(
                        where + (key,),
                        f"expected a finite number ({key} limit [rad or m]), got "
                        f"{_describe(value)}",
                    )
                    ok = False
                else:
                    values[key] = _to_float(value)
            if "lower" in values and "upper" in values and values["lower"] >= values["upper"]:
                self.error(
                    where,
                    f"lower {values['lower']:g} must be below upper {values['upper']:g}",
                )
                ok = False
            limits[str(name)] = values
        return limits if ok else _INVALID

    def package_dirs(self, spec: object) -> list[Path] | None | object:
        """``package_dirs: [folder, ...]``: mesh folders, relative to the program's folder."""
        if spec is None:
            return None
        path: KeyPath = ("package_dirs",)
        if isinstance(spec, str):
            spec = [spec]
        if not isinstance(spec, list) or not spec or not all(isinstance(d, str) for d in spec):
            self.error(path, f"expected a list of folders, got {_describe(spec)}")
            return _INVALID
        folders = []
        for k, text in enumerate(spec):
            folder = Path(text).expanduser()
            folder = folder if folder.is_absolute() else self.base_dir / folder
            if not folder.is_dir():
                self.error(
                    path + (k,),
                    f"no folder {str(folder)!r} (relative folders are taken from the program's "
                    "folder)",
                )
                return _INVALID
            folders.append(folder)
        return folders

    def base_pose(self, spec: object) -> pin.SE3 | None | object:
        """``base_pose: {xyz: [..] m, rpy_deg: [..] | quat_xyzw: [..]}``: the robot's root in
        the world."""
        if spec is None:
            return None
        path: KeyPath = ("base_pose",)
        if not isinstance(spec, dict) or "xyz" not in spec:
            self.error(
                path,
                "expected {xyz: [x, y, z]} [m] with rpy_deg: [r, p, y] or quat_xyzw: [x, y, z, "
                f"w] (the robot's root in the world), got {_describe(spec)}",
            )
            return _INVALID
        unknown = [key for key in spec if key not in _POSE_KEYS]
        for key in unknown:
            self.error(path + (str(key),), f"unknown key {key!r}; expected {', '.join(_POSE_KEYS)}")
        point = self.cartesian_pose(spec, path, "the robot's root position [m]")
        if unknown or point is None:
            return _INVALID
        position, rotation = point
        return pin.SE3(np.eye(3) if rotation is None else rotation, position)

    def cartesian_pose(
        self, spec: dict, path: KeyPath, what: str = "tool position [m]"
    ) -> tuple[np.ndarray, np.ndarray | None] | None:
        """(position [m], rotation or None) of ``xyz`` with ``rpy_deg`` or ``quat_xyzw``; None
        after reporting a problem."""
        position = self.numbers(spec["xyz"], path + ("xyz",), 3, what, bound=MAX_COORDINATE)
        rotation = None
        if "rpy_deg" in spec and "quat_xyzw" in spec:
            self.error(path, "give rpy_deg or quat_xyzw, not both")
            return None
        if "rpy_deg" in spec:
            rpy = self.numbers(spec["rpy_deg"], path + ("rpy_deg",), 3, "roll, pitch, yaw [deg]")
            if rpy is None:
                return None
            rotation = pin.rpy.rpyToMatrix(*np.radians(rpy))
        elif "quat_xyzw" in spec:
            quat = self.numbers(spec["quat_xyzw"], path + ("quat_xyzw",), 4, "quaternion x y z w")
            if quat is None:
                return None
            with np.errstate(over="ignore"):
                norm = float(np.linalg.norm(quat))
            if not math.isfinite(norm):
                self.error(path + ("quat_xyzw",), "the quaternion is too large; give a unit one")
                return None
            if norm < 1e-9:
                self.error(path + ("quat_xyzw",), "the quaternion is zero; give a unit quaternion")
                return None
            if abs(norm - 1.0) > 1e-3:
                self.warn(path + ("quat_xyzw",), f"quaternion of norm {norm:.4g} normalised")
            x, y, z, w = np.asarray(quat, dtype=float) / norm
            rotation = pin.Quaternion(w, x, y, z).toRotationMatrix()
        return None if position is None else (position, rotation)

    def start(self, data: dict) -> np.ndarray | None:
        spec = data.get("start")
        if spec is None:
            self.error(("start",), "missing; expected {joints: [...]} [rad] or {joints_deg: [...]}")
            return None
        if (
            not isinstance(spec, dict)
            or len([k for k in ("joints", "joints_deg") if k in spec]) != 1
        ):
            self.error(
                ("start",),
                "expected {joints: [...]} [rad] or {joints_deg: [...]} (the start is a joint "
                f"configuration), got {_describe(spec)}",
            )
            return None
        for key in spec:
            if key not in ("joints", "joints_deg"):
                self.error(
                    ("start", str(key)), f"unknown key {key!r}; expected joints or joints_deg"
                )
        return self.joints(spec, ("start",))

    def points(self, spec: object, start: np.ndarray | None) -> dict[str, Point]:
        if spec is None:
            return {}
        if not isinstance(spec, dict):
            self.error(("points",), f"expected a mapping of point names, got {_describe(spec)}")
            return {}
        points = {}
        for name, value in spec.items():
            point = self.point(str(name), value, ("points", str(name)), start)
            if point is not None:
                points[str(name)] = point
            else:
                points[str(name)] = Point(str(name))  # known name, so moves don't re-report it
        return points

    def point(
        self, name: str, spec: object, path: KeyPath, start: np.ndarray | None
    ) -> Point | None:
        expected = "joints, joints_deg, or xyz (+ rpy_deg or quat_xyzw)"
        if not isinstance(spec, dict):
            self.error(path, f"expected a mapping with {expected}, got {_describe(spec)}")
            return None
        if not _NAME.match(name):
            self.error(
                path, f"point name {name!r} must start with a letter or _ (letters, digits, _ . -)"
            )
        for key in spec:
            if key not in _POINT_KEYS:
                self.error(path + (str(key),), f"unknown key {key!r}; expected {expected}")
        kinds = [key for key in ("joints", "joints_deg", "xyz") if key in spec]
        if len(kinds) != 1:
            found = f"got {', '.join(kinds)}" if kinds else "got none of them"
            self.error(path, f"give exactly one of joints, joints_deg or xyz; {found}")
            return None
        if kinds[0] != "xyz":
            for key in ("rpy_deg", "quat_xyzw"):
                if key in spec:
                    self.error(path + (key,), f"{key} only goes with xyz (joints fix the pose)")
            q = self.joints(spec, path)
            return Point(name, joints=q, key=_format_path(path)) if q is not None else None
        return self.cartesian_point(name, spec, path, start)

    def cartesian_point(
        self, name: str, spec: dict, path: KeyPath, start: np.ndarray | None
    ) -> Point | None:
        pose = self.cartesian_pose(spec, path)
        if pose is None:
            return None
        position, rotation = pose
        robot = self.robot
        if robot is not None and rotation is not None and robot.default_position_only():
            self.warn(
                path,
                f"{robot.name} has {robot.nq} joints and is planned position-only; the "
                "orientation is ignored",
            )
            rotation = None
        point = Point(name, position=position, rotation=rotation, key=_format_path(path))
        if robot is not None:
            self.check_reachable(point, path, start)
        return point

    def check_reachable(self, point: Point, path: KeyPath, start: np.ndarray | None) -> None:
        """Report a point no configuration within the joint limits reaches."""
        robot = self.robot
        target = (
            point.position if point.rotation is None else pin.SE3(point.rotation, point.position)
        )
        result = robot.ik(target, q_seed=start, position_only=point.rotation is None)
        if result.success:
            return
        where = ", ".join(f"{x:.4g}" for x in point.position)
        from cartesian.events import out_of_reach

        why = out_of_reach(robot, result, point.position)
        fix = "move the point" + ("" if point.rotation is None else " or change its orientation")
        self.error(path, f"({where}) m is out of reach of {robot.name}: {why}; {fix}")

    def moves(self, spec: object, points: dict[str, Point]) -> list[Move]:
        if spec is None:
            self.error(("moves",), "missing; expected a list of moves such as {ptp: a}")
            return []
        if not isinstance(spec, list) or not spec:
            self.error(("moves",), f"expected a non-empty list of moves, got {_describe(spec)}")
            return []
        moves = []
        for index, item in enumerate(spec):
            move = self.move(index, item, points)
            if move is not None:
                moves.append(move)
        return moves

    def point_name(self, value: object, path: KeyPath, points: dict[str, Point]) -> str | None:
        known = ", ".join(points) if points else "none (add a points: section)"
        if not isinstance(value, (str, int)) or isinstance(value, bool):
            self.error(path, f"expected the name of a point; known points: {known}")
            return None
        if str(value) not in points:
            self.error(path, f"unknown point {str(value)!r}; known points: {known}")
            return None
        return str(value)

    def move(self, index: int, spec: object, points: dict[str, Point]) -> Move | None:
        path: KeyPath = ("moves", index)
        expected = "a mapping such as {ptp: a}, {lin: b, speed: 0.05} or {circ: c, via: d}"
        if not isinstance(spec, dict):
            self.error(path, f"expected {expected}, got {_describe(spec)}")
            return None
        kinds = [key for key in MOVE_KINDS if key in spec]
        for key in spec:
            if key not in MOVE_KINDS and key not in _MOVE_OPTIONS:
                self.error(
                    path + (str(key),),
                    f"unknown key {key!r}; a move has one of {', '.join(MOVE_KINDS)} (with the "
                    f"target point) and options {', '.join(_MOVE_OPTIONS)}",
                )
        if len(kinds) != 1:
            found = f"got {', '.join(kinds)}" if kinds else "got none"
            self.error(path, f"expected exactly one of {', '.join(MOVE_KINDS)}; {found}")
            return None
        kind = kinds[0]
        target = self.point_name(spec[kind], path + (kind,), points)
        via = None
        if kind == "circ":
            if "via" not in spec:
                self.error(path, "a circ move needs via: <point> (the arc passes through it)")
            else:
                via = self.point_name(spec["via"], path + ("via",), points)
        elif "via" in spec:
            self.error(path + ("via",), f"via only goes with circ, not {kind}")
        options = self.move_options(kind, spec, path)
        if target is None or options is None or (kind == "circ" and via is None):
            return None
        return Move(index, kind, target, via, **options)

    def move_options(self, kind: str, spec: dict, path: KeyPath) -> dict | None:
        ok = True
        duration = speed = None
        if "duration" in spec:
            duration = self.positive(spec["duration"], path + ("duration",), "duration [s]")
            ok &= duration is not None
        if "speed" in spec:
            what = (
                "share of the joint velocity limits, ≤ 1" if kind == "ptp" else "tool speed [m/s]"
            )
            speed = self.positive(spec["speed"], path + ("speed",), what)
            if speed is not None and kind == "ptp" and speed > 1.0:
                self.error(
                    path + ("speed",),
                    f"for a ptp move, speed is the share of the joint velocity limits, "
                    f"0 < speed ≤ 1; got {speed:g}",
                )
                speed = None
            ok &= speed is not None
        if duration is not None and speed is not None:
            self.error(path, "give duration or speed, not both")
            ok = False
        profile = spec.get("profile", "trapezoid")
        profiles = PTP_PROFILES if kind == "ptp" else PROFILES
        if profile not in profiles:
            self.error(
                path + ("profile",),
                f"unknown profile {_describe(profile)} for a {kind} move; expected one of "
                f"{', '.join(profiles)}",
            )
            ok = False
        name = spec.get("name")
        if name is not None and not isinstance(name, str):
            self.error(path + ("name",), f"expected text, got {_describe(name)}")
            ok = False
        if not ok:
            return None
        return {"duration": duration, "speed": speed, "profile": profile, "name": name}


def resolve_robot_source(source: str, base_dir: Path) -> str:
    """A robot name as is; a file path, relative to the program's folder, made absolute.

    Raises:
        InputError: ``source`` is not a string or ``base_dir`` not a folder path.
    """
    source = checks.text(source, "source (a robot name or URDF path)")
    base_dir = Path(checks.file_path(base_dir, "base_dir (the program's folder)"))
    if source in bundled_robots() or source in known_names():
        return source
    try:
        path = Path(source).expanduser()
    except RuntimeError:  # ~user of an unknown user: load_robot says the file does not exist
        path = Path(source)
    if not path.is_absolute():
        path = base_dir / path
    looks_like_a_path = "/" in source or "\\" in source or path.suffix.lower() in (".urdf", ".xml")
    try:
        is_file = path.is_file()
    except (OSError, ValueError):  # a name too long for the file system, a NUL character
        is_file = False
    return str(path) if looks_like_a_path or is_file else source


_ROBOT_CACHE: dict[tuple[str, str | None], Robot] = {}


def _load_robot(
    source: str,
    tip: str | None,
    locked_joints: Mapping[str, float] | None = None,
    limits: Mapping[str, Mapping[str, float]] | None = None,
    package_dirs: Sequence[Path] | None = None,
    base_pose: pin.SE3 | None = None,
) -> Robot:
    """load_robot, cached for named robots without options (loading parses the URDF)."""
    options = {
        "locked_joints": locked_joints,
        "limits": limits,
        "package_dirs": package_dirs,
        "base_pose": base_pose,
    }
    if source not in known_names() or any(value is not None for value in options.values()):
        return load_robot(source, tip=tip, **options)
    key = (source, tip)
    if key not in _ROBOT_CACHE:
        _ROBOT_CACHE[key] = load_robot(source, tip=tip)
    return _ROBOT_CACHE[key]


# ----------------------------------------------------------------------------------------------
# Planning
# ----------------------------------------------------------------------------------------------


@dataclass
class MoveReport:
    """What one move did.

    Attributes:
        number: 1-based move number.
        kind: ``ptp``, ``lin``, ``circ`` or ``path``.
        label: Short description (``lin to b``).
        key: Key path in the program (``moves[2]``), or None for moves built in Python.
        status: ``ok``, or why the move failed (``unreachable``, ``singular``, ``joint_limit``,
            ``velocity_limit``, ``jump``, ``ik``, ``invalid``).
        t0: Start time in the program [s].
        t1: End time in the program [s] (where it stopped, for a failed move).
        first: Index of the move's first sample in the plan's arrays.
        last: Index of its last sample (the next move's first).
        min_manipulability: Smallest manipulability over its samples.
        peak_speed_ratio: Largest |joint speed| / velocity limit over its samples [-].
        fraction: Share of the move achieved (1.0 when ok) [-].
        message: One-line reason when it failed, else "".
        cartesian_plan: The :class:`cartesian.CartesianPlan` of a Cartesian move.
    """

    number: int
    kind: str
    label: str
    key: str | None
    status: str
    t0: float
    t1: float
    first: int
    last: int
    min_manipulability: float = math.nan
    peak_speed_ratio: float = 0.0
    fraction: float = 1.0
    message: str = ""
    cartesian_plan: cartesian.CartesianPlan | None = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def duration(self) -> float:
        """Duration of the move [s]."""
        return self.t1 - self.t0


class ProgramPlan(Trajectory):
    """A planned program: the whole motion as one timed joint motion, plus reports.

    It is a :class:`~kinplan.trajectory.Trajectory` (quintic Hermite pieces through the samples,
    exact in position, velocity and acceleration at every sample), so ``sample``, ``duration``
    and :func:`kinplan.plot.plot_trajectory` work on it; its :attr:`knots` are the move
    boundaries. The samples themselves are ``t``, ``q``, ``qd``, ``qdd``, as on a
    :class:`cartesian.CartesianPlan`.

    Attributes:
        robot: The robot.
        t: Sample times [s], shape (N,), every move appended in time.
        q: Joint positions [rad], shape (N, nq).
        qd: Joint velocities [rad/s], shape (N, nq).
        qdd: Joint accelerations [rad/s²], shape (N, nq).
        tool_positions: Tool positions by forward kinematics [m], shape (N, 3).
        tool_quaternions: Tool orientations as quaternions (x, y, z, w), shape (N, 4), sign-
            continuous.
        tool_speed: Tool linear speed [m/s], shape (N,).
        manipulability: Manipulability of every sample, shape (N,).
        moves: One :class:`MoveReport` per move planned (the failed one last).
        ok: Whether every move was planned.
        status: ``ok`` or the failed move's status.
        reason: One-line reason of the failure, or "".
        events: The failure as one :class:`cartesian.Event` (``s`` is the share of the failed
            move achieved, ``t`` the program time), or empty when ok.
        points: Taught points: name → tool position [m] (markers for the viewer).
        paths: The Cartesian paths of the lin/circ/path moves, in order.
        program: The program planned, or None for a motion built in Python.
        dt: Sampling period [s].
    """

    def __init__(
        self,
        robot: Robot,
        t: np.ndarray,
        q: np.ndarray,
        qd: np.ndarray,
        qdd: np.ndarray,
        moves: list[MoveReport],
        reason: str = "",
        points: dict[str, np.ndarray] | None = None,
        paths: list[cartesian.Path] | None = None,
        program: Program | None = None,
        dt: float = DEFAULT_DT,
    ):
        self.robot = robot
        self.t, self.q, self.qd, self.qdd = t, q, qd, qdd
        self.moves = moves
        self.reason = reason
        self.ok = not reason
        failed = [m for m in moves if not m.ok]
        self.status = failed[0].status if failed else ("ok" if self.ok else "failed")
        self.points = dict(points or {})
        self.paths = list(paths or [])
        self.program = program
        self.dt = dt
        boundaries = sorted({0} | {m.first for m in moves} | {m.last for m in moves})
        super().__init__(
            hermite_segments(t, q, qd, qdd),
            waypoints=Waypoints(t[boundaries], q[boundaries]),
            end=q[-1],
            end_velocity=qd[-1],
            end_acceleration=qdd[-1],
        )
        self._tool_states(robot)
        self.events = self._failure_events(failed[0] if failed else None)

    def __repr__(self) -> str:
        state = "ok" if self.ok else f"failed: {self.reason}"
        return (
            f"ProgramPlan({self.robot.name}, {len(self.moves)} moves, {self.duration:.3f} s, "
            f"{len(self.t)} samples, {state})"
        )

    @property
    def knots(self) -> np.ndarray:
        """Move boundaries [s] (not the sample pieces), so plots mark the moves."""
        return np.unique(
            np.concatenate(
                [[0.0, self.duration], [m.t0 for m in self.moves], [m.t1 for m in self.moves]]
            )
        )

    # -- kinplan.motion.SampledMotion: what viewers, plots and exports read --------------------
    @property
    def kind(self) -> MotionKind:
        """Always "program": an event's ``s`` is the share of the failed move achieved."""
        return "program"

    @property
    def description(self) -> str:
        """The number of moves, for captions."""
        return f"{len(self.moves)} moves"

    @property
    def planned_paths(self) -> list[PlannedPath]:
        """The paths of the Cartesian moves, in order, each reached as far as its move got."""
        plans = [m.cartesian_plan for m in self.moves if m.cartesian_plan is not None]
        return [piece for plan in plans for piece in plan.planned_paths]

    def _tool_states(self, robot: Robot) -> None:
        n = len(self.t)
        poses, jacobians = np.empty((n, 4, 4)), np.empty((n, 6, robot.nq))
        for k in range(n):
            pose, jacobians[k] = robot.pose_and_jacobian(self.q[k])
            poses[k] = pose.homogeneous
        self.tool_positions, self.tool_quaternions = pose_to_track(poses)
        self.tool_speed = np.linalg.norm(np.einsum("nij,nj->ni", jacobians[:, :3], self.qd), axis=1)
        position_only = robot.default_position_only()
        rows, rank = robot.task_rows(position_only), robot.task_rank(position_only)
        self.manipulability = manipulability_of(jacobians[:, rows], rank)
        for move in self.moves:
            window = slice(move.first, move.last + 1)
            if math.isnan(move.min_manipulability):
                move.min_manipulability = float(self.manipulability[window].min())

    def _failure_events(self, move: MoveReport | None) -> list[cartesian.Event]:
        """The failure as a :class:`cartesian.Event` in program time (for viewers and plots)."""
        if move is None:
            return []
        return [
            cartesian.Event(
                kind=move.status,
                t=move.t1,
                s=move.fraction,
                index=move.last,
                message=self.reason,
                position=self.tool_positions[move.last].copy(),
            )
        ]

    def summary_rows(self) -> list[dict[str, object]]:
        """One dict per move: number, move, key, duration [s], min manipulability, peak joint
        speed / limit, status."""
        return [
            {
                "number": m.number,
                "move": m.label,
                "key": m.key or "",
                "duration": m.duration,
                "min_manipulability": m.min_manipulability,
                "peak_speed_ratio": m.peak_speed_ratio,
                "status": m.status,
            }
            for m in self.moves
        ]


def hermite_segments(
    t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> list[Segment]:
    """Quintic Hermite pieces through samples: exact position, velocity and acceleration at
    every sample time ``t`` [s] (the samples' units: rad, rad/s, rad/s²)."""
    if len(t) == 1:
        return [Segment(0.0, 0.0, q[:1].T.copy())]
    ends = [x.T for x in (q[:-1], q[1:], qd[:-1], qd[1:], qdd[:-1], qdd[1:])]  # (n, pieces)
    coefficients = quintic_coefficients(*ends, np.diff(t))  # (n, 6, pieces)
    coefficients = np.moveaxis(coefficients, 2, 0)  # (pieces, n, 6)
    return [Segment(float(t[k]), float(t[k + 1]), coefficients[k]) for k in range(len(t) - 1)]


def _where(position: np.ndarray) -> str:
    text = ", ".join(f"{x:.3f}" for x in position).replace("-0.000", "0.000")
    return f"({text}) m"


def _program_remedy(plan: cartesian.CartesianPlan) -> str:
    """What the author of a program can do about a failed move's first event (the event's own
    remedy names :func:`cartesian.follow`'s arguments)."""
    event = plan.events[0]
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
    return event.remedy


def _start_turn(path: cartesian.Path, pose: pin.SE3, position_only: bool) -> float:
    """Angle between a path's start orientation and the tool's [rad] (0 if not oriented)."""
    if position_only or not path.has_orientation:
        return 0.0
    return float(np.linalg.norm(pin.log3(pose.rotation.T @ path.start.rotation)))


def _peak_speed_ratio(robot: Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> float:
    """Largest joint speed over its limit: the rates at the samples and the mean speeds
    between them (:func:`kinplan.sampling.joint_speeds`)."""
    if qd.size == 0:
        return 0.0
    limit = robot.velocity_limit
    finite = np.isfinite(limit)
    if not finite.any():
        return 0.0
    speeds = joint_speeds(q, qd, t)
    return float(np.max(speeds[:, finite] / limit[finite]))


class MotionBuilder:
    """Chains moves from the end state of the previous one into one sampled joint motion.

    Every method plans one move from the current configuration :attr:`q`. A move that cannot be
    done raises :class:`MoveError` (one-line message naming the move and where it failed) after
    recording the failure; :meth:`finish` then returns the motion up to the failure with
    ``ok = False``.

    Args:
        robot: The arm.
        q_start: Start configuration [rad], shape (nq,).
        dt: Sampling period [s].

    Example:
        >>> builder = MotionBuilder(robot, q_home)
        >>> builder.ptp(approach_pose)
        >>> builder.lin(seam_start, speed=0.05)
        >>> builder.follow(seam, speed=0.03, label="weld seam")
        >>> plan = builder.finish()
    """

    def __init__(self, robot: Robot, q_start: np.ndarray, dt: float = DEFAULT_DT):
        if not (math.isfinite(dt) and dt > 0):
            raise KinplanError(f"dt must be a finite number of seconds > 0, got {dt!r}")
        self.robot = robot
        self.dt = float(dt)
        self.q = robot.check_q(q_start, "q_start").copy()
        self.reports: list[MoveReport] = []
        self.paths: list[cartesian.Path] = []
        self.reason = ""
        self._t = [np.zeros(1)]
        self._q = [self.q[None, :].copy()]
        self._qd = [np.zeros((1, robot.nq))]
        self._qdd = [np.zeros((1, robot.nq))]
        self._time = 0.0
        self._count = 1

    # -- state ---------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """End time of the motion so far [s]."""
        return self._time

    def tool_pose(self) -> pin.SE3:
        """Current tool pose in the base frame."""
        return self.robot.fk(self.q)

    # -- moves ---------------------------------------------------------------------------------
    def ptp(
        self,
        goal: np.ndarray | Sequence[float] | pin.SE3,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "ptp",
        key: str | None = None,
    ) -> MoveReport:
        """Joint-interpolated move to a Cartesian goal, solved by IK seeded from the current
        configuration (so the arm stays on its branch).

        Args:
            goal: Tool pose (SE3) or tool position [m] (shape (3,): keeps the current
                orientation when nq ≥ 6, position-only otherwise).
            duration, speed, profile, label, key: As in :meth:`ptp_joints`.
        """
        self._check_open()
        position, rotation = self._target(goal)
        target = position if rotation is None else pin.SE3(rotation, position)
        result = self.robot.ik(target, q_seed=self.q, position_only=rotation is None)
        if not result.success:
            why = (
                f"ik: no inverse kinematics solution for {_where(position)} within the joint "
                f"limits (the closest found is {result.position_error:.4f} m, "
                f"{result.rotation_error:.3f} rad away); move the point"
            )
            self._record("ptp", label, key, status="ik", why=why)
        return self.ptp_joints(
            result.q, duration=duration, speed=speed, profile=profile, label=label, key=key
        )

    def ptp_joints(
        self,
        q_goal: np.ndarray | Sequence[float],
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "ptp",
        key: str | None = None,
    ) -> MoveReport:
        """Joint-interpolated move to joint values.

        Args:
            q_goal: Joint values [rad], shape (nq,).
            duration: Duration [s]; default the minimum time within the scaled limits. A given
                duration must keep every joint within its velocity limit.
            speed: Share of the joint velocity limits (0, 1]; default :data:`DEFAULT_PTP_SPEED`.
            profile: ``trapezoid``, ``quintic``, ``cubic``, ``scurve`` or ``time_optimal``.
            label: Description for reports.
            key: Key path in a program, for messages.
        """
        self._check_open()
        q_goal = self.robot.check_q(q_goal, "ptp goal")
        try:
            traj = self._joint_trajectory(q_goal, duration, speed, profile)
        except InfeasibleError as exc:  # a duration the limits cannot meet: states the minimum
            self._record("ptp", label, key, status="invalid", why=f"invalid: {exc}")
        t = traj.time_grid(motion_step(traj.duration, self.dt))
        q, qd, qdd = traj.sample(t)
        ratio = _peak_speed_ratio(self.robot, t, q, qd)
        if ratio > 1.0 + 1e-6:
            speeds = np.max(joint_speeds(q, qd, t), axis=0)
            j = int(np.argmax(speeds / self.robot.velocity_limit))
            why = (
                f"velocity_limit: joint {j} ({self.robot.joint_names[j]}) would need "
                f"{speeds[j]:.4g} rad/s, above its limit "
                f"{self.robot.velocity_limit[j]:.3f} rad/s; give a duration of at least "
                f"{traj.duration * ratio:.3f} s, or no duration (minimum time)"
            )
            self._record("ptp", label, key, status="velocity_limit", why=why, ratio=ratio)
        return self._record("ptp", label, key, (t, q, qd, qdd), ratio=ratio)

    def lin(
        self,
        goal: np.ndarray | Sequence[float] | pin.SE3,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "lin",
        key: str | None = None,
    ) -> MoveReport:
        """Straight tool line from the current pose to ``goal`` (SE3 or position [m]).

        A position keeps the current orientation (arms with ≥ 6 joints) or is position-only.
        ``speed`` is the tool cruise speed [m/s] (default :data:`DEFAULT_TOOL_SPEED`).
        """
        self._check_open()
        start, (end,) = self._cartesian_points([goal])
        path = self._build_path("lin", label, key, lambda: cartesian.Line(start, end))
        return self.follow(
            path, duration=duration, speed=speed, profile=profile, label=label, key=key,
            kind="lin",
        )  # fmt: skip

    def circ(
        self,
        goal: np.ndarray | Sequence[float] | pin.SE3,
        via: np.ndarray | Sequence[float] | pin.SE3,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "circ",
        key: str | None = None,
    ) -> MoveReport:
        """Arc of the circle through the current tool position, ``via`` and ``goal``.

        The tool orientation moves by slerp from the current one to the goal's (the via point's
        orientation is not used). Options as in :meth:`lin`.
        """
        self._check_open()
        start, (end, middle) = self._cartesian_points([goal, via])
        path = self._build_path("circ", label, key, lambda: cartesian.Arc(start, middle, end))
        return self.follow(
            path, duration=duration, speed=speed, profile=profile, label=label, key=key,
            kind="circ",
        )  # fmt: skip

    def follow(
        self,
        path: cartesian.Path,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "path",
        key: str | None = None,
        kind: str = "path",
    ) -> MoveReport:
        """Follow a Cartesian path that starts at the current tool pose (within 0.1 mm, 1 mrad).

        Args:
            path: Any :class:`cartesian.Path` (e.g. a :class:`cartesian.PathSequence` of lines
                and arcs: one move at constant tool speed).
            duration: Duration [s]; or
            speed: Tool cruise speed [m/s] (default :data:`DEFAULT_TOOL_SPEED`).
            profile: 1-D time law: ``trapezoid``, ``quintic`` or ``cubic``.
            label: Description for reports.
            key: Key path in a program, for messages.
            kind: Kind shown in reports.
        """
        self._check_open()
        here = self.tool_pose().translation
        gap = float(np.linalg.norm(path.start.translation - here))
        if gap > 1e-4:
            why = (
                f"invalid: the path starts at {_where(path.start.translation)}, {gap:.4f} m away "
                f"from the tool at {_where(here)}; move there first (ptp or lin)"
            )
            self._record(kind, label, key, status="invalid", why=why)
        turn = _start_turn(path, self.tool_pose(), self.robot.default_position_only())
        if turn > 1e-3:
            why = (
                f"invalid: the path starts with a tool orientation {turn:.3f} rad away from the "
                "current one; reorient first (ptp or lin to the path's start pose)"
            )
            self._record(kind, label, key, status="invalid", why=why)
        if duration is None and speed is None:
            if path.length > 0:
                speed = DEFAULT_TOOL_SPEED
            else:
                duration = 1.0
        try:
            plan = cartesian.follow(
                self.robot, path, duration=duration, speed=speed, profile=profile, dt=self.dt,
                q_seed=self.q,
            )  # fmt: skip
        except KinplanError as exc:
            self._record(kind, label, key, status="invalid", why=f"invalid: {exc}")
        self.paths.append(path)
        ratio = plan.peak_speed_ratio
        samples = (plan.t, plan.q, plan.qd, plan.qdd) if len(plan.t) else None
        if samples and np.max(np.abs(plan.q[0] - self.q)) > JOIN_TOLERANCE:
            why = (
                "jump: the path's first configuration is on another branch than the current "
                "one; move to the path start with a lin move first"
            )
            self._record(kind, label, key, status="jump", why=why, ratio=ratio, plan=plan)
        if not plan.ok:
            event = plan.events[0]
            why = f"{event.kind} at s = {event.s:.2f}: {event.message}; {_program_remedy(plan)}"
            self._record(
                kind, label, key, samples, status=plan.status, why=why, ratio=ratio,
                fraction=plan.fraction, plan=plan,
            )  # fmt: skip
        return self._record(kind, label, key, samples, ratio=ratio, plan=plan)

    def finish(
        self, points: dict[str, np.ndarray] | None = None, program: Program | None = None
    ) -> ProgramPlan:
        """The whole motion so far as a :class:`ProgramPlan` (``ok = False`` after a failure).

        Args:
            points: Named tool positions to mark [m].
            program: The program planned, if any.
        """
        return ProgramPlan(
            self.robot,
            np.concatenate(self._t),
            np.vstack(self._q),
            np.vstack(self._qd),
            np.vstack(self._qdd),
            list(self.reports),
            reason=self.reason,
            points=points,
            paths=self.paths,
            program=program,
            dt=self.dt,
        )

    # -- helpers -------------------------------------------------------------------------------
    def _check_open(self) -> None:
        if self.reason:
            raise KinplanError(f"planning stopped at the failed move: {self.reason}")

    def _target(self, goal) -> tuple[np.ndarray, np.ndarray | None]:
        """(position, rotation or None) of a Cartesian goal, applying the orientation rule."""
        if isinstance(goal, pin.SE3):
            position, rotation = np.array(goal.translation), np.array(goal.rotation)
        else:
            position = np.asarray(goal, dtype=float)
            if position.shape != (3,) or not np.all(np.isfinite(position)):
                raise KinplanError(
                    f"a Cartesian goal is a pin.SE3 or a finite position 3-vector [m], got "
                    f"{_describe(goal)}; use ptp_joints for joint values"
                )
            rotation = None
        if self.robot.default_position_only():
            return position, None
        if rotation is None:
            rotation = self.tool_pose().rotation.copy()
        return position, rotation

    def _cartesian_points(self, goals: list) -> tuple[object, list]:
        """The path start (current tool pose) and the goals, as SE3 or as positions (arms with
        fewer than 6 joints)."""
        start = self.tool_pose()
        targets = [self._target(goal) for goal in goals]
        if self.robot.default_position_only():
            return start.translation.copy(), [position for position, _ in targets]
        return start, [pin.SE3(rotation, position) for position, rotation in targets]

    def _build_path(self, kind: str, label: str, key: str | None, build: Callable):
        try:
            return build()
        except KinplanError as exc:
            self._record(kind, label, key, status="invalid", why=f"invalid: {exc}")

    def _joint_trajectory(
        self, q_goal: np.ndarray, duration: float | None, speed: float | None, profile: str
    ) -> Trajectory:
        if profile not in PTP_PROFILES:
            raise KinplanError(
                f"unknown profile {profile!r}; choose one of {', '.join(PTP_PROFILES)}"
            )
        if speed is not None and not (0 < speed <= 1):
            raise KinplanError(f"ptp speed is a share of the joint limits in (0, 1], got {speed}")
        limit = self.robot.velocity_limit
        limit = np.where(np.isfinite(limit), limit, FALLBACK_JOINT_SPEED)
        max_velocity = limit * (DEFAULT_PTP_SPEED if speed is None else float(speed))
        max_acceleration = max_velocity / PTP_RAMP_TIME
        q0 = self.q
        if profile in ("scurve", "time_optimal"):
            # The robot's limits (all of them when a duration is given), the trapezoid's ramp
            # where it has no acceleration limit, jerk from the acceleration ramp time.
            share = DEFAULT_PTP_SPEED if speed is None else float(speed)
            share = 1.0 if duration is not None else share
            velocity = limit * share
            known = self.robot.acceleration_limit
            acceleration = np.where(np.isfinite(known), known * share, velocity / PTP_RAMP_TIME)
            if profile == "scurve":
                return trajectory.scurve(
                    q0, q_goal, velocity, acceleration, acceleration / PTP_JERK_TIME, duration
                )
            return trajectory.time_optimal([q0, q_goal], velocity, acceleration, 0.0, duration)
        if profile == "trapezoid":
            if duration is None:
                return trajectory.trapezoid(
                    q0, q_goal, max_velocity=max_velocity, max_acceleration=max_acceleration
                )
            return trajectory.trapezoid(q0, q_goal, duration=duration)
        if duration is None:
            distance = np.abs(q_goal - q0)
            duration = _polynomial_duration(distance, max_velocity, max_acceleration, profile)
        if duration == 0.0:  # nothing moves
            return trajectory.trapezoid(q0, q_goal, max_velocity=1.0, max_acceleration=1.0)
        build = trajectory.quintic if profile == "quintic" else trajectory.cubic
        return build(q0, q_goal, duration)

    def _record(
        self,
        kind: str,
        label: str,
        key: str | None,
        samples: tuple[np.ndarray, ...] | None = None,
        *,
        status: str = "ok",
        why: str = "",
        ratio: float = 0.0,
        fraction: float | None = None,
        plan: cartesian.CartesianPlan | None = None,
    ) -> MoveReport:
        """Append a move's samples (local times from 0) and its report.

        A status other than ``ok`` records the failure (the samples are the part achieved) and
        raises :class:`MoveError`.
        """
        number = len(self.reports) + 1
        first, t0 = self._count - 1, self._time
        if samples is not None:
            t, q, qd, qdd = samples
            self._t.append(np.asarray(t[1:], dtype=float) + self._time)
            self._q.append(q[1:])
            self._qd.append(qd[1:])
            self._qdd.append(qdd[1:])
            self._count += len(t) - 1
            self._time += float(t[-1])
            self.q = np.array(q[-1])
        message = ""
        if status != "ok":
            where = f"{label}, {key}" if key else label
            message = f"move {number} ({where}): {why}"
        report = MoveReport(
            number=number,
            kind=kind,
            label=label,
            key=key,
            status=status,
            t0=t0,
            t1=self._time,
            first=first,
            last=self._count - 1,
            peak_speed_ratio=ratio,
            fraction=(1.0 if status == "ok" else 0.0) if fraction is None else fraction,
            message=message,
            cartesian_plan=plan,
        )
        self.reports.append(report)
        if status != "ok":
            self.reason = message
            logger.info("planning stopped: %s", message)
            raise MoveError(message, report)
        return report


def _polynomial_duration(
    distance: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray, profile: str
) -> float:
    """Shortest duration [s] of a rest-to-rest cubic/quintic within the speed and acceleration
    limits: peak speed k_v Δ/T, peak acceleration k_a Δ/T²."""
    k_v, k_a = REST_TO_REST_PEAKS[profile]
    times = np.maximum(k_v * distance / max_velocity, np.sqrt(k_a * distance / max_acceleration))
    return float(times.max(initial=0.0))


def plan_program(
    program: Program,
    dt: float = DEFAULT_DT,
    progress: Callable[[int, int, str], None] | None = None,
) -> ProgramPlan:
    """Plan every move of a program, each from the end state of the previous one.

    Args:
        program: A validated program (:func:`load_program`).
        dt: Sampling period [s].
        progress: Called as ``progress(done, total, label)`` before each move and at the end.

    Returns:
        The plan; ``ok`` is False when a move could not be done: ``reason`` says which move
        (number, label, key path) failed and where, and the plan holds the motion up to there.
    """
    robot = program.robot
    builder = MotionBuilder(robot, program.start, dt=dt)
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
    options = {
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
        via = program.points[move.via]
        builder.circ(target.goal(robot), via.goal(robot), **options)


def run_program(path: str | os.PathLike[str], dt: float = DEFAULT_DT) -> ProgramPlan:
    """:func:`load_program` then :func:`plan_program`."""
    return plan_program(load_program(path), dt=dt)
