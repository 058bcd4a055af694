"""Time-optimal Cartesian timing: kinplan's retimed plan beside toppra, in one run.

For UR5 and panda lines and arcs (about 1,000 samples at dt = 1 ms), the same joint
limits (the robot's speed limits, 5 rad/s² for every joint), no tool-speed cap:

* **kinplan**: the whole `cartesian.follow(..., retime=True)` call — the geometric IK pass, the
  time-optimal law and the IK of every output sample with its monitoring; on the panda the two
  IK passes run the lean loop (:mod:`cartesian.lean_track`), on UR5 the output samples are
  solved whole (:mod:`cartesian.batch_track`);
* **kinplan, full loop**: the same call with those fast paths switched off (their A/B);
* **toppra**: its parametrisation alone (`TOPPRA(...).compute_parameterization(0, 0)` on a
  spline through 1,000 joint samples of the same path, computed by kinplan's IK to 1e-12 m
  beforehand and not timed), plus its duration from `compute_trajectory`.

Times are medians of interleaved repeats (A, B, A, B, ...), so a slow spell of the machine
falls on both. Usage: ``python tests/bench/bench_retime.py [--repeat 7]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import pinocchio as pin

import cartesian
import kinplan
from cartesian import batch_track, lean_track
from cartesian.geometry import trace_geometry
from cartesian.tracker import Tracker

ACCELERATION = 5.0  # rad/s², every joint
STARTS = {
    "ur5": np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0]),
    "panda": np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8]),
}


def paths(robot: kinplan.Robot, q0: np.ndarray) -> dict[str, cartesian.Path]:
    """A 0.3 m line and a half-circle arc of radius 0.1 m from the tool pose at q0."""
    start = robot.fk(q0)
    rotation, p = start.rotation, start.translation
    return {
        "line 0.3 m": cartesian.Line(start, pin.SE3(rotation, p + [0.0, 0.3, 0.0])),
        "arc r 0.1 m": cartesian.Arc(
            start, pin.SE3(rotation, p + [0.1, 0.1, 0.0]), pin.SE3(rotation, p + [0.0, 0.2, 0.0])
        ),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    import toppra
    from toppra import algorithm, constraint

    toppra.setup_logging("WARNING")
    print("| robot | path | kinplan duration [s] | toppra duration [s] | ratio | "
          "kinplan whole plan [ms] | toppra parametrisation [ms] | speed ratio | "
          "kinplan, full loop [ms] | fast paths' gain |")  # fmt: skip
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, q0 in STARTS.items():
        robot = kinplan.load_robot(name)
        v = robot.velocity_limit
        a = np.full(robot.nq, ACCELERATION)
        for label, path in paths(robot, q0).items():
            tracker = Tracker(robot, False, 1e-12, 1e-12, 0.0, 1.0, 0.05)
            geometry = trace_geometry(tracker, path, np.linspace(0.0, 1.0, 1000), q0)
            limits = [
                constraint.JointVelocityConstraint(np.stack([-v, v], 1)),
                constraint.JointAccelerationConstraint(np.stack([-a, a], 1)),
            ]

            def reference(geometry=geometry, limits=limits):
                return algorithm.TOPPRA(
                    limits, toppra.SplineInterpolator(geometry.s, geometry.q),
                    gridpoints=geometry.s, parametrizer="ParametrizeConstAccel",
                )  # fmt: skip

            def ours(robot=robot, path=path, q0=q0):
                return cartesian.follow(
                    robot, path, speed=100.0, acceleration=1e6, dt=0.001, q_seed=q0,
                    retime=True, max_acceleration=ACCELERATION,
                )  # fmt: skip

            def full_loop(ours=ours):
                batch_track.ENABLED = lean_track.ENABLED = False
                try:
                    return ours()
                finally:
                    batch_track.ENABLED = lean_track.ENABLED = True

            ours(), full_loop(), reference().compute_parameterization(0, 0)  # warm-up
            mine, theirs, looped = [], [], []
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                plan = ours()
                mine.append(time.perf_counter() - t0)
                instance = reference()
                t0 = time.perf_counter()
                instance.compute_parameterization(0, 0)
                theirs.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                full_loop()
                looped.append(time.perf_counter() - t0)
            duration = reference().compute_trajectory(0, 0).duration
            ours_ms, theirs_ms = 1e3 * np.median(mine), 1e3 * np.median(theirs)
            loop_ms = 1e3 * np.median(looped)
            status = "" if plan.ok else f" ({plan.status})"
            print(
                f"| {name} | {label} | {plan.duration:.4f}{status} | {duration:.4f} | "
                f"{plan.duration / duration:.4f} | {ours_ms:.1f} | {theirs_ms:.1f} | "
                f"{theirs_ms / ours_ms:.2f}× | {loop_ms:.1f} | {loop_ms / ours_ms:.2f}× |"
            )


if __name__ == "__main__":
    main()
