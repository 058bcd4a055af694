"""The state every :class:`~kinplan.program.MotionBuilder` move starts from and ends in:
:class:`BuilderBase` holds the robot, the current configuration, the cell and the limits,
records each move (:mod:`~kinplan.program.record`) or its failure, and finishes the whole motion
as a :class:`~kinplan.program.ProgramPlan`. The moves themselves are in
:mod:`~kinplan.program.cartesian_moves` (lin, circ, seams, paths) and
:mod:`~kinplan.program.build` (ptp, splines, dwells, transit moves).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import NoReturn

import numpy as np
import pinocchio as pin

import cartesian
from kinplan import checks
from kinplan.cell import MotionCheck, WorkCell
from kinplan.errors import InputError, KinplanError
from kinplan.model.robot import Robot
from kinplan.program.checker import describe
from kinplan.program.plan import MoveReport, ProgramPlan
from kinplan.program.ptp import (
    acceleration_limits,
)
from kinplan.program.record import MotionRecord
from kinplan.program.remedies import (
    too_many_samples_reason,
)
from kinplan.program.schema import (
    DEFAULT_DT,
    MAX_SAMPLES,
    Program,
)
from kinplan.program.seams import (
    Goal,
    goal_from,
)
from kinplan.trajectory import Segment

__all__ = ["BuilderBase"]


def is_real(value: object) -> bool:
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


class BuilderBase:
    """State and bookkeeping of :class:`~kinplan.program.MotionBuilder` (see it for the
    arguments and attributes): the current configuration, the recorded motion, failures."""

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
        if not (is_real(dt) and math.isfinite(dt) and dt > 0):
            raise KinplanError(f"dt must be a finite number of seconds > 0, got {dt!r}")
        if cell is not None and not isinstance(cell, WorkCell):
            raise KinplanError(f"cell must be a kinplan.WorkCell, got {describe(cell)}")
        if not (is_real(clearance) and math.isfinite(clearance) and clearance >= 0):
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

    def _check_samples(self, count: float, kind: str, label: str, key: str | None,
                       what: str) -> None:  # fmt: skip
        """Fail a move that would take the program past :data:`MAX_SAMPLES` samples at this dt
        (before allocating them)."""
        total = len(self._motion) + count
        if not total <= MAX_SAMPLES:  # also NaN and inf
            why = too_many_samples_reason(what, self.dt, total)
            self._fail(kind, label, key, status="invalid", why=why)

    def _acceleration_limit(self, max_acceleration: object) -> np.ndarray:
        """A move's acceleration limits [rad/s²]: its own ``max_acceleration`` (on top of the
        robot's) or the builder's."""
        given = _checked_acceleration(max_acceleration, self.robot.nq, "max_acceleration")
        return self.acceleration_limit if given is None else acceleration_limits(self.robot, given)

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
