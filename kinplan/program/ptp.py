"""Timing of joint-interpolated (``ptp``) moves within the joint limits, checked over the
continuous motion.

Every ptp profile honours the robot's position, velocity and acceleration limits (the URDF's,
the program's ``limits:`` and ``max_acceleration:``): timed by the planner (no ``duration``) it
is planned within them; timed by the user (``duration`` or ``times``) it is checked, over the
continuous polynomial motion and not only at samples (:func:`kinplan.program.peaks.joint_peaks`),
and refused with a :class:`PtpLimitError` that states the shortest duration (or the time
scale) that works, rounded up and verified by planning it again, so that pasting it works.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from kinplan import trajectory
from kinplan.errors import InfeasibleError, KinplanError
from kinplan.model.robot import Robot
from kinplan.program.peaks import joint_peaks
from kinplan.program.schema import (
    DEFAULT_PTP_SPEED,
    FALLBACK_JOINT_SPEED,
    PTP_JERK_TIME,
    PTP_RAMP_TIME,
)
from kinplan.trajectory import DEFAULT_BLEND_FRACTION, Trajectory
from kinplan.trajectory._profiles import PTP_PROFILES, REST_TO_REST_PEAKS, round_up
from kinplan.trajectory.sampling import joint_speeds

__all__ = [
    "LIMIT_TOLERANCE",
    "POSITION_TOLERANCE",
    "LimitProblem",
    "PtpLimitError",
    "acceleration_limits",
    "distinct",
    "limit_problem",
    "motion_limits",
    "peak_speed_ratio",
    "plan_ptp",
    "plan_ptp_through",
    "polynomial_duration",
    "ptp_through_trajectory",
    "ptp_trajectory",
    "trapezoid_minimum_duration",
]

LIMIT_TOLERANCE = 1e-9
"""Relative slack on the velocity and acceleration limits for rounding [-]."""
POSITION_TOLERANCE = 1e-9
"""Slack on the joint position limits for rounding [rad or m]."""
_REMEDY_DIGITS = 4
"""Significant digits of a duration or time scale a refusal states (rounded up, verified)."""


class PtpLimitError(InfeasibleError):
    """A ptp move whose motion would leave the joint limits; the message says by how much and
    what to change (a value rounded up that was verified to work).

    Attributes:
        status: ``joint_limit``, ``velocity_limit``, ``acceleration_limit`` or ``invalid`` (a
            duration shorter than a limit-timed profile allows).
        ratio: Largest joint speed over its limit [-] (0 when not computed).
    """

    def __init__(self, status: str, message: str, ratio: float = 0.0) -> None:
        super().__init__(message)
        self.status = status
        self.ratio = ratio


@dataclass(frozen=True)
class LimitProblem:
    """The worst way a joint motion leaves the limits.

    Attributes:
        status: ``joint_limit``, ``velocity_limit`` or ``acceleration_limit``.
        text: ``status: what and where`` (no remedy).
        scale: Time scale (≥ 1) that would bring the speeds and accelerations within their
            limits (speeds divide by it, accelerations by its square); inf for a position
            limit (time scaling does not move the path).
        speed_ratio: Largest joint speed over its limit [-].
    """

    status: str
    text: str
    scale: float
    speed_ratio: float


def distinct(value: float, bound: float, unit: str) -> tuple[str, str]:
    """``value`` and ``bound`` printed with 4 significant digits, or more until they differ
    (so that "-1.0472 rad, beyond its lower limit -1.0472 rad" cannot be printed)."""
    for digits in range(4, 18):
        a, b = f"{value:.{digits}g}", f"{bound:.{digits}g}"
        if a != b:
            return f"{a} {unit}", f"{b} {unit}"
    return f"{value!r} {unit}", f"{bound!r} {unit}"


def acceleration_limits(robot: Robot, max_acceleration: np.ndarray | float | None) -> np.ndarray:
    """The joint acceleration limits a move must keep [rad/s² or m/s²], shape (nq,): the
    robot's (URDF or ``limits:``) and ``max_acceleration`` (one number or one per joint), the
    lower of the two; inf where neither limits a joint."""
    limit = np.array(robot.acceleration_limit, dtype=float)
    if max_acceleration is None:
        return limit
    given = np.broadcast_to(np.asarray(max_acceleration, dtype=float), limit.shape)
    return np.minimum(limit, given)


def limit_problem(
    robot: Robot, traj: Trajectory, acceleration_limit: np.ndarray | None = None
) -> LimitProblem | None:
    """How a joint trajectory leaves the robot's limits over its continuous motion, or None.

    Position limits come first (no timing fixes them); then speed and acceleration, reported
    for whichever needs the larger time scale.

    Args:
        robot: The arm (position and velocity limits).
        traj: The motion.
        acceleration_limit: Acceleration limits [rad/s²], shape (nq,), inf where none;
            default the robot's.
    """
    limit_a = robot.acceleration_limit if acceleration_limit is None else acceleration_limit
    peaks = joint_peaks(traj)
    names = robot.joint_names
    below = robot.lower - peaks.lowest
    above = peaks.highest - robot.upper
    over = np.maximum(below, above)
    with np.errstate(invalid="ignore"):
        over = np.where(np.isfinite(over), over, -np.inf)
    limit_v = robot.velocity_limit
    ratio_v = np.where(np.isfinite(limit_v), peaks.speed / limit_v, 0.0)
    ratio_a = np.where(np.isfinite(limit_a), peaks.acceleration / limit_a, 0.0)
    speed_ratio = float(ratio_v.max(initial=0.0))
    if over.max(initial=-np.inf) > POSITION_TOLERANCE:
        j = int(np.argmax(over))
        lower = below[j] >= above[j]
        value, when = (
            (peaks.lowest[j], peaks.t_lowest[j])
            if lower
            else (peaks.highest[j], peaks.t_highest[j])
        )
        bound = robot.lower[j] if lower else robot.upper[j]
        shown, limit = distinct(float(value), float(bound), "rad")
        text = (
            f"joint_limit: joint {j} ({names[j]}) would reach {shown} at t = {when:.3f} s of "
            f"the move, beyond its {'lower' if lower else 'upper'} limit {limit}"
        )
        return LimitProblem("joint_limit", text, np.inf, speed_ratio)
    scale_v = float(ratio_v.max(initial=0.0))
    scale_a = float(np.sqrt(ratio_a.max(initial=0.0)))
    if max(scale_v, scale_a) <= 1.0 + LIMIT_TOLERANCE:
        return None
    if scale_v >= scale_a:
        j = int(np.argmax(ratio_v))
        text = (
            f"velocity_limit: joint {j} ({names[j]}) would need {peaks.speed[j]:.4g} rad/s, "
            f"above its limit {limit_v[j]:.4g} rad/s"
        )
        return LimitProblem("velocity_limit", text, scale_v, speed_ratio)
    j = int(np.argmax(ratio_a))
    text = (
        f"acceleration_limit: joint {j} ({names[j]}) would need {peaks.acceleration[j]:.4g} "
        f"rad/s², above its limit {limit_a[j]:.4g} rad/s²"
    )
    return LimitProblem("acceleration_limit", text, scale_a, speed_ratio)


def _verified(
    build: Callable[[float], Trajectory],
    estimate: float,
    robot: Robot,
    acceleration_limit: np.ndarray,
) -> float | None:
    """The smallest value from ``estimate`` up, rounded up to :data:`_REMEDY_DIGITS`
    significant digits, with which ``build`` gives a motion within the limits; None if none
    was found a little above the estimate (the remedy then names no value)."""
    if not (np.isfinite(estimate) and estimate > 0.0):
        return None
    value = round_up(estimate, _REMEDY_DIGITS)
    step = 1e-4
    for _ in range(40):
        try:
            ok = limit_problem(robot, build(value), acceleration_limit) is None
        except InfeasibleError:
            ok = False
        if ok:
            return value
        value = round_up(value * (1.0 + step), _REMEDY_DIGITS)
        step *= 2.0
    return None


def ptp_trajectory(
    robot: Robot,
    q_start: np.ndarray,
    q_goal: np.ndarray,
    duration: float | None,
    speed: float | None,
    profile: str,
    acceleration_limit: np.ndarray | None = None,
) -> Trajectory:
    """The joint trajectory of a ``ptp`` move (not checked against the limits: see
    :func:`plan_ptp`).

    Without a duration every joint cruises within ``speed`` × its velocity limit (a joint
    without a limit at :data:`~kinplan.program.FALLBACK_JOINT_SPEED`) and reaches it in
    :data:`~kinplan.program.PTP_RAMP_TIME`, or sooner where an acceleration limit is lower;
    ``scurve`` and ``time_optimal`` use the acceleration limits where there are some (scaled by
    ``speed``; all of them with a ``duration``), ``scurve`` with jerk ramps of
    :data:`~kinplan.program.PTP_JERK_TIME`. A ``trapezoid`` with a duration blends for a third
    of it, or longer (a lower acceleration) where a joint's acceleration limit asks for it.

    Args:
        robot: The arm.
        q_start: Start configuration [rad], shape (nq,).
        q_goal: Goal configuration [rad], shape (nq,).
        duration: Duration [s], or None for the minimum time within the scaled limits.
        speed: Share of the joint velocity limits in (0, 1], or None for
            :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
        profile: ``trapezoid``, ``quintic``, ``cubic``, ``scurve`` or ``time_optimal``.
        acceleration_limit: Joint acceleration limits [rad/s²], shape (nq,), inf where none;
            default the robot's (:func:`acceleration_limits`).

    Raises:
        InfeasibleError: a ``duration`` the limits cannot meet (``scurve``, ``time_optimal``,
            or a ``trapezoid`` whose acceleration limit asks for more time).
        KinplanError: an unknown profile or a speed outside (0, 1].
    """
    if profile not in PTP_PROFILES:
        raise KinplanError(f"unknown profile {profile!r}; choose one of {', '.join(PTP_PROFILES)}")
    if speed is not None and not (0 < speed <= 1):
        raise KinplanError(f"ptp speed is a share of the joint limits in (0, 1], got {speed}")
    accel = robot.acceleration_limit if acceleration_limit is None else acceleration_limit
    limit = robot.velocity_limit
    limit = np.where(np.isfinite(limit), limit, FALLBACK_JOINT_SPEED)
    max_velocity = limit * (DEFAULT_PTP_SPEED if speed is None else float(speed))
    max_acceleration = np.minimum(max_velocity / PTP_RAMP_TIME, accel)
    q0 = q_start
    if profile in ("scurve", "time_optimal"):
        velocity, acceleration = motion_limits(robot, duration, speed, accel)
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
        return _trapezoid_in(q0, q_goal, duration, accel)
    if duration is None:
        distance = np.abs(q_goal - q0)
        duration = polynomial_duration(distance, max_velocity, max_acceleration, profile)
    if duration == 0.0:  # nothing moves
        return trajectory.trapezoid(q0, q_goal, max_velocity=1.0, max_acceleration=1.0)
    build = trajectory.quintic if profile == "quintic" else trajectory.cubic
    return build(q0, q_goal, duration)


def _trapezoid_in(
    q0: np.ndarray, q_goal: np.ndarray, duration: float, acceleration_limit: np.ndarray
) -> Trajectory:
    """A trapezoid lasting ``duration`` [s]: blends of a third of it (acceleration
    4.5 |Δ|/T²), or each joint at its acceleration limit where that is lower (a longer blend,
    a higher cruise speed)."""
    distance = np.abs(q_goal - q0)
    nominal = distance / (DEFAULT_BLEND_FRACTION * (1.0 - DEFAULT_BLEND_FRACTION) * duration**2)
    if np.all(nominal <= acceleration_limit) or not np.any(distance > 0.0):
        return trajectory.trapezoid(q0, q_goal, duration=duration)
    acceleration = np.where(distance > 0.0, np.minimum(nominal, acceleration_limit), 1.0)
    return trajectory.trapezoid(q0, q_goal, duration=duration, acceleration=acceleration)


def trapezoid_minimum_duration(
    distance: np.ndarray, velocity_limit: np.ndarray, acceleration_limit: np.ndarray
) -> float:
    """Shortest duration [s] of the trapezoid :func:`ptp_trajectory` plans for a given
    duration (blends of a third of it, or at a joint's acceleration limit) within the limits.

    Per joint, with Δ, v and a its move and limits: the third-blend profile's acceleration is
    4.5 Δ/T², at most a from T_c = sqrt(4.5 Δ/a), and its speed 1.5 Δ/T; below T_c the blend
    at a is feasible from the minimum time T_lim = Δ/v + v/a (2 sqrt(Δ/a) when v is not
    reached). So T_min = T_lim where T_lim < T_c, else max(T_c, 1.5 Δ/v).

    Args:
        distance: |Δq| per joint [rad].
        velocity_limit: Per joint [rad/s] (inf: none).
        acceleration_limit: Per joint [rad/s²] (inf: none).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        critical = np.sqrt(distance / (DEFAULT_BLEND_FRACTION * (1 - DEFAULT_BLEND_FRACTION)
                                       * acceleration_limit))  # fmt: skip
        cruise = distance > velocity_limit**2 / acceleration_limit
        fastest = np.where(
            cruise,
            distance / velocity_limit + velocity_limit / acceleration_limit,
            2.0 * np.sqrt(distance / acceleration_limit),
        )
        third = distance / ((1.0 - DEFAULT_BLEND_FRACTION) * velocity_limit)
    fastest = np.nan_to_num(fastest, nan=0.0)
    times = np.where(fastest < critical, fastest, np.maximum(critical, third))
    times = np.where(distance > 0.0, times, 0.0)
    return float(times.max(initial=0.0))


def plan_ptp(
    robot: Robot,
    q_start: np.ndarray,
    q_goal: np.ndarray,
    duration: float | None,
    speed: float | None,
    profile: str,
    acceleration_limit: np.ndarray | None = None,
) -> Trajectory:
    """:func:`ptp_trajectory`, checked over the continuous motion against the position,
    velocity and acceleration limits.

    Raises:
        PtpLimitError: the motion leaves a limit; with a ``duration`` the message states the
            shortest duration that works (rounded up to 4 significant digits and verified).
        KinplanError: an unknown profile or a speed outside (0, 1].
    """
    accel = robot.acceleration_limit if acceleration_limit is None else acceleration_limit

    def build(value: float | None) -> Trajectory:
        return ptp_trajectory(robot, q_start, q_goal, value, speed, profile, accel)

    if profile == "trapezoid" and duration is not None:
        _check_trapezoid_acceleration(robot, q_start, q_goal, duration, accel, build)
    try:
        traj = build(duration)
    except InfeasibleError as exc:
        least = _verified(build, _ptp_estimate(robot, q_start, q_goal, profile, accel, build),
                          robot, accel)  # fmt: skip
        raise PtpLimitError("invalid", _too_short(str(exc), duration, least)) from None
    problem = limit_problem(robot, traj, accel)
    if problem is None:
        return traj
    remedy = "lower the speed (speed:)"
    if problem.status == "joint_limit":
        remedy = "move the target point within the joint limits"
    elif duration is not None:
        estimate = max(duration * problem.scale,
                       _ptp_estimate(robot, q_start, q_goal, profile, accel, build))  # fmt: skip
        least = _verified(build, estimate, robot, accel)
        remedy = _duration_remedy(least)
    raise PtpLimitError(problem.status, f"{problem.text}; {remedy}", problem.speed_ratio)


def _check_trapezoid_acceleration(
    robot: Robot,
    q_start: np.ndarray,
    q_goal: np.ndarray,
    duration: float,
    acceleration_limit: np.ndarray,
    build: Callable[[float | None], Trajectory],
) -> None:
    """Refuse a trapezoid ``duration`` [s] in which a joint cannot make its move even with no
    cruise at all (a triangle needs 4 |Δ|/T²) within its acceleration limit."""
    distance = np.abs(q_goal - q_start)
    need = 4.0 * distance / duration**2
    with np.errstate(invalid="ignore"):
        ratio = np.where(np.isfinite(acceleration_limit), need / acceleration_limit, 0.0)
    if ratio.max(initial=0.0) <= 1.0 + LIMIT_TOLERANCE:
        return
    j = int(np.argmax(ratio))
    estimate = _ptp_estimate(robot, q_start, q_goal, "trapezoid", acceleration_limit, build)
    least = _verified(build, estimate, robot, acceleration_limit)
    raise PtpLimitError(
        "acceleration_limit",
        f"acceleration_limit: joint {j} ({robot.joint_names[j]}) would need at least "
        f"{need[j]:.4g} rad/s² (4 |Δq|/T² for {distance[j]:.4g} rad in {duration:g} s), above "
        f"its limit {acceleration_limit[j]:.4g} rad/s²; {_duration_remedy(least)}",
    )


def _duration_remedy(least: float | None) -> str:
    if least is None:
        return "give a longer duration, or no duration (minimum time)"
    return f"give a duration of at least {least:g} s, or no duration (minimum time)"


def _too_short(message: str, duration: float | None, least: float | None) -> str:
    """The refusal of a duration a limit-timed profile cannot meet, with a verified minimum."""
    head = message.split(";")[0]
    if not head.startswith("duration "):
        head = f"duration {duration:g} s is too short: {head}"
    return f"invalid: {head}; {_duration_remedy(least)}"


def _ptp_estimate(
    robot: Robot,
    q_start: np.ndarray,
    q_goal: np.ndarray,
    profile: str,
    acceleration_limit: np.ndarray,
    build: Callable[[float | None], Trajectory],
) -> float:
    """Shortest duration [s] of a ptp with a given duration, within the full limits."""
    distance = np.abs(q_goal - q_start)
    velocity, acceleration = motion_limits(robot, 1.0, None, acceleration_limit)
    if profile in ("quintic", "cubic"):
        vlimit = robot.velocity_limit
        return polynomial_duration(distance, vlimit, acceleration_limit, profile)
    if profile == "trapezoid":
        return trapezoid_minimum_duration(distance, robot.velocity_limit, acceleration_limit)
    try:  # scurve, time_optimal: their own minimum time within the full limits
        if profile == "scurve":
            fastest = trajectory.scurve(
                q_start, q_goal, velocity, acceleration, acceleration / PTP_JERK_TIME
            )
        else:
            fastest = trajectory.time_optimal([q_start, q_goal], velocity, acceleration)
    except KinplanError:
        return float("nan")
    return fastest.duration


def motion_limits(
    robot: Robot,
    duration: float | None,
    speed: float | None,
    acceleration_limit: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration limits of a ptp timed by the robot's limits (``scurve``,
    ``time_optimal``, ``spline``): ``speed`` × the limits (all of them when a duration is
    given), the trapezoid's ramp time where no acceleration is limited.

    Args:
        robot: The arm.
        duration: The move's duration [s] or None.
        speed: Share of the limits in (0, 1], or None for the default.
        acceleration_limit: Acceleration limits [rad/s²], inf where none; default the
            robot's.

    Returns:
        (velocity [rad/s], acceleration [rad/s²]), each shape (nq,).
    """
    limit = robot.velocity_limit
    limit = np.where(np.isfinite(limit), limit, FALLBACK_JOINT_SPEED)
    share = DEFAULT_PTP_SPEED if speed is None else float(speed)
    share = 1.0 if duration is not None else share
    velocity = limit * share
    known = robot.acceleration_limit if acceleration_limit is None else acceleration_limit
    acceleration = np.where(np.isfinite(known), known * share, velocity / PTP_RAMP_TIME)
    return velocity, acceleration


def ptp_through_trajectory(
    robot: Robot,
    points: np.ndarray,
    duration: float | None,
    speed: float | None,
    profile: str,
    blend: float = 0.0,
    times: Sequence[float] | None = None,
    acceleration_limit: np.ndarray | None = None,
) -> Trajectory:
    """The joint trajectory of a ``ptp`` through several points, one motion rest to rest (not
    checked against the limits: see :func:`plan_ptp_through`).

    Args:
        robot: The arm.
        points: The start configuration then the points to pass [rad], shape (m, nq).
        duration: Duration [s], or None for the minimum time within the scaled limits.
        speed: Share of the joint velocity and acceleration limits in (0, 1], or None for
            :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
        profile: ``time_optimal`` (:func:`kinplan.trajectory.time_optimal`, corners within
            ``blend``) or ``spline`` (:func:`kinplan.trajectory.spline`).
        blend: Largest deviation from a corner [rad] (``time_optimal``).
        times: ``spline``: the times [s] at which it passes ``points[1:]`` (the clamped cubic
            spline through them, :func:`kinplan.trajectory.cubic_via`); None: chord-length
            knot times, timed by the limits.
        acceleration_limit: Joint acceleration limits [rad/s²], inf where none; default the
            robot's.

    Raises:
        InfeasibleError: a ``duration`` shorter than the limits allow.
        KinplanError: an unknown profile, a speed outside (0, 1], or a blend with ``spline``.
    """
    if speed is not None and not (0 < speed <= 1):
        raise KinplanError(f"ptp speed is a share of the joint limits in (0, 1], got {speed}")
    velocity, acceleration = motion_limits(robot, duration, speed, acceleration_limit)
    if profile == "time_optimal":
        if times is not None:
            raise KinplanError("times go with profile spline")
        return trajectory.time_optimal(points, velocity, acceleration, blend, duration)
    if profile == "spline":
        if blend:
            raise KinplanError("a spline passes through its points: blend goes with time_optimal")
        if times is not None:
            if len(times) != len(points) - 1:
                raise KinplanError(
                    f"expected {len(points) - 1} times, one per point, got {len(times)}"
                )
            return trajectory.cubic_via(points, [0.0, *times])
        return trajectory.spline(points, velocity, acceleration, duration)
    if times is not None:
        raise KinplanError("times go with profile spline")
    raise KinplanError(
        f"a ptp through several points is time_optimal or spline, got profile {profile!r}"
    )


def plan_ptp_through(
    robot: Robot,
    points: np.ndarray,
    duration: float | None,
    speed: float | None,
    profile: str,
    blend: float = 0.0,
    times: Sequence[float] | None = None,
    acceleration_limit: np.ndarray | None = None,
) -> Trajectory:
    """:func:`ptp_through_trajectory`, checked over the continuous motion against the
    position, velocity and acceleration limits.

    Raises:
        PtpLimitError: the motion leaves a limit: a spline that overshoots a joint limit
            between its points (the remedy: ``profile: time_optimal``, straight lines between
            the points), or a ``duration`` / ``times`` too short (the message states the
            shortest duration or the scaled times that work, rounded up and verified).
        KinplanError: as :func:`ptp_through_trajectory`.
    """
    accel = robot.acceleration_limit if acceleration_limit is None else acceleration_limit

    def build(value: float | None) -> Trajectory:
        return ptp_through_trajectory(robot, points, value, speed, profile, blend, None, accel)

    def estimate() -> float:
        velocity, acceleration = motion_limits(robot, 1.0, None, accel)
        try:
            if profile == "spline":
                return trajectory.spline(points, velocity, acceleration).duration
            return trajectory.time_optimal(points, velocity, acceleration, blend).duration
        except KinplanError:
            return float("nan")

    try:
        if times is not None:
            traj = ptp_through_trajectory(robot, points, None, speed, profile, blend, times, accel)
        else:
            traj = build(duration)
    except InfeasibleError as exc:
        least = _verified(build, estimate(), robot, accel)
        raise PtpLimitError("invalid", _too_short(str(exc), duration, least)) from None
    problem = limit_problem(robot, traj, accel)
    if problem is None:
        return traj
    if problem.status == "joint_limit":
        remedy = "move the points within the joint limits"
        if profile == "spline":
            remedy = (
                "the spline overshoots between its points: use profile: time_optimal (straight "
                "lines between the points; without times:), or add a point where it overshoots"
            )
        raise PtpLimitError(problem.status, f"{problem.text}; {remedy}", problem.speed_ratio)
    if times is not None:
        remedy = _times_remedy(robot, points, list(times), problem.scale, accel)
    elif duration is not None:
        least = _verified(build, max(duration * problem.scale, estimate()), robot, accel)
        remedy = _duration_remedy(least)
    else:
        remedy = "lower the speed (speed:)"
    raise PtpLimitError(problem.status, f"{problem.text}; {remedy}", problem.speed_ratio)


def _times_remedy(
    robot: Robot,
    points: np.ndarray,
    times: list[float],
    scale: float,
    acceleration_limit: np.ndarray,
) -> str:
    """The spline's ``times:`` scaled by the smallest factor that keeps it within the limits,
    each time rounded up and the result verified."""
    base = np.array(times)
    factor = round_up(scale, _REMEDY_DIGITS)
    step = 1e-4
    for _ in range(40):
        scaled = [round_up(float(t), _REMEDY_DIGITS) for t in base * factor]
        if all(b > a for a, b in zip([0.0, *scaled], scaled, strict=False)):
            try:
                traj = trajectory.cubic_via(points, [0.0, *scaled])
                if limit_problem(robot, traj, acceleration_limit) is None:
                    text = ", ".join(f"{t:g}" for t in scaled)
                    return f"slow it down by a factor of at least {factor:g}: times: [{text}]"
            except KinplanError:
                pass
        factor = round_up(factor * (1.0 + step), _REMEDY_DIGITS)
        step *= 2.0
    return "give later times"


def polynomial_duration(
    distance: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray, profile: str
) -> float:
    """Shortest duration of a rest-to-rest cubic/quintic within the speed and acceleration
    limits: peak speed k_v Δ/T, peak acceleration k_a Δ/T² (exact peaks of the polynomial).

    Args:
        distance: |Δq| per joint [rad].
        max_velocity: Speed limit per joint [rad/s] (inf: none).
        max_acceleration: Acceleration limit per joint [rad/s²] (inf: none).
        profile: ``cubic`` or ``quintic``.

    Returns:
        The duration [s] (0 when nothing moves).
    """
    k_v, k_a = REST_TO_REST_PEAKS[profile]
    times = np.maximum(k_v * distance / max_velocity, np.sqrt(k_a * distance / max_acceleration))
    return float(times.max(initial=0.0))


def peak_speed_ratio(robot: Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> float:
    """Largest joint speed over its limit: the rates at the samples and the mean speeds
    between them (:func:`kinplan.sampling.joint_speeds`).

    Args:
        robot: The arm (its velocity limits; joints without one are left out).
        t: Sample times [s], shape (N,).
        q: Joint positions [rad], shape (N, nq).
        qd: Joint velocities [rad/s], shape (N, nq).

    Returns:
        The ratio [-] (0 without samples or limits).
    """
    if qd.size == 0:
        return 0.0
    limit = robot.velocity_limit
    finite = np.isfinite(limit)
    if not finite.any():
        return 0.0
    speeds = joint_speeds(q, qd, t)
    return float(np.max(speeds[:, finite] / limit[finite]))
