"""Sampling speed of Trajectory.sample (not a test): joint samples per second.

A 6-joint trajectory of many segments (cubic spline through 50 via points, the LSPB
minimum-time profile, a quintic, a 4-3-4 profile) is sampled at 1e6 time points; a "joint
sample" is one joint's position, velocity and acceleration at one time. Target: ≥ 1e7 joint
samples per second.

Run: ``python tests/bench/bench_trajectory.py [--points 1000000] [--repeats 5]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from kinplan import trajectory

TARGET = 1e7  # joint samples per second


def profiles(n: int = 6) -> dict[str, trajectory.Trajectory]:
    """Representative 6-joint trajectories, each of several segments."""
    rng = np.random.default_rng(0)
    points = rng.uniform(-2.0, 2.0, (50, n))
    times = np.cumsum(rng.uniform(0.2, 1.0, 50))
    q0, qf = rng.uniform(-2.0, 2.0, n), rng.uniform(-2.0, 2.0, n)
    return {
        "cubic_via, 49 segments": trajectory.cubic_via(points, times),
        "trapezoid_via, blends": trajectory.trapezoid_via(points[:10], np.full(9, 1.0), 40.0),
        "trapezoid, min time": trajectory.trapezoid(
            q0, qf, max_velocity=rng.uniform(0.5, 2.0, n), max_acceleration=rng.uniform(1, 5, n)
        ),
        "four_three_four": trajectory.four_three_four(q0, q0 + 0.1, qf - 0.1, qf, [0.5, 2, 0.5]),
        "quintic, 1 segment": trajectory.quintic(q0, qf, 2.0),
    }


def best_time(function, repeats: int) -> float:
    """Shortest wall time of ``repeats`` calls [s]."""
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main(points: int = 1_000_000, repeats: int = 5) -> dict[str, float]:
    """Print a table and return joint samples per second for each trajectory."""
    print(f"{'trajectory':<26}{'segments':>9}{'time [ms]':>11}{'joint samples/s':>18}  target")
    rates = {}
    for name, traj in profiles().items():
        t = np.linspace(-0.01, traj.duration + 0.01, points)
        elapsed = best_time(lambda traj=traj, t=t: traj.sample(t), repeats)
        rates[name] = points * traj.n / elapsed
        verdict = "ok" if rates[name] >= TARGET else "SLOW"
        print(
            f"{name:<26}{len(traj.segments):>9}{1e3 * elapsed:>11.1f}"
            f"{rates[name]:>18.3e}  {verdict}"
        )
    return rates


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000, help="time points per call")
    parser.add_argument("--repeats", type=int, default=5, help="calls per trajectory (best)")
    arguments = parser.parse_args()
    main(arguments.points, arguments.repeats)
