"""Time-optimal timing of a weld seam that passes near a wrist singularity.

A UR5 draws a 0.3 m straight seam at 0.1 m/s with its torch held at a fixed orientation. Near the
middle of the seam the wrist nearly aligns, so at constant tool speed a joint would need more
than its speed limit: the nominal plan stops with a velocity_limit event. ``retime=True`` keeps
the exact seam and times it optimally under the joint speed limits and 10 rad/s² joint
accelerations: 0.1 m/s wherever the arm allows, slower only near the singularity.

Run: ``python examples/retime_seam.py [OUT_DIR]`` (writes ``retime_seam.png``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

import cartesian
import kinplan
from kinplan.trajectory.sampling import joint_speeds

START = np.array([0.63328222, -1.01665046, 1.86838938, -1.03828987, -0.49586564, 0.0])
SEAM = np.array([-0.29989079, 0.00809425, 0.0])  # [m], from the tool's start position
SPEED = 0.1  # m/s
ACCELERATION = 10.0  # rad/s², every joint


def main(out: Path | str = ".") -> dict:
    robot = kinplan.load_robot("ur5")
    start = robot.fk(START)
    seam = cartesian.Line(start, pin.SE3(start.rotation, start.translation + SEAM))
    options = dict(speed=SPEED, dt=0.005, q_seed=START, max_acceleration=ACCELERATION)
    nominal = cartesian.follow(robot, seam, **options)
    print(f"constant {SPEED} m/s: {nominal.summary()}")
    print(f"  remedy: {nominal.events[0].remedy}" if nominal.events else "")
    retimed = cartesian.follow(robot, seam, retime=True, **options)
    print(f"retime=True: {retimed.summary()}")
    figure = plot(robot, seam, nominal, retimed)
    path = Path(out) / "retime_seam.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    print(f"wrote {path}")
    return {"nominal": nominal, "retimed": retimed, "figure": path}


def plot(robot, seam, nominal, retimed):
    """Joint speeds against their limits, and the tool speed along the seam, before and after."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(10, 4.2), layout="constrained")
    speeds_axis, tool_axis = figure.subplots(1, 2)
    ratios = joint_speeds(retimed.q, retimed.qd, retimed.t) / robot.velocity_limit
    for j, name in enumerate(robot.joint_names):
        speeds_axis.plot(retimed.t, ratios[:, j], label=name.replace("_joint", ""))
    speeds_axis.axhline(1.0, color="k", linestyle="--", linewidth=1, label="limit")
    speeds_axis.set(xlabel="t [s]", ylabel="|q̇| / limit", title="retimed: joint speeds")
    speeds_axis.legend(fontsize=7, loc="upper left")
    tool_axis.plot(
        retimed.s * seam.length, seam.length * np.gradient(retimed.s, retimed.t),
        label="retime=True (time-optimal)", linewidth=2.5,
    )  # fmt: skip
    nominal_speed = seam.length * np.gradient(nominal.s, nominal.t)
    tool_axis.plot(nominal.s * seam.length, nominal_speed, "k--",
                   label=f"constant {SPEED} m/s: stops ({nominal.status})")  # fmt: skip
    if nominal.events:
        stop = nominal.events[0].s * seam.length
        tool_axis.plot([stop], [nominal_speed[-1]], "rx", markersize=10)
    tool_axis.set(xlabel="distance along the seam [m]", ylabel="tool speed [m/s]",
                  title="tool speed along the seam")  # fmt: skip
    tool_axis.legend(fontsize=8, loc="lower center")
    return figure


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
