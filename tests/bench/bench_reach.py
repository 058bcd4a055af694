"""Batch IK and capability maps: throughput, the 5 cm UR5 map, scaling over Dask workers.

Measured in one run on this machine (2 cores; other work on it shows as noise: compare the
ratios of one run, not absolute figures across runs).

Tables:
    1. ``Robot.ik_batch`` beside a Python loop over ``Robot.ik`` on the same targets (FK of random
       in-limit configurations, default seeds): targets per second and the ratio; the share of
       targets where both succeed with the same q (closed forms: to 1e-9 rad).
    2. The UR5 capability map at 5 cm with 32 orientations (the issue's target: < 60 s),
       in-process and on a LocalCluster of 2 workers (started for the run, start-up included),
       with the memory one work item needs.
    3. A numerical arm (tests/urdf/skewed_axes.urdf, no closed form) mapped on LocalClusters of
       1 and 2 workers (clusters started before the clock): the speed-up of the second worker.
    4. What a 1 cm UR5 map would take on 100 workers, extrapolated from table 2's rate.

Usage:
    python tests/bench/bench_reach.py [--quick] [--seed 0]
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import platform
import time
import tracemalloc
from pathlib import Path

import numpy as np

import kinplan
from kinplan.scale.reach import capability_map

URDF = Path(__file__).resolve().parents[1] / "urdf"


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def ik_batch_rows(seed: int, quick: bool) -> list[list[str]]:
    cases = [
        ("ur5", "ur5", 20_000 if quick else 100_000, 200),
        ("planar_2r", "planar_2r", 20_000 if quick else 100_000, 200),
        ("panda", "panda", 500 if quick else 2_000, 100),
        ("skewed_axes (numerical)", URDF / "skewed_axes.urdf", 500 if quick else 2_000, 100),
    ]
    rows = []
    for label, source, n_batch, n_loop in cases:
        robot = kinplan.load_robot(source)
        rng = np.random.default_rng([seed, len(rows)])
        q_true = np.array([robot.random_configuration(rng) for _ in range(n_batch)])
        kinematics = robot.batch_solver.kinematics
        positions, rotations = kinematics.fk(q_true)
        if robot.default_position_only():
            targets = positions
        else:
            targets = np.zeros((n_batch, 4, 4))
            targets[:, :3, :3], targets[:, :3, 3], targets[:, 3, 3] = rotations, positions, 1.0
        robot.ik_batch(targets[:10])  # warm-up (solver construction)
        started = time.perf_counter()
        q, success = robot.ik_batch(targets)
        batch_rate = n_batch / (time.perf_counter() - started)
        loop_targets = [
            t if t.ndim == 1 else kinplan.model.robot.pin.SE3(t) for t in targets[:n_loop]
        ]
        started = time.perf_counter()
        results = [robot.ik(t) for t in loop_targets]
        loop_rate = n_loop / (time.perf_counter() - started)
        agree = sum(  # the same q: to 1e-9 rad for closed forms, 1e-6 for iterations
            r.success == ok and (not ok or np.abs(r.q - row).max() < 1e-6)
            for r, ok, row in zip(results, success[:n_loop], q[:n_loop])
        )
        rows.append(
            [
                label,
                robot.batch_solver.method(robot.default_position_only()),
                f"{n_batch:,}",
                f"{batch_rate:,.0f}",
                f"{loop_rate:,.0f}",
                f"{batch_rate / loop_rate:.0f}×",
                f"{success.mean():.1%}",
                f"{agree}/{n_loop}",
            ]
        )
    return rows


def chunk_memory(robot, resolution: float, orientations: int) -> float:
    """Peak Python-allocated memory [MB] of one work item of a map (numpy arrays included)."""
    from kinplan.scale.engines import robot_payload
    from kinplan.scale.reach import CHUNK_TARGETS, _map_chunk, orientation_set

    rotations = orientation_set(orientations)
    per_chunk = CHUNK_TARGETS[robot.batch_solver.method(False)] // orientations
    centers = robot.fk(robot.neutral()).translation + resolution * np.random.default_rng(0).normal(
        size=(per_chunk, 3)
    )
    payload = {
        "robot": robot_payload(robot),
        "rotations": rotations,
        "max_restarts": 4,
        "cell": None,
    }
    _map_chunk(centers[:2], payload)  # the robot is built and cached outside the measure
    tracemalloc.start()
    _map_chunk(centers, payload)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / 1e6


def map_rows(quick: bool) -> tuple[list[list[str]], float]:
    robot = kinplan.load_robot("ur5")
    resolution, orientations = (0.1, 32) if quick else (0.05, 32)
    rows = []
    rate = math.nan
    for label, options in (("in-process", {}), ("LocalCluster, 2 workers", {"jobs": 2})):
        started = time.perf_counter()
        reach_map = capability_map(robot, resolution, orientations, **options)
        seconds = time.perf_counter() - started
        poses = reach_map.info["poses"]
        if not options:
            rate = poses / seconds
        rows.append(
            [
                label,
                f"{resolution:g} m × {orientations}",
                f"{reach_map.info['solved_voxels']:,}",
                f"{poses:,}",
                f"{reach_map.info['chunks']}",
                f"{seconds:.1f} s",
                f"{poses / seconds:,.0f}",
                f"{int(reach_map.reachable.sum()):,}",
            ]
        )
    return rows, rate


def scaling_rows(quick: bool) -> list[list[str]]:
    from distributed import Client, LocalCluster

    from kinplan.scale.engines import robot_from_payload, robot_payload

    robot = kinplan.load_robot(URDF / "skewed_axes.urdf")
    resolution = 0.2 if quick else 0.12
    rows = []
    base = math.nan
    for workers in (1, 2):
        with (
            LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            ) as cluster,
            Client(cluster) as client,
        ):
            # every worker imports kinplan and builds the arm before the clock starts
            payload = robot_payload(robot)
            client.run(lambda p: robot_from_payload(p).batch_solver and None, payload)
            started = time.perf_counter()
            reach_map = capability_map(robot, resolution, 8, engine=client, chunk_targets=1024)
            seconds = time.perf_counter() - started
        base = seconds if workers == 1 else base
        rows.append(
            [
                f"{workers}",
                f"{resolution:g} m × 8",
                f"{reach_map.info['poses']:,}",
                f"{reach_map.info['chunks']}",
                f"{seconds:.1f} s",
                f"{reach_map.info['poses'] / seconds:,.0f}",
                f"{base / seconds:.2f}×",
            ]
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller problems (a smoke run)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores\n")
    print("**Robot.ik_batch** vs a Python loop over Robot.ik (same targets, default seeds)\n")
    header = [
        "arm",
        "solver",
        "targets",
        "ik_batch /s",
        "ik loop /s",
        "ratio",
        "success",
        "same as ik",
    ]
    print(table(header, ik_batch_rows(args.seed, args.quick)))
    print("\n**UR5 capability map** (voxels beyond the reach are not solved)\n")
    rows, rate = map_rows(args.quick)
    header = [
        "engine",
        "grid",
        "voxels solved",
        "IK targets",
        "chunks",
        "time",
        "targets/s",
        "reachable",
    ]
    print(table(header, rows))
    memory = chunk_memory(kinplan.load_robot("ur5"), 0.05, 32)
    print(f"\nOne work item (16,384 targets, closed form) peaks at {memory:.0f} MB of arrays.")
    print("\n**Numerical arm** (skewed_axes.urdf, no closed form) over Dask workers\n")
    header = ["workers", "grid", "IK targets", "chunks", "time", "targets/s", "speed-up"]
    print(table(header, scaling_rows(args.quick)))
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"\nLoad average after the run (1, 5, 15 min): {load} on {os.cpu_count()} cores.")
    voxels = 4.0 / 3.0 * math.pi * (kinplan.load_robot("ur5").reach() / 0.01) ** 3
    targets = voxels * 32
    print(
        f"\n**Extrapolated**: a 1 cm UR5 map with 32 orientations solves ~{voxels / 1e6:.1f} M "
        f"voxels × 32 = {targets / 1e6:.0f} M targets: {targets / rate / 3600:.1f} core-hours "
        f"at this run's in-process rate, ~{targets / rate / 100:.0f} s of work on each of 100 "
        f"workers (+ start-up; {math.ceil(targets / 16384):,} work items of 16,384 targets)."
    )


if __name__ == "__main__":
    main()
