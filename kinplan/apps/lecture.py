"""The lecture's worked example: its numbers and the two helpers every use of it needs.

Robotics (Prof. P. Seshu, IIT Bombay), lecture 14, trajectory planning: a planar 2R arm with
l1 = l2 = 1 m moves its tip B from (1.366, 1.366) m to (−1.366, 1.366) m in 1 s, at rest at both
ends, through the via point (0, 1.366) m at 0.5 s (1.366 = (1 + √3)/2, so the joint angles come
out round: θ = (30°, 30°) at the start, (150°, −30°) at the end on the other elbow branch).
Used by ``examples/lecture_2r.py`` and ``kinplan demo lecture``.
"""

from __future__ import annotations

import numpy as np

from kinplan.errors import KinplanError
from kinplan.model.robot import Robot
from kinplan.trajectory import Trajectory

TIP = (1.0 + np.sqrt(3.0)) / 2.0
"""1.366 m: both coordinates of the start point."""
START_XY = (TIP, TIP)
"""Start of the tip B [m]."""
VIA_XY = (0.0, TIP)
"""The via point [m], on the straight line between start and end."""
END_XY = (-TIP, TIP)
"""End of the tip B [m] (the start mirrored about the y axis)."""
DURATION = 1.0
"""Duration of the motion [s]."""
VIA_TIME = 0.5
"""Time of the via point [s]."""
JOINTS = ("θ1", "θ2")
"""Joint names as the lecture writes them."""
START_SEED = np.radians([30.0, 30.0])
"""The lecture's elbow branch at the start [rad]."""


def solve_ik(robot: Robot, xy: tuple[float, float], seed: np.ndarray) -> np.ndarray:
    """Joint angles [rad] that put the tip at ``xy`` [m], on the seed's branch.

    Raises:
        KinplanError: no solution (the point is out of the arm's reach).
    """
    result = robot.ik(np.array([xy[0], xy[1], 0.0]), q_seed=seed, position_only=True)
    if not result.success:
        raise KinplanError(
            f"no inverse kinematics solution for the tip at {xy} m "
            f"(error {result.position_error:.3g} m)"
        )
    return result.q


def tip_path(robot: Robot, motion: Trajectory, dt: float) -> np.ndarray:
    """Tip positions [m] along a joint motion sampled every ``dt`` [s], shape (k, 3)."""
    return robot.tool_positions(motion.sample(motion.time_grid(dt))[0])
