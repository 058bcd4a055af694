"""Start-up time of the console command: ``kinplan info ur5`` and ``import kinplan``.

Each command runs in a fresh interpreter (``subprocess``), ``--repeat`` times after one warm-up
run (which fills the OS file cache); the table gives the median and the fastest wall time.
Issue 18 asks for ``kinplan info ur5`` ≤ 0.5 s median: it imports only what the command needs
(Pinocchio, which loads coal, is most of it; numba, matplotlib and the viewer are not loaded).

Usage: ``python tests/bench/bench_startup.py [--repeat 9]``.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

COMMANDS = {
    "kinplan info ur5": [sys.executable, "-m", "kinplan.apps.cli", "info", "ur5"],
    "python -c 'import kinplan'": [sys.executable, "-c", "import kinplan"],
    "python -c 'import pinocchio' (its floor)": [sys.executable, "-c", "import pinocchio"],
}


def wall_times(command: list[str], repeat: int) -> list[float]:
    """Wall times [s] of ``repeat`` runs of ``command`` after one warm-up run."""
    subprocess.run(command, check=True, capture_output=True)
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()
    rows = ["| command | median [s] | fastest [s] |", "|---|---:|---:|"]
    for name, command in COMMANDS.items():
        times = wall_times(command, args.repeat)
        rows.append(f"| `{name}` | {statistics.median(times):.3f} | {min(times):.3f} |")
    print(f"Fresh interpreter per run, median of {args.repeat} after a warm-up run.\n")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
