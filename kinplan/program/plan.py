"""A planned motion and what each move did: :class:`ProgramPlan` and :class:`MoveReport`.

A :class:`ProgramPlan` is the whole motion of a program (or of a
:class:`~kinplan.program.MotionBuilder`) as samples and as a
:class:`~kinplan.trajectory.Trajectory`, with the tool states of every sample and one
:class:`MoveReport` per move.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

import cartesian
from kinplan.cell import MotionCheck, WorkCell
from kinplan.model.robot import Robot, manipulability_of
from kinplan.program.peaks import segment_peaks
from kinplan.program.schema import DEFAULT_DT, IoEvent, Program
from kinplan.program.segments import hermite_segments
from kinplan.trajectory import Segment, Trajectory, Waypoints
from kinplan.trajectory.motion import MotionKind, PlannedPath, pose_to_track

__all__ = ["MoveReport", "ProgramPlan", "move_span"]

_MOVE_KEY = re.compile(r"^moves\[(\d+)(?:\.\.(\d+))?\](\.dwell)?$")


def move_span(key: str | None) -> tuple[int, int] | None:
    """The 1-based numbers of the program moves a report stands for, from its key.

    ``moves[2]`` → (3, 3); ``moves[6..9]`` (moves blended into one motion) → (7, 10); a
    dwell (``moves[2].dwell``) belongs to its move: (3, 3). None for keys of moves built in
    Python (no program) or anything else.
    """
    match = _MOVE_KEY.match(key or "")
    if match is None:
        return None
    first = int(match.group(1)) + 1
    return first, (int(match.group(2)) + 1 if match.group(2) else first)


@dataclass
class MoveReport:
    """What one move did.

    Attributes:
        number: 1-based move number.
        kind: ``ptp``, ``lin``, ``circ`` or ``path``.
        label: Short description (``lin to b``).
        key: Key path in the program (``moves[2]``), or None for moves built in Python.
        status: ``ok``, or why the move failed (``unreachable``, ``singular``, ``joint_limit``,
            ``velocity_limit``, ``jump``, ``ik``, ``invalid``).
        t0: Start time in the program [s].
        t1: End time in the program [s] (where it stopped, for a failed move).
        first: Index of the move's first sample in the plan's arrays.
        last: Index of its last sample (the next move's first).
        min_manipulability: Smallest manipulability over its samples.
        peak_speed_ratio: Largest |joint speed| / velocity limit over its samples [-].
        fraction: Share of the move achieved (1.0 when ok) [-].
        message: One-line reason when it failed, else "".
        cartesian_plan: The :class:`cartesian.CartesianPlan` of a Cartesian move.
        min_clearance: Smallest distance between the robot (tool body included) and the cell's
            obstacles over the move's samples [m] (inf without a cell or obstacles).
        min_clearance_pair: (robot body, obstacle) at ``min_clearance``, or None.
        min_self_clearance: Smallest distance between the robot's own checked pairs [m].
        clearances: Robot–obstacle distance at each of the move's samples [m] (first sample
            included), or None without a cell.
        self_clearances: Smallest distance between the robot's own checked pairs at each of
            the move's samples [m], or None without a cell.
        clearance_margin: The ``clearance`` margin the move was checked with [m].
        acceleration_limit: The joint acceleration limits the move kept [rad/s²], shape (nq,),
            inf where none (joints not acceleration-limited), or None when not recorded.
        peak_acceleration: Largest |q̈| of each joint over the move's continuous motion (the
            plan's interpolant) [rad/s²], shape (nq,), or None without motion.
        collision: The failed :class:`kinplan.cell.MotionCheck` of a ``collision`` move (its
            ``bodies``, ``point``, ``q``), else None.
    """

    number: int
    kind: str
    label: str
    key: str | None
    status: str
    t0: float
    t1: float
    first: int
    last: int
    min_manipulability: float = math.nan
    peak_speed_ratio: float = 0.0
    fraction: float = 1.0
    message: str = ""
    cartesian_plan: cartesian.CartesianPlan | None = None
    min_clearance: float = math.inf
    min_clearance_pair: tuple[str, str] | None = None
    min_self_clearance: float = math.inf
    clearances: np.ndarray | None = None
    collision: MotionCheck | None = None
    self_clearances: np.ndarray | None = None
    clearance_margin: float = 0.0
    acceleration_limit: np.ndarray | None = None
    peak_acceleration: np.ndarray | None = None

    @property
    def ok(self) -> bool:
        """Whether the move was done."""
        return self.status == "ok"

    @property
    def duration(self) -> float:
        """Duration of the move [s]."""
        return self.t1 - self.t0

    @property
    def is_dwell(self) -> bool:
        """Whether this is the dwell after a move (the arm standing still)."""
        return self.kind == "dwell"

    @property
    def roll_range(self) -> tuple[float, float] | None:
        """(lowest, highest) torch roll [deg] :func:`cartesian.plan_seam` chose along a seam
        (a ``torch:`` without ``roll_deg``, or with tolerance bands), relative to the taught
        torch; None for other moves."""
        plan = self.cartesian_plan
        roll = None if plan is None else getattr(plan, "roll", None)
        if roll is None or len(roll) == 0:
            return None
        return float(np.degrees(np.min(roll))), float(np.degrees(np.max(roll)))

    @property
    def roll_text(self) -> str:
        """``roll −12° … 35°`` for a searched seam (:attr:`roll_range`), else ""."""
        if self.roll_range is None:
            return ""
        low, high = (f"{value:.0f}".replace("-", "−") for value in self.roll_range)
        low, high = ("0" if v == "−0" else v for v in (low, high))
        return f"roll {low}° … {high}°"

    @property
    def numbers(self) -> str:
        """The program move number(s) as printed: ``3``, or ``7–10`` for moves blended into
        one motion."""
        span = move_span(self.key)
        if span is None or span[0] == span[1]:
            return str(self.number)
        return f"{span[0]}–{span[1]}"


class ProgramPlan(Trajectory):
    """A planned program: the whole motion as one timed joint motion, plus reports.

    It is a :class:`~kinplan.trajectory.Trajectory`: a ptp move's own profile (the motion its
    limits were checked on) and quintic Hermite pieces through the samples of the other moves
    (exact in position, velocity and acceleration at every sample), so ``sample``, ``duration``
    and :func:`kinplan.plot.plot_trajectory` work on it; its :attr:`knots` are the move
    boundaries. The samples themselves are ``t``, ``q``, ``qd``, ``qdd``, as on a
    :class:`cartesian.CartesianPlan`.

    Args:
        robot: The robot.
        t: Sample times [s], shape (N,).
        q: Joint positions [rad], shape (N, nq).
        qd: Joint velocities [rad/s], shape (N, nq).
        qdd: Joint accelerations [rad/s²], shape (N, nq).
        moves: One report per move planned (the failed one last).
        reason: One-line reason of the failure, or "" when every move was planned.
        points: Taught points: name → tool position [m].
        paths: The Cartesian paths of the lin/circ/path moves, in order.
        program: The program planned, or None for a motion built in Python.
        dt: Sampling period [s].
        cell: The work cell the moves were checked against, or None.
        segments: The motion's polynomial pieces in program time (through the samples);
            default quintic Hermite pieces through them.

    Attributes:
        robot: The robot.
        t: Sample times [s], shape (N,), every move appended in time.
        q: Joint positions [rad], shape (N, nq).
        qd: Joint velocities [rad/s], shape (N, nq).
        qdd: Joint accelerations [rad/s²], shape (N, nq).
        tool_positions: Tool positions by forward kinematics [m], shape (N, 3).
        tool_quaternions: Tool orientations as quaternions (x, y, z, w), shape (N, 4), sign-
            continuous.
        tool_speed: Tool linear speed [m/s], shape (N,).
        manipulability: Manipulability of every sample, shape (N,).
        moves: One :class:`MoveReport` per move planned (the failed one last).
        ok: Whether every move was planned.
        status: ``ok`` or the failed move's status.
        reason: One-line reason of the failure, or "".
        events: The failure as one :class:`cartesian.Event` (``s`` is the share of the failed
            move achieved, ``t`` the program time), or empty when ok.
        points: Taught points: name → tool position [m] (markers for the viewer).
        paths: The Cartesian paths of the lin/circ/path moves, in order.
        program: The program planned, or None for a motion built in Python.
        dt: Sampling period [s].
        cell: The work cell the moves were checked against, or None.
        clearance: Robot–obstacle distance at every sample [m], shape (N,) (nan where no move
            was checked), or None without a cell.
        min_clearance: Smallest robot–obstacle distance over the plan [m] (inf without a cell
            or obstacles); ``min_clearance_pair`` its (robot body, obstacle).
        min_self_clearance: Smallest distance between the robot's own checked pairs [m].
        self_clearance: Smallest distance between the robot's own checked pairs at every
            sample [m], shape (N,) (nan where no move was checked), or None without a cell.
        clearance_margin: The ``clearance`` margin the moves were checked with [m] (kept from
            the obstacles; 0: only contact fails).
        peak_acceleration: Largest |q̈| of each joint over the plan's continuous motion
            [rad/s²], shape (nq,).
        notes: Remarks a reader of the plan must see, one line each: e.g. that accelerations
            were not limited (the URDF declares none and no ``max_acceleration:`` was given).
    """

    def __init__(
        self,
        robot: Robot,
        t: np.ndarray,
        q: np.ndarray,
        qd: np.ndarray,
        qdd: np.ndarray,
        moves: list[MoveReport],
        reason: str = "",
        points: dict[str, np.ndarray] | None = None,
        paths: list[cartesian.Path] | None = None,
        program: Program | None = None,
        dt: float = DEFAULT_DT,
        cell: WorkCell | None = None,
        segments: list[Segment] | None = None,
    ) -> None:
        self.robot = robot
        self.cell = cell
        self.t, self.q, self.qd, self.qdd = t, q, qd, qdd
        self.moves = moves
        self.reason = reason
        self.ok = not reason
        failed = [m for m in moves if not m.ok]
        self.status = failed[0].status if failed else ("ok" if self.ok else "failed")
        self.points = dict(points or {})
        self.paths = list(paths or [])
        self.program = program
        self.dt = dt
        self.io_events: list[IoEvent] = []
        boundaries = sorted({0} | {m.first for m in moves} | {m.last for m in moves})
        super().__init__(
            hermite_segments(t, q, qd, qdd) if segments is None else segments,
            waypoints=Waypoints(t[boundaries], q[boundaries]),
            end=q[-1],
            end_velocity=qd[-1],
            end_acceleration=qdd[-1],
        )
        self._tool_states(robot)
        self._clearances(len(t))
        self.events = self._failure_events(failed[0] if failed else None)
        self.peak_acceleration = segment_peaks(self.segments, q[0]).acceleration
        self.notes = self._acceleration_notes()

    def __repr__(self) -> str:
        state = "ok" if self.ok else f"failed: {self.reason}"
        return (
            f"ProgramPlan({self.robot.name}, {self.move_count} moves, {self.duration:.3f} s, "
            f"{len(self.t)} samples, {state})"
        )

    @property
    def move_count(self) -> int:
        """Number of moves of the program (its ``moves:`` list), or of moves built in Python
        (dwells not counted)."""
        if self.program is not None:
            return len(self.program.moves)
        return len({m.number for m in self.moves})

    @property
    def moves_done(self) -> int:
        """Number of the program's moves done (a blended motion counts each of its moves;
        dwells are part of their move)."""
        done: set[int] = set()
        for m in self.moves:
            if m.ok and not m.is_dwell:
                span = move_span(m.key) or (m.number, m.number)
                done.update(range(span[0], span[1] + 1))
        return len(done)

    @property
    def knots(self) -> np.ndarray:
        """Move boundaries [s] (not the sample pieces), so plots mark the moves."""
        return np.unique(
            np.concatenate(
                [[0.0, self.duration], [m.t0 for m in self.moves], [m.t1 for m in self.moves]]
            )
        )

    # -- kinplan.motion.SampledMotion: what viewers, plots and exports read --------------------
    @property
    def kind(self) -> MotionKind:
        """Always "program": an event's ``s`` is the share of the failed move achieved."""
        return "program"

    @property
    def description(self) -> str:
        """The number of moves, for captions."""
        return f"{self.move_count} moves"

    @property
    def planned_paths(self) -> list[PlannedPath]:
        """The paths of the Cartesian moves, in order, each reached as far as its move got."""
        plans = [m.cartesian_plan for m in self.moves if m.cartesian_plan is not None]
        return [piece for plan in plans for piece in plan.planned_paths]

    def _tool_states(self, robot: Robot) -> None:
        n = len(self.t)
        poses, jacobians = np.empty((n, 4, 4)), np.empty((n, 6, robot.nq))
        for k in range(n):
            pose, jacobians[k] = robot.pose_and_jacobian(self.q[k])
            poses[k] = pose.homogeneous
        self.tool_positions, self.tool_quaternions = pose_to_track(poses)
        self.tool_speed = np.linalg.norm(np.einsum("nij,nj->ni", jacobians[:, :3], self.qd), axis=1)
        position_only = robot.default_position_only()
        rows, rank = robot.task_rows(position_only), robot.task_rank(position_only)
        self.manipulability = np.asarray(manipulability_of(jacobians[:, rows], rank))
        for move in self.moves:
            window = slice(move.first, move.last + 1)
            if math.isnan(move.min_manipulability):
                move.min_manipulability = float(self.manipulability[window].min())

    def _clearances(self, n: int) -> None:
        """The plan's clearance along its samples and its minima, from the moves' checks."""
        self.min_clearance, self.min_clearance_pair = math.inf, None
        self.min_self_clearance = math.inf
        self.clearance = None if self.cell is None else np.full(n, np.nan)
        self.self_clearance = None if self.cell is None else np.full(n, np.nan)
        self.clearance_margin = max((m.clearance_margin for m in self.moves), default=0.0)
        for move in self.moves:
            if move.min_clearance < self.min_clearance:
                self.min_clearance, self.min_clearance_pair = (
                    move.min_clearance, move.min_clearance_pair,
                )  # fmt: skip
            self.min_self_clearance = min(self.min_self_clearance, move.min_self_clearance)
            for mine, theirs in (
                (self.clearance, move.clearances), (self.self_clearance, move.self_clearances),
            ):  # fmt: skip
                if mine is not None and theirs is not None:
                    values = theirs[: move.last - move.first + 1]
                    mine[move.first : move.first + len(values)] = values

    def _failure_events(self, move: MoveReport | None) -> list[cartesian.Event]:
        """The failure as a :class:`cartesian.Event` in program time (for viewers and plots)."""
        if move is None:
            return []
        return [
            cartesian.Event(
                kind=move.status,
                t=move.t1,
                s=move.fraction,
                index=move.last,
                message=self.reason,
                position=self.tool_positions[move.last].copy(),
            )
        ]

    def _acceleration_notes(self) -> list[str]:
        """A note naming the joints whose accelerations no move limited, with the largest
        acceleration they reach."""
        limits = [m.acceleration_limit for m in self.moves if m.acceleration_limit is not None]
        if not limits:
            return []
        limited = np.all(np.isfinite(np.array(limits)), axis=0)  # in every move
        free = np.flatnonzero(~limited)
        if free.size == 0:
            return []
        names = self.robot.joint_names
        j = int(free[np.argmax(self.peak_acceleration[free])])
        which = "accelerations" if free.size == len(names) else (
            "accelerations of " + ", ".join(names[k] for k in free)
        )  # fmt: skip
        return [
            f"{which} not limited (the URDF declares none; set max_acceleration: [rad/s²]): "
            f"the largest is {self.peak_acceleration[j]:.4g} rad/s² ({names[j]})"
        ]

    def summary(self) -> str:
        """A text summary: one line per move (number, label, duration [s], peak joint speed /
        limit, status), the total, then the :attr:`notes`."""
        lines = [
            f"{m.numbers:>3}. {m.label} ({m.key or '-'}): {m.duration:.3f} s, peak speed "
            f"{m.peak_speed_ratio:.2f} of the limit, {m.status}"
            + (f", {m.roll_text}" if m.roll_text else "")
            for m in self.moves
        ]
        lines.append(
            f"total: {self.move_count} moves, {self.duration:.3f} s, "
            + ("ok" if self.ok else f"failed: {self.reason}")
        )
        lines += [f"note: {note}" for note in self.notes]
        return "\n".join(lines)

    def summary_rows(self) -> list[dict[str, object]]:
        """One dict per move: number, move, key, duration [s], min manipulability, peak joint
        speed / limit, min clearance [m] (inf without a cell), status, the torch roll range
        chosen along a searched seam (``roll −12° … 35°``, else "")."""
        return [
            {
                "number": m.numbers,
                "move": m.label,
                "key": m.key or "",
                "duration": m.duration,
                "min_manipulability": m.min_manipulability,
                "peak_speed_ratio": m.peak_speed_ratio,
                "min_clearance": m.min_clearance,
                "status": m.status,
                "roll": m.roll_text,
            }
            for m in self.moves
        ]
