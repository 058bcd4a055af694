"""The work cells of the free-motion tests and benchmark: a UR5 and a panda among a table, a wall,
a two-board shelf and a pillar (boxes and a cylinder, posed in the robot's base frame)."""

from __future__ import annotations

import numpy as np

import kinplan
from kinplan.cell import WorkCell, xyz_rpy


def ur5_cell(robot: kinplan.Robot | None = None) -> WorkCell:
    """A UR5 on a table, a wall behind it, a two-board shelf in front-right, a pillar front-left."""
    robot = robot or kinplan.load_robot("ur5")
    cell = WorkCell(robot)
    cell.add_box("table", (1.6, 1.2, 0.04), xyz_rpy((0.3, 0.0, -0.02)))
    cell.add_box("wall", (0.02, 1.6, 1.2), xyz_rpy((-0.55, 0.0, 0.6)))
    cell.add_box("shelf_low", (0.3, 0.5, 0.02), xyz_rpy((0.5, -0.35, 0.25)))
    cell.add_box("shelf_high", (0.3, 0.5, 0.02), xyz_rpy((0.5, -0.35, 0.55)))
    cell.add_cylinder("pillar", 0.05, 1.0, xyz_rpy((0.4, 0.35, 0.5)))
    return cell


def panda_cell(robot: kinplan.Robot | None = None) -> WorkCell:
    """A panda on a table, a wall, a two-board shelf and a pillar (closer in: reach 0.85 m)."""
    robot = robot or kinplan.load_robot("panda")
    cell = WorkCell(robot)
    cell.add_box("table", (1.4, 1.2, 0.04), xyz_rpy((0.3, 0.0, -0.021)))
    cell.add_box("wall", (0.02, 1.4, 1.2), xyz_rpy((-0.45, 0.0, 0.6)))
    cell.add_box("shelf_low", (0.25, 0.4, 0.02), xyz_rpy((0.45, -0.3, 0.25)))
    cell.add_box("shelf_high", (0.25, 0.4, 0.02), xyz_rpy((0.45, -0.3, 0.5)))
    cell.add_cylinder("pillar", 0.04, 1.0, xyz_rpy((0.4, 0.3, 0.5)))
    return cell


def colliding_pairs(
    cell: WorkCell, count: int, seed: int, clearance: float = 0.0
) -> list[tuple[np.ndarray, np.ndarray]]:
    """``count`` start/goal pairs of free configurations whose straight joint move collides
    (seeded: the same pairs for the same seed).

    Configurations are drawn uniformly within the joint limits clipped to ±π, and for UR arms
    the shoulder lift within [−π, 0] (the upper arm above the table's plane). A UR's joints
    reach ±2π, but the table under it splits that space into parts no motion joins: the upper
    arm cannot swing through the table, so a shoulder lift of +180° (horizontal, backwards) is
    not joined to one of −90° (upright) although −180° is the same pose. Pairs across such a
    split have no solution for a joint goal (``any_turn=True`` solves them).
    """
    robot = cell.robot
    rng = np.random.default_rng(seed)
    lower, upper = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
    if robot.name.startswith("ur"):
        upper[1] = 0.0
    pairs: list[tuple[np.ndarray, np.ndarray]] = []
    free: list[np.ndarray] = []
    for _ in range(1000 * count):
        if len(pairs) == count:
            return pairs
        q = lower + (upper - lower) * rng.random(robot.nq)
        if cell.collisions(q, margin=clearance):
            continue
        if free and not cell.check_motion(np.stack([free[-1], q]), clearance).ok:
            pairs.append((free.pop(), q))
        else:
            free.append(q)
    raise AssertionError(f"found {len(pairs)} of {count} pairs: the cell is too cluttered")
