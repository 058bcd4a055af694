"""The pendant's state: the arm, its start and current configuration, the steps and jog speed,
what was recorded; the start it comes back to (:func:`home_configuration`), a command's
:class:`Reply`, the status line and moving the arm (captured by a running recording)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.apps.teach.capture import Recording, capture
from kinplan.apps.teach.paths import RecordedPath
from kinplan.apps.teach.settings import (
    DEFAULT_ANGULAR_STEP_DEG,
    DEFAULT_JOG_SPEED,
    DEFAULT_LINEAR_STEP,
    DEFAULT_PATH_TOLERANCE,
    MAX_LINEAR_JOG,
    MAX_PATH_TOLERANCE_DEG,
    MAX_ROTATION_JOG_DEG,
)
from kinplan.cell import WorkCell
from kinplan.errors import InputError
from kinplan.model.robot import Robot
from kinplan.program.schema import FALLBACK_JOINT_SPEED, PTP_RAMP_TIME

_HOME_DEG = {
    "ur": [0.0, -90.0, 90.0, -90.0, -90.0, 0.0],
    "panda": [0.0, -45.0, 0.0, -135.0, 0.0, 90.0, 45.0],
}


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


@dataclass(frozen=True)
class MoveSpec:
    """How the program reaches a recorded point.

    Attributes:
        kind: ``ptp``, ``lin`` or ``circ``.
        via: The via point of a ``circ``, or None.
        speed: Tool speed [m/s] of a lin/circ, or None (the program's default).
        weave: (pattern, amplitude [m], frequency [Hz]) of a lin/circ, or None.
        torch: (work angle, travel angle) [deg] of a lin/circ, or None.
        arc: ``on`` / ``off`` when the move switches the arc, else None.
    """

    kind: str = "ptp"
    via: str | None = None
    speed: float | None = None
    weave: tuple[str, float, float] | None = None
    torch: tuple[float, float] | None = None
    arc: str | None = None

    def yaml(self, name: str) -> str:
        """The move as a YAML flow mapping, e.g. ``{lin: b, speed: 0.01, arc: on}``."""
        parts = [f"{self.kind}: {name}"]
        if self.via is not None:
            parts.append(f"via: {self.via}")
        if self.speed is not None:
            parts.append(f"speed: {self.speed:g}")
        if self.weave is not None:
            pattern, amplitude, frequency = self.weave
            parts.append(
                f"weave: {{pattern: {pattern}, amplitude: {amplitude:g}, frequency: {frequency:g}}}"
            )
        if self.torch is not None:
            parts.append(
                f"torch: {{work_angle_deg: {self.torch[0]:g}, travel_angle_deg: {self.torch[1]:g}}}"
            )
        if self.arc is not None:
            parts.append(f"arc: {self.arc}")
        return "{" + ", ".join(parts) + "}"


class PendantState:
    """A teach session's state, shared by the pendant's commands (:class:`TeachPendant
    <kinplan.apps.teach.TeachPendant>` documents the arguments and attributes)."""

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
        self._recording: Recording | None = None
        self.flange_robot = robot  # the robot without the pendant's tool
        self.tool_pose: tuple[tuple[float, ...], tuple[float, ...]] | None = None  # m, deg
        self.weave: tuple[str, float, float] | None = None  # for the next lin/circ moves
        self.torch: tuple[float, float] | None = None  # work, travel angle [deg]
        self.arc: str | None = None  # "on" / "off" on the next recorded move
        self.move_specs: dict[str, MoveSpec] = {}  # how the program reaches each point
        self.cell: WorkCell | None = None  # jogs are checked against it (use_cell)
        self.clearance = 0.0  # [m] from its obstacles
        self.cell_lines: list[str] = []  # its obstacles: and clearance: for the program

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

    def _go(self, q: np.ndarray, along: tuple[np.ndarray, np.ndarray] | None = None) -> Reply:
        """Move to ``q`` (captured by a running recording: along the joint path ``along``, path
        fractions and configurations, or joint-interpolated)."""
        if self.cell is not None:
            rows = [self.q, *(along[1] if along is not None else []), q]
            check = self.cell.check_motion(np.array(rows, dtype=float), self.clearance)
            if not check.ok:
                first, second = check.bodies if check.bodies else ("the robot", "the cell")
                return Reply(
                    f"refused: {first} would hit {second} (clearance {1e3 * self.clearance:g} "
                    "mm); jog another way"
                )
        if self._recording is not None:
            refusal = capture(
                self._recording, self.q, q, along, self._jog_velocity, self._jog_acceleration
            )
            if refusal:
                return Reply(refusal)
        self.q = q
        return Reply(self.status(), moved=True)


def _check_robot(robot: object) -> None:
    if not isinstance(robot, Robot):
        raise InputError(
            f"robot must be a kinplan.Robot (from kinplan.load_robot), got {checks.describe(robot)}"
        )
