"""A UR5 weld cell: a MIG torch welds a woven fillet seam and a blended rectangular seam.

The demo program ``weld_cell.yaml`` (kinplan's demo program, the same as
``examples/programs/weld_cell.yaml``): a table, a T-joint workpiece and a bent-neck torch on the
flange; the fillet along the foot of the web is woven (``weave:``) with the torch at 45° work
angle and 10° push (``torch:``), the rectangle's corners are blended (``blend:``) so the torch
keeps its speed through them; every move is checked against the cell with a 2 mm clearance.
Then ``weld_collision.yaml`` (an approach through the workpiece) and ``weld_unreachable.yaml``
(a seam across the robot's base) show the one-line failures ``kinplan run`` reports.

Writes into the output folder: ``weld.html`` (MeshCat playback, works offline),
``weld_motion.png`` (joint position/velocity/acceleration, tool speed, clearance),
``weld_tool_path.png``, ``weld.csv`` (every sample: t, q, qd, qdd, tool pose), ``weld.script``
(URScript), ``weld_trajectory.json`` (ROS JointTrajectory) and the programs with the torch mesh.

Run ``python examples/weld_demo.py --out out/weld`` (the same as ``kinplan demo weld``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from kinplan.apps import demos


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
    result = demos.weld(out_dir, html=html, dt=dt, progress=print)
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
