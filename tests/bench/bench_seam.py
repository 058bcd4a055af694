"""Seam planning benchmark (issue 27): ``cartesian.plan_seam`` on a 330° tube seam.

The seam: a fillet around the foot of a vertical tube of radius 5 cm standing in front of the
arm (UR5: foot at (0.45, 0, 0.1) m; panda: (0.45, 0, 0.2) m), 330° counter-clockwise from the
side facing away from the base, the torch 45° down pointing at the tube, taught roll 0
(:func:`tests.cartesian.seam_corpus.tube_seam`); tool speed 0.02 m/s, samples every 10 ms.
``plan_seam`` samples the seam every 10° (its default ``resolution``) with the roll free.

Rows (median over ``--repeat`` calls after one warm-up; wall clock and this process's CPU time):
    plan_seam: the whole call — candidates, ladder graph, smoothing and the final tracking
        by ``cartesian.follow`` (its monitoring included).
    taught roll: ``cartesian.follow`` with roll 0 from the IK solution nearest the arm's
        neutral configuration (what kinplan did before issue 27).
    brute force (``--brute``): constant rolls every 10° × every IK start of the first pose
        (UR5: 8 branches, wrist 3 also a turn away; panda: θ7 at 6 values), each screened by
        ``check_reachability`` and followed: the least joint travel found, and the time.

Joint travel is Σ|Δq| over the plan [rad and °]. Tesseract's Descartes (the issue's reference:
0.16 s, 476° on the UR5 seam) is not installed here (``pip install tesseract-robotics`` needs
its plugins by absolute path); its figures are quoted from PEERS.md.

Usage:
    python tests/bench/bench_seam.py [--repeat 5] [--brute]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

import cartesian
import kinplan

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cartesian"))
from seam_corpus import tube_seam  # noqa: E402
from test_plan_seam import brute_force_all  # noqa: E402

SPEED, DT = 0.02, 0.01
CENTRES = {"ur5": [0.45, 0.0, 0.1], "panda": [0.45, 0.0, 0.2]}


def seam(name: str) -> cartesian.Path:
    """The benchmark's 330° tube seam for robot ``name``."""
    return tube_seam(CENTRES[name], 0.05, math.radians(330.0), math.pi)


def timed(call, repeat: int) -> tuple[float, float, object]:
    """(median wall [s], median CPU [s], last result) of ``call()`` after one warm-up."""
    result = call()
    walls, cpus = [], []
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        result = call()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return float(np.median(walls)), float(np.median(cpus)), result


def travel(plan: cartesian.CartesianPlan) -> float:
    return float(np.abs(np.diff(plan.q, axis=0)).sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--brute", action="store_true", help="also run the brute-force search")
    args = parser.parse_args()
    print("| robot | method | status | wall [s] | CPU [s] | joint travel |")
    print("|---|---|---|---|---|---|")
    for name in ("ur5", "panda"):
        robot = kinplan.load_robot(name)
        path = seam(name)
        rows = []
        wall, cpu, plan = timed(
            lambda r=robot, p=path: cartesian.plan_seam(r, p, speed=SPEED, dt=DT), args.repeat
        )
        rows.append(("plan_seam (roll free)", plan, wall, cpu))
        home = robot.ik(path.start, q_seed=robot.neutral()).q
        wall, cpu, plan = timed(
            lambda r=robot, p=path, q=home: cartesian.follow(r, p, speed=SPEED, dt=DT, q_seed=q),
            args.repeat,
        )
        rows.append(("taught roll (follow)", plan, wall, cpu))
        if args.brute:
            w, c = time.perf_counter(), time.process_time()
            best = brute_force_all(robot, path, SPEED, math.radians(10.0), 6)
            rows.append(("brute force", best, time.perf_counter() - w, time.process_time() - c))
        for label, plan, wall, cpu in rows:
            if plan is None:
                print(f"| {name} | {label} | none | {wall:.3f} | {cpu:.3f} | — |")
                continue
            moved = (
                f"{travel(plan):.2f} rad ({math.degrees(travel(plan)):.0f}°)" if plan.ok else "—"
            )
            print(f"| {name} | {label} | {plan.status} | {wall:.3f} | {cpu:.3f} | {moved} |")


if __name__ == "__main__":
    main()
