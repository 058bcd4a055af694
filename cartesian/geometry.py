"""The geometry of a path for an arm, before any timing: continuous IK along it.

:func:`trace_geometry` solves warm-started IK at path fractions, bisecting where a joint moves
fast, and stops at the first joint limit, singularity, branch flip or unreachable point;
:func:`check_reachability` is the public pre-check built on it, :func:`trace_between` what the
follower asks when a sample seems to jump.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cartesian import lean_track
from cartesian.events import Event, OutOfReach, Status, beyond_reach, where
from cartesian.paths import Path
from cartesian.tracker import SINGULAR_FRACTION, Tracker, path_targets, resolve_task
from kinplan.model.robot import Robot


@dataclass
class Reachability:
    """Result of :func:`check_reachability` (geometric: no timing).

    Attributes:
        ok: Whether every sampled point of the path is reachable continuously.
        status: "ok" or the kind of the first event.
        fraction: Path fraction reached before the first failure (1.0 when ok).
        events: The events at the first failing point.
        s: Path fractions checked (up to the failure).
        q: Joint positions at those points (IK checks; empty for an analytic check).
    """

    ok: bool
    status: str
    fraction: float
    events: list[Event]
    s: np.ndarray
    q: np.ndarray

    def __repr__(self) -> str:
        text = f"Reachability({self.status}, fraction {self.fraction:.3f}, {len(self.s)} points"
        return text + (f": {self.events[0].message})" if self.events else ")")


@dataclass
class Geometry:
    """Joint solutions along the path up to the first event (for checks and retiming).

    Attributes:
        s: Path fractions solved (the requested ones plus refinements).
        q: Joint positions there, shape (len(s), nq).
        dq_ds: Geometric joint rates dq/ds there.
        events: The first event, if any.
        jacobians: Tool Jacobians (len(s), 6, nq) there.
    """

    s: np.ndarray
    q: np.ndarray
    dq_ds: np.ndarray
    events: list[Event]
    jacobians: np.ndarray


#: Largest joint step [rad] between checked points before the interval is bisected.
MAX_JOINT_STEP = 0.1


#: Smallest interval in s that is still bisected.
MIN_REFINE_DS = 1e-7


def _points(tracker: Tracker, path: Path, s: np.ndarray) -> list[tuple]:
    """(s, position, rotation or None, dx/ds) of each path fraction in ``s``."""
    targets = path_targets(path, s, tracker.position_only, tracker.rows)
    rotations = [None] * len(s) if targets.rotations is None else list(targets.rotations)
    return list(zip(s.tolist(), targets.positions, rotations, targets.rate))


def trace_geometry(tracker: Tracker, path: Path, s: np.ndarray, seed: np.ndarray) -> Geometry:
    """Warm-started IK at path fractions ``s`` with joint-limit/jump/singularity checks.

    Where a joint moves more than :data:`MAX_JOINT_STEP` between two points the interval is
    bisected, so a singularity or a branch flip between grid points is not stepped over. Also
    returns dq/ds = J⁺ dx/ds at every solved point.
    """
    robot = tracker.robot
    # a path with no event on an arm of full task rank: the lean loop, monitored after it
    lean = lean_track.trace(tracker, path, s, seed, MAX_JOINT_STEP, MIN_REFINE_DS)
    if lean is not None:
        return Geometry(lean[0], lean[1], lean[2], [], lean[3])
    # A stack of (s, position, rotation, dx/ds): the next point to check is at the end.
    pending = _points(tracker, path, s)[::-1]
    solved_s: list[float] = []
    qs: list[np.ndarray] = []
    dqs: list[np.ndarray] = []
    jacobians: list[np.ndarray] = []
    events: list[Event] = []
    q_prev: np.ndarray | None = None
    while pending:
        sk, position, rotation, dx = pending[-1]
        k = len(qs)
        if q_prev is None:
            guess = tracker.start(position, rotation, seed)
        elif len(dqs) > 1:  # second order: the rate's change over the last step
            h, h_prev = sk - solved_s[-1], solved_s[-1] - solved_s[-2]
            guess = q_prev + dqs[-1] * h + (0.5 * h * h / h_prev) * (dqs[-1] - dqs[-2])
        else:
            guess = q_prev + dqs[-1] * (sk - solved_s[-1])
        # most predictions are within tolerance: one kinematics pass, else Newton steps
        floats = position.tolist(), None if rotation is None else rotation.reshape(9).tolist()
        evaluation, ok, corrected = tracker.evaluate(guess, *floats), True, False
        if not tracker.within(evaluation):
            *_, evaluation = tracker.solve(guess, position, rotation, evaluated=evaluation)
            ok, corrected = tracker.within(evaluation), True
        q = evaluation.q
        if q_prev is not None and sk - solved_s[-1] > MIN_REFINE_DS:
            if not ok or np.max(np.abs(q - q_prev)) > MAX_JOINT_STEP:
                pending += _points(tracker, path, np.array([0.5 * (sk + solved_s[-1])]))
                continue
        if not ok:
            found = tracker.rescue(k, 0.0, sk, guess, q_prev, position, rotation)
            if isinstance(found, Event):
                events.append(found)
                break
            q, evaluation = found, tracker.evaluate(found, *floats)
        # the follower's own checks, with rates per unit s instead of per second
        h = sk - solved_s[-1] if solved_s else 0.0
        rate_prev = dqs[-1] if dqs else None
        event, J, _, dq = tracker.check_sample(
            k, 0.0, sk, evaluation, q_prev, rate_prev, h, dx, position, int(corrected)
        )
        if event is not None:
            events.append(event)
            break
        assert J is not None and dq is not None  # no event: both were computed
        pending.pop()
        solved_s.append(sk)
        qs.append(q)
        dqs.append(dq)
        jacobians.append(J)
        q_prev = q
    nq = robot.nq
    return Geometry(
        np.array(solved_s),
        np.array(qs).reshape(-1, nq),
        np.array(dqs).reshape(-1, nq),
        events,
        np.array(jacobians).reshape(-1, 6, nq),
    )


#: Points of the finer trace that checks a jump between two samples.
JUMP_CHECK_POINTS = 17


def trace_between(
    tracker: Tracker, path: Path, s0: float, s1: float, q0: np.ndarray
) -> np.ndarray | Event | None:
    """Follow the path geometrically from ``q0`` at fraction ``s0`` to ``s1`` on a finer grid
    (bisected where a joint moves fast): what a sample that seems to jump really is.

    Returns:
        The configuration at s1 reached continuously (the sample's step was only too coarse
        for the motion: its speed is then checked like any other), the event that the finer
        trace meets on the way (a singularity, a joint limit, a branch flip), or None when it
        cannot be started from q0.
    """
    geometry = trace_geometry(tracker, path, np.linspace(s0, s1, JUMP_CHECK_POINTS), q0)
    if geometry.events:
        return geometry.events[0]
    if len(geometry.q) == 0 or np.max(np.abs(geometry.q[0] - q0)) > tracker.jump_tolerance:
        return None
    return geometry.q[-1]


# ------------------------------------------------------------------------------------------
def check_reachability(
    robot: Robot,
    path: Path,
    q_seed: Sequence[float] | np.ndarray | None = None,
    position_only: bool | None = None,
    *,
    resolution: float = 0.005,
    singular_threshold: float | None = None,
) -> Reachability:
    """Fast pre-check: does the path stay in the workspace, continuously, away from singularities?

    Warm-started IK at points every ``resolution`` metres (at least 50 points, bisected where a
    joint moves more than 0.1 rad), reporting unreachable points, joint limits, branch jumps and
    singularities with the thresholds :func:`follow` uses, so the two agree. Planar arms first
    check their analytic workspace (the annulus r_min ≤ r ≤ r_max about the first joint, in its
    plane), which names the exact reason of an unreachable point. No timing, so no velocity
    check.

    Args:
        robot: The arm.
        path: The path.
        q_seed: Start configuration guess.
        position_only: As in :func:`follow`.
        resolution: Spacing of the checked points along the path [m].
        singular_threshold: As in :func:`follow`.
    """
    seed = robot.neutral() if q_seed is None else robot.check_q(q_seed, "q_seed")
    path, position_only = resolve_task(robot, path, position_only, seed)
    count = max(50, int(np.ceil(path.length / resolution)) + 1)
    s = np.linspace(0.0, 1.0, count)
    reach = robot.planar_reach()
    if reach is not None and position_only:
        annulus = _planar_check(robot, path, s, reach)
        if not annulus.ok:  # the analytic answer, with its exact reason
            return annulus
    if singular_threshold is None:
        singular_threshold = SINGULAR_FRACTION * robot.reference_manipulability(position_only)
    tracker = Tracker(robot, position_only, 1e-7, 1e-7, singular_threshold, 1.0, 0.1)
    geometry = trace_geometry(tracker, path, s, seed)
    done = len(geometry.q)
    return Reachability(
        ok=not geometry.events,
        status=geometry.events[0].kind if geometry.events else Status.OK,
        fraction=1.0 if not geometry.events else (float(geometry.s[-1]) if done else 0.0),
        events=geometry.events,
        s=geometry.s,
        q=geometry.q,
    )


def _planar_check(
    robot: Robot, path: Path, s: np.ndarray, reach: tuple[float, float]
) -> Reachability:
    """Analytic check of a planar arm: annulus about the first joint, in its plane."""
    local, r, bad = _in_planar_frame(robot, path, s, reach)
    r_min, r_max = reach
    if not bad.any():
        return Reachability(True, Status.OK, 1.0, [], s, np.empty((0, robot.nq)))
    k = int(np.argmax(bad))
    position = path.position(s[k : k + 1])[0]
    if abs(local[k, 2]) > 1e-9:
        why = f"it is {local[k, 2]:.4f} m off the arm's plane"
    elif r[k] < r_min:
        why = f"its distance to the first joint, {r[k]:.4f} m, is inside the hole r < {r_min:.4f} m"
    else:
        why = f"its distance to the first joint, {r[k]:.4f} m, exceeds the reach {r_max:.4f} m"
    event = Event(
        Status.UNREACHABLE, 0.0, float(s[k]), k, f"{where(position)} is out of reach: {why}",
        position,
        remedy="shorten or move the path, or move the robot's base",
    )  # fmt: skip
    fraction = float(s[k - 1]) if k else 0.0
    return Reachability(
        False, Status.UNREACHABLE, fraction, [event], s[:k], np.empty((0, robot.nq))
    )


#: Arms whose closed form lists every IK branch of a full pose: 6 joints, and a closed form
#: (UR family, spherical wrists). A redundant arm's closed form (panda) fixes a joint, so its
#: "no solution" does not mean out of reach.
COMPLETE_CLOSED_FORM_JOINTS = 6


def unreachable_stretch(
    robot: Robot,
    path: Path,
    position_only: bool,
    start: float = 0.0,
    *,
    resolution: float = 0.005,
) -> OutOfReach | None:
    """The first stretch of ``path`` beyond fraction ``start`` that the arm cannot reach at all,
    decided exactly where the arm allows it: the annulus of a planar arm (position targets) or a
    6-joint arm's closed-form IK (every branch, within the joint limits; full poses). None when
    every checked point is reachable, or when the arm has neither (the numerical IK could only
    say that it did not find a solution).

    Used by :func:`cartesian.follow` to tell a refusal whose remedy cannot work (a path through
    the hole around a 2R arm's base or the column above a UR's) from one that a slower motion
    or another start would fix.

    Args:
        robot: The arm.
        path: The path, resolved for the task (:func:`resolve_task`).
        position_only: Whether the tool orientation is free.
        start: Path fraction from which to look [-].
        resolution: Spacing of the checked points along the path [m].
    """
    count = max(50, int(np.ceil(path.length * (1.0 - start) / resolution)) + 1)
    s = np.linspace(start, 1.0, count)
    reach = robot.planar_reach()
    if position_only and reach is not None:
        bad = _in_planar_frame(robot, path, s, reach)[2]
        if not bad.any():
            return None
        event = _planar_check(robot, path, s, reach).events[0]  # its reason, in words
        return OutOfReach(
            event.s, _stretch_end(s, bad, event.index), event.position,
            event.message.split("out of reach: ", 1)[-1],
        )  # fmt: skip
    solver = robot.closed_form_ik
    if position_only or solver is None or robot.nq != COMPLETE_CLOSED_FORM_JOINTS:
        return None
    rotations = path.rotation(s)
    if rotations is None:
        return None
    positions = path.position(s)
    solutions = solver.nearest_batch(positions, rotations, robot.neutral())
    bad = np.isnan(solutions).any(axis=1)
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    why = beyond_reach(robot, positions[k]) or (
        "no joint configuration within the limits puts the tool at this pose, on any branch"
    )
    return OutOfReach(float(s[k]), _stretch_end(s, bad, k), positions[k].copy(), why)


def _in_planar_frame(
    robot: Robot, path: Path, s: np.ndarray, reach: tuple[float, float]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The path's points in a planar arm's first-joint frame, their distance from its axis [m]
    and whether each is out of the annulus ``reach`` = (r_min, r_max) or off the plane."""
    base = robot.model.jointPlacements[1]
    local = (path.position(s) - base.translation) @ base.rotation
    r = np.hypot(local[:, 0], local[:, 1])
    bad = (r < reach[0] - 1e-9) | (r > reach[1] + 1e-9) | (np.abs(local[:, 2]) > 1e-9)
    return local, r, bad


def _stretch_end(s: np.ndarray, bad: np.ndarray, first: int) -> float:
    """Path fraction of the last point of the unreachable run that starts at index ``first``."""
    after = np.flatnonzero(~bad[first:])
    return float(s[first + after[0] - 1]) if after.size else float(s[-1])
