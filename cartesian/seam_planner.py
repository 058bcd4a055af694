"""Seam planning with tolerances: the joint motion through a weld seam, not only its following.

A welding torch is symmetric about its axis, and its work and travel angles have tolerance bands:
the seam fixes the TCP position and, within those bands, the torch axis (tool z). :func:`plan_seam`
searches the free coordinates globally, as Descartes does (ROS-Industrial; its ladder graph):

1. waypoints along the seam (every ``waypoint_spacing`` metres and every ``resolution`` radians
   of the path's rotation); at each, the roll about the torch axis (every ``resolution``
   radians, or the given roll), the work / travel tilts (−tol, 0, +tol each), a 7-joint arm's
   self-motion (θ7 samples) × every IK branch give the candidate configurations within the
   joint limits, away from singularities (:mod:`cartesian.seam_candidates`); in a cell, the
   candidates the search's paths use are checked against it, lazily (:mod:`cartesian.
   seam_cell`);
2. the ladder graph joins consecutive waypoints' candidates whose joint motion fits the time
   between them at the seam's speed (the joints' speed limits), without a branch flip, with the
   roll changing by a bounded step; dynamic programming finds the path of least joint travel
   (plus small costs for roll changes, tilt, and nearness to singularities) in which joints that
   can wind stay within their limits (:mod:`cartesian.seam_ladder`);
3. the chosen roll and tilt become smooth laws of s (cubic splines, continuous rate), applied to
   the seam's poses (:class:`~cartesian.seam_path.SeamPath`), and :func:`cartesian.follow` tracks
   that path from the chosen start configuration and monitors it as always: the result is an
   ordinary :class:`~cartesian.CartesianPlan`, with ``roll`` and ``tilt`` per sample. A 7-joint
   arm's follower resolves the self-motion its own way (minimum-norm rates: the least joint
   motion where it works); where that fails, the ladder path is tracked with the self-motion
   the search chose (:mod:`cartesian.seam_self_motion`, not with ``retime``).

When no torch orientation within the tolerances works somewhere, the refused plan says where
(the ``s`` range) and what blocks it; when configurations exist but cannot be joined, between
which fractions and why.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from cartesian import seam_cell, seam_self_motion
from cartesian.events import Status
from cartesian.follow import follow
from cartesian.geometry import check_reachability
from cartesian.paths import Path
from cartesian.plan import CartesianPlan
from cartesian.seam_candidates import (
    TAU,
    generate,
    roll_joint_sign,
    self_motion_samples,
    wide_joints,
)
from cartesian.seam_cell import CellVerdict
from cartesian.seam_ladder import Ladder, LadderPath
from cartesian.seam_path import (
    CachedPath,
    SeamPath,
    SmoothLaw,
    seam_frames,
    tilt_rotations,
    torch_deviation,
)
from cartesian.seam_refusals import SPEED_MARGIN, blocked_event, empty_stretch, refused
from cartesian.timing import time_path
from cartesian.tracker import SINGULAR_FRACTION
from kinplan import checks
from kinplan.cell import WorkCell
from kinplan.errors import InputError
from kinplan.model.robot import Robot

__all__ = ["plan_seam"]

logger = logging.getLogger(__name__)

#: Candidates this many times the follower's singularity threshold or nearer to a singularity
#: are left out (the ladder's cost keeps its paths farther away).
SINGULAR_MARGIN = 1.05
#: Largest joint change between waypoints [rad]: more is a branch flip.
JUMP_CAP = math.pi / 3
#: How many ladder paths (distinct start candidates) are tracked before giving up.
ATTEMPTS = 4
#: Constant-roll paths of the ladder tracked when its best paths could not be.
FALLBACKS = 8
#: Constant-roll attempts (screened) after those (see _constant_roll_choices), and how many
#: start candidates per roll.
SWEEP = 16
START_CANDIDATES = 3
#: Other start configurations of a redundant arm tried with the best roll law.
OTHER_STARTS = 6
#: Distance [m] / angle [rad] within which ``q_start`` counts as on the path's start.
START_TOLERANCE = 1e-5
#: Options of :func:`follow` that plan_seam sets itself.
_OWN_OPTIONS = ("q_seed", "position_only", "duration", "speed", "dt", "retime", "cell", "clearance")


def plan_seam(
    robot: Robot,
    path: Path,
    speed: float | None = None,
    duration: float | None = None,
    dt: float = 0.01,
    *,
    roll: str | float = "free",
    work_tolerance: float = 0.0,
    travel_tolerance: float = 0.0,
    q_start: Sequence[float] | np.ndarray | None = None,
    cell: WorkCell | None = None,
    clearance: float | None = None,
    retime: bool = False,
    resolution: float = math.radians(10.0),
    waypoint_spacing: float = 0.02,
    self_motion: int = 24,
    **follow_options: Any,
) -> CartesianPlan:
    """Plan the torch along a seam with its roll free and its angles within tolerance bands.

    Args:
        robot: The arm (6 or more joints; the search is fastest with a closed-form IK: the UR
            family, panda-type arms).
        path: The seam with orientation: its poses give the TCP position and the torch axis
            (tool z) in the base (world) frame; e.g. :class:`cartesian.TorchOrientation`.
        speed: Tool cruise speed [m/s]; or
        duration: Motion duration [s] (exactly one of the two).
        dt: Sampling period [s] of the plan (as :func:`cartesian.follow`).
        roll: "free": the rotation about the torch axis is searched and may vary along the
            seam; a number [rad]: that constant roll, relative to the path's poses.
        work_tolerance: Band [rad] in [0, π/2) within which the torch axis may tilt across the
            seam (about its travel direction).
        travel_tolerance: Band [rad] in [0, π/2) within which it may tilt along the seam.
        q_start: The configuration the plan must start from (on the path's start pose, torch
            within the tolerances), or None: any.
        cell: A :class:`kinplan.WorkCell`: candidates collide with nothing in it, and the plan
            is checked as :func:`cartesian.follow` checks it.
        clearance: Margin [m] to the cell's obstacles (as :func:`cartesian.follow`).
        retime: Time the chosen path optimally (as :func:`cartesian.follow`); the search then
            ignores the seam's nominal speed.
        resolution: Roll sampling step and the path rotation between waypoints [rad]
            (default 10°).
        waypoint_spacing: Largest distance between waypoints along the seam [m].
        self_motion: θ7 samples of a panda-type arm's self-motion.
        **follow_options: Passed to :func:`cartesian.follow` (``profile``, ``acceleration``,
            ``velocity_scale``, ``tolerance``, ``max_acceleration``, ...).

    Returns:
        A :class:`~cartesian.CartesianPlan` of the rotated seam
        (:class:`~cartesian.seam_path.SeamPath`) with ``roll`` ((N,) rad, about the torch axis,
        relative to the path's poses) and ``tilt`` ((N, 2) rad: work, travel deviation) per
        sample; when refused, an event says where and why (no samples when the search itself
        found no way).

    Raises:
        InputError: a path without orientation, tolerances outside [0, π/2), an unknown
            ``roll``, a ``q_start`` off the path's start, or options plan_seam sets itself.
    """
    _check_inputs(robot, path)
    free = _roll_mode(roll)
    work_tolerance = _tolerance(work_tolerance, "work_tolerance")
    travel_tolerance = _tolerance(travel_tolerance, "travel_tolerance")
    resolution = checks.number(resolution, "resolution", positive=True, unit="rad")
    waypoint_spacing = checks.number(waypoint_spacing, "waypoint_spacing", positive=True, unit="m")
    self_motion = checks.count(self_motion, "self_motion", minimum=1)
    dt = checks.number(dt, "dt", positive=True, unit="s")
    retime = checks.flag(retime, "retime")
    for name in _OWN_OPTIONS:
        if name in follow_options:
            raise InputError(
                f"plan_seam sets {name} itself; pass q_start= for the start configuration, and "
                "speed, duration, dt, retime, cell, clearance as its own arguments"
            )
    fixed_roll = None if free else float(roll)
    start = None if q_start is None else robot.check_q(q_start, "q_start")
    profile = follow_options.get("profile", "trapezoid")
    timing = time_path(
        path.length, duration, speed, follow_options.get("acceleration"), profile, dt
    )
    s = _waypoints(path, waypoint_spacing, resolution)
    rotations = path.rotation(s)
    assert rotations is not None  # checked oriented
    frames = seam_frames(path, s, rotations)
    start_roll, start_tilt = 0.0, np.zeros(2)
    if start is not None:
        start_roll, start_tilt = _start_angles(robot, path, start, work_tolerance, travel_tolerance)
        if fixed_roll is not None and abs(_wrap(start_roll - fixed_roll)) > 1e-6:
            raise InputError(
                f"q_start turns the torch by {math.degrees(start_roll):.2f}° about its axis, but "
                f"roll={fixed_roll:g} rad ({math.degrees(fixed_roll):.2f}°) was asked; pass "
                "roll='free' or a q_start with that roll"
            )
    velocity_scale = float(follow_options.get("velocity_scale", 1.0))
    singular_threshold = follow_options.get("singular_threshold")
    if singular_threshold is None:
        singular_threshold = SINGULAR_FRACTION * robot.reference_manipulability(False)
    ladder = _build_ladder(
        robot, path, s, rotations, frames, timing, free, fixed_roll, resolution,
        work_tolerance, travel_tolerance, self_motion, SINGULAR_MARGIN * float(singular_threshold),
        velocity_scale, retime,
    )  # fmt: skip
    # the cell is asked only about the candidates the search's paths use (seam_cell)
    verdict = None if cell is None else CellVerdict(ladder.candidates, cell, robot, clearance)
    if start is not None:
        ladder.start, ladder.start_roll, ladder.start_tilt = start, start_roll, start_tilt
    empty = empty_stretch(ladder, s, start is not None, list(robot.joint_names))
    if empty is not None:
        return refused(robot, path, empty, float(singular_threshold))
    paths, blocked = seam_cell.solve(ladder, verdict, ATTEMPTS)
    if verdict is not None and verdict.complete:  # no way through: is a stretch blocked?
        empty = empty_stretch(ladder, s, start is not None, list(robot.joint_names))
        if empty is not None:
            return refused(robot, path, empty, float(singular_threshold))
    too_fast = blocked is not None and blocked.kind == "velocity_limit"
    if too_fast:
        # the speed caps are the search's estimate: follow judges the speed itself
        caps = ladder.caps
        ladder.caps = np.broadcast_to(ladder.jump_caps, caps.shape).copy()
        paths, _ = seam_cell.solve(ladder, verdict, ATTEMPTS)
        ladder.caps = caps
    cached = CachedPath(path)  # every attempt rotates the same seam on the same grids
    track: dict[str, Any] = dict(
        start=start, speed=speed, duration=duration, dt=dt, retime=retime, cell=cell,
        clearance=clearance, work_tolerance=work_tolerance, travel_tolerance=travel_tolerance,
        follow_options=follow_options,
    )  # fmt: skip
    first: CartesianPlan | None = None
    # the grid may miss a way (the self-motion between its samples, a law smoothed away from
    # the nodes): then constant rolls that have candidates at every waypoint, from their starts
    # (computed only when the ladder's paths cannot be tracked)
    # (the fallbacks read every candidate: the cell checks them all first)
    others = _lazy(
        lambda: _other_starts(ladder, paths[0] if paths else None, OTHER_STARTS), verdict
    )
    choices = itertools.chain(
        paths,
        others,
        _lazy(lambda: _constant_roll_paths(ladder)),
        _constant_roll_choices(robot, path, ladder, s, start),
    )
    for choice in choices:
        # the first attempt in full (its events say why, if all fail); the others screened
        plan = _track(robot, cached, s, choice, **track, screen=first is not None)
        if plan is None:
            continue
        if plan.ok:
            return plan
        logger.debug("seam tracking from ladder path of cost %.3f: %s", choice.cost, plan.status)
        first = first or plan
        if too_fast and plan.status in (Status.VELOCITY_LIMIT, Status.ACCELERATION_LIMIT):
            break  # the ladder found the seam too fast, and the follower agrees: no sweep
    if blocked is None:
        assert first is not None  # the ladder's best path was tracked, and failed
        return first
    # the search found no way through: the ladder says where and why (the constant rolls
    # tried after it found none either)
    event = blocked_event(robot, blocked, s, timing)
    return refused(robot, path, event, float(singular_threshold))


def _lazy(
    make: Callable[[], list[LadderPath]], verdict: CellVerdict | None = None
) -> Iterator[LadderPath]:
    """The paths ``make`` gives, made when first asked for (after checking every candidate
    against the cell, with a ``verdict``)."""
    if verdict is not None:
        verdict.check_all()
    yield from make()


def _constant_roll_paths(ladder: Ladder) -> list[LadderPath]:
    """The ladder's least-cost paths that keep their start roll (one per roll, best first, up
    to :data:`FALLBACKS`): a constant roll is the simplest law to track."""
    if not ladder.factored or ladder.roll_steps == 0:
        return []
    steps, ladder.roll_steps = ladder.roll_steps, 0
    try:
        paths, _ = ladder.solve(4 * FALLBACKS)
    finally:
        ladder.roll_steps = steps
    chosen: dict[float, LadderPath] = {}
    for candidate in paths:
        key = round(float(candidate.roll[0]), 6)
        if key not in chosen:
            chosen[key] = candidate
    return list(chosen.values())[:FALLBACKS]


def _other_starts(ladder: Ladder, best: LadderPath | None, count: int) -> list[LadderPath]:
    """``best`` (its roll and tilt laws) from up to ``count`` other start candidates of the same
    start roll and tilt, nearest its own start first (a redundant arm's only: a 6-joint arm's
    follower has no self-motion to resolve otherwise)."""
    c = ladder.candidates
    K, S, B, I = c.valid.shape
    if best is None or ladder.start is not None or c.q.shape[-1] < 7 or best.nodes[0] < 0:
        return []
    slot, _, i = np.unravel_index(int(best.nodes[0]), (S, B, I))
    same = np.isclose(c.roll, c.roll[slot, i]) & np.all(c.tilt == c.tilt[slot], axis=1)[:, None]
    nodes = np.argwhere(same[:, None, :] & c.valid[0])
    q = c.q[0][tuple(nodes.T)]
    order = np.argsort(np.abs(q - best.q[0]).sum(axis=1))[1 : count + 1]
    return [
        LadderPath(
            best.nodes,
            np.vstack([q[j], best.q[1:]]),
            best.roll,
            best.tilt,
            best.cost,
            searched=False,
        )
        for j in order.tolist()
    ]


def _constant_roll_choices(
    robot: Robot, path: Path, ladder: Ladder, s: np.ndarray, start: np.ndarray | None
) -> Iterator[LadderPath]:
    """Up to :data:`SWEEP` constant-roll attempts without tilt, as a brute-force search makes
    them but in a better order: the rolls with a candidate at every waypoint, nearest the taught
    roll first; first from each roll's IK solution nearest the arm's neutral configuration,
    then from its start candidates (every branch and self-motion sample), farthest from
    singularities first. Generated lazily: each is made when the one before has failed."""
    c = ladder.candidates
    K, S, B, I = c.valid.shape
    untilted = np.flatnonzero(~c.tilt.any(axis=1))
    if start is not None or not untilted.size:
        return
    valid = c.valid[:, untilted]  # (K, S0, B, I)
    rolls = c.roll[untilted]  # (S0, I)
    values = np.unique(np.round(rolls, 9))
    masks = [np.isclose(rolls, r) for r in values]
    everywhere = [
        (r, mask)
        for r, mask in zip(values.tolist(), masks)
        if (valid & mask[None, :, None, :]).any(axis=(1, 2, 3)).all()
    ]
    everywhere.sort(key=lambda item: abs(_wrap(item[0])))
    rotation = path.rotation(np.zeros(1))
    assert rotation is not None
    position = path.position(np.zeros(1))[0]

    def attempt(q: np.ndarray, r: float) -> LadderPath:
        return LadderPath(
            np.zeros(K, int),
            np.tile(q, (K, 1)),
            np.full(K, r),
            np.zeros((K, 2)),
            0.0,
            searched=False,
        )

    made = 0
    for r, _ in everywhere:  # pass 1: the start a person would take, per roll
        cr, sr = math.cos(r), math.sin(r)
        turned = rotation[0] @ np.array([[cr, -sr, 0.0], [sr, cr, 0.0], [0.0, 0.0, 1.0]])
        home = robot.ik(pin.SE3(turned, position), q_seed=robot.neutral())
        if home.success:
            yield attempt(home.q, r)
            made += 1
            if made >= SWEEP // 2:
                break
    for r, mask in everywhere:  # pass 2: the candidates of the first waypoint
        nodes = np.argwhere(mask[:, None, :] & valid[0])
        manipulability = c.manipulability[0, untilted][nodes[:, 0], nodes[:, 1]]
        for slot, b, i in nodes[np.argsort(-manipulability)][:START_CANDIDATES].tolist():
            yield attempt(c.q[0, untilted[slot], b, i], r)
            made += 1
            if made >= SWEEP:
                return


# ------------------------------------------------------------------------------ inputs
def _check_inputs(robot: object, path: object) -> None:
    if not isinstance(robot, Robot):
        raise InputError(
            f"robot must be a kinplan.Robot (from kinplan.load_robot), got {checks.describe(robot)}"
        )
    if not isinstance(path, Path):
        raise InputError(
            "path must be a cartesian path with orientation (cartesian.TorchOrientation, or a "
            f"Line / Arc / Polyline of SE3 poses), got {checks.describe(path)}"
        )
    if robot.nq < 6:
        raise InputError(
            f"plan_seam needs an arm with 6 or more joints (the torch axis and position fix 5 "
            f"coordinates), {robot.name} has {robot.nq}; use cartesian.follow instead"
        )
    if not path.has_orientation:
        raise InputError(
            "plan_seam needs a path with orientation: its poses give the torch axis (tool z). "
            "Build it from SE3 poses, or wrap the seam in cartesian.TorchOrientation(path, "
            "normal, work_angle, travel_angle)"
        )
    if path.length <= 0:
        raise InputError("plan_seam needs a seam of non-zero length")


def _roll_mode(roll: object) -> bool:
    """True for a free roll; checks a fixed one."""
    if isinstance(roll, str):
        if roll == "free":
            return True
        raise InputError(
            f"roll must be 'free' (searched along the seam) or a number [rad] (a constant roll "
            f"relative to the path's poses), got {roll!r}"
        )
    checks.number(roll, "roll", unit="rad")
    return False


def _tolerance(value: object, name: str) -> float:
    tolerance = checks.number(value, name, unit="rad")
    if not 0.0 <= tolerance < 0.5 * math.pi:
        raise InputError(
            f"{name} must be an angle in [0, π/2) rad (0 to below 90°), got {tolerance!r} rad "
            f"({math.degrees(tolerance):.1f}°); e.g. {name}=math.radians(10)"
        )
    return tolerance


def _wrap(angle: float) -> float:
    return (angle + math.pi) % TAU - math.pi


def _start_angles(
    robot: Robot, path: Path, q: np.ndarray, work_tolerance: float, travel_tolerance: float
) -> tuple[float, np.ndarray]:
    """Roll [rad] and (work, travel) [rad] of ``q`` on the path's start pose.

    Raises:
        InputError: ``q`` puts the TCP off the start, or the torch axis beyond the tolerances.
    """
    pose = robot.fk(q)
    s0 = np.array([0.0])
    target = path.position(s0)[0]
    rotation = path.rotation(s0)
    assert rotation is not None
    gap = float(np.linalg.norm(pose.translation - target))
    if gap > START_TOLERANCE:
        raise InputError(
            f"q_start puts the TCP {gap * 1e3:.3f} mm from the seam's start "
            f"{np.round(target, 4).tolist()} m; pass a configuration on it "
            "(e.g. robot.ik(path.start)) or q_start=None"
        )
    frames = seam_frames(path, s0, rotation)
    work, travel = torch_deviation(frames, pose.rotation[None, :, 2])[0]
    for name, value, band in (("work", work, work_tolerance), ("travel", travel, travel_tolerance)):
        if abs(value) > band + START_TOLERANCE:
            raise InputError(
                f"q_start tilts the torch {math.degrees(value):.2f}° ({name}) from the seam's "
                f"torch axis, beyond {name}_tolerance = {math.degrees(band):.2f}°; pass a "
                f"configuration with the torch within the band, a wider {name}_tolerance, or "
                "q_start=None"
            )
    tilted = tilt_rotations(frames, np.array([work]), np.array([travel]))[0] @ rotation[0]
    turn = tilted.T @ pose.rotation
    return float(math.atan2(turn[1, 0], turn[0, 0])), np.array([work, travel])


# ------------------------------------------------------------------------------ the ladder
def _waypoints(path: Path, spacing: float, angle: float) -> np.ndarray:
    """Waypoint fractions: at most ``spacing`` [m] and ``angle`` [rad] of rotation apart."""
    fine = np.linspace(0.0, 1.0, 257)
    rotations = path.rotation(fine)
    assert rotations is not None
    relative = np.einsum("nji,njk->nik", rotations[:-1], rotations[1:])
    cos = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    turn = float(np.arccos(cos).sum())
    count = max(2, math.ceil(path.length / spacing), math.ceil(turn / angle))
    return np.linspace(0.0, 1.0, count + 1)


def _build_ladder(
    robot: Robot,
    path: Path,
    s: np.ndarray,
    rotations: np.ndarray,
    frames: np.ndarray,
    timing: Any,
    free: bool,
    fixed_roll: float | None,
    resolution: float,
    work_tolerance: float,
    travel_tolerance: float,
    self_motion: int,
    singular_threshold: float,
    velocity_scale: float,
    retime: bool,
) -> Ladder:
    """The candidates of every waypoint and the graph's settings."""
    count = len(s)
    if free:
        rolls = int(max(1, round(TAU / resolution)))
        roll_values = -math.pi + TAU * np.arange(rolls) / rolls
    else:
        assert fixed_roll is not None
        roll_values = np.array([fixed_roll])
    works = np.array([-work_tolerance, 0.0, work_tolerance]) if work_tolerance > 0 else np.zeros(1)
    travels = (
        np.array([-travel_tolerance, 0.0, travel_tolerance])
        if travel_tolerance > 0
        else np.zeros(1)
    )
    sign = roll_joint_sign(robot) if free else 0
    factored = sign != 0
    roll_axis = roll_values if factored else np.zeros(1)
    slot_rolls = np.zeros(1) if factored else roll_values
    # rotation slots: (roll slot, work, travel), coordinates for the adjacency
    grid = np.stack(
        np.meshgrid(np.arange(len(slot_rolls)), np.arange(len(works)), np.arange(len(travels)),
                    indexing="ij"),
        axis=-1,
    ).reshape(-1, 3)  # fmt: skip
    slot_roll = slot_rolls[grid[:, 0]]
    slot_tilt = np.stack([works[grid[:, 1]], travels[grid[:, 2]]], axis=1)
    T = len(grid)
    tilt = tilt_rotations(
        np.repeat(frames, T, axis=0),
        np.tile(slot_tilt[:, 0], count),
        np.tile(slot_tilt[:, 1], count),
    ).reshape(count, T, 3, 3)
    c, sn = np.cos(slot_roll), np.sin(slot_roll)
    rz = np.zeros((T, 3, 3))
    rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = c, -sn, sn, c, 1.0
    targets = tilt @ rotations[:, None] @ rz[None]
    psi = self_motion_samples(robot, self_motion, factored)
    candidates = generate(
        robot, path.position(s), targets, slot_tilt, slot_roll, psi, roll_axis, sign,
        singular_threshold,
    )  # fmt: skip
    # slot adjacency: the roll slot by up to `steps`, tilts and self-motion by one
    # (the elbow-end slots of a panda-type arm, NaN in psi, neighbour every ψ slot)
    P, uniform = len(psi), int(np.isfinite(psi).sum())
    coords = np.concatenate([np.repeat(grid, P, axis=0), np.tile(np.arange(P), T)[:, None]], axis=1)
    edge = np.tile(np.isnan(psi), T)
    steps = 2 if free else 0
    diff = np.abs(coords[:, None, :] - coords[None, :, :])
    if not factored and free and len(slot_rolls) > 1:
        diff[..., 0] = np.minimum(diff[..., 0], len(slot_rolls) - diff[..., 0])
    if factored and uniform > 1:  # ψ goes all round
        diff[..., 3] = np.minimum(diff[..., 3], uniform - diff[..., 3])
    diff[edge, :, 3] = diff[:, edge, 3] = 0
    near = np.all(diff[..., 1:3] <= 1, axis=-1) & (diff[..., 3] <= 2)
    near &= diff[..., 0] <= (0 if factored else steps)
    adjacency = np.argwhere(near)
    # caps: the joints' speed over the time between waypoints, and the jump cap
    t_at = np.interp(s, timing.s, timing.t)
    gaps = np.diff(t_at)
    speed_caps = SPEED_MARGIN * velocity_scale * robot.velocity_limit[None, :] * gaps[:, None]
    jump_caps = np.full(robot.nq, JUMP_CAP)
    caps = jump_caps[None, :] if retime else np.minimum(speed_caps, jump_caps[None, :])
    caps = np.broadcast_to(caps, (count - 1, robot.nq)).copy()
    return Ladder(
        candidates, adjacency, steps if factored else 0, free and factored, caps, jump_caps,
        wide_joints(robot), robot.lower, robot.upper, factored,
        robot.reference_manipulability(False),
    )  # fmt: skip


# ------------------------------------------------------------------------------ tracking
def _law(s: np.ndarray, values: np.ndarray, start: float | None, bound: float | None) -> SmoothLaw:
    law = SmoothLaw(s, values)
    if bound is not None:
        law.scaled_into(bound, start)
    elif start is not None:
        law.anchor(start)
    return law


def _track(
    robot: Robot,
    path: Path,
    s: np.ndarray,
    choice: LadderPath,
    start: np.ndarray | None,
    speed: float | None,
    duration: float | None,
    dt: float,
    retime: bool,
    cell: WorkCell | None,
    clearance: float | None,
    work_tolerance: float,
    travel_tolerance: float,
    follow_options: dict[str, Any],
    screen: bool = False,
) -> CartesianPlan | None:
    """Follow the seam rotated by the ladder path's smoothed roll and tilt laws; ``screen``:
    skip :func:`cartesian.follow` when the geometric pre-check (:func:`cartesian.
    check_reachability`, no timing) already fails from that start. A redundant arm's ladder
    path that follow cannot track is then followed with its self-motion as the search chose it
    (:mod:`cartesian.seam_self_motion`). None when neither was planned (screened out)."""
    anchor = start is not None
    roll = _law(s, choice.roll, choice.roll[0] if anchor else None, None)
    work = _law(s, choice.tilt[:, 0], choice.tilt[0, 0] if anchor else None, work_tolerance)
    travel = _law(s, choice.tilt[:, 1], choice.tilt[0, 1] if anchor else None, travel_tolerance)
    seam = SeamPath(path, roll, work, travel)
    seed = choice.q[0] if start is None else start
    plan = None
    if not screen or check_reachability(robot, seam, q_seed=seed).ok:
        plan = follow(
            robot, seam, duration=duration, speed=speed, dt=dt, q_seed=seed, retime=retime,
            cell=cell, clearance=clearance, **follow_options,
        )  # fmt: skip
        plan.roll = seam.roll(plan.s) if len(plan.s) else np.zeros(0)
        plan.tilt = seam.tilt(plan.s) if len(plan.s) else np.zeros((0, 2))
        if plan.ok:
            return plan
    if choice.searched and seam_self_motion.tracks_self_motion(robot) and not retime:
        # a redundant arm: follow resolved its self-motion its own way (minimum-norm rates)
        # and ran into something the search avoided: the self-motion as the search chose it
        tracked = _self_motion_plan(
            robot, s, choice, start, (speed, duration, dt, cell, clearance), seam,
            follow_options,
        )  # fmt: skip
        if tracked is not None:
            return tracked
    return plan


def _self_motion_plan(
    robot: Robot,
    s: np.ndarray,
    choice: LadderPath,
    start: np.ndarray | None,
    motion: tuple[float | None, float | None, float, WorkCell | None, float | None],
    seam: SeamPath,
    follow_options: dict[str, Any],
) -> CartesianPlan | None:
    """``seam`` (the path rotated by the ladder path's smoothed laws) followed with the
    self-motion pulled toward the ladder path's configurations
    (:mod:`cartesian.seam_self_motion`), or None when that is not clean.
    ``motion``: (speed, duration, dt, cell, clearance)."""
    speed, duration, dt, cell, clearance = motion
    seed = choice.q[0] if start is None else start
    plan = seam_self_motion.track(
        robot, seam, s, choice.q, seed, speed, duration, dt, cell, clearance, follow_options
    )
    if plan is not None:
        plan.roll, plan.tilt = seam.roll(plan.s), seam.tilt(plan.s)
    return plan
