"""What :func:`cartesian.follow` returns: :class:`CartesianPlan`, a timed, monitored motion.

Frames and units: positions in the robot's base (world) frame [m], times [s], joints [rad or m].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cartesian.events import Event, OutOfReach
from cartesian.paths import Path
from kinplan.cell import MotionCheck, WorkCell
from kinplan.model.robot import Robot
from kinplan.trajectory import Waypoints
from kinplan.trajectory.motion import MotionKind, MoveSpan, PlannedPath, no_waypoints

__all__ = ["CartesianPlan"]


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
        peak_acceleration_ratio: Largest joint acceleration over its limit, where limited, at
            the samples and between them (0 where no joint is limited).
        max_interpolation_deviation: Largest tool distance from the path between the samples
            returned, of the motion a controller runs between them (the quintic Hermite
            interpolant through (q, q̇, q̈) at the samples, :func:`kinplan.sampling.
            hermite_between`) [m]; checked against ``interpolation_tolerance``.
        interpolation_tolerance: The tolerance of that deviation [m] the plan was checked with.
        slowdown: For a plan stopped by a speed or acceleration limit: a factor by which the
            law was slowed down and then planned without breaking those limits (the factor its
            remedy names), or None when none was found.
        accelerations_limited: Whether every joint's acceleration was limited (declared by the
            robot or given as ``max_acceleration``); when not, the plan's accelerations were
            not checked for those joints.
        check_step: The largest step of the grid every check ran on [s]: the caller's ``dt``,
            or a fraction of it for a motion shorter than 16 periods (the samples returned are
            always the caller's grid).
        roll: For a plan of :func:`cartesian.plan_seam`: the torch's rotation about its axis
            at each sample [rad], relative to the seam's poses, shape (N,); None for
            :func:`cartesian.follow`.
        tilt: For a plan of :func:`cartesian.plan_seam`: the torch axis' (work, travel)
            deviation from the seam's at each sample [rad], shape (N, 2); None otherwise.
        out_of_reach: For a plan of :func:`cartesian.follow` stopped by a singularity, a limit
            or a jump: the stretch ahead that no configuration reaches, when the arm's closed
            form or planar workspace proves one (:func:`cartesian.geometry.
            unreachable_stretch`); its remedy then says so instead of offering a slower law.
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
    peak_acceleration_ratio: float = 0.0
    max_interpolation_deviation: float = 0.0
    interpolation_tolerance: float = 0.0
    check_step: float = 0.0
    accelerations_limited: bool = True
    slowdown: float | None = None
    robot: Robot | None = None  # the robot it was planned for
    cell: WorkCell | None = None  # the work cell it was checked against (issue 16)
    cell_check: MotionCheck | None = None  # that check: pairs, per-sample distances
    roll: np.ndarray | None = None  # plan_seam: roll about the torch axis per sample [rad]
    tilt: np.ndarray | None = None  # plan_seam: (work, travel) deviation per sample [rad]
    out_of_reach: OutOfReach | None = None  # follow: the unreachable stretch ahead, if proven

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
        """One line: status, and the first event's message when there is one; an ok plan
        says when joint accelerations were not limited (no limit declared or given)."""
        if self.ok:
            text = f"ok: {len(self.t)} samples, {self.duration:.3f} s"
            if not self.accelerations_limited:
                text += (
                    "; joint accelerations not limited (the robot declares no acceleration "
                    "limit for some joints: give max_acceleration=)"
                )
            return text
        return f"{self.status} at s = {self.events[0].s:.3f}: {self.events[0].message}"


# ------------------------------------------------------------------------------------------
