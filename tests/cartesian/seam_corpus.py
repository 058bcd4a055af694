"""Seeded corpora of hard weld seams for the seam planner's tests and benchmark.

Every seam is a :class:`cartesian.TorchOrientation` (torch axis = tool z, taught roll 0):

* tube seams: circumferential fillets around the foot of a vertical tube (radius 3–8 cm,
  270–360°) standing on a plate in front of the arm, the torch pointing at the tube's foot
  45° down (work angle ±45°, toward the tube), either direction of travel;
* T-joint fillets: straight seams along the corner of a plate and a wall, torch 45° into it,
  near the base, at the rim of the workspace and across the arm's front;
* seams near joint limits: tube seams low and to the side of the base.

Frames: the robot's base frame, metres and radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import cartesian


@dataclass
class Seam:
    """One corpus seam: its path and how it was made (for messages)."""

    name: str
    path: cartesian.Path


def tube_seam(
    center: np.ndarray | list[float],
    radius: float,
    sweep: float,
    start: float = 0.0,
    clockwise: bool = False,
) -> cartesian.TorchOrientation:
    """A fillet around the foot of a vertical tube: centre [m] (the foot's), radius [m], sweep
    [rad] from the angle ``start`` [rad]; the torch 45° down, pointing at the tube."""
    e1 = np.array([math.cos(start), math.sin(start), 0.0])
    e2 = np.array([-math.sin(start), math.cos(start), 0.0])
    if clockwise:
        e2 = -e2
    arc = cartesian.CircularArc(center, radius, e1, e2, sweep)
    work = -math.pi / 4 if clockwise else math.pi / 4  # toward the tube (left of travel: ccw)
    return cartesian.TorchOrientation(arc, normal=(0.0, 0.0, 1.0), work_angle=work)


def t_joint_seam(a: np.ndarray, b: np.ndarray, wall_side: float) -> cartesian.TorchOrientation:
    """A fillet from ``a`` to ``b`` [m] along a wall on the left (``wall_side`` = 1) or right
    (−1) of the travel direction, on a horizontal plate: torch 45° down into the corner."""
    return cartesian.TorchOrientation(
        cartesian.Line(a, b), normal=(0.0, 0.0, 1.0), work_angle=wall_side * math.pi / 4
    )


def corpus(robot_name: str, count: int, seed: int = 27) -> list[Seam]:
    """``count`` seeded seams for ``robot_name`` ("ur5" or "panda"): about 60 % tube seams,
    20 % T-joints, 20 % tube seams near the joint limits (low, beside the base)."""
    rng = np.random.default_rng(seed)
    height = (0.0, 0.15) if robot_name == "ur5" else (0.05, 0.3)
    seams: list[Seam] = []
    for k in range(count):
        kind = ("tube", "tube", "tube", "t_joint", "limits")[k % 5]
        if kind in ("tube", "limits"):
            if kind == "tube":
                center = [rng.uniform(0.35, 0.55), rng.uniform(-0.25, 0.25), rng.uniform(*height)]
            else:
                side = rng.choice([-1.0, 1.0])
                center = [rng.uniform(0.2, 0.35), side * rng.uniform(0.25, 0.4), height[0]]
            radius = rng.uniform(0.03, 0.08)
            sweep = math.radians(rng.uniform(270.0, 360.0))
            start = rng.uniform(-math.pi, math.pi)
            clockwise = bool(rng.integers(2))
            path = tube_seam(center, radius, sweep, start, clockwise)
            name = (
                f"{kind} {k}: r {radius * 100:.1f} cm, {math.degrees(sweep):.0f}°, centre "
                f"{np.round(center, 3).tolist()}, {'cw' if clockwise else 'ccw'}"
            )
        else:
            reach = 0.35 if robot_name == "ur5" else 0.3
            a = np.array([rng.uniform(0.25, 0.55), rng.uniform(-0.3, 0.0), rng.uniform(*height)])
            direction = rng.uniform(-math.pi, math.pi)
            b = a + reach * np.array([math.cos(direction), math.sin(direction), 0.0])
            path = t_joint_seam(a, b, float(rng.choice([-1.0, 1.0])))
            name = f"t_joint {k}: {np.round(a, 3).tolist()} → {np.round(b, 3).tolist()}"
        seams.append(Seam(name, path))
    return seams
