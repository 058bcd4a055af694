"""Work cells: obstacles, the robot's collision geometry, distances and motion checks (coal).

* :class:`WorkCell` — a robot among obstacles: :meth:`~WorkCell.distance`,
  :meth:`~WorkCell.collisions`, :meth:`~WorkCell.check_motion` (between samples too);
* :class:`Body` — a box, cylinder, sphere or mesh with its pose (an obstacle, or a tool body
  for :meth:`kinplan.Robot.with_tool`); :func:`xyz_rpy` builds a pose;
* :class:`MotionCheck`, :class:`PairDistance`, :class:`ExcludedPair` — results;
* :class:`CellError` — a wrong cell or tool argument (a :class:`kinplan.KinplanError`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from kinplan._lazy import lazy_attributes
from kinplan.cell.body import Body, CellError, xyz_rpy

if TYPE_CHECKING:  # loaded on first use (see __getattr__)
    from kinplan.cell.motion import TOLERANCE, MotionCheck
    from kinplan.cell.robot_geometry import ExcludedPair
    from kinplan.cell.work_cell import PairDistance, WorkCell

#: Names loaded on first use, by module: a robot with a tool body needs only :mod:`.body`.
_LAZY = {
    "TOLERANCE": "motion",
    "MotionCheck": "motion",
    "ExcludedPair": "robot_geometry",
    "PairDistance": "work_cell",
    "WorkCell": "work_cell",
}


__getattr__ = lazy_attributes(__name__, _LAZY)


__all__ = [
    "TOLERANCE",
    "Body",
    "CellError",
    "ExcludedPair",
    "MotionCheck",
    "PairDistance",
    "WorkCell",
    "xyz_rpy",
]
