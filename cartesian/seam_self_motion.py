"""Following a seam with a redundant arm's self-motion as the seam search chose it.

:func:`cartesian.follow` resolves a 7-joint arm's redundancy its own way (minimum-norm joint
rates from its start), so the self-motion the ladder of :func:`cartesian.plan_seam` chose is
lost, and a seam the search found can reach a joint limit when followed. :func:`track` follows
the search's configurations instead, as a secondary task in the null space of the tool's:

    dq/ds = J⁺ x'(s) + n nᵀ (q*'(s) + κ (q*(s) − q))

with x' the path's twist per unit fraction s, J the tool Jacobian (6 × 7), n the unit vector of
its null space and q*(s) the cubic spline [rad] through the ladder's configurations at its
waypoints: the tool follows the path exactly, and the self-motion (the one direction the tool
does not see) is pulled toward the chosen configurations with gain κ [per unit s]. The law is a
geometric path q(s), integrated along the samples' fractions (the trapezoid rule: Heun's
predictor, two corrector steps), each sample put
back on the path by the follower's Newton steps (minimum-norm corrections, which leave the
self-motion alone to first order); then q̇ = (dq/ds) ṡ and q̈ = (d²q/ds²) ṡ² + (dq/ds) s̈, the
second derivative by differences of dq/ds along s.

The result is monitored as :func:`cartesian.follow`'s clean paths are (:mod:`cartesian.
batch_track`'s checks): joint limits, singularity (the arm's manipulability, follow's
threshold), the steps between samples explained by the rates (q̇ = dq/dt), joint speeds and
accelerations, the work cell; then the motion between the samples (:func:`cartesian.between.
check_between`). It answers only for clean seams: anything flagged gives None, and the caller
follows the seam with :func:`cartesian.follow` (whose refusal then says why). Frames: the
robot's base (world) frame; units m, rad, s.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.interpolate import make_interp_spline  # type: ignore[import-untyped]

from cartesian.batch_track import (
    JUMP_SHARE,
    cell_check,
    regular,
    speed_peak,
    within_accelerations,
    within_limits,
)
from cartesian.between import check_between
from cartesian.events import Status
from cartesian.paths import Path
from cartesian.plan import CartesianPlan
from cartesian.timing import time_path
from cartesian.tracker import SINGULAR_FRACTION, Tracker, path_targets
from kinplan import checks
from kinplan.cell import WorkCell
from kinplan.model.robot import Robot, manipulability_of
from kinplan.trajectory._profiles import PROFILES
from kinplan.trajectory.sampling import MIN_INTERVALS

__all__ = ["SUPPORTED_OPTIONS", "track", "tracks_self_motion"]

#: Options of :func:`cartesian.follow` this tracker honours (any other: the caller follows).
SUPPORTED_OPTIONS = frozenset(
    ("profile", "acceleration", "singular_threshold", "velocity_scale", "jump_tolerance",
     "tolerance", "rotation_tolerance", "max_acceleration", "interpolation_tolerance",
     "whole_periods")
)  # fmt: skip
#: Gain κ of the pull toward the chosen configurations, per waypoint interval: the self-motion
#: closes the gap by e^−GAIN over one interval between waypoints.
GAIN = 3.0
#: Corrector steps of the trapezoid rule per sample (the steps between samples then match the
#: rates at their ends: q̇ = dq/dt).
CORRECTIONS = 2


def tracks_self_motion(robot: Robot) -> bool:
    """Whether :func:`track` follows ``robot``'s self-motion: an arm of 7 revolute joints with
    a 6-D tool task (one redundant direction)."""
    return robot.nq == 7 and not robot.prismatic.any() and robot.task_rank(False) == 6


def track(
    robot: Robot,
    path: Path,
    waypoints: np.ndarray,
    chosen: np.ndarray,
    q_start: np.ndarray,
    speed: float | None,
    duration: float | None,
    dt: float,
    cell: WorkCell | None,
    clearance: float | None,
    follow_options: dict[str, Any],
) -> CartesianPlan | None:
    """The ok plan of ``path`` with the self-motion pulled toward ``chosen``, or None (see the
    module docstring).

    Args:
        robot: A 7-joint arm (:func:`tracks_self_motion`).
        path: The oriented path (the rotated seam), world frame.
        waypoints: Fractions s of the chosen configurations (K,), 0 to 1, increasing.
        chosen: The configurations [rad] (K, 7) the search chose there (continuous).
        q_start: The configuration [rad] the plan starts from (put on the path's start).
        speed, duration, dt, cell, clearance: As :func:`cartesian.follow`'s.
        follow_options: The other options of :func:`cartesian.follow` (checked as it checks
            them); with one not in :data:`SUPPORTED_OPTIONS` the answer is None.
    """
    if not tracks_self_motion(robot) or not set(follow_options) <= SUPPORTED_OPTIONS:
        return None
    tracker, options = _tracker(robot, cell, clearance, follow_options)
    timing = time_path(path.length, duration, speed, options["acceleration"], options["profile"],
                       dt)  # fmt: skip
    if options["whole_periods"]:  # at rest at the end until a whole number of periods
        timing = timing.on_whole_periods(dt)
    s, sd, sdd = timing.s, timing.sd, timing.sdd
    if len(timing.t) - 1 < MIN_INTERVALS or not np.all(np.diff(s) > 0.0):
        return None  # follow checks a short motion on a finer grid; a pause has no dq/ds
    targets = path_targets(path, s, False, tracker.rows)
    assert targets.rotations is not None  # an oriented path
    spline = make_interp_spline(waypoints, chosen, k=min(3, len(waypoints) - 1))
    wanted, wanted_rate = spline(s), spline(s, 1)
    gain = min(GAIN * (len(waypoints) - 1), 1.0 / max(float(np.diff(s).max()), 1e-12))
    geometry = _integrate(tracker, targets, s, wanted, wanted_rate, gain, q_start)
    if geometry is None:
        return None
    q, dq_ds, J = geometry
    if not within_limits(tracker, q):
        return None
    manipulability = np.asarray(manipulability_of(J, 6), dtype=float)
    if not regular(tracker, manipulability):
        return None
    qd = dq_ds * sd[:, None]
    d2q_ds2 = np.gradient(dq_ds, s, axis=0)
    qdd = d2q_ds2 * (sd**2)[:, None] + dq_ds * sdd[:, None]
    if not _explained(tracker, timing.t, q, qd):
        return None
    peak = speed_peak(tracker, timing.t, q, qd)
    if peak is None or not within_accelerations(tracker, qdd):
        return None
    free, check = cell_check(tracker, q)
    if not free:
        return None
    tool = robot.tool_positions(q)
    deviation = np.linalg.norm(tool - targets.positions, axis=1)
    plan = CartesianPlan(
        t=timing.t.copy(), q=q, qd=qd, qdd=qdd, s=s.copy(), ok=True, status=Status.OK,
        fraction=1.0, events=[], max_deviation=float(deviation.max()),
        min_manipulability=float(manipulability.min()), duration=float(timing.duration),
        path=path, position_only=False, singular_threshold=float(tracker.singular_threshold),
        tool_positions=tool, manipulability=manipulability, peak_speed_ratio=peak,
        peak_acceleration_ratio=float(
            (np.abs(qdd) / tracker.acceleration_limit).max(initial=0.0)
        ),
        robot=robot, cell=tracker.cell, cell_check=check,
        min_clearance=np.inf if check is None else float(check.min_obstacle_clearance),
        min_self_clearance=np.inf if check is None else float(check.min_self_clearance),
    )  # fmt: skip
    plan.check_step = float(np.diff(timing.t).max(initial=0.0))
    plan.interpolation_tolerance = options["interpolation_tolerance"]
    plan.accelerations_limited = bool(np.isfinite(tracker.acceleration_limit).all())
    check_between(tracker, plan, timing)
    return plan if plan.ok else None


def _integrate(
    tracker: Tracker,
    targets: Any,
    s: np.ndarray,
    wanted: np.ndarray,
    wanted_rate: np.ndarray,
    gain: float,
    q_start: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """q(s) (N, 7) [rad], dq/ds (N, 7) and the Jacobians (N, 6, 7) along the samples (module
    docstring), or None when Newton steps do not put a sample on the path."""
    positions, rotations, rate = targets.positions, targets.rotations, targets.rate
    count = len(s)
    q_out, dq_out, J_out = np.empty((count, 7)), np.empty((count, 7)), np.empty((count, 6, 7))

    def slope(q: np.ndarray, J: np.ndarray, k: int) -> np.ndarray:
        """dq/ds at sample k's fraction from q (its Jacobian J)."""
        task = J.T @ np.linalg.solve(J @ J.T, rate[k])
        null = np.linalg.svd(J)[2][-1]  # the unit vector of J's null space
        pull = wanted_rate[k] + gain * (wanted[k] - q)
        return task + null * float(null @ pull)

    def on_path(guess: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray] | None:
        q, ok, *_, evaluation = tracker.solve(guess, positions[k], rotations[k])
        return (q, np.asarray(evaluation.jacobian)) if ok else None

    found = on_path(q_start, 0)
    if found is None:
        return None
    q, J = found
    step = slope(q, J, 0)
    q_out[0], dq_out[0], J_out[0] = q, step, J
    for k in range(1, count):
        ds = float(s[k] - s[k - 1])
        predicted = q + ds * step
        J_predicted = tracker.robot.jacobian(predicted)
        end = slope(predicted, J_predicted, k)
        for _ in range(CORRECTIONS):  # the trapezoid rule, solved by fixed-point steps
            found = on_path(q + 0.5 * ds * (step + end), k)
            if found is None:
                return None
            end = slope(*found, k)
        q, J = found
        step = end
        q_out[k], dq_out[k], J_out[k] = q, step, J
    return q_out, dq_out, J_out


def _tracker(
    robot: Robot, cell: WorkCell | None, clearance: float | None, options: dict[str, Any]
) -> tuple[Tracker, dict[str, Any]]:
    """The tracker :func:`cartesian.follow` would build with these options (checked as it
    checks them), and the options with their defaults."""
    get = options.get
    profile = checks.choice(get("profile", "trapezoid"), "profile", PROFILES)
    acceleration = checks.optional_number(
        get("acceleration"), "acceleration", positive=True, unit="m/s²"
    )
    tolerance = checks.number(get("tolerance", 1e-7), "tolerance", positive=True, unit="m")
    rotation_tolerance = checks.number(
        get("rotation_tolerance", 1e-7), "rotation_tolerance", positive=True, unit="rad"
    )
    velocity_scale = checks.number(get("velocity_scale", 1.0), "velocity_scale", positive=True)
    jump_tolerance = checks.number(
        get("jump_tolerance", 0.05), "jump_tolerance", positive=True, unit="rad"
    )
    threshold = get("singular_threshold")
    if threshold is None:
        threshold = SINGULAR_FRACTION * robot.reference_manipulability(False)
    threshold = checks.number(threshold, "singular_threshold", minimum=0.0)
    accel_limit = robot.acceleration_limit
    limit = get("max_acceleration")
    if limit is not None:
        if np.ndim(limit) == 0:
            accel_limit = np.full(robot.nq, checks.number(limit, "max_acceleration", positive=True))
        else:
            accel_limit = checks.vector(limit, "max_acceleration", robot.nq)
    tracker = Tracker(
        robot, False, tolerance, rotation_tolerance, threshold, velocity_scale, jump_tolerance,
        accel_limit,
    )  # fmt: skip
    if cell is not None and cell.robot is not robot:
        cell = cell.for_robot(robot)
    tracker.cell = cell
    tracker.clearance = 0.0 if clearance is None else float(clearance)
    interpolation = checks.number(
        get("interpolation_tolerance", 1e-4), "interpolation_tolerance", positive=True, unit="m"
    )
    whole = checks.flag(get("whole_periods", False), "whole_periods")
    return tracker, {
        "profile": profile, "acceleration": acceleration, "interpolation_tolerance": interpolation,
        "whole_periods": whole,
    }  # fmt: skip


def _explained(tracker: Tracker, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> bool:
    """Whether every joint step between samples is explained by the rates at its ends (the
    follower's jump test, within :data:`~cartesian.batch_track.JUMP_SHARE` of its tolerance):
    q̇ = dq/dt along the samples."""
    if len(t) < 2:
        return True
    h = np.diff(t)[:, None]
    unexplained = np.abs(np.diff(q, axis=0) - 0.5 * h * (qd[1:] + qd[:-1]))
    return bool(unexplained.max() <= JUMP_SHARE * tracker.jump_tolerance and math.isfinite(
        float(unexplained.max())))  # fmt: skip
