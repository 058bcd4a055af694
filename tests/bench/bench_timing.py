"""Jerk-limited and time-optimal joint timing beside ruckig and TOPP-RA (not a test).

Two tables, on UR5-like 6-joint inputs drawn from ``numpy.random.default_rng(seed)``:

- **scurve vs ruckig**: random rest-to-rest moves (start and goal uniform in ±π, limits the
  UR5's velocity limits times U(0.3, 1), accelerations 8-16 rad/s² times U(0.3, 1), jerks
  100-200 rad/s³ times U(0.3, 1)); the largest |duration difference| against ruckig's
  (community version, time-synchronised) and the median time per call: the whole
  ``trajectory.scurve`` (validation, profile, Trajectory object) against ruckig's
  ``Ruckig.calculate`` alone (inputs built before the clock starts).
- **time_optimal vs TOPP-RA**: random waypoint sets (``--points`` points uniform in ±1.5 rad)
  for each blend size ``max_deviation``; the duration ratio kinplan / TOPP-RA on the same
  geometric path (tests/timing_references.py: lines and circular blends evaluated exactly,
  grid spacing 0.01 rad and 0.002 rad along the path and at least 60 intervals on each blend,
  solved from rest to rest between kept corners) and the median time per call: the whole
  ``trajectory.time_optimal`` (path, timing, dense limit check, Trajectory object) against
  TOPP-RA's ``compute_parameterization`` alone. TOPP-RA's duration approaches the optimum from
  above as its grid is refined (its lines are timed one constant path acceleration per grid
  interval; kinplan's exactly), so the ratio rises towards 1 with the finer grid.

Run: ``python tests/bench/bench_timing.py [--cases 200] [--paths 20] [--points 6] [--seed 0]``.
The peers come with the ``bench`` extra; a missing one is reported as "not installed".
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/: the peer references

from timing_references import ruckig_duration, toppra_duration  # noqa: E402

from kinplan import trajectory  # noqa: E402
from kinplan.trajectory import totg  # noqa: E402

UR5_VELOCITY = np.array([3.15, 3.15, 3.15, 3.2, 3.2, 3.2])  # rad/s, the URDF's limits
UR5_ACCELERATION = np.array([8.0, 8.0, 8.0, 16.0, 16.0, 16.0])  # rad/s², a typical choice
UR5_JERK = np.array([100.0, 100.0, 100.0, 200.0, 200.0, 200.0])  # rad/s³
DEVIATIONS = (0.0, 0.05, 0.2)  # rad
SPACINGS = (0.01, 0.002)  # TOPP-RA grid spacings [rad of path length]: coarse, fine


def timed(function) -> tuple[object, float]:
    """``function()`` and its wall time [s]."""
    start = time.perf_counter()
    result = function()
    return result, time.perf_counter() - start


def scaled(rng: np.random.Generator, limits: np.ndarray) -> np.ndarray:
    return limits * rng.uniform(0.3, 1.0, limits.size)


def scurve_table(cases: int, seed: int) -> None:
    """scurve against ruckig: duration difference and time per call."""
    rng = np.random.default_rng(seed)
    moves = [
        (
            rng.uniform(-np.pi, np.pi, 6),
            rng.uniform(-np.pi, np.pi, 6),
            scaled(rng, UR5_VELOCITY),
            scaled(rng, UR5_ACCELERATION),
            scaled(rng, UR5_JERK),
        )
        for _ in range(cases)
    ]
    ours, durations = [], []
    for q0, qf, v, a, j in moves:
        traj, elapsed = timed(
            lambda q0=q0, qf=qf, v=v, a=a, j=j: trajectory.scurve(q0, qf, v, a, j)
        )
        ours.append(elapsed)
        durations.append(traj.duration)
    print(f"scurve vs ruckig: {cases} random UR5-like 6-joint rest-to-rest moves (seed {seed})")
    print(f"{'method':<28}{'max |ΔT| [s]':>14}{'median [µs/call]':>18}")
    print(f"{'kinplan trajectory.scurve':<28}{'-':>14}{1e6 * np.median(ours):>18.1f}")
    try:
        import ruckig
    except ModuleNotFoundError:
        print(f"{'ruckig':<28}{'not installed':>14}")
        return
    theirs, differences = [], []
    otg = ruckig.Ruckig(6)
    for (q0, qf, v, a, j), duration in zip(moves, durations, strict=True):
        inp = ruckig.InputParameter(6)
        inp.current_position, inp.target_position = list(q0), list(qf)
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = list(v), list(a), list(j)
        result = ruckig.Trajectory(6)
        _, elapsed = timed(lambda inp=inp, result=result: otg.calculate(inp, result))
        theirs.append(elapsed)
        differences.append(duration - result.duration)
    worst = float(np.max(np.abs(differences)))
    print(f"{'ruckig Ruckig.calculate':<28}{worst:>14.2e}{1e6 * np.median(theirs):>18.1f}")
    single = max(
        abs(trajectory.scurve(q0[0], qf[0], v[0], a[0], j[0]).duration
            - ruckig_duration(q0[:1], qf[:1], v[:1], a[:1], j[:1]))
        for q0, qf, v, a, j in moves
    )  # fmt: skip
    print(f"(joint 0 alone, same moves: max |ΔT| {single:.2e} s)")


def time_optimal_table(paths: int, points: int, seed: int) -> None:
    """time_optimal against TOPP-RA: duration ratio and time per call."""
    rng = np.random.default_rng(seed)
    print()
    print(
        f"time_optimal vs TOPP-RA: {paths} random UR5-like waypoint sets of {points} points "
        f"per blend size (seed {seed}); TOPP-RA grid spacing {', '.join(map(str, SPACINGS))} rad"
    )
    try:
        import toppra  # noqa: F401
    except ModuleNotFoundError:
        toppra_installed = False
    else:
        toppra_installed = True
    print(
        f"{'max_deviation [rad]':<21}{'segments':>9}{'kinplan [ms]':>14}"
        + "".join(f"{f'ratio @{h}':>20}{f'toppra @{h} [ms]':>19}" for h in SPACINGS)
    )
    for deviation in DEVIATIONS:
        ours, segments = [], []
        ratios: dict[float, list[float]] = {h: [] for h in SPACINGS}
        theirs: dict[float, list[float]] = {h: [] for h in SPACINGS}
        for _ in range(paths):
            waypoints = rng.uniform(-1.5, 1.5, (points, 6))
            v, a = scaled(rng, UR5_VELOCITY), scaled(rng, UR5_ACCELERATION)
            traj, elapsed = timed(
                lambda w=waypoints, v=v, a=a, d=deviation: trajectory.time_optimal(w, v, a, d)
            )
            ours.append(elapsed)
            segments.append(len(traj.segments))
            if toppra_installed:
                path = totg.JointPath(waypoints, deviation)
                for h in SPACINGS:
                    reference, spent = toppra_duration(path, v, a, h)
                    ratios[h].append(traj.duration / reference)
                    theirs[h].append(spent)
        row = f"{deviation:<21g}{int(np.median(segments)):>9}{1e3 * np.median(ours):>14.1f}"
        for h in SPACINGS:
            if toppra_installed:
                spread = f"{min(ratios[h]):.4f}-{max(ratios[h]):.4f}"
                row += f"{spread:>20}{1e3 * np.median(theirs[h]):>19.1f}"
            else:
                row += f"{'-':>20}{'not installed':>19}"
        print(row)
    print("ratio = kinplan duration / TOPP-RA duration (min-max); times are medians per call")


def main(cases: int = 200, paths: int = 20, points: int = 6, seed: int = 0) -> None:
    trajectory.scurve(0.0, 1.0, 1.0, 1.0, 1.0)  # warm-up (imports, caches)
    trajectory.time_optimal([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], 1.0, 1.0, 0.1)
    scurve_table(cases, seed)
    time_optimal_table(paths, points, seed)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=200, help="scurve moves")
    parser.add_argument("--paths", type=int, default=20, help="waypoint sets per blend size")
    parser.add_argument("--points", type=int, default=6, help="waypoints per set")
    parser.add_argument("--seed", type=int, default=0)
    arguments = parser.parse_args()
    main(arguments.cases, arguments.paths, arguments.points, arguments.seed)
