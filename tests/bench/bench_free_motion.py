"""Collision-free transit moves: kinplan.free_motion on start/goal pairs whose straight move
collides, every returned motion re-checked independently (issue 28).

The cells (``tests/planning/free_motion_cells.py``): a UR5 and a panda each on a table, with a
wall behind, a two-board shelf and a pillar. The problems: ``--n`` pairs of collision-free
configurations drawn uniformly within the joint limits clipped to ±π (seeded), kept when the
straight joint move between them collides (kinplan's motion check); the goal is the joint
vector itself (not its 2π-equivalents).

Columns:
    solved: share of the pairs planned (``status == "ok"``) within ``time_limit = 1 s``.
    colliding: returned motions in collision when re-checked with Pinocchio and coal called
        directly (``tests/planning/independent.py``: the URDF read again, trimesh's convex
        hulls, the obstacles rebuilt) at joint steps of at most 0.5° along the timed trajectory.
    time: median and 95th percentile of ``plan.planning_time`` (wall clock of the whole call:
        search, shortcuts, timing and the check of the timed path), and the median CPU time of
        this process per call (``time.process_time``, less disturbed by other load).
    path: median joint path length of the waypoints' polyline [rad] (Euclidean over joints).
    waypoints: median number of waypoints; duration: median duration of the timed motion [s].

Usage:
    python tests/bench/bench_free_motion.py [--n 50] [--seed 1] [--robots ur5 panda]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "planning"))

from free_motion_cells import colliding_pairs, panda_cell, ur5_cell  # noqa: E402
from independent import Recheck, obstacles_of  # noqa: E402

from kinplan.planning import free_motion  # noqa: E402

CELLS = {"ur5": ur5_cell, "panda": panda_cell}


def run(name: str, n: int, seed: int) -> dict[str, object]:
    cell = CELLS[name]()
    recheck = Recheck(cell.robot, obstacles_of(cell), str(cell.srdf_path))
    pairs = colliding_pairs(cell, n, seed)
    free_motion(cell.robot, *pairs[0], cell, seed=0)  # warm-up: the cell's screen, numpy
    walls, cpus, lengths, waypoints, durations = [], [], [], [], []
    solved = colliding = 0
    statuses: dict[str, int] = {}
    for k, (start, goal) in enumerate(pairs):
        cpu = time.process_time()
        plan = free_motion(cell.robot, start, goal, cell, seed=k, time_limit=1.0)
        cpus.append(time.process_time() - cpu)
        walls.append(plan.planning_time)
        statuses[plan.status] = statuses.get(plan.status, 0) + 1
        if not plan.ok:
            continue
        solved += 1
        colliding += bool(recheck.motion(plan.trajectory))
        lengths.append(plan.path_length)
        waypoints.append(len(plan.waypoints))
        durations.append(plan.duration)
    return {
        "robot": name,
        "pairs": n,
        "solved": solved / n,
        "colliding": colliding,
        "median_ms": 1e3 * float(np.median(walls)),
        "p95_ms": 1e3 * float(np.percentile(walls, 95)),
        "cpu_ms": 1e3 * float(np.median(cpus)),
        "path": float(np.median(lengths)) if lengths else float("nan"),
        "waypoints": float(np.median(waypoints)) if waypoints else float("nan"),
        "duration": float(np.median(durations)) if durations else float("nan"),
        "statuses": statuses,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=50)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--robots", nargs="+", default=["ur5", "panda"], choices=list(CELLS))
    args = parser.parse_args()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"load average before the run: {load:.2f} ({os.cpu_count()} cores)")
    print(
        "| robot | pairs | solved ≤ 1 s | colliding (re-check) | median time [ms] | p95 [ms] "
        "| median CPU [ms] | median path [rad] | waypoints | duration [s] |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in args.robots:
        r = run(name, args.n, args.seed)
        print(
            f"| {r['robot']} | {r['pairs']} | {100 * r['solved']:.0f} % | {r['colliding']} | "
            f"{r['median_ms']:.0f} | {r['p95_ms']:.0f} | {r['cpu_ms']:.0f} | {r['path']:.2f} | "
            f"{r['waypoints']:.0f} | {r['duration']:.2f} |"
        )
        print(f"<!-- {name} statuses: {r['statuses']} -->")


if __name__ == "__main__":
    main()
