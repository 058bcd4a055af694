"""Following a Cartesian path: IK at every sample, with reachability and singularity monitoring.

:func:`follow` times the path with a 1-D profile, solves IK at every sample warm-started from the
previous one (so the arm stays on its branch), derives joint velocities and accelerations from the
timed path (q̇ = J⁺ẋ, q̈ = dq̇/dt = J⁺(ẍ − J̇q̇) plus, for a redundant arm, the null-space part
of the derivative of its minimum-norm q̇), and stops at the first sample that is unreachable,
beyond a joint limit, needs a branch flip ("jump"), is near a singularity or too fast for a
joint. The plan says where and why (:class:`Event`) and how much of the path was achieved.
On arms with a vectorised closed form (UR family, planar 2R) a path that raises no flag is
solved whole instead (:mod:`cartesian.batch_track`: the same samples, exact); on other arms by
the lean loop (:mod:`cartesian.lean_track`: the loop's IK alone per sample, monitored after it);
every other path, and every one that comes near a flag, goes through the per-sample loop.
:func:`check_reachability` runs the same monitoring on the geometry alone, before any timing.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cartesian import batch_track, lean_track
from cartesian.events import Event, Status, where
from cartesian.geometry import trace_between, trace_geometry
from cartesian.paths import Path
from cartesian.retime import grid_points, optimal_speeds, timing_from_speeds
from cartesian.timing import PathTiming, time_path
from cartesian.tracker import (
    SINGULAR_FRACTION,
    Tracker,
    adams_bashforth_weights,
    path_targets,
    resolve_task,
)
from kinplan import checks
from kinplan._profiles import PROFILES
from kinplan.cell import MotionCheck, WorkCell
from kinplan.errors import InputError
from kinplan.motion import MotionKind, MoveSpan, PlannedPath, no_waypoints
from kinplan.robot import Robot
from kinplan.sampling import joint_speeds
from kinplan.trajectory import Waypoints


@dataclass
class CartesianPlan:
    """A timed, monitored Cartesian motion.

    Attributes:
        t: Sample times [s], shape (N,) (only the samples achieved before a failure).
        q: Joint positions, shape (N, nq).
        qd: Joint velocities [rad/s], shape (N, nq).
        qdd: Joint accelerations [rad/s²], shape (N, nq).
        s: Path fraction of each sample.
        ok: True when the whole path was planned without event.
        status: "ok" or the kind of the first event.
        fraction: Path fraction achieved before the first failure (1.0 when ok).
        events: The events at the offending sample (empty when ok).
        max_deviation: Largest tool distance from the path over the samples [m].
        min_manipulability: Smallest manipulability over the samples.
        duration: Duration of the planned (timed) motion [s].
        path: The Cartesian path.
        position_only: Whether the tool orientation was ignored.
        singular_threshold: Manipulability below which a sample counts as singular.
        tool_positions: Achieved tool positions (FK of q) [m], shape (N, 3).
        manipulability: Manipulability of each sample, shape (N,).
        retimed: Whether the time law was slowed down to respect the joint speed limits.
        retime_duration: For a plan stopped by a velocity limit: the duration of the retimed
            plan (``retime=True``) when that one is ok, else None.
        peak_speed_ratio: Largest joint speed over its (scaled) limit among the samples solved
            (:func:`kinplan.sampling.joint_speeds`), including those past a velocity event: the
            factor by which the motion is too fast (> 1) or has margin (< 1).
        min_clearance: Smallest distance between the robot (and its tool body) and the cell's
            obstacles over the samples achieved [m] (inf without a cell or obstacles).
        min_self_clearance: Smallest distance between the robot's own checked link pairs [m]
            (inf without a cell).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    s: np.ndarray
    ok: bool
    status: str
    fraction: float
    events: list[Event]
    max_deviation: float
    min_manipulability: float
    duration: float
    path: Path
    position_only: bool
    singular_threshold: float
    tool_positions: np.ndarray
    manipulability: np.ndarray
    retimed: bool = False
    retime_duration: float | None = None
    peak_speed_ratio: float = 0.0
    min_clearance: float = np.inf
    min_self_clearance: float = np.inf
    robot: Robot | None = None  # the robot it was planned for
    cell: WorkCell | None = None  # the work cell it was checked against (issue 16)
    cell_check: MotionCheck | None = None  # that check: pairs, per-sample distances

    # -- kinplan.motion.SampledMotion: what viewers, plots and exports read --------------------
    @property
    def kind(self) -> MotionKind:
        """Always "cartesian": an event's ``s`` is a fraction of :attr:`path`."""
        return "cartesian"

    @property
    def description(self) -> str:
        """The path and its length, for captions."""
        return f"Cartesian path {float(self.path.length):.3f} m"

    @property
    def planned_paths(self) -> list[PlannedPath]:
        """The path, reached up to the first event's path fraction (all of it when ok)."""
        return [PlannedPath(self.path, self.events[0].s if self.events else 1.0)]

    @property
    def waypoints(self) -> Waypoints:
        """None: a Cartesian plan is planned through no joint positions."""
        return no_waypoints(self.q.shape[1])

    @property
    def moves(self) -> tuple[MoveSpan, ...]:
        """None: a single motion."""
        return ()

    def __repr__(self) -> str:
        text = (
            f"CartesianPlan({self.status}, {len(self.t)} samples, {self.duration:.3f} s, "
            f"fraction {self.fraction:.3f}, max deviation {self.max_deviation:.2e} m"
        )
        return text + (f": {self.events[0].message})" if self.events else ")")

    def summary(self) -> str:
        """One line: status, and the first event's message when there is one."""
        if self.ok:
            return f"ok: {len(self.t)} samples, {self.duration:.3f} s"
        return f"{self.status} at s = {self.events[0].s:.3f}: {self.events[0].message}"


# ------------------------------------------------------------------------------------------
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
) -> CartesianPlan:
    """Plan the tool along ``path``: timed, IK at every sample, monitored.

    Args:
        robot: The arm.
        path: The Cartesian path (:class:`~cartesian.Line`, :class:`~cartesian.Arc`, ...).
        duration: Motion duration [s]; or
        speed: Tool cruise speed [m/s].
        profile: 1-D time law: "trapezoid" (default), "quintic" or "cubic".
        dt: Sampling period [s]; samples at 0, dt, ..., the last exactly at the end.
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
    timing = time_path(path.length, duration, speed, acceleration, profile, dt)
    if retime:
        return _retimed_plan(tracker, path, timing, seed, dt)
    plan = _track(tracker, path, timing, seed)
    if plan.status in (Status.VELOCITY_LIMIT, Status.ACCELERATION_LIMIT):
        # offer retiming only when it would pass: try it
        retimed = _retimed_plan(tracker, path, timing, seed, dt)
        if retimed.ok:
            plan.retime_duration = retimed.duration
            plan.events[0].remedy += (
                f", or retime (retime=True: the exact path in {retimed.duration:.3f} s instead "
                f"of {plan.duration:.3f} s)"
            )
    return plan


def _retimed_plan(
    tracker: Tracker, path: Path, timing: PathTiming, seed: np.ndarray, dt: float
) -> CartesianPlan:
    """The plan of ``path`` with its time-optimal law (:mod:`cartesian.retime`) under the joint
    velocity and acceleration limits and the nominal law's top path speed (the nominal law's
    path acceleration too where no joint acceleration is limited); the nominal plan when the
    geometric pass fails or no finite timing exists (the plan then reports why)."""
    grid = np.linspace(0.0, 1.0, grid_points(path.length))
    geometry = trace_geometry(tracker, path, grid, seed)
    if geometry.events:
        return _track(tracker, path, timing, seed)
    targets = path_targets(path, geometry.s, tracker.position_only, tracker.rows)
    d2q = tracker.accelerations(geometry.q, geometry.jacobians, geometry.dq_ds, targets.curvature)
    accel = tracker.acceleration_limit
    path_accel = float(np.abs(timing.sdd).max()) if not np.isfinite(accel).any() else np.inf
    speeds = optimal_speeds(
        geometry.s, geometry.dq_ds, d2q, tracker.speed_limit, accel,
        float(timing.sd.max()), path_accel,
    )  # fmt: skip
    retimed = timing_from_speeds(geometry.s, speeds, dt)
    if retimed is None:  # stopped for good at a singular point: the nominal plan says where
        return _track(tracker, path, timing, seed)
    plan = _track(tracker, path, retimed, seed)
    plan.retimed = True
    return plan


def collision_event(
    check: MotionCheck, t: np.ndarray, s: np.ndarray, position: np.ndarray
) -> Event:
    """The "collision" event of a failed :meth:`~kinplan.WorkCell.check_motion`: the two bodies,
    where (at sample ``check.index`` or between it and the one before) and how deep."""
    k = check.index
    assert k is not None and check.bodies is not None  # a failed check: its sample and bodies
    first, second = check.bodies
    when = f"between samples {k - 1} and {k}" if check.between else f"at sample {k}"
    if check.kind == "obstacle" and check.clearance > 0 and check.distance > 0:
        what = (
            f"{first} comes within {1e3 * check.distance:.1f} mm of {second}, "
            f"{1e3 * check.penetration:.1f} mm inside the clearance {1e3 * check.clearance:.1f} mm"
        )
    else:
        what = f"{first} collides with {second} ({1e3 * check.penetration:.1f} mm deep)"
    point = "" if check.point is None else f" near {where(check.point)}"
    return Event(
        Status.COLLISION, float(t[k]), float(s[k]), k, f"{what} {when}{point}", position,
        value=float(check.distance), limit=float(check.clearance),
        remedy="move the path or the obstacle, or start from another configuration (q_seed)",
    )  # fmt: skip


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


def _track(tracker: Tracker, path: Path, timing: PathTiming, seed: np.ndarray) -> CartesianPlan:
    robot = tracker.robot
    position_only = tracker.position_only
    t, s, sd, sdd = timing.t, timing.s, timing.sd, timing.sdd
    n, nq = len(t), robot.nq

    targets = path_targets(path, s, position_only, tracker.rows)
    xd = targets.rate * sd[:, None]  # task velocity ẋ = x' ṡ
    xdd = targets.curvature * (sd**2)[:, None] + targets.rate * sdd[:, None]  # x'' ṡ² + x' s̈
    # a clean path on an arm with a vectorised closed form: every sample at once
    clean = batch_track.track(tracker, targets, timing, xd, xdd, seed)
    if clean is None:  # any other arm: the lean loop, monitored after it
        clean = lean_track.track(tracker, targets, timing, xd, xdd, seed)
    if clean is not None:
        return _clean_plan(tracker, path, timing, targets.positions, clean)

    positions, position_floats = targets.positions, targets.positions.tolist()
    rotations: Sequence[np.ndarray | None]
    rotation_floats: Sequence[list[float] | None]
    if targets.rotations is None:
        rotations, rotation_floats = [None] * n, [None] * n
    else:
        rotations = list(targets.rotations)
        rotation_floats = targets.rotations.reshape(n, 9).tolist()

    # per sample: IK, Jacobian, manipulability, q̇ (for the next prediction); q̈ after the loop
    qs: list[np.ndarray] = []
    qds: list[np.ndarray] = []
    jacobians: list[np.ndarray] = []
    tools: list[tuple[float, float, float]] = []
    manips: list[float] = []
    events: list[Event] = []
    q_prev: np.ndarray | None = None
    qd_prev: np.ndarray | None = None
    qd_before: np.ndarray | None = None
    qdd_first = np.zeros(nq)  # q̈ at the first sample when it is at rest, for the second's guess
    steps = np.diff(t, prepend=0.0).tolist()  # h_k = t_k − t_(k−1) [s]
    weights = adams_bashforth_weights(np.diff(t))
    for k in range(n):
        if k == 0:
            guess = tracker.start(positions[0], rotations[0], seed)
        elif qd_before is None:  # second sample: Taylor, with q̈ = J⁺ẍ when starting at rest
            assert q_prev is not None and qd_prev is not None  # sample k − 1 was kept
            guess = q_prev + qd_prev * steps[k] + (0.5 * steps[k] ** 2) * qdd_first
        else:
            assert q_prev is not None and qd_prev is not None  # sample k − 1 was kept
            w_prev, w_before = weights[k]
            guess = q_prev + qd_prev * w_prev + qd_before * w_before
        # most predictions are within tolerance: one kinematics pass, else Newton steps
        evaluation, corrections = tracker.evaluate(guess, position_floats[k], rotation_floats[k]), 0
        if not tracker.within(evaluation):
            _, ok, _, _, corrections, evaluation = tracker.solve(
                guess, positions[k], rotations[k], evaluated=evaluation
            )
            if not ok:
                found = tracker.rescue(k, t[k], s[k], guess, q_prev, positions[k], rotations[k])
                if isinstance(found, Event):
                    events.append(found)
                    break
                evaluation = tracker.evaluate(found, position_floats[k], rotation_floats[k])
                corrections = 1
        q = evaluation.q
        event, J, m, qd = tracker.check_sample(
            k, t[k], s[k], evaluation, q_prev, qd_prev, steps[k], xd[k], positions[k], corrections
        )
        if event is not None and k > 0 and event.kind in (Status.JOINT_LIMIT, Status.JUMP):
            assert q_prev is not None  # sample k − 1 was kept
            # a limit or a branch flip, or only a step too coarse for a fast motion?
            traced = trace_between(tracker, path, s[k - 1], s[k], q_prev)
            if isinstance(traced, Event):  # met between the samples: reported at sample k
                traced.t, traced.s, traced.index = float(t[k]), float(s[k]), k
                traced.position = positions[k]
                event = traced
            elif traced is not None:  # the continuous solution
                evaluation = tracker.evaluate(traced, position_floats[k], rotation_floats[k])
                q = traced
                event, J, m, qd = tracker.check_sample(
                    k, t[k], s[k], evaluation, q_prev, qd_prev, steps[k], xd[k], positions[k], 1
                )
                if event is not None and event.kind == Status.JUMP:
                    assert qd is not None  # a jump is checked after the rates
                    event = tracker.coarse_step_event(
                        k, t, s[k], q, q_prev, qd, qd_prev, steps[k], positions[k], qs, qds
                    )
        if event is not None:
            events.append(event)
            break
        assert J is not None and qd is not None  # no event: the sample's Jacobian and rates
        if k == 0 and not qd.any():
            qdd_first = tracker.rates(xdd[0])
        qs.append(q)
        qds.append(qd)
        jacobians.append(J)
        tools.append(evaluation.tool_position)
        manips.append(m)
        q_prev, qd_prev, qd_before = q, qd, qd_prev

    done = len(qs)
    q_out = np.array(qs).reshape(done, nq)
    qd_out = np.array(qds).reshape(done, nq)
    # joint speeds are checked once, vectorised (rates and mean speeds between samples); a
    # sample too fast comes before any event the loop stopped at (those stop the loop at index
    # `done`), so it is the first event
    ratios = joint_speeds(q_out, qd_out, t[:done]) / tracker.speed_limit
    over = np.flatnonzero((ratios > 1.0).any(axis=1))
    peak = float(ratios.max(initial=0.0))
    if len(over):
        k = int(over[0])
        events = [tracker.speed_event(k, t[k], s[k], ratios[k], peak, positions[k])]
        done = k
    q_out, qd_out = q_out[:done], qd_out[:done]
    jacobian_stack = np.array(jacobians[:done]).reshape(done, 6, nq)
    qdd_out = tracker.accelerations(q_out, jacobian_stack, qd_out, xdd[:done])
    if np.isfinite(tracker.acceleration_limit).any() and done:
        # accelerations are checked where they are limited; q̈ is exact at every sample (the
        # profiles' s̈ jumps at their knots: a knot's sample carries the later segment's)
        accel_ratios = np.abs(qdd_out) / tracker.acceleration_limit
        hard = np.flatnonzero((accel_ratios > 1.0 + 1e-9).any(axis=1))
        if len(hard):
            k = int(hard[0])
            peak_accel = float(accel_ratios.max())
            events = [
                tracker.acceleration_event(k, t[k], s[k], qdd_out[k], peak_accel, positions[k])
            ]
            done = k
            q_out, qd_out, qdd_out = q_out[:done], qd_out[:done], qdd_out[:done]
    min_clearance = min_self_clearance = np.inf
    check = None
    if tracker.cell is not None and done:
        check = tracker.cell.check_motion(q_out, tracker.clearance)
        min_clearance, min_self_clearance = check.min_obstacle_clearance, check.min_self_clearance
        if check.index is not None:
            k = check.index
            events = [collision_event(check, t, s, positions[k])]
            done = k
            q_out, qd_out, qdd_out = q_out[:done], qd_out[:done], qdd_out[:done]
    tool = np.array(tools[:done]).reshape(done, 3)
    manip = np.array(manips[:done])

    ok = not events
    deviation = np.linalg.norm(tool - positions[:done], axis=1)
    return CartesianPlan(
        t=t[:done].copy(),
        q=q_out,
        qd=qd_out,
        qdd=qdd_out,
        s=s[:done].copy(),
        ok=ok,
        status=Status.OK if ok else events[0].kind,
        peak_speed_ratio=peak,
        fraction=1.0 if ok else (float(s[done - 1]) if done else 0.0),
        events=events,
        max_deviation=float(deviation.max()) if done else 0.0,
        min_manipulability=float(manip.min()) if done else 0.0,
        duration=float(timing.duration),
        path=path,
        position_only=position_only,
        singular_threshold=float(tracker.singular_threshold),
        tool_positions=tool,
        manipulability=manip,
        robot=robot,
        min_clearance=float(min_clearance),
        min_self_clearance=float(min_self_clearance),
        cell=tracker.cell,
        cell_check=check,
    )


def _clean_plan(
    tracker: Tracker,
    path: Path,
    timing: PathTiming,
    positions: np.ndarray,
    clean: batch_track.BatchTrack,
) -> CartesianPlan:
    """The plan of a path :func:`cartesian.batch_track.track` solved whole (status ok).

    Args:
        positions: The path's tool positions at the samples [m], (N, 3).
    """
    check = clean.check
    deviation = np.linalg.norm(clean.tool_positions - positions, axis=1)
    return CartesianPlan(
        t=timing.t.copy(),
        q=clean.q,
        qd=clean.qd,
        qdd=clean.qdd,
        s=timing.s.copy(),
        ok=True,
        status=Status.OK,
        peak_speed_ratio=clean.peak_speed_ratio,
        fraction=1.0,
        events=[],
        max_deviation=float(deviation.max()),
        min_manipulability=float(clean.manipulability.min()),
        duration=float(timing.duration),
        path=path,
        position_only=tracker.position_only,
        singular_threshold=float(tracker.singular_threshold),
        tool_positions=clean.tool_positions,
        manipulability=clean.manipulability,
        robot=tracker.robot,
        min_clearance=np.inf if check is None else float(check.min_obstacle_clearance),
        min_self_clearance=np.inf if check is None else float(check.min_self_clearance),
        cell=tracker.cell,
        cell_check=check,
    )
