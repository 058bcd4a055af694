"""Run every benchmark and write their tables into tests/bench/README.md.

Usage: ``python tests/bench/run_all.py`` (what ``make bench`` runs). Each script's output is
printed as it comes and stored in the README between the markers
``<!-- results:start -->`` and ``<!-- results:end -->``, with the date and the command, so the
README always holds the tables of the last full run.
"""

from __future__ import annotations

import datetime
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
README = HERE / "README.md"
START, END = "<!-- results:start -->", "<!-- results:end -->"
SCRIPTS = [
    ("Inverse kinematics", ["bench_ik.py"]),
    ("Inverse kinematics from a mid-range seed", ["bench_ik.py", "--mid-seed"]),
    ("Closed-form IK (UR family)", ["bench_analytic_ik.py", "--robots", "ur5"]),
    ("Cartesian following", ["bench_cartesian.py"]),
    ("Time-optimal Cartesian timing against toppra", ["bench_retime.py"]),
    ("Trajectory sampling", ["bench_trajectory.py"]),
    ("Joint timing: S-curve and time-optimal", ["bench_timing.py"]),
    ("Batch IK and capability maps", ["bench_reach.py"]),
    ("Batch IK against issue 18's targets", ["bench_ik_batch.py"]),
    ("Start-up of the console command", ["bench_startup.py"]),
    ("Industrial arms beside rtb", ["bench_industrial_ik.py", "--synthetic"]),
    ("Completeness of the 1-D search", ["bench_1d_search_completeness.py"]),
    ("Closed forms beside IK-Geo", ["bench_ikgeo.py"]),
    ("Seam planning with a free roll", ["bench_seam.py"]),
    ("Collision-free transit moves beside OMPL", ["bench_free_motion.py"]),
]


def run(script: list[str]) -> str:
    """Run one benchmark script, echo its output, and return it."""
    command = [sys.executable, str(HERE / script[0]), *script[1:]]
    print(f"$ python tests/bench/{' '.join(script)}", flush=True)
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    sys.stdout.write(done.stdout)
    sys.stderr.write(done.stderr)
    if done.returncode != 0:
        raise SystemExit(f"{script[0]} failed with exit status {done.returncode}")
    return done.stdout


def main() -> None:
    today = datetime.date.today().isoformat()
    sections = [f"Last full run: {today}, `python tests/bench/run_all.py` (`make bench`).\n"]
    for title, script in SCRIPTS:
        output = run(script)
        sections.append(f"### {title}\n\n`python tests/bench/{' '.join(script)}`\n\n{output}")
    text = README.read_text()
    if START not in text or END not in text:
        text = text.rstrip() + f"\n\n## Current results\n\n{START}\n{END}\n"
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    README.write_text(f"{head}{START}\n" + "\n".join(sections) + f"\n{END}{tail}")
    print(f"tables written to {README}")


if __name__ == "__main__":
    main()
