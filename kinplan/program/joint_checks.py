"""A joint-space (ptp) move's samples checked: the share of the velocity limits its continuous
motion reaches, and its cell check on a grid fine enough for a short move, reported on the
caller's grid.

In :mod:`kinplan.program`, after :mod:`~kinplan.program.peaks` (which it uses) and before
:mod:`~kinplan.program.build`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from kinplan.cell import MotionCheck, WorkCell
from kinplan.model.robot import Robot
from kinplan.program.peaks import joint_peaks
from kinplan.trajectory import Trajectory

__all__ = ["cell_check", "speed_ratio"]


def speed_ratio(robot: Robot, traj: Trajectory) -> float:
    """The largest share of a joint's velocity limit that the continuous motion reaches [-]
    (joints without a velocity limit left out)."""
    peaks = joint_peaks(traj)
    finite = np.isfinite(robot.velocity_limit)
    return float(np.max(peaks.speed[finite] / robot.velocity_limit[finite], initial=0.0))


def cell_check(
    cell: WorkCell,
    clearance: float,
    traj: Trajectory,
    t: np.ndarray,
    q: np.ndarray,
    step: float,
    dt: float,
) -> MotionCheck:
    """The cell check of a joint motion sampled at ``t`` [s] (``q`` [rad], period ``dt``).

    The samples recorded are the caller's grid; the cell is checked on a grid fine enough for a
    short move (period ``step``: at least MIN_INTERVALS intervals), which contains it when finer.
    A failure found there is reported at the first caller sample at or after it, the distances
    interpolated onto ``t``.
    """
    fine_t = t if step >= dt else traj.time_grid(step)
    fine_q = q if step >= dt else traj.sample(fine_t)[0]
    check = cell.check_motion(fine_q, clearance)
    if check.index is not None and step < dt:  # the first caller sample at/after
        at = float(fine_t[check.index])
        index = int(np.searchsorted(t, at - 1e-12))
        check = dataclasses.replace(
            check, index=index, between=check.between or not np.isclose(t[index], at),
            distances=np.interp(t, fine_t, check.distances),
            obstacle_distances=np.interp(t, fine_t, check.obstacle_distances),
            self_distances=np.interp(t, fine_t, check.self_distances),
        )  # fmt: skip
    return check
