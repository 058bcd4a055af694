"""Start-up time of the console command: ``kinplan info ur5`` and ``import kinplan``.

Each command runs in a fresh interpreter (``subprocess``), ``--repeat`` times after one warm-up
run (which fills the OS file cache); the table gives the median and the fastest wall time.
Issue 18 asks for ``kinplan info ur5`` ≤ 0.5 s median: it imports only what the command needs
(Pinocchio, which loads coal, is most of it; numba, matplotlib, the viewer, the closed-form IK
and the work cell are not loaded), and reads the arm's reach from disk after its first search
(a row without that cache shows the search's cost).

Usage: ``python tests/bench/bench_startup.py [--repeat 9]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

#: The reach ``kinplan info`` prints is kept on disk after its first search
#: (:func:`kinplan.model.extent.stored_reach`): this row gives every run an empty cache.
COLD = "kinplan info ur5, reach not yet on disk"

COMMANDS = {
    "kinplan info ur5": [sys.executable, "-m", "kinplan.apps.cli", "info", "ur5"],
    COLD: [sys.executable, "-m", "kinplan.apps.cli", "info", "ur5"],
    "python -c 'import kinplan'": [sys.executable, "-c", "import kinplan"],
    "python -c 'import pinocchio' (its floor)": [sys.executable, "-c", "import pinocchio"],
}


def wall_times(command: list[str], repeat: int, cold: bool = False) -> list[float]:
    """Wall times [s] of ``repeat`` runs of ``command`` after one warm-up run (``cold``: each
    with an empty kinplan cache folder of its own)."""
    subprocess.run(command, check=True, capture_output=True)
    times = []
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as folder:
            env = {**os.environ, "KINPLAN_CACHE_DIR": folder} if cold else None
            start = time.perf_counter()
            subprocess.run(command, check=True, capture_output=True, env=env)
            times.append(time.perf_counter() - start)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()
    rows = ["| command | median [s] | fastest [s] |", "|---|---:|---:|"]
    for name, command in COMMANDS.items():
        times = wall_times(command, args.repeat, cold=name == COLD)
        rows.append(f"| `{name}` | {statistics.median(times):.3f} | {min(times):.3f} |")
    print(f"Fresh interpreter per run, median of {args.repeat} after a warm-up run.\n")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
