"""What a motion program contains: its keys, defaults, the validated dataclasses, the YAML loader.

:class:`Program` holds a validated program: the robot, the start configuration, the taught
:class:`Point` s and the :class:`Move` s. The constants are the defaults of the moves and the
keys a program file may use; :class:`ProgramLoader` reads YAML with YAML 1.2 floats.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
import yaml

from kinplan import defaults
from kinplan.cell import WorkCell
from kinplan.model.robot import Robot

__all__ = [
    "AVOID_TIME_LIMIT",
    "DEFAULT_DT",
    "DEFAULT_PTP_SPEED",
    "DEFAULT_TOOL_SPEED",
    "FALLBACK_JOINT_SPEED",
    "JOIN_TOLERANCE",
    "MAX_ACCELERATION",
    "MAX_COORDINATE",
    "MAX_INTEGER_DIGITS",
    "MAX_SAMPLES",
    "MAX_SECONDS",
    "MOVE_KINDS",
    "MOVE_OPTIONS",
    "NAME_PATTERN",
    "POINT_KEYS",
    "POSE_KEYS",
    "PTP_JERK_TIME",
    "PTP_RAMP_TIME",
    "THROUGH_PROFILES",
    "TOP_KEYS",
    "TORCH_KEYS",
    "WEAVE_KEYS",
    "IoEvent",
    "JobOutput",
    "KeyPath",
    "Move",
    "Payload",
    "Point",
    "Program",
    "ProgramLoader",
    "TorchSpec",
    "WeaveSpec",
]

MOVE_KINDS = ("ptp", "lin", "circ")
"""The kinds of move a program may use."""
DEFAULT_DT = defaults.DEFAULT_DT
"""Sampling period of planned programs [s] (:data:`kinplan.defaults.DEFAULT_DT`)."""
DEFAULT_PTP_SPEED = 0.5
"""Cruise speed of a ``ptp`` move without ``speed``/``duration``, share of the joint limits [-]."""
PTP_RAMP_TIME = 0.5
"""Time a ``ptp`` joint takes to reach its cruise speed (sets the joint acceleration) [s]."""
PTP_JERK_TIME = 0.1
"""Time an ``scurve`` ``ptp`` joint takes to build up its acceleration (sets the jerk) [s]."""
FALLBACK_JOINT_SPEED = 1.0
"""Velocity limit assumed for joints whose URDF gives none [rad/s]."""
AVOID_TIME_LIMIT = 2.0
"""Longest search for a ptp with ``avoid: true`` [s] (:func:`kinplan.free_motion`)."""
DEFAULT_TOOL_SPEED = 0.05
"""Tool cruise speed of ``lin``/``circ`` moves without ``speed``/``duration`` [m/s]."""
JOIN_TOLERANCE = 1e-6
"""Largest joint gap accepted where a Cartesian move starts from the previous end [rad]."""
MAX_COORDINATE = 1e6
"""Largest |x|, |y|, |z| of a taught tool position [m]: anything beyond is a typo in a program
(and out of reach of any arm)."""
MAX_SECONDS = 1e5
"""Largest ``duration``, ``dwell`` or ``times`` entry of a program [s] (about 28 hours): beyond
is a unit mistake."""
MAX_SAMPLES = 1_000_000
"""Most samples a planned program may have (a move or dwell that would take it further is
refused, naming the dt): 10,000 s at the default dt."""
MAX_ACCELERATION = 1e6
"""Largest ``max_acceleration:`` accepted [rad/s² or m/s²]: beyond is a unit mistake."""

TOP_KEYS = (
    "robot",
    "tip",
    "locked_joints",
    "limits",
    "package_dirs",
    "base_pose",
    "tool",
    "obstacles",
    "clearance",
    "avoid",
    "max_acceleration",
    "start",
    "points",
    "moves",
    "description",
    "arc_output",
    "job_output",
)
"""The keys a program may have at its top level."""
POSE_KEYS = ("xyz", "rpy_deg", "quat_xyzw")
"""The keys of a Cartesian pose (``base_pose:``)."""
POINT_KEYS = ("joints", "joints_deg", "xyz", "rpy_deg", "quat_xyzw", "arc", "io", "weld")
"""The keys of a taught point (``arc``, ``io`` and ``weld``: signals set when a move arrives
there, :mod:`kinplan.program.process`)."""
MOVE_OPTIONS = (
    "via", "duration", "speed", "profile", "blend", "times", "weave", "torch", "dwell", "name",
    "max_acceleration", "arc", "io", "weld", "avoid",
)  # fmt: skip
"""The keys of a move besides its kind."""
WEAVE_KEYS = ("pattern", "amplitude", "frequency", "dwell", "normal")
"""The keys of a move's ``weave:`` (``amplitude`` and ``frequency`` required)."""
TORCH_KEYS = (
    "normal", "work_angle_deg", "travel_angle_deg", "roll_deg", "work_tolerance_deg",
    "travel_tolerance_deg",
)  # fmt: skip
"""The keys of a move's ``torch:`` (all optional; without ``roll_deg`` the roll is free and
searched by :func:`cartesian.plan_seam`)."""
THROUGH_PROFILES = ("time_optimal", "spline")
"""The time laws of a ``ptp`` through several points (the first is the default)."""
NAME_PATTERN = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\-]*$")
"""What a point name looks like."""

KeyPath = tuple[str | int, ...]
"""A key path in a program file, e.g. ``("moves", 2, "lin")``."""


@dataclass
class Point:
    """A taught point: joint values, or a tool position with an optional orientation.

    Attributes:
        name: Point name.
        joints: Joint values [rad], shape (nq,), or None for a Cartesian point.
        position: Tool position [m], shape (3,), or None for a joint point.
        rotation: Tool rotation (3×3) or None (keep the move's start orientation / position only).
        key: Key path in the program (``points.a``).
        arc: ``arc: on`` (True) or ``off`` (False) at the point: the arc output switched when a
            move arrives there (the end of its motion, before its dwell), or None.
        io: The point's ``io:`` as (output, value) pairs, set when a move arrives there.
        job: The weld job of the point's ``weld: {job: N}`` (which also switches the arc on
            there), or None.
    """

    name: str
    joints: np.ndarray | None = None
    position: np.ndarray | None = None
    rotation: np.ndarray | None = None
    key: str = ""
    arc: bool | None = None
    io: tuple[tuple[int, bool], ...] = ()
    job: int | None = None

    def tool_position(self, robot: Robot) -> np.ndarray:
        """Tool position of the point [m] (by forward kinematics for a joint point).

        Args:
            robot: The arm the point is taught for.

        Returns:
            The position [m], shape (3,).
        """
        if self.joints is not None:
            return np.array(robot.fk(self.joints).translation)
        return np.array(self.position)

    def goal(self, robot: Robot) -> np.ndarray | pin.SE3:
        """The point as a Cartesian goal.

        Args:
            robot: The arm the point is taught for.

        Returns:
            A pose in the base frame, or a position [m] when no orientation is given (a joint
            point's pose by forward kinematics).
        """
        if self.joints is not None:
            return robot.fk(self.joints)
        assert self.position is not None  # not a joint point: a Cartesian one
        if self.rotation is None:
            return self.position.copy()
        return pin.SE3(self.rotation, self.position)


@dataclass(frozen=True)
class WeaveSpec:
    """A move's ``weave:``: the torch oscillates across the seam (:class:`cartesian.Weave`).

    Attributes:
        pattern: ``sine``, ``triangle`` or ``trapezoid``.
        amplitude: Largest lateral offset [m].
        frequency: Oscillations per second at the travel speed [Hz].
        dwell: Time held at each side [s].
        normal: Axis the oscillation is perpendicular to (world frame), or None: the tool axis.
    """

    pattern: str
    amplitude: float
    frequency: float
    dwell: float = 0.0
    normal: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class TorchSpec:
    """A move's ``torch:``: the tool held at welding angles to the seam
    (:class:`cartesian.TorchOrientation`).

    Attributes:
        normal: Surface normal (world frame).
        work_angle: Tilt across the seam [rad].
        travel_angle: Tilt along the seam [rad], positive = push.
        roll: Turn about the torch axis [rad], or None: free, searched along the seam by
            :func:`cartesian.plan_seam` (``torch:`` without ``roll_deg``).
        work_tolerance: Band [rad] in [0, π/2) within which the torch axis may tilt across the
            seam (``work_tolerance_deg``).
        travel_tolerance: Band [rad] in [0, π/2) within which it may tilt along the seam
            (``travel_tolerance_deg``).
    """

    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    work_angle: float = 0.0
    travel_angle: float = 0.0
    roll: float | None = 0.0
    work_tolerance: float = 0.0
    travel_tolerance: float = 0.0

    @property
    def searched(self) -> bool:
        """Whether the seam is planned by :func:`cartesian.plan_seam` (roll free or tolerance
        bands) rather than followed as taught by :func:`cartesian.follow`."""
        return self.roll is None or self.work_tolerance > 0 or self.travel_tolerance > 0


@dataclass(frozen=True)
class Payload:
    """The ``tool:``'s ``payload:``: what the controller must know the flange carries.

    Attributes:
        mass: Mass of the tool and what it holds [kg], ≥ 0.
        cog: Centre of gravity in the flange frame (the robot's tip before the tool) [m].
    """

    mass: float
    cog: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class JobOutput:
    """Where ``weld: {job: N}`` writes the weld job number (the top-level ``job_output:``).

    Attributes:
        register: The integer output register (0 to 47) the job is written to
            (URScript ``write_output_integer_register``), or None when ``outputs`` are used.
        outputs: The standard digital outputs the job is written to in binary, the least
            significant bit first (``job_output: {outputs: [4, 5, 6, 7]}``); empty for a
            register.
    """

    register: int | None = 0
    outputs: tuple[int, ...] = ()


@dataclass(frozen=True)
class IoEvent:
    """An output set at an instant of a planned program (``arc:``, ``io:`` or ``weld:`` of a
    move or of the point a move arrives at).

    Attributes:
        t: Program time at which it takes effect [s]: the start of the move that carries it
            (after the previous move's dwell), or the end of the motion of a move to the point
            that carries it (before that move's dwell).
        output: Digital output number (0 to 7, the controller's standard outputs), or the
            integer output register's number when ``register`` is true.
        value: The level set (True = on / 1), or the integer written to a register.
        kind: ``"arc"`` (``arc:``, or the arc switched on by ``weld:``), ``"io"`` (``io:``) or
            ``"job"`` (the job number of ``weld: {job: N}``, set just before its arc).
        move: 1-based number of the move in the program's ``moves:`` list (for a point's
            signal, the move that arrives at the point).
        key: Key path of the signal in the program (``moves[2].arc``, ``points.b.io``).
        job: The weld job number of a ``"job"`` event (one event per bit with
            ``job_output: {outputs: [...]}``), else None.
        register: Whether ``output`` is an integer output register (``value`` the job number).
    """

    t: float
    output: int
    value: bool | int
    kind: str
    move: int
    key: str
    job: int | None = None
    register: bool = False


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
        profile: ``trapezoid``, ``quintic`` or ``cubic``; for ``ptp`` also ``scurve`` or
            ``time_optimal``; a ``ptp`` through several points ``time_optimal`` or ``spline``.
        name: Optional label given in the file.
        through: A ``ptp`` through several points: the points before ``target``, in order.
        blend: ``lin``/``circ``: radius [m] of the blend into the next move (no stop at the
            corner); ``ptp`` through several points: largest deviation from a corner [rad].
        weave: The ``weave:`` of a ``lin``/``circ``, or None.
        torch: The ``torch:`` angles of a ``lin``/``circ``, or None.
        dwell: Time the arm stands still after the move [s] (arc-off / crater fill; on the
            approach move of a seam, the arc-on dwell).
        times: A ``spline`` ``ptp`` through several points: the time at which it passes each
            point, from the move's start [s] (strictly increasing), or None (chord-length knot
            times, the fastest timing within the limits).
        max_acceleration: The move's joint acceleration limits [rad/s² or m/s²]: one number
            for every joint or one per joint, or None (the program's ``max_acceleration:``).
        arc: ``arc: on`` (True) or ``off`` (False): the arc output switched when the move
            starts, or None (``weld: {job: N}`` gives True).
        io: The move's ``io:`` as (output, value) pairs, set when the move starts.
        job: The weld job number of the move's ``weld: {job: N}`` (0 to 255), written to
            the program's ``job_output:`` when the move starts, just before the arc goes on.
        avoid: A ``ptp`` to one point: ``avoid: true`` plans it around the cell's obstacles
            (:func:`kinplan.free_motion`), ``false`` never; None: the program's ``avoid:``.
    """

    index: int
    kind: str
    target: str
    via: str | None = None
    duration: float | None = None
    speed: float | None = None
    profile: str = "trapezoid"
    name: str | None = None
    through: tuple[str, ...] = ()
    blend: float | None = None
    weave: WeaveSpec | None = None
    torch: TorchSpec | None = None
    dwell: float = 0.0
    times: tuple[float, ...] | None = None
    max_acceleration: float | tuple[float, ...] | None = None
    arc: bool | None = None
    io: tuple[tuple[int, bool], ...] = ()
    avoid: bool | None = None
    job: int | None = None

    @property
    def key(self) -> str:
        """Key path in the program, e.g. ``moves[2]``."""
        return f"moves[{self.index}]"

    @property
    def label(self) -> str:
        """Short description, e.g. ``lin to b`` or ``circ to a via c``."""
        text = f"{self.kind} to {self.target}"
        if len(self.through) > 3:
            text = f"{self.kind} through {len(self.through)} points to {self.target}"
        elif self.through:
            text = f"{self.kind} through {', '.join(self.through)} to {self.target}"
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
        cell: The work cell every move is checked against (the ``obstacles:`` and the robot's
            own collision geometry, its ``tool:`` body included), or None.
        clearance: The ``clearance:`` margin [m] (0: only contact fails).
        max_acceleration: The program's joint acceleration limits [rad/s² or m/s²], shape
            (nq,), on top of the robot's own, or None (the robot's alone).
        payload: The ``tool:``'s ``payload:``, or None.
        obstacle_colors: ``color:`` of each obstacle that gives one, ``"#rrggbb"``.
        arc_output: The digital output ``arc: on|off`` switches (``arc_output:``, default 0).
        job_output: Where ``weld: {job: N}`` writes the job number (``job_output:``; default
            the integer output register 0).
        avoid: ``avoid: true`` at the top level: every ``ptp`` to one point that does not say
            ``avoid: false`` is planned around the obstacles.
    """

    source: str
    robot: Robot
    robot_source: str
    start: np.ndarray
    points: dict[str, Point]
    moves: list[Move]
    description: str = ""
    warnings: list[str] = field(default_factory=list)
    cell: WorkCell | None = None
    clearance: float = 0.0
    max_acceleration: np.ndarray | None = None
    payload: Payload | None = None
    obstacle_colors: dict[str, str] = field(default_factory=dict)
    arc_output: int = 0
    avoid: bool = False
    job_output: JobOutput = field(default_factory=JobOutput)


class ProgramLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 floats.

    YAML 1.1 (PyYAML's default) only reads a float with a dot and a signed exponent, so
    ``speed: 1e9`` or ``1.0e9`` would be a string; YAML 1.2's core schema reads ``1e9``,
    ``1.0e9``, ``.5`` and ``-2E-3`` as floats, as programs mean them.
    """


ProgramLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"^[-+]?(?:(?:[0-9][0-9_]*)?\.[0-9_]+(?:[eE][-+]?[0-9]+)?"  # .5, 1.5, 1.5e9
        r"|[0-9][0-9_]*\.(?:[eE][-+]?[0-9]+)?"  # 1., 1.e9
        r"|[0-9][0-9_]*[eE][-+]?[0-9]+)$"  # 1e9, 2E-3
    ),
    list("-+0123456789."),
)

MAX_INTEGER_DIGITS = 400
"""Most digits of an integer in a program file: a longer one (far beyond any float) is refused
as it is read, with its line (Python refuses to convert integers of more than 4,300 digits)."""


def _construct_int(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> object:
    """PyYAML's integer, refusing integers of more than :data:`MAX_INTEGER_DIGITS` digits."""
    text = str(loader.construct_scalar(node))
    digits = sum(c.isalnum() for c in text)
    if digits > MAX_INTEGER_DIGITS:
        raise yaml.constructor.ConstructorError(
            None,
            None,
            f"an integer of {digits} digits; a number in a program has at most "
            f"{MAX_INTEGER_DIGITS} digits (give it in scientific notation, e.g. 1e9)",
            node.start_mark,
        )
    return yaml.constructor.SafeConstructor.construct_yaml_int(loader, node)


ProgramLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)
