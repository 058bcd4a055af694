"""Batch IK (``Robot.ik_batch``) against issue 18's targets and a Python loop over ``Robot.ik``.

Measured in one process on this machine (2 cores; other work on it shows as noise, and the speed
drifts up to 2× between runs: compare the ratios of one run, not absolute figures across runs).

Per row: targets are FK of random in-limit configurations (``default_rng(seed)``), given as an
(N, 4, 4) array unless the row says "list of SE3"; seeds are one random in-limit configuration
per target, or the default seed (``Robot.neutral``). In each of ``--rounds`` rounds the batch
solves all N targets and the loop solves the first ``n_loop`` of them target by target, the
order alternating from round to round (3 rounds at most for the numerical arms, whose loop
runs over 1,000 targets); the table gives the medians.

Columns:
    poses/s: ``ik_batch`` over the N targets (median of the rounds), its default threads (one
        per core for 8,192 targets or more: :mod:`kinplan.ik.batch_threads`).
    1 thread /s: the same with ``threads=1``.
    target: issue 18's bar: UR5 ≥ 500k poses/s, panda ≥ 100k poses/s, numerical arms ≥ 10× a
        Python loop over ``ik`` (planar 2R: no bar, shown for reference).
    of target: poses/s over the bar (or batch over the Python-LM loop over 10× for numerical
        arms); ≥ 1 is met.
    loop over ik: ``Robot.ik`` target by target on the first n_loop targets, same seeds.
    batch/loop: the two rates' ratio.
    Python-LM loop: for numerical arms, the same loop with ``ik``'s compiled solve switched off
        (``IKSolver._kernel = False``): the Python Levenberg–Marquardt that ``ik`` ran when
        issue 18 set its bar (the same steps and answers; ``tests/ik/test_numeric_kernel.py``),
        and the batch's rate over it. ``ik`` itself now runs the whole solve compiled, so the
        batch can only add the second core and save ``ik``'s per-call Python over it.
    success: the batch's, over all N targets (the loop's on its targets in brackets).
    max error: of the batch's successes, tool position [m] / rotation [rad], by the vectorised
        FK (itself checked against Pinocchio to 1e-12 by the tests).
    same as ik: of the loop's targets, those where batch and loop agree on success and, where
        both succeed, on q (to 1e-9 rad for closed forms, 1e-6 for numerical arms).

Usage:
    python tests/bench/bench_ik_batch.py [--quick] [--seed 0] [--rounds 5]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

import kinplan

URDF = Path(__file__).resolve().parents[1] / "urdf"


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def case_row(
    label: str,
    source: str | Path,
    n_batch: int,
    n_loop: int,
    bar: tuple[str, float] | None,
    *,
    seeded: bool,
    se3_list: bool = False,
    seed: int,
    rounds: int,
) -> list[str]:
    robot = kinplan.load_robot(source)
    rng = np.random.default_rng([seed, n_batch, int(seeded), int(se3_list)])
    q_true = np.array([robot.random_configuration(rng) for _ in range(n_batch)])
    kinematics = robot.batch_solver.kinematics
    assert kinematics is not None
    positions, rotations = kinematics.fk(q_true)
    array = np.zeros((n_batch, 4, 4))
    array[:, :3, :3], array[:, :3, 3], array[:, 3, 3] = rotations, positions, 1.0
    targets: np.ndarray | list[pin.SE3] = [pin.SE3(t) for t in array] if se3_list else array
    one_by_one = [pin.SE3(t) for t in array[:n_loop]]
    seeds = np.array([robot.random_configuration(rng) for _ in range(n_batch)]) if seeded else None
    robot.ik_batch(array[:10], q_seed=None if seeds is None else seeds[:10])  # builds the solver
    robot.ik(one_by_one[0])
    batch_rates, single_rates, loop_rates, python_rates = [], [], [], []
    closed = robot.batch_solver.method(False).startswith("closed-form")
    solver = robot.ik_solver
    q = success = None
    results = []
    for r in range(rounds):
        for what in ("batch", "single", "loop") if r % 2 == 0 else ("loop", "single", "batch"):
            started = time.perf_counter()
            if what == "batch":
                q, success = robot.ik_batch(targets, q_seed=seeds)
                batch_rates.append(n_batch / (time.perf_counter() - started))
            elif what == "single":
                robot.ik_batch(targets, q_seed=seeds, threads=1)
                single_rates.append(n_batch / (time.perf_counter() - started))
            else:
                results = [
                    robot.ik(t, q_seed=None if seeds is None else seeds[k])
                    for k, t in enumerate(one_by_one)
                ]
                loop_rates.append(n_loop / (time.perf_counter() - started))
                if not closed:  # the Python Levenberg–Marquardt (issue 18's reference)
                    kernel, solver._kernel = solver._kernel, False
                    started = time.perf_counter()
                    for k, t in enumerate(one_by_one):
                        robot.ik(t, q_seed=None if seeds is None else seeds[k])
                    python_rates.append(n_loop / (time.perf_counter() - started))
                    solver._kernel = kernel
    assert q is not None and success is not None
    batch_rate, loop_rate = float(np.median(batch_rates)), float(np.median(loop_rates))
    position2, frobenius2 = kinematics.errors(q[success], positions[success], rotations[success])
    rotation_error = 2.0 * np.arcsin(np.minimum(np.sqrt(frobenius2.max(initial=0.0)) / 8**0.5, 1))
    tolerance = 1e-9 if closed else 1e-6
    agree = sum(
        res.success == ok and (not ok or np.abs(res.q - row).max() < tolerance)
        for res, ok, row in zip(results, success[:n_loop], q[:n_loop])
    )
    loop_success = np.mean([res.success for res in results])
    if bar is None:
        target, of_target = "–", "–"
    elif bar[0] == "loop":
        python_rate = float(np.median(python_rates))
        of_target = f"{batch_rate / python_rate / bar[1]:.2f}"
        target = f"{bar[1]:.0f}× Python-LM loop"
    else:
        target, of_target = f"{bar[1]:,.0f}/s", f"{batch_rate / bar[1]:.2f}"
    return [
        label,
        f"{n_batch:,}",
        f"{batch_rate:,.0f}",
        f"{float(np.median(single_rates)):,.0f}",
        target,
        of_target,
        f"{loop_rate:,.0f}",
        f"{batch_rate / loop_rate:.1f}×",
        f"{np.median(python_rates):,.0f} ({batch_rate / np.median(python_rates):.0f}×)"
        if python_rates
        else "–",
        f"{success.mean():.1%} ({loop_success:.1%})",
        f"{math.sqrt(position2.max(initial=0.0)):.0e} / {rotation_error:.0e}",
        f"{agree}/{n_loop}",
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller problems (a smoke run)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    big, mid, small = (20_000, 5_000, 1_000) if args.quick else (100_000, 20_000, 10_000)
    numerical_loop = 100 if args.quick else 1_000  # failures are rare and costly: a big sample
    numerical_rounds = min(args.rounds, 3)
    cases: list[tuple[str, str | Path, int, int, tuple[str, float] | None, dict[str, Any]]] = [
        ("ur5, seed per target", "ur5", big, 300, ("poses", 500_000), {"seeded": True}),
        ("ur5, seed per target", "ur5", mid, 300, ("poses", 500_000), {"seeded": True}),
        ("ur5, default seed", "ur5", big, 300, ("poses", 500_000), {"seeded": False}),
        (
            "ur5, list of SE3",
            "ur5",
            big,
            300,
            ("poses", 500_000),
            {"seeded": True, "se3_list": True},
        ),
        ("panda, seed per target", "panda", mid, 200, ("poses", 100_000), {"seeded": True}),
        ("panda, default seed", "panda", mid, 200, ("poses", 100_000), {"seeded": False}),
        ("planar 2R, default seed", "planar_2r", big, 300, None, {"seeded": False}),
        (
            "skewed_axes (numerical), default seed",
            URDF / "skewed_axes.urdf",
            small,
            numerical_loop,
            ("loop", 10.0),
            {"seeded": False, "rounds": numerical_rounds},
        ),
        (
            "prismatic_gantry (numerical), default seed",
            URDF / "prismatic_gantry.urdf",
            small,
            numerical_loop,
            ("loop", 10.0),
            {"seeded": False, "rounds": numerical_rounds},
        ),
    ]
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    print(f"load average before the run (1, 5, 15 min): {load}\n")
    header = [
        "arm, targets",
        "N",
        "poses/s",
        "1 thread /s",
        "target",
        "of target",
        "loop over ik /s",
        "batch/loop",
        "Python-LM loop /s (batch/it)",
        "success (loop)",
        "max error m / rad",
        "same as ik",
    ]
    rows = []
    for label, source, n, n_loop, bar, options in cases:
        options = {"rounds": args.rounds, **options}
        rows.append(case_row(label, source, n, n_loop, bar, seed=args.seed, **options))
    print(table(header, rows))
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"\nLoad average after the run (1, 5, 15 min): {load} on {os.cpu_count()} cores.")


if __name__ == "__main__":
    main()
