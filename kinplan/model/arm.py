"""What the layers below :class:`kinplan.Robot` need of a robot: its model, joints, limits, tool
frame and forward kinematics — as a protocol of their own.

The IK solvers, the batch solver and the work cell take an arm; :class:`kinplan.Robot` builds
them and has all of this. Typing them with :class:`Arm` (not with ``Robot``) keeps the imports
one-way: ``kinplan.model.robot`` imports ``kinplan.ik`` and ``kinplan.cell``, never the reverse.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np
import pinocchio as pin


@runtime_checkable
class Arm(Protocol):
    """A serial arm as the lower layers see it (a :class:`kinplan.Robot` is one).

    Attributes:
        name: The robot's name.
        model: Pinocchio model of the chain, one coordinate per joint (radians or metres).
        nq: Number of joint coordinates.
        joint_names: Names of the joints of ``q``, in order.
        tip_id: Index of the tool frame in ``model.frames``.
        lower: Lower joint limits [rad or m], shape (nq,).
        upper: Upper joint limits [rad or m], shape (nq,).
        urdf_path: The URDF the model was read from.
    """

    name: str
    model: pin.Model
    nq: int
    joint_names: list[str]
    tip_id: int
    lower: np.ndarray
    upper: np.ndarray
    urdf_path: Path

    def check_q(self, q: Sequence[float] | np.ndarray, what: str = "q") -> np.ndarray:
        """``q`` as a float array of shape (nq,) [rad or m], or an InputError naming ``what``."""
        ...

    def fk(self, q: Sequence[float] | np.ndarray) -> pin.SE3:
        """Pose of the tool frame in the base (world) frame at ``q``."""
        ...

    def neutral(self) -> np.ndarray:
        """A configuration within the limits [rad or m] (the model's neutral, clipped)."""
        ...

    def random_configuration(self, rng: np.random.Generator) -> np.ndarray:
        """A uniformly random configuration within the limits [rad or m]."""
        ...
