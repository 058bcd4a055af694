"""Chaining moves into one sampled joint motion: :class:`MotionBuilder`.

Each move (``ptp``, ``lin``, ``circ``, or any :class:`cartesian.Path` to follow) starts from the
end state of the previous one; :meth:`MotionBuilder.finish` returns the whole motion as a
:class:`~kinplan.program.ProgramPlan`.

In :mod:`kinplan.program`, after :mod:`~kinplan.program.ptp` (the timing of ptp moves),
:mod:`~kinplan.program.joint_checks` (a ptp move's speed share and cell check),
:mod:`~kinplan.program.record` (the samples and reports so far),
:mod:`~kinplan.program.remedies` (how a failed move is worded) and
:mod:`~kinplan.program.seams` (the paths of lin, circ and seam moves), and before
:mod:`~kinplan.program.run`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import NoReturn

import numpy as np
import pinocchio as pin

import cartesian
from cartesian.events import collision_event
from kinplan import checks
from kinplan.cell import MotionCheck, WorkCell
from kinplan.errors import InputError, KinplanError
from kinplan.model.robot import Robot
from kinplan.program.checker import describe
from kinplan.program.joint_checks import cell_check, speed_ratio
from kinplan.program.plan import MoveReport, ProgramPlan
from kinplan.program.ptp import (
    PtpLimitError,
    acceleration_limits,
    limit_problem,
    motion_limits,
    plan_ptp,
    plan_ptp_through,
)
from kinplan.program.record import MotionRecord
from kinplan.program.remedies import (
    SMALL_GAP,
    ik_reason,
    jump_reason,
    program_remedy,
    ptp_collision_reason,
    start_gap_reason,
    start_turn_reason,
    too_many_samples_reason,
    torch_start_reason,
    trajectory_remedy,
)
from kinplan.program.schema import (
    AVOID_TIME_LIMIT,
    DEFAULT_DT,
    DEFAULT_TOOL_SPEED,
    JOIN_TOLERANCE,
    MAX_SAMPLES,
    Program,
    TorchSpec,
    WeaveSpec,
)
from kinplan.program.seams import (
    TORCH_START_TOLERANCE,
    Goal,
    SeamPiece,
    goal_from,
    seam_path,
    start_turn,
    torch_path,
    weave_path,
)
from kinplan.trajectory import Segment, Trajectory, whole_periods
from kinplan.trajectory.sampling import motion_step

__all__ = ["Goal", "MotionBuilder", "SeamPiece"]


def _is_real(value: object) -> bool:
    """Whether ``value`` is a real number (not a boolean)."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def _checked_acceleration(value: object, nq: int, name: str) -> np.ndarray | None:
    """A ``max_acceleration`` argument: None, one number > 0 or one per joint [rad/s²]."""
    if value is None:
        return None
    if not isinstance(value, (list, tuple, np.ndarray)):
        number = checks.number(value, name, positive=True, unit="rad/s²")
        return np.full(nq, number)
    array = checks.vector(value, name, nq, unit="rad/s²")
    for j in np.flatnonzero(array <= 0.0):
        raise InputError(f"{name} must be > 0 rad/s² for every joint, got {array[j]} for joint {j}")
    return array


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
        clearance: Margin [m] (≥ 0) between the robot (links and tool body) and the cell's
            obstacles: closer than this collides too. The robot's own link pairs collide only
            on contact.
        max_acceleration: Joint acceleration limits of every move [rad/s² or m/s²], one
            number or one per joint, on top of the robot's own (the lower one holds); a move's
            ``max_acceleration`` replaces it. None: the robot's limits alone (joints without
            one are not acceleration-limited: see :attr:`acceleration_limit`).

    Attributes:
        robot: The arm.
        dt: Sampling period [s].
        acceleration_limit: The joint acceleration limits moves keep unless they give their
            own [rad/s²], shape (nq,), inf where none.
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
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> None:
        if not isinstance(robot, Robot):
            raise InputError(f"robot must be a kinplan.Robot, got {describe(robot)}")
        if not (_is_real(dt) and math.isfinite(dt) and dt > 0):
            raise KinplanError(f"dt must be a finite number of seconds > 0, got {dt!r}")
        if cell is not None and not isinstance(cell, WorkCell):
            raise KinplanError(f"cell must be a kinplan.WorkCell, got {describe(cell)}")
        if not (_is_real(clearance) and math.isfinite(clearance) and clearance >= 0):
            raise KinplanError(f"clearance must be a number of metres >= 0, got {clearance!r}")
        if cell is not None and cell.robot is not robot:
            cell = cell.for_robot(robot)
        self.cell = cell
        self.clearance = float(clearance)
        self.robot = robot
        self.dt = float(dt)
        self.q = robot.check_q(q_start, "q_start").copy()
        self.max_acceleration = _checked_acceleration(
            max_acceleration, robot.nq, "max_acceleration"
        )
        self.acceleration_limit = acceleration_limits(robot, self.max_acceleration)
        self.paths: list[cartesian.Path] = []
        self._motion = MotionRecord(self.q)
        self._ahead: tuple[cartesian.Path, cartesian.CartesianPlan] | None = None

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
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Joint-interpolated move to a Cartesian goal, solved by IK seeded from the current
        configuration (so the arm stays on its branch).

        Args:
            goal: Tool pose (SE3) or tool position [m] (shape (3,): keeps the current
                orientation when nq ≥ 6, position-only otherwise).
            duration, speed, profile, label, key, max_acceleration: As in :meth:`ptp_joints`.
        """
        self._check_open()
        position, rotation = self._target(goal)
        target = position if rotation is None else pin.SE3(rotation, position)
        result = self.robot.ik(target, q_seed=self.q, position_only=rotation is None)
        if not result.success:
            self._fail("ptp", label, key, status="ik", why=ik_reason(position, result))
        return self.ptp_joints(
            result.q, duration=duration, speed=speed, profile=profile, label=label, key=key,
            max_acceleration=max_acceleration,
        )  # fmt: skip

    def ptp_joints(
        self,
        q_goal: np.ndarray | Sequence[float],
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "ptp",
        key: str | None = None,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Joint-interpolated move to joint values.

        The continuous motion (not only its samples) keeps every joint within its position,
        velocity and acceleration limits; a ``duration`` that cannot is refused with the
        shortest one that can (``velocity_limit`` or ``acceleration_limit``).

        Args:
            q_goal: Joint values [rad], shape (nq,).
            duration: Duration [s]; default the minimum time within the scaled limits.
            speed: Share of the joint velocity limits (0, 1]; default
                :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
            profile: ``trapezoid``, ``quintic``, ``cubic``, ``scurve`` or ``time_optimal``.
            label: Description for reports.
            key: Key path in a program, for messages.
            max_acceleration: Joint acceleration limits of this move [rad/s²], one number or
                one per joint (the robot's own still hold); default the builder's.
        """
        self._check_open()
        q_goal = self.robot.check_q(q_goal, "ptp goal")
        limit = self._acceleration_limit(max_acceleration)
        try:
            traj = plan_ptp(self.robot, self.q, q_goal, duration, speed, profile, limit)
        except PtpLimitError as exc:  # states the duration that works
            self._fail("ptp", label, key, status=exc.status, why=str(exc), ratio=exc.ratio)
        except KinplanError as exc:
            self._fail("ptp", label, key, status="invalid", why=f"invalid: {exc}")
        return self._joint_motion(traj, label, key, limit)

    def ptp_through(
        self,
        q_points: Sequence[np.ndarray | Sequence[float]],
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "time_optimal",
        blend: float = 0.0,
        times: Sequence[float] | None = None,
        label: str = "ptp",
        key: str | None = None,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """One joint-space motion from the current configuration through several configurations,
        without stopping at them.

        Args:
            q_points: The configurations to pass, in order, the last one the goal [rad], each
                shape (nq,).
            duration: Duration [s]; default the minimum time within the scaled limits.
            speed: Share of the joint velocity and acceleration limits (0, 1]; default
                :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
            profile: ``time_optimal`` (straight lines in joint space, corners blended within
                ``blend``; :func:`kinplan.trajectory.time_optimal`) or ``spline`` (the clamped
                cubic spline through the points; :func:`kinplan.trajectory.spline`).
            blend: ``time_optimal``: largest deviation from a corner [rad] (0: through the
                points exactly, stopping at corners).
            times: ``spline``: the time [s] at which the motion passes each point, from its
                start (then checked against the limits like a ptp with a duration).
            label: Description for reports.
            key: Key path in a program, for messages.
            max_acceleration: As in :meth:`ptp_joints`.

        The continuous motion keeps every joint within its position, velocity and
        acceleration limits: a spline that overshoots a joint limit between its points is
        refused (``joint_limit``), and so are a ``duration`` or ``times`` too short, with the
        values that work.
        """
        self._check_open()
        points = [self.q] + [
            self.robot.check_q(q, f"ptp point {k}") for k, q in enumerate(q_points)
        ]
        limit = self._acceleration_limit(max_acceleration)
        try:
            traj = plan_ptp_through(
                self.robot, np.array(points), duration, speed, profile, blend, times, limit
            )
        except PtpLimitError as exc:
            self._fail("ptp", label, key, status=exc.status, why=str(exc), ratio=exc.ratio)
        except KinplanError as exc:
            self._fail("ptp", label, key, status="invalid", why=f"invalid: {exc}")
        return self._joint_motion(traj, label, key, limit)

    def trajectory(
        self, traj: Trajectory, *, label: str = "trajectory", key: str | None = None
    ) -> MoveReport:
        """Append a joint trajectory that starts at the current configuration (e.g. one of
        :mod:`kinplan.trajectory`'s profiles), checked like a ptp (position, velocity and
        acceleration limits over the continuous motion, the cell).

        Raises:
            KinplanError: the trajectory has another number of joints or does not start at the
                current configuration (within :data:`~kinplan.program.JOIN_TOLERANCE`).
        """
        self._check_open()
        if not isinstance(traj, Trajectory) or traj.n != self.robot.nq:
            raise KinplanError(
                f"expected a kinplan.trajectory.Trajectory of {self.robot.nq} joints, got "
                f"{describe(traj)}"
            )
        gap = float(np.max(np.abs(traj.sample(np.array([0.0]))[0][0] - self.q)))
        if gap > JOIN_TOLERANCE:
            raise KinplanError(
                f"the trajectory starts {gap:.3g} rad away from the current configuration; "
                "plan it from MotionBuilder.q"
            )
        problem = limit_problem(self.robot, traj, self.acceleration_limit)
        if problem is not None:
            why = f"{problem.text}; {trajectory_remedy(problem.scale)}"
            self._fail("ptp", label, key, status=problem.status, why=why, ratio=problem.speed_ratio)
        return self._joint_motion(traj, label, key, self.acceleration_limit)

    def dwell(self, seconds: float, *, label: str = "dwell", key: str | None = None) -> MoveReport:
        """Stand still for ``seconds`` [s] (an arc-on or arc-off dwell of a weld)."""
        self._check_open()
        if not (_is_real(seconds) and math.isfinite(seconds) and seconds >= 0):
            raise KinplanError(f"dwell must be a finite number of seconds >= 0, got {seconds!r}")
        self._check_samples(seconds / self.dt, "dwell", label, key, f"a {seconds:g} s dwell")
        steps = max(1, math.ceil(seconds / self.dt - 1e-9))
        if seconds > 0:  # whole periods, as every move: the samples stay on the program's grid
            seconds = steps * self.dt
        t = np.arange(steps + 1) * self.dt if seconds > 0 else np.zeros(2)
        q = np.tile(self.q, (len(t), 1))
        zero = np.zeros_like(q)
        still = [Segment(0.0, float(seconds), self.q[:, None].copy())] if seconds > 0 else []
        return self._record("dwell", label, key, (t, q, zero, zero.copy()), segments=still)

    def _check_samples(self, count: float, kind: str, label: str, key: str | None,
                       what: str) -> None:  # fmt: skip
        """Fail a move that would take the program past :data:`MAX_SAMPLES` samples at this dt
        (before allocating them)."""
        total = len(self._motion) + count
        if not total <= MAX_SAMPLES:  # also NaN and inf
            why = too_many_samples_reason(what, self.dt, total)
            self._fail(kind, label, key, status="invalid", why=why)

    def ptp_around(
        self,
        q_goal: np.ndarray | Sequence[float],
        *,
        speed: float | None = None,
        label: str = "ptp",
        key: str | None = None,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
        seed: int = 0,
        time_limit: float = AVOID_TIME_LIMIT,
    ) -> MoveReport:
        """Joint move to joint values around the cell's obstacles (``avoid: true``).

        :func:`kinplan.free_motion` finds waypoints whose straight segments the cell's motion
        check certifies (with the builder's clearance) and times the motion through them
        time-optimally within ``speed`` × the joint limits; the motion is then checked like
        any ptp. The report's label says how many waypoints it needed.

        Args:
            q_goal: Joint values [rad], shape (nq,).
            speed: Share of the joint velocity and acceleration limits (0, 1]; default
                :data:`~kinplan.program.DEFAULT_PTP_SPEED`.
            label, key, max_acceleration: As in :meth:`ptp_joints`.
            seed: Seed of the search (the same seed, the same motion).
            time_limit: Longest search [s].
        """
        from kinplan.planning import free_motion  # the planners load on first use

        self._check_open()
        q_goal = self.robot.check_q(q_goal, "ptp goal")
        limit = self._acceleration_limit(max_acceleration)
        velocity, acceleration = motion_limits(self.robot, None, speed, limit)
        cell = self.cell if self.cell is not None else WorkCell(self.robot)
        try:
            plan = free_motion(
                self.robot, self.q, q_goal, cell, clearance=self.clearance, seed=seed,
                time_limit=time_limit, max_velocity=velocity, max_acceleration=acceleration,
            )  # fmt: skip
        except KinplanError as exc:
            self._fail("ptp", label, key, status="invalid", why=f"invalid: {exc}")
        if not plan.ok:
            why = f"collision: avoid: {plan.events[0]}"
            self._fail("ptp", label, key, status="collision", why=why)
        label = f"{label} around the obstacles ({len(plan.waypoints)} waypoints)"
        return self._joint_motion(plan.trajectory, label, key, limit)

    def _acceleration_limit(self, max_acceleration: object) -> np.ndarray:
        """A move's acceleration limits [rad/s²]: its own ``max_acceleration`` (on top of the
        robot's) or the builder's."""
        given = _checked_acceleration(max_acceleration, self.robot.nq, "max_acceleration")
        return self.acceleration_limit if given is None else acceleration_limits(self.robot, given)

    def _joint_motion(
        self, traj: Trajectory, label: str, key: str | None, acceleration_limit: np.ndarray
    ) -> MoveReport:
        """Sample a joint trajectory from the current configuration (checked within the limits
        over its continuous motion), check it against the cell and record it with its own
        segments (the plan's interpolant between the samples is the profile itself)."""
        whole = whole_periods(traj.duration, self.dt)
        if whole > traj.duration:  # held at its end to whole periods: on the program's grid
            traj = traj.held(whole)
        step = motion_step(traj.duration, self.dt)
        self._check_samples(traj.duration / step, "ptp", label, key, f"a {traj.duration:g} s move")
        # the samples recorded are the caller's grid; the cell is checked on a grid fine enough
        # for a short move (at least MIN_INTERVALS intervals), which contains it when finer
        t = traj.time_grid(self.dt)
        q, qd, qdd = traj.sample(t)
        ratio = speed_ratio(self.robot, traj)
        check = None
        if self.cell is not None:
            check = cell_check(self.cell, self.clearance, traj, t, q, step, self.dt)
            if check.index is not None:
                k = check.index
                share = t / t[-1] if t[-1] > 0 else np.ones_like(t)
                position = self.robot.fk(q[k]).translation
                event = collision_event(check, t, share, position)
                why = ptp_collision_reason(check.kind, share[k], event.message)
                kept = max(k, 1)
                self._fail(
                    "ptp", label, key, (t[:kept], q[:kept], qd[:kept], qdd[:kept]),
                    status="collision", why=why, ratio=ratio, fraction=float(share[k]),
                    check=check,
                )  # fmt: skip
        return self._record(
            "ptp", label, key, (t, q, qd, qdd), ratio=ratio, check=check,
            segments=list(traj.segments), acceleration_limit=acceleration_limit,
        )  # fmt: skip

    def lin(
        self,
        goal: Goal,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec | None = None,
        label: str = "lin",
        key: str | None = None,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Straight tool line from the current pose to ``goal`` (SE3 or position [m]).

        A position keeps the current orientation (arms with ≥ 6 joints) or is position-only.
        ``speed`` is the tool cruise speed [m/s] (default
        :data:`~kinplan.program.DEFAULT_TOOL_SPEED`); ``weave``, ``torch`` and
        ``max_acceleration`` as in :meth:`seam`.
        """
        return self.seam(
            [("lin", goal, None)], duration=duration, speed=speed, profile=profile, weave=weave,
            torch=torch, label=label, key=key, kind="lin", max_acceleration=max_acceleration,
        )  # fmt: skip

    def circ(
        self,
        goal: Goal,
        via: Goal,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec | None = None,
        label: str = "circ",
        key: str | None = None,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Arc of the circle through the current tool position, ``via`` and ``goal``.

        The tool orientation moves by slerp from the current one to the goal's (the via point's
        orientation is not used). Options as in :meth:`lin`.
        """
        return self.seam(
            [("circ", goal, via)], duration=duration, speed=speed, profile=profile, weave=weave,
            torch=torch, label=label, key=key, kind="circ", max_acceleration=max_acceleration,
        )  # fmt: skip

    def seam(
        self,
        pieces: Sequence[SeamPiece],
        *,
        blend: float | Sequence[float] = 0.0,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec | None = None,
        label: str = "seam",
        key: str | None = None,
        kind: str = "seam",
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Lines and arcs one after the other as one Cartesian motion, corners blended.

        Each piece starts where the previous one ends; a goal given as a position keeps the
        orientation the tool has there (arms with ≥ 6 joints). The corners are blended within
        ``blend`` (:func:`cartesian.blend_corners`), so the tool passes them at cruise speed.

        Args:
            pieces: (``"lin"``, goal, None) or (``"circ"``, goal, via) for each piece.
            blend: Blend radius [m] at every corner, or one per corner (0: a sharp corner).
            duration, speed, profile: As in :meth:`follow`.
            weave: The torch oscillates across the seam (:class:`cartesian.Weave`, wavelength
                = travel speed / frequency).
            torch: The tool held at welding angles to the seam
                (:class:`cartesian.TorchOrientation`); the seam must start with the tool at
                that orientation.
            label, key, kind: For reports.
            max_acceleration: Joint acceleration limits of this move [rad/s²], one number or
                one per joint (the robot's own still hold); default the builder's. Checked at
                every sample by :func:`cartesian.follow`.
        """
        self._check_open()
        start, flat = self.tool_pose(), self.robot.default_position_only()
        path = self._build_path(kind, label, key, lambda: seam_path(pieces, blend, start, flat))
        if torch is not None:
            if self.robot.default_position_only():
                why = (
                    "invalid: torch angles need an arm with 6 or more joints; "
                    f"{self.robot.name} has {self.robot.nq}"
                )
                self._fail(kind, label, key, status="invalid", why=why)
            path = self._build_path(kind, label, key, lambda: torch_path(path, torch))
            if not torch.searched:
                self._check_torch_start(path, kind, label, key)
        if weave is not None:
            travel = DEFAULT_TOOL_SPEED if speed is None else speed
            path = self._build_path(kind, label, key, lambda: weave_path(path, weave, travel))
        if torch is not None and torch.searched:
            return self._searched_seam(
                path, torch, duration=duration, speed=speed, profile=profile, label=label,
                key=key, kind=kind, max_acceleration=max_acceleration,
            )  # fmt: skip
        return self.follow(
            path, duration=duration, speed=speed, profile=profile, label=label, key=key,
            kind=kind, max_acceleration=max_acceleration,
        )  # fmt: skip

    def seam_start(
        self,
        pieces: Sequence[SeamPiece],
        at: Goal,
        *,
        blend: float | Sequence[float] = 0.0,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> np.ndarray | None:
        """Plan a searched torch seam (roll free or tolerance bands) that will start at ``at``
        before the approach move that takes the arm there, so the approach can go to the start
        configuration :func:`cartesian.plan_seam` chose.

        Args:
            pieces, blend, duration, speed, profile, weave, torch, max_acceleration: As in
                :meth:`seam` (the seam's own move, planned next).
            at: The approach's goal: the seam's start (pose, or position [m] keeping the
                current orientation).

        Returns:
            The seam's first configuration [rad], shape (nq,), for the approach to end at; None
            when the seam cannot be planned from there (the approach then goes as taught and
            :meth:`seam` fails the seam, saying why).
        """
        self._check_open()
        self._ahead = None
        if not torch.searched or self.robot.default_position_only():
            return None
        try:
            start = goal_from(at, self.tool_pose())
            path = torch_path(seam_path(pieces, blend, start, False), torch)
            if weave is not None:
                travel = DEFAULT_TOOL_SPEED if speed is None else speed
                path = weave_path(path, weave, travel)
            plan = self._plan_seam(path, torch, duration, speed, profile, max_acceleration, None)
        except KinplanError:
            return None  # the seam's own move says why
        self._ahead = (path, plan)
        return np.array(plan.q[0]) if plan.ok and len(plan.t) else None

    def _plan_seam(
        self,
        path: cartesian.Path,
        torch: TorchSpec,
        duration: float | None,
        speed: float | None,
        profile: str,
        max_acceleration: object,
        q_start: np.ndarray | None,
    ) -> cartesian.CartesianPlan:
        """:func:`cartesian.plan_seam` of a torch seam (its roll free or fixed at the path's,
        its tolerance bands [rad]) with the builder's cell, dt and acceleration limits."""
        limit = self._acceleration_limit(max_acceleration)
        if duration is None and speed is None:
            if path.length > 0:
                speed = DEFAULT_TOOL_SPEED
            else:
                duration = 1.0
        return cartesian.plan_seam(
            self.robot, path, speed=speed, duration=duration, dt=self.dt,
            roll="free" if torch.roll is None else 0.0,  # a fixed roll is in the path's poses
            work_tolerance=torch.work_tolerance, travel_tolerance=torch.travel_tolerance,
            q_start=q_start, cell=self.cell, clearance=self.clearance, profile=profile,
            whole_periods=True, max_acceleration=limit if np.all(np.isfinite(limit)) else None,
        )  # fmt: skip

    def _searched_seam(
        self,
        path: cartesian.Path,
        torch: TorchSpec,
        *,
        duration: float | None,
        speed: float | None,
        profile: str,
        label: str,
        key: str | None,
        kind: str,
        max_acceleration: float | Sequence[float] | np.ndarray | None,
    ) -> MoveReport:
        """A torch seam planned by :func:`cartesian.plan_seam`: the plan made before the
        approach (:meth:`seam_start`) when the arm is at its start, else one from the current
        configuration (``q_start``: the roll free from there on)."""
        limit = self._acceleration_limit(max_acceleration)
        here = self.tool_pose().translation
        gap = float(np.linalg.norm(path.start.translation - here))
        if gap > 1e-4:
            why = start_gap_reason(path.start.translation, here, gap)
            self._fail(kind, label, key, status="invalid", why=why)
        ahead, self._ahead = self._ahead, None
        plan = None
        if ahead is not None:
            before, planned = ahead
            moved = float(np.linalg.norm(before.start.translation - here))
            joins = not (planned.ok and len(planned.t)) or (
                float(np.max(np.abs(planned.q[0] - self.q))) <= JOIN_TOLERANCE
            )
            if moved <= 1e-4 and joins:
                path, plan = before, planned
        if plan is None:
            axis = self.tool_pose().rotation[:, 2] @ path.start.rotation[:, 2]
            turn = math.acos(min(1.0, max(-1.0, float(axis))))
            band = math.hypot(torch.work_tolerance, torch.travel_tolerance)
            if turn > band + TORCH_START_TOLERANCE:  # the torch axis, whatever its roll
                self._fail(kind, label, key, status="invalid",
                           why=torch_start_reason(path.start, turn))  # fmt: skip
            try:
                plan = self._plan_seam(
                    path, torch, duration, speed, profile, max_acceleration, self.q
                )
            except KinplanError as exc:
                self._fail(kind, label, key, status="invalid", why=f"invalid: {exc}")
        return self._take_plan(plan, plan.path, kind, label, key, limit, 0.0)

    def _check_torch_start(
        self, path: cartesian.Path, kind: str, label: str, key: str | None
    ) -> None:
        """Refuse a torch seam whose start orientation is not the tool's (within
        :data:`TORCH_START_TOLERANCE`),
        printing the orientation with the digits that make pasting it work."""
        turn = start_turn(path, self.tool_pose(), False)
        if turn > TORCH_START_TOLERANCE:
            why = torch_start_reason(path.start, turn)
            self._fail(kind, label, key, status="invalid", why=why)

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
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
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
            max_acceleration: As in :meth:`seam`.
        """
        self._check_open()
        limit = self._acceleration_limit(max_acceleration)
        here = self.tool_pose().translation
        gap = float(np.linalg.norm(path.start.translation - here))
        if gap > 1e-4:
            why = start_gap_reason(path.start.translation, here, gap)
            self._fail(kind, label, key, status="invalid", why=why)
        turn = start_turn(path, self.tool_pose(), self.robot.default_position_only())
        if turn > 1e-3:
            self._fail(kind, label, key, status="invalid", why=start_turn_reason(turn))
        if duration is None and speed is None:
            if path.length > 0:
                speed = DEFAULT_TOOL_SPEED
            else:
                duration = 1.0
        try:
            plan = cartesian.follow(
                self.robot, path, duration=duration, speed=speed, profile=profile, dt=self.dt,
                q_seed=self.q, cell=self.cell, clearance=self.clearance, whole_periods=True,
                max_acceleration=limit if np.all(np.isfinite(limit)) else None,
            )  # fmt: skip
        except KinplanError as exc:
            self._fail(kind, label, key, status="invalid", why=f"invalid: {exc}")
        return self._take_plan(plan, path, kind, label, key, limit, turn)

    def _take_plan(
        self,
        plan: cartesian.CartesianPlan,
        path: cartesian.Path,
        kind: str,
        label: str,
        key: str | None,
        limit: np.ndarray,
        turn: float,
    ) -> MoveReport:
        """Record a Cartesian plan from the current configuration: a move, or its failure
        (a jump from the current configuration, the plan's first event). ``turn`` [rad]: the
        path start's angle to the tool's orientation."""
        self.paths.append(path)
        ratio = plan.peak_speed_ratio
        samples = (plan.t, plan.q, plan.qd, plan.qdd) if len(plan.t) else None
        gap = float(np.max(np.abs(plan.q[0] - self.q))) if samples else 0.0
        if gap > JOIN_TOLERANCE:
            offset: float | None = None
            if gap < SMALL_GAP:  # not another branch: the tool is not quite at the path start
                offset = float(
                    np.linalg.norm(path.start.translation - self.tool_pose().translation)
                )
            why = jump_reason(gap, offset, turn)
            self._fail(kind, label, key, status="jump", why=why, ratio=ratio, plan=plan)
        if not plan.ok:
            event = plan.events[0]
            why = f"{event.kind} at s = {event.s:.2f}: {event.message}; {program_remedy(plan)}"
            self._fail(
                kind, label, key, samples, status=plan.status, why=why, ratio=ratio,
                fraction=plan.fraction, plan=plan,
            )  # fmt: skip
        return self._record(
            kind, label, key, samples, ratio=ratio, plan=plan, acceleration_limit=limit
        )

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
            segments=self._motion.segments,
        )

    def fail_move(
        self, kind: str, label: str, key: str | None, *, status: str, why: str
    ) -> NoReturn:
        """Record a move that cannot be planned (e.g. a point without an IK solution) and raise
        :class:`~kinplan.program.MoveError`; ``why`` starts with the status."""
        self._check_open()
        self._fail(kind, label, key, status=status, why=why)

    # -- helpers -------------------------------------------------------------------------------
    def _check_open(self) -> None:
        if self.reason:
            raise KinplanError(f"planning stopped at the failed move: {self.reason}")

    def _target(self, goal: Goal) -> tuple[np.ndarray, np.ndarray | None]:
        """(position, rotation or None) of a Cartesian goal, applying the orientation rule."""
        pose = goal_from(goal, self.tool_pose())
        if self.robot.default_position_only():
            return pose.translation.copy(), None
        return pose.translation.copy(), pose.rotation.copy()

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
        segments: list[Segment] | None = None,
        acceleration_limit: np.ndarray | None = None,
    ) -> MoveReport:
        """Append a move that was done (samples in local times from 0) and its report
        (``segments``: its own motion in local time, else quintic Hermite pieces through the
        samples; ``acceleration_limit``: the limits it kept, default the builder's)."""
        if samples is not None:
            self.q = np.array(samples[1][-1])
        limit = self.acceleration_limit if acceleration_limit is None else acceleration_limit
        return self._motion.append(
            kind, label, key, samples, ratio=ratio, plan=plan, check=check, segments=segments,
            acceleration_limit=limit,
        )  # fmt: skip

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
