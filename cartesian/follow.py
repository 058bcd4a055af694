"""Following a Cartesian path: IK at every sample, with reachability and singularity monitoring.

:func:`follow` times the path with a 1-D profile, solves IK at every sample warm-started from the
previous one (so the arm stays on its branch), derives joint velocities and accelerations from the
timed path (q̇ = J⁺ẋ, q̈ = dq̇/dt = J⁺(ẍ − J̇q̇) plus, for a redundant arm, the null-space part
of the derivative of its minimum-norm q̇), and stops at the first sample that is unreachable,
beyond a joint limit, needs a branch flip ("jump"), is near a singularity or too fast for a
joint. The plan says where and why (:class:`Event`) and how much of the path was achieved.
The samples come from :func:`cartesian.tracking.track`, which chooses the engine in one place:
on arms with a vectorised closed form (UR family, planar 2R) a path that raises no flag is
solved whole (:mod:`cartesian.batch_track`: the same samples, exact); on other arms by the lean
loop (:mod:`cartesian.lean_track`: the loop's IK alone per sample, monitored after it); every
other path, and every one that comes near a flag, by the monitored per-sample loop
(:mod:`cartesian.loop_track`).
:func:`check_reachability` runs the same monitoring on the geometry alone, before any timing.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from cartesian.between import check_between
from cartesian.events import Status
from cartesian.geometry import trace_geometry, unreachable_stretch
from cartesian.paths import Path
from cartesian.plan import CartesianPlan
from cartesian.remedies import offer_finer_sampling, offer_slower
from cartesian.retime import grid_points, optimal_speeds, path_feature, timing_from_speeds
from cartesian.timing import PathTiming, time_path
from cartesian.tracker import (
    SINGULAR_FRACTION,
    Tracker,
    path_targets,
    resolve_task,
)
from cartesian.tracking import track
from kinplan import checks
from kinplan.cell import WorkCell
from kinplan.errors import InputError
from kinplan.model.robot import Robot
from kinplan.trajectory._profiles import PROFILES
from kinplan.trajectory.sampling import MIN_INTERVALS


def follow(
    robot: Robot,
    path: Path,
    duration: float | None = None,
    speed: float | None = None,
    profile: str = "trapezoid",
    dt: float = 0.01,
    q_seed: Sequence[float] | np.ndarray | None = None,
    position_only: bool | None = None,
    *,
    acceleration: float | None = None,
    singular_threshold: float | None = None,
    velocity_scale: float = 1.0,
    jump_tolerance: float = 0.05,
    tolerance: float = 1e-7,
    rotation_tolerance: float = 1e-7,
    retime: bool = False,
    max_acceleration: float | np.ndarray | None = None,
    cell: WorkCell | None = None,
    clearance: float | None = None,
    interpolation_tolerance: float = 1e-4,
    whole_periods: bool = False,
) -> CartesianPlan:
    """Plan the tool along ``path``: timed, IK at every sample, monitored.

    Args:
        robot: The arm.
        path: The Cartesian path (:class:`~cartesian.Line`, :class:`~cartesian.Arc`, ...).
        duration: Motion duration [s]; or
        speed: Tool cruise speed [m/s].
        profile: 1-D time law: "trapezoid" (default), "quintic" or "cubic".
        dt: Sampling period [s]; the samples returned are at 0, dt, ..., the last exactly at
            the end (the caller's grid, whatever the motion). A motion shorter than 16 periods
            is checked on a finer grid; between the samples the motion a controller runs (the
            quintic Hermite interpolant through q, q̇, q̈) is checked too: when the period
            cannot represent the motion (a weave faster than the sampling, a corner), the plan
            is refused as "sampling" with the largest period that works in its remedy.
        q_seed: Start configuration guess (the IK of the path start stays on its branch).
        position_only: Ignore the tool orientation; default: when the arm has fewer than 6
            joints. On an arm with 6 or more joints a path built from 3-vectors keeps the tool
            orientation of ``q_seed`` (its FK) all along, as programs do; ``True`` opts out.
        acceleration: Tool acceleration of the trapezoid [m/s²] (default: cruise in 0.25 s).
        singular_threshold: Manipulability under which a sample is singular; default 5 % of
            the arm's median manipulability over its joint space.
        velocity_scale: Fraction of the robot's joint speed limits allowed.
        jump_tolerance: Largest joint step [rad] beyond what the joint velocities explain.
        tolerance: Tool position tolerance of every sample [m].
        rotation_tolerance: Tool rotation tolerance of every sample [rad].
        retime: Time the exact path optimally instead (:mod:`cartesian.retime`): the fastest
            law within the joint velocity limits, the joint acceleration limits and the
            nominal law's top tool speed (``speed``, or the peak of the law ``duration`` gives),
            at rest at both ends: constant tool speed wherever the arm allows, slower only where
            it must (near singularities, at corners). Where no joint acceleration is limited, the
            nominal law's path acceleration is kept too. The plan's ``duration`` is the law's.
        max_acceleration: Joint acceleration limits [rad/s² or m/s²], one number for all joints
            or one per joint; default the robot's ``acceleration_limit`` (inf where unknown).
            Limited joints are checked at every sample (an "acceleration_limit" event).
        cell: A :class:`kinplan.WorkCell`: the motion is checked against its obstacles and the
            robot's own links, at the samples and between them
            (:meth:`~kinplan.WorkCell.check_motion`, conservative advancement): a "collision"
            event at the first colliding sample; ``min_clearance`` and ``min_self_clearance``
            on the plan.
        clearance: Margin [m] (≥ 0, default 0) between the robot (links and tool body) and the
            cell's obstacles: a robot–obstacle distance below it is a "collision" too. The
            robot's own link pairs fail only on contact (neighbouring links of real arms sit
            millimetres apart all the time).
        interpolation_tolerance: Largest tool distance [m] from where the path has it at the
            same time, allowed between the samples for the interpolant through them (default
            0.1 mm), or 1 % of the tool's travel between the two samples when that is more (a
            coarse grid asks for a coarse motion); a rotation counts as the displacement it
            causes 0.1 m from the tool frame.
        whole_periods: Hold the tool at rest at the path's end until a whole number of
            periods ``dt`` (less than one period more): every sample, the last included, on the
            grid k · dt, the motion itself unchanged. Programs plan their moves so (their
            samples are one grid, move after move); default False: the last sample exactly at
            the law's end.

    Returns:
        CartesianPlan; an event stops it at the first offending sample.
    """
    _check_robot_and_path(robot, path)
    seed = robot.neutral() if q_seed is None else robot.check_q(q_seed, "q_seed")
    if position_only is not None:
        position_only = checks.flag(position_only, "position_only")
    path, position_only = resolve_task(robot, path, position_only, seed)
    duration = checks.optional_number(duration, "duration", positive=True, unit="s")
    speed = checks.optional_number(speed, "speed", positive=True, unit="m/s")
    acceleration = checks.optional_number(acceleration, "acceleration", positive=True, unit="m/s²")
    profile = checks.choice(profile, "profile", PROFILES)
    dt = checks.number(dt, "dt", positive=True, unit="s")
    velocity_scale = checks.number(velocity_scale, "velocity_scale", positive=True)
    jump_tolerance = checks.number(jump_tolerance, "jump_tolerance", positive=True, unit="rad")
    tolerance = checks.number(tolerance, "tolerance", positive=True, unit="m")
    rotation_tolerance = checks.number(
        rotation_tolerance, "rotation_tolerance", positive=True, unit="rad"
    )
    retime = checks.flag(retime, "retime")
    whole_periods = checks.flag(whole_periods, "whole_periods")
    if cell is not None:
        if not isinstance(cell, WorkCell):
            raise InputError(f"cell must be a kinplan.WorkCell, got {checks.describe(cell)}")
        if cell.robot is not robot:
            cell = cell.for_robot(robot)
    clearance = 0.0 if clearance is None else checks.number(clearance, "clearance", minimum=0.0)
    accel_limit = robot.acceleration_limit
    if max_acceleration is not None:
        if np.ndim(max_acceleration) == 0:
            value = checks.number(max_acceleration, "max_acceleration", positive=True)
            accel_limit = np.full(robot.nq, value)
        else:
            accel_limit = checks.vector(max_acceleration, "max_acceleration", robot.nq)
            if np.any(accel_limit <= 0):
                raise InputError(f"max_acceleration must be > 0 for every joint, got {accel_limit}")
    if singular_threshold is None:
        singular_threshold = SINGULAR_FRACTION * robot.reference_manipulability(position_only)
    singular_threshold = checks.number(singular_threshold, "singular_threshold", minimum=0.0)
    tracker = Tracker(
        robot, position_only, tolerance, rotation_tolerance, singular_threshold,
        velocity_scale, jump_tolerance, accel_limit,
    )  # fmt: skip
    tracker.cell, tracker.clearance = cell, clearance
    interpolation_tolerance = checks.number(
        interpolation_tolerance, "interpolation_tolerance", positive=True, unit="m"
    )
    if interpolation_tolerance < tolerance:
        raise InputError(
            f"interpolation_tolerance ({interpolation_tolerance:g} m) must be at least the "
            f"tolerance of the samples ({tolerance:g} m): between samples the tool cannot be "
            "closer to the path than at them"
        )

    def plan_at(
        step: float, law: tuple[float | None, float | None, float | None] | None = None
    ) -> CartesianPlan:
        """The plan at sampling period ``step``, with the law's (duration, speed, acceleration)
        (default the caller's)."""
        length_law = (duration, speed, acceleration) if law is None else law
        timing = time_path(path.length, *length_law, profile, step)
        if whole_periods:
            timing = timing.on_whole_periods(step)
        if retime:
            plan = _retimed_plan(
                tracker, path, timing, seed, step, interpolation_tolerance, whole_periods
            )
        else:
            plan = _planned(tracker, path, timing, seed, interpolation_tolerance)
        plan.accelerations_limited = bool(np.isfinite(accel_limit).all())
        return plan

    plan = plan_at(dt)
    if plan.status in REMEDIED_BY_MOTION:
        beyond = unreachable_stretch(robot, path, position_only, plan.events[0].s)
        if beyond is not None:  # no slower law or other start would pass: say so, offer none
            plan.events[0].remedy = str(beyond)
            plan.out_of_reach = beyond
            return plan
    if plan.status == Status.SAMPLING:
        offer_finer_sampling(plan, dt, plan_at)
    elif not retime and plan.status in (Status.VELOCITY_LIMIT, Status.ACCELERATION_LIMIT):
        offer_slower(plan, lambda law: plan_at(dt, law), (duration, speed, acceleration))
        # offer retiming only when it would pass: try it
        timing = time_path(path.length, duration, speed, acceleration, profile, dt)
        retimed = _retimed_plan(
            tracker, path, timing, seed, dt, interpolation_tolerance, whole_periods
        )
        if retimed.ok:
            plan.retime_duration = retimed.duration
            plan.events[0].remedy += (
                f", or retime (retime=True: the exact path in {retimed.duration:.4g} s instead "
                f"of {plan.duration:.4g} s)"
            )
    return plan


#: Refusals whose usual remedy (a slower law, another start configuration, keeping away from
#: a singularity or a limit) :func:`follow` replaces when the path ahead is out of reach.
REMEDIED_BY_MOTION = frozenset(
    (Status.SINGULAR, Status.VELOCITY_LIMIT, Status.ACCELERATION_LIMIT, Status.JUMP,
     Status.JOINT_LIMIT)
)  # fmt: skip


def _planned(
    tracker: Tracker,
    path: Path,
    timing: PathTiming,
    seed: np.ndarray,
    interpolation_tolerance: float,
) -> CartesianPlan:
    """The plan on the caller's grid ``timing.t``: tracked and monitored on a check grid (the
    caller's, or finer for a short motion: :func:`check_parts`), then checked between the
    samples returned (:func:`_between_samples`)."""
    parts = check_parts(timing)
    fine = track(tracker, path, timing.refined(parts), seed)
    plan = _on_caller_grid(fine, parts)
    plan.check_step = float(np.diff(timing.t).max(initial=0.0)) / parts
    plan.interpolation_tolerance = interpolation_tolerance
    if plan.ok:
        if np.isfinite(tracker.acceleration_limit).any() and plan.max_deviation > POLISHED:
            _polish(tracker, plan)
        check_between(tracker, plan, timing)
    return plan


#: Tool error [m] below which samples are exact enough for the interpolant's accelerations.
POLISHED = 1e-11


def _polish(tracker: Tracker, plan: CartesianPlan) -> None:
    """Newton steps at every sample down to the last digits: the interpolant's acceleration
    between samples amplifies the samples' position errors by ~60 / Δt² (1e-7 m at 1 kHz:
    several rad/s²), so a plan whose accelerations are checked between samples is solved to
    rounding first (the tool position moves by less than the tolerance it already met)."""
    targets = path_targets(plan.path, plan.s, tracker.position_only, tracker.rows)
    rotations = targets.rotations
    for k, q in enumerate(plan.q):
        rotation = None if rotations is None else rotations[k]
        solved = tracker.solver.descend(
            q, targets.positions[k], rotation, 1e-14, 1e-14, 3, clamp=False
        )
        plan.q[k] = solved[0]
    plan.tool_positions = tracker.robot.tool_positions(plan.q)
    plan.max_deviation = min(
        plan.max_deviation,
        float(np.linalg.norm(plan.tool_positions - targets.positions, axis=1).max()),
    )


def check_parts(timing: PathTiming) -> int:
    """Into how many parts every interval of the caller's grid is split for the checks: 1,
    or enough that the motion has :data:`~kinplan.sampling.MIN_INTERVALS` check intervals
    (a 1 ms move is not checked at its two resting ends only; a motion held at rest until a
    whole period counts the intervals it moves in)."""
    intervals = timing.moving_intervals
    if intervals <= 0:
        return 1
    return max(1, min(MAX_CHECK_PARTS, math.ceil(MIN_INTERVALS / intervals)))


#: Most parts a caller interval is split into for the checks: a motion shorter than 1/64 of a
#: period (held at rest for the rest of it) is checked at fewer than MIN_INTERVALS points
#: inside it, but its mean speed between them (huge: it moves in microseconds) still is, and
#: the check grid stays small (a 1 ns motion would otherwise need 1.6e8 check samples).
MAX_CHECK_PARTS = 1024


def _on_caller_grid(fine: CartesianPlan, parts: int) -> CartesianPlan:
    """The plan ``fine`` (tracked on a grid splitting every caller interval into ``parts``) on
    the caller's grid: every ``parts``-th sample; an event's index is the first caller sample
    at or after it; the extremes (deviation, manipulability, speeds, clearances) stay those of
    the check grid."""
    if parts == 1:
        return fine
    done = len(fine.t)
    keep = np.arange(math.ceil(done / parts)) * parts
    for event in fine.events:
        event.index = math.ceil(event.index / parts)
    check = fine.cell_check
    if check is not None:
        check = dataclasses.replace(
            check,
            index=None if check.index is None else math.ceil(check.index / parts),
            distances=check.distances[keep],
            obstacle_distances=check.obstacle_distances[keep],
            self_distances=check.self_distances[keep],
        )
    return dataclasses.replace(
        fine,
        t=fine.t[keep],
        q=fine.q[keep],
        qd=fine.qd[keep],
        qdd=fine.qdd[keep],
        s=fine.s[keep],
        tool_positions=fine.tool_positions[keep],
        manipulability=fine.manipulability[keep],
        fraction=1.0 if fine.ok else (float(fine.s[keep[-1]]) if len(keep) else 0.0),
        cell_check=check,
    )


def _retimed_plan(
    tracker: Tracker,
    path: Path,
    timing: PathTiming,
    seed: np.ndarray,
    dt: float,
    interpolation_tolerance: float,
    whole_periods: bool = False,
) -> CartesianPlan:
    """The plan of ``path`` with its time-optimal law (:mod:`cartesian.retime`) under the joint
    velocity and acceleration limits and the nominal law's top path speed (the nominal law's
    path acceleration too where no joint acceleration is limited); the nominal plan when the
    geometric pass fails or no finite timing exists (the plan then reports why).

    The law keeps the limits on its geometric grid; between grid points and between the samples
    the motion may exceed them slightly (the law's acceleration jumps at every grid point): when
    the checks find that, the law is planned again with the limits lowered by the excess, up
    to :data:`RETIME_ATTEMPTS` times."""
    grid = np.linspace(0.0, 1.0, grid_points(path.length, path_feature(path)))
    geometry = trace_geometry(tracker, path, grid, seed)
    if geometry.events:
        return _planned(tracker, path, timing, seed, interpolation_tolerance)
    targets = path_targets(path, geometry.s, tracker.position_only, tracker.rows)
    d2q = tracker.accelerations(geometry.q, geometry.jacobians, geometry.dq_ds, targets.curvature)
    accel = tracker.acceleration_limit
    path_accel = float(np.abs(timing.sdd).max()) if not np.isfinite(accel).any() else np.inf
    scale = 1.0
    plan: CartesianPlan | None = None
    for _ in range(RETIME_ATTEMPTS):
        speeds = optimal_speeds(
            geometry.s, geometry.dq_ds, d2q, tracker.speed_limit * scale, accel * scale,
            float(timing.sd.max()), path_accel,
        )  # fmt: skip
        retimed = timing_from_speeds(geometry.s, speeds, dt)
        if retimed is None:  # stopped for good at a singular point: the nominal plan says why
            return _planned(tracker, path, timing, seed, interpolation_tolerance)
        if whole_periods:
            retimed = retimed.on_whole_periods(dt)
        plan = _planned(tracker, path, retimed, seed, interpolation_tolerance)
        plan.retimed = True
        excess = _limit_excess(plan)
        if excess is None:
            return plan
        scale *= (1.0 - 1e-3) / excess
    assert plan is not None  # at least one attempt
    return plan


#: How many times a retimed law is planned again with lowered limits.
RETIME_ATTEMPTS = 6


def _limit_excess(plan: CartesianPlan) -> float | None:
    """By how much a retimed plan broke a speed or acceleration limit (the event's ratio), or
    None when it did not (ok, or stopped for another reason)."""
    if plan.ok or plan.status not in (Status.VELOCITY_LIMIT, Status.ACCELERATION_LIMIT):
        return None
    ratio = max(plan.peak_speed_ratio, plan.peak_acceleration_ratio)
    return ratio if ratio > 1.0 else None


def _check_robot_and_path(robot: object, path: object) -> None:
    if not isinstance(robot, Robot):
        raise InputError(
            f"robot must be a kinplan.Robot (from kinplan.load_robot), got {checks.describe(robot)}"
        )
    if not isinstance(path, Path):
        raise InputError(
            "path must be a cartesian path (cartesian.Line, Arc, Circle, Polyline, PathSequence, "
            f"FunctionPath), got {checks.describe(path)}"
        )
