"""Chaining moves into one sampled joint motion: :class:`MotionBuilder`.

Each move (``ptp``, ``lin``, ``circ``, or any :class:`cartesian.Path` to follow) starts from the
end state of the previous one; :meth:`MotionBuilder.finish` returns the whole motion as a
:class:`~kinplan.program.ProgramPlan`.

In :mod:`kinplan.program`, after :mod:`~kinplan.program.ptp` (the timing of ptp moves),
:mod:`~kinplan.program.joint_checks` (a ptp move's speed share and cell check),
:mod:`~kinplan.program.record` (the samples and reports so far),
:mod:`~kinplan.program.remedies` (how a failed move is worded) and
:mod:`~kinplan.program.seams` (the paths of lin, circ and seam moves),
:mod:`~kinplan.program.builder_base` (the state, the record, failures) and
:mod:`~kinplan.program.cartesian_moves` (lin, circ, seams, paths), and before
:mod:`~kinplan.program.run`. This module adds the joint moves: ptp, splines through points,
trajectories, dwells and transit moves around the cell.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from cartesian.events import collision_event
from kinplan.cell import WorkCell
from kinplan.errors import KinplanError
from kinplan.program.builder_base import is_real
from kinplan.program.cartesian_moves import CartesianMoves
from kinplan.program.checker import describe
from kinplan.program.joint_checks import cell_check, speed_ratio
from kinplan.program.plan import MoveReport
from kinplan.program.ptp import (
    PtpLimitError,
    limit_problem,
    motion_limits,
    plan_ptp,
    plan_ptp_through,
)
from kinplan.program.remedies import (
    ik_reason,
    ptp_collision_reason,
    trajectory_remedy,
)
from kinplan.program.schema import (
    AVOID_TIME_LIMIT,
    JOIN_TOLERANCE,
)
from kinplan.program.seams import (
    Goal,
    SeamPiece,
)
from kinplan.trajectory import Segment, Trajectory, whole_periods
from kinplan.trajectory.sampling import motion_step

__all__ = ["Goal", "MotionBuilder", "SeamPiece"]


class MotionBuilder(CartesianMoves):
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
        if not (is_real(seconds) and math.isfinite(seconds) and seconds >= 0):
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
