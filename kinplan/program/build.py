"""Chaining moves into one sampled joint motion: :class:`MotionBuilder`.

Each move (``ptp``, ``lin``, ``circ``, or any :class:`cartesian.Path` to follow) starts from the
end state of the previous one; :meth:`MotionBuilder.finish` returns the whole motion as a
:class:`~kinplan.program.ProgramPlan`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import NoReturn, TypeAlias

import numpy as np
import pinocchio as pin

import cartesian
from cartesian.follow import collision_event
from kinplan.cell import MotionCheck, WorkCell
from kinplan.errors import InfeasibleError, KinplanError
from kinplan.program.checker import describe
from kinplan.program.plan import MoveReport, ProgramPlan
from kinplan.program.ptp import peak_speed_ratio, ptp_trajectory
from kinplan.program.record import MotionRecord
from kinplan.program.schema import DEFAULT_DT, DEFAULT_TOOL_SPEED, JOIN_TOLERANCE, Program
from kinplan.robot import Robot
from kinplan.sampling import joint_speeds, motion_step

__all__ = ["Goal", "MotionBuilder"]

Goal: TypeAlias = np.ndarray | Sequence[float] | pin.SE3
"""A Cartesian goal: a tool pose, or a tool position [m]."""


def _where(position: np.ndarray) -> str:
    text = ", ".join(f"{x:.3f}" for x in position).replace("-0.000", "0.000")
    return f"({text}) m"


def _program_remedy(plan: cartesian.CartesianPlan) -> str:
    """What the author of a program can do about a failed move's first event (the event's own
    remedy names :func:`cartesian.follow`'s arguments)."""
    event = plan.events[0]
    if event.kind == "velocity_limit":
        factor = plan.peak_speed_ratio
        return (
            f"slow this move down by a factor of at least {factor:.3g} (a lower speed or a longer "
            "duration on the move)"
        )
    if event.kind in ("joint_limit", "jump"):
        return (
            "reach the move's start in another configuration (a ptp to joint values before it), "
            "or move its points"
        )
    if event.kind == "unreachable":
        return "move the move's points into the arm's workspace"
    if event.kind == "collision":
        return (
            "move the move's points or the obstacle (obstacles:), or reach the move's start in "
            "another configuration (a ptp to joint values before it)"
        )
    return event.remedy


def _start_turn(path: cartesian.Path, pose: pin.SE3, position_only: bool) -> float:
    """Angle between a path's start orientation and the tool's [rad] (0 if not oriented)."""
    if position_only or not path.has_orientation:
        return 0.0
    return float(np.linalg.norm(pin.log3(pose.rotation.T @ path.start.rotation)))


class MotionBuilder:
    """Chains moves from the end state of the previous one into one sampled joint motion.

    Every method plans one move from the current configuration :attr:`q`. A move that cannot be
    done raises :class:`~kinplan.program.MoveError` (one-line message naming the move and where
    it failed) after recording the failure; :meth:`finish` then returns the motion up to the
    failure with ``ok = False``.

    Args:
        robot: The arm.
        q_start: Start configuration [rad], shape (nq,).
        dt: Sampling period [s].
        cell: A :class:`kinplan.WorkCell`: every move is checked against it (its obstacles and
            the robot's self-collision, between samples too) and fails with status
            ``collision`` naming the two bodies; None: not checked.
        clearance: Margin [m] (≥ 0): bodies closer than this collide too.

    Attributes:
        robot: The arm.
        dt: Sampling period [s].
        q: The current configuration (the end of the motion so far) [rad], shape (nq,).
        paths: The Cartesian paths followed, in order.

    Example:
        >>> builder = MotionBuilder(robot, q_home)
        >>> builder.ptp(approach_pose)
        >>> builder.lin(seam_start, speed=0.05)
        >>> builder.follow(seam, speed=0.03, label="weld seam")
        >>> plan = builder.finish()
    """

    def __init__(
        self,
        robot: Robot,
        q_start: np.ndarray,
        dt: float = DEFAULT_DT,
        *,
        cell: WorkCell | None = None,
        clearance: float = 0.0,
    ) -> None:
        if not (math.isfinite(dt) and dt > 0):
            raise KinplanError(f"dt must be a finite number of seconds > 0, got {dt!r}")
        if cell is not None and not isinstance(cell, WorkCell):
            raise KinplanError(f"cell must be a kinplan.WorkCell, got {describe(cell)}")
        if not (math.isfinite(clearance) and clearance >= 0):
            raise KinplanError(f"clearance must be a number of metres >= 0, got {clearance!r}")
        if cell is not None and cell.robot is not robot:
            cell = cell.for_robot(robot)
        self.cell = cell
        self.clearance = float(clearance)
        self.robot = robot
        self.dt = float(dt)
        self.q = robot.check_q(q_start, "q_start").copy()
        self.paths: list[cartesian.Path] = []
        self._motion = MotionRecord(self.q)

    # -- state ---------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """End time of the motion so far [s]."""
        return self._motion.time

    @property
    def reports(self) -> list[MoveReport]:
        """One report per move planned (a failed one last)."""
        return self._motion.reports

    @property
    def reason(self) -> str:
        """The failed move's one-line message, or "" while every move was done."""
        return self._motion.reason

    def tool_pose(self) -> pin.SE3:
        """Current tool pose in the base frame."""
        return self.robot.fk(self.q)

    # -- moves ---------------------------------------------------------------------------------
    def ptp(
        self,
        goal: Goal,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "ptp",
        key: str | None = None,
    ) -> MoveReport:
        """Joint-interpolated move to a Cartesian goal, solved by IK seeded from the current
        configuration (so the arm stays on its branch).

        Args:
            goal: Tool pose (SE3) or tool position [m] (shape (3,): keeps the current
                orientation when nq ≥ 6, position-only otherwise).
            duration, speed, profile, label, key: As in :meth:`ptp_joints`.
        """
        self._check_open()
        position, rotation = self._target(goal)
        target = position if rotation is None else pin.SE3(rotation, position)
        result = self.robot.ik(target, q_seed=self.q, position_only=rotation is None)
        if not result.success:
            why = (
                f"ik: no inverse kinematics solution for {_where(position)} within the joint "
                f"limits (the closest found is {result.position_error:.4f} m, "
                f"{result.rotation_error:.3f} rad away); move the point"
            )
            self._fail("ptp", label, key, status="ik", why=why)
        return self.ptp_joints(
            result.q, duration=duration, speed=speed, profile=profile, label=label, key=key
        )

    def ptp_joints(
        self,
        q_goal: np.ndarray | Sequence[float],
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "ptp",
        key: str | None = None,
    ) -> MoveReport:
        """Joint-interpolated move to joint values.

        Args:
            q_goal: Joint values [rad], shape (nq,).
            duration: Duration [s]; default the minimum time within the scaled limits. A given
                duration must keep every joint within its velocity limit.
            speed: Share of the joint velocity limits (0, 1]; default
                :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
            profile: ``trapezoid``, ``quintic``, ``cubic``, ``scurve`` or ``time_optimal``.
            label: Description for reports.
            key: Key path in a program, for messages.
        """
        self._check_open()
        q_goal = self.robot.check_q(q_goal, "ptp goal")
        try:
            traj = ptp_trajectory(self.robot, self.q, q_goal, duration, speed, profile)
        except InfeasibleError as exc:  # a duration the limits cannot meet: states the minimum
            self._fail("ptp", label, key, status="invalid", why=f"invalid: {exc}")
        t = traj.time_grid(motion_step(traj.duration, self.dt))
        q, qd, qdd = traj.sample(t)
        ratio = peak_speed_ratio(self.robot, t, q, qd)
        if ratio > 1.0 + 1e-6:
            speeds = np.max(joint_speeds(q, qd, t), axis=0)
            j = int(np.argmax(speeds / self.robot.velocity_limit))
            why = (
                f"velocity_limit: joint {j} ({self.robot.joint_names[j]}) would need "
                f"{speeds[j]:.4g} rad/s, above its limit "
                f"{self.robot.velocity_limit[j]:.3f} rad/s; give a duration of at least "
                f"{traj.duration * ratio:.3f} s, or no duration (minimum time)"
            )
            self._fail("ptp", label, key, status="velocity_limit", why=why, ratio=ratio)
        check = None
        if self.cell is not None:
            check = self.cell.check_motion(q, self.clearance)
            if check.index is not None:
                k = check.index
                share = t / t[-1] if t[-1] > 0 else np.ones_like(t)
                position = self.robot.fk(q[k]).translation
                event = collision_event(check, t, share, position)
                why = (
                    f"collision at s = {share[k]:.2f}: {event.message}; move a point of the move, "
                    "add a via point around the obstacle, or use lin moves"
                )
                kept = max(k, 1)
                self._fail(
                    "ptp", label, key, (t[:kept], q[:kept], qd[:kept], qdd[:kept]),
                    status="collision", why=why, ratio=ratio, fraction=float(share[k]),
                    check=check,
                )  # fmt: skip
        return self._record("ptp", label, key, (t, q, qd, qdd), ratio=ratio, check=check)

    def lin(
        self,
        goal: Goal,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "lin",
        key: str | None = None,
    ) -> MoveReport:
        """Straight tool line from the current pose to ``goal`` (SE3 or position [m]).

        A position keeps the current orientation (arms with ≥ 6 joints) or is position-only.
        ``speed`` is the tool cruise speed [m/s] (default
        :data:`~kinplan.program.DEFAULT_TOOL_SPEED`).
        """
        self._check_open()
        start, (end,) = self._cartesian_points([goal])
        path = self._build_path("lin", label, key, lambda: cartesian.Line(start, end))
        return self.follow(
            path, duration=duration, speed=speed, profile=profile, label=label, key=key,
            kind="lin",
        )  # fmt: skip

    def circ(
        self,
        goal: Goal,
        via: Goal,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "circ",
        key: str | None = None,
    ) -> MoveReport:
        """Arc of the circle through the current tool position, ``via`` and ``goal``.

        The tool orientation moves by slerp from the current one to the goal's (the via point's
        orientation is not used). Options as in :meth:`lin`.
        """
        self._check_open()
        start, (end, middle) = self._cartesian_points([goal, via])
        path = self._build_path("circ", label, key, lambda: cartesian.Arc(start, middle, end))
        return self.follow(
            path, duration=duration, speed=speed, profile=profile, label=label, key=key,
            kind="circ",
        )  # fmt: skip

    def follow(
        self,
        path: cartesian.Path,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "path",
        key: str | None = None,
        kind: str = "path",
    ) -> MoveReport:
        """Follow a Cartesian path that starts at the current tool pose (within 0.1 mm, 1 mrad).

        Args:
            path: Any :class:`cartesian.Path` (e.g. a :class:`cartesian.PathSequence` of lines
                and arcs: one move at constant tool speed).
            duration: Duration [s]; or
            speed: Tool cruise speed [m/s] (default :data:`~kinplan.program.DEFAULT_TOOL_SPEED`).
            profile: 1-D time law: ``trapezoid``, ``quintic`` or ``cubic``.
            label: Description for reports.
            key: Key path in a program, for messages.
            kind: Kind shown in reports.
        """
        self._check_open()
        here = self.tool_pose().translation
        gap = float(np.linalg.norm(path.start.translation - here))
        if gap > 1e-4:
            why = (
                f"invalid: the path starts at {_where(path.start.translation)}, {gap:.4f} m away "
                f"from the tool at {_where(here)}; move there first (ptp or lin)"
            )
            self._fail(kind, label, key, status="invalid", why=why)
        turn = _start_turn(path, self.tool_pose(), self.robot.default_position_only())
        if turn > 1e-3:
            why = (
                f"invalid: the path starts with a tool orientation {turn:.3f} rad away from the "
                "current one; reorient first (ptp or lin to the path's start pose)"
            )
            self._fail(kind, label, key, status="invalid", why=why)
        if duration is None and speed is None:
            if path.length > 0:
                speed = DEFAULT_TOOL_SPEED
            else:
                duration = 1.0
        try:
            plan = cartesian.follow(
                self.robot, path, duration=duration, speed=speed, profile=profile, dt=self.dt,
                q_seed=self.q, cell=self.cell, clearance=self.clearance,
            )  # fmt: skip
        except KinplanError as exc:
            self._fail(kind, label, key, status="invalid", why=f"invalid: {exc}")
        self.paths.append(path)
        ratio = plan.peak_speed_ratio
        samples = (plan.t, plan.q, plan.qd, plan.qdd) if len(plan.t) else None
        if samples and np.max(np.abs(plan.q[0] - self.q)) > JOIN_TOLERANCE:
            why = (
                "jump: the path's first configuration is on another branch than the current "
                "one; move to the path start with a lin move first"
            )
            self._fail(kind, label, key, status="jump", why=why, ratio=ratio, plan=plan)
        if not plan.ok:
            event = plan.events[0]
            why = f"{event.kind} at s = {event.s:.2f}: {event.message}; {_program_remedy(plan)}"
            self._fail(
                kind, label, key, samples, status=plan.status, why=why, ratio=ratio,
                fraction=plan.fraction, plan=plan,
            )  # fmt: skip
        return self._record(kind, label, key, samples, ratio=ratio, plan=plan)

    def finish(
        self, points: dict[str, np.ndarray] | None = None, program: Program | None = None
    ) -> ProgramPlan:
        """The whole motion so far as a :class:`~kinplan.program.ProgramPlan` (``ok = False``
        after a failure).

        Args:
            points: Named tool positions to mark [m].
            program: The program planned, if any.
        """
        return ProgramPlan(
            self.robot,
            *self._motion.arrays(),
            list(self.reports),
            reason=self.reason,
            points=points,
            paths=self.paths,
            program=program,
            dt=self.dt,
            cell=self.cell,
        )

    # -- helpers -------------------------------------------------------------------------------
    def _check_open(self) -> None:
        if self.reason:
            raise KinplanError(f"planning stopped at the failed move: {self.reason}")

    def _target(self, goal: Goal) -> tuple[np.ndarray, np.ndarray | None]:
        """(position, rotation or None) of a Cartesian goal, applying the orientation rule."""
        if isinstance(goal, pin.SE3):
            position, rotation = np.array(goal.translation), np.array(goal.rotation)
        else:
            position = np.asarray(goal, dtype=float)
            if position.shape != (3,) or not np.all(np.isfinite(position)):
                raise KinplanError(
                    f"a Cartesian goal is a pin.SE3 or a finite position 3-vector [m], got "
                    f"{describe(goal)}; use ptp_joints for joint values"
                )
            rotation = None
        if self.robot.default_position_only():
            return position, None
        if rotation is None:
            rotation = self.tool_pose().rotation.copy()
        return position, rotation

    def _cartesian_points(
        self, goals: list[Goal]
    ) -> tuple[pin.SE3 | np.ndarray, list[pin.SE3] | list[np.ndarray]]:
        """The path start (current tool pose) and the goals, as SE3 or as positions (arms with
        fewer than 6 joints)."""
        start = self.tool_pose()
        targets = [self._target(goal) for goal in goals]
        if self.robot.default_position_only():
            return start.translation.copy(), [position for position, _ in targets]
        return start, [pin.SE3(rotation, position) for position, rotation in targets]

    def _build_path(
        self, kind: str, label: str, key: str | None, build: Callable[[], cartesian.Path]
    ) -> cartesian.Path:
        try:
            return build()
        except KinplanError as exc:
            self._fail(kind, label, key, status="invalid", why=f"invalid: {exc}")

    def _record(
        self,
        kind: str,
        label: str,
        key: str | None,
        samples: tuple[np.ndarray, ...] | None,
        *,
        ratio: float = 0.0,
        plan: cartesian.CartesianPlan | None = None,
        check: MotionCheck | None = None,
    ) -> MoveReport:
        """Append a move that was done (samples in local times from 0) and its report."""
        if samples is not None:
            self.q = np.array(samples[1][-1])
        return self._motion.append(kind, label, key, samples, ratio=ratio, plan=plan, check=check)

    def _fail(
        self,
        kind: str,
        label: str,
        key: str | None,
        samples: tuple[np.ndarray, ...] | None = None,
        *,
        status: str,
        why: str,
        ratio: float = 0.0,
        fraction: float = 0.0,
        plan: cartesian.CartesianPlan | None = None,
        check: MotionCheck | None = None,
    ) -> NoReturn:
        """Record a failed move (the samples are the part achieved) and raise
        :class:`~kinplan.program.MoveError`."""
        if samples is not None:
            self.q = np.array(samples[1][-1])
        self._motion.fail(
            kind, label, key, samples, status=status, why=why, ratio=ratio, fraction=fraction,
            plan=plan, check=check,
        )  # fmt: skip
