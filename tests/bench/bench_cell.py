"""Work-cell benchmark: checking a 1,000-sample UR5 plan against a cell of 10 obstacles, beside
the inverse kinematics of that plan (issue 16: the check must cost less than the IK).

The plan: ``cartesian.follow`` of a straight 0.3 m tool line (+y, fixed orientation) over 1 s
sampled every 1 ms (1001 samples), by a UR5 carrying a welding torch (``Robot.with_tool``: TCP
0.3 m out and tilted 30°, a cylinder body). The cell: the table the robot stands on, the
workpiece under the line (15 mm below the torch tip's path), a fixture, two posts, a wall, a
shelf, a ball, a pipe and a mesh bracket (an STL written by trimesh): 10 obstacles; with the
robot's 9 bodies (8 links and the torch) 102 checked pairs: 80 robot–obstacle (the base link,
fixed in the world, is not checked against obstacles) and 22 self pairs (ur5.srdf).

Rows (each the median over ``--repeat`` calls, methods interleaved call by call, one warm-up):
    IK: ``cartesian.follow(robot, line, duration=1.0, dt=0.001, q_seed=q0)`` (IK per sample,
        warm-started, with its monitoring): the reference.
    check_motion c = 0 / c = 10 mm: ``cell.check_motion(plan.q, clearance)``: every sample and
        every segment between samples (conservative advancement), per-sample exact minima.
    sample by sample: ``cell.distance(q)`` at every sample: coal on every pair at every sample
        (Pinocchio's ``computeDistances``), no between-sample guarantee: what the bounds save.
    failing approach: ``check_motion`` of a 1,000-sample joint move whose torch goes through the
        workpiece (stops at the first collision).

"coal calls" counts exact pair distances. Times are wall clock and this process's CPU time
(``time.process_time``, less disturbed by other load on the machine); "× IK" is the CPU ratio.

Usage:
    python tests/bench/bench_cell.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin
import trimesh

import cartesian
import kinplan
from kinplan.cell import Body, WorkCell, xyz_rpy

Q0 = np.radians([0.0, -100.0, 100.0, -90.0, -90.0, 0.0])
DURATION, DT = 1.0, 0.001  # [s]
#: The torch, in the flange frame: its axis tilted 30° about x, the TCP (wire tip) 0.30 m along
#: it, the body (a cylinder of radius 18 mm) from 0.02 m to 0.27 m along it.
_TILT = pin.rpy.rpyToMatrix(np.radians(30.0), 0.0, 0.0)
TORCH_TCP = pin.SE3(_TILT, _TILT @ np.array([0.0, 0.0, 0.30]))
TORCH_BODY = Body.cylinder(0.018, 0.25, pin.SE3(_TILT, _TILT @ np.array([0.0, 0.0, 0.145])))


def bracket_stl(folder: Path) -> Path:
    """An L-shaped bracket (mm) as an STL file."""
    foot = trimesh.creation.box((120.0, 80.0, 10.0))
    web = trimesh.creation.box((10.0, 80.0, 90.0))
    web.apply_translation((-55.0, 0.0, 50.0))
    path = folder / "bracket.stl"
    trimesh.util.concatenate([foot, web]).export(path)
    return path


def build(folder: Path) -> tuple[kinplan.Robot, WorkCell, cartesian.Line, np.ndarray]:
    robot = kinplan.load_robot("ur5").with_tool(TORCH_TCP, TORCH_BODY)
    start = robot.fk(Q0)
    end = pin.SE3(start.rotation, start.translation + np.array([0.0, 0.3, 0.0]))
    line = cartesian.Line(start, end)
    tip = start.translation
    cell = WorkCell(robot)
    cell.add_box("table", (1.6, 1.2, 0.04), xyz_rpy((0.3, 0.0, -0.02)))
    part_top = tip[2] - 0.015
    cell.add_box("part", (0.15, 0.5, 0.1), xyz_rpy((tip[0], tip[1] + 0.15, part_top - 0.05)))
    cell.add_box("fixture", (0.05, 0.05, 0.12), xyz_rpy((tip[0] + 0.15, tip[1], 0.06)))
    cell.add_cylinder("post", 0.04, 0.9, xyz_rpy((0.65, 0.6, 0.45)))
    cell.add_cylinder("post2", 0.04, 0.9, xyz_rpy((-0.45, -0.5, 0.45)))
    cell.add_box("wall", (0.02, 1.6, 1.2), xyz_rpy((-0.75, 0.0, 0.6)))
    cell.add_box("shelf", (0.3, 0.3, 0.02), xyz_rpy((0.45, -0.5, 0.45)))
    cell.add_sphere("ball", 0.06, xyz_rpy((-0.1, 0.55, 0.75)))
    cell.add_cylinder("pipe", 0.03, 1.2, xyz_rpy((0.0, 0.0, 1.1), (90.0, 0.0, 0.0)))
    cell.add_mesh("bracket", bracket_stl(folder), xyz_rpy((0.5, -0.35, 0.0)), scale=0.001)
    return robot, cell, line, tip


def timed(run: Callable[[], object], repeat: int) -> tuple[object, float, float]:
    """(last result, median wall ms, median CPU ms)."""
    walls, cpus, result = [], [], None
    for _ in range(repeat):
        wall, cpu = time.perf_counter(), time.process_time()
        result = run()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return result, 1e3 * float(np.median(walls)), 1e3 * float(np.median(cpus))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        robot, cell, line, tip = build(Path(folder))
        plan = cartesian.follow(robot, line, duration=DURATION, dt=DT, q_seed=Q0)
        assert plan.ok, plan.status
        n_pairs = len(cell.checked_pairs)
        # a joint move from above the part down through it (the torch tip 5 cm into the part)
        rotation = robot.fk(Q0).rotation
        above = robot.ik(pin.SE3(rotation, tip + [0.0, 0.1, 0.1]), Q0)
        below = robot.ik(pin.SE3(rotation, tip + [0.0, 0.1, -0.05]), above.q)
        assert above.success and below.success
        plunge = above.q + np.linspace(0, 1, len(plan.q))[:, None] * (below.q - above.q)
        runs = {
            "IK (cartesian.follow)": lambda: cartesian.follow(
                robot, line, duration=DURATION, dt=DT, q_seed=Q0
            ),
            "check_motion, c = 0": lambda: cell.check_motion(plan.q),
            "check_motion, c = 10 mm": lambda: cell.check_motion(plan.q, clearance=0.01),
            "sample by sample (no between)": lambda: [cell.distance(q) for q in plan.q],
            "failing approach (plunge)": lambda: cell.check_motion(plunge),
        }
        for run in runs.values():  # warm-up
            run()
        results: dict[str, list[tuple[object, float, float]]] = {name: [] for name in runs}
        for _ in range(args.repeat):  # interleaved, one call each per round
            for name, run in runs.items():
                results[name].append(timed(run, 1))
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} CPUs; python "
        f"{platform.python_version()}, pinocchio {pin.__version__}, numpy {np.__version__}"
    )
    print(
        f"\nUR5 + torch, {len(plan.q)} samples, {len(cell.obstacles)} obstacles, "
        f"{n_pairs} checked pairs (robot bodies: {len(cell.robot_bodies)})\n"
    )
    print("| method | samples | coal calls | result | wall ms | CPU ms | × IK (CPU) |")
    print("|---|---:|---:|---|---:|---:|---:|")
    reference = float(np.median([cpu for _, _, cpu in results["IK (cartesian.follow)"]]))
    for name, rows in results.items():
        last = rows[-1][0]
        wall = float(np.median([w for _, w, _ in rows]))
        cpu = float(np.median([c for _, _, c in rows]))
        if name.startswith("IK"):
            samples, calls, outcome = len(last.q), "–", last.status
        elif name.startswith("sample"):
            samples, calls = len(last), len(last) * n_pairs
            outcome = f"min {min(last) * 1e3:.1f} mm"
        else:
            samples = len(plunge) if name.startswith("failing") else len(plan.q)
            calls = last.evaluations
            outcome = (
                last.describe()
                if not last.ok
                else (f"free, min {last.min_clearance * 1e3:.1f} mm ({' – '.join(last.min_pair)})")
            )
        print(f"| {name} | {samples} | {calls} | {outcome} | {wall:.1f} | {cpu:.1f} | "
              f"{cpu / reference:.2f} |")  # fmt: skip


if __name__ == "__main__":
    main()
