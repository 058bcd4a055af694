"""The robot a command names (``ROBOT`` with ``--tip`` and ``--lock NAME=VALUE``) and the joint
values it is given."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence

import numpy as np

import kinplan
from kinplan.errors import InputError


def _locks(texts: Sequence[str] | None) -> dict[str, float] | None:
    """``--lock NAME=VALUE`` arguments as {name: value [rad or m]}.

    Raises:
        InputError: not NAME=VALUE with a finite number, or a joint given twice.
    """
    if not texts:
        return None
    locks: dict[str, float] = {}
    for text in texts:
        name, equals, value = text.partition("=")
        name = name.strip()
        try:
            number = float(value) if equals else math.nan
        except ValueError:
            number = math.nan
        if not name or not math.isfinite(number):
            raise InputError(
                f"--lock {text}: expected NAME=VALUE, the joint's name and its value in radians "
                "(metres for a prismatic joint), e.g. --lock torso_lift_joint=0.15"
            )
        if name in locks:
            raise InputError(f"--lock: joint {name!r} is locked twice")
        locks[name] = number
    return locks


def robot_of(args: argparse.Namespace) -> kinplan.Robot:
    """The robot of a command: ROBOT with ``--tip`` and ``--lock``."""
    return kinplan.load_robot(args.robot, tip=args.tip, locked_joints=_locks(args.lock))


def joint_values(robot: kinplan.Robot, values: Sequence[float], degrees: bool, what: str):
    q = np.radians(values) if degrees else np.asarray(values, dtype=float)
    return robot.check_q(q, what)
