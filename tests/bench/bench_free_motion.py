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

When OMPL's Python bindings are installed (``pip install ompl``), a second row per arm runs
OMPL's RRT-Connect on the same problems as the issue did: its state validity checker is the
independent re-check above (Pinocchio + coal, called from Python), motion validation at 1 % of
the space's extent (``setStateValidityCheckingResolution(0.01)``), ``solve(1.0)`` then
``simplifySolution()`` (both timed), the joint goal exact. Its "colliding" counts returned paths
(straight between their states) that collide at 0.5° steps; it returns no timing.

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


def run_ompl(name: str, n: int, seed: int) -> dict[str, object] | None:
    """The same problems with OMPL's RRT-Connect (None when OMPL is not installed)."""
    try:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou
    except ImportError:
        return None
    ou.setLogLevel(ou.LOG_NONE)
    cell = CELLS[name]()
    robot = cell.robot
    recheck = Recheck(robot, obstacles_of(cell), str(cell.srdf_path))
    nq = robot.nq
    space = ob.RealVectorStateSpace(nq)
    bounds = ob.RealVectorBounds(nq)
    for j in range(nq):
        bounds.setLow(j, float(robot.lower[j]))
        bounds.setHigh(j, float(robot.upper[j]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(
        lambda state: not recheck.colliding(np.array([state[j] for j in range(nq)]))
    )
    setup.getSpaceInformation().setStateValidityCheckingResolution(0.01)
    walls, lengths = [], []
    solved = colliding = 0
    for start, goal in colliding_pairs(cell, n, seed):
        setup.clear()
        ends = [space.allocState(), space.allocState()]
        for state, q in zip(ends, (start, goal)):
            for j in range(nq):
                state[j] = float(q[j])
        setup.setStartAndGoalStates(ends[0], ends[1])
        setup.setPlanner(og.RRTConnect(setup.getSpaceInformation()))
        began = time.perf_counter()
        found = bool(setup.solve(1.0)) and setup.haveExactSolutionPath()
        if found:
            setup.simplifySolution()
        walls.append(time.perf_counter() - began)
        if not found:
            continue
        solved += 1
        path = setup.getSolutionPath()
        points = np.array(
            [[path.getState(i)[j] for j in range(nq)] for i in range(path.getStateCount())]
        )
        lengths.append(float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1))))
        colliding += _polyline_collides(recheck, points)
    return {
        "robot": f"{name}, OMPL RRT-Connect",
        "pairs": n,
        "solved": solved / n,
        "colliding": colliding,
        "median_ms": 1e3 * float(np.median(walls)),
        "p95_ms": 1e3 * float(np.percentile(walls, 95)),
        "cpu_ms": float("nan"),
        "path": float(np.median(lengths)) if lengths else float("nan"),
        "waypoints": float("nan"),
        "duration": float("nan"),
        "statuses": {},
    }


def _polyline_collides(recheck: Recheck, points: np.ndarray) -> bool:
    """Whether the straight segments between ``points`` collide at ≤ 0.5° joint steps."""
    for a, b in zip(points[:-1], points[1:]):
        steps = max(1, int(np.ceil(np.max(np.abs(b - a)) / np.radians(0.5))))
        for f in np.linspace(0.0, 1.0, steps + 1):
            if recheck.colliding(a + f * (b - a)):
                return True
    return False


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
        for r in (run(name, args.n, args.seed), run_ompl(name, args.n, args.seed)):
            if r is None:
                print(f"| {name}, OMPL | not installed (pip install ompl) |")
                continue
            print(
                f"| {r['robot']} | {r['pairs']} | {100 * r['solved']:.0f} % | {r['colliding']} "
                f"| {r['median_ms']:.0f} | {r['p95_ms']:.0f} | {r['cpu_ms']:.0f} | "
                f"{r['path']:.2f} | {r['waypoints']:.0f} | {r['duration']:.2f} |"
            )


if __name__ == "__main__":
    main()
