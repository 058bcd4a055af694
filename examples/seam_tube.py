"""Seam planning with a free torch roll: a 330° fillet around a tube, UR5 and panda.

A tube of radius 5 cm stands on a plate in front of the arm; the fillet at its foot runs 330°
around it, the torch pointing at the tube's foot 45° down (``cartesian.TorchOrientation``,
taught roll 0). Held at the taught roll, the torch turns 330° about the vertical with the seam,
and the wrist with it. ``cartesian.plan_seam`` lets the roll about the torch axis vary along the
seam (a welding torch is symmetric about its axis) and searches it, with every IK branch (and
the panda's self-motion), for the joint motion of least travel; then it follows the seam with
that roll law, monitored as ``cartesian.follow`` always is.

Run: ``python examples/seam_tube.py [OUT_DIR]`` (writes ``seam_tube.png``: the roll chosen along
the seam, and each joint's motion with the taught roll and with the searched one).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

import cartesian
import kinplan

SPEED = 0.02  # m/s
CENTRES = {"ur5": [0.45, 0.0, 0.1], "panda": [0.45, 0.0, 0.2]}  # the tube's foot [m]


def tube_seam(centre: list[float], radius: float = 0.05, sweep_deg: float = 330.0):
    """The fillet: counter-clockwise seen from above, from the side facing away from the base,
    the torch 45° down, tilted toward the tube (the left of the travel direction)."""
    arc = cartesian.CircularArc(
        centre, radius, [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], math.radians(sweep_deg)
    )
    return cartesian.TorchOrientation(arc, normal=(0, 0, 1), work_angle=math.radians(45))


def travel(plan: cartesian.CartesianPlan) -> float:
    """Joint travel Σ|Δq| [rad]."""
    return float(np.abs(np.diff(plan.q, axis=0)).sum())


def main(out: Path | str = ".", robots: tuple[str, ...] = ("ur5", "panda")) -> dict:
    results = {}
    for name in robots:
        robot = kinplan.load_robot(name)
        seam = tube_seam(CENTRES[name])
        home = robot.ik(seam.start, q_seed=robot.neutral()).q
        taught = cartesian.follow(robot, seam, speed=SPEED, q_seed=home)
        planned = cartesian.plan_seam(robot, seam, speed=SPEED)
        print(f"{name}, taught roll: {taught.summary()}")
        print(f"{name}, plan_seam:   {planned.summary()}")
        if planned.ok:
            roll = np.degrees(planned.roll)
            print(
                f"  roll {roll.min():.0f}° to {roll.max():.0f}° along the seam; joint travel "
                f"{math.degrees(travel(planned)):.0f}°"
                + (f" (taught roll: {math.degrees(travel(taught)):.0f}°)" if taught.ok else "")
            )
        results[name] = {"taught": taught, "planned": planned}
    figure = plot(results)
    path = Path(out) / "seam_tube.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    print(f"wrote {path}")
    results["figure"] = path
    return results


def plot(results: dict):
    """Left: the roll plan_seam chose along the seam, per arm. Right: the UR5's joints, with
    the taught roll (dashed) and the searched one (solid)."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(10, 4.2), layout="constrained")
    roll_axis, joint_axis = figure.subplots(1, 2)
    for name, result in results.items():
        planned = result["planned"]
        if planned.ok:
            degrees = np.degrees(planned.roll)
            roll_axis.plot(planned.s * 330.0, degrees, linewidth=2, label=f"{name}: plan_seam")
    roll_axis.axhline(0.0, color="k", linestyle="--", linewidth=1, label="taught roll")
    roll_axis.set(xlabel="angle around the tube [°]", ylabel="roll about the torch axis [°]",
                  title="roll chosen along the 330° tube seam")  # fmt: skip
    roll_axis.legend(fontsize=8)
    if "ur5" in results:
        taught, planned = results["ur5"]["taught"], results["ur5"]["planned"]
        for j in range(planned.q.shape[1]):
            line = joint_axis.plot(
                planned.s * 330.0, np.degrees(planned.q[:, j]), label=f"q{j + 1}"
            )
            if taught.ok or len(taught.q):
                joint_axis.plot(taught.s * 330.0, np.degrees(taught.q[:, j]), "--",
                                color=line[0].get_color(), linewidth=1)  # fmt: skip
        joint_axis.set(xlabel="angle around the tube [°]", ylabel="joint [°]",
                       title="UR5 joints: plan_seam (solid), taught roll (dashed)")  # fmt: skip
        joint_axis.legend(fontsize=7, ncol=3)
    return figure


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
