"""kinplan: kinematic motion planning for URDF robot arms.

Robots (:func:`load_robot`, :func:`planar_arm`) with Pinocchio kinematics, joint-space
trajectories (:mod:`kinplan.trajectory`), Cartesian paths (the :mod:`cartesian` package) and
MeshCat playback (:mod:`kinplan.viewer`).
"""

from __future__ import annotations

import logging
from types import ModuleType
from typing import TYPE_CHECKING, Any

from kinplan.cell import Body, CellError, MotionCheck, WorkCell
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
from kinplan.robot import Robot, load_robot, planar_arm

if TYPE_CHECKING:  # imported on first use (see __getattr__): the planners load the timing
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


def __getattr__(name: str) -> ModuleType | Any:
    # `free_motion` and `MotionPlan` (kinplan.planning) on first use
    if name in ("free_motion", "MotionPlan"):
        from kinplan import planning

        return getattr(planning, name)
    # Submodules imported on first use: `kinplan.trajectory`, `kinplan.viewer`, `kinplan.plot`.
    if name in (
        "trajectory", "viewer", "plot", "program", "cli", "teach", "demos", "export",
        "reach", "batch", "placement", "planning",
    ):  # fmt: skip
        import importlib

        return importlib.import_module(f"kinplan.{name}")
    raise AttributeError(f"module 'kinplan' has no attribute {name!r}")
