"""The configurations a seam planner chooses from: at every waypoint of the seam, every IK branch
for every sample of the free coordinates (roll about the torch axis, work and travel tilts
within their bands, the self-motion of a 7-joint arm), within the joint limits, away from
singularities (and collisions, with a cell).

Layout: a waypoint's candidates are indexed (slot, branch, roll): a *slot* is one sample of the
free coordinates that change the IK problem (tilts, self-motion, and the roll when it cannot be
factored out); *branch* one of the closed form's solutions; *roll* the roll samples that only
turn the last joint. When the arm's last joint turns the tool about its own z axis through the
TCP (UR family and panda with their default tools: :func:`roll_joint_sign`), rolling the tool by
ρ is turning that joint by ±ρ, so the IK runs once per slot and the roll samples come for free.

Closed forms: the UR family lists its 8 branches vectorised over poses
(``all_branches``); panda-type arms list the solutions for a given θ7 (``solutions_q7``), θ7
sampled as the self-motion. Other arms: :meth:`kinplan.Robot.ik_batch` from a fixed set of
seeds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kinplan.ik.base import ClosedFormIK
from kinplan.ik.batch import BatchKinematics
from kinplan.ik.panda import PandaIK
from kinplan.model.robot import Robot, manipulability_of

TAU = 2.0 * math.pi
#: Self-motion slots of a panda-type arm (roll factored) for the ends of the elbow's θ7
#: intervals at each pose, where joint 4 reaches a limit: a narrow interval (the elbow pinned
#: at its limit) falls between the uniform samples.
EDGE_SLOTS = 4
#: Joint-limit slack [rad] of a candidate (the closed forms' own).
LIMIT_SLACK = 1e-9


@dataclass
class Candidates:
    """Every waypoint's candidate configurations.

    Attributes:
        q: Joint values [rad] (K, S, B, I, nq): canonical (wide joints wrapped into [−π, π),
            the others the representative within their limits); NaN where there is none.
        valid: (K, S, B, I) candidates that exist, are within limits, non-singular (and
            collision-free).
        rest: q without the roll axis (K, S, B, nq) when the roll only turns the last joint
            (its last column then the value at roll 0), else q[..., 0, :].
        roll: Roll of each (slot, roll index) [rad] (S, I).
        tilt: (work, travel) of each slot [rad] (S, 2).
        manipulability: (K, S, B) (roll-independent when factored; else of roll 0).
        counts: Per waypoint, how many candidates survived each stage: "solved", "limits",
            "singular", "collision" (K,) each; and "limit_joint": (K, nq) how many solutions
            each joint put beyond its limits.
        pairs: Colliding body pairs (first pair of each colliding candidate) and their counts.
        limited_ik: Whether the IK lists only solutions within the joint limits (panda-type
            arms), so "solved" already counts those.
    """

    q: np.ndarray
    valid: np.ndarray
    rest: np.ndarray
    roll: np.ndarray
    tilt: np.ndarray
    manipulability: np.ndarray
    counts: dict[str, np.ndarray]
    pairs: dict[tuple[str, str], int] = field(default_factory=dict)
    limited_ik: bool = False


def _rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def roll_joint_sign(robot: Robot) -> int:
    """+1 or −1 when turning the last joint by δ turns the tool by ±δ about its own z axis
    through the TCP (checked by FK at three configurations), else 0."""
    if robot.nq < 6 or robot.prismatic[-1]:
        return 0
    rng = np.random.default_rng(7)
    lower, upper = (
        np.nan_to_num(robot.lower, neginf=-np.pi),
        np.nan_to_num(robot.upper, posinf=np.pi),
    )
    found = set()
    for _ in range(3):
        q = lower + (upper - lower) * rng.uniform(0.2, 0.8, robot.nq)
        base = robot.fk(q)
        moved = q.copy()
        moved[-1] += 0.3
        after = robot.fk(moved)
        for sign in (1, -1):
            c, s = math.cos(0.3 * sign), math.sin(0.3 * sign)
            rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            if (
                np.abs(after.translation - base.translation).max() < 1e-9
                and np.abs(after.rotation - base.rotation @ rz).max() < 1e-9
            ):
                found.add(sign)
    return found.pop() if len(found) == 1 else 0


def wide_joints(robot: Robot) -> np.ndarray:
    """(nq,) bool: revolute joints whose range exceeds a turn (several 2π-equivalents fit)."""
    span = robot.upper - robot.lower
    return (~robot.prismatic) & (span > TAU + 1e-9)


def canonical(q: np.ndarray, robot: Robot, wide: np.ndarray) -> np.ndarray:
    """Joint values (..., nq) as candidates hold them: wide joints wrapped into [−π, π), the
    others moved by whole turns into their limits (NaN where no equivalent is within them)."""
    lower, upper = robot.lower, robot.upper
    middle = np.where(np.isfinite(lower) & np.isfinite(upper), 0.5 * (lower + upper), 0.0)
    revolute = ~robot.prismatic
    shifted = np.where(revolute, q - TAU * np.round((q - middle) / TAU), q)
    inside = (shifted >= lower - LIMIT_SLACK) & (shifted <= upper + LIMIT_SLACK)
    out = np.where(inside, np.clip(shifted, lower, upper), np.nan)
    wrapped = (q + math.pi) % TAU - math.pi
    return np.where(wide, wrapped, out)


def _solve_slots(
    robot: Robot, positions: np.ndarray, rotations: np.ndarray, psi: np.ndarray, sign: int
) -> np.ndarray:
    """Every IK branch of poses (M, 3) / (M, 3, 3): (M, P, B, nq) raw solutions [rad] (any 2π
    representative, NaN rows where none), P the self-motion samples ``psi`` (one sample for
    arms without a searched self-motion).

    ψ of a panda-type arm is θ7 when the roll is not factored; when it is (``sign`` ≠ 0), ψ is
    the θ7 the arm would have at roll 0, any angle: the pose turned by −sign·(ψ − c) about its
    z is solved with θ7 = c (c mid-range), which gives the same first six joints, and the
    solution's θ7 is reported as ψ (the roll samples then add sign·ρ to it)."""
    solver = robot.closed_form_ik
    count = len(positions)
    if isinstance(solver, PandaIK):
        out = np.full((count, len(psi), 8, 7), np.nan)
        middle = 0.5 * float(robot.lower[-1] + robot.upper[-1])
        edge_slots = np.flatnonzero(np.isnan(psi))
        values = np.tile(psi, (count, 1))  # ψ per pose and slot
        if sign and len(edge_slots):
            for m in range(count):
                edges = _elbow_edges(solver, positions[m], rotations[m], sign, robot)
                values[m, edge_slots[: len(edges)]] = edges[: len(edge_slots)]
        for p in range(len(psi)):
            for m in range(count):
                value = float(values[m, p])
                if math.isnan(value):
                    continue
                if sign:
                    turned, at = rotations[m] @ _rz(-sign * (value - middle)), middle
                else:
                    turned, at = rotations[m], value
                found = solver.solutions_q7(positions[m], turned, at)
                out[m, p, : len(found)] = found[:8]
                if sign:
                    out[m, p, : len(found), -1] = value
        return out
    if isinstance(solver, ClosedFormIK) and robot.nq == 6:
        raw, _ = solver.all_branches(positions, rotations, np.zeros((count, robot.nq)))
        return raw[:, None]
    # any other arm: the numerical batch IK from a fixed spread of seeds
    seeds = _seeds(robot)
    targets = np.zeros((count, 4, 4))
    targets[:, :3, :3], targets[:, :3, 3], targets[:, 3, 3] = rotations, positions, 1.0
    out = np.full((count, 1, len(seeds), robot.nq), np.nan)
    for b, seed in enumerate(seeds):
        q, ok = robot.ik_batch(targets, q_seed=np.tile(seed, (count, 1)))
        out[ok, 0, b] = q[ok]
    return out


def _elbow_edges(
    solver: PandaIK, position: np.ndarray, rotation: np.ndarray, sign: int, robot: Robot
) -> list[float]:
    """The ψ values [rad] (θ7 at roll 0, any angle) where the elbow joint reaches a limit for
    this pose, 1e-6 rad inside the ranges where it is within them, sorted: the ends of the
    panda closed form's θ7 intervals (:meth:`~kinplan.ik.panda.PandaIK.elbow_q7_intervals`), for
    the pose and for the pose turned half a turn (θ7's range is not a whole turn)."""
    lo7, hi7 = float(robot.lower[-1]), float(robot.upper[-1])
    edges: set[float] = set()
    for shift in (0.0, math.pi):
        turned = rotation @ _rz(-sign * shift)  # (P·Rz(ρ), θ7 = ψ + sign·ρ): ψ = θ7 + shift
        intervals = solver.elbow_q7_intervals(position, turned)
        for start, end in intervals:
            for value, inward in ((start, 1e-6), (end, -1e-6)):
                if lo7 + 1e-9 < value < hi7 - 1e-9:  # the elbow's end, not θ7's own limit
                    edges.add(round((value + inward + shift + math.pi) % TAU - math.pi, 9))
    return sorted(edges)


def _seeds(robot: Robot, count: int = 8) -> np.ndarray:
    lower, upper = (
        np.nan_to_num(robot.lower, neginf=-np.pi),
        np.nan_to_num(robot.upper, posinf=np.pi),
    )
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    steps = (np.arange(count)[:, None] * golden * (1.0 + np.arange(robot.nq))[None]) % 1.0
    return lower + (upper - lower) * (0.15 + 0.7 * steps)


def self_motion_samples(robot: Robot, count: int, factored: bool) -> np.ndarray:
    """Self-motion samples ψ [rad] of a panda-type arm (one NaN for other arms): θ7 within
    its limits, or, when the roll is factored, the roll-0 θ7 all round [−π, π)."""
    if not isinstance(robot.closed_form_ik, PandaIK):
        return np.array([np.nan])
    if factored:  # the uniform samples, then slots for the elbow's ends (NaN: per pose)
        uniform = -math.pi + TAU * np.arange(count) / count
        return np.concatenate([uniform, np.full(EDGE_SLOTS, np.nan)])
    lo, hi = float(robot.lower[-1]), float(robot.upper[-1])
    return lo + (hi - lo) * (np.arange(count) + 0.5) / count


def generate(
    robot: Robot,
    positions: np.ndarray,
    rotations: np.ndarray,
    slot_tilt: np.ndarray,
    slot_roll: np.ndarray,
    psi: np.ndarray,
    roll_samples: np.ndarray,
    sign: int,
    singular_threshold: float,
) -> Candidates:
    """The candidates of every waypoint.

    Args:
        positions: Waypoint tool positions [m] (K, 3).
        rotations: Waypoint tool rotations for every tilt slot (K, T, 3, 3), roll 0 when the
            roll is factored (``sign`` ≠ 0), else already rolled by ``slot_roll``.
        slot_tilt: (work, travel) [rad] of each of the T rotation slots (T, 2).
        slot_roll: Roll [rad] of each of the T rotation slots (T,) (0 when factored).
        psi: Self-motion samples (P,) (:func:`self_motion_samples`).
        roll_samples: Roll samples that turn the last joint [rad] (I,) (``[0]`` when not
            factored).
        sign: :func:`roll_joint_sign`.
        singular_threshold: Manipulability below which a candidate is singular.
    """
    count, tilts = rotations.shape[:2]
    nq = robot.nq
    raw = _solve_slots(
        robot, np.repeat(positions, tilts, axis=0), rotations.reshape(-1, 3, 3), psi, sign
    )  # (K·T, P, B, nq)
    branches = raw.shape[2]
    raw = raw.reshape(count, tilts, len(psi), branches, nq).reshape(count, -1, branches, nq)
    slots = raw.shape[1]
    wide = wide_joints(robot)
    solved = np.all(np.isfinite(raw), axis=-1)  # (K, S, B)
    # the roll turns the last joint: q_last = value at roll 0 + sign · roll
    rolls = len(roll_samples)
    q = np.repeat(raw[:, :, :, None, :], rolls, axis=3)
    q[..., -1] += sign * roll_samples
    q = canonical(q, robot, wide)
    within = np.all(np.isfinite(q), axis=-1) & solved[..., None]
    rest = canonical(raw, robot, wide)
    rest[..., -1] = np.where(solved, raw[..., -1], np.nan)
    # which joints put the solutions beyond their limits (for the refusal's message)
    beyond = solved[..., None, None] & ~np.isfinite(q)  # (K, S, B, I, nq)
    limit_joint = beyond.reshape(count, -1, nq).sum(axis=1)
    # manipulability: roll-independent when the roll only turns the last joint
    manip = np.zeros((count, slots, branches))
    flat = rest.reshape(-1, nq)
    good = np.all(np.isfinite(flat), axis=1) if sign else solved.reshape(-1)
    kinematics = BatchKinematics.of(robot)
    if good.any():
        sample = (
            np.nan_to_num(flat[good])
            if sign
            else np.nan_to_num(q[:, :, :, 0].reshape(-1, nq)[good])
        )
        if kinematics is not None:
            _, _, J = kinematics.fk_jacobian(sample)
        else:
            J = np.array([robot.jacobian(x) for x in sample])
        values = np.zeros(len(flat))
        values[good] = manipulability_of(J, robot.task_rank(False))
        manip = values.reshape(count, slots, branches)
    regular = manip > singular_threshold
    valid = within & regular[..., None]
    roll = np.repeat(slot_roll, len(psi))[:, None] + roll_samples[None, :]
    tilt = np.repeat(slot_tilt, len(psi), axis=0)
    counts = {
        "solved": solved.sum(axis=(1, 2)) * rolls,
        "limits": within.sum(axis=(1, 2, 3)),
        "singular": valid.sum(axis=(1, 2, 3)),
        "collision": valid.sum(axis=(1, 2, 3)),
        "limit_joint": limit_joint,
    }
    limited = isinstance(robot.closed_form_ik, PandaIK)
    return Candidates(q, valid, rest, roll, tilt, manip, counts, limited_ik=limited)
