"""The monitored per-sample loop: IK at every sample warm-started from the previous one, each
sample checked as it is solved (reach, joint limits, branch flips, singularities), then joint
speeds, accelerations and the cell checked on the samples kept.

The engine of last resort behind :func:`cartesian.tracking.track`: it plans every path, and stops
at the first sample that raises a flag, saying where and why (:class:`~cartesian.events.Event`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cartesian.events import Event, Status, collision_event
from cartesian.geometry import trace_between
from cartesian.paths import Path
from cartesian.plan import CartesianPlan
from cartesian.timing import PathTiming
from cartesian.tracker import Targets, Tracker, adams_bashforth_weights
from kinplan.trajectory.sampling import joint_speeds


def track(
    tracker: Tracker,
    path: Path,
    timing: PathTiming,
    targets: Targets,
    xd: np.ndarray,
    xdd: np.ndarray,
    seed: np.ndarray,
) -> CartesianPlan:
    """The plan of a timed path, sample by sample, stopped at the first event.

    Args:
        tracker: The plan's tracker (arm, tolerances, thresholds, limits, cell).
        path: The path followed.
        timing: The samples' times [s] and path fractions.
        targets: The path's targets at the samples (:func:`~cartesian.tracker.path_targets`).
        xd: Task velocities ẋ (N, r) of the samples.
        xdd: Task accelerations ẍ (N, r) of the samples.
        seed: The configuration the plan starts from [rad].
    """
    robot = tracker.robot
    position_only = tracker.position_only
    t, s = timing.t, timing.s
    n, nq = len(t), robot.nq
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
    peak_accel = 0.0
    if np.isfinite(tracker.acceleration_limit).any() and done:
        # accelerations are checked where they are limited; q̈ is exact at every sample (the
        # profiles' s̈ jumps at their knots: a knot's sample carries the later segment's)
        accel_ratios = np.abs(qdd_out) / tracker.acceleration_limit
        peak_accel = float(accel_ratios.max())
        hard = np.flatnonzero((accel_ratios > 1.0 + 1e-9).any(axis=1))
        if len(hard):
            k = int(hard[0])
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
        peak_acceleration_ratio=peak_accel,
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
