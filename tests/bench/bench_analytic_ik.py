"""Closed-form IK benchmark: URIK's single-pose path beside its batch path and roboticstoolbox.

Every method solves the same targets from the same seeds in one run. Targets are the forward
kinematics of random in-limit configurations, seeds other random in-limit configurations (both
from ``numpy.random.default_rng(seed)``).

Methods:
    fast nearest: ``solver.nearest(position, rotation, seed)``, the plain-float single-pose path
        (falls back to the batch path by itself near singularities).
    batch nearest: ``solver._nearest_batch_path(...)``, the vectorised machinery for N = 1 (the
        implementation before the single-pose path).
    fast solutions / batch solutions: all solutions of the pose, the same two ways.
    rtb ik_LM: roboticstoolbox-python's C++ Levenberg–Marquardt at ``tol=5e-9`` (see
        bench_ik.py), if installed; a numerical solver, for scale.

Two timings per method: the median of per-call wall-clock times (methods interleaved target by
target, so machine drift hits all alike), and the mean over a loop of all ``n`` calls timed as
one (``time.perf_counter``, garbage collector off), best of ``--repeat`` loops. The script also
checks that the fast and batch answers agree and reach the targets.

Usage:
    python tests/bench/bench_analytic_ik.py [--robots ur3 ur5 ur10] [--n 1000] [--seed 0]
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from kinplan import Robot, load_robot
from kinplan.ik import URIK, ClosedFormIK, analytic_solver_for

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_ik import RTB_TOL, machine_info, rtb_method  # noqa: E402

WARMUP = 20  # untimed calls per method


def methods_for(robot: Robot, solver: URIK, seed: int) -> dict[str, Callable]:
    """name → call(position, rotation, homogeneous, q_seed)."""
    methods: dict[str, Callable] = {
        "fast nearest": lambda p, r, h, s: solver.nearest(p, r, s),
        "batch nearest": lambda p, r, h, s: solver._nearest_batch_path(p, r, s),
        "fast solutions": lambda p, r, h, s: solver.solutions(p, r),
        "batch solutions": lambda p, r, h, s: ClosedFormIK.solutions(solver, p, r),
    }
    rtb = rtb_method(robot, np.random.default_rng([seed, 2]))
    if rtb.unavailable is None:
        methods[f"rtb ik_LM (C++, tol={RTB_TOL:g})"] = lambda p, r, h, s: rtb.solve(h, s)
    else:
        print(f"rtb ik_LM: {rtb.unavailable}")
    return methods


def check(robot: Robot, solver: URIK, problems: list) -> str:
    """Largest |fast − batch| [rad] and FK error of the fast answers [m, rad]."""
    gap, position_error, rotation_error = 0.0, 0.0, 0.0
    for position, rotation, _, q_seed in problems:
        fast = solver.nearest(position, rotation, q_seed)
        batch = solver._nearest_batch_path(position, rotation, q_seed)
        gap = max(gap, float(np.max(np.abs(fast - batch))))
        reached = robot.fk(fast)
        position_error = max(position_error, float(np.linalg.norm(reached.translation - position)))
        rotation_error = max(
            rotation_error, float(np.linalg.norm(pin.log3(reached.rotation.T @ rotation)))
        )
    return (
        f"max |fast - batch| = {gap:.1e} rad; FK error of the fast answers "
        f"{position_error:.1e} m / {rotation_error:.1e} rad"
    )


def measure(methods: dict[str, Callable], problems: list, repeat: int) -> dict[str, tuple]:
    """name → (median per call [µs], p95 [µs], best loop mean [µs])."""
    for call in methods.values():
        for problem in problems[:WARMUP]:
            call(*problem)
    per_call = {name: [] for name in methods}
    gc.collect()
    gc.disable()
    try:
        for problem in problems:
            for name, call in methods.items():
                start = time.perf_counter()
                call(*problem)
                per_call[name].append(time.perf_counter() - start)
        loops = {name: [] for name in methods}
        for _ in range(repeat):
            for name, call in methods.items():
                start = time.perf_counter()
                for problem in problems:
                    call(*problem)
                loops[name].append((time.perf_counter() - start) / len(problems))
    finally:
        gc.enable()
    return {
        name: (
            1e6 * float(np.median(per_call[name])),
            1e6 * float(np.percentile(per_call[name], 95)),
            1e6 * min(loops[name]),
        )
        for name in methods
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=["ur3", "ur5", "ur10"])
    parser.add_argument("--n", type=int, default=1000, help="targets per robot")
    parser.add_argument("--seed", type=int, default=0, help="seed of the numpy Generator")
    parser.add_argument("--repeat", type=int, default=3, help="timed loops per method")
    args = parser.parse_args(argv)

    print(machine_info())
    print("Times in µs. The machine is noisy: compare the ratios within one run.\n")
    for name in args.robots:
        robot = load_robot(name)
        solver = analytic_solver_for(robot)
        if not isinstance(solver, URIK):
            print(f"{name}: no UR closed form\n")
            continue
        rng = np.random.default_rng(args.seed)
        problems = []
        for _ in range(args.n):
            target = robot.fk(robot.random_configuration(rng))
            position, rotation = target.translation.copy(), target.rotation.copy()
            problems.append(
                (position, rotation, target.homogeneous, robot.random_configuration(rng))
            )
        results = measure(methods_for(robot, solver, args.seed), problems, args.repeat)
        print(f"### {name} ({args.n} targets, random seeds)\n")
        print("| method | median per call | p95 per call | mean over a loop |")
        print("|---|---:|---:|---:|")
        for method, (median, p95, loop) in results.items():
            print(f"| {method} | {median:.1f} | {p95:.1f} | {loop:.1f} |")
        fast, batch = results["fast nearest"], results["batch nearest"]
        print(
            f"\nbatch / fast nearest: {batch[0] / fast[0]:.1f}x (median), "
            f"{batch[2] / fast[2]:.1f}x (loop)"
        )
        solutions = results["fast solutions"], results["batch solutions"]
        print(f"batch / fast solutions: {solutions[1][0] / solutions[0][0]:.1f}x (median)")
        rtb = [key for key in results if key.startswith("rtb")]
        if rtb:
            print(f"rtb ik_LM / fast nearest: {results[rtb[0]][0] / fast[0]:.2f}x (median)")
        print(check(robot, solver, problems))
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
