"""The limit check every export runs: :func:`check_limits` and :class:`LimitViolationError`.

Every export that writes a motion first checks the continuous motion it stands for
(:mod:`kinplan.export.continuous`) against the robot's limits, whatever built the motion:
positions, velocities and the accelerations the robot declares, at the samples and between
them. A motion beyond a limit is refused with a :class:`LimitViolationError` naming the joint,
the time, the value, the limit and how much slower the motion must be.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from kinplan import checks
from kinplan.errors import InputError
from kinplan.export.common import motion_samples
from kinplan.export.continuous import continuous_motion
from kinplan.trajectory.motion import SampledMotion

__all__ = [
    "CHECK_SUBDIVISIONS",
    "POSITION_SLACK",
    "RATE_SLACK",
    "LimitViolationError",
    "check_limits",
]


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
    t, q, qd, qdd = motion_samples(plan, what)
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
    motion = continuous_motion(plan, t, q, qd, qdd, between)
    yield t - t[0], q, qd, qdd
    if len(t) < 2:
        return
    u = np.arange(1, CHECK_SUBDIVISIONS) / CHECK_SUBDIVISIONS  # inside the intervals
    chunk = max(1, 100_000 // len(u))
    for start in range(0, len(t) - 1, chunk):
        left, right = t[start : start + chunk + 1][:-1], t[start + 1 : start + chunk + 1]
        times = (left[:, None] + (right - left)[:, None] * u[None, :]).reshape(-1) - t[0]
        yield (times, *motion(times))


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
