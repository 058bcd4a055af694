"""A UR5 welds two seams on a horizontal plate, tool pointing down, at constant tool speed.

- A rectangular seam with rounded corners: four lines joined by quarter-circle arcs
  (:func:`kinplan.demos.rounded_rectangle`), followed as one path, so the tool keeps its speed
  through the corners.
- A circular seam (:func:`cartesian.Circle`).

Each seam is approached with a ``ptp`` move above its start and a ``lin`` move down, and left with
a ``lin`` move up (:class:`kinplan.program.MotionBuilder`); the arm goes home at the end. Then the
program ``weld_unreachable.yaml`` (kinplan's demo program, the same as
``examples/programs/weld_unreachable.yaml``), whose seam crosses the column above the robot's
base, shows the one-line failure ``kinplan run`` reports.

Writes into the output folder: ``weld.html`` (MeshCat playback, works offline),
``weld_motion.png`` (joint position/velocity/acceleration and tool speed), ``weld_tool_path.png``,
``weld.csv`` (every sample: t, q, qd, qdd, tool pose) and ``weld_unreachable.yaml``.

Run ``python examples/weld_demo.py --out out/weld`` (the same as ``kinplan demo weld``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from kinplan import demos


def main(
    out_dir: str | Path = "out/weld", html: str | Path | None = None, dt: float | None = None
) -> demos.DemoResult:
    """Plan the weld, write the files and print a summary.

    Args:
        out_dir: Output folder (created).
        html: HTML playback file (default ``out_dir/weld.html``).
        dt: Sampling period [s] (default 0.01).

    Returns:
        The demo's result (``ok``, summary lines, files, the plan in ``data["plan"]``).
    """
    result = demos.weld(out_dir, html=html, dt=dt)
    print("\n".join(result.lines))
    print(f"\nfiles in {result.out_dir} ({result.seconds:.1f} s):")
    for label, path in result.files.items():
        print(f"  {label:<22} {path}")
    return result


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/weld", help="output folder")
    parser.add_argument("--html", help="HTML playback file (default: in the output folder)")
    parser.add_argument("--dt", type=float, help="sampling period [s]")
    arguments = parser.parse_args()
    outcome = main(arguments.out, html=arguments.html, dt=arguments.dt)
    raise SystemExit(0 if outcome.ok else 1)
