"""The motion between the samples of a plan: what a controller runs, checked.

The samples of a plan are its caller's grid; between them viewers, :meth:`ProgramPlan.sample`
and the exports play the quintic Hermite interpolant through (q, q̇, q̈)
(:func:`kinplan.sampling.hermite_between`). :func:`check_between` holds it to the joint limits,
speed limits and (where limited) acceleration limits, its tool to the path, and the rates to the
steps; it refuses an ``ok`` plan whose motion between the samples breaks one of them: as the
limit it breaks where the interpolant stays on the path (the peak fell between samples), as
"sampling" where the period is too coarse for the motion.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from cartesian.events import Event, Status
from cartesian.plan import CartesianPlan
from cartesian.timing import PathTiming
from cartesian.tracker import Tracker
from kinplan.model.robot import Robot
from kinplan.trajectory._profiles import round_up
from kinplan.trajectory.sampling import MIN_INTERVALS, hermite_between, hermite_peaks

__all__ = ["CHORD_SHARE", "ROTATION_LEVER", "check_between"]


#: Where, inside every interval between two samples, the interpolant's tool pose is compared
#: with the path (fractions of the interval; one forward kinematics each).
POSE_FRACTIONS = np.array([0.25, 0.5, 0.75])
#: Largest difference between a joint's mean speed over an interval and what its rates at the
#: ends explain, as a share of the joint's top speed in the plan (plus :data:`RATE_FLOOR`).
RATE_CONSISTENCY = 0.05
#: Speed [rad/s or m/s] added to a joint's top speed for :data:`RATE_CONSISTENCY` (a joint at
#: rest is not held to a share of zero).
RATE_FLOOR = 1e-3
#: Lever [m] that turns the interpolation tolerance into a rotation tolerance (rad): the
#: same displacement at a point this far from the tool frame.
ROTATION_LEVER = 0.1


def check_between(tracker: Tracker, plan: CartesianPlan, timing: PathTiming) -> None:
    """Check the motion between the samples of an ok ``plan``: its quintic Hermite interpolant
    (what viewers, :meth:`ProgramPlan.sample` and the exports play) within the joint limits,
    speed limits and (where limited) acceleration limits at its exact extremes in every
    interval, and its tool near the path at :data:`POSE_FRACTIONS` of the interval.

    Where the interpolant stays on the path, it is the motion: a speed or acceleration above
    its limit there is a "velocity_limit" or "acceleration_limit" event like one at a sample
    (the peak fell between samples). Where it leaves the path, the period is too coarse for the
    motion: a "sampling" event (:func:`follow` then offers a period that works). Sets
    :attr:`CartesianPlan.max_interpolation_deviation` and raises
    :attr:`CartesianPlan.peak_speed_ratio` to the interpolant's peak."""
    if len(plan.t) < 2:
        return
    robot = tracker.robot
    times, q, _, _ = hermite_between(plan.t, plan.q, plan.qd, plan.qdd, POSE_FRACTIONS)
    intervals = len(plan.t) - 1
    # the tool against the path at the same times
    s, _, _ = timing.law(times.ravel())
    s = np.clip(s, 0.0, 1.0)
    rows = q.reshape(-1, robot.nq)
    positions, rotations = _tool_poses(robot, rows, not tracker.position_only)
    distance = np.linalg.norm(positions - plan.path.position(s), axis=1)
    if rotations is not None:
        targets = plan.path.rotation(s)
        assert targets is not None  # a pose task follows an oriented path
        distance = np.maximum(distance, ROTATION_LEVER * _rotation_angles(rotations, targets))
    distance = distance.reshape(intervals, len(POSE_FRACTIONS)).max(axis=1)
    plan.max_interpolation_deviation = float(distance.max())
    allowed = np.maximum(plan.interpolation_tolerance, CHORD_SHARE * _chords(plan))
    off_path = distance > allowed

    events: list[tuple[int, Event]] = []

    def add(k: int, kind: str, what: str, value: float | None, limit: float | None,
            joint: str | None, remedy: str) -> None:  # fmt: skip
        if off_path[k]:
            kind, remedy = Status.SAMPLING, "sample more finely"
            what += (
                f", leaving the path by {1e3 * distance[k]:.3g} mm (it may by "
                f"{1e3 * allowed[k]:.3g} mm there: the interpolation tolerance, or "
                f"{100 * CHORD_SHARE:g} % of the tool's travel between the samples): the "
                "sampling period is too coarse for the motion"
            )
        message = (
            f"between samples {k} and {k + 1} (t = {plan.t[k]:.4f}–{plan.t[k + 1]:.4f} s) the "
            f"motion interpolated through the samples {what}"
        )
        position = plan.path.position(plan.s[k + 1 : k + 2])[0]
        events.append((k, Event(
            kind, float(plan.t[k + 1]), float(plan.s[k + 1]), k + 1, message, position,
            joint, value, limit, remedy=remedy,
        )))  # fmt: skip

    # the limits against the interpolant's exact extremes in every interval (not only where it
    # was sampled): lowest and highest q, largest |q̇| and |q̈| (kinplan.sampling.hermite_peaks)
    limits = (robot.lower, robot.upper, tracker.speed_limit, tracker.acceleration_limit)
    lowest, highest, fastest, hardest = hermite_peaks(plan.t, plan.q, plan.qd, plan.qdd, limits)
    q, qd, qdd = np.stack([lowest, highest], axis=1), fastest[:, None], hardest[:, None]
    below, above = (robot.lower - q) > 1e-9, (q - robot.upper) > 1e-9
    beyond = (below | above).any(axis=2)
    if beyond.any():
        k, f = (int(x) for x in np.argwhere(beyond)[0])
        j = int(np.argmax(np.maximum(robot.lower - q[k, f], q[k, f] - robot.upper)))
        side = "lower" if below[k, f, j] else "upper"
        bound = float(robot.lower[j] if side == "lower" else robot.upper[j])
        add(
            k, Status.JOINT_LIMIT, f"takes joint {robot.joint_names[j]} to "
            f"{q[k, f, j]:.6g} {tracker.units[j]}, beyond its {side} limit {bound:.6g}",
            float(q[k, f, j]), bound, robot.joint_names[j],
            "keep the path away from the joint limits, or start from another configuration "
            "(q_seed)",
        )  # fmt: skip
    speed = np.abs(qd) / tracker.speed_limit
    peak = max(plan.peak_speed_ratio, float(speed.max(initial=0.0)))
    plan.peak_speed_ratio = peak
    fast = (speed > 1.0 + 1e-9).any(axis=2)
    if fast.any():
        k = int(np.argwhere(fast)[0][0])
        j = int(np.argmax(speed[k].max(axis=0)))
        limit = float(tracker.speed_limit[j])
        add(
            k, Status.VELOCITY_LIMIT, f"moves joint {robot.joint_names[j]} at "
            f"{speed[k, :, j].max() * limit:.4g} {tracker.units[j]}/s, above its limit "
            f"{limit:.4g} {tracker.units[j]}/s (the motion needs up to {peak:.4g}× the joint "
            "speed limits)", float(speed[k, :, j].max() * limit), limit,
            robot.joint_names[j], f"slow the tool down by a factor of at least "
            f"{round_up(peak, 3):g} (a lower speed or a longer duration)",
        )  # fmt: skip
    limited = np.isfinite(tracker.acceleration_limit)
    if limited.any():
        accel = np.abs(qdd[:, :, limited]) / tracker.acceleration_limit[limited]
        plan.peak_acceleration_ratio = max(plan.peak_acceleration_ratio, float(accel.max()))
        hard = (accel > 1.0 + 1e-9).any(axis=2)
        if hard.any():
            k = int(np.argwhere(hard)[0][0])
            j = int(np.flatnonzero(limited)[np.argmax(accel[k].max(axis=0))])
            worst = float(accel.max())
            plan.peak_acceleration_ratio = max(plan.peak_acceleration_ratio, worst)
            limit = float(tracker.acceleration_limit[j])
            value = float(np.abs(qdd[k, :, j]).max())
            add(
                k, Status.ACCELERATION_LIMIT, f"accelerates joint {robot.joint_names[j]} at "
                f"{value:.4g} {tracker.units[j]}/s², above its limit {limit:.4g} "
                f"{tracker.units[j]}/s²", value, limit,
                robot.joint_names[j], f"slow the tool down by a factor of at least "
                f"{round_up(math.sqrt(worst), 3):g} (a lower speed or a longer duration)",
            )  # fmt: skip
    # the rates at the samples explain the step between them (the mean speed over an interval
    # is the mean of the rates, with the Hermite quadrature's correction h (q̈0 − q̈1) / 12):
    # where they do not, the motion between the samples is not the one the rates describe
    # (on a grid that resolves the motion: with fewer than MIN_INTERVALS intervals the samples
    # are waypoints of a coarse motion, held to the path by the interpolant instead)
    h = np.diff(plan.t)[:, None]
    mean = np.diff(plan.q, axis=0) / h
    rates = 0.5 * (plan.qd[1:] + plan.qd[:-1]) + h * (plan.qdd[:-1] - plan.qdd[1:]) / 12.0
    scale = np.maximum(np.abs(plan.qd).max(axis=0), np.abs(mean).max(axis=0)) + RATE_FLOOR
    mismatch = np.abs(mean - rates) / scale
    if intervals < MIN_INTERVALS:
        mismatch[:] = 0.0
    unexplained = np.flatnonzero((mismatch > RATE_CONSISTENCY).any(axis=1))
    if unexplained.size:
        k = int(unexplained[0])
        j = int(np.argmax(mismatch[k]))
        events.append((k, Event(
            Status.SAMPLING, float(plan.t[k + 1]), float(plan.s[k + 1]), k + 1,
            f"between samples {k} and {k + 1} (t = {plan.t[k]:.4f}–{plan.t[k + 1]:.4f} s) joint "
            f"{robot.joint_names[j]} moves at a mean {mean[k, j]:.4g} {tracker.units[j]}/s, "
            f"which its rates at the samples ({plan.qd[k, j]:.4g}, {plan.qd[k + 1, j]:.4g}) do "
            f"not explain (off by {100 * mismatch[k, j]:.3g} % of its top speed): the sampling "
            "period is too coarse for the motion",
            plan.path.position(plan.s[k + 1 : k + 2])[0], robot.joint_names[j],
            remedy="sample more finely",
        )))  # fmt: skip
    off = np.flatnonzero(off_path)
    if off.size:
        k = int(off[0])
        events.append((k, Event(
            Status.SAMPLING, float(plan.t[k + 1]), float(plan.s[k + 1]), k + 1,
            f"between samples {k} and {k + 1} (t = {plan.t[k]:.4f}–{plan.t[k + 1]:.4f} s) the "
            f"motion interpolated through the samples leaves the path by "
            f"{1e3 * distance[k]:.3g} mm (it may by {1e3 * allowed[k]:.3g} mm there: the "
            f"interpolation tolerance, or {100 * CHORD_SHARE:g} % of the tool's travel between "
            "the samples): the sampling period is too coarse for the motion",
            plan.path.position(plan.s[k + 1 : k + 2])[0], remedy="sample more finely",
        )))  # fmt: skip
    if not events:
        return
    k, event = min(events, key=lambda item: item[0])
    keep = k + 1
    plan.ok, plan.status, plan.events = False, event.kind, [event]
    plan.t, plan.q, plan.qd, plan.qdd = (
        plan.t[:keep],
        plan.q[:keep],
        plan.qd[:keep],
        plan.qdd[:keep],
    )
    plan.s, plan.tool_positions = plan.s[:keep], plan.tool_positions[:keep]
    plan.manipulability = plan.manipulability[:keep]
    plan.fraction = float(plan.s[-1])


#: Share of the tool's travel between two samples it may leave the path by between them (a
#: coarse grid asks for a coarse motion), when that is more than the interpolation tolerance.
CHORD_SHARE = 0.01


def _chords(plan: CartesianPlan) -> np.ndarray:
    """The tool's travel [m] over each interval between samples (N−1,): the larger of the
    straight distances of the interval and its neighbours (a sample at rest is no measure)."""
    chord = np.linalg.norm(np.diff(plan.tool_positions, axis=0), axis=1)
    wider = chord.copy()
    wider[1:] = np.maximum(wider[1:], chord[:-1])
    wider[:-1] = np.maximum(wider[:-1], chord[1:])
    return wider


def _tool_poses(
    robot: Robot, rows: np.ndarray, with_rotation: bool
) -> tuple[np.ndarray, np.ndarray | None]:
    """Tool positions (N, 3) [m] and, when asked, rotations (N, 3, 3) of joint ``rows``: all at
    once by the robot's batch kinematics (:class:`kinplan.batch_ik.BatchKinematics`, checked
    against Pinocchio when built) where it has them, else one Pinocchio pass per row."""
    kinematics = robot.batch_solver.kinematics
    if kinematics is not None:
        positions, rotations = kinematics.fk(rows)
        return positions, rotations if with_rotation else None
    model, data, tip = robot.model, robot.data, robot.tip_id
    positions = np.empty((len(rows), 3))
    rotation_rows = np.empty((len(rows), 3, 3)) if with_rotation else None
    for k, row in enumerate(rows):
        pin.forwardKinematics(model, data, row)
        placement = pin.updateFramePlacement(model, data, tip)
        positions[k] = placement.translation
        if rotation_rows is not None:
            rotation_rows[k] = placement.rotation
    return positions, rotation_rows


def _rotation_angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles [rad] of the rotations a_k b_kᵀ (N,), from their traces (to ~1e-8 rad)."""
    cosine = 0.5 * (np.einsum("kij,kij->k", a, b) - 1.0)
    return np.arccos(np.clip(cosine, -1.0, 1.0))
