"""kinplan: kinematic motion planning for URDF robot arms.

Robots (:func:`load_robot`, :func:`planar_arm`) with Pinocchio kinematics, joint-space
trajectories (:mod:`kinplan.trajectory`), Cartesian paths (the :mod:`cartesian` package) and
MeshCat playback (:mod:`kinplan.viewer`).
"""

from __future__ import annotations

import logging
from types import ModuleType
from typing import TYPE_CHECKING, Any

from kinplan._moved import MOVED
from kinplan.cell import Body, CellError
from kinplan.errors import (
    FrameError,
    InfeasibleError,
    InputError,
    KinplanError,
    RobotNotFoundError,
    URDFError,
    ViewerError,
)
from kinplan.ik import IKResult
from kinplan.model.robot import Robot, load_robot, planar_arm

if TYPE_CHECKING:  # imported on first use (see __getattr__): the planners load the timing
    from kinplan.cell import MotionCheck, WorkCell
    from kinplan.planning import MotionPlan, free_motion

logging.getLogger(__name__).addHandler(logging.NullHandler())

__version__ = "0.1.0"

__all__ = [
    "Body",
    "CellError",
    "FrameError",
    "IKResult",
    "InfeasibleError",
    "InputError",
    "KinplanError",
    "MotionCheck",
    "MotionPlan",
    "Robot",
    "RobotNotFoundError",
    "URDFError",
    "ViewerError",
    "WorkCell",
    "free_motion",
    "load_robot",
    "planar_arm",
]


#: Submodules loaded on first use, by attribute name (old names of moved modules included).
_SUBMODULES = {
    **{name: f"kinplan.{name}" for name in ("trajectory", "viewer", "plot", "program", "export")},
    "planning": "kinplan.planning",
    **MOVED,
}


def __getattr__(name: str) -> ModuleType | Any:
    # `free_motion` and `MotionPlan` (kinplan.planning) on first use
    if name in ("free_motion", "MotionPlan"):
        from kinplan import planning

        return getattr(planning, name)
    if name in ("MotionCheck", "WorkCell"):  # the work cell's modules load on first use
        from kinplan import cell

        return getattr(cell, name)
    # Submodules imported on first use: `kinplan.trajectory`, `kinplan.viewer`, `kinplan.plot`, ...
    # and the old names of the modules that moved into sub-packages (issue 31): `kinplan.reach`
    # is `kinplan.scale.reach` (its old path is a shim that aliases the new module).
    if name in _SUBMODULES:
        import importlib

        return importlib.import_module(_SUBMODULES[name])
    raise AttributeError(f"module 'kinplan' has no attribute {name!r}")
