"""Files out of a planned motion: CSV samples, a plot, and programs a controller can run.

:func:`write_csv` writes one row per sample (time, joint positions, velocities, accelerations and
the tool pose); :func:`plot_motion` draws joint position, velocity, acceleration and the tool
speed against time, with the move boundaries. Both take any planned motion with a robot
(:class:`kinplan.motion.SampledMotion`: a :class:`kinplan.program.ProgramPlan`, a
:class:`cartesian.CartesianPlan`, or a joint trajectory sampled by
:func:`kinplan.motion.sampled` with its robot); the tool poses and speeds come from the robot's
kinematics at the samples (:func:`kinplan.motion.tool_track`).

Controller exports (issue 17) take the same motions, but only whole ones: a failed plan is
refused (:class:`~kinplan.errors.InputError`), since a controller would run the partial motion.

* :func:`urscript` / :func:`write_urscript`: a URScript program for a Universal Robots arm that
  goes to the start with ``movej`` and replays the motion with one ``servoj`` per controller
  period, the motion resampled at that period (:func:`servo_samples`);
* :func:`joint_trajectory` / :func:`write_joint_trajectory`: a ROS 2
  ``trajectory_msgs/msg/JointTrajectory`` document (JSON or YAML) holding the plan's samples.

Between its samples a motion is its own continuous motion when it has one (a
:class:`~kinplan.program.ProgramPlan` is a Trajectory: a ptp move's profile, the quintic Hermite
through the samples of the other moves; a sampled joint trajectory is the trajectory), otherwise
the quintic Hermite interpolation of the samples (exact in position, velocity and acceleration
at every sample: :func:`kinplan.program.hermite_segments`). The servo stream resamples the
former; a controller given the written points (a JointTrajectory, a CSV) interpolates the
latter.

Every export that writes a motion (:func:`write_csv`, :func:`servo_samples`, :func:`urscript`,
:func:`joint_trajectory` and their writers) first checks the continuous motion it stands for
against the robot's limits, whatever built the motion (:func:`check_limits`): positions,
velocities and the accelerations the robot declares, at the samples and between them. A motion
beyond a limit is refused with a :class:`LimitViolationError` naming the joint, the time, the
value and the limit.
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from kinplan import checks, defaults
from kinplan.errors import InputError, KinplanError
from kinplan.motion import (
    JointTrajectory,
    MoveSpan,
    SampledMotion,
    ToolTrack,
    collision_check,
    collision_time,
    tool_track,
)
from kinplan.trajectory import Trajectory, time_grid

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from kinplan.robot import Robot

logger = logging.getLogger(__name__)

__all__ = [
    "CHECK_SUBDIVISIONS",
    "DEFAULT_SERVO_PERIOD",
    "POSITION_SLACK",
    "RATE_SLACK",
    "TRAJECTORY_FORMATS",
    "UR_JOINT_NAMES",
    "LimitViolationError",
    "check_limits",
    "csv_header",
    "joint_trajectory",
    "plan_failure",
    "plot_motion",
    "ros_duration",
    "servo_samples",
    "trajectory_format",
    "ur_arm_problem",
    "urscript",
    "write_csv",
    "write_joint_trajectory",
    "write_urscript",
]


def csv_header(joint_names: Sequence[str]) -> list[str]:
    """Column names: ``t``, ``q_<joint>``…, ``qd_<joint>``…, ``qdd_<joint>``…, ``x y z`` (tool
    position [m]) and ``qx qy qz qw`` (tool orientation quaternion)."""
    names = _name_list(joint_names, "joint_names")
    columns = ["t"]
    for prefix in ("q", "qd", "qdd"):
        columns += [f"{prefix}_{name}" for name in names]
    return columns + ["x", "y", "z", "qx", "qy", "qz", "qw"]


def write_csv(
    path: str | os.PathLike[str], plan: SampledMotion, joint_names: Sequence[str]
) -> Path:
    """Write the samples of a plan as CSV, one row per sample, with a header line.

    Units: s, rad (or m for prismatic joints), rad/s, rad/s², m; the quaternion is (x, y, z, w).

    Args:
        path: File to write (its folder is created).
        plan: The motion, with its robot (:class:`~kinplan.motion.SampledMotion`).
        joint_names: Names of the joints, for the header.

    Returns:
        The written path.

    Raises:
        InputError: not a motion with a robot, or not a file path.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`; a
            failed plan's achieved part too).
        KinplanError: the file cannot be written.
    """
    target = Path(checks.file_path(path, "path"))
    track = _tool_track(plan, "write_csv")
    header = csv_header(_joint_names(plan, joint_names, np.shape(plan.q)[-1]))
    check_limits(plan, "write_csv")
    table = np.column_stack([plan.t, plan.q, plan.qd, plan.qdd, track.positions, track.quaternions])
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        np.savetxt(
            target,
            table,
            fmt="%.9g",
            delimiter=",",
            header=",".join(header),
            comments="",
        )
    except OSError as exc:
        raise KinplanError(f"cannot write the CSV file {target}: {exc}") from exc
    logger.info("wrote %s (%d rows)", target, len(table))
    return target


# ----------------------------------------------------------------------------------------------
# Controller exports (issue 17): URScript for UR arms, ROS JointTrajectory documents
# ----------------------------------------------------------------------------------------------

UR_JOINT_NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
"""Joints of a Universal Robots arm, base to wrist 3: the order of URScript joint vectors."""

DEFAULT_SERVO_PERIOD = defaults.DEFAULT_SERVO_PERIOD
"""Period of the ``servoj`` stream [s]: the CB-series controller's 125 Hz (e-Series: 0.002)."""

TRAJECTORY_FORMATS = {".json": "json", ".yaml": "yaml", ".yml": "yaml"}
"""File extensions of :func:`write_joint_trajectory` and the format each writes."""

_NANOSECONDS = 1_000_000_000


#: Sub-intervals of each sample interval at which the exports check the interpolant (the quintic
#: Hermite through the samples) against the robot's limits, besides the samples themselves.
CHECK_SUBDIVISIONS = 16
#: Slack of the position-limit check [rad or m]: rounding, nothing a controller could resolve.
POSITION_SLACK = 1e-9
#: Relative slack of the velocity and acceleration checks [-]: rounding, and the maximum of the
#: interpolant between two of the sub-samples (below 1e-3 of its curvature scale at
#: :data:`CHECK_SUBDIVISIONS` = 16).
RATE_SLACK = 1e-6


class LimitViolationError(InputError):
    """An export refused a motion that breaks the robot's limits.

    Attributes:
        joint: The joint's name.
        quantity: ``"position"``, ``"velocity"`` or ``"acceleration"``.
        t: When [s], from the motion's start (the worst instant of the interpolant).
        value: The joint's value there [rad, rad/s, rad/s² or m, m/s, m/s²].
        limit: The limit it breaks (the nearer position limit, or the rate limit).
    """

    def __init__(
        self, message: str, joint: str, quantity: str, t: float, value: float, limit: float
    ) -> None:
        super().__init__(message)
        self.joint = joint
        self.quantity = quantity
        self.t = t
        self.value = value
        self.limit = limit


def check_limits(
    plan: SampledMotion, what: str = "the export", *, between: str = "samples"
) -> None:
    """Refuse a motion whose continuous motion breaks its robot's position, velocity or
    (declared) acceleration limits.

    The continuous motion is checked at every sample and at :data:`CHECK_SUBDIVISIONS` − 1
    instants inside every interval between two samples (so a controller's own period — a
    ``servoj`` stream's Δq / period and its second differences — stays within the same
    bounds): positions within [lower, upper] (± :data:`POSITION_SLACK`), |q̇| within the
    velocity limit and |q̈| within the acceleration limit where the robot declares one (each
    with a relative slack :data:`RATE_SLACK`). A motion without a robot has no limits to check.

    Args:
        plan: A motion with samples (:class:`~kinplan.motion.SampledMotion`).
        what: The export's name, for the message.
        between: Which continuous motion: ``"samples"``, the quintic Hermite through the
            samples (positions, velocities and accelerations: what a controller interpolating
            the written points runs, e.g. a ROS JointTrajectory); ``"plan"``, the plan's own
            (``plan.sample`` of a program plan, the trajectory of a sampled joint trajectory,
            the Hermite through the samples otherwise: what :func:`servo_samples` resamples).

    Raises:
        LimitViolationError: the worst violation of the first kind found (positions, then
            velocities, then accelerations), naming the joint, the time [s], the value, the
            limit and what to change.
        InputError: not a motion, samples that are not finite, an unknown ``between``.
    """
    between = checks.choice(between, "between", ("samples", "plan"))
    t, q, qd, qdd = _samples(plan, what)
    robot = plan.robot
    if robot is None or len(t) == 0:
        return
    lower, upper = np.asarray(robot.lower, float), np.asarray(robot.upper, float)
    speed = np.asarray(robot.velocity_limit, float)
    accel = np.asarray(robot.acceleration_limit, float)
    worst: dict[str, tuple[float, int, float, float, float]] = {}  # ratio, joint, t, value, limit
    first: dict[str, float] = {}  # the earliest instant beyond a limit of each kind [s]

    def keep(quantity: str, ratio: np.ndarray, times: np.ndarray, values: np.ndarray, bound):
        threshold = 1.0 + RATE_SLACK if quantity != "position" else 0.0
        beyond = times[(ratio > threshold).any(axis=1)]
        first[quantity] = min(first.get(quantity, math.inf), float(beyond.min()))
        k, j = divmod(int(np.argmax(ratio)), ratio.shape[1])
        if ratio[k, j] > worst.get(quantity, (0.0,))[0]:
            limit = float(bound[j] if np.ndim(bound) == 1 else bound[k, j])
            worst[quantity] = (float(ratio[k, j]), j, float(times[k]), float(values[k, j]), limit)

    for times, position, velocity, acceleration in _continuous(plan, t, q, qd, qdd, between):
        below, above = lower - position, position - upper
        excess = np.maximum(below, above)
        if np.any(excess > POSITION_SLACK):
            bound = np.where(below > above, lower, upper)
            keep("position", np.where(excess > POSITION_SLACK, excess, 0.0), times, position,
                 bound)  # fmt: skip
        with np.errstate(divide="ignore", invalid="ignore"):
            for quantity, values, limit in (
                ("velocity", velocity, speed),
                ("acceleration", acceleration, accel),
            ):
                ratio = np.where(np.isfinite(limit), np.abs(values) / limit, 0.0)
                ratio = np.where(np.isnan(ratio), np.inf, ratio)  # a limit of 0, a motion
                if np.any(ratio > 1.0 + RATE_SLACK):
                    keep(quantity, ratio, times, values, limit)
    for quantity in ("position", "velocity", "acceleration"):
        if quantity in worst:
            peak, j, when, value, edge = worst[quantity]
            raise _violation(plan, what, quantity, j, when, value, edge, peak, first[quantity])


def _continuous(
    plan: SampledMotion,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    between: str,
) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """The continuous motion (see :func:`check_limits`) at the samples and
    :data:`CHECK_SUBDIVISIONS` − 1 instants inside each interval, in chunks: (times (K,) [s]
    from the first sample, q, q̇, q̈ (K, n) each)."""
    motion = _motion(plan, t, q, qd, qdd, between)
    yield t - t[0], q, qd, qdd
    if len(t) < 2:
        return
    u = np.arange(1, CHECK_SUBDIVISIONS) / CHECK_SUBDIVISIONS  # inside the intervals
    chunk = max(1, 100_000 // len(u))
    for start in range(0, len(t) - 1, chunk):
        left, right = t[start : start + chunk + 1][:-1], t[start + 1 : start + chunk + 1]
        times = (left[:, None] + (right - left)[:, None] * u[None, :]).reshape(-1) - t[0]
        yield (times, *motion(times))


def _motion(
    plan: SampledMotion,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    between: str,
) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The continuous motion as a function of the time from the first sample [s]: the plan's
    own (``between="plan"``: a program plan, a sampled joint trajectory) or the quintic
    Hermite through the samples."""
    if between == "plan":
        own = plan if isinstance(plan, Trajectory) else getattr(plan, "trajectory", None)
        if isinstance(own, JointTrajectory) and not isinstance(own, SampledMotion):
            start = float(t[0]) if own is plan else 0.0
            return lambda times: tuple(  # type: ignore[return-value]
                np.asarray(x, dtype=float).reshape(len(times), -1)
                for x in own.sample(times + start)
            )
        if isinstance(own, Trajectory):  # a program plan: it is itself a Trajectory
            start = float(t[0])
            return lambda times: own.sample(times + start)
    if len(t) == 1:
        return lambda times: (np.repeat(q, len(times), 0), np.zeros((len(times), q.shape[1])),
                              np.zeros((len(times), q.shape[1])))  # fmt: skip
    from kinplan.program.segments import hermite_segments

    hermite = Trajectory(
        hermite_segments(t - t[0], q, qd, qdd),
        end=q[-1],
        end_velocity=qd[-1],
        end_acceleration=qdd[-1],
    )
    return hermite.sample


def _samples(
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


def _violation(
    plan: SampledMotion,
    what: str,
    quantity: str,
    joint: int,
    when: float,
    value: float,
    limit: float,
    ratio: float,
    since: float,
) -> LimitViolationError:
    """The error of the worst violation of one kind (``since``: the first instant beyond a
    limit of that kind [s]), with what to change."""
    robot = plan.robot
    assert robot is not None
    name = robot.joint_names[joint]
    prismatic = bool(np.asarray(getattr(robot, "prismatic", np.zeros(robot.nq)))[joint])
    unit = {"position": "m", "velocity": "m/s", "acceleration": "m/s²"}[quantity]
    if not prismatic:
        unit = unit.replace("m", "rad", 1)
    where = _move_at(plan, when)
    if since < when - 1e-12:
        where += f" (the first beyond a {quantity} limit at t = {since:.4f} s)"
    if quantity == "position":
        side = "lower" if value < limit else "upper"
        text = (
            f"joint {name} reaches {value:.6g} {unit} at t = {when:.4f} s{where}, beyond its "
            f"{side} limit {limit:.6g} {unit}; move the motion's points so that the joint stays "
            "within its limits (the motion between two samples included)"
        )
    else:
        scale = ratio if quantity == "velocity" else math.sqrt(ratio)
        slower = math.ceil(scale * 1000.0) / 1000.0  # rounded up: pasting it works
        text = (
            f"joint {name} {'moves at' if quantity == 'velocity' else 'accelerates at'} "
            f"{abs(value):.6g} {unit} at t = {when:.4f} s{where}, {ratio:.3g}× its {quantity} "
            f"limit {limit:.6g} {unit}; plan the motion at least {slower:g}× slower (a longer "
            "duration or a lower speed)"
        )
    if quantity == "acceleration" and np.isinf(ratio):
        text = text.replace(f"{ratio:.3g}×", "beyond")
    return LimitViolationError(
        f"{what} refuses a motion beyond the robot's limits: {text}",
        name,
        quantity,
        when,
        value,
        limit,
    )


def _move_at(plan: SampledMotion, when: float) -> str:
    """`` in move 3 (label)`` for the program move running at ``when`` [s], else ""."""
    moves = list(getattr(plan, "moves", None) or [])
    if not moves:
        return ""
    start = float(np.asarray(plan.t, dtype=float)[0])
    for move in moves:
        if float(move.t0) - start <= when <= float(move.t1) - start + 1e-12:
            return f" in move {move.number} ({move.label})"
    return ""


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


def trajectory_format(path: str | os.PathLike[str]) -> str:
    """The format :func:`write_joint_trajectory` writes to ``path``: ``"json"`` or ``"yaml"``.

    Raises:
        InputError: not a path, or an extension other than .json, .yaml, .yml.
    """
    text = checks.file_path(path, "path")
    suffix = Path(text).suffix.lower()
    if suffix not in TRAJECTORY_FORMATS:
        got = f"a {suffix} file" if suffix else "a file without an extension"
        raise InputError(
            f"a JointTrajectory file is written as JSON or YAML, got {got} ({text}); give a "
            f"file ending in {', '.join(TRAJECTORY_FORMATS)}"
        )
    return TRAJECTORY_FORMATS[suffix]


def plan_failure(plan: SampledMotion) -> str:
    """Where and why a plan failed, one short phrase ("" when it is ok): ``the plan failed at
    move 3 (collision)`` for a program, ``the plan stopped at t = 1.250 s (unreachable)``
    otherwise."""
    if not isinstance(plan, SampledMotion):
        raise InputError(
            f"plan_failure takes a planned motion (kinplan.motion.SampledMotion), got "
            f"{checks.describe(plan)}"
        )
    if plan.ok:
        return ""
    failed = [move for move in plan.moves if move.status != "ok"]
    if failed:
        return f"the plan failed at move {failed[0].number} ({failed[0].status})"
    if plan.events:
        event = plan.events[0]
        return f"the plan stopped at t = {event.t:.3f} s ({event.kind})"
    return f"the plan failed ({plan.status})"


def ros_duration(seconds: float) -> dict[str, int]:
    """A time as a ROS 2 ``builtin_interfaces/Duration``: ``{"sec": ..., "nanosec": ...}``.

    ``sec`` is the whole seconds (floor) and ``nanosec`` the rest rounded to the nearest
    nanosecond, carried into ``sec`` when it rounds to 10⁹: always 0 ≤ nanosec < 10⁹.

    Args:
        seconds: The time, 0 ≤ seconds < 2³¹ [s].

    Raises:
        InputError: not a finite number in that range.
    """
    value = checks.number(seconds, "seconds", minimum=0.0, maximum=2.0**31 - 1.0, unit="s")
    whole = math.floor(value)
    nanosec = round((value - whole) * 1e9)  # value - whole is exact in floating point
    if nanosec >= _NANOSECONDS:
        whole, nanosec = whole + 1, nanosec - _NANOSECONDS
    return {"sec": int(whole), "nanosec": int(nanosec)}


def servo_samples(
    plan: SampledMotion, period: float = DEFAULT_SERVO_PERIOD
) -> tuple[np.ndarray, np.ndarray]:
    """The motion resampled at a controller's period: the targets of a ``servoj`` stream.

    The times are ``k · period`` from the plan's first sample, the last exactly at its end
    (:func:`kinplan.trajectory.time_grid`: ceil(duration / period) + 1 samples, a remainder
    below 10⁻⁶ period absorbed); the positions are the plan's continuous motion there (its own
    ``sample`` for a program plan or a sampled joint trajectory, otherwise the quintic Hermite
    interpolation of the plan's samples: positions, velocities and accelerations), the first
    ``plan.q[0]`` and the last ``plan.q[-1]``, exactly. That motion is checked against the
    robot's limits first (:func:`check_limits` with ``between="plan"``).

    Args:
        plan: A whole motion (:class:`~kinplan.motion.SampledMotion` that is ok).
        period: Sampling period [s], > 0.

    Returns:
        Times (K,) [s] from the plan's start and joint positions (K, nq) [rad or m].

    Raises:
        InputError: not a motion, a failed plan, samples that are not finite or whose times do
            not increase, or a period that is not a positive number.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`).
    """
    return _servo_samples(plan, period, "servo_samples")


def _servo_samples(plan: SampledMotion, period: float, what: str) -> tuple[np.ndarray, np.ndarray]:
    """:func:`servo_samples`, its errors naming ``what``."""
    step = checks.number(period, "period", positive=True, unit="s")
    t, q, qd, qdd = _whole_motion(plan, what, between="plan")
    times = time_grid(float(t[-1] - t[0]), step)
    if len(t) == 1:
        return times, np.repeat(q, len(times), axis=0)
    targets = np.array(_motion(plan, t, q, qd, qdd, "plan")(times)[0], dtype=float)
    targets[0], targets[-1] = q[0], q[-1]  # the motion's ends, exactly
    return times, targets


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
    times, targets = _servo_samples(plan, period, "urscript")
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
    _write_text(target, text, "URScript")
    return target


def joint_trajectory(
    plan: SampledMotion, joint_names: Sequence[str] | None = None
) -> dict[str, Any]:
    """A whole motion as a ROS 2 ``trajectory_msgs/msg/JointTrajectory`` (plain dicts and lists).

    One point per sample of the plan: ``positions`` [rad or m], ``velocities`` [rad/s or m/s],
    ``accelerations`` [rad/s² or m/s²] (the samples' values, unchanged) and
    ``time_from_start`` (:func:`ros_duration` of the time from the plan's first sample). The
    ``header`` has a zero ``stamp`` (a trajectory controller starts it on receipt) and an
    empty ``frame_id``::

        {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
         "joint_names": [...],
         "points": [{"positions": [...], "velocities": [...], "accelerations": [...],
                     "time_from_start": {"sec": 0, "nanosec": 10000000}}, ...]}

    Args:
        plan: A whole motion (:class:`~kinplan.motion.SampledMotion` that is ok).
        joint_names: One name per joint; default the robot's (required without a robot).

    Raises:
        InputError: not a motion, a failed plan, no joint names (or not one per joint),
            samples that are not finite, or two samples at the same nanosecond.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`; a
            motion without a robot is not checked).
    """
    t, q, qd, qdd = _whole_motion(plan, "joint_trajectory")
    names = _joint_names(plan, joint_names, q.shape[1])
    stamps = [ros_duration(x) for x in (t - t[0]).tolist()]
    for k in range(1, len(stamps)):
        if (stamps[k]["sec"], stamps[k]["nanosec"]) <= (
            stamps[k - 1]["sec"],
            stamps[k - 1]["nanosec"],
        ):
            raise InputError(
                f"samples {k - 1} and {k} of the plan are less than 1 ns apart ({t[k - 1]!r} s, "
                f"{t[k]!r} s): a JointTrajectory needs increasing times; resample the motion"
            )
    points = [
        {
            "positions": positions,
            "velocities": velocities,
            "accelerations": accelerations,
            "time_from_start": stamp,
        }
        for positions, velocities, accelerations, stamp in zip(
            q.tolist(), qd.tolist(), qdd.tolist(), stamps, strict=True
        )
    ]
    return {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
        "joint_names": names,
        "points": points,
    }


def write_joint_trajectory(
    path: str | os.PathLike[str],
    plan: SampledMotion,
    joint_names: Sequence[str] | None = None,
) -> Path:
    """Write :func:`joint_trajectory` of a whole motion as JSON (.json) or YAML (.yaml, .yml).

    Floats are written with the shortest text that reads back to the same number (Python's
    ``repr``), so the file holds the samples exactly. JSON has one point per line; YAML has one
    point per block, its lists inline.

    Args:
        path: File to write (its folder is created); the extension picks the format.
        plan: A whole motion (:class:`~kinplan.motion.SampledMotion` that is ok).
        joint_names: One name per joint; default the robot's.

    Returns:
        The written path.

    Raises:
        InputError: an extension other than .json, .yaml, .yml (checked first), or as
            :func:`joint_trajectory`.
        KinplanError: the file cannot be written.
    """
    kind = trajectory_format(path)
    target = Path(os.fspath(path))
    document = joint_trajectory(plan, joint_names)
    if kind == "json":
        text = _json_text(document)
    else:
        import yaml

        text = yaml.safe_dump(document, sort_keys=False, default_flow_style=None, width=10**9)
    _write_text(target, text, "JointTrajectory")
    return target


def _whole_motion(
    plan: SampledMotion, what: str, limits: bool = True, between: str = "samples"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The samples (t, q, qd, qdd) of a motion a controller may run; InputError for anything
    else: not a motion, a failed plan, samples that are not finite or times that do not
    increase, and (``limits``) a motion beyond its robot's limits (:func:`check_limits` of
    the continuous motion ``between``)."""
    if not isinstance(plan, SampledMotion):
        raise InputError(
            f"{what} takes a planned motion (kinplan.motion.SampledMotion: a program or Cartesian "
            f"plan, or kinplan.motion.sampled(trajectory, robot)), got {type(plan).__name__}"
        )
    if not plan.ok:
        raise InputError(
            f"{what} refuses a failed plan: {plan_failure(plan)}; a controller must not run a "
            "partial motion (write_csv and plot_motion show the achieved part for inspection)"
        )
    t, q, qd, qdd = _samples(plan, what)
    if len(t) == 0:
        raise InputError(f"{what}: the plan has no samples")
    if limits:
        check_limits(plan, what, between=between)
    return t, q, qd, qdd


def _ur_robot(plan: SampledMotion, what: str) -> Robot:
    """The robot of a whole motion when it is a UR arm; InputError otherwise."""
    _whole_motion(plan, what, limits=False)  # not a motion, or a failed plan: said first
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


def _joint_names(plan: SampledMotion, joint_names: Sequence[str] | None, n: int) -> list[str]:
    if joint_names is None:
        if plan.robot is None:
            raise InputError(
                "joint_names is needed for a motion without a robot: give one name per joint"
            )
        return list(plan.robot.joint_names)
    names = _name_list(joint_names, "joint_names", n)
    if len(names) != n:
        raise InputError(f"joint_names must hold {n} names (one per joint), got {len(names)}")
    return names


def _name_list(names: object, what: str, n: int | None = None) -> list[str]:
    """``names`` as a list of non-empty strings; InputError otherwise."""
    count = "names" if n is None else f"{n} names"
    if isinstance(names, (str, bytes)) or not isinstance(names, (Sequence, np.ndarray)):
        raise InputError(f"{what} must be a list of {count}, got {checks.describe(names)}")
    return [checks.text(name, f"{what}[...]") for name in names]


def _json_text(document: dict[str, Any]) -> str:
    """The document as JSON, one trajectory point per line."""
    head = [
        f"  {json.dumps(key)}: {json.dumps(value, allow_nan=False)},"
        for key, value in document.items()
        if key != "points"
    ]
    points = ",\n".join(f"    {json.dumps(p, allow_nan=False)}" for p in document["points"])
    return "\n".join(["{", *head, '  "points": [', points, "  ]", "}"]) + "\n"


def _write_text(target: Path, text: str, what: str) -> None:
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise KinplanError(f"cannot write the {what} file {target}: {exc}") from exc
    logger.info("wrote %s (%d bytes)", target, len(text))


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


def plot_motion(
    plan: SampledMotion,
    path: str | os.PathLike[str] | None = None,
    joint_names: Sequence[str] | None = None,
    title: str | None = None,
    unit: str = "rad",
) -> Figure:
    """Joint position, velocity, acceleration and tool speed against time, one line per joint.

    Move boundaries (``plan.moves`` with ``t0``/``t1``) are drawn as faint vertical lines and
    numbered at the top; a failed move is shaded red. A plan checked against a work cell
    (``cell=`` of :func:`cartesian.follow`, a program) gets a fifth panel, its clearance [mm]:
    the smallest robot–obstacle distance and the smallest distance between the robot's own
    checked pairs at every sample (coal's exact distances at the samples,
    :class:`kinplan.cell.MotionCheck`; between two samples the check certified the margin, the
    lines just join the samples), the ``clearance`` margin (kept from the obstacles) dashed, and
    for a plan stopped by a collision a cross at the failing pair's distance at the failing
    instant (a sample the plan does not keep, or between two samples).

    Args:
        plan: The motion, with its robot (:class:`~kinplan.motion.SampledMotion`); a program's
            moves are marked.
        path: Image file to save to (format from the suffix); None: don't save.
        joint_names: One name per joint (default ``joint 0``, ...).
        title: Figure title.
        unit: Unit of joint position for the labels.

    Returns:
        The figure (four stacked axes; five with the clearance).

    Raises:
        InputError: not a motion with a robot; ``path`` not a file path of an image type
            Matplotlib writes; ``joint_names`` not one name per joint; ``title`` not a string.
        KinplanError: the image cannot be written.
    """
    from matplotlib.figure import Figure

    target = None if path is None else checks.file_path(path, "path (the image file to write)")
    if title is not None and not isinstance(title, str):
        raise InputError(f"title must be a string or None, got {checks.describe(title)}")
    track = _tool_track(plan, "plot_motion")
    n = plan.q.shape[1]
    names = (
        _joint_names(plan, joint_names, n)
        if joint_names is not None
        else [f"joint {j}" for j in range(n)]
    )
    clearances = _clearances(plan)
    rows = 4 if clearances is None else 5
    figure = Figure(figsize=(9.0, 9.0 if rows == 4 else 11.0), layout="constrained")
    axes = figure.subplots(rows, 1, sharex=True)
    for j in range(n):
        for ax, values in zip(axes[:3], (plan.q, plan.qd, plan.qdd)):
            ax.plot(plan.t, values[:, j], color=f"C{j % 10}", label=names[j], linewidth=1.2)
    axes[3].plot(plan.t, 1000.0 * track.speed, color="k", linewidth=1.2)
    labels = (
        f"position [{unit}]",
        f"velocity [{unit}/s]",
        f"acceleration [{unit}/s²]",
        "tool speed [mm/s]",
    )
    for ax, label in zip(axes, labels):
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    if clearances is not None:
        _plot_clearances(axes[4], plan.t, clearances)
    _mark_moves(axes, plan.moves)
    axes[-1].set_xlabel("time [s]")
    axes[0].legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    if title:
        figure.suptitle(title)
    if target is not None:
        try:
            Path(target).parent.mkdir(parents=True, exist_ok=True)
            figure.savefig(target, dpi=110)
        except ValueError as exc:  # an image format Matplotlib does not write
            raise InputError(f"cannot save {target}: {exc}") from None
        except OSError as exc:
            raise KinplanError(f"cannot write {target}: {exc.strerror or exc}") from None
        logger.info("wrote %s", target)
    return figure


@dataclass(frozen=True)
class _Clearances:
    """What the clearance panel of :func:`plot_motion` draws (distances [m] at the samples)."""

    obstacle: np.ndarray  # smallest robot–obstacle distance (N,): inf without obstacles
    own: np.ndarray  # smallest distance of the robot's own checked pairs (N,)
    margin: float  # the clearance margin (robot–obstacle pairs)
    failure: tuple[float, float, str] | None  # (t [s], distance [m], label) of a collision


def _clearances(plan: SampledMotion) -> _Clearances | None:
    """The per-sample clearances of a plan checked against a work cell, or None.

    A Cartesian plan keeps its :class:`kinplan.cell.MotionCheck` (``cell_check``), a program
    plan the clearances of its moves' checks (``clearance``, ``self_clearance``).
    """
    if getattr(plan, "cell", None) is None:
        return None
    n = len(plan.t)
    check = getattr(plan, "cell_check", None)
    per_sample = getattr(plan, "clearance", None)
    if check is not None:
        obstacle = np.asarray(check.obstacle_distances, dtype=float)[:n]
        own = np.asarray(check.self_distances, dtype=float)[:n]
        margin = float(check.clearance)
    elif per_sample is not None:
        obstacle = np.asarray(per_sample, dtype=float)
        own_values = getattr(plan, "self_clearance", None)
        own = np.full(n, np.nan) if own_values is None else np.asarray(own_values, dtype=float)
        margin = float(getattr(plan, "clearance_margin", 0.0))
    else:
        return None
    failed = collision_check(plan)
    failure = None
    if failed is not None and failed.bodies is not None:
        label = f"collision: {failed.bodies[0]} – {failed.bodies[1]}"
        failure = (collision_time(plan, failed), float(failed.distance), label)
    if not (np.isfinite(obstacle).any() or np.isfinite(own).any() or failure):
        return None
    return _Clearances(obstacle, own, margin, failure)


def _plot_clearances(ax: Axes, t: np.ndarray, clearances: _Clearances) -> None:
    """The clearance panel: distances [mm] against time, the margin dashed, the collision."""
    for values, colour, label in (
        (clearances.obstacle, "C3", "robot–obstacle"),
        (clearances.own, "C0", "robot–robot (self)"),
    ):
        if np.isfinite(values).any():
            ax.plot(t, 1e3 * values, color=colour, linewidth=1.2, label=label)
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    if clearances.margin > 0:
        ax.axhline(
            1e3 * clearances.margin, color="C3", linestyle="--", linewidth=1.0,
            label=f"clearance margin {1e3 * clearances.margin:g} mm (obstacles)",
        )  # fmt: skip
    if clearances.failure is not None:
        when, distance, label = clearances.failure
        ax.plot([when], [1e3 * distance], "x", color="C3", markersize=9, mew=2, label=label)
    ax.set_ylabel("clearance [mm]")
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))


def _tool_track(plan: SampledMotion, what: str) -> ToolTrack:
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


def _mark_moves(axes: Sequence[Axes], moves: Sequence[MoveSpan]) -> None:
    for move in moves:
        failed = move.status != "ok"
        for ax in axes:
            ax.axvline(move.t0, color="0.8", linewidth=0.6, zorder=0)
            if failed:
                ax.axvspan(move.t0, max(move.t1, move.t0 + 1e-9), color="C3", alpha=0.12)
        middle = 0.5 * (move.t0 + move.t1)
        axes[0].annotate(
            str(move.number),
            (middle, 1.0),
            xycoords=("data", "axes fraction"),
            ha="center",
            va="bottom",
            fontsize="x-small",
            color="C3" if failed else "0.35",
        )
